//! `gnss_ins compare --plots DIR`: figures of the filters' errors over time and of the
//! estimated pseudo-range noise σ against the true σ, in the spirit of the ERMAKF paper's
//! Figures 4–8, each as PNG and SVG:
//! - `position_error`: east, north and up position errors (m);
//! - `velocity_error`: east, north and up velocity errors (m/s);
//! - `attitude_error`: roll, pitch and yaw errors (deg);
//! - `noise_sigma`: estimated against true pseudo-range σ (m) of a few satellites.
//!
//! Environment segments other than open sky (foliage, urban canyon, outage) are shaded;
//! for a recording, the reference's quality (RTK fixed, float, worse), each its own
//! shade. A recording's UNIX stamps are shown as seconds since its first, named in UTC.
//!
//! Choice: text is drawn with DejaVu Sans (the `dejavu` crate's copy, Bitstream Vera
//! licence: free to embed and redistribute) through plotters' pure-Rust `ab_glyph`
//! renderer, so the figures need no system font library (freetype, fontconfig). The SVGs
//! name the font family "sans-serif" and leave the text to the viewer.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::eval::SolutionError;
use crate::gnss::SatId;

use super::scoring::SessionReport;

/// Font family name the figures use (registered once, from the embedded DejaVu Sans).
const FONT: &str = "sans-serif";
/// Size of the three-panel figures (px).
const FIGURE_SIZE: (u32, u32) = (1400, 1000);
/// Satellites shown in the noise figure.
const NOISE_SATELLITES: usize = 4;
/// Choice: the y range of an error panel covers this quantile of |error| over all
/// filters (plus a margin), so a start-up transient of one filter does not flatten the
/// rest; lines beyond it are clipped at the panel's edge.
const RANGE_QUANTILE: f64 = 0.995;

/// Colours of the filters, in the order given (Tableau 10, distinguishable in print).
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// One filter's results, as plotted.
#[derive(Debug, Clone)]
pub struct FilterRun {
    /// Filter name (legend).
    pub name: String,
    /// The session's results (error series and σ samples).
    pub report: SessionReport,
}

/// Why the figures could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("{path}: {reason}")]
    Io { path: String, reason: String },
    #[error("{path}: drawing failed: {reason}")]
    Draw { path: String, reason: String },
    #[error("the embedded font could not be loaded")]
    Font,
}

/// A time span in one environment.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentSpan {
    pub start_s: f64,
    pub end_s: f64,
    pub name: String,
}

/// Writes the figures into `dir` (created if needed); returns the files written.
///
/// `progress` is called before each file with the fraction of the files written.
pub fn write_plots(
    dir: &Path,
    runs: &[FilterRun],
    mut progress: impl FnMut(f64),
) -> Result<Vec<PathBuf>, PlotError> {
    register_font()?;
    std::fs::create_dir_all(dir).map_err(|e| PlotError::Io {
        path: dir.display().to_string(),
        reason: e.to_string(),
    })?;
    let spans = runs
        .first()
        .map(|r| environment_spans(&r.report.errors))
        .unwrap_or_default();
    let figures = [
        error_figure(
            "position_error",
            "Position error",
            "m",
            runs,
            |e| Some(e.position_enu_m.into()),
            ["east", "north", "up"],
        ),
        error_figure(
            "velocity_error",
            "Velocity error",
            "m/s",
            runs,
            |e| e.velocity_enu_mps.map(Into::into),
            ["east", "north", "up"],
        ),
        error_figure(
            "attitude_error",
            "Attitude error",
            "deg",
            runs,
            |e| {
                e.attitude_rpy_rad
                    .map(|a| [a[0].to_degrees(), a[1].to_degrees(), a[2].to_degrees()])
            },
            ["roll", "pitch", "yaw"],
        ),
        noise_figure(runs),
    ];
    let mut written = Vec::new();
    // Two files (PNG and SVG) per figure.
    let files = 2 * figures.iter().flatten().count();
    for figure in figures.iter().flatten() {
        progress(written.len() as f64 / files as f64);
        let png = dir.join(format!("{}.png", figure.file_stem));
        let drawn = draw_figure(
            &BitMapBackend::new(&png, FIGURE_SIZE).into_drawing_area(),
            figure,
            &spans,
        );
        drawn.map_err(|reason| PlotError::Draw {
            path: png.display().to_string(),
            reason,
        })?;
        written.push(png);
        progress(written.len() as f64 / files as f64);
        let svg = dir.join(format!("{}.svg", figure.file_stem));
        let drawn = draw_figure(
            &SVGBackend::new(&svg, FIGURE_SIZE).into_drawing_area(),
            figure,
            &spans,
        );
        drawn.map_err(|reason| PlotError::Draw {
            path: svg.display().to_string(),
            reason,
        })?;
        written.push(svg);
    }
    Ok(written)
}

