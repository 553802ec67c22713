//! The `gnss_ins` subcommands for real receiver data: `convert` (UBX log + IMU CSV +
//! reference into a bag) and `spp` (our single-point solution over a bag or a UBX log).

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::convert::{
    convert_with_progress as convert_files, ConvertOptions, ConvertSummary, EphemerisMode,
    GnssSource, ImuInput, ImuTime, TruthInput,
};
use super::convert_bag::{
    RobotBag, RobotBagSummary, RobotBagTopics, UbxInput, DEFAULT_IMU_TOPIC, DEFAULT_RAWX_TOPIC,
    DEFAULT_SFRBX_TOPIC, DEFAULT_STREAM_TOPIC,
};
use super::imu_csv::{AccelUnit, GyroUnit, ImuCsvFormat};
use super::progress::Progress;
use super::simulate::TRUTH_TOPIC;
use super::spp_rinex::spp_rinex as solve_rinex_files;
use super::spp_run::{bag_spp_inputs, run_spp_with, write_spp_csv};
use crate::gnss::atmosphere::TroposphereModel;
use crate::gnss::ionosphere::IonosphereMode;
use crate::gnss::rinex_spp::{Ionosphere, RinexSppOptions};
use crate::gnss::time_scale::DEFAULT_GPS_UTC_LEAP_S;
use crate::ros::node::params::config_from_files;
use crate::ros::ubx_adapter::{TimeBase, DEFAULT_HOST_LATENCY_S};

/// Unit of the accelerometer columns.
#[derive(Clone, Copy, ValueEnum)]
pub enum AccelUnitArg {
    /// Standard gravities (9.80665 m/s²).
    G,
    /// m/s².
    Mps2,
}

/// Unit of the gyro columns.
#[derive(Clone, Copy, ValueEnum)]
pub enum GyroUnitArg {
    DegPerS,
    RadPerS,
}

/// How the pseudo-ranges deal with the ionosphere.
#[derive(Clone, Copy, ValueEnum)]
pub enum IonosphereArg {
    /// Dual-frequency ionosphere-free combination (GPS L1 C/A + L2C, Galileo E1 + E5a or
    /// E5b, BeiDou B1I + B3I or B2I); single-frequency satellites left out. The default:
    /// it removes the ionospheric delay (metres), which a short log may carry no model
    /// for, at about three times the code noise.
    IonoFree,
    /// One signal per satellite, corrected with the broadcast GPS Klobuchar model when
    /// the log holds it (else not corrected).
    Broadcast,
    /// One signal per satellite, not corrected.
    None,
}

impl IonosphereArg {
    fn mode(self) -> IonosphereMode {
        match self {
            Self::IonoFree => IonosphereMode::IonoFree,
            Self::Broadcast => IonosphereMode::Broadcast,
            Self::None => IonosphereMode::None,
        }
    }
}

/// The receiver clocks of the single-point solution.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ClockArg {
    /// One clock for all satellites, as the filter has, so that the two are compared on
    /// the same model. The default.
    Common,
    /// One clock per constellation: absorbs the inter-system biases of a multi-GNSS
    /// receiver (time-scale offsets, per-signal receiver delays).
    PerConstellation,
}

/// The clock of the GNSS stamps of a converted robot bag.
#[derive(Clone, Copy, ValueEnum)]
pub enum TimeBaseArg {
    /// The receiver's time: GPST - leap seconds (for IMU stamps on a synced host clock).
    Gnss,
    /// The driver's receive stamp (a stream chunk's log time) - --host-latency-s.
    Host,
}

