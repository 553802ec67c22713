//! UBX decoding and SPP on the real walk_0827 recording (u-blox RAWX/SFRBX/NAV-PVT).

use adaptive_gnss_ins::earth::{ecef_to_llh, llh_to_ecef, rot_ecef_to_enu, Llh};
use adaptive_gnss_ins::gnss::spp::{solve_spp, SppConfig};
use adaptive_gnss_ins::gnss::ubx::{read_ubx_log, CarrierSolution, UbxLog};
use adaptive_gnss_ins::gnss::Constellation;

fn data_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/walk_0827")
        .join(name)
}

fn read_data(name: &str) -> Vec<u8> {
    let path = data_path(name);
    std::fs::read(&path).unwrap_or_else(|e| {
        panic!(
            "test data {} missing ({e}); the repository expects shared/ beside it",
            path.display()
        )
    })
}

fn log() -> UbxLog {
    read_ubx_log(&read_data("gnss_1730.ubx"))
}

#[test]
fn explore() {
    let log = log();
    println!("{:?}", log.stats);
    println!(
        "store {} sats {:?}",
        log.store.len(),
        log.store.satellites().collect::<Vec<_>>()
    );
    println!("klob {:?}", log.klobuchar);
    let epochs: Vec<_> = log
        .rawx
        .iter()
        .map(|r| adaptive_gnss_ins::gnss::ubx::build_epoch(r, &log.store, log.klobuchar))
        .collect();
    let first = &epochs[0];
    println!("first {:?}", first.stats);
    let t0 = first.receive_time;
    println!(
        "rcv {:.9} pvt {:?}",
        t0.tow_s,
        log.nav_pvt
            .iter()
            .take(3)
            .map(|p| p.itow_ms)
            .collect::<Vec<_>>()
    );
    let mut h = Vec::new();
    let mut v = Vec::new();
    for e in &epochs {
        if e.receive_time.seconds_since(&t0) > 60.0 {
            break;
        }
        let Ok(sol) = solve_spp(&e.epoch, &SppConfig::default()) else {
            println!("fail {:?}", e.stats);
            continue;
        };
        let Some(pvt) = log
            .nav_pvt
            .iter()
            .find(|p| (p.itow_ms as f64 * 1e-3 - e.receive_time.tow_s).abs() < 0.05)
        else {
            continue;
        };
        let ref_llh = Llh::new(pvt.lat_rad, pvt.lon_rad, pvt.height_m);
        let d = rot_ecef_to_enu(&ref_llh) * (sol.pos_ecef_m - llh_to_ecef(&ref_llh));
        h.push((d[0] * d[0] + d[1] * d[1]).sqrt());
        v.push(d[2]);
        let mut per = std::collections::BTreeMap::new();
        for r in &sol.residuals {
            *per.entry(r.sat.constellation.code()).or_insert(0) += 1;
        }
        if e.receive_time.tow_s % 10.0 == 0.0 {
            for r in &sol.residuals {
                print!("{} {:.1} | ", r.sat, r.residual_m);
            }
            println!();
        }
        println!(
            "{:.2} used {} {:?} d {:.2} {:.2} {:.2} excl {:?}",
            e.receive_time.tow_s,
            sol.num_used,
            per,
            d[0],
            d[1],
            d[2],
            sol.excluded.len()
        );
    }
    let _ = (ecef_to_llh, CarrierSolution::Fixed, Constellation::Gps);
}