fn register_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular()).is_ok()
            && plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold()).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font)
    }
}

/// One line of a panel.
#[derive(Debug, Clone)]
struct Line {
    label: String,
    color: RGBColor,
    /// Dashed (the reference) or solid.
    dashed: bool,
    points: Vec<(f64, f64)>,
}

/// One panel: a title and its lines.
#[derive(Debug, Clone)]
struct Panel {
    title: String,
    y_label: String,
    lines: Vec<Line>,
    /// Symmetric about zero (errors) or from zero up (σ).
    symmetric: bool,
}

/// A figure of panels stacked vertically.
#[derive(Debug, Clone)]
struct Figure {
    file_stem: &'static str,
    title: String,
    panels: Vec<Panel>,
}

/// The three-panel figure of one error quantity of every run; None when no run has it.
fn error_figure(
    file_stem: &'static str,
    title: &str,
    unit: &str,
    runs: &[FilterRun],
    component: impl Fn(&SolutionError) -> Option<[f64; 3]>,
    names: [&str; 3],
) -> Option<Figure> {
    let panels: Vec<Panel> = (0..3)
        .map(|axis| Panel {
            title: format!("{} {}", names[axis], title.to_lowercase()),
            y_label: format!("{} ({unit})", names[axis]),
            symmetric: true,
            lines: runs
                .iter()
                .enumerate()
                .map(|(i, run)| Line {
                    label: run.name.clone(),
                    color: PALETTE[i % PALETTE.len()],
                    dashed: false,
                    points: run
                        .report
                        .errors
                        .iter()
                        .filter_map(|(_, e)| component(e).map(|c| (e.t_s, c[axis])))
                        .collect(),
                })
                .collect(),
        })
        .collect();
    let any = panels
        .iter()
        .any(|p| p.lines.iter().any(|l| !l.points.is_empty()));
    any.then(|| Figure {
        file_stem,
        title: format!("{title} against the reference"),
        panels,
    })
}

/// The noise figure: per satellite, each filter's estimated pseudo-range σ and the true
/// σ; None without σ samples.
fn noise_figure(runs: &[FilterRun]) -> Option<Figure> {
    let all: Vec<&super::scoring::SigmaSample> =
        runs.iter().flat_map(|r| r.report.sigmas.iter()).collect();
    let sats = busiest_satellites(all.iter().map(|s| s.sat), NOISE_SATELLITES);
    if sats.is_empty() {
        return None;
    }
    let panels = sats
        .iter()
        .map(|sat| {
            let mut lines: Vec<Line> = runs
                .iter()
                .enumerate()
                .map(|(i, run)| Line {
                    label: run.name.clone(),
                    color: PALETTE[i % PALETTE.len()],
                    dashed: false,
                    points: run
                        .report
                        .sigmas
                        .iter()
                        .filter(|s| s.sat == *sat)
                        .map(|s| (s.t_s, s.estimated_sigma_m))
                        .collect(),
                })
                .collect();
            // The truth is the same in every run: take it from the run with most samples.
            let truth: BTreeMap<u64, f64> = all
                .iter()
                .filter(|s| s.sat == *sat)
                .map(|s| ((s.t_s * 1e3).round() as u64, s.true_sigma_m))
                .collect();
            lines.push(Line {
                label: "true σ".to_owned(),
                color: BLACK,
                dashed: true,
                points: truth
                    .into_iter()
                    .map(|(t_ms, sigma)| (t_ms as f64 * 1e-3, sigma))
                    .collect(),
            });
            Panel {
                title: format!("pseudo-range σ of satellite {sat}"),
                y_label: "σ (m)".to_owned(),
                symmetric: false,
                lines,
            }
        })
        .collect();
    Some(Figure {
        file_stem: "noise_sigma",
        title: "Estimated pseudo-range noise σ against the true σ".to_owned(),
        panels,
    })
}

