//! UBX framing cost of 1 MiB sync floods (issue 12 item 15: repeated `B5 62 02 15 FF FF`,
//! every candidate declaring a 64 KiB payload; and the same with 8 KiB, the longest
//! payload accepted, whose checksums must all be checked) and of the real walk_0827 log,
//! whole and streamed in 512-byte chunks. Run with `cargo bench --bench ubx_framing`.

use std::hint::black_box;
use std::path::Path;

use adaptive_gnss_ins::gnss::ubx::{FrameReader, UbxFramer};
use criterion::{criterion_group, criterion_main, Criterion};

/// 1 MiB of sync patterns, each followed by class/id 02 15 and the length `len`.
fn sync_flood(len: u16) -> Vec<u8> {
    let [lo, hi] = len.to_le_bytes();
    [0xB5u8, 0x62, 0x02, 0x15, lo, hi]
        .iter()
        .copied()
        .cycle()
        .take(1 << 20)
        .collect()
}

fn walk_log() -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/walk_0827/gnss_1730.ubx");
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Frames of `data` fed to a [`UbxFramer`] in chunks of `chunk` bytes.
fn streamed(data: &[u8], chunk: usize) -> usize {
    let mut framer = UbxFramer::new();
    let mut frames = 0;
    for piece in data.chunks(chunk) {
        framer.push(piece);
        while framer.next_frame().is_some() {
            frames += 1;
        }
    }
    framer.finish();
    while framer.next_frame().is_some() {
        frames += 1;
    }
    frames
}

fn framing(c: &mut Criterion) {
    let flood_64k = sync_flood(0xFFFF);
    let flood_8k = sync_flood(0x2000);
    let log = walk_log();
    let mut group = c.benchmark_group("ubx_framing");
    group.sample_size(10);
    group.bench_function("sync_flood_64k_1mib_file", |b| {
        b.iter(|| FrameReader::new(black_box(&flood_64k)).count())
    });
    group.bench_function("sync_flood_8k_1mib_file", |b| {
        b.iter(|| FrameReader::new(black_box(&flood_8k)).count())
    });
    group.bench_function("sync_flood_8k_1mib_stream_512", |b| {
        b.iter(|| streamed(black_box(&flood_8k), 512))
    });
    group.bench_function("walk_0827_file", |b| {
        b.iter(|| FrameReader::new(black_box(&log)).count())
    });
    group.bench_function("walk_0827_stream_512", |b| {
        b.iter(|| streamed(black_box(&log), 512))
    });
    group.finish();
}

criterion_group!(benches, framing);
criterion_main!(benches);
