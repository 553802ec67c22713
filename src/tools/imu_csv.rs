//! IMU samples from a CSV file, pure parsing: a column map names what each column holds,
//! units are converted to SI, the axes are rotated into the FLU body frame (REP-103), and
//! times come from a GPST column or from a tick column stamped with an RTKLIB time-tag
//! file.
//!
//! Lines that cannot be used (wrong number of fields, a field that is not a finite
//! number, a time that does not increase) are skipped and counted by reason. Empty lines
//! and lines starting with `#` are ignored.

use std::collections::BTreeMap;
use std::str::FromStr;

use nalgebra::{Rotation3, Vector3};

use super::time_tag::TimeTag;

/// Standard gravity (m/s²): the unit "g" of accelerometers.
pub const STANDARD_GRAVITY_M_S2: f64 = 9.806_65;

/// Largest accepted |stretch − 1| between an IMU's tick clock and the logging computer's
/// clock over a recording. Choice: crystal clocks differ by ppm to hundreds of ppm; a
/// percent means the tag and the CSV are not the same recording.
pub const MAX_TICK_STRETCH_ERROR: f64 = 0.01;

/// What one column of the CSV holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImuColumn {
    AccelX,
    AccelY,
    AccelZ,
    GyroX,
    GyroY,
    GyroZ,
    /// A millisecond tick of the IMU's own clock (stamped with a time-tag file).
    TickMs,
    /// GPST seconds since 1970 (GPS scale).
    GpstS,
    /// Not used.
    Skip,
}

impl FromStr for ImuColumn {
    type Err = ImuCsvError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(match s.trim() {
            "ax" => Self::AccelX,
            "ay" => Self::AccelY,
            "az" => Self::AccelZ,
            "gx" => Self::GyroX,
            "gy" => Self::GyroY,
            "gz" => Self::GyroZ,
            "tick_ms" => Self::TickMs,
            "gpst_s" => Self::GpstS,
            "-" | "skip" => Self::Skip,
            other => {
                return Err(ImuCsvError::UnknownColumn {
                    name: other.to_owned(),
                })
            }
        })
    }
}

/// Unit of the accelerometer columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AccelUnit {
    /// Standard gravities ([`STANDARD_GRAVITY_M_S2`]).
    G,
    MetresPerSecond2,
}

/// Unit of the gyro columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GyroUnit {
    DegPerS,
    RadPerS,
}

/// Why an IMU CSV or its format cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImuCsvError {
    #[error("unknown IMU column '{name}' (known: ax ay az gx gy gz tick_ms gpst_s -)")]
    UnknownColumn { name: String },
    #[error("the IMU column map must name each of ax ay az gx gy gz once and one time column (tick_ms or gpst_s); got {spec}")]
    IncompleteColumns { spec: String },
    #[error("no usable IMU line")]
    NoSamples,
    #[error("IMU ticks span {span_ms} ms: cannot stretch them onto the time tag")]
    ZeroSpan { span_ms: f64 },
    #[error("the IMU ticks span {ticks_s} s but the time tag {tag_s} s: not the same recording")]
    SpanMismatch { ticks_s: f64, tag_s: f64 },
    #[error("the IMU CSV has a {found} time column; {needed} needed")]
    WrongTimeColumn {
        found: &'static str,
        needed: &'static str,
    },
}

/// Format of an IMU CSV.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuCsvFormat {
    pub columns: Vec<ImuColumn>,
    pub accel_unit: AccelUnit,
    pub gyro_unit: GyroUnit,
    /// Rotation taking IMU-axis vectors into the FLU body frame.
    pub imu_to_flu: Rotation3<f64>,
}

impl ImuCsvFormat {
    /// A format from a comma-separated column map (e.g. "ax,ay,az,gx,gy,gz,tick_ms") and
    /// the IMU-to-FLU rotation as roll, pitch, yaw (deg) composed R = Rz(yaw)·Ry(pitch)·Rx(roll),
    /// as the `mounting.imu_rotation_rpy_deg` parameter.
    pub fn new(
        columns: &str,
        accel_unit: AccelUnit,
        gyro_unit: GyroUnit,
        imu_to_flu_rpy_deg: [f64; 3],
    ) -> Result<Self, ImuCsvError> {
        let parsed = columns
            .split(',')
            .map(ImuColumn::from_str)
            .collect::<Result<Vec<_>, _>>()?;
        let once = |c: ImuColumn| parsed.iter().filter(|&&x| x == c).count() == 1;
        let times = parsed
            .iter()
            .filter(|c| matches!(c, ImuColumn::TickMs | ImuColumn::GpstS))
            .count();
        let axes = [
            ImuColumn::AccelX,
            ImuColumn::AccelY,
            ImuColumn::AccelZ,
            ImuColumn::GyroX,
            ImuColumn::GyroY,
            ImuColumn::GyroZ,
        ];
        if !axes.into_iter().all(once) || times != 1 {
            return Err(ImuCsvError::IncompleteColumns {
                spec: columns.to_owned(),
            });
        }
        let [r, p, y] = imu_to_flu_rpy_deg.map(f64::to_radians);
        Ok(Self {
            columns: parsed,
            accel_unit,
            gyro_unit,
            imu_to_flu: Rotation3::from_euler_angles(r, p, y),
        })
    }