/// A robot's bag as the GNSS and IMU input of `convert`.
#[derive(Args, Clone)]
pub struct RobotBagArgs {
    /// A robot's rosbag2 MCAP bag (.mcap file or bag directory) with the u-blox drivers'
    /// raw GNSS (ublox_dgnss UBXRxmRawx + UBXRxmSfrbx, or ublox_gps's byte stream as
    /// std_msgs/UInt8MultiArray) and sensor_msgs/Imu, converted through the live adapter:
    /// as received, whatever --ephemeris says. The IMU messages are copied as recorded.
    #[arg(long, conflicts_with_all = ["ubx", "rinex_obs", "imu_csv", "truth_ubx"])]
    pub bag: Option<PathBuf>,
    /// Topic of the UBXRxmRawx messages in --bag.
    #[arg(long, default_value = DEFAULT_RAWX_TOPIC)]
    pub rawx_topic: String,
    /// Topic of the UBXRxmSfrbx messages in --bag.
    #[arg(long, default_value = DEFAULT_SFRBX_TOPIC)]
    pub sfrbx_topic: String,
    /// Topic of the UBX byte stream (UInt8MultiArray) in --bag, read when the bag has no
    /// RAWX messages.
    #[arg(long, default_value = DEFAULT_STREAM_TOPIC)]
    pub ubx_stream_topic: String,
    /// Topic of the sensor_msgs/Imu messages in --bag.
    #[arg(long, default_value = DEFAULT_IMU_TOPIC)]
    pub imu_topic: String,
    /// Clock of the GNSS stamps written for --bag.
    #[arg(long, value_enum, default_value_t = TimeBaseArg::Gnss)]
    pub time_base: TimeBaseArg,
    /// Receiver output latency (s): measurement epoch to the host receive stamp; host
    /// stamps are the receive stamp minus this, and the clock check expects it.
    #[arg(long, default_value_t = DEFAULT_HOST_LATENCY_S)]
    pub host_latency_s: f64,
}

impl Default for RobotBagArgs {
    fn default() -> Self {
        let topics = RobotBagTopics::default();
        Self {
            bag: None,
            rawx_topic: topics.rawx,
            sfrbx_topic: topics.sfrbx,
            ubx_stream_topic: topics.stream,
            imu_topic: topics.imu,
            time_base: TimeBaseArg::Gnss,
            host_latency_s: DEFAULT_HOST_LATENCY_S,
        }
    }
}

impl RobotBagArgs {
    /// The GNSS source of `--bag`, if given.
    fn source(&self) -> Option<GnssSource> {
        let path = self.bag.clone()?;
        Some(GnssSource::Bag {
            bag: RobotBag {
                path,
                topics: RobotBagTopics {
                    rawx: self.rawx_topic.clone(),
                    sfrbx: self.sfrbx_topic.clone(),
                    stream: self.ubx_stream_topic.clone(),
                    imu: self.imu_topic.clone(),
                },
            },
            time_base: match self.time_base {
                TimeBaseArg::Gnss => TimeBase::Gnss,
                TimeBaseArg::Host => TimeBase::Host,
            },
            host_latency_s: self.host_latency_s,
        })
    }
}

/// Which ephemerides give the satellite states.
#[derive(Clone, Copy, ValueEnum)]
pub enum EphemerisArg {
    /// Every ephemeris decoded anywhere in the log (post-processing).
    WholeLog,
    /// Only those decoded before each epoch (real time).
    AsReceived,
}

/// The reference trajectory and time scale of a conversion (`convert`, and `spp` of a
/// UBX log).
#[derive(Args, Clone)]
pub struct ReferenceArgs {
    /// Reference from the log's UBX-NAV-PVT solutions (e.g. a receiver running RTK).
    #[arg(long, conflicts_with = "truth_pos")]
    pub truth_ubx: bool,
    /// Reference from an RTKLIB .pos file (GPST).
    #[arg(long)]
    pub truth_pos: Option<PathBuf>,
    /// Geoid separation (m) added to the .pos heights (0 when they are ellipsoidal; the
    /// receiver's NAV-PVT height − hMSL when they are above mean sea level).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub geoid_separation_m: f64,
    /// GPS − UTC leap seconds: ROS stamps are GPST − this.
    #[arg(long, default_value_t = DEFAULT_GPS_UTC_LEAP_S)]
    pub leap_seconds: f64,
}

