//! The adapter's message handling, driven as the node and replay drive it.

use nalgebra::Matrix3;

use super::*;
use crate::engine::{Output, RejectionReason};
use crate::ins::ImuSample;
use crate::ros::convert::seconds_to_time;
use crate::ros::msg::{
    DiagnosticStatus, Imu, NavSatFix, NavSatStatus, Time, TwistWithCovarianceStamped,
};
use crate::ros::outbound;

fn imu_at(t_s: f64) -> Imu {
    let sample = ImuSample {
        t_s,
        w_ib_b_rad_s: nalgebra::Vector3::zeros(),
        f_ib_b_m_s2: nalgebra::Vector3::new(0.0, 0.0, 9.8),
    };
    outbound::imu(&sample, seconds_to_time(t_s).unwrap(), "imu")
}

/// The messages of a published solution.
fn messages(published: &Published) -> Option<&SolutionMessages> {
    match published {
        Published::Solution(s) => s.messages.as_deref(),
        Published::Epoch(_) | Published::NoFix(_) => None,
    }
}

fn feed(adapter: &mut RosAdapter, t0_s: f64, t1_s: f64) {
    let n = ((t1_s - t0_s) * 100.0).round() as usize;
    for k in 0..n {
        adapter.on_imu(&imu_at(t0_s + k as f64 * 0.01));
    }
}

fn diagnostic(adapter: &RosAdapter, key: &str) -> Option<String> {
    let d = adapter.diagnostics("/n", Time::default());
    d.status[0]
        .values
        .iter()
        .find(|kv| kv.key == key)
        .map(|kv| kv.value.clone())
}

#[test]
fn time_jump_backwards_resets_small_steps_are_rejected() {
    let mut adapter = RosAdapter::new(Config::default(), OutputFrames::default());
    feed(&mut adapter, 100.0, 102.0);
    adapter.on_imu(&imu_at(101.5));
    assert_eq!(adapter.counts().time_jump_resets, 0);
    assert_eq!(
        adapter
            .engine()
            .counters()
            .count(RejectionReason::ImuOutOfOrder),
        1
    );
    feed(&mut adapter, 50.0, 51.0);
    assert_eq!(adapter.counts().time_jump_resets, 1);
    assert_eq!(adapter.engine().last_imu_t_s(), Some(50.99));
    assert_eq!(
        adapter
            .engine()
            .counters()
            .count(RejectionReason::ImuOutOfOrder),
        1,
        "the samples after the jump are accepted"
    );
    assert_eq!(
        diagnostic(&adapter, "time_jump_resets").as_deref(),
        Some("1")
    );
    assert_eq!(diagnostic(&adapter, "imu_received").as_deref(), Some("301"));
}

#[test]
fn bad_inputs_are_counted_and_dropped() {
    let mut adapter = RosAdapter::new(Config::default(), OutputFrames::default());
    feed(&mut adapter, 10.0, 10.5);
    let mut nan = imu_at(10.5);
    nan.linear_acceleration.y = f64::NAN;
    assert!(adapter.on_imu(&nan).is_empty());
    let mut bad_stamp = imu_at(10.6);
    bad_stamp.header.stamp.nanosec = 1_500_000_000;
    assert!(adapter.on_imu(&bad_stamp).is_empty());
    adapter.on_undecodable("imu", "truncated payload");
    let mut no_fix = NavSatFix::default();
    no_fix.status.status = -1;
    assert!(adapter.on_fix(&no_fix).is_empty());
    assert_eq!(
        adapter.counts().stream(Input::Imu).unconvertible,
        2,
        "NaN and a bad stamp"
    );
    assert_eq!(adapter.counts().stream(Input::Fix).unconvertible, 1);
    assert_eq!(adapter.counts().undecodable, 1);
    assert_eq!(
        diagnostic(&adapter, "unconvertible_imu").as_deref(),
        Some("2")
    );
    assert_eq!(
        diagnostic(&adapter, "phase").as_deref(),
        Some("initializing (Leveling)")
    );
    // The node goes on with good data.
    feed(&mut adapter, 10.7, 11.0);
    assert_eq!(adapter.engine().last_imu_t_s(), Some(10.99));
}

#[test]
fn a_second_imu_frame_is_counted_and_dropped() {
    let mut adapter = RosAdapter::new(Config::default(), OutputFrames::default());
    feed(&mut adapter, 10.0, 10.5);
    let mut other = imu_at(10.505);
    other.header.frame_id = "other_imu".to_owned();
    assert!(adapter.on_imu(&other).is_empty());
    assert_eq!(adapter.counts().stream(Input::Imu).foreign_frame, 1);
    assert_eq!(
        adapter.engine().last_imu_t_s(),
        Some(10.49),
        "not fed to the engine"
    );
    assert_eq!(
        diagnostic(&adapter, "foreign_frame_imu").as_deref(),
        Some("1")
    );
    feed(&mut adapter, 10.5, 10.6);
    assert_eq!(
        adapter.engine().last_imu_t_s(),
        Some(10.59),
        "the first frame goes on"
    );
}

#[test]
fn loose_coupling_runs_on_fixes_and_counts_raw_epochs_as_wrong_coupling() {
    use crate::sim::SimEvent;
    let mut adapter = loose_adapter(OutputFrames::default());
    let (mut odometry, mut epochs) = (0, 0);
    let mut out_had_tf = false;
    for_each_static_event_30_s(|event, stamp| {
        let out = match event {
            SimEvent::Imu(s) => adapter.on_imu(&outbound::imu(&s, stamp, "imu")),
            SimEvent::Fix(f) => adapter.on_fix(&outbound::receiver_fix(&f, stamp, "gnss")),
            SimEvent::Gnss { epoch, .. } => {
                epochs += 1;
                adapter.on_gnss(&outbound::gnss_measurements(&epoch, 0, stamp, "gnss"))
            }
            _ => Vec::new(),
        };
        odometry += out
            .iter()
            .filter(|m| matches!(m, Published::Solution(_)))
            .count();
        out_had_tf |= out
            .iter()
            .any(|m| messages(m).is_some_and(|m| m.tf.is_some()));
    });
    assert!(odometry > 2000, "{odometry} odometry messages in 30 s");
    assert_eq!(adapter.counts().stream(Input::Velocity).received, 0);
    assert!(!out_had_tf, "no /tf without publish_tf");
    assert_eq!(adapter.engine().init_phase(), None, "running");
    assert_eq!(adapter.counts().stream(Input::Fix).unconvertible, 0);
    assert_eq!(
        adapter
            .engine()
            .counters()
            .count(RejectionReason::WrongCoupling),
        epochs
    );
}

