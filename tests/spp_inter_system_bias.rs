//! Single-point solution with one receiver clock per constellation: an inter-system bias
//! on the satellites of one system is absorbed by that system's clock and leaves the
//! position alone; one common clock pushes it into the position.

use adaptive_gnss_ins::earth::{llh_to_ecef, rot_ecef_to_enu, Llh};
use adaptive_gnss_ins::gnss::spp::{solve_spp, SppConfig};
use adaptive_gnss_ins::gnss::{Constellation, GnssEpoch, Klobuchar};
use adaptive_gnss_ins::sim::constellation::{
    AtmosphereTruth, GpsConstellation, ObservationNoise, ReceiverTruth,
};
use nalgebra::Vector3;

/// Inter-system bias put on the relabelled satellites (m): tens of ns, as between GPS and
/// BeiDou time plus receiver signal delays.
const BIAS_M: f64 = 25.0;
/// Noise-free data: the per-constellation solution must be exact to this (m).
const MAX_EXACT_ERR_M: f64 = 1e-3;

fn epoch_with_bias(site: &Llh, t_s: f64) -> (GnssEpoch, ReceiverTruth) {
    let c = GpsConstellation::augmented(1);
    let atmosphere = AtmosphereTruth::models(Klobuchar {
        alpha: [1.1176e-8, 7.4506e-9, -5.9605e-8, -1.1921e-7],
        beta: [1.1469e5, 0.0, -1.9661e5, -6.5536e4],
    });
    let rx = ReceiverTruth {
        pos_ecef_m: llh_to_ecef(site),
        vel_ecef_mps: rot_ecef_to_enu(site).transpose() * Vector3::new(3.0, -2.0, 0.0),
        clock_bias_m: 12_345.0,
        clock_drift_mps: -7.0,
    };
    let mut epoch = c
        .simulate_epoch(t_s, &rx, &atmosphere, 5f64.to_radians(), |_| {
            ObservationNoise::default()
        })
        .unwrap();
    // Every other satellite becomes a "Galileo" satellite with the bias.
    for obs in epoch.satellites.iter_mut().skip(1).step_by(2) {
        obs.sat.constellation = Constellation::Galileo;
        obs.pseudorange_m = obs.pseudorange_m.map(|p| p + BIAS_M);
    }
    (epoch, rx)
}

#[test]
fn a_clock_per_constellation_absorbs_an_inter_system_bias() {
    let site = Llh::from_degrees(40.0, -105.1, 1573.0);
    for t_s in [0.0, 7_200.0, 30_000.0] {
        let (epoch, rx) = epoch_with_bias(&site, t_s);
        let galileo = epoch
            .satellites
            .iter()
            .filter(|s| s.sat.constellation == Constellation::Galileo)
            .count();
        assert!(galileo >= 3 && epoch.satellites.len() - galileo >= 3);
        let per = SppConfig {
            clock_per_constellation: true,
            outlier_threshold: None,
            ..SppConfig::default()
        };
        let sol = solve_spp(&epoch, &per).unwrap();
        let err = (sol.pos_ecef_m - rx.pos_ecef_m).norm();
        assert!(err < MAX_EXACT_ERR_M, "t {t_s}: position error {err} m");
        // The reported clock is GPS's (first in order); Galileo's carries the bias.
        assert!((sol.clock_bias_m - rx.clock_bias_m).abs() < MAX_EXACT_ERR_M);
        assert_eq!(sol.clock_biases_m.len(), 2);
        assert_eq!(sol.clock_biases_m[0].0, Constellation::Gps);
        let (c, galileo_clock_m) = sol.clock_biases_m[1];
        assert_eq!(c, Constellation::Galileo);
        assert!((galileo_clock_m - rx.clock_bias_m - BIAS_M).abs() < MAX_EXACT_ERR_M);
        assert!(sol.dop.pdop.is_finite() && sol.dop.tdop > 0.0);

        // One common clock: the bias leaks into the position.
        let common = SppConfig {
            outlier_threshold: None,
            ..SppConfig::default()
        };
        let sol = solve_spp(&epoch, &common).unwrap();
        let err = (sol.pos_ecef_m - rx.pos_ecef_m).norm();
        println!("t {t_s}: one clock for all, position error {err:.2} m");
        assert!(err > 1.0, "t {t_s}: common clock error only {err} m");
        assert_eq!(sol.clock_biases_m.len(), 1);
    }
}

#[test]
fn one_system_gives_the_same_solution_either_way() {
    let site = Llh::from_degrees(-33.9, 151.2, 40.0);
    let (mut epoch, _) = epoch_with_bias(&site, 3_600.0);
    epoch
        .satellites
        .retain(|s| s.sat.constellation == Constellation::Gps);
    let common = solve_spp(&epoch, &SppConfig::default()).unwrap();
    let per = solve_spp(
        &epoch,
        &SppConfig {
            clock_per_constellation: true,
            ..SppConfig::default()
        },
    )
    .unwrap();
    assert!((common.pos_ecef_m - per.pos_ecef_m).norm() < 1e-6);
    assert!((common.clock_bias_m - per.clock_bias_m).abs() < 1e-6);
    assert_eq!(common.num_used, per.num_used);
}
