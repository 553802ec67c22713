//! The real recording walk_0827 (../shared/data/walk_0827) converted in-process by the
//! `gnss_ins convert` code and run through the tightly-coupled EKF on the path of
//! `gnss_ins replay` and `compare` (the ROS adapter), against the receiver's RTK solution
//! (its fixed epochs).

mod walk_0827_support;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use adaptive_gnss_ins::config::Config;
use adaptive_gnss_ins::eval::ErrorSummary;
use adaptive_gnss_ins::eval::TruthSample;
use adaptive_gnss_ins::gnss::ionosphere::IonosphereMode;
use adaptive_gnss_ins::gnss::time_scale::DEFAULT_GPS_UTC_LEAP_S;
use adaptive_gnss_ins::ins::ImuSample;
use adaptive_gnss_ins::ros::adapter::{Input, InputMessage};
use adaptive_gnss_ins::ros::bag::BagReader;
use adaptive_gnss_ins::tools::bag_inputs::{BagInput, BagInputs, BagTopics};
use adaptive_gnss_ins::tools::convert::{
    convert, ConvertOptions, EphemerisMode, GnssSource, ImuInput, ImuTime, TruthInput,
};
use adaptive_gnss_ins::tools::imu_csv::{AccelUnit, GyroUnit, ImuCsvFormat};
use adaptive_gnss_ins::tools::replay::{replay, ReplayOptions, TruthSource};
use adaptive_gnss_ins::tools::scoring::Reference;
use adaptive_gnss_ins::tools::session::SessionInput;
use adaptive_gnss_ins::tools::simulate::TRUTH_TOPIC;
use adaptive_gnss_ins::tools::spp_run::{bag_spp_inputs, run_spp};

/// The data set README: NAV-PVT height − hMSL.
const GEOID_SEPARATION_M: f64 = -21.387;

/// The IMU axes in the FLU body: x left, y backward, z up, i.e. R = Rz(+90°).
///
/// The README gives the mounting as roll, pitch, yaw = 180°, 0°, −90° against a
/// forward-right-down body without the convention. Found from the data
/// (`imu_axes_are_confirmed_by_gravity_turns_and_travel` checks it on every run):
/// - at rest the accelerometers read +1.01 g on z: z is up for a specific force;
/// - the z gyro turns with the reference's course, counter-clockwise positive: z is up
///   in a right-handed frame (so the accelerometers do report specific force);
/// - in turns the centripetal acceleration (speed × yaw rate, towards the inside) shows
///   on IMU x with a positive sign: x points left, so y points backward.
///
/// That is the README's angles composed R_imu→FRD = Rz(−90°)·Rx(180°) (yaw after roll,
/// the order of `mounting.imu_rotation_rpy_deg`); FRD → FLU (Rx(180°)) then gives
/// Rz(+90°). The other order, Rx(180°)·Rz(−90°), would put x to the right: refuted.
const IMU_TO_FLU_RPY_DEG: [f64; 3] = [0.0, 0.0, 90.0];

/// Horizontal RMSE budget of the tightly-coupled EKF (params/walk_0827.yaml) against the
/// RTK-fixed epochs (m), on the dual-frequency ionosphere-free pseudo-ranges (the
/// `convert` default). Measured 6.533 m on 291 fixed epochs when this was set (docs/walk_0827.md,
/// "Real data: walk_0827"); the budget is that plus about 7 %. (Single-frequency, with no
/// ionosphere model in this 134 s log, the EKF measured 8.905 m.)
///
/// What remains is again a bias common to every epoch: the ionosphere-free single-point
/// errors average (5.2 E, 3.7 N, −4.5 U) m with a spread of (1.7, 1.2, 5.7) m, and the
/// ionosphere-free residuals at the reference positions fit an offset of the reference
/// position of (5.4 E, 3.9 N, −0.6 U) m on average (`tests/iono_free_walk_0827.rs`); GPS
/// alone and Galileo alone both put the antenna east of the reference. Not explained
/// here (a datum offset of the reference would do it; see docs/walk_0827.md).
const TC_EKF_FIXED_HORIZONTAL_BUDGET_M: f64 = 7.0;

/// The conversion `gnss_ins convert` does with the command line of docs/walk_0827.md.
fn options() -> ConvertOptions {
    let d = walk_0827_support::dir();
    ConvertOptions {
        gnss: GnssSource::Ubx(d.join("gnss_1730.ubx")),
        imu: Some(ImuInput {
            csv: d.join("imu_1730.csv"),
            format: ImuCsvFormat::new(
                "ax,ay,az,gx,gy,gz,tick_ms",
                AccelUnit::G,
                GyroUnit::DegPerS,
                IMU_TO_FLU_RPY_DEG,
            )
            .unwrap(),
            time: ImuTime::Tag(d.join("imu_1730.csv.tag")),
        }),
        truth: TruthInput::Pos {
            path: d.join("gnss_1730_sf.pos"),
            geoid_separation_m: GEOID_SEPARATION_M,
        },
        leap_seconds: DEFAULT_GPS_UTC_LEAP_S,
        ephemeris: EphemerisMode::WholeLog,
        ionosphere: IonosphereMode::IonoFree,
    }
}