fn loose_adapter(frames: OutputFrames) -> RosAdapter {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/params/ekf_loose.yaml");
    let text = std::fs::read_to_string(path).unwrap();
    let mut config = Config::from_yaml_str(&text, path).unwrap();
    // The static scenario faces north; heading is not observable at rest.
    config.set_parameter("init.heading_deg", "0.0").unwrap();
    RosAdapter::new(config, frames)
}

/// Calls `on_event` with the static scenario's events of its first 30 s, each with its
/// stamp.
fn for_each_static_event_30_s(on_event: impl FnMut(crate::sim::SimEvent, Time)) {
    for_each_static_event(30.0, on_event);
}

/// Calls `on_event` with the static scenario's events up to `until_s`, each with its
/// stamp.
fn for_each_static_event(until_s: f64, mut on_event: impl FnMut(crate::sim::SimEvent, Time)) {
    let scenario = crate::sim::Scenario::builtin("static", 5).unwrap();
    for event in scenario.events() {
        let event = event.unwrap();
        if event.t_s() > until_s {
            break;
        }
        let stamp = seconds_to_time(event.t_s()).unwrap();
        on_event(event, stamp);
    }
}

/// The velocity message of a simulated fix (ENU twist, the linear covariance block).
fn velocity_of(fix: &crate::engine::GnssFix, frame_id: &str) -> TwistWithCovarianceStamped {
    let stamp = seconds_to_time(fix.t_s).unwrap();
    outbound::receiver_velocity(fix, stamp, frame_id).unwrap()
}

#[test]
fn velocities_pair_with_their_fixes_bad_ones_are_counted_and_tf_follows_odometry() {
    use crate::sim::SimEvent;
    let frames = OutputFrames {
        map_frame: "map".to_owned(),
        base_frame: "imu_link".to_owned(),
        publish_tf: true,
        ..OutputFrames::default()
    };
    let mut adapter = loose_adapter(frames);
    let mut out = Vec::new();
    let (mut fixes, mut paired) = (0, 0);
    for_each_static_event_30_s(|event, stamp| {
        match event {
            SimEvent::Imu(s) => out.extend(adapter.on_imu(&outbound::imu(&s, stamp, "imu"))),
            SimEvent::Fix(f) => {
                fixes += 1;
                let fix = outbound::receiver_fix(&f, stamp, "gnss");
                // Velocity in the map frame or in the fix's frame, after or before
                // (after for the first: it pairs as well).
                let mut velocity = velocity_of(&f, ["map", "gnss"][fixes % 2]);
                match fixes {
                    3 => velocity.twist.twist.linear.x = f64::NAN,
                    5 => velocity.header.frame_id = "base_link".to_owned(),
                    _ => paired += 1,
                }
                if fixes % 2 == 0 {
                    out.extend(adapter.on_velocity(&velocity));
                    out.extend(adapter.on_fix(&fix));
                } else {
                    out.extend(adapter.on_fix(&fix));
                    out.extend(adapter.on_velocity(&velocity));
                }
                if fixes == 7 {
                    // A velocity whose fix never comes, and one repeated after its fix.
                    let mut late = velocity.clone();
                    late.header.stamp = seconds_to_time(f.t_s + 0.5).unwrap();
                    out.extend(adapter.on_velocity(&velocity));
                    out.extend(adapter.on_velocity(&late));
                }
            }
            _ => {}
        }
    });
    let c = adapter.counts();
    assert!(fixes > 25, "{fixes} fixes");
    assert_eq!(c.stream(Input::Velocity).received, fixes as u64 + 2);
    assert_eq!(c.velocity_paired, paired);
    assert_eq!(c.stream(Input::Velocity).unconvertible, 1, "NaN");
    assert_eq!(c.stream(Input::Velocity).foreign_frame, 1);
    assert_eq!(adapter.unpaired_velocities(), 2, "repeated and fix-less");
    assert_eq!(
        diagnostic(&adapter, "unpaired_velocity").as_deref(),
        Some("2")
    );
    assert_eq!(
        diagnostic(&adapter, "velocity_paired"),
        Some(paired.to_string())
    );
    let counters = adapter.engine().counters();
    for reason in [
        RejectionReason::MeasurementDuplicate,
        RejectionReason::FixNotFinite,
        RejectionReason::MeasurementTooOld,
    ] {
        assert_eq!(counters.count(reason), 0, "{reason:?}");
    }
    assert_eq!(adapter.engine().init_phase(), None, "running");
    // Every Odometry comes with its TF: same stamp, frames, translation and rotation.
    let mut tf_count = 0;
    for m in &out {
        if let Some(SolutionMessages {
            odometry: o,
            tf: Some(tf),
            ..
        }) = messages(m)
        {
            tf_count += 1;
            let t = &tf.transforms[0];
            assert_eq!(t.header, o.header);
            assert_eq!(
                (t.header.frame_id.as_str(), t.child_frame_id.as_str()),
                ("map", "imu_link")
            );
            let p = &o.pose.pose.position;
            let tr = &t.transform.translation;
            assert_eq!([tr.x, tr.y, tr.z], [p.x, p.y, p.z]);
            assert_eq!(t.transform.rotation, o.pose.pose.orientation);
        }
    }
    let odometry = out
        .iter()
        .filter(|m| matches!(m, Published::Solution(_)))
        .count();
    assert!(
        odometry > 2000 && tf_count == odometry,
        "{tf_count} TF, {odometry} odometry"
    );
}

#[test]
fn a_paired_velocity_reaches_the_filter() {
    use crate::sim::SimEvent;
    // The receiver at rest claims 1 m/s east with σ 0.05 m/s: the filter must follow it.
    let speed_after = |bias_mps: f64| {
        let mut adapter = loose_adapter(OutputFrames::default());
        let mut last = None;
        for_each_static_event_30_s(|event, stamp| {
            let out = match event {
                SimEvent::Imu(s) => adapter.on_imu(&outbound::imu(&s, stamp, "imu")),
                SimEvent::Fix(mut f) => {
                    let mut out = adapter.on_fix(&outbound::receiver_fix(&f, stamp, "gnss"));
                    f.velocity_enu_mps = Some(nalgebra::Vector3::new(bias_mps, 0.0, 0.0));
                    f.velocity_covariance_enu_m2_s2 = Some(Matrix3::identity() * 0.05f64.powi(2));
                    out.extend(adapter.on_velocity(&velocity_of(&f, "map")));
                    out
                }
                _ => Vec::new(),
            };
            for m in out {
                if let Some(s) = messages(&m) {
                    let v = &s.odometry.twist.twist.linear;
                    last = Some(nalgebra::Vector3::new(v.x, v.y, v.z).norm());
                }
            }
        });
        assert!(adapter.counts().velocity_paired > 25);
        last.unwrap()
    };
    let honest = speed_after(0.0);
    let biased = speed_after(1.0);
    eprintln!("speed after 30 s: {honest:.3} m/s at rest, {biased:.3} m/s with the 1 m/s claim");
    assert!(honest < 0.1, "at rest: {honest} m/s");
    assert!(biased > 0.5, "following the claimed 1 m/s: {biased} m/s");
}

