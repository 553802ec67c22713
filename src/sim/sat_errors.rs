//! The errors the scenario adds to each satellite's observation, drawn from seeded,
//! independent random streams.
//!
//! Random streams. Every draw comes from a `ChaCha8Rng` keyed by the scenario seed, with
//! the ChaCha stream number naming the purpose and the satellite ([`stream_id`]) and the
//! word position naming the GNSS epoch (or the environment segment). A draw therefore
//! depends only on (seed, purpose, satellite, epoch): adding a satellite, changing an
//! environment or the IMU leaves every other draw unchanged, and the open-sky epochs of two
//! scenarios with the same seed and geometry carry the same thermal noise.
//!
//! Added errors per received satellite (see [`crate::sim::environment`]):
//! pseudo-range: thermal + multipath + NLOS bias + outlier; rate: thermal + multipath;
//! carrier phase: thermal (the phase-lock loop's; multipath on the phase is millimetres
//! and left out).

use std::collections::BTreeMap;

use rand::RngExt;
use rand_chacha::rand_core::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::gnss::SatId;
use crate::sim::ar_process::{ArModel, ArProcess};
use crate::sim::environment::{Environment, FoliageSpec, UrbanCanyonSpec};
use crate::sim::scenario_spec::ThermalNoiseSpec;

/// What a random stream is used for (the high bits of the ChaCha stream number).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StreamPurpose {
    /// The IMU error model.
    Imu = 1,
    /// The receiver clock.
    ReceiverClock = 2,
    /// A satellite's thermal noise.
    Thermal = 3,
    /// A satellite's pseudo-range multipath.
    MultipathRange = 4,
    /// A satellite's pseudo-range-rate multipath.
    MultipathRate = 5,
    /// A satellite's random events (heavy-tail component, outliers).
    Events = 6,
    /// A satellite's NLOS state in an urban-canyon segment.
    Nlos = 7,
    /// A satellite's carrier-phase noise.
    CarrierPhase = 8,
    /// The integer ambiguity of a satellite's carrier-phase track.
    CarrierAmbiguity = 9,
    /// A dual-antenna pair's heading error.
    BaselineHeading = 10,
}

/// 32-bit words reserved per epoch (or segment) in a stream. Choice: 2²⁰ words; an epoch
/// draws a handful of normals (the ziggurat sampler rarely needs more than one 64-bit word
/// each), so a stream can never run into the next epoch's words.
const WORDS_PER_SLOT: u128 = 1 << 20;

/// ChaCha stream number for `purpose` and satellite `sat` (None: not per satellite).
pub fn stream_id(purpose: StreamPurpose, sat: Option<SatId>) -> u64 {
    let sat_bits = sat.map_or(0, |s| {
        (u64::from(s.constellation.code()) << 16) | u64::from(s.prn)
    });
    ((purpose as u64) << 48) | sat_bits
}

/// The generator for one stream, positioned at `slot` (an epoch or segment index).
pub fn stream_rng(seed: u64, purpose: StreamPurpose, sat: Option<SatId>, slot: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream_id(purpose, sat));
    rng.set_word_pos(u128::from(slot) * WORDS_PER_SLOT);
    rng
}

/// The truth of what was added to one satellite's observation at one epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatErrorTruth {
    /// The satellite.
    pub sat: SatId,
    /// True elevation at the antenna (rad).
    pub elevation_rad: f64,
    /// True azimuth at the antenna, clockwise from north (rad).
    pub azimuth_rad: f64,
    /// C/N0 after the environment's loss (dB-Hz), as reported in the observation.
    pub cn0_dbhz: f64,
    /// Total error added to the pseudo-range (m).
    pub pseudorange_error_m: f64,
    /// Total error added to the pseudo-range rate (m/s).
    pub pseudorange_rate_error_mps: f64,
    /// Error added to the carrier phase (m), besides its ambiguity.
    pub carrier_phase_error_m: f64,
    /// Its multipath part on the pseudo-range (m).
    pub multipath_m: f64,
    /// Its multipath part on the rate (m/s).
    pub multipath_rate_mps: f64,
    /// Its NLOS bias (m), 0 for a line-of-sight signal.
    pub nlos_bias_m: f64,
    /// Its outlier (m), 0 when none.
    pub outlier_m: f64,
    /// Root-mean-square of the pseudo-range error the environment adds, over its random
    /// draws, given the satellite's NLOS bias (see [`SatErrorGenerator::draw`]) (m).
    pub pseudorange_sigma_m: f64,
    /// Root-mean-square of the rate error (m/s).
    pub pseudorange_rate_sigma_mps: f64,
}

