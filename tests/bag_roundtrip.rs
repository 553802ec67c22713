//! Writing and reading ROS 2 MCAP bags: round trip, determinism, damaged and foreign files.

mod bag_support;

use std::path::{Path, PathBuf};

use adaptive_gnss_ins::ros::bag::{
    BagError, BagMessage, BagReader, BagWriteOptions, BagWriter, ChunkCompression, ReadOrder,
    TopicInfo,
};
use adaptive_gnss_ins::ros::cdr;
use adaptive_gnss_ins::ros::msg::{
    GnssMeasurements, Imu, NavSatFix, NoiseEstimates, Odometry, TFMessage,
};
use bag_support::{
    fix, gnss, imu, noise, odometry, write_sample_bag, Recorder, Written, IMU_PERIOD_NS, START_NS,
    TOPICS,
};
use mcap::sans_io::{SummaryReadEvent, SummaryReader};

/// Chunks this small put the 3 s sample bag (~130 kB) into dozens of chunks.
const SMALL_CHUNKS: BagWriteOptions = BagWriteOptions {
    chunk_size_bytes: 4096,
    compression: ChunkCompression::None,
};

/// Reads every item of the stream: the messages, and the errors in order.
fn read_all(reader: &BagReader) -> (Vec<Written>, Vec<BagError>) {
    let mut messages = Vec::new();
    let mut errors = Vec::new();
    for item in reader.messages().unwrap() {
        match item {
            Ok(BagMessage {
                topic,
                type_name,
                log_time_ns,
                data,
            }) => messages.push(Written {
                topic,
                type_name,
                log_time_ns,
                data,
            }),
            Err(error) => errors.push(error),
        }
    }
    (messages, errors)
}

/// Expected topic list of a sample bag.
fn expected_topics(written: &[Written]) -> Vec<TopicInfo> {
    TOPICS
        .iter()
        .map(|(topic, type_name)| TopicInfo {
            topic: topic.to_string(),
            type_name: type_name.to_string(),
            message_count: written.iter().filter(|m| m.topic == *topic).count() as u64,
        })
        .collect()
}

/// Summary of an intact file, read with the MCAP library directly.
fn summary_of(bytes: &[u8]) -> mcap::Summary {
    let mut reader = SummaryReader::new();
    let mut cursor = std::io::Cursor::new(bytes);
    while let Some(event) = reader.next_event() {
        match event.unwrap() {
            SummaryReadEvent::ReadRequest(need) => {
                let read = std::io::Read::read(&mut cursor, reader.insert(need)).unwrap();
                reader.notify_read(read);
            }
            SummaryReadEvent::SeekRequest(to) => {
                let position = std::io::Seek::seek(&mut cursor, to).unwrap();
                reader.notify_seeked(position);
            }
        }
    }
    reader.finish().unwrap()
}

fn temp_path(dir: &tempfile::TempDir, name: &str) -> PathBuf {
    dir.path().join(name)
}

#[test]
fn round_trip_keeps_messages_order_topics_and_counts() {
    let dir = tempfile::tempdir().unwrap();
    let mut sizes = Vec::new();
    for (name, options) in [
        ("default.mcap", BagWriteOptions::default()),
        ("small_chunks.mcap", SMALL_CHUNKS),
        (
            "zstd_chunks.mcap",
            BagWriteOptions {
                compression: ChunkCompression::Zstd,
                ..SMALL_CHUNKS
            },
        ),
    ] {
        let path = temp_path(&dir, name);
        let written = write_sample_bag(&path, options, 3);
        assert_eq!(written.len(), 300 + 3 * 3 + 30);

        let reader = BagReader::open(&path).unwrap();
        assert_eq!(reader.read_order(), ReadOrder::LogTime, "{name}");
        assert_eq!(
            reader.topics(),
            expected_topics(&written).as_slice(),
            "{name}"
        );
        let (read, errors) = read_all(&reader);
        assert!(errors.is_empty(), "{name}: {errors:?}");
        assert_eq!(read, written, "{name}");
        sizes.push(std::fs::metadata(&path).unwrap().len());
    }
    assert!(sizes[2] < sizes[1], "zstd chunks are compressed: {sizes:?}");
}