/// Runs the static scenario for `until_s` through a loose adapter, the IMU in frame `imu`;
/// `before_imu` is called with each IMU sample before it is sent (to send others first).
/// The number of solutions published.
fn run_static(
    adapter: &mut RosAdapter,
    until_s: f64,
    mut before_imu: impl FnMut(&mut RosAdapter, &ImuSample),
) -> usize {
    use crate::sim::SimEvent;
    let mut solutions = 0;
    for_each_static_event(until_s, |event, stamp| {
        let out = match event {
            SimEvent::Imu(s) => {
                before_imu(adapter, &s);
                adapter.on_imu(&outbound::imu(&s, stamp, "imu"))
            }
            SimEvent::Fix(f) => adapter.on_fix(&outbound::receiver_fix(&f, stamp, "gnss")),
            _ => Vec::new(),
        };
        solutions += out
            .iter()
            .filter(|m| matches!(m, Published::Solution(_)))
            .count();
    });
    solutions
}

/// `sample` restamped at `t_s` as an Imu message of `frame_id`.
fn imu_message(sample: &ImuSample, t_s: f64, frame_id: &str) -> Imu {
    let sample = ImuSample { t_s, ..*sample };
    outbound::imu(&sample, seconds_to_time(t_s).unwrap(), frame_id)
}

fn level(adapter: &RosAdapter) -> (u8, String) {
    let d = adapter.diagnostics("/n", Time::default());
    (d.status[0].level, d.status[0].message.clone())
}

#[test]
fn stray_imu_samples_sent_first_do_not_lock_out_the_imu() {
    // Issue 12, item 10: five samples of another frame before the real IMU locked the
    // node onto that frame for good.
    let mut adapter = loose_adapter(OutputFrames::default());
    let mut strays = 0;
    let solutions = run_static(&mut adapter, 60.0, |adapter, s| {
        while strays < 5 {
            let t_s = s.t_s + 0.001 * f64::from(strays);
            adapter.on_imu(&imu_message(s, t_s, "stray"));
            strays += 1;
        }
    });
    let c = adapter.counts();
    assert_eq!(c.stream(Input::Imu).frame_switches, 1);
    assert!(
        c.stream(Input::Imu).foreign_frame > 0 && c.stream(Input::Imu).foreign_frame < 1000,
        "the real IMU waited {} samples",
        c.stream(Input::Imu).foreign_frame
    );
    assert_eq!(adapter.engine().init_phase(), None, "running");
    assert!(solutions > 2000, "{solutions} solutions");
    assert_eq!(diagnostic(&adapter, "imu_frame").as_deref(), Some("imu"));
    assert_eq!(
        diagnostic(&adapter, "frame_switches_imu").as_deref(),
        Some("1")
    );
    assert_eq!(
        level(&adapter).0,
        DiagnosticStatus::OK,
        "the conflict is over"
    );
}

#[test]
fn a_configured_imu_frame_admits_no_other_and_reports_the_conflict() {
    let mut adapter = loose_adapter(OutputFrames::default()).with_imu_frame("imu");
    let mut n = 0u64;
    let mut strays = 0;
    let solutions = run_static(&mut adapter, 30.0, |adapter, s| {
        // A stray publisher: first, and then once every ten samples.
        if n % 10 == 0 {
            adapter.on_imu(&imu_message(s, s.t_s + 0.0005, "stray"));
            strays += 1;
        }
        n += 1;
    });
    assert_eq!(adapter.counts().stream(Input::Imu).foreign_frame, strays);
    assert_eq!(adapter.counts().stream(Input::Imu).frame_switches, 0);
    assert_eq!(adapter.engine().init_phase(), None, "running");
    assert!(solutions > 2000, "{solutions} solutions");
    let (level, message) = level(&adapter);
    assert_eq!(level, DiagnosticStatus::WARN);
    assert!(
        message.contains("`stray`") && message.contains("`imu`"),
        "{message}"
    );
    // Without a configured frame the live IMU keeps its lock against the same stray.
    let mut adapter = loose_adapter(OutputFrames::default());
    n = 0;
    run_static(&mut adapter, 30.0, |adapter, s| {
        if n % 10 == 0 && n > 0 {
            adapter.on_imu(&imu_message(s, s.t_s + 0.0005, "stray"));
        }
        n += 1;
    });
    assert_eq!(adapter.counts().stream(Input::Imu).frame_switches, 0);
    assert_eq!(adapter.engine().init_phase(), None, "running");
}

#[test]
fn single_spoofed_stamps_are_dropped_and_counted_not_reset() {
    // Issue 12, item 11: one sample 1.5 s in the past, or far in the future, reset the
    // filter; one a second kept it from ever running.
    let mut adapter = loose_adapter(OutputFrames::default());
    let mut next_spoof_s = 2.0;
    let mut spoofs = 0;
    let solutions = run_static(&mut adapter, 60.0, |adapter, s| {
        if s.t_s >= next_spoof_s {
            let t_s = if spoofs % 2 == 0 {
                s.t_s - 1.5
            } else {
                s.t_s + 1e6
            };
            adapter.on_imu(&imu_message(s, t_s, "imu"));
            spoofs += 1;
            next_spoof_s += 1.0;
        }
    });
    assert!(spoofs >= 58, "{spoofs} spoofed stamps");
    assert_eq!(adapter.counts().time_jump_resets, 0);
    assert_eq!(adapter.counts().imu_stamp_outliers, spoofs);
    let counters = adapter.engine().counters();
    assert_eq!(counters.count(RejectionReason::ImuGap), 0);
    assert_eq!(counters.count(RejectionReason::ImuOutOfOrder), 0);
    assert_eq!(adapter.engine().init_phase(), None, "running");
    assert!(solutions > 4000, "{solutions} solutions");
    assert_eq!(
        diagnostic(&adapter, "imu_stamp_outliers"),
        Some(spoofs.to_string())
    );
}