    fn time_column(&self) -> TimeColumn {
        if self.columns.contains(&ImuColumn::TickMs) {
            TimeColumn::TickMs
        } else {
            TimeColumn::GpstS
        }
    }
}

/// Which time the rows carry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeColumn {
    TickMs,
    GpstS,
}

impl TimeColumn {
    fn name(self) -> &'static str {
        match self {
            Self::TickMs => "tick_ms",
            Self::GpstS => "gpst_s",
        }
    }
}

/// One usable line: its time column and the FLU body-frame vectors in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuRow {
    /// The time column (ms tick or GPST s, see [`ImuCsv::time_column`]).
    pub time: f64,
    pub f_flu_m_s2: Vector3<f64>,
    pub w_flu_rad_s: Vector3<f64>,
}

/// The usable lines of a CSV and what was skipped.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuCsv {
    pub rows: Vec<ImuRow>,
    pub time_column: TimeColumn,
    /// Skipped lines by reason.
    pub skipped: BTreeMap<&'static str, usize>,
}

/// Parses `text` in `format`.
pub fn parse_imu_csv(text: &str, format: &ImuCsvFormat) -> ImuCsv {
    let accel_scale = match format.accel_unit {
        AccelUnit::G => STANDARD_GRAVITY_M_S2,
        AccelUnit::MetresPerSecond2 => 1.0,
    };
    let gyro_scale = match format.gyro_unit {
        GyroUnit::DegPerS => 1f64.to_radians(),
        GyroUnit::RadPerS => 1.0,
    };
    let mut out = ImuCsv {
        rows: Vec::new(),
        time_column: format.time_column(),
        skipped: BTreeMap::new(),
    };
    for line in text.lines() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        match parse_line(line, format) {
            Err(reason) => *out.skipped.entry(reason).or_insert(0) += 1,
            Ok((time, f, w)) => {
                if out.rows.last().is_some_and(|last| time <= last.time) {
                    *out.skipped.entry("time not increasing").or_insert(0) += 1;
                    continue;
                }
                out.rows.push(ImuRow {
                    time,
                    f_flu_m_s2: format.imu_to_flu * (f * accel_scale),
                    w_flu_rad_s: format.imu_to_flu * (w * gyro_scale),
                });
            }
        }
    }
    out
}

type Parsed = (f64, Vector3<f64>, Vector3<f64>);

fn parse_line(line: &str, format: &ImuCsvFormat) -> Result<Parsed, &'static str> {
    let fields: Vec<&str> = line.split(',').collect();
    if fields.len() != format.columns.len() {
        return Err("wrong number of fields");
    }
    let mut f = Vector3::zeros();
    let mut w = Vector3::zeros();
    let mut time = f64::NAN;
    for (column, field) in format.columns.iter().zip(fields) {
        if *column == ImuColumn::Skip {
            continue;
        }
        let v: f64 = field.trim().parse().map_err(|_| "not a number")?;
        if !v.is_finite() {
            return Err("not finite");
        }
        match column {
            ImuColumn::AccelX => f[0] = v,
            ImuColumn::AccelY => f[1] = v,
            ImuColumn::AccelZ => f[2] = v,
            ImuColumn::GyroX => w[0] = v,
            ImuColumn::GyroY => w[1] = v,
            ImuColumn::GyroZ => w[2] = v,
            ImuColumn::TickMs | ImuColumn::GpstS => time = v,
            ImuColumn::Skip => {}
        }
    }
    Ok((time, f, w))
}

/// GPST seconds of tick-stamped rows by the RTKLIB time tag of the CSV: GPST = tag start +
/// (tick − first tick) / 1000 · s, the stretch s chosen so that the last row lands on the
/// tag's last record (the IMU's tick clock and the logging computer's clock run at
/// slightly different rates; the tag records when the computer received the bytes).
pub fn gpst_from_tag(csv: &ImuCsv, tag: &TimeTag) -> Result<Vec<f64>, ImuCsvError> {
    if csv.time_column != TimeColumn::TickMs {
        return Err(ImuCsvError::WrongTimeColumn {
            found: csv.time_column.name(),
            needed: TimeColumn::TickMs.name(),
        });
    }
    let (Some(first), Some(last)) = (csv.rows.first(), csv.rows.last()) else {
        return Err(ImuCsvError::NoSamples);
    };
    let span_ms = last.time - first.time;
    let tag_ms = tag.last().map_or(0.0, |r| f64::from(r.tick_ms));
    if span_ms <= 0.0 {
        return Err(ImuCsvError::ZeroSpan { span_ms });
    }
    let stretch = tag_ms / span_ms;
    if (stretch - 1.0).abs() > MAX_TICK_STRETCH_ERROR {
        return Err(ImuCsvError::SpanMismatch {
            ticks_s: span_ms * 1e-3,
            tag_s: tag_ms * 1e-3,
        });
    }
    Ok(csv
        .rows
        .iter()
        .map(|r| tag.start_gpst_s + (r.time - first.time) * 1e-3 * stretch)
        .collect())
}