/// The `n` satellites with the most samples (ties by id), in id order.
fn busiest_satellites(sats: impl Iterator<Item = SatId>, n: usize) -> Vec<SatId> {
    let mut counts: BTreeMap<SatId, usize> = BTreeMap::new();
    for sat in sats {
        *counts.entry(sat).or_insert(0) += 1;
    }
    let mut by_count: Vec<(SatId, usize)> = counts.into_iter().collect();
    by_count.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let mut chosen: Vec<SatId> = by_count.into_iter().take(n).map(|(s, _)| s).collect();
    chosen.sort();
    chosen
}

/// The spans of environments other than open sky, from the labelled error series.
pub fn environment_spans(errors: &[(String, SolutionError)]) -> Vec<EnvironmentSpan> {
    let mut spans: Vec<EnvironmentSpan> = Vec::new();
    let mut open: Option<EnvironmentSpan> = None;
    for (name, e) in errors {
        let shaded = !matches!(name.as_str(), "open_sky" | "unlabelled");
        match open.as_mut() {
            Some(span) if span.name == *name => span.end_s = e.t_s,
            _ => {
                spans.extend(open.take());
                if shaded {
                    open = Some(EnvironmentSpan {
                        start_s: e.t_s,
                        end_s: e.t_s,
                        name: name.clone(),
                    });
                }
            }
        }
    }
    spans.extend(open);
    spans
}

/// The `q` quantile of `values` (by rank; None when empty or not all finite).
fn quantile(mut values: Vec<f64>, q: f64) -> Option<f64> {
    if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let rank = ((values.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize;
    values.get(rank).copied()
}

/// The y range of a panel (see [`RANGE_QUANTILE`]).
fn y_range(panel: &Panel) -> Range<f64> {
    let values: Vec<f64> = panel
        .lines
        .iter()
        .flat_map(|l| l.points.iter().map(|p| p.1))
        .filter(|v| v.is_finite())
        .collect();
    let top = quantile(values.iter().map(|v| v.abs()).collect(), RANGE_QUANTILE)
        .filter(|t| *t > 0.0)
        .unwrap_or(1.0)
        * 1.1;
    if panel.symmetric {
        -top..top
    } else {
        0.0..top
    }
}

/// The time range of a figure.
fn x_range(figure: &Figure) -> Range<f64> {
    let times = figure
        .panels
        .iter()
        .flat_map(|p| p.lines.iter().flat_map(|l| l.points.iter().map(|p| p.0)));
    let (lo, hi) = times.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| {
        (lo.min(t), hi.max(t))
    });
    if lo.is_finite() && hi > lo {
        lo..hi
    } else {
        0.0..1.0
    }
}

fn environment_color(name: &str) -> RGBColor {
    match name {
        "foliage" => RGBColor(120, 200, 120),
        "urban_canyon" => RGBColor(160, 160, 200),
        "outage" => RGBColor(230, 120, 120),
        // A real reference's quality: fixed pale, float amber, anything worse lilac.
        "rtk_fixed" => RGBColor(170, 210, 240),
        "rtk_float" => RGBColor(240, 180, 80),
        _ => RGBColor(200, 150, 220),
    }
}

/// Times from this on are UNIX times (1973 on); below, a time line of its own (a scenario's
/// when `compare` simulates it without a bag).
const UNIX_TIME_FROM_S: f64 = 1e8;

/// The time axis of a figure spanning `x`: the offset subtracted from every time and the
/// axis description. UNIX times are shown as seconds since the figure's first whole
/// second, named in UTC (a recording's stamps); smaller times as they are.
fn time_axis(x: &Range<f64>) -> (f64, String) {
    if x.start < UNIX_TIME_FROM_S {
        return (0.0, "time (s)".to_owned());
    }
    let start_s = x.start.floor();
    (
        start_s,
        format!("time since {} UTC (s)", utc_text(start_s as i64)),
    )
}

/// `YYYY-MM-DD hh:mm:ss` of a UNIX time (days to the civil date after H. Hinnant's
/// proleptic Gregorian algorithm).
fn utc_text(unix_s: i64) -> String {
    let (days, second_of_day) = (unix_s.div_euclid(86_400), unix_s.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let day_of_era = z.rem_euclid(146_097);
    let year_of_era =
        (day_of_era - day_of_era / 1_460 + day_of_era / 36_524 - day_of_era / 146_096) / 365;
    let day_of_year = day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
    let mp = (5 * day_of_year + 2) / 153;
    let day = day_of_year - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = year_of_era + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02} {:02}:{:02}:{:02}",
        second_of_day / 3_600,
        second_of_day % 3_600 / 60,
        second_of_day % 60
    )
}