#[test]
fn a_sustained_time_jump_resets_once_and_loses_no_sample() {
    let mut adapter = RosAdapter::new(Config::default(), OutputFrames::default());
    feed(&mut adapter, 100.0, 102.0);
    // Ahead by 50 s, and then back by 100 s: each run of agreeing samples is one jump.
    feed(&mut adapter, 152.0, 153.0);
    assert_eq!(
        adapter.engine().counters().count(RejectionReason::ImuGap),
        1
    );
    assert_eq!(adapter.engine().last_imu_t_s(), Some(152.99));
    feed(
        &mut adapter,
        52.0,
        52.0 + 0.01 * TIME_JUMP_CONFIRM_SAMPLES as f64,
    );
    assert_eq!(adapter.counts().time_jump_resets, 1);
    assert_eq!(adapter.counts().imu_stamp_outliers, 0);
    assert_eq!(
        adapter.engine().last_imu_t_s(),
        Some(52.0 + 0.01 * (TIME_JUMP_CONFIRM_SAMPLES - 1) as f64),
        "the held samples were fed"
    );
    // One sample short of a run: outliers.
    feed(
        &mut adapter,
        10.0,
        10.0 + 0.01 * (TIME_JUMP_CONFIRM_SAMPLES - 1) as f64,
    );
    feed(&mut adapter, 52.1, 52.2);
    assert_eq!(adapter.counts().time_jump_resets, 1);
    assert_eq!(
        adapter.counts().imu_stamp_outliers,
        TIME_JUMP_CONFIRM_SAMPLES as u64 - 1
    );
}

#[test]
fn a_flood_of_imu_samples_and_far_future_measurements_keep_the_buffers_bounded() {
    use crate::engine::standstill::MAX_WINDOW_SAMPLES;
    use crate::engine::{MAX_BUFFERED_IMU_SAMPLES, MAX_PENDING_MEASUREMENTS, STATE_EVERY_STEPS};
    use crate::sim::SimEvent;
    // Issue 12, item 12: stamps 1 µs apart, and a fix 1000 s ahead, grew memory for good.
    let mut adapter = loose_adapter(OutputFrames::default());
    let mut last = None;
    let mut fix = None;
    for_each_static_event_30_s(|event, stamp| match event {
        SimEvent::Imu(s) => {
            adapter.on_imu(&outbound::imu(&s, stamp, "imu"));
            last = Some(s);
        }
        SimEvent::Fix(f) => {
            adapter.on_fix(&outbound::receiver_fix(&f, stamp, "gnss"));
            fix = Some(f);
        }
        _ => {}
    });
    assert_eq!(adapter.engine().init_phase(), None, "running");
    let (last, mut fix) = (last.unwrap(), fix.unwrap());
    let t0_s = last.t_s;
    let mut most = adapter.engine().buffered();
    for k in 1..=100_000u32 {
        let t_s = t0_s + 1e-6 * f64::from(k);
        adapter.on_imu(&imu_message(&last, t_s, "imu"));
        if k % 1000 == 0 {
            // A fix stamped 1000 s ahead: rejected, never queued.
            fix.t_s = t_s + 1000.0;
            let stamp = seconds_to_time(fix.t_s).unwrap();
            adapter.on_fix(&outbound::receiver_fix(&fix, stamp, "gnss"));
            let b = adapter.engine().buffered();
            most.imu_samples = most.imu_samples.max(b.imu_samples);
            most.steps = most.steps.max(b.steps);
            most.states = most.states.max(b.states);
            most.measurements = most.measurements.max(b.measurements);
            most.standstill_samples = most.standstill_samples.max(b.standstill_samples);
        }
    }
    assert_eq!(
        adapter.engine().last_imu_t_s(),
        Some(t0_s + 1e-6 * 100_000.0)
    );
    assert_eq!(adapter.engine().init_phase(), None, "still running");
    assert_eq!(most.imu_samples, MAX_BUFFERED_IMU_SAMPLES);
    assert_eq!(most.steps, MAX_BUFFERED_IMU_SAMPLES);
    assert_eq!(most.states, MAX_BUFFERED_IMU_SAMPLES / STATE_EVERY_STEPS);
    assert!(most.measurements <= 1, "{most:?}");
    assert_eq!(most.standstill_samples, MAX_WINDOW_SAMPLES);
    let counters = adapter.engine().counters();
    assert_eq!(counters.count(RejectionReason::MeasurementTooNew), 100);
    assert_eq!(
        diagnostic(&adapter, "rejected_measurement_too_new").as_deref(),
        Some("100")
    );
    // Without any IMU, measurements wait; the queue keeps the newest.
    let mut adapter = loose_adapter(OutputFrames::default());
    for k in 0..3 * MAX_PENDING_MEASUREMENTS {
        fix.t_s = 10.0 + k as f64;
        let stamp = seconds_to_time(fix.t_s).unwrap();
        adapter.on_fix(&outbound::receiver_fix(&fix, stamp, "gnss"));
    }
    assert_eq!(
        adapter.engine().buffered().measurements,
        MAX_PENDING_MEASUREMENTS
    );
    assert_eq!(
        adapter
            .engine()
            .counters()
            .count(RejectionReason::MeasurementQueueFull),
        2 * MAX_PENDING_MEASUREMENTS as u64
    );
}

/// A bag played in a loop: the time jumps back at each pass and the filter resets. The
/// standstill detector's window kept the old pass's samples in front and grew by every
/// sample of the next (a node looping a bag grew by 56 B a sample, 1 MiB/s at 20 kHz);
/// now every buffer holds after the third pass what it held after the first.
#[test]
fn a_bag_played_in_a_loop_keeps_the_buffers_bounded() {
    use crate::sim::SimEvent;
    let mut adapter = loose_adapter(OutputFrames::default());
    let mut after_pass = Vec::new();
    for _ in 0..3 {
        for_each_static_event_30_s(|event, stamp| match event {
            SimEvent::Imu(s) => {
                adapter.on_imu(&outbound::imu(&s, stamp, "imu"));
            }
            SimEvent::Fix(f) => {
                adapter.on_fix(&outbound::receiver_fix(&f, stamp, "gnss"));
            }
            _ => {}
        });
        after_pass.push(adapter.engine().buffered());
    }
    assert_eq!(adapter.counts().time_jump_resets, 2);
    // A 1 s window and the 2 s of `engine.imu_buffer_s` before it, of a 100 Hz IMU.
    assert!(after_pass[0].standstill_samples <= 301, "{after_pass:?}");
    assert_eq!(after_pass[2], after_pass[0], "{after_pass:?}");
}

