//! The dual-frequency ionosphere-free pseudo-ranges built from the real walk_0827 log
//! (u-blox RAWX: GPS L1 C/A + L2C, Galileo E1 + E5a), checked against the raw
//! measurements, the ICD group-delay relations and the receiver's RTK solution.

mod walk_0827_support;

use adaptive_gnss_ins::earth::{llh_to_ecef, rot_ecef_to_enu, Llh};
use adaptive_gnss_ins::gnss::ephemeris::{iono_free_coefficients, GroupDelay, RangingCode, Signal};
use adaptive_gnss_ins::gnss::ionosphere::IonosphereMode;
use adaptive_gnss_ins::gnss::spp::{solve_spp, SppConfig};
use adaptive_gnss_ins::gnss::ubx::{
    build_epoch_with, read_ubx_log, sat_id, signal, NavPvt, UbxLog,
};
use nalgebra::Vector3;

fn log() -> UbxLog {
    read_ubx_log(&walk_0827_support::read("gnss_1730.ubx"))
}

#[test]
fn iono_free_epochs_combine_two_signals_with_their_group_delays() {
    let log = log();
    let (mut checked, mut gps, mut galileo, mut single, mut phase_only) = (0, 0, 0, 0, 0);
    for raw in &log.rawx {
        let free = build_epoch_with(raw, &log.store, None, IonosphereMode::IonoFree);
        let one = build_epoch_with(raw, &log.store, None, IonosphereMode::Broadcast);
        single += free.stats.single_frequency;
        for (obs, code) in free.epoch.satellites.iter().zip(&free.signals) {
            let RangingCode::IonoFree { first, second } = *code else {
                // A single signal beside the pairs: its phase and rate only, never its
                // range (the ionosphere would come back with it as a bias).
                let k = one.epoch.satellites.iter().position(|s| s.sat == obs.sat);
                let single_frequency = &one.epoch.satellites[k.unwrap()];
                assert_eq!(one.signals[k.unwrap()], *code, "{}", obs.sat);
                assert_eq!((obs.pseudorange_m, obs.pseudorange_sigma_m), (None, None));
                assert!(obs.carrier_phase.is_some(), "{}", obs.sat);
                assert_eq!(obs.carrier_phase, single_frequency.carrier_phase);
                assert_eq!(
                    obs.pseudorange_rate_mps,
                    single_frequency.pseudorange_rate_mps
                );
                assert_eq!(obs.sat_pos_ecef_m, single_frequency.sat_pos_ecef_m);
                phase_only += 1;
                continue;
            };
            // The engine must add no ionosphere model on top.
            assert_eq!(obs.iono_delay_m, Some(0.0));
            // The range: a₁ P₁ + a₂ P₂ of the two raw measurements.
            let raw_of = |s: Signal| {
                raw.measurements
                    .iter()
                    .find(|m| {
                        sat_id(m.gnss_id, m.sv_id) == Some(obs.sat)
                            && signal(m.gnss_id, m.sig_id) == Some(s)
                    })
                    .unwrap()
            };
            let (m1, m2) = (raw_of(first), raw_of(second));
            let (a1, a2) =
                iono_free_coefficients(first.carrier_frequency_hz(), second.carrier_frequency_hz())
                    .unwrap();
            let combined_m = a1 * m1.pseudorange_m + a2 * m2.pseudorange_m;
            assert!((obs.pseudorange_m.unwrap() - combined_m).abs() < 1e-6);
            let sigma = (a1 * m1.pseudorange_sigma_m).hypot(a2 * m2.pseudorange_sigma_m);
            assert!((obs.pseudorange_sigma_m.unwrap() - sigma).abs() < 1e-12);
            // The rate: the first signal's Doppler.
            let rate = -first.wavelength_m() * m1.doppler_hz;
            assert!((obs.pseudorange_rate_mps.unwrap() - rate).abs() < 1e-9);
            // Satellite clock against the single-frequency one of the same satellite: the
            // difference (Δt − T(first)) − (Δt − T(IF)) = T(IF) − T(first), which the ICDs
            // fix as −T_GD for GPS L1/L2 (the LNAV clock is that pair's) and −BGD(E1,E5a) for
            // Galileo E1/E5a on the I/NAV clock (E1: BGD(E1,E5b); E1/E5a: BGD(E1,E5b) −
            // BGD(E1,E5a)).
            let Some(k) = one.epoch.satellites.iter().position(|s| s.sat == obs.sat) else {
                continue;
            };
            assert_eq!(one.signals[k], RangingCode::Single(first));
            let eph = log.store.select(obs.sat, &free.receive_time).unwrap();
            let expected_s = match (eph.group_delay, first) {
                (GroupDelay::Gps { tgd_s }, Signal::GpsL1Ca) => {
                    gps += 1;
                    -tgd_s
                }
                (GroupDelay::Galileo { bgd_e1_e5a_s, .. }, Signal::GalileoE1) => {
                    assert_eq!(second, Signal::GalileoE5a);
                    galileo += 1;
                    -bgd_e1_e5a_s
                }
                other => panic!("{}: unexpected pair {other:?}", obs.sat),
            };
            // The two transmission times differ by the ionosphere (< 100 ns): the clock
            // drift (< 1e-9) makes that < 1e-16 s.
            let difference_s = one.epoch.satellites[k].sat_clock_bias_s - obs.sat_clock_bias_s;
            assert!(
                (difference_s - expected_s).abs() < 1e-12,
                "{}: {difference_s} s against {expected_s} s",
                obs.sat
            );
            checked += 1;
        }
    }
    println!(
        "{checked} satellite-epochs checked ({gps} GPS, {galileo} Galileo); {single} \
         single-frequency, {phase_only} of them kept for their phase"
    );
    assert!(gps > 1500 && galileo > 2000, "{gps} GPS, {galileo} Galileo");
    // BeiDou: the log has B1C, B2a and B3I but no B1I, and D1 gives no B1C/B2a group delay.
    assert!(single > 3000, "{single} single-frequency satellite-epochs");
    assert!(
        phase_only > 3000 && phase_only <= single,
        "{phase_only} of {single} kept for their phase"
    );
}

