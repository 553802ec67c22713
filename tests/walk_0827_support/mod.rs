//! The real recording walk_0827 for the tests that read it: it lives in the shared data
//! folder beside the crate (../shared/data/walk_0827), not in the repository.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The folder of the recording.
pub fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/walk_0827")
}

/// The recording's file `name` (not checked to exist: a tool under test may be meant to
/// find it missing).
pub fn path(name: &str) -> PathBuf {
    dir().join(name)
}

/// The bytes of the recording's file `name`; a missing file fails the test saying where
/// the data is expected.
pub fn read(name: &str) -> Vec<u8> {
    let path = path(name);
    std::fs::read(&path).unwrap_or_else(|e| {
        panic!(
            "test data {} is missing ({e}): the repository expects the shared/ data folder \
             beside the crate (../shared/data/walk_0827)",
            path.display()
        )
    })
}

/// The text of the recording's file `name` (RINEX, CSV: ASCII).
pub fn read_text(name: &str) -> String {
    String::from_utf8(read(name)).unwrap_or_else(|e| panic!("{name} is not text: {e}"))
}