/// `stamp` moved `sec` seconds and `nanosec` nanoseconds later (`nanosec` below what
/// keeps the nanoseconds of the simulator's stamps, multiples of 10 ms, under a second).
fn later(stamp: Time, sec: i32, nanosec: u32) -> Time {
    Time {
        sec: stamp.sec + sec,
        nanosec: stamp.nanosec + nanosec,
    }
}

#[test]
fn outputs_carry_their_inputs_stamps_to_the_nanosecond() {
    use crate::sim::SimEvent;
    use std::collections::HashSet;
    // Stamps of this decade, where f64 seconds resolve 238 ns: IMU samples at x.0025 s,
    // every other one a nanosecond later, fixes at x.000000001 s.
    const SEC_2025: i32 = 1_764_000_000;
    const GPS_AND_GALILEO: u16 = NavSatStatus::SERVICE_GPS | NavSatStatus::SERVICE_GALILEO;
    let frames = OutputFrames {
        publish_tf: true,
        ..OutputFrames::default()
    };
    let mut adapter = loose_adapter(frames);
    let (mut imu_stamps, mut fix_stamps) = (HashSet::new(), HashSet::new());
    let mut out = Vec::new();
    let mut k = 0;
    for_each_static_event_30_s(|event, stamp| match event {
        SimEvent::Imu(s) => {
            k += 1;
            let stamp = later(stamp, SEC_2025, 2_500_000 + k % 2);
            imu_stamps.insert(stamp);
            out.extend(adapter.on_imu(&outbound::imu(&s, stamp, "imu")));
        }
        SimEvent::Fix(f) => {
            let stamp = later(stamp, SEC_2025, 1);
            fix_stamps.insert(stamp);
            let mut fix = outbound::receiver_fix(&f, stamp, "gnss");
            fix.status.service = GPS_AND_GALILEO;
            out.extend(adapter.on_fix(&fix));
        }
        _ => {}
    });
    let (mut solutions, mut reports, mut no_fixes) = (0, 0, 0);
    for published in &out {
        match published {
            Published::Solution(s) => {
                let m = s.messages.as_deref().unwrap();
                let stamp = m.odometry.header.stamp;
                assert!(imu_stamps.contains(&stamp), "Odometry at {stamp:?}");
                assert_eq!(m.fix.header.stamp, stamp);
                // The fused fix names the receiver's constellations once an update used
                // one of its fixes.
                let service = if reports > 0 { GPS_AND_GALILEO } else { 0 };
                assert_eq!(m.fix.status.service, service);
                assert_eq!(m.fix.status.status, NavSatStatus::STATUS_FIX);
                assert_eq!(m.tf.as_ref().unwrap().transforms[0].header.stamp, stamp);
                solutions += 1;
            }
            Published::NoFix(f) => {
                // Only while initializing, at a fix's stamp.
                assert_eq!(solutions, 0, "NO_FIX after the start: {f:?}");
                assert!(
                    fix_stamps.contains(&f.header.stamp),
                    "NO_FIX at {:?}",
                    f.header
                );
                no_fixes += 1;
            }
            Published::Epoch(e) => {
                let stamp = e.noise.header.stamp;
                assert!(fix_stamps.contains(&stamp), "NoiseEstimates at {stamp:?}");
                reports += 1;
            }
        }
    }
    assert!(
        solutions > 2000 && reports > 25,
        "{solutions} solutions, {reports} reports"
    );
    assert!(no_fixes > 0, "the fixes before the start say NO_FIX");
}

#[test]
fn a_refused_solution_says_no_fix_at_its_stamp() {
    let mut adapter = loose_adapter(OutputFrames::default());
    let mut last = None;
    run_static(&mut adapter, 10.0, |_, _| {});
    // The last solution again (its IMU stamp is remembered), once with a position that is
    // not finite and once with a negative variance.
    for_each_static_event(10.0, |event, stamp| {
        if let crate::sim::SimEvent::Imu(_) = event {
            last = Some(stamp);
        }
    });
    let stamp = last.unwrap();
    let solution = adapter.engine().state().unwrap().solution();
    let mut not_finite = solution.clone();
    not_finite.nav.p.height_m = f64::NAN;
    let mut negative = solution;
    negative.covariance[(0, 0)] = -1.0;
    for bad in [not_finite, negative] {
        let published = adapter.publishable(vec![Output::Solution(Box::new(bad))]);
        let [Published::NoFix(fix)] = published.as_slice() else {
            panic!("{published:?}");
        };
        assert_eq!(fix.header.stamp, stamp);
        assert_eq!(fix.status.status, NavSatStatus::STATUS_NO_FIX);
        assert_eq!(
            fix.position_covariance_type,
            NavSatFix::COVARIANCE_TYPE_UNKNOWN
        );
        assert!(fix.latitude.is_nan());
    }
    let c = adapter.counts();
    assert_eq!((c.non_finite_outputs, c.negative_variance_outputs), (1, 1));
}

/// Issue 14: with `constraints.zupt` the static scenario's standstill is held by ZUPT and
/// ZARU updates, counted on /diagnostics (10 Hz and 1 Hz while running); without, the
/// counts stay 0.
#[test]
fn constraint_updates_are_counted_on_diagnostics() {
    use crate::sim::SimEvent;
    let counts = |zupt: &str| {
        let mut config = loose_adapter(OutputFrames::default())
            .engine()
            .config()
            .clone();
        config.set_parameter("constraints.zupt", zupt).unwrap();
        let mut adapter = RosAdapter::new(config, OutputFrames::default());
        for_each_static_event_30_s(|event, stamp| {
            match event {
                SimEvent::Imu(s) => adapter.on_imu(&outbound::imu(&s, stamp, "imu")),
                SimEvent::Fix(f) => adapter.on_fix(&outbound::receiver_fix(&f, stamp, "gnss")),
                _ => Vec::new(),
            };
        });
        assert_eq!(adapter.engine().init_phase(), None, "running");
        [
            "updates_zero_velocity",
            "updates_zero_rate",
            "updates_non_holonomic",
        ]
        .map(|key| diagnostic(&adapter, key).unwrap().parse::<u64>().unwrap())
    };
    let [zero_velocity, zero_rate, non_holonomic] = counts("true");
    // Running for most of the 30 s: hundreds of ZUPTs, a tenth as many ZARUs.
    assert!(zero_velocity > 200, "{zero_velocity}");
    assert!(
        zero_rate * 10 <= zero_velocity + 10 && zero_rate > 20,
        "{zero_rate}"
    );
    assert_eq!(non_holonomic, 0);
    assert_eq!(counts("false"), [0, 0, 0]);
}

