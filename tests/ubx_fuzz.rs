//! The UBX input never panics: random bytes, random frames of the decoded message types
//! and bit-flipped copies of valid frames (fixed seed, many iterations); and what it skips
//! is counted.

use adaptive_gnss_ins::gnss::ephemeris::GpsTime;
use adaptive_gnss_ins::gnss::ubx::{
    decode_message, encode_frame, read_ubx_log, FrameReader, NavDecoder, Sfrbx, UbxMessage,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// (class, id) of RAWX, SFRBX, NAV-PVT and an unknown message.
const KINDS: [(u8, u8); 4] = [(0x02, 0x15), (0x02, 0x13), (0x01, 0x07), (0x0A, 0x09)];

fn random_payload(rng: &mut ChaCha8Rng, kind: (u8, u8)) -> Vec<u8> {
    let len = match kind {
        // Consistent lengths half of the time so the decoders go deep.
        (0x02, 0x15) if rng.random_bool(0.5) => {
            let n = rng.random_range(0..8usize);
            let mut p: Vec<u8> = (0..16 + 32 * n).map(|_| rng.random()).collect();
            p[11] = n as u8;
            return p;
        }
        (0x02, 0x13) if rng.random_bool(0.5) => {
            let n = [8usize, 9, 10][rng.random_range(0..3)];
            let mut p: Vec<u8> = (0..8 + 4 * n).map(|_| rng.random()).collect();
            p[0] = [0u8, 2, 3, 5][rng.random_range(0..4)];
            p[2] = [0u8, 1, 4][rng.random_range(0..3)];
            p[4] = n as u8;
            return p;
        }
        (0x01, 0x07) if rng.random_bool(0.5) => 92,
        _ => rng.random_range(0..200usize),
    };
    (0..len).map(|_| rng.random()).collect()
}

#[test]
fn random_and_mutated_input_never_panics() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5EED_0827);
    for iteration in 0..2_000 {
        let mut data = Vec::new();
        for _ in 0..rng.random_range(0..12) {
            match rng.random_range(0..3) {
                0 => data.extend((0..rng.random_range(0..64)).map(|_| rng.random::<u8>())),
                _ => {
                    let kind = KINDS[rng.random_range(0..KINDS.len())];
                    let payload = random_payload(&mut rng, kind);
                    data.extend(encode_frame(kind.0, kind.1, &payload).unwrap());
                }
            }
        }
        // Mutations: bit flips, a cut, sync bytes sprinkled in.
        for _ in 0..rng.random_range(0..4) {
            if !data.is_empty() {
                let i = rng.random_range(0..data.len());
                data[i] ^= 1 << rng.random_range(0..8);
            }
        }
        if rng.random_bool(0.3) && !data.is_empty() {
            let cut = rng.random_range(0..data.len());
            data.truncate(cut);
        }
        if rng.random_bool(0.3) {
            data.extend([0xB5, 0x62]);
        }
        let log = read_ubx_log(&data);
        let s = log.stats;
        assert!(
            s.frames.frames <= data.len() / 8 + 1,
            "iteration {iteration}"
        );
        // Every valid frame is accounted for exactly once.
        assert_eq!(
            s.frames.frames,
            s.rawx + s.sfrbx + s.nav_pvt + s.unknown + s.decode_errors,
            "iteration {iteration}"
        );
    }
}

#[test]
fn random_navigation_words_never_panic_and_are_rejected() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    let mut decoder = NavDecoder::new();
    let t = GpsTime::new(2381, 408_660.0);
    for _ in 0..20_000 {
        let gnss_id = [0u8, 2, 3, 5, 6][rng.random_range(0..5)];
        let n = rng.random_range(0..12usize);
        let msg = Sfrbx {
            gnss_id,
            sv_id: rng.random_range(0..40),
            sig_id: [0u8, 1, 4][rng.random_range(0..3)],
            freq_id: 0,
            channel: 0,
            version: 2,
            words: (0..n).map(|_| rng.random()).collect(),
        };
        assert!(decoder.push(&msg, &t).is_none());
    }
    let s = decoder.stats();
    assert_eq!(s.ephemerides, 0);
    assert_eq!(s.accepted + s.rejected + s.unsupported, 20_000, "{s:?}");
    assert!(s.rejected > 5_000, "{s:?}");
}

#[test]
fn unknown_corrupt_and_truncated_frames_are_skipped_and_counted() {
    let pvt = encode_frame(0x01, 0x07, &[0u8; 92]).unwrap();
    let unknown = encode_frame(0x0A, 0x04, &[1, 2, 3, 4]).unwrap();
    let short_rawx = encode_frame(0x02, 0x15, &[0u8; 15]).unwrap();
    let mut corrupt = pvt.clone();
    corrupt[50] ^= 0x10;
    let mut data = Vec::new();
    data.extend(&pvt);
    data.extend(&unknown);
    data.extend(&corrupt);
    data.extend(&short_rawx);
    data.extend(&pvt);
    data.extend(&pvt[..60]);
    let log = read_ubx_log(&data);
    let s = log.stats;
    assert_eq!(s.nav_pvt, 2);
    assert_eq!(s.unknown, 1);
    assert_eq!(s.decode_errors, 1);
    assert_eq!(s.frames.bad_checksum, 1);
    assert_eq!(s.frames.truncated, 1);
    // Two NAV-PVT, the unknown one and the short RAWX.
    assert_eq!(s.frames.frames, 4);
    let frames: Vec<_> = FrameReader::new(&data).collect();
    assert!(matches!(
        decode_message(&frames[1]),
        Ok(UbxMessage::Unknown {
            class: 0x0A,
            id: 0x04
        })
    ));
}