#[test]
fn read_messages_decode_to_the_values_written() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_path(&dir, "decode.mcap");
    write_sample_bag(&path, SMALL_CHUNKS, 2);
    let reader = BagReader::open(&path).unwrap();
    let mut decoded = 0;
    let mut imu_index = 0_u64;
    let mut epoch = 0_u64;
    let mut odometry_index = 0_u64;
    for message in reader.messages().unwrap() {
        let message = message.unwrap();
        let t_ns = message.log_time_ns;
        match message.type_name.as_str() {
            "sensor_msgs/msg/Imu" => {
                assert_eq!(
                    cdr::decode::<Imu>(&message.data).unwrap(),
                    imu(imu_index, t_ns)
                );
                imu_index += 1;
            }
            "adaptive_gnss_ins/msg/GnssMeasurements" => {
                let value = cdr::decode::<GnssMeasurements>(&message.data).unwrap();
                assert_eq!(value, gnss(epoch, t_ns));
            }
            "sensor_msgs/msg/NavSatFix" => {
                assert_eq!(
                    cdr::decode::<NavSatFix>(&message.data).unwrap(),
                    fix(epoch, t_ns)
                );
            }
            "adaptive_gnss_ins/msg/NoiseEstimates" => {
                let value = cdr::decode::<NoiseEstimates>(&message.data).unwrap();
                assert_eq!(value, noise(epoch, t_ns));
                epoch += 1;
            }
            "nav_msgs/msg/Odometry" => {
                let value = cdr::decode::<Odometry>(&message.data).unwrap();
                assert_eq!(value, odometry(odometry_index, t_ns));
                odometry_index += 1;
            }
            other => panic!("unexpected type {other}"),
        }
        decoded += 1;
    }
    assert_eq!(decoded, 200 + 2 * 3 + 20);
    assert_eq!((imu_index, epoch, odometry_index), (200, 2, 20));
}

/// Writes IMU samples in time order with each GNSS epoch written 0.35 s late (after
/// the IMU samples that follow it), so chunks overlap in time; returns the messages in
/// file order.
fn write_unordered_bag(path: &Path) -> Vec<Written> {
    let mut recorder = Recorder::create(path, SMALL_CHUNKS);
    let mut late = Vec::new();
    for k in 0..300_u64 {
        let t_ns = START_NS + k * IMU_PERIOD_NS;
        recorder.write("/imu/data", &imu(k, t_ns), t_ns);
        if k % 50 == 0 {
            late.push((k + 35, k / 50, t_ns));
        }
        while let Some(&(due, epoch, stamp_ns)) = late.first() {
            if due > k {
                break;
            }
            recorder.write("/gnss/measurements", &gnss(epoch, stamp_ns), stamp_ns);
            late.remove(0);
        }
    }
    recorder.finish().unwrap()
}

#[test]
fn messages_written_out_of_time_order_are_read_in_log_time_order() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_path(&dir, "unordered.mcap");
    let mut expected = write_unordered_bag(&path);
    // Log-time order, ties in file (write) order: a stable sort.
    expected.sort_by_key(|message| message.log_time_ns);

    let reader = BagReader::open(&path).unwrap();
    assert_eq!(reader.read_order(), ReadOrder::LogTime);
    let (read, errors) = read_all(&reader);
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(read.len(), expected.len());
    assert_eq!(read, expected);
}

#[test]
fn same_messages_give_identical_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let first = temp_path(&dir, "first.mcap");
    let second = temp_path(&dir, "second.mcap");
    write_sample_bag(&first, SMALL_CHUNKS, 2);
    write_sample_bag(&second, SMALL_CHUNKS, 2);
    let first_bytes = std::fs::read(&first).unwrap();
    assert!(first_bytes.len() > 50_000);
    assert_eq!(first_bytes, std::fs::read(&second).unwrap());
}