fn draw_figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    figure: &Figure,
    spans: &[EnvironmentSpan],
) -> Result<(), String> {
    let text = |e: &dyn std::fmt::Display| e.to_string();
    root.fill(&WHITE).map_err(|e| text(&e))?;
    let area = root
        .titled(&figure.title, (FONT, 30).into_font().style(FontStyle::Bold))
        .map_err(|e| text(&e))?;
    let (legend_area, area) = area.split_vertically(LEGEND_HEIGHT_PX);
    draw_legend(&legend_area, &legend_entries(figure, spans)).map_err(|e| text(&e))?;
    let panels = area.split_evenly((figure.panels.len(), 1));
    let x = x_range(figure);
    let (t0_s, x_description) = time_axis(&x);
    let x = (x.start - t0_s)..(x.end - t0_s);
    for (k, (panel, region)) in figure.panels.iter().zip(&panels).enumerate() {
        let y = y_range(panel);
        let mut chart = ChartBuilder::on(region)
            .margin(8)
            .caption(&panel.title, (FONT, 22))
            .x_label_area_size(if k + 1 == figure.panels.len() { 45 } else { 25 })
            .y_label_area_size(80)
            .build_cartesian_2d(x.clone(), y.clone())
            .map_err(|e| text(&e))?;
        let decimals = tick_decimals(&y);
        let y_tick = move |v: &f64| tick_label(*v, decimals);
        let mut mesh = chart.configure_mesh();
        mesh.y_desc(&panel.y_label)
            .y_label_formatter(&y_tick)
            .label_style((FONT, 16))
            .axis_desc_style((FONT, 18))
            .light_line_style(WHITE.mix(0.0));
        if k + 1 == figure.panels.len() {
            mesh.x_desc(&x_description);
        }
        mesh.draw().map_err(|e| text(&e))?;
        for span in spans {
            let color = environment_color(&span.name);
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(span.start_s - t0_s, y.start), (span.end_s - t0_s, y.end)],
                    color.mix(SHADE_ALPHA).filled(),
                )))
                .map_err(|e| text(&e))?;
        }
        for line in &panel.lines {
            let style = ShapeStyle::from(&line.color).stroke_width(2);
            for run in split_at_gaps(&line.points) {
                let points = run.iter().map(|&(t_s, v)| (t_s - t0_s, v));
                if line.dashed {
                    chart.draw_series(DashedLineSeries::new(points, 8, 5, style))
                } else {
                    chart.draw_series(LineSeries::new(points, style))
                }
                .map_err(|e| text(&e))?;
            }
        }
    }
    root.present().map_err(|e| text(&e))
}

/// Decimals that tell apart the ticks of `range` (about ten of them).
fn tick_decimals(range: &Range<f64>) -> usize {
    let step = (range.end - range.start).abs() / 10.0;
    if step.is_finite() && step > 0.0 {
        (-step.log10().floor()).clamp(0.0, 6.0) as usize
    } else {
        0
    }
}

