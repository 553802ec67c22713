//! The Python interpreter of the test peers' venv (`.venv/`, made by
//! `scripts/setup_test_peers.sh` with the pinned packages of
//! `tools/requirements-test-peers.txt`: rosbags, cyclonedds, ROS 2 Jazzy rclpy, PyYAML).

use std::path::{Path, PathBuf};

/// The venv's `python`; a missing venv fails the test (it is never skipped) and says how
/// to make it.
pub fn python() -> PathBuf {
    let python = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python");
    assert!(
        python.exists(),
        "FAILED, not skipped: {} is missing. Run `bash scripts/setup_test_peers.sh` first \
         (it creates the venv with the pinned test peers of tools/requirements-test-peers.txt).",
        python.display()
    );
    python
}