/// Where a satellite is and which environment it is in at one epoch.
#[derive(Debug, Clone, Copy)]
pub struct SatContext<'a> {
    /// The satellite.
    pub sat: SatId,
    /// GNSS epoch index (0 at scenario time 0).
    pub epoch_index: u64,
    /// True elevation (rad).
    pub elevation_rad: f64,
    /// True azimuth, clockwise from north (rad).
    pub azimuth_rad: f64,
    /// Vehicle course over ground, clockwise from north (rad), for the street geometry.
    pub course_rad: f64,
    /// The environment in force.
    pub environment: &'a Environment,
    /// Its segment index in the spec (None: open sky outside every segment).
    pub segment: Option<usize>,
}

/// AR models of a foliage segment: range and rate.
#[derive(Debug, Clone)]
pub struct FoliageModels {
    range: ArModel,
    rate: ArModel,
}

impl FoliageModels {
    /// The models of `spec` (None if its AR coefficients are invalid, which validation
    /// excludes).
    pub fn new(spec: &FoliageSpec) -> Option<Self> {
        let m = &spec.multipath;
        Some(Self {
            range: ArModel::new(&m.ar_coefficients, m.pseudorange_sigma_m).ok()?,
            rate: ArModel::new(&m.ar_coefficients, m.pseudorange_rate_sigma_mps).ok()?,
        })
    }
}

/// Multipath state of one satellite.
#[derive(Debug, Clone)]
struct MultipathState {
    range: ArProcess,
    rate: ArProcess,
}

/// Draws the per-satellite errors, keeping the multipath processes between epochs.
#[derive(Debug, Clone)]
pub struct SatErrorGenerator {
    seed: u64,
    thermal: ThermalNoiseSpec,
    /// Per environment segment: its foliage models, if it is a foliage segment.
    foliage: Vec<Option<FoliageModels>>,
    /// The segment whose multipath states are held.
    multipath_segment: Option<usize>,
    multipath: BTreeMap<SatId, MultipathState>,
    /// Satellites drawn at the current epoch (the others' multipath is dropped).
    seen: Vec<SatId>,
    current_epoch: Option<u64>,
}

impl SatErrorGenerator {
    /// A generator for `seed`, the thermal model and the foliage models per segment.
    pub fn new(seed: u64, thermal: ThermalNoiseSpec, foliage: Vec<Option<FoliageModels>>) -> Self {
        Self {
            seed,
            thermal,
            foliage,
            multipath_segment: None,
            multipath: BTreeMap::new(),
            seen: Vec::new(),
            current_epoch: None,
        }
    }

    /// Begins epoch `epoch_index`: multipath of satellites not drawn at the previous
    /// epoch ends (a satellite that comes back starts a fresh stationary process).
    fn begin_epoch(&mut self, epoch_index: u64) {
        if self.current_epoch == Some(epoch_index) {
            return;
        }
        let seen = std::mem::take(&mut self.seen);
        self.multipath.retain(|sat, _| seen.contains(sat));
        self.current_epoch = Some(epoch_index);
    }