/// A tick label with `decimals` decimals, and no "-0.0".
fn tick_label(v: f64, decimals: usize) -> String {
    let text = format!("{v:.decimals$}");
    if text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        text.trim_start_matches('-').to_owned()
    } else {
        text
    }
}

/// Height of the legend row under the title (px).
const LEGEND_HEIGHT_PX: u32 = 36;
/// Opacity of the environment shading.
const SHADE_ALPHA: f64 = 0.25;

/// What a legend entry shows.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Swatch {
    Line,
    Dashed,
    Patch,
}

/// The legend of a figure: its lines (once per label), then the shaded environments.
fn legend_entries(figure: &Figure, spans: &[EnvironmentSpan]) -> Vec<(String, RGBColor, Swatch)> {
    let mut entries: Vec<(String, RGBColor, Swatch)> = Vec::new();
    for line in figure.panels.iter().flat_map(|p| &p.lines) {
        if !entries.iter().any(|(label, _, _)| *label == line.label) {
            let swatch = if line.dashed {
                Swatch::Dashed
            } else {
                Swatch::Line
            };
            entries.push((line.label.clone(), line.color, swatch));
        }
    }
    for span in spans {
        let label = span.name.replace('_', " ");
        if !entries.iter().any(|(l, _, _)| *l == label) {
            entries.push((label, environment_color(&span.name), Swatch::Patch));
        }
    }
    entries
}

/// The legend as one centred row.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, RGBColor, Swatch)],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = TextStyle::from((FONT, 18).into_font());
    let swatch_px = 28;
    let widths: Vec<i32> = entries
        .iter()
        .map(|(label, _, _)| {
            let (w, _) = area.estimate_text_size(label, &font).unwrap_or((100, 18));
            swatch_px + 8 + w as i32 + 24
        })
        .collect();
    let (width, height) = area.dim_in_pixel();
    let mut x = (width as i32 - widths.iter().sum::<i32>()).max(0) / 2;
    let y = height as i32 / 2;
    for ((label, color, swatch), w) in entries.iter().zip(widths) {
        match swatch {
            Swatch::Line => area.draw(&PathElement::new(
                vec![(x, y), (x + swatch_px, y)],
                color.stroke_width(3),
            ))?,
            Swatch::Dashed => {
                for k in 0..3 {
                    let x0 = x + k * 11;
                    area.draw(&PathElement::new(
                        vec![(x0, y), (x0 + 7, y)],
                        color.stroke_width(3),
                    ))?;
                }
            }
            Swatch::Patch => area.draw(&Rectangle::new(
                [(x, y - 9), (x + swatch_px, y + 9)],
                color.mix(SHADE_ALPHA * 1.6).filled(),
            ))?,
        }
        area.draw(&Text::new(
            label.clone(),
            (x + swatch_px + 8, y - 10),
            font.clone(),
        ))?;
        x += w;
    }
    Ok(())
}