#[test]
fn truncated_file_yields_the_messages_before_the_cut_then_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_path(&dir, "intact.mcap");
    let written = write_sample_bag(&path, SMALL_CHUNKS, 3);
    let bytes = std::fs::read(&path).unwrap();
    let summary = summary_of(&bytes);
    assert!(summary.chunk_indexes.len() > 20);
    let len = bytes.len();

    for cut in [
        len / 10,
        len / 4,
        len / 2,
        len * 3 / 4,
        len * 9 / 10,
        len - 30,
        len - 1,
    ] {
        let cut_path = temp_path(&dir, &format!("cut_{cut}.mcap"));
        std::fs::write(&cut_path, &bytes[..cut]).unwrap();
        let reader = BagReader::open(&cut_path).unwrap();
        assert_eq!(reader.read_order(), ReadOrder::File, "cut {cut}");
        let (read, errors) = read_all(&reader);

        // Every message of a chunk that lies wholly before the cut comes back.
        let first_incomplete_start = summary
            .chunk_indexes
            .iter()
            .filter(|chunk| chunk.chunk_start_offset + chunk.chunk_length > cut as u64)
            .map(|chunk| chunk.message_start_time)
            .min()
            .unwrap_or(u64::MAX);
        let in_complete_chunks = written
            .iter()
            .filter(|message| message.log_time_ns < first_incomplete_start)
            .count();
        assert!(
            read.len() >= in_complete_chunks,
            "cut {cut}: {} read, {in_complete_chunks} in complete chunks",
            read.len()
        );
        assert_eq!(read.as_slice(), &written[..read.len()], "cut {cut}");

        // The damage is reported once, naming the file.
        assert_eq!(errors.len(), 1, "cut {cut}: {errors:?}");
        let text = errors[0].to_string();
        assert!(text.contains(&*cut_path.to_string_lossy()), "{text}");
        assert!(matches!(errors[0], BagError::Mcap { .. }), "{text}");

        // Topics found by the front-to-back scan count the readable messages.
        let counted: u64 = reader.topics().iter().map(|t| t.message_count).sum();
        assert_eq!(counted, read.len() as u64, "cut {cut}");
    }
}

#[test]
fn file_cut_inside_the_magic_is_not_mcap() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_path(&dir, "intact.mcap");
    write_sample_bag(&path, SMALL_CHUNKS, 1);
    let bytes = std::fs::read(&path).unwrap();
    let cut_path = temp_path(&dir, "cut.mcap");
    std::fs::write(&cut_path, &bytes[..5]).unwrap();
    assert!(matches!(
        BagReader::open(&cut_path),
        Err(BagError::NotMcap { len: 5, .. })
    ));
}

/// The chunks of an intact file in file order, each with the range of the written
/// (file-order) messages it holds, counted from its message index records.
fn chunk_runs(bytes: &[u8]) -> Vec<(mcap::records::ChunkIndex, std::ops::Range<usize>)> {
    let mut chunks = summary_of(bytes).chunk_indexes;
    chunks.sort_by_key(|chunk| chunk.chunk_start_offset);
    let mut first = 0;
    chunks
        .into_iter()
        .map(|chunk| {
            let count = messages_in_chunk(bytes, &chunk);
            let run = first..first + count;
            first += count;
            (chunk, run)
        })
        .collect()
}

/// Writes `bytes` with one byte flipped in the middle of `chunk`'s content.
fn corrupt_copy(bytes: &[u8], chunk: &mcap::records::ChunkIndex, path: &Path) {
    let mut bytes = bytes.to_vec();
    let flip_at = chunk.chunk_start_offset + chunk.chunk_length - chunk.compressed_size / 2;
    bytes[flip_at as usize] ^= 0x5a;
    std::fs::write(path, &bytes).unwrap();
}

