//! Property tests of the WGS84 conversions: ECEF ↔ geodetic and ENU round trips hold to
//! well below a millimetre anywhere from below the surface to GNSS orbit altitude.

use adaptive_gnss_ins::earth::{self, Llh};
use nalgebra::Vector3;
use proptest::prelude::*;

/// Round-trip tolerance (m): Bowring plus Newton iterations converge to rounding level.
const ROUND_TRIP_TOLERANCE_M: f64 = 1e-6;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn llh_to_ecef_to_llh_round_trip(
        lat_deg in -89.999f64..89.999,
        lon_deg in -180.0f64..180.0,
        height_m in -1_000.0f64..30_000_000.0,
    ) {
        let p = Llh::from_degrees(lat_deg, lon_deg, height_m);
        let r = earth::llh_to_ecef(&p);
        let back = earth::ecef_to_llh(&r).expect("defined away from the centre");
        // Compare in metres: the round trip through ECEF again, and the height directly.
        prop_assert!((earth::llh_to_ecef(&back) - r).norm() < ROUND_TRIP_TOLERANCE_M);
        prop_assert!((back.height_m - height_m).abs() < ROUND_TRIP_TOLERANCE_M);
        let north_m = (back.lat_rad - p.lat_rad) * earth::SEMI_MAJOR_AXIS_M;
        prop_assert!(north_m.abs() < ROUND_TRIP_TOLERANCE_M);
    }

    #[test]
    fn ecef_to_llh_to_ecef_round_trip(
        x in -3.0e7f64..3.0e7,
        y in -3.0e7f64..3.0e7,
        z in -3.0e7f64..3.0e7,
    ) {
        let r = Vector3::new(x, y, z);
        // Points deep inside the earth are not geodetic positions; stay above 6000 km.
        prop_assume!(r.norm() > 6.0e6);
        let p = earth::ecef_to_llh(&r).expect("defined away from the centre");
        prop_assert!((earth::llh_to_ecef(&p) - r).norm() < ROUND_TRIP_TOLERANCE_M);
    }

    #[test]
    fn enu_round_trip(
        lat_deg in -89.0f64..89.0,
        lon_deg in -180.0f64..180.0,
        e in -50_000.0f64..50_000.0,
        n in -50_000.0f64..50_000.0,
        u in -1_000.0f64..10_000.0,
    ) {
        let origin = Llh::from_degrees(lat_deg, lon_deg, 100.0);
        let enu = Vector3::new(e, n, u);
        let p = earth::enu_to_llh(&enu, &origin).expect("geodetic");
        prop_assert!((earth::llh_to_enu(&p, &origin) - enu).norm() < ROUND_TRIP_TOLERANCE_M);
    }
}

#[test]
fn the_earth_centre_and_non_finite_points_have_no_geodetic_position() {
    assert!(earth::ecef_to_llh(&Vector3::zeros()).is_none());
    assert!(earth::ecef_to_llh(&Vector3::new(f64::NAN, 0.0, 0.0)).is_none());
    assert!(earth::ecef_to_llh(&Vector3::new(f64::INFINITY, 1.0, 0.0)).is_none());
}