    /// The error of one satellite at one epoch, or None when the environment blocks it.
    /// Call in epoch order, each satellite at most once per epoch.
    ///
    /// The σ reported is the root-mean-square of the added error over the environment's
    /// random draws, given the satellite's NLOS bias (which is fixed for the segment):
    /// σ² = σ_th² (1 − p + p s²) + σ_mp² + p_out E\[M²\] + β², E\[M²\] = (a² + ab + b²)/3 for
    /// M ~ U[a, b], and for the rate σ_th,rate² (1 − p + p s²) + σ_mp,rate².
    pub fn draw(&mut self, ctx: &SatContext<'_>) -> Option<SatErrorTruth> {
        self.begin_epoch(ctx.epoch_index);
        if let Environment::UrbanCanyon(u) = ctx.environment {
            let relative = ctx.azimuth_rad - ctx.course_rad;
            if ctx.elevation_rad < u.mask_elevation_rad(relative) {
                return None;
            }
        }
        if matches!(ctx.environment, Environment::Outage) {
            return None;
        }
        self.seen.push(ctx.sat);

        let cn0_dbhz = self
            .thermal
            .cn0_dbhz(ctx.elevation_rad, ctx.environment.cn0_loss_db());
        let ratio = self.thermal.sigma_ratio(cn0_dbhz);
        let sigma_range = self.thermal.pseudorange_sigma_zenith_m * ratio;
        let sigma_rate = self.thermal.pseudorange_rate_sigma_zenith_mps * ratio;

        let mut thermal_rng = stream_rng(
            self.seed,
            StreamPurpose::Thermal,
            Some(ctx.sat),
            ctx.epoch_index,
        );
        let xi_range: f64 = StandardNormal.sample(&mut thermal_rng);
        let xi_rate: f64 = StandardNormal.sample(&mut thermal_rng);
        let mut events_rng = stream_rng(
            self.seed,
            StreamPurpose::Events,
            Some(ctx.sat),
            ctx.epoch_index,
        );

        let mut truth = SatErrorTruth {
            sat: ctx.sat,
            elevation_rad: ctx.elevation_rad,
            azimuth_rad: ctx.azimuth_rad,
            cn0_dbhz,
            pseudorange_error_m: 0.0,
            pseudorange_rate_error_mps: 0.0,
            carrier_phase_error_m: 0.0,
            multipath_m: 0.0,
            multipath_rate_mps: 0.0,
            nlos_bias_m: 0.0,
            outlier_m: 0.0,
            pseudorange_sigma_m: 0.0,
            pseudorange_rate_sigma_mps: 0.0,
        };
        let mut white_scale = 1.0;
        let mut white_variance_factor = 1.0;
        let mut extra_range_variance = 0.0;
        let mut extra_rate_variance = 0.0;
        match ctx.environment {
            Environment::Foliage(f) => {
                let h = &f.heavy_tail;
                let u: f64 = events_rng.random();
                if u < h.probability {
                    white_scale = h.scale;
                }
                white_variance_factor = 1.0 - h.probability + h.probability * h.scale * h.scale;
                if let Some((mp_range, mp_rate)) = self.multipath_step(ctx) {
                    truth.multipath_m = mp_range;
                    truth.multipath_rate_mps = mp_rate;
                }
                extra_range_variance += f.multipath.pseudorange_sigma_m.powi(2);
                extra_rate_variance += f.multipath.pseudorange_rate_sigma_mps.powi(2);
            }
            Environment::UrbanCanyon(u) => {
                truth.nlos_bias_m = self.nlos_bias_m(u, ctx);
                let draw: f64 = events_rng.random();
                if draw < u.outlier_probability {
                    let magnitude: f64 = events_rng.random();
                    let sign: f64 = events_rng.random();
                    let m = u.outlier_min_m + (u.outlier_max_m - u.outlier_min_m) * magnitude;
                    truth.outlier_m = if sign < 0.5 { -m } else { m };
                }
                let (a, b) = (u.outlier_min_m, u.outlier_max_m);
                extra_range_variance += u.outlier_probability * (a * a + a * b + b * b) / 3.0
                    + truth.nlos_bias_m * truth.nlos_bias_m;
            }
            Environment::OpenSky | Environment::Outage => {}
        }
        truth.pseudorange_error_m = white_scale * sigma_range * xi_range
            + truth.multipath_m
            + truth.nlos_bias_m
            + truth.outlier_m;
        truth.pseudorange_rate_error_mps =
            white_scale * sigma_rate * xi_rate + truth.multipath_rate_mps;
        let mut phase_rng = stream_rng(
            self.seed,
            StreamPurpose::CarrierPhase,
            Some(ctx.sat),
            ctx.epoch_index,
        );
        let xi_phase: f64 = StandardNormal.sample(&mut phase_rng);
        truth.carrier_phase_error_m =
            white_scale * self.thermal.carrier_phase_sigma_zenith_m * ratio * xi_phase;
        truth.pseudorange_sigma_m =
            (sigma_range * sigma_range * white_variance_factor + extra_range_variance).sqrt();
        truth.pseudorange_rate_sigma_mps =
            (sigma_rate * sigma_rate * white_variance_factor + extra_rate_variance).sqrt();
        Some(truth)
    }

    /// Steps (or starts) the satellite's multipath in the current foliage segment.
    fn multipath_step(&mut self, ctx: &SatContext<'_>) -> Option<(f64, f64)> {
        let segment = ctx.segment?;
        let models = self.foliage.get(segment)?.as_ref()?;
        if self.multipath_segment != Some(segment) {
            self.multipath.clear();
            self.multipath_segment = Some(segment);
        }
        let mut range_rng = stream_rng(
            self.seed,
            StreamPurpose::MultipathRange,
            Some(ctx.sat),
            ctx.epoch_index,
        );
        let mut rate_rng = stream_rng(
            self.seed,
            StreamPurpose::MultipathRate,
            Some(ctx.sat),
            ctx.epoch_index,
        );
        let state = match self.multipath.get_mut(&ctx.sat) {
            Some(state) => {
                models.range.step(&mut state.range, &mut range_rng);
                models.rate.step(&mut state.rate, &mut rate_rng);
                state
            }
            None => self.multipath.entry(ctx.sat).or_insert(MultipathState {
                range: models.range.start(&mut range_rng),
                rate: models.rate.start(&mut rate_rng),
            }),
        };
        Some((state.range.value(), state.rate.value()))
    }