/// For every chunk of the bag at `path` (messages `written` in file order): with that
/// chunk corrupt, the stream reports one CRC error and yields every other message, in
/// log-time order.
fn check_each_corrupt_chunk(dir: &tempfile::TempDir, path: &Path, written: &[Written]) {
    let bytes = std::fs::read(path).unwrap();
    let runs = chunk_runs(&bytes);
    assert!(runs.len() > 10);
    assert_eq!(runs.last().unwrap().1.end, written.len());
    for (chunk, run) in &runs {
        let corrupt_path = temp_path(dir, &format!("corrupt_{}.mcap", chunk.chunk_start_offset));
        corrupt_copy(&bytes, chunk, &corrupt_path);
        let reader = BagReader::open(&corrupt_path).unwrap();
        assert_eq!(reader.read_order(), ReadOrder::LogTime);
        let (read, errors) = read_all(&reader);
        assert_eq!(errors.len(), 1, "{errors:?}");
        assert!(
            matches!(errors[0], BagError::ChunkCrc { chunk_offset, .. } if chunk_offset == chunk.chunk_start_offset),
            "{:?}",
            errors[0]
        );
        let mut expected: Vec<Written> = written[..run.start]
            .iter()
            .chain(&written[run.end..])
            .cloned()
            .collect();
        expected.sort_by_key(|message| message.log_time_ns);
        assert_eq!(
            read.len(),
            expected.len(),
            "chunk at {}",
            chunk.chunk_start_offset
        );
        assert!(read == expected, "chunk at {}", chunk.chunk_start_offset);
    }
}

#[test]
fn corrupt_chunk_is_reported_and_reading_goes_on_without_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_path(&dir, "intact.mcap");
    let written = write_sample_bag(&path, SMALL_CHUNKS, 3);
    check_each_corrupt_chunk(&dir, &path, &written);
}

#[test]
fn corrupt_chunk_among_chunks_overlapping_in_time_loses_only_that_chunk() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_path(&dir, "unordered.mcap");
    let written = write_unordered_bag(&path);
    check_each_corrupt_chunk(&dir, &path, &written);
}

/// Number of messages of `chunk`, from its message index records.
fn messages_in_chunk(bytes: &[u8], chunk: &mcap::records::ChunkIndex) -> usize {
    chunk
        .message_index_offsets
        .values()
        .map(|&offset| {
            let offset = offset as usize;
            assert_eq!(bytes[offset], mcap::records::op::MESSAGE_INDEX);
            let len = u64::from_le_bytes(bytes[offset + 1..offset + 9].try_into().unwrap());
            let body = &bytes[offset + 9..offset + 9 + len as usize];
            match mcap::parse_record(mcap::records::op::MESSAGE_INDEX, body).unwrap() {
                mcap::records::Record::MessageIndex(index) => index.records.len(),
                other => panic!("not a message index: {other:?}"),
            }
        })
        .sum()
}

#[test]
fn garbage_and_empty_files_are_not_mcap() {
    let dir = tempfile::tempdir().unwrap();
    let garbage = temp_path(&dir, "garbage.mcap");
    let bytes: Vec<u8> = (0..10_000_u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    std::fs::write(&garbage, &bytes).unwrap();
    let error = BagReader::open(&garbage).err().unwrap();
    assert!(
        matches!(error, BagError::NotMcap { len: 10_000, .. }),
        "{error}"
    );
    assert!(error.to_string().contains("garbage.mcap"), "{error}");

    let empty = temp_path(&dir, "empty.mcap");
    std::fs::write(&empty, b"").unwrap();
    assert!(matches!(
        BagReader::open(&empty),
        Err(BagError::NotMcap { len: 0, .. })
    ));

    let missing = temp_path(&dir, "missing.mcap");
    assert!(matches!(
        BagReader::open(&missing),
        Err(BagError::Io { .. })
    ));
}

#[test]
fn mcap_magic_followed_by_garbage_opens_and_reports_the_damage() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_path(&dir, "magic_then_garbage.mcap");
    let mut bytes = mcap::MAGIC.to_vec();
    bytes.extend((0..5000_u32).map(|i| (i.wrapping_mul(40_503) >> 7) as u8));
    std::fs::write(&path, &bytes).unwrap();
    let reader = BagReader::open(&path).unwrap();
    let (read, errors) = read_all(&reader);
    assert!(read.is_empty());
    assert_eq!(errors.len(), 1, "{errors:?}");
}