/// ENU error (m) of a solution against the NAV-PVT solution of the same epoch.
/// The receiver's NAV-PVT solution (the reference) of the epoch at GPS time of week `tow_s`.
fn reference_at(log: &UbxLog, tow_s: f64) -> Option<&NavPvt> {
    log.nav_pvt
        .iter()
        .find(|p| (f64::from(p.itow_ms) * 1e-3 - tow_s).abs() < 0.05)
}

fn errors(log: &UbxLog, mode: IonosphereMode) -> Vec<Vector3<f64>> {
    let mut out = Vec::new();
    for raw in &log.rawx {
        let built = build_epoch_with(raw, &log.store, log.klobuchar, mode);
        let tow = built.receive_time.tow_s;
        let Some(pvt) = reference_at(log, tow) else {
            continue;
        };
        let Ok(sol) = solve_spp(&built.epoch, &SppConfig::default()) else {
            continue;
        };
        let reference = Llh::new(pvt.lat_rad, pvt.lon_rad, pvt.height_m);
        out.push(rot_ecef_to_enu(&reference) * (sol.pos_ecef_m - llh_to_ecef(&reference)));
    }
    out
}

fn mean(v: &[Vector3<f64>]) -> Vector3<f64> {
    v.iter().sum::<Vector3<f64>>() / v.len() as f64
}

fn horizontal_rms(v: &[Vector3<f64>]) -> f64 {
    (v.iter().map(|e| e[0] * e[0] + e[1] * e[1]).sum::<f64>() / v.len() as f64).sqrt()
}

/// An uncorrected ionosphere lengthens low satellites' ranges most and lifts a
/// single-point height by several times the zenith delay; the combination removes it.
#[test]
fn iono_free_spp_removes_the_ionospheric_height_bias() {
    let log = log();
    let broadcast = errors(&log, IonosphereMode::Broadcast);
    let free = errors(&log, IonosphereMode::IonoFree);
    let (mb, mf) = (mean(&broadcast), mean(&free));
    println!(
        "single frequency: {} epochs, mean ENU error {:.2?} m, horizontal RMS {:.2} m; \
         ionosphere-free: {} epochs, mean {:.2?} m, horizontal RMS {:.2} m",
        broadcast.len(),
        mb.as_slice(),
        horizontal_rms(&broadcast),
        free.len(),
        mf.as_slice(),
        horizontal_rms(&free)
    );
    assert!(free.len() > 500 && broadcast.len() > 500);
    assert!(mb[2] > 5.0, "single-frequency height bias {} m", mb[2]);
    assert!(
        mf[2].abs() < 0.5 * mb[2],
        "ionosphere-free height bias {} m",
        mf[2]
    );
    assert!(horizontal_rms(&free) < horizontal_rms(&broadcast));
}