/// A receiver that claims far less than it errs, on /diagnostics: from 20 s on the static
/// scenario's fixes scatter by up to 3 m per axis at their claimed σ. Once the fix judge
/// has declared the claim too small, `unclaimed_sigma_3d_m` holds what it found beyond
/// the claim, and the published `position_sigma_3d_m` is at least that; before, it is 0.
#[test]
fn a_misclaiming_receiver_floors_the_published_sigma_on_diagnostics() {
    use crate::sim::SimEvent;
    let mut adapter = loose_adapter(OutputFrames::default());
    let value = |adapter: &RosAdapter, key: &str| -> f64 {
        diagnostic(adapter, key).unwrap().parse().unwrap()
    };
    let mut before = None;
    for_each_static_event(60.0, |event, stamp| match event {
        SimEvent::Imu(s) => {
            adapter.on_imu(&outbound::imu(&s, stamp, "imu"));
        }
        SimEvent::Fix(mut f) => {
            if f.t_s >= 20.0 {
                let k = f.t_s;
                let off = nalgebra::Vector3::new((1.7 * k).sin(), (2.3 * k).cos(), (0.9 * k).sin());
                f.position = crate::earth::enu_to_llh(&(off * 3.0), &f.position).unwrap();
            } else if f.t_s >= 19.0 && before.is_none() {
                before = Some(value(&adapter, "unclaimed_sigma_3d_m"));
            }
            adapter.on_fix(&outbound::receiver_fix(&f, stamp, "gnss"));
        }
        _ => {}
    });
    assert_eq!(before, Some(0.0));
    let floor_m = value(&adapter, "unclaimed_sigma_3d_m");
    let sigma_m = value(&adapter, "position_sigma_3d_m");
    assert!(floor_m > 1.0, "{floor_m}");
    assert!(sigma_m >= floor_m - 1e-3, "{sigma_m} {floor_m}");
}

/// A divergence on /diagnostics: after a 3 s outage the receiver's fixes come back 500 m
/// away and stay there (the monitor cannot tell which side moved; it trusts the GNSS that
/// agrees with itself). The engine resets; until the filter runs again the level is ERROR
/// and each fix gives a NO_FIX; `divergence_resets` counts the reset, and once the filter
/// has started again from the fixes the level is OK.
#[test]
fn a_divergence_is_an_error_on_diagnostics_until_the_filter_runs_again() {
    use crate::sim::SimEvent;
    let mut adapter = loose_adapter(OutputFrames::default());
    let (mut errors, mut no_fixes_while_diverged) = (0, 0);
    for_each_static_event(60.0, |event, stamp| {
        let out = match event {
            SimEvent::Imu(s) => adapter.on_imu(&outbound::imu(&s, stamp, "imu")),
            SimEvent::Fix(_) if (30.5..33.0).contains(&event.t_s()) => Vec::new(),
            SimEvent::Fix(mut f) => {
                if f.t_s > 30.5 {
                    let east = nalgebra::Vector3::new(500.0, 0.0, 0.0);
                    f.position = crate::earth::enu_to_llh(&east, &f.position).unwrap();
                }
                adapter.on_fix(&outbound::receiver_fix(&f, stamp, "gnss"))
            }
            _ => Vec::new(),
        };
        if adapter.engine().diverged_at_t_s().is_some() {
            assert_eq!(level(&adapter).0, DiagnosticStatus::ERROR);
            errors += 1;
            no_fixes_while_diverged += out
                .iter()
                .filter(|m| matches!(m, Published::NoFix(_)))
                .count();
        }
    });
    assert_eq!(adapter.engine().divergence_resets(), 1);
    assert_eq!(
        diagnostic(&adapter, "divergence_resets").as_deref(),
        Some("1")
    );
    assert!(
        errors > 0 && no_fixes_while_diverged > 0,
        "{errors} {no_fixes_while_diverged}"
    );
    assert_eq!(adapter.engine().init_phase(), None, "running again");
    assert_eq!(
        level(&adapter).0,
        DiagnosticStatus::OK,
        "{:?}",
        level(&adapter)
    );
}

/// Fixes that leap 60 m up without the IMU's support (no outage before, the filter at
/// rest): a dispute, WARN with the offset while it lasts, its message saying when the
/// fixes are held back by the leap (loosely coupled, out of steady fixes), and no reset;
/// OK again once the fixes are back.
#[test]
fn a_gnss_leap_is_a_warning_on_diagnostics_while_disputed() {
    use crate::sim::SimEvent;
    let mut adapter = loose_adapter(OutputFrames::default());
    let leap = 30.5..40.0;
    let (mut warnings, mut held) = (0, 0);
    for_each_static_event(60.0, |event, stamp| {
        match event {
            SimEvent::Imu(s) => {
                adapter.on_imu(&outbound::imu(&s, stamp, "imu"));
            }
            SimEvent::Fix(mut f) => {
                if leap.contains(&f.t_s) {
                    let up = nalgebra::Vector3::new(0.0, 0.0, 60.0);
                    f.position = crate::earth::enu_to_llh(&up, &f.position).unwrap();
                }
                adapter.on_fix(&outbound::receiver_fix(&f, stamp, "gnss"));
            }
            _ => {}
        }
        if adapter.engine().gnss_dispute_offset_enu_m().is_some() {
            let (level, message) = level(&adapter);
            assert_eq!(level, DiagnosticStatus::WARN, "{message}");
            let dispute_m: f64 = diagnostic(&adapter, "gnss_dispute_m")
                .unwrap()
                .parse()
                .unwrap();
            assert!((40.0..70.0).contains(&dispute_m), "{dispute_m} m");
            let says_held = message.contains("held back") || message.contains("left out");
            assert_eq!(
                says_held,
                adapter.engine().fix_hold().is_some(),
                "{message}"
            );
            held += usize::from(says_held);
            warnings += 1;
        }
    });
    assert!(warnings > 0, "no dispute");
    assert!(held > 0, "the leap out of steady fixes was not held back");
    assert_eq!(adapter.engine().divergence_resets(), 0);
    assert_eq!(
        diagnostic(&adapter, "gnss_dispute_m").as_deref(),
        Some("none")
    );
    assert_eq!(
        level(&adapter).0,
        DiagnosticStatus::OK,
        "{:?}",
        level(&adapter)
    );
}

