//! Reading a bag streams it: the peak memory of a full read does not grow with the file.
//! (Its own test binary, so no other test shares the process whose peak is measured.)

mod bag_support;

use adaptive_gnss_ins::ros::bag::{BagReader, BagWriteOptions, ReadOrder};
use bag_support::{gnss, imu, Recorder, IMU_PERIOD_NS, START_NS};

/// Ten minutes of IMU at 100 Hz and GNSS at 1 Hz: about 23 MB.
const SECONDS: u64 = 600;

/// Largest growth of the peak resident set allowed while reading (bytes): a few chunks
/// and buffers, far below the file size.
const MAX_PEAK_GROWTH_BYTES: u64 = 8 * 1024 * 1024;

/// Peak resident set size of this process (bytes), from /proc/self/status.
fn peak_rss_bytes() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let line = status
        .lines()
        .find(|line| line.starts_with("VmHWM:"))
        .unwrap();
    let kib: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kib * 1024
}

/// Resets the peak resident set size to the current one (Linux >= 4.0).
fn reset_peak_rss() {
    std::fs::write("/proc/self/clear_refs", "5").unwrap();
}

/// Reads every message of `reader`, returning (messages, errors, payload bytes).
fn read_through(reader: &BagReader) -> (u64, u64, u64) {
    let mut messages = 0;
    let mut errors = 0;
    let mut bytes = 0;
    for item in reader.messages().unwrap() {
        match item {
            Ok(message) => {
                messages += 1;
                bytes += message.data.len() as u64;
            }
            Err(_) => errors += 1,
        }
    }
    (messages, errors, bytes)
}

#[cfg(target_os = "linux")]
#[test]
fn reading_a_large_bag_keeps_the_peak_memory_flat() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ten_minutes.mcap");
    let mut recorder = Recorder::create(&path, BagWriteOptions::default());
    for k in 0..SECONDS * 100 {
        let t_ns = START_NS + k * IMU_PERIOD_NS;
        recorder
            .writer
            .write("/imu/data", &imu(k, t_ns), t_ns)
            .unwrap();
        if k % 100 == 0 {
            recorder
                .writer
                .write("/gnss/measurements", &gnss(k / 100, t_ns), t_ns)
                .unwrap();
        }
    }
    recorder.finish().unwrap();
    let file_len = std::fs::metadata(&path).unwrap().len();
    assert!(file_len > 2 * MAX_PEAK_GROWTH_BYTES, "{file_len}");
    let expected_messages = SECONDS * 100 + SECONDS;

    // Indexed (log-time) reading of the intact file.
    reset_peak_rss();
    let before = peak_rss_bytes();
    let reader = BagReader::open(&path).unwrap();
    assert_eq!(reader.read_order(), ReadOrder::LogTime);
    let (messages, errors, bytes) = read_through(&reader);
    let growth = peak_rss_bytes().saturating_sub(before);
    assert_eq!((messages, errors), (expected_messages, 0));
    assert!(
        bytes > file_len * 3 / 4,
        "{bytes} payload bytes of {file_len}"
    );
    assert!(
        growth < MAX_PEAK_GROWTH_BYTES,
        "indexed read: peak grew {growth} B"
    );

    // Front-to-back reading of a truncated copy.
    let cut_path = dir.path().join("cut.mcap");
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&cut_path, &bytes[..bytes.len() * 9 / 10]).unwrap();
    drop(bytes);
    reset_peak_rss();
    let before = peak_rss_bytes();
    let reader = BagReader::open(&cut_path).unwrap();
    assert_eq!(reader.read_order(), ReadOrder::File);
    let (messages, errors, _) = read_through(&reader);
    let growth = peak_rss_bytes().saturating_sub(before);
    assert!(messages > expected_messages * 8 / 10, "{messages}");
    assert_eq!(errors, 1);
    assert!(
        growth < MAX_PEAK_GROWTH_BYTES,
        "front-to-back read: peak grew {growth} B"
    );
}
