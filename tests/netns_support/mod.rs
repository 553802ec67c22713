//! DDS tests run inside a private network namespace that has only loopback (`unshare -n`,
//! needs root), where discovery still works between the processes of the namespace and no
//! packet leaves the machine.
#![allow(dead_code)]

use std::process::{Child, Command};

const IN_NETNS: &str = "GNSS_INS_TEST_IN_NETNS";

/// Runs the test `name` of this test binary again inside a loopback-only network
/// namespace and asserts that it passed there. Returns false when already inside (the
/// caller then does the real work), true when the caller must return.
pub fn reexec_in_private_netns(name: &str) -> bool {
    if std::env::var_os(IN_NETNS).is_some() {
        return false;
    }
    let probe = Command::new("unshare").arg("--version").output();
    assert!(
        probe.is_ok_and(|o| o.status.success()),
        "this test needs `unshare` (util-linux) and root to run DDS in a private network namespace"
    );
    let exe = std::env::current_exe().unwrap();
    let status = Command::new("unshare")
        .args(["-n", "sh", "-c", "ip link set lo up && exec \"$0\" \"$@\""])
        .arg(exe)
        // --include-ignored: an ignored test run by hand is run inside too.
        .args([
            name,
            "--exact",
            "--include-ignored",
            "--nocapture",
            "--test-threads=1",
        ])
        .env(IN_NETNS, "1")
        .status()
        .unwrap();
    assert!(
        status.success(),
        "{name} failed inside the network namespace"
    );
    true
}

/// A child process killed when dropped (also when the test panics).
pub struct KillOnDrop(pub Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Resident memory (kB) of process `pid` (VmRSS of /proc/PID/status), for the soaks.
pub fn rss_kb(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches(" kB").trim().parse().ok())
        .unwrap()
}