/// Issue 15: with `gnss.tdcp` the phase changes used and left out show on /diagnostics;
/// a satellite whose half cycle is never resolved is counted under its reason every
/// epoch, and without `gnss.tdcp` there are no such keys.
#[test]
fn carrier_phase_changes_used_and_left_out_are_counted_on_diagnostics() {
    use crate::ros::msg::SatelliteMeasurement;
    use crate::sim::SimEvent;
    let run = |tdcp: bool| {
        let mut config = Config::default();
        config
            .set_parameter("gnss.tdcp", if tdcp { "true" } else { "false" })
            .unwrap();
        // At rest the heading is not observable: the static scenario's is given.
        config.set_parameter("init.heading_deg", "0.0").unwrap();
        let mut adapter = RosAdapter::new(config, OutputFrames::default());
        let mut epochs = 0u64;
        for_each_static_event_30_s(|event, stamp| {
            match event {
                SimEvent::Imu(s) => adapter.on_imu(&outbound::imu(&s, stamp, "imu")),
                SimEvent::Gnss { epoch, .. } => {
                    let mut msg = outbound::gnss_measurements(&epoch, 0, stamp, "gnss");
                    if let Some(first) = msg.satellites.first_mut() {
                        first.carrier_phase_flags |=
                            SatelliteMeasurement::CARRIER_HALF_CYCLE_UNRESOLVED;
                    }
                    epochs += 1;
                    adapter.on_gnss(&msg)
                }
                _ => Vec::new(),
            };
        });
        assert_eq!(adapter.engine().init_phase(), None, "running");
        (adapter, epochs)
    };
    let (adapter, epochs) = run(true);
    let count = |key: &str| {
        diagnostic(&adapter, key)
            .unwrap_or_else(|| panic!("no {key}"))
            .parse::<u64>()
            .unwrap()
    };
    let used = count("tdcp_phases_used");
    let half_cycle = count("tdcp_rejected_half_cycle_unresolved");
    assert!(
        used > 5 * half_cycle,
        "used {used}, half cycle {half_cycle}"
    );
    assert!(
        half_cycle > epochs / 2 && half_cycle <= epochs,
        "half cycle {half_cycle} of {epochs} epochs"
    );
    assert_eq!(adapter.phase_counts().used, used);
    let (adapter, _) = run(false);
    assert_eq!(diagnostic(&adapter, "tdcp_phases_used"), None);
}

/// Issue 11, item 3: a satellite whose pseudo-range carries a constant 8 m bias (a
/// facade's reflection) from 20 s on is judged correlated and its variance inflated,
/// counted as `correlated_measurements` on /diagnostics; without `gnss.error_correlation`
/// nothing is. (Not only that satellite: the fit of the common errors spreads its bias
/// into the others' parity residuals, where it is constant too; measured 234 inflations
/// over the 40 biased epochs.)
#[test]
fn correlated_errors_are_counted_on_diagnostics() {
    use crate::sim::SimEvent;
    let run = |judge: bool| {
        let mut config = Config::default();
        config
            .set_parameter(
                "gnss.error_correlation",
                if judge { "true" } else { "false" },
            )
            .unwrap();
        // At rest the heading is not observable: the static scenario's is given.
        config.set_parameter("init.heading_deg", "0.0").unwrap();
        let mut adapter = RosAdapter::new(config, OutputFrames::default());
        for_each_static_event(60.0, |event, stamp| {
            match event {
                SimEvent::Imu(s) => adapter.on_imu(&outbound::imu(&s, stamp, "imu")),
                SimEvent::Gnss { epoch, .. } => {
                    let mut msg = outbound::gnss_measurements(&epoch, 0, stamp, "gnss");
                    if epoch.t_s >= 20.0 {
                        if let Some(reflected) = msg.satellites.first_mut() {
                            reflected.pseudorange_m += 8.0;
                        }
                    }
                    adapter.on_gnss(&msg)
                }
                _ => Vec::new(),
            };
        });
        assert_eq!(adapter.engine().init_phase(), None, "running");
        diagnostic(&adapter, "correlated_measurements")
            .expect("a correlated_measurements key")
            .parse::<u64>()
            .unwrap()
    };
    let judged = run(true);
    assert!(judged >= 30, "{judged} inflated");
    assert_eq!(run(false), 0);
}

/// Issue 14, item 3: wheel odometry on /diagnostics. With `wheel_odometry.enabled`, the
/// static scenario's standstill is reported by a base controller at the truth's rate:
/// every message is counted as received; one with a NaN speed or a negative variance as
/// unconvertible, one from a second child frame as foreign; the speeds before the filter
/// runs are rejected as such, the others reach the filter.
#[test]
fn wheel_odometry_is_counted_on_diagnostics() {
    use crate::ros::msg::Odometry;
    use crate::sim::SimEvent;
    let mut config = loose_adapter(OutputFrames::default())
        .engine()
        .config()
        .clone();
    config
        .set_parameter("wheel_odometry.enabled", "true")
        .unwrap();
    let mut adapter = RosAdapter::new(config, OutputFrames::default());
    let odometry = |stamp: Time, child_frame_id: &str, speed_mps: f64, variance: f64| {
        let mut msg = Odometry::default();
        msg.header.stamp = stamp;
        msg.header.frame_id = "odom".to_owned();
        msg.child_frame_id = child_frame_id.to_owned();
        msg.twist.twist.linear.x = speed_mps;
        msg.twist.covariance[0] = variance;
        msg
    };
    let mut sent = 0;
    for_each_static_event_30_s(|event, stamp| match event {
        SimEvent::Imu(s) => {
            adapter.on_imu(&outbound::imu(&s, stamp, "imu"));
        }
        SimEvent::Fix(f) => {
            adapter.on_fix(&outbound::receiver_fix(&f, stamp, "gnss"));
        }
        SimEvent::Truth(_) => {
            adapter.on_wheel_odometry(&odometry(stamp, "base_link", 0.0, 1e-4));
            sent += 1;
        }
        _ => {}
    });
    let late = seconds_to_time(29.995).unwrap();
    for msg in [
        odometry(late, "base_link", f64::NAN, 1e-4),
        odometry(late, "base_link", 0.0, -1e-4),
        odometry(late, "wheels_of_another_robot", 0.0, 1e-4),
    ] {
        adapter.on_message(&InputMessage::WheelOdometry(Box::new(msg)));
    }
    assert_eq!(adapter.engine().init_phase(), None, "running");
    let count = |key: &str| diagnostic(&adapter, key).unwrap().parse::<u64>().unwrap();
    assert!(sent > 200, "{sent}");
    assert_eq!(count("wheel_odometry_received"), sent + 3);
    assert_eq!(count("unconvertible_wheel_odometry"), 2);
    assert_eq!(count("foreign_frame_wheel_odometry"), 1);
    let before_start = count("rejected_wheel_speed_before_start");
    assert!(before_start > 0 && before_start < sent, "{before_start}");
    let counters = adapter.engine().counters();
    assert_eq!(counters.count(RejectionReason::WheelSpeedInvalid), 0);
    assert_eq!(counters.count(RejectionReason::WheelOdometryOff), 0);
}

