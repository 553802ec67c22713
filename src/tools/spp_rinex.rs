//! `gnss_ins spp-rinex`: the single-point solution of every epoch of a RINEX 3
//! observation file with a RINEX navigation file's ephemerides
//! ([`crate::gnss::rinex_spp`]), written as CSV.
//!
//! CSV columns: `gps_week, gps_tow_s` (receive time), `status` (`solved` or the reason:
//! `not_enough_satellites`, `singular_geometry`, `not_converged`, `non_finite`,
//! `invalid_config`, `non_finite_epoch_time`), `num_used`, `x_m, y_m, z_m` (ECEF),
//! `lat_deg, lon_deg, height_m` (WGS84 ellipsoid), `clock_bias_m`, `gdop`; the solution
//! fields are empty when there is none.

use std::io::Write;
use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::gnss::rinex_nav::{parse_rinex_nav, RinexNavError};
use crate::gnss::rinex_obs::{parse_rinex_obs, RinexObsError};
use crate::gnss::rinex_spp::{solve_rinex_spp_with_progress, RinexSppEpoch, RinexSppOptions};
use crate::gnss::spp::SppError;

/// Why the tool could not run.
#[derive(Debug, Error)]
pub enum SppRinexError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The observation file's header is unreadable.
    #[error("{path}: {source}")]
    Observation {
        path: PathBuf,
        source: RinexObsError,
    },
    /// The navigation file is unreadable.
    #[error("{path}: {source}")]
    Navigation {
        path: PathBuf,
        source: RinexNavError,
    },
}

/// What a run did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SppRinexSummary {
    /// Observation epochs in the file.
    pub epochs: usize,
    /// Epochs solved.
    pub solved: usize,
    /// Malformed lines of the observation file that were skipped.
    pub malformed_lines: usize,
    /// Event and cycle-slip records skipped.
    pub skipped_records: usize,
}

/// Reads `obs_path` and `nav_path`, solves every epoch with `options` (`progress` is
/// called with the fraction of the epochs solved) and writes the CSV to `out_csv`.
pub fn spp_rinex(
    obs_path: &Path,
    nav_path: &Path,
    out_csv: &Path,
    options: &RinexSppOptions,
    progress: impl FnMut(f64),
) -> Result<SppRinexSummary, SppRinexError> {
    let read = |path: &Path| {
        std::fs::read_to_string(path).map_err(|source| SppRinexError::Io {
            path: path.to_path_buf(),
            source,
        })
    };
    let obs = parse_rinex_obs(&read(obs_path)?).map_err(|source| SppRinexError::Observation {
        path: obs_path.to_path_buf(),
        source,
    })?;
    let nav = parse_rinex_nav(&read(nav_path)?).map_err(|source| SppRinexError::Navigation {
        path: nav_path.to_path_buf(),
        source,
    })?;
    let solved = solve_rinex_spp_with_progress(&obs, &nav, options, progress);
    let io = |source| SppRinexError::Io {
        path: out_csv.to_path_buf(),
        source,
    };
    let file = std::fs::File::create(out_csv).map_err(io)?;
    let mut out = std::io::BufWriter::new(file);
    write_csv(&solved, &mut out).map_err(io)?;
    out.flush().map_err(io)?;
    Ok(SppRinexSummary {
        epochs: solved.len(),
        solved: solved.iter().filter(|e| e.solution.is_ok()).count(),
        malformed_lines: obs.stats.errors.len(),
        skipped_records: obs.stats.skipped.values().sum(),
    })
}

/// Writes the CSV (see the module notes) of `epochs`.
pub fn write_csv(epochs: &[RinexSppEpoch], out: &mut impl Write) -> std::io::Result<()> {
    writeln!(
        out,
        "gps_week,gps_tow_s,status,num_used,x_m,y_m,z_m,lat_deg,lon_deg,height_m,clock_bias_m,gdop"
    )?;
    for e in epochs {
        write!(out, "{},{:.7},", e.time.week, e.time.tow_s)?;
        match &e.solution {
            Ok(s) => writeln!(
                out,
                "solved,{},{:.4},{:.4},{:.4},{:.9},{:.9},{:.4},{:.4},{:.3}",
                s.num_used,
                s.pos_ecef_m.x,
                s.pos_ecef_m.y,
                s.pos_ecef_m.z,
                s.pos_llh.lat_rad.to_degrees(),
                s.pos_llh.lon_rad.to_degrees(),
                s.pos_llh.height_m,
                s.clock_bias_m,
                s.dop.gdop
            )?,
            Err(err) => writeln!(out, "{},,,,,,,,,", status(err))?,
        }
    }
    Ok(())
}

/// The CSV status of a failed epoch.
fn status(err: &SppError) -> &'static str {
    match err {
        SppError::InvalidConfig { .. } => "invalid_config",
        SppError::NonFiniteEpochTime { .. } => "non_finite_epoch_time",
        SppError::NotEnoughSatellites { .. } => "not_enough_satellites",
        SppError::SingularGeometry { .. } => "singular_geometry",
        SppError::NonFinite { .. } => "non_finite",
        SppError::NotConverged { .. } => "not_converged",
    }
}