/// Arguments of `gnss_ins convert`.
#[derive(Args)]
pub struct ConvertArgs {
    /// u-blox UBX log with UBX-RXM-RAWX and UBX-RXM-SFRBX (and UBX-NAV-PVT for
    /// --truth-ubx). RAWX carries GPS time, so the log needs no time tag.
    #[arg(
        long,
        required_unless_present_any = ["rinex_obs", "bag"],
        conflicts_with = "rinex_obs"
    )]
    pub ubx: Option<PathBuf>,
    /// RINEX 3 observation file (instead of --ubx; single frequency, with --rinex-nav).
    #[arg(long, requires = "rinex_nav")]
    pub rinex_obs: Option<PathBuf>,
    /// RINEX 3 navigation file of --rinex-obs.
    #[arg(long, requires = "rinex_obs")]
    pub rinex_nav: Option<PathBuf>,
    /// IMU CSV, one sample per line (see --imu-columns).
    #[arg(long)]
    pub imu_csv: Option<PathBuf>,
    /// What each CSV column holds, comma-separated: ax ay az (accelerometer, specific
    /// force), gx gy gz (gyro), one time column (tick_ms: the IMU's millisecond tick,
    /// stamped with --imu-tag; gpst_s: GPST seconds since 1970), '-' to ignore a column.
    #[arg(long, default_value = "ax,ay,az,gx,gy,gz,tick_ms")]
    pub imu_columns: String,
    /// Unit of the accelerometer columns.
    #[arg(long, value_enum, default_value_t = AccelUnitArg::G)]
    pub imu_accel_unit: AccelUnitArg,
    /// Unit of the gyro columns.
    #[arg(long, value_enum, default_value_t = GyroUnitArg::DegPerS)]
    pub imu_gyro_unit: GyroUnitArg,
    /// Rotation taking IMU-axis vectors into the FLU body frame: roll,pitch,yaw in degrees,
    /// composed R = Rz(yaw)·Ry(pitch)·Rx(roll) (as mounting.imu_rotation_rpy_deg).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true,
          default_values_t = [0.0, 0.0, 0.0])]
    pub imu_to_flu_rpy_deg: Vec<f64>,
    /// RTKLIB time-tag file of the IMU CSV (for a tick_ms column): a sample's GPST is the
    /// tag's start + (tick − first tick)/1000, stretched so that the last sample lands on
    /// the tag's last record.
    #[arg(long)]
    pub imu_tag: Option<PathBuf>,
    #[command(flatten)]
    pub robot_bag: RobotBagArgs,
    #[command(flatten)]
    pub reference: ReferenceArgs,
    /// Which ephemerides each epoch may use.
    #[arg(long, value_enum, default_value_t = EphemerisArg::WholeLog)]
    pub ephemeris: EphemerisArg,
    /// The pseudo-ranges to form.
    #[arg(long, value_enum, default_value_t = IonosphereArg::IonoFree)]
    pub ionosphere: IonosphereArg,
    /// Output bag.
    #[arg(long)]
    pub out: PathBuf,
}

impl ConvertArgs {
    /// The conversion these arguments ask for.
    pub fn options(&self) -> Result<ConvertOptions, String> {
        self.check_numbers()?;
        let imu = match &self.imu_csv {
            None => None,
            Some(csv) => {
                let [r, p, y] = <[f64; 3]>::try_from(self.imu_to_flu_rpy_deg.as_slice())
                    .map_err(|_| "--imu-to-flu-rpy-deg needs three angles".to_owned())?;
                let format = ImuCsvFormat::new(
                    &self.imu_columns,
                    match self.imu_accel_unit {
                        AccelUnitArg::G => AccelUnit::G,
                        AccelUnitArg::Mps2 => AccelUnit::MetresPerSecond2,
                    },
                    match self.imu_gyro_unit {
                        GyroUnitArg::DegPerS => GyroUnit::DegPerS,
                        GyroUnitArg::RadPerS => GyroUnit::RadPerS,
                    },
                    [r, p, y],
                )
                .map_err(|e| e.to_string())?;
                let ticks = self.imu_columns.split(',').any(|c| c.trim() == "tick_ms");
                let time = match (&self.imu_tag, ticks) {
                    (Some(tag), true) => ImuTime::Tag(tag.clone()),
                    (None, false) => ImuTime::Column,
                    (None, true) => {
                        return Err("a tick_ms IMU column needs --imu-tag".to_owned());
                    }
                    (Some(_), false) => {
                        return Err("--imu-tag needs a tick_ms IMU column".to_owned());
                    }
                };
                Some(ImuInput {
                    csv: csv.clone(),
                    format,
                    time,
                })
            }
        };
        let r = &self.reference;
        let truth = match (&r.truth_pos, r.truth_ubx) {
            (Some(path), _) => TruthInput::Pos {
                path: path.clone(),
                geoid_separation_m: r.geoid_separation_m,
            },
            (None, true) => TruthInput::UbxNavPvt,
            (None, false) => TruthInput::None,
        };
        let gnss = match (&self.ubx, &self.rinex_obs, &self.rinex_nav) {
            (Some(ubx), None, None) => GnssSource::Ubx(ubx.clone()),
            (None, Some(obs), Some(nav)) => GnssSource::Rinex {
                obs: obs.clone(),
                nav: nav.clone(),
            },
            (None, None, None) if self.robot_bag.bag.is_some() => {
                self.robot_bag.source().ok_or("--bag needs a path")?
            }
            _ => return Err("give either --ubx, --rinex-obs with --rinex-nav, or --bag".to_owned()),
        };
        Ok(ConvertOptions {
            gnss,
            imu,
            truth,
            leap_seconds: r.leap_seconds,
            ephemeris: match self.ephemeris {
                EphemerisArg::WholeLog => EphemerisMode::WholeLog,
                EphemerisArg::AsReceived => EphemerisMode::AsReceived,
            },
            ionosphere: self.ionosphere.mode(),
        })
    }
}