#[test]
fn empty_bags_read_back_empty() {
    let dir = tempfile::tempdir().unwrap();

    let nothing = temp_path(&dir, "nothing.mcap");
    BagWriter::create(&nothing).unwrap().finish().unwrap();
    let reader = BagReader::open(&nothing).unwrap();
    assert_eq!(reader.read_order(), ReadOrder::LogTime);
    assert!(reader.topics().is_empty());
    let (read, errors) = read_all(&reader);
    assert!(read.is_empty() && errors.is_empty());

    let topics_only = temp_path(&dir, "topics_only.mcap");
    let mut writer = BagWriter::create(&topics_only).unwrap();
    writer.add_topic::<Imu>("/imu/data").unwrap();
    writer.add_topic::<TFMessage>("/tf").unwrap();
    writer.finish().unwrap();
    let reader = BagReader::open(&topics_only).unwrap();
    assert_eq!(
        reader.topics(),
        [
            TopicInfo {
                topic: "/imu/data".to_string(),
                type_name: "sensor_msgs/msg/Imu".to_string(),
                message_count: 0
            },
            TopicInfo {
                topic: "/tf".to_string(),
                type_name: "tf2_msgs/msg/TFMessage".to_string(),
                message_count: 0
            }
        ]
    );
    let (read, errors) = read_all(&reader);
    assert!(read.is_empty() && errors.is_empty());
}

#[test]
fn writer_rejects_a_second_type_on_a_topic_and_raw_data_on_an_unknown_topic() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_path(&dir, "misuse.mcap");
    let mut writer = BagWriter::create(&path).unwrap();
    writer.add_topic::<Imu>("/imu/data").unwrap();
    writer.add_topic::<Imu>("/imu/data").unwrap();
    let error = writer.add_topic::<NavSatFix>("/imu/data").unwrap_err();
    assert!(
        matches!(error, BagError::TopicTypeMismatch { .. }),
        "{error}"
    );
    let error = writer
        .write("/imu/data", &fix(0, START_NS), START_NS)
        .unwrap_err();
    assert!(
        matches!(error, BagError::TopicTypeMismatch { .. }),
        "{error}"
    );
    let payload = cdr::encode(&fix(0, START_NS)).unwrap();
    let error = writer
        .write_cdr("/gnss/fix", &payload, START_NS)
        .unwrap_err();
    assert!(matches!(error, BagError::UnknownTopic { .. }), "{error}");

    // Serialized data on an added topic is stored as given.
    writer.add_topic::<NavSatFix>("/gnss/fix").unwrap();
    writer.write_cdr("/gnss/fix", &payload, START_NS).unwrap();
    writer.finish().unwrap();
    let (read, errors) = read_all(&BagReader::open(&path).unwrap());
    assert!(errors.is_empty());
    assert_eq!(read.len(), 1);
    assert_eq!(read[0].data, payload);
}

#[test]
fn a_rosbag2_directory_holding_one_file_opens() {
    let dir = tempfile::tempdir().unwrap();
    let bag_dir = dir.path().join("run1");
    std::fs::create_dir(&bag_dir).unwrap();
    let written = write_sample_bag(&bag_dir.join("run1_0.mcap"), SMALL_CHUNKS, 1);
    std::fs::write(
        bag_dir.join("metadata.yaml"),
        "rosbag2_bagfile_information: {}\n",
    )
    .unwrap();
    let reader = BagReader::open(&bag_dir).unwrap();
    assert_eq!(reader.path(), bag_dir.join("run1_0.mcap").as_path());
    let (read, errors) = read_all(&reader);
    assert!(errors.is_empty());
    assert_eq!(read, written);

    write_sample_bag(&bag_dir.join("run1_1.mcap"), SMALL_CHUNKS, 1);
    let error = BagReader::open(&bag_dir).err().unwrap();
    assert!(
        matches!(error, BagError::BagDirectory { found: 2, .. }),
        "{error}"
    );
    assert_path_in_message(&error, &bag_dir);
}

fn assert_path_in_message(error: &BagError, path: &Path) {
    let text = error.to_string();
    assert!(text.contains(&*path.to_string_lossy()), "{text}");
}