    /// The satellite's NLOS bias in this urban segment (0 when line of sight): a function
    /// of (seed, segment, satellite) only.
    fn nlos_bias_m(&self, u: &UrbanCanyonSpec, ctx: &SatContext<'_>) -> f64 {
        let slot = ctx.segment.map_or(0, |s| s as u64 + 1);
        let mut rng = stream_rng(self.seed, StreamPurpose::Nlos, Some(ctx.sat), slot);
        let select: f64 = rng.random();
        let size: f64 = rng.random();
        if select < u.nlos_fraction {
            u.nlos_bias_min_m + (u.nlos_bias_max_m - u.nlos_bias_min_m) * size
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss::Constellation;
    use crate::sim::environment::UrbanCanyonSpec;
    use rand::Rng;

    fn sat(prn: u16) -> SatId {
        SatId {
            constellation: Constellation::Gps,
            prn,
        }
    }

    fn ctx(environment: &Environment, elevation_deg: f64, azimuth_deg: f64) -> SatContext<'_> {
        SatContext {
            sat: sat(3),
            epoch_index: 12,
            elevation_rad: elevation_deg.to_radians(),
            azimuth_rad: azimuth_deg.to_radians(),
            course_rad: 0.0,
            environment,
            segment: Some(0),
        }
    }

    #[test]
    fn streams_depend_only_on_seed_purpose_satellite_and_slot() {
        let draw = |seed, purpose, s, slot| stream_rng(seed, purpose, s, slot).next_u64();
        let a = draw(1, StreamPurpose::Thermal, Some(sat(3)), 12);
        assert_eq!(a, draw(1, StreamPurpose::Thermal, Some(sat(3)), 12));
        assert_ne!(a, draw(2, StreamPurpose::Thermal, Some(sat(3)), 12));
        assert_ne!(a, draw(1, StreamPurpose::Events, Some(sat(3)), 12));
        assert_ne!(a, draw(1, StreamPurpose::Thermal, Some(sat(4)), 12));
        assert_ne!(a, draw(1, StreamPurpose::Thermal, Some(sat(3)), 13));
        assert_ne!(
            stream_id(StreamPurpose::Imu, None),
            stream_id(StreamPurpose::ReceiverClock, None)
        );
    }

    #[test]
    fn open_sky_sigma_follows_the_cn0() {
        let thermal = ThermalNoiseSpec::default();
        let mut g = SatErrorGenerator::new(5, thermal.clone(), vec![None]);
        let open = Environment::OpenSky;
        let zenith = g.draw(&ctx(&open, 90.0, 0.0)).unwrap();
        assert!((zenith.cn0_dbhz - 50.0).abs() < 1e-12);
        assert!((zenith.pseudorange_sigma_m - 0.5).abs() < 1e-12);
        assert!((zenith.pseudorange_rate_sigma_mps - 0.05).abs() < 1e-12);
        // 30°: C/N0 = 35 + 7.5 = 42.5 dB-Hz, σ ratio 10^(7.5/20).
        let mut g = SatErrorGenerator::new(5, thermal, vec![None]);
        let low = g.draw(&ctx(&open, 30.0, 0.0)).unwrap();
        assert!((low.cn0_dbhz - 42.5).abs() < 1e-12);
        assert!((low.pseudorange_sigma_m - 0.5 * 10f64.powf(7.5 / 20.0)).abs() < 1e-12);
        assert_eq!(low.nlos_bias_m, 0.0);
        assert_eq!(low.multipath_m, 0.0);
    }

    #[test]
    fn urban_mask_and_outage_block() {
        let urban = Environment::UrbanCanyon(UrbanCanyonSpec {
            cn0_loss_db: 0.0,
            min_mask_elevation_deg: 15.0,
            building_height_m: 15.0,
            street_width_m: 30.0,
            nlos_fraction: 0.0,
            nlos_bias_min_m: 10.0,
            nlos_bias_max_m: 50.0,
            outlier_probability: 0.0,
            outlier_min_m: 20.0,
            outlier_max_m: 80.0,
        });
        let mut g = SatErrorGenerator::new(5, ThermalNoiseSpec::default(), vec![None]);
        // Across the street (azimuth 90° from the course) the walls reach 45°.
        assert!(g.draw(&ctx(&urban, 44.0, 90.0)).is_none());
        assert!(g.draw(&ctx(&urban, 46.0, 90.0)).is_some());
        // Along the street only the 15° floor.
        assert!(g.draw(&ctx(&urban, 14.0, 0.0)).is_none());
        assert!(g.draw(&ctx(&urban, 16.0, 180.0)).is_some());
        assert!(g.draw(&ctx(&Environment::Outage, 80.0, 0.0)).is_none());
    }
}
