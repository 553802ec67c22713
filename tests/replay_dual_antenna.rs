//! `gnss_ins replay` with a moving-base pair's `/ubx_nav_rel_pos_ned`
//! (ublox_ubx_msgs/UBXNavRelPosNED through the bag's CDR, the node's adapter and the
//! engine; issue 14, item 4): the simulated consumer-MEMS car of tests/dual_antenna.rs
//! through its 30 s GNSS outage, written by the simulator with its pair. With
//! `dual_antenna.enabled` every message reaches the engine and the heading error stays
//! within 1°; without, the messages are counted as unfed and the run is the one of the
//! bag of the same scenario without a pair.

mod car_outage_support;

use std::path::Path;

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::ros::adapter::Input;
use adaptive_gnss_ins::sim::{DualAntennaSpec, Scenario};
use adaptive_gnss_ins::tools::bag_run::BagRun;
use adaptive_gnss_ins::tools::replay::{replay, ReplayOptions, TruthSource};
use adaptive_gnss_ins::tools::simulate::{self, simulate_with, SimulateOptions, REL_POS_NED_TOPIC};

use car_outage_support::{consumer_mems_loose, spec, CAR_OUTAGE, SEED};

fn car_config(pair: bool) -> Config {
    let mut config = consumer_mems_loose();
    config.dual_antenna.enabled = pair;
    config
}

fn replay_scored(bag: &Path, config: &Config) -> BagRun {
    let truth = TruthSource::Topic(simulate::TRUTH_TOPIC.to_owned());
    replay(bag, config, truth, &ReplayOptions::default(), |_| {}).unwrap()
}

fn max_yaw_error_deg(run: &BagRun) -> f64 {
    run.report
        .errors
        .iter()
        .map(|(_, e)| e.attitude_rpy_rad.unwrap().z.to_degrees().abs())
        .fold(0.0, f64::max)
}

#[test]
fn replay_feeds_the_pairs_headings_of_a_bag_when_enabled() {
    let dir = tempfile::tempdir().unwrap();
    let options = SimulateOptions { velocity: true };
    let plain = dir.path().join("plain.mcap");
    simulate_with(
        &Scenario::new(spec(CAR_OUTAGE), SEED).unwrap(),
        &plain,
        options,
    )
    .unwrap();
    let mut paired_spec = spec(CAR_OUTAGE);
    paired_spec.dual_antenna = Some(DualAntennaSpec {
        baseline_m: [1.0, 0.0, 0.0],
        heading_sigma_deg: 0.3,
    });
    let paired = dir.path().join("paired.mcap");
    let written = simulate_with(&Scenario::new(paired_spec, SEED).unwrap(), &paired, options)
        .unwrap()
        .rel_pos_ned as u64;

    let on = replay_scored(&paired, &car_config(true));
    let off = replay_scored(&paired, &car_config(false));
    let without = replay_scored(&plain, &car_config(false));

    assert!(written > 150, "{written}");
    assert_eq!(on.counts.stream(Input::RelPosNed).received, written);
    assert_eq!(on.problems.used(REL_POS_NED_TOPIC), written);
    assert_eq!(on.counts.stream(Input::RelPosNed).unconvertible, 0);
    assert_eq!(on.rejections.total(), 0, "{:?}", on.rejections);
    assert_eq!(off.counts.stream(Input::RelPosNed).received, 0);
    assert_eq!(
        off.problems.unfed_inputs.get(REL_POS_NED_TOPIC),
        Some(&written)
    );
    assert_eq!(off.report.errors, without.report.errors);

    let (on_deg, off_deg) = (max_yaw_error_deg(&on), max_yaw_error_deg(&off));
    println!(
        "replay: {written} UBXNavRelPosNED; largest heading error {on_deg:.3} deg with them, \
         {off_deg:.3} deg without"
    );
    assert!(on_deg < 1.0, "{on_deg:.3} deg");
    assert!(on_deg < off_deg);
}