/// Residuals of the ionosphere-free ranges at the reference position of each epoch (the
/// NAV-PVT solution), with the elevation mask of the single point (10°).
struct ReferenceResiduals {
    /// Per epoch: (line of sight in ENU, residual m, constellation index 0 GPS / 1 Galileo).
    epochs: Vec<Vec<(Vector3<f64>, f64, usize)>>,
}

fn reference_residuals(log: &UbxLog) -> ReferenceResiduals {
    use adaptive_gnss_ins::gnss::geometry::predict;
    use adaptive_gnss_ins::gnss::Constellation;
    let mut epochs = Vec::new();
    for raw in &log.rawx {
        let built = build_epoch_with(raw, &log.store, None, IonosphereMode::IonoFree);
        let tow = built.receive_time.tow_s;
        let Some(pvt) = reference_at(log, tow) else {
            continue;
        };
        let reference = Llh::new(pvt.lat_rad, pvt.lon_rad, pvt.height_m);
        let r = llh_to_ecef(&reference);
        let rows: Vec<_> = built
            .epoch
            .satellites
            .iter()
            .filter_map(|obs| {
                let pseudorange_m = obs.pseudorange_m?;
                let p = predict(obs, &r, &Vector3::zeros(), 0.0, 0.0, None, tow).ok()?;
                let group = usize::from(obs.sat.constellation == Constellation::Galileo);
                (p.elevation_rad > 10f64.to_radians()).then(|| {
                    (
                        rot_ecef_to_enu(&reference) * p.los_ecef,
                        pseudorange_m - p.pseudorange_m,
                        group,
                    )
                })
            })
            .collect();
        epochs.push(rows);
    }
    ReferenceResiduals { epochs }
}

/// Least squares of one epoch's residuals on a clock per system and, with `offset`, a
/// position offset Δ (ENU): v = −e·Δ + clock. Returns Δ (zero without) and the RMS left.
fn fit(rows: &[(Vector3<f64>, f64, usize)], offset: bool) -> Option<(Vector3<f64>, f64)> {
    let n_pos = if offset { 3 } else { 0 };
    let unknowns = n_pos + 2;
    if rows.len() < unknowns + 2 || !(0..2).all(|g| rows.iter().any(|r| r.2 == g)) {
        return None;
    }
    let mut h = nalgebra::DMatrix::<f64>::zeros(rows.len(), unknowns);
    let mut y = nalgebra::DVector::<f64>::zeros(rows.len());
    for (i, (e, v, g)) in rows.iter().enumerate() {
        for k in 0..n_pos {
            h[(i, k)] = -e[k];
        }
        h[(i, n_pos + g)] = 1.0;
        y[i] = *v;
    }
    let x = (h.transpose() * &h).try_inverse()? * h.transpose() * &y;
    let left = &y - &h * &x;
    let delta = if offset {
        Vector3::new(x[0], x[1], x[2])
    } else {
        Vector3::zeros()
    };
    Some((delta, (left.norm_squared() / rows.len() as f64).sqrt()))
}

/// What the iono-free single point's remaining error looks like: at the reference
/// positions, the residuals of GPS and Galileo fit a position offset (the same in every
/// epoch) to about a metre, and a clock alone leaves several metres.
#[test]
fn iono_free_residuals_at_the_reference_fit_one_position_offset() {
    let log = log();
    let residuals = reference_residuals(&log);
    let (mut deltas, mut with, mut without) = (Vec::new(), Vec::new(), Vec::new());
    for rows in &residuals.epochs {
        if let (Some((d, rms)), Some((_, rms0))) = (fit(rows, true), fit(rows, false)) {
            deltas.push(d);
            with.push(rms);
            without.push(rms0);
        }
    }
    let n = deltas.len() as f64;
    let mean_delta = deltas.iter().sum::<Vector3<f64>>() / n;
    let spread = (deltas
        .iter()
        .map(|d| (d - mean_delta).component_mul(&(d - mean_delta)))
        .sum::<Vector3<f64>>()
        / n)
        .map(f64::sqrt);
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (rms_with, rms_without) = (median(&mut with), median(&mut without));
    println!(
        "{} epochs: position offset of the reference mean {:.2?} m (ENU), spread {:.2?} m; \
         median residual RMS {rms_with:.2} m with the offset, {rms_without:.2} m with \
         clocks alone",
        deltas.len(),
        mean_delta.as_slice(),
        spread.as_slice()
    );
    assert!(deltas.len() > 500);
    assert!(rms_with < 1.5, "{rms_with} m left with an offset");
    assert!(
        rms_without > 2.0 * rms_with,
        "{rms_without} m with clocks alone"
    );
}