impl ConvertArgs {
    /// Every numeric argument within its range (NaN never is).
    ///
    /// Choice of ranges: mounting angles within ±360°; geoid separations within ±120 m
    /// (the EGM2008 undulation spans −107…+86 m); GPS − UTC a whole number of seconds in
    /// 0..=100 (18 since 2017); a receiver-to-host latency up to 10 s.
    fn check_numbers(&self) -> Result<(), String> {
        for angle in &self.imu_to_flu_rpy_deg {
            within("imu-to-flu-rpy-deg", *angle, -360.0, 360.0)?;
        }
        let r = &self.reference;
        within("geoid-separation-m", r.geoid_separation_m, -120.0, 120.0)?;
        within("leap-seconds", r.leap_seconds, 0.0, 100.0)?;
        if r.leap_seconds.fract() != 0.0 {
            return Err(format!(
                "--leap-seconds must be a whole number, got {}",
                r.leap_seconds
            ));
        }
        within("host-latency-s", self.robot_bag.host_latency_s, 0.0, 10.0)?;
        Ok(())
    }
}

/// An error naming argument `--name` unless `value` lies in [lo, hi].
fn within(name: &str, value: f64, lo: f64, hi: f64) -> Result<(), String> {
    if (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(format!("--{name} must lie in [{lo}, {hi}], got {value}"))
    }
}

/// Arguments of `gnss_ins spp`.
#[derive(Args)]
pub struct SppArgs {
    /// A bag with GNSS measurements (and a reference on /ground_truth), or a UBX log
    /// (name ending in .ubx), converted on the fly.
    pub input: PathBuf,
    /// Parameter file whose gnss.* settings (mask, σ model, constellations) are used;
    /// repeatable as for `replay` (a later value wins).
    #[arg(long)]
    pub params: Vec<PathBuf>,
    /// With a UBX log: its reference and time scale (as for `convert`).
    #[command(flatten)]
    pub reference: ReferenceArgs,
    /// With a UBX log: the pseudo-ranges to form (as `convert --ionosphere`).
    #[arg(long, value_enum, default_value_t = IonosphereArg::IonoFree)]
    pub ionosphere: IonosphereArg,
    /// Receiver clocks to solve for.
    #[arg(long, value_enum, default_value_t = ClockArg::Common)]
    pub clock: ClockArg,
    /// Output CSV of the solutions.
    #[arg(long)]
    pub csv: Option<PathBuf>,
}