/// The converted bag, made once per test binary in Cargo's scratch folder.
fn bag() -> &'static Path {
    static BAG: OnceLock<PathBuf> = OnceLock::new();
    BAG.get_or_init(|| {
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("walk_0827_tc.mcap");
        let summary = convert(&options(), &out).unwrap_or_else(|e| {
            panic!("converting walk_0827 (../shared/data/walk_0827 beside the crate): {e}")
        });
        println!("{summary:?}");
        assert_eq!(summary.gnss_epochs, 536);
        assert_eq!(summary.imu_samples, 20_455);
        // BeiDou (B1C, B2a, B3I here) has no ionosphere-free pair: kept for its phase.
        assert!(summary.phase_only > 3000, "{summary:?}");
        assert_eq!(
            summary.truth,
            vec![("rtk_fixed".to_owned(), 349), ("rtk_float".to_owned(), 187)]
        );
        out
    })
}

/// The bag's IMU samples and reference samples.
fn imu_and_truth() -> (Vec<ImuSample>, Vec<TruthSample>) {
    let reader = BagReader::open(bag()).unwrap();
    let mut imu = Vec::new();
    let mut truth = Vec::new();
    for item in BagInputs::new(
        reader.messages().unwrap(),
        BagTopics::default(),
        &[Input::Imu],
    ) {
        match item {
            BagInput::Message(InputMessage::Imu(m)) => imu.push(ImuSample::try_from(&m).unwrap()),
            BagInput::Reference(Reference::Truth(t)) => truth.push(t),
            _ => {}
        }
    }
    (imu, truth)
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

#[test]
fn imu_axes_are_confirmed_by_gravity_turns_and_travel() {
    let (imu, truth) = imu_and_truth();
    // Gravity: the mean specific force over the first 5 s (at rest) points up.
    let t0 = imu[0].t_s;
    let rest: Vec<_> = imu.iter().filter(|s| s.t_s < t0 + 5.0).collect();
    let f = rest
        .iter()
        .map(|s| s.f_ib_b_m_s2)
        .sum::<nalgebra::Vector3<f64>>()
        / rest.len() as f64;
    println!("mean specific force at rest (FLU): {:?}", f.as_slice());
    assert!(f[2] > 9.6 && f[2] < 10.1, "{f:?}");
    assert!(f[0].hypot(f[1]) < 0.5, "{f:?}");
    // Turns: at each reference sample while walking, the IMU averaged over ±0.125 s
    // against the reference's course rate (counter-clockwise) and centripetal acceleration.
    let (mut gyro_z, mut course_rate, mut f_left, mut f_fwd, mut centripetal) =
        (vec![], vec![], vec![], vec![], vec![]);
    for w in truth.windows(3) {
        let (a, b, c) = (&w[0], &w[1], &w[2]);
        let (Some(va), Some(vb), Some(vc)) = (a.v_n, b.v_n, c.v_n) else {
            continue;
        };
        let speed = vb[0].hypot(vb[1]);
        if speed < 0.5 || va[0].hypot(va[1]) < 0.5 || vc[0].hypot(vc[1]) < 0.5 {
            continue;
        }
        let course = |v: &nalgebra::Vector3<f64>| v[1].atan2(v[0]);
        let mut d = course(&vc) - course(&va);
        d = (d + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
            - std::f64::consts::PI;
        let rate = d / (c.t_s - a.t_s);
        let near: Vec<_> = imu
            .iter()
            .filter(|s| (s.t_s - b.t_s).abs() <= 0.125)
            .collect();
        if near.is_empty() {
            continue;
        }
        let n = near.len() as f64;
        let mean_w = near
            .iter()
            .map(|s| s.w_ib_b_rad_s)
            .sum::<nalgebra::Vector3<f64>>()
            / n;
        let mean_f = near
            .iter()
            .map(|s| s.f_ib_b_m_s2)
            .sum::<nalgebra::Vector3<f64>>()
            / n;
        gyro_z.push(mean_w[2]);
        course_rate.push(rate);
        f_left.push(mean_f[1]);
        f_fwd.push(mean_f[0]);
        centripetal.push(speed * rate);
    }
    let yaw = correlation(&gyro_z, &course_rate);
    let left = correlation(&f_left, &centripetal);
    let forward = correlation(&f_fwd, &centripetal);
    println!(
        "{} walking samples: corr(gyro z, course rate) {yaw:.3}, corr(f left, v·rate) \
         {left:.3}, corr(f forward, v·rate) {forward:.3}",
        gyro_z.len()
    );
    assert!(gyro_z.len() > 300);
    assert!(yaw > 0.6, "z gyro against the course rate: {yaw}");
    assert!(
        left > 0.5,
        "left axis against the centripetal acceleration: {left}"
    );
    assert!(
        forward.abs() < 0.3,
        "forward axis against the centripetal: {forward}"
    );
}

fn config() -> Config {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("params/walk_0827.yaml");
    let text = std::fs::read_to_string(&path).unwrap();
    Config::from_yaml_str(&text, "walk_0827.yaml").unwrap()
}

fn summary(by: &std::collections::BTreeMap<String, ErrorSummary>, key: &str) -> ErrorSummary {
    *by.get(key)
        .unwrap_or_else(|| panic!("no {key} epochs scored: {:?}", by.keys()))
}

#[test]
fn tightly_coupled_ekf_stays_within_budget() {
    let config = config();
    let truth = TruthSource::Topic(TRUTH_TOPIC.to_owned());
    let run = replay(bag(), &config, truth, &ReplayOptions::default(), |_| {}).unwrap();
    let report = &run.report;
    let by = report.summary_by_environment(f64::NEG_INFINITY);
    let fixed = summary(&by, "rtk_fixed");
    let first_scored_t_s = report
        .errors
        .iter()
        .map(|(_, e)| e.t_s)
        .fold(f64::INFINITY, f64::min);
    // Our single-point solution on the same measurements and the same epochs (those
    // after the filter started), with one receiver clock as the filter.
    let spp = run_spp(
        bag_spp_inputs(bag(), Some(TRUTH_TOPIC.to_owned()))
            .unwrap()
            .filter(|i| match i {
                SessionInput::Gnss(e) => e.t_s >= first_scored_t_s,
                _ => true,
            }),
        &config,
    );
    let spp_fixed = summary(&spp.summary_by_label(), "rtk_fixed");
    println!(
        "EKF on {} fixed epochs: horizontal {:.3} m, vertical {:.3} m; SPP on {}: \
         horizontal {:.3} m, vertical {:.3} m; rejected inputs {}",
        fixed.epochs,
        fixed.pos_rmse_horizontal_m,
        fixed.pos_rmse_u_m,
        spp_fixed.epochs,
        spp_fixed.pos_rmse_horizontal_m,
        spp_fixed.pos_rmse_u_m,
        run.rejections.total()
    );
    assert!(fixed.epochs > 250, "{} fixed epochs scored", fixed.epochs);
    assert!(
        spp_fixed.epochs > 250,
        "{} SPP epochs scored",
        spp_fixed.epochs
    );
    assert!(
        fixed.pos_rmse_horizontal_m < TC_EKF_FIXED_HORIZONTAL_BUDGET_M,
        "horizontal RMSE {} m over the budget {} m",
        fixed.pos_rmse_horizontal_m,
        TC_EKF_FIXED_HORIZONTAL_BUDGET_M
    );
    // The filter beats our single-point solution on the same measurements and epochs.
    assert!(
        fixed.pos_rmse_horizontal_m < spp_fixed.pos_rmse_horizontal_m,
        "EKF {} m, single point {} m",
        fixed.pos_rmse_horizontal_m,
        spp_fixed.pos_rmse_horizontal_m
    );
}

/// Time-differenced carrier phase (issue 15) on the walk: the horizontal RMSE over the
/// fixed epochs after removing the mean offset (the reference's datum, see
/// docs/walk_0827.md), which is what a filter can change.
///
/// Measured at this commit: 0.637 m without and 0.451 m with the phase changes (the
/// single-frequency BeiDou satellites give theirs too; the start combines the rest's
/// single-point solutions). The bounds hold the measured gain (with below 0.85 times
/// without; measured 0.71) and the figure, 0.5 m with TDCP.
#[test]
fn carrier_phase_changes_tighten_the_walk() {
    let horizontal_demeaned_m = |tdcp: bool| {
        let mut config = config();
        config.gnss.tdcp = tdcp;
        let truth = TruthSource::Topic(TRUTH_TOPIC.to_owned());
        let run = replay(bag(), &config, truth, &ReplayOptions::default(), |_| {}).unwrap();
        let by = run.report.summary_by_environment(f64::NEG_INFINITY);
        let fixed = summary(&by, "rtk_fixed");
        assert!(fixed.epochs > 250, "{} fixed epochs scored", fixed.epochs);
        fixed.pos_rmse_horizontal_offset_removed_m
    };
    let (without, with) = (horizontal_demeaned_m(false), horizontal_demeaned_m(true));
    println!("fixed epochs, offset removed: {without:.3} m without TDCP, {with:.3} m with");
    assert!(
        with < 0.85 * without,
        "{with} m with TDCP, {without} m without"
    );
    assert!(with <= 0.5, "{with} m with TDCP");
}
