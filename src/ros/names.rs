//! ROS 2 topic-name resolution: relative and `~/` names against the node's namespace and
//! name, then the command line's remappings.

/// The fully qualified form of `name` for node `node` in namespace `ns` (absolute).
///
/// `/a` stays as is, `a` becomes `ns/a`, `~/a` becomes `ns/node/a`.
pub fn resolve(name: &str, ns: &str, node: &str) -> String {
    let prefix = if ns == "/" { "" } else { ns };
    if name.starts_with('/') {
        name.to_owned()
    } else if let Some(private) = name.strip_prefix("~/") {
        format!("{prefix}/{node}/{private}")
    } else {
        format!("{prefix}/{name}")
    }
}

/// The topic `name` resolves to after the remappings `(from, to)`.
///
/// Choice (as rcl does): both sides of a rule are resolved like the name itself and the
/// first rule whose resolved `from` equals the resolved name wins.
pub fn resolve_remapped(name: &str, ns: &str, node: &str, remaps: &[(String, String)]) -> String {
    let resolved = resolve(name, ns, node);
    remaps
        .iter()
        .find(|(from, _)| resolve(from, ns, node) == resolved)
        .map_or(resolved, |(_, to)| resolve(to, ns, node))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolution_in_root_and_nested_namespaces() {
        assert_eq!(resolve("imu", "/", "n"), "/imu");
        assert_eq!(resolve("gnss/fix", "/r1", "n"), "/r1/gnss/fix");
        assert_eq!(resolve("/diagnostics", "/r1", "n"), "/diagnostics");
        assert_eq!(resolve("~/noise_estimates", "/", "n"), "/n/noise_estimates");
        assert_eq!(
            resolve("~/noise_estimates", "/a/b", "n"),
            "/a/b/n/noise_estimates"
        );
    }

    #[test]
    fn remapping_matches_resolved_names() {
        let remaps = vec![
            ("imu".to_owned(), "/sensors/imu".to_owned()),
            ("/r1/odometry".to_owned(), "odom".to_owned()),
            ("~/noise_estimates".to_owned(), "noise".to_owned()),
        ];
        let r = |name| resolve_remapped(name, "/r1", "ins", &remaps);
        assert_eq!(r("imu"), "/sensors/imu");
        assert_eq!(r("odometry"), "/r1/odom");
        assert_eq!(r("~/noise_estimates"), "/r1/noise");
        assert_eq!(r("fix"), "/r1/fix");
        // A rule for `imu` does not touch `gnss/imu`.
        assert_eq!(r("gnss/imu"), "/r1/gnss/imu");
    }
}