fn print_convert_summary(out: &std::path::Path, s: &ConvertSummary) {
    eprintln!(
        "wrote {}: {} GNSS epochs ({:.1} satellites each; {} epochs without a usable \
         satellite left out; {:.1} single-frequency satellites per epoch without a range, \
         {:.1} of them kept for their carrier phase; Klobuchar {}), {} IMU samples, reference {:?}; UTC {:.3}..{:.3} s",
        out.display(),
        s.gnss_epochs,
        s.satellites as f64 / s.gnss_epochs.max(1) as f64,
        s.empty_epochs,
        s.single_frequency as f64 / s.gnss_epochs.max(1) as f64,
        s.phase_only as f64 / s.gnss_epochs.max(1) as f64,
        if s.klobuchar { "present" } else { "absent" },
        s.imu_samples,
        s.truth,
        s.span_utc_s.0,
        s.span_utc_s.1
    );
    for (reason, n) in &s.imu_skipped {
        eprintln!("skipped {n} IMU lines: {reason}");
    }
    for (reason, n) in &s.truth_skipped {
        eprintln!("skipped {n} reference lines: {reason}");
    }
    if let Some(bag) = &s.robot_bag {
        print_robot_bag_summary(bag);
    }
}

fn print_robot_bag_summary(s: &RobotBagSummary) {
    let input = match s.input {
        UbxInput::DriverMessages => "UBXRxmRawx/UBXRxmSfrbx messages",
        UbxInput::ByteStream => "the UBX byte stream",
    };
    eprintln!("raw GNSS read from {input}; what the adapter counted:");
    let counts = s.counts.key_values();
    let nonzero: Vec<String> = counts
        .iter()
        .filter(|(_, v)| v != "0")
        .map(|(k, v)| format!("{k} {v}"))
        .collect();
    eprintln!("  {}", nonzero.join(", "));
    let ms = |v: f64| format!("{:.1} ms", v * 1e3);
    match s.clock.receiver_to_host_s {
        Some((mean, jitter)) => eprintln!(
            "  receiver time to host receive stamp: {} (jitter {})",
            ms(mean),
            ms(jitter)
        ),
        None => eprintln!("  receiver time to host receive stamp: unknown"),
    }
    match s.clock.imu_gnss_skew_s {
        Some(skew) => eprintln!(
            "  {}IMU/GNSS stamp skew beyond --host-latency-s: {}",
            if s.clock.skew_exceeded {
                "warning: "
            } else {
                ""
            },
            ms(skew)
        ),
        None => eprintln!("  IMU/GNSS stamp skew: unknown (no IMU message near a GNSS epoch)"),
    }
    if s.read_errors > 0 {
        eprintln!("warning: {} bag read errors (messages lost)", s.read_errors);
    }
}

/// `gnss_ins convert`.
pub fn convert(args: ConvertArgs) -> Result<(), String> {
    let options = args.options()?;
    let progress = Progress::new();
    let summary = convert_files(&options, &args.out, &mut |phase, f| {
        progress.fraction(&format!("convert, {phase}"), f)
    });
    progress.end();
    let summary = summary.map_err(|e| e.to_string())?;
    print_convert_summary(&args.out, &summary);
    if let Some(leap) = summary.receiver_leap_seconds {
        if f64::from(leap) != options.leap_seconds {
            eprintln!(
                "warning: the receiver reports GPS - UTC = {leap} s, --leap-seconds is {} s",
                options.leap_seconds
            );
        }
    }
    Ok(())
}