/// Issue 14: the scale factors the filter estimates are on /diagnostics with their σ
/// (within their initial σ once running), and absent when they are not estimated.
#[test]
fn estimated_scale_factors_are_on_diagnostics() {
    let run = |estimated: bool| {
        let mut config = loose_adapter(OutputFrames::default())
            .engine()
            .config()
            .clone();
        for key in [
            "wheel_odometry.enabled",
            "wheel_odometry.scale_factor_state",
            "imu.scale_factor_states",
        ] {
            config.set_parameter(key, &estimated.to_string()).unwrap();
        }
        let mut adapter = RosAdapter::new(config, OutputFrames::default());
        run_static(&mut adapter, 30.0, |_, _| {});
        assert_eq!(adapter.engine().init_phase(), None, "running");
        adapter
    };
    let numbers = |adapter: &RosAdapter, key: &str| -> Option<Vec<f64>> {
        let value = diagnostic(adapter, key)?;
        Some(value.split(", ").map(|x| x.parse().unwrap()).collect())
    };
    let adapter = run(true);
    let factor = numbers(&adapter, "wheel_scale_factor").unwrap();
    let factor_sigma = numbers(&adapter, "wheel_scale_factor_sigma").unwrap();
    assert!((factor[0] - 1.0).abs() < 0.05, "{factor:?}");
    assert!(
        factor_sigma[0] > 0.0 && factor_sigma[0] <= 0.05,
        "{factor_sigma:?}"
    );
    for name in ["gyro", "accel"] {
        let errors = numbers(&adapter, &format!("{name}_scale_error_ppm")).unwrap();
        let sigmas = numbers(&adapter, &format!("{name}_scale_error_sigma_ppm")).unwrap();
        assert_eq!((errors.len(), sigmas.len()), (3, 3), "{name}");
        assert!(errors.iter().all(|e| e.abs() < 3000.0), "{name} {errors:?}");
        assert!(
            sigmas.iter().all(|s| *s > 0.0 && *s <= 1000.0),
            "{name} {sigmas:?}"
        );
    }
    let adapter = run(false);
    for key in [
        "wheel_scale_factor",
        "gyro_scale_error_ppm",
        "accel_scale_error_ppm",
    ] {
        assert_eq!(diagnostic(&adapter, key), None, "{key}");
    }
}

/// Issue 14, item 4: a moving-base pair's UBXNavRelPosNED on /diagnostics. The static
/// scenario's receiver stands facing north with no configured heading: with
/// `dual_antenna.enabled` and a pair reporting north at each fix, the filter starts (it
/// cannot without: no course at rest). Each message is counted as received; one without a
/// carrier solution or not in moving-base mode as unconvertible, one from a second pair as
/// foreign, a float solution as rejected.
#[test]
fn a_dual_antenna_heading_starts_a_receiver_at_rest_and_is_counted() {
    use crate::engine::{BaselineHeadingReading, CarrierSolution};
    use crate::ros::msg::CarrSoln;
    use crate::ros::rel_pos_ned::message_of_reading;
    use crate::sim::SimEvent;
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/params/ekf_loose.yaml");
    let text = std::fs::read_to_string(path).unwrap();
    let mut config = Config::from_yaml_str(&text, path).unwrap();
    let mut without = RosAdapter::new(config.clone(), OutputFrames::default());
    config
        .set_parameter("dual_antenna.enabled", "true")
        .unwrap();
    let mut adapter = RosAdapter::new(config, OutputFrames::default());
    let north = |t_s: f64, carrier| BaselineHeadingReading {
        t_s,
        heading_rad: 0.0,
        sigma_rad: 0.3f64.to_radians(),
        length_m: 1.0,
        carrier,
    };
    let mut sent = 0;
    for_each_static_event_30_s(|event, stamp| {
        if let SimEvent::Imu(s) = &event {
            adapter.on_imu(&outbound::imu(s, stamp, "imu"));
            without.on_imu(&outbound::imu(s, stamp, "imu"));
        }
        if let SimEvent::Fix(f) = &event {
            let msg = message_of_reading(&north(f.t_s, CarrierSolution::Fixed), stamp, "pair");
            adapter.on_rel_pos_ned(&msg);
            adapter.on_fix(&outbound::receiver_fix(f, stamp, "gnss"));
            without.on_rel_pos_ned(&msg);
            without.on_fix(&outbound::receiver_fix(f, stamp, "gnss"));
            sent += 1;
        }
    });
    let late = seconds_to_time(29.995).unwrap();
    let mut no_carrier = message_of_reading(&north(29.995, CarrierSolution::Fixed), late, "pair");
    no_carrier.carr_soln.status = CarrSoln::NO_CARRIER_RANGE_SOLUTION;
    let mut static_base = no_carrier.clone();
    static_base.carr_soln.status = CarrSoln::PHASE_WITH_FIXED_AMBIGUITIES;
    static_base.is_moving = false;
    let float = message_of_reading(&north(29.995, CarrierSolution::Float), late, "pair");
    let foreign = message_of_reading(&north(29.995, CarrierSolution::Fixed), late, "other_pair");
    for msg in [no_carrier, static_base, float, foreign] {
        adapter.on_message(&InputMessage::RelPosNed(Box::new(msg)));
    }
    assert_eq!(adapter.engine().init_phase(), None, "running");
    assert_eq!(
        without.engine().init_phase(),
        Some(crate::engine::InitPhase::WaitingForHeading)
    );
    let count = |key: &str| diagnostic(&adapter, key).unwrap().parse::<u64>().unwrap();
    assert!(sent > 20, "{sent}");
    assert_eq!(count("rel_pos_ned_received"), sent + 4);
    assert_eq!(count("unconvertible_rel_pos_ned"), 2);
    assert_eq!(count("foreign_frame_rel_pos_ned"), 1);
    assert_eq!(count("rejected_baseline_heading_float"), 1);
    let counters = adapter.engine().counters();
    assert_eq!(counters.count(RejectionReason::BaselineHeadingGated), 0);
    assert_eq!(counters.count(RejectionReason::BaselineHeadingInvalid), 0);
}