/// GPST seconds of rows that carry them.
pub fn gpst_from_column(csv: &ImuCsv) -> Result<Vec<f64>, ImuCsvError> {
    if csv.time_column != TimeColumn::GpstS {
        return Err(ImuCsvError::WrongTimeColumn {
            found: csv.time_column.name(),
            needed: TimeColumn::GpstS.name(),
        });
    }
    if csv.rows.is_empty() {
        return Err(ImuCsvError::NoSamples);
    }
    Ok(csv.rows.iter().map(|r| r.time).collect())
}

#[cfg(test)]
mod tests {
    use super::super::time_tag::TagRecord;
    use super::*;

    fn walk_format() -> ImuCsvFormat {
        ImuCsvFormat::new(
            "ax,ay,az,gx,gy,gz,tick_ms",
            AccelUnit::G,
            GyroUnit::DegPerS,
            [0.0, 0.0, 90.0],
        )
        .unwrap()
    }

    #[test]
    fn converts_units_rotates_axes_and_counts_bad_lines() {
        let text = "0.007,1.011,0.038,-0.160,0.160,3326339\n\
                    1.0,0.0,1.0,0.0,90.0,0.0,1000\n\
                    # comment\n\
                    0.0,1.0,1.0,nan,0.0,0.0,1006\n\
                    0.0,1.0,1.0,x,0.0,0.0,1006\n\
                    0.0,1.0,1.0,0.0,0.0,0.0,1000\n\
                    0.0,1.0,1.0,0.0,0.0,0.0,1012\n";
        let csv = parse_imu_csv(text, &walk_format());
        assert_eq!(csv.rows.len(), 2);
        assert_eq!(csv.skipped.get("wrong number of fields"), Some(&1));
        assert_eq!(csv.skipped.get("not finite"), Some(&1));
        assert_eq!(csv.skipped.get("not a number"), Some(&1));
        assert_eq!(csv.skipped.get("time not increasing"), Some(&1));
        // Rz(90°): IMU x -> FLU left, IMU y -> FLU backward.
        let r = &csv.rows[0];
        let g = STANDARD_GRAVITY_M_S2;
        assert!((r.f_flu_m_s2 - Vector3::new(0.0, g, g)).norm() < 1e-12);
        assert!((r.w_flu_rad_s - Vector3::new(-90f64.to_radians(), 0.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn tag_stretches_ticks_onto_its_last_record() {
        let csv = parse_imu_csv(
            "0,0,1,0,0,0,5000\n0,0,1,0,0,0,6000\n0,0,1,0,0,0,7000\n",
            &walk_format(),
        );
        let tag = TimeTag {
            open_tick_ms: 0,
            start_gpst_s: 100.5,
            records: vec![TagRecord {
                tick_ms: 2002,
                byte_offset: 0,
            }],
            trailing_bytes: 0,
        };
        let t = gpst_from_tag(&csv, &tag).unwrap();
        assert_eq!(t[0], 100.5);
        assert!((t[1] - 101.501).abs() < 1e-9 && (t[2] - 102.502).abs() < 1e-9);
        let far = TimeTag {
            records: vec![TagRecord {
                tick_ms: 3000,
                byte_offset: 0,
            }],
            ..tag
        };
        assert!(matches!(
            gpst_from_tag(&csv, &far),
            Err(ImuCsvError::SpanMismatch { .. })
        ));
        assert!(gpst_from_column(&csv).is_err());
    }

    #[test]
    fn column_map_must_be_complete() {
        let bad = ImuCsvFormat::new(
            "ax,ay,az,gx,gy,gz",
            AccelUnit::G,
            GyroUnit::DegPerS,
            [0.0; 3],
        );
        assert!(matches!(bad, Err(ImuCsvError::IncompleteColumns { .. })));
        let unknown = ImuCsvFormat::new("ax,q", AccelUnit::G, GyroUnit::DegPerS, [0.0; 3]);
        assert!(matches!(unknown, Err(ImuCsvError::UnknownColumn { .. })));
    }
}