/// `gnss_ins spp`.
pub fn spp(args: SppArgs) -> Result<(), String> {
    let config = config_from_files(&args.params).map_err(|e| e.to_string())?;
    let progress = Progress::new();
    let is_ubx = args
        .input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ubx"));
    let temp = std::env::temp_dir().join(format!("gnss_ins_spp_{}.mcap", std::process::id()));
    let bag = if is_ubx {
        let convert = ConvertArgs {
            ubx: Some(args.input.clone()),
            rinex_obs: None,
            rinex_nav: None,
            imu_csv: None,
            imu_columns: String::new(),
            imu_accel_unit: AccelUnitArg::G,
            imu_gyro_unit: GyroUnitArg::DegPerS,
            imu_to_flu_rpy_deg: vec![0.0; 3],
            imu_tag: None,
            robot_bag: RobotBagArgs::default(),
            reference: args.reference.clone(),
            ephemeris: EphemerisArg::WholeLog,
            ionosphere: args.ionosphere,
            out: temp.clone(),
        };
        convert_files(&convert.options()?, &temp, &mut |phase, f| {
            progress.fraction(&format!("spp, {phase}"), f)
        })
        .map_err(|e| e.to_string())?;
        temp.clone()
    } else {
        args.input.clone()
    };
    let inputs = bag_spp_inputs(&bag, Some(TRUTH_TOPIC.to_owned())).map_err(|e| e.to_string());
    let per_constellation = args.clock == ClockArg::PerConstellation;
    let report = inputs.map(|inputs| {
        run_spp_with(inputs, &config, per_constellation, |f| {
            progress.fraction("spp", f)
        })
    });
    progress.end();
    if is_ubx {
        // Best effort: a temporary file left behind is harmless.
        let _ = std::fs::remove_file(&temp);
    }
    let report = report?;
    if let Some(path) = &args.csv {
        write_spp_csv(path, &report).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    println!(
        "{} epochs solved, {} not",
        report.rows.len(),
        report.failures.values().sum::<usize>()
    );
    for (reason, n) in &report.failures {
        println!("  {n} epochs: {reason}");
    }
    for (c, (bias_m, n)) in report.mean_inter_system_biases_m() {
        println!("  inter-system bias of {c:?} against the first clock: {bias_m:.3} m mean over {n} epochs");
    }
    println!(
        "{:<14} {:>7} {:>8} {:>12} {:>8} {:>8}",
        "reference", "epochs", "horiz_m", "horiz_demean", "vert_m", "pos3d_m"
    );
    for (label, s) in report.summary_by_label() {
        println!(
            "{:<14} {:>7} {:>8.3} {:>12.3} {:>8.3} {:>8.3}",
            label,
            s.epochs,
            s.pos_rmse_horizontal_m,
            s.pos_rmse_horizontal_offset_removed_m,
            s.pos_rmse_u_m,
            s.pos_rmse_3d_m
        );
    }
    Ok(())
}

/// `gnss_ins spp-rinex`: RINEX 3 observation and navigation files.
#[derive(Args)]
pub struct SppRinexArgs {
    /// RINEX 3 observation file.
    obs: PathBuf,
    /// RINEX 3 navigation file.
    nav: PathBuf,
    /// Output CSV, one line per epoch.
    #[arg(long)]
    out_csv: PathBuf,
    /// Neither ionospheric nor tropospheric delays (rnx2rtkp's command-line default).
    #[arg(long)]
    no_atmosphere: bool,
}

pub fn spp_rinex(args: SppRinexArgs) -> Result<(), String> {
    let options = if args.no_atmosphere {
        RinexSppOptions::rtklib_single(Ionosphere::Off, TroposphereModel::Off)
    } else {
        RinexSppOptions::rtklib_single_brdc_saas()
    };
    let progress = Progress::new();
    let s = solve_rinex_files(&args.obs, &args.nav, &args.out_csv, &options, |f| {
        progress.fraction("spp-rinex", f)
    });
    progress.end();
    let s = s.map_err(|e| e.to_string())?;
    eprintln!(
        "wrote {}: {} of {} epochs solved ({} malformed lines, {} event records skipped)",
        args.out_csv.display(),
        s.solved,
        s.epochs,
        s.malformed_lines,
        s.skipped_records
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::ConvertArgs;

    #[derive(Parser)]
    struct Convert {
        #[command(flatten)]
        args: ConvertArgs,
    }

    fn options_of(extra: &[&str]) -> Result<(), String> {
        let mut argv = vec!["convert", "--ubx", "log.ubx", "--out", "out.mcap"];
        argv.extend_from_slice(extra);
        let parsed = Convert::try_parse_from(argv).map_err(|e| e.to_string())?;
        parsed.args.options().map(|_| ())
    }

    #[test]
    fn numeric_arguments_out_of_range_are_refused() {
        assert_eq!(options_of(&[]), Ok(()));
        assert_eq!(options_of(&["--imu-to-flu-rpy-deg", "180,-90,45"]), Ok(()));
        for bad in [
            ["--imu-to-flu-rpy-deg", "nan,0,0"],
            ["--imu-to-flu-rpy-deg", "0,1e300,0"],
            ["--geoid-separation-m", "nan"],
            ["--geoid-separation-m", "-1e9"],
            ["--leap-seconds", "inf"],
            ["--leap-seconds", "18.5"],
            ["--host-latency-s", "11"],
        ] {
            let err = options_of(&bad).expect_err(&bad.join(" "));
            assert!(err.contains(bad[0]), "{}: {err}", bad.join(" "));
        }
    }
}