/// The points split where the time step exceeds five times the median step (a satellite
/// out of view, a filter not yet started), so a gap is not drawn as a straight line.
fn split_at_gaps(points: &[(f64, f64)]) -> Vec<&[(f64, f64)]> {
    let steps: Vec<f64> = points.windows(2).map(|w| w[1].0 - w[0].0).collect();
    let Some(median) = quantile(steps.clone(), 0.5) else {
        return vec![points];
    };
    let mut runs = Vec::new();
    let mut start = 0;
    for (i, step) in steps.iter().enumerate() {
        if *step > 5.0 * median {
            runs.push(&points[start..=i]);
            start = i + 1;
        }
    }
    runs.push(&points[start..]);
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn error(t_s: f64, east_m: f64) -> SolutionError {
        SolutionError {
            t_s,
            position_enu_m: Vector3::new(east_m, 0.0, 0.0),
            velocity_enu_mps: None,
            attitude_rpy_rad: None,
            nees: 1.0,
            nees_dof: 3,
            position_nees: 1.0,
        }
    }

    #[test]
    fn unix_times_are_shown_from_the_first_second_named_in_utc() {
        let (t0_s, text) = time_axis(&(1_756_315_800.25..1_756_316_400.0));
        assert_eq!(t0_s, 1_756_315_800.0);
        assert_eq!(text, "time since 2025-08-27 17:30:00 UTC (s)");
        assert_eq!(utc_text(0), "1970-01-01 00:00:00");
        assert_eq!(utc_text(951_825_599), "2000-02-29 11:59:59");
        assert_eq!(utc_text(4_107_542_400), "2100-03-01 00:00:00");
        assert_eq!(
            time_axis(&(10_800.0..10_836.0)),
            (0.0, "time (s)".to_owned())
        );
    }

    #[test]
    fn rtk_fixed_float_and_worse_have_their_own_shades() {
        let colors = [
            "rtk_fixed",
            "rtk_float",
            "q5",
            "foliage",
            "urban_canyon",
            "outage",
        ]
        .map(environment_color);
        for (i, a) in colors.iter().enumerate() {
            assert!(colors[i + 1..].iter().all(|b| b != a), "{colors:?}");
        }
    }

    #[test]
    fn spans_cover_each_run_of_a_shaded_environment() {
        let labels = [
            "unlabelled",
            "open_sky",
            "foliage",
            "foliage",
            "open_sky",
            "urban_canyon",
            "urban_canyon",
        ];
        let errors: Vec<(String, SolutionError)> = labels
            .iter()
            .enumerate()
            .map(|(i, l)| (l.to_string(), error(i as f64, 0.0)))
            .collect();
        let spans = environment_spans(&errors);
        assert_eq!(
            spans,
            vec![
                EnvironmentSpan {
                    start_s: 2.0,
                    end_s: 3.0,
                    name: "foliage".to_owned()
                },
                EnvironmentSpan {
                    start_s: 5.0,
                    end_s: 6.0,
                    name: "urban_canyon".to_owned()
                },
            ]
        );
    }

    #[test]
    fn the_error_range_ignores_a_rare_transient() {
        let mut points: Vec<(f64, f64)> = (0..1000).map(|i| (i as f64, (i % 7) as f64)).collect();
        points[3].1 = -500.0;
        let panel = Panel {
            title: String::new(),
            y_label: String::new(),
            symmetric: true,
            lines: vec![Line {
                label: String::new(),
                color: BLACK,
                dashed: false,
                points,
            }],
        };
        let r = y_range(&panel);
        assert!((r.end - 6.6).abs() < 1e-12, "{r:?}");
        assert_eq!(r.start, -r.end);
    }

    #[test]
    fn tick_labels_have_the_decimals_of_the_range_and_no_negative_zero() {
        assert_eq!(tick_decimals(&(-0.6..0.6)), 1);
        assert_eq!(tick_decimals(&(-0.2..0.2)), 2);
        assert_eq!(tick_decimals(&(-18.0..18.0)), 0);
        assert_eq!(tick_label(-0.0001, 1), "0.0");
        assert_eq!(tick_label(-0.25, 2), "-0.25");
        assert_eq!(tick_label(15.0, 0), "15");
    }

    #[test]
    fn lines_break_at_gaps_only() {
        let points: Vec<(f64, f64)> = [0.0, 1.0, 2.0, 3.0, 30.0, 31.0, 32.0]
            .iter()
            .map(|t| (*t, 1.0))
            .collect();
        let runs = split_at_gaps(&points);
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0].len(), 4);
        assert_eq!(runs[1].len(), 3);
        assert_eq!(split_at_gaps(&points[..4]).len(), 1);
        assert_eq!(split_at_gaps(&[]).len(), 1);
    }

    #[test]
    fn the_busiest_satellites_are_chosen() {
        use crate::gnss::Constellation::Gps;
        let sat = |prn| SatId {
            constellation: Gps,
            prn,
        };
        let samples = [3, 1, 3, 2, 3, 2, 5].into_iter().map(sat);
        assert_eq!(busiest_satellites(samples, 2), vec![sat(2), sat(3)]);
    }
}
