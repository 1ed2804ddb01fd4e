//! PNG plots (plotters, bitmap backend, with an embedded font so that they render the same
//! on any machine).

use anyhow::{Context, Result, anyhow};
use plotters::coord::{CoordTranslate, Shift};
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
use std::path::Path;
use std::sync::Once;

static FONT: Once = Once::new();

fn register() {
    FONT.call_once(|| {
        // The embedded DejaVu Sans (assets/fonts/README.md) under the family plotters asks for.
        let bytes: &'static [u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
        if register_font("sans-serif", FontStyle::Normal, bytes).is_err() {
            eprintln!("warning: embedded font rejected; plot text may be missing");
        }
    });
}

/// Draws a chart of `size` pixels on white and writes it to `path` whole: into a partial
/// file beside it, renamed over it once drawn, and removed if drawing fails.
fn write_png(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<()>,
) -> Result<()> {
    register();
    let tmp = path.with_extension("partial.png");
    let drawn = (|| {
        let root = BitMapBackend::new(&tmp, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        draw(&root)?;
        root.present().map_err(|e| anyhow!("{e}"))
    })();
    if let Err(e) = drawn {
        let _ = std::fs::remove_file(&tmp);
        return Err(e.context(format!("{}: cannot draw", path.display())));
    }
    std::fs::rename(&tmp, path).with_context(|| format!("{}: cannot write", path.display()))
}

/// The series legend, boxed on white, where the chart has room for it.
fn legend<'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, CT>,
    position: SeriesLabelPosition,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()
        .map_err(|e| anyhow!("{e}"))
}

/// One point of a Pareto plot.
pub struct ParetoPoint {
    pub series: String,
    pub label: String,
    pub x: f64,
    pub y: f64,
}

const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];

/// Log-log scatter of cost against error, one colour per series, each point labelled.
pub fn pareto(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    points: &[ParetoPoint],
) -> Result<()> {
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let xs: Vec<f64> = points
        .iter()
        .map(|p| p.x)
        .filter(|v| positive(*v))
        .collect();
    let ys: Vec<f64> = points
        .iter()
        .map(|p| p.y)
        .filter(|v| positive(*v))
        .collect();
    anyhow::ensure!(!xs.is_empty() && !ys.is_empty(), "nothing to plot");
    let range = |v: &[f64]| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(0.0, f64::max);
        (lo / 2.0)..(hi * 2.0)
    };
    // Errors of exactly zero (the reference itself) sit on the floor of the axis.
    let y_range = range(&ys);
    let floor = y_range.start;
    write_png(path, (1000, 700), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 26))
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(range(&xs).log_scale(), y_range.log_scale())
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style(("sans-serif", 16))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        let mut series: Vec<&str> = Vec::new();
        for p in points {
            if !series.contains(&p.series.as_str()) {
                series.push(&p.series);
            }
        }
        for (k, name) in series.iter().enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            let mine: Vec<&ParetoPoint> = points.iter().filter(|p| p.series == *name).collect();
            chart
                .draw_series(mine.iter().filter(|p| positive(p.x)).map(|p| {
                    let y = if positive(p.y) { p.y } else { floor };
                    EmptyElement::at((p.x, y))
                        + Circle::new((0, 0), 6, colour.filled())
                        + Text::new(p.label.clone(), (8, -14), ("sans-serif", 14))
                }))
                .map_err(|e| anyhow!("{e}"))?
                .label(*name)
                .legend(move |(x, y)| Circle::new((x, y), 6, colour.filled()));
        }
        legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
        Ok(())
    })
}

/// One estimator's (true, predicted) pairs.
pub struct ScatterSeries {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// Predicted against true on equal axes over `range`, with the identity line: the paper's
/// Fig. 5.
pub fn predicted_vs_true(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    range: [f64; 2],
    series: &[ScatterSeries],
) -> Result<()> {
    write_png(path, (900, 800), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 24))
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(range[0]..range[1], range[0]..range[1])
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style(("sans-serif", 16))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .draw_series(LineSeries::new(
                [(range[0], range[0]), (range[1], range[1])],
                BLACK.mix(0.5).stroke_width(2),
            ))
            .map_err(|e| anyhow!("{e}"))?
            .label("identity")
            .legend(|(x, y)| PathElement::new([(x - 10, y), (x + 10, y)], BLACK.mix(0.5)));
        let clamp = |v: f64| v.clamp(range[0], range[1]);
        for (k, s) in series.iter().enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            chart
                .draw_series(
                    s.points
                        .iter()
                        .map(|(t, p)| Circle::new((clamp(*t), clamp(*p)), 5, colour.filled())),
                )
                .map_err(|e| anyhow!("{e}"))?
                .label(s.name.clone())
                .legend(move |(x, y)| Circle::new((x, y), 5, colour.filled()));
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
        Ok(())
    })
}

/// One labelled group of values (a fruit's ripeness stage).
pub struct StageGroup {
    pub label: String,
    pub values: Vec<f64>,
    /// The true value, drawn as a black bar.
    pub truth: Option<f64>,
}

/// Each group's values as dots beside a box from its 25th to 75th percentile with a line at
/// the median (and the true value as a black bar): the spread behind a table of medians and
/// IQRs.
pub fn stage_groups(path: &Path, title: &str, y_label: &str, groups: &[StageGroup]) -> Result<()> {
    anyhow::ensure!(!groups.is_empty(), "nothing to plot");
    let all: Vec<f64> = groups
        .iter()
        .flat_map(|g| g.values.iter().copied().chain(g.truth))
        .collect();
    let lo = all.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let pad = ((hi - lo) * 0.08).max(1.0);
    let n = groups.len();
    let width = (200 + 110 * n as u32).max(900);
    write_png(path, (width, 650), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 22))
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(-0.5..n as f64 - 0.5, (lo - pad)..(hi + pad))
            .map_err(|e| anyhow!("{e}"))?;
        let labels: Vec<String> = groups.iter().map(|g| g.label.clone()).collect();
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n)
            .x_label_formatter(&|x| {
                let k = x.round();
                if (x - k).abs() < 1e-6 && k >= 0.0 && (k as usize) < labels.len() {
                    labels[k as usize].clone()
                } else {
                    String::new()
                }
            })
            .x_label_style(("sans-serif", 15))
            .y_desc(y_label)
            .label_style(("sans-serif", 16))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        for (k, g) in groups.iter().enumerate() {
            let x = k as f64;
            let colour = PALETTE[k % PALETTE.len()];
            let q = |p: f64| tactex_core::stats::quantile(&g.values, p);
            let (q25, q50, q75) = (q(0.25)?, q(0.5)?, q(0.75)?);
            chart
                .draw_series([Rectangle::new(
                    [(x - 0.3, q25), (x + 0.3, q75)],
                    colour.mix(0.25).filled(),
                )])
                .map_err(|e| anyhow!("{e}"))?;
            chart
                .draw_series([PathElement::new(
                    [(x - 0.3, q50), (x + 0.3, q50)],
                    colour.stroke_width(3),
                )])
                .map_err(|e| anyhow!("{e}"))?;
            if let Some(t) = g.truth {
                chart
                    .draw_series([PathElement::new(
                        [(x - 0.4, t), (x + 0.4, t)],
                        BLACK.stroke_width(2),
                    )])
                    .map_err(|e| anyhow!("{e}"))?;
            }
            // Dots spread evenly across the box so that equal values stay visible.
            let m = g.values.len().max(2) as f64;
            chart
                .draw_series(g.values.iter().enumerate().map(|(i, v)| {
                    let dx = -0.25 + 0.5 * i as f64 / (m - 1.0);
                    Circle::new((x + dx, *v), 3, colour.filled())
                }))
                .map_err(|e| anyhow!("{e}"))?;
        }
        Ok(())
    })
}

/// One named series of a bar chart: a value per category.
pub struct BarSeries {
    pub name: String,
    pub values: Vec<f64>,
}

/// Bars per category, one per series side by side (`stacked` false: success rates of
/// detectors per tier) or piled up (`stacked` true: latency stages adding up to the total).
pub fn bars(
    path: &Path,
    title: &str,
    y_label: &str,
    categories: &[String],
    series: &[BarSeries],
    stacked: bool,
) -> Result<()> {
    anyhow::ensure!(
        !categories.is_empty() && !series.is_empty(),
        "nothing to plot"
    );
    let n = categories.len();
    let top = (0..n)
        .map(|c| {
            let column = series
                .iter()
                .map(|s| s.values.get(c).copied().unwrap_or(0.0));
            if stacked {
                column.sum::<f64>()
            } else {
                column.fold(0.0, f64::max)
            }
        })
        .fold(0.0, f64::max);
    let top = if top > 0.0 { top * 1.25 } else { 1.0 };
    let width = (260 + 150 * n as u32).max(900);
    write_png(path, (width, 600), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 22))
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(-0.5..n as f64 - 0.5, 0.0..top)
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n)
            .x_label_formatter(&|x| {
                let k = x.round();
                if (x - k).abs() < 1e-6 && k >= 0.0 && (k as usize) < n {
                    categories[k as usize].clone()
                } else {
                    String::new()
                }
            })
            .x_label_style(("sans-serif", 15))
            .y_desc(y_label)
            .label_style(("sans-serif", 16))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        let m = series.len() as f64;
        let mut base = vec![0.0; n];
        for (k, s) in series.iter().enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            let rects: Vec<_> = s
                .values
                .iter()
                .take(n)
                .enumerate()
                .map(|(c, v)| {
                    let x = c as f64;
                    let (x0, x1, y0) = if stacked {
                        (x - 0.3, x + 0.3, base[c])
                    } else {
                        let w = 0.7 / m;
                        (
                            x - 0.35 + w * k as f64,
                            x - 0.35 + w * (k as f64 + 1.0),
                            0.0,
                        )
                    };
                    if stacked {
                        base[c] += v;
                    }
                    Rectangle::new([(x0, y0), (x1, y0 + v)], colour.filled())
                })
                .collect();
            chart
                .draw_series(rects)
                .map_err(|e| anyhow!("{e}"))?
                .label(s.name.clone())
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 6), (x + 12, y + 6)], colour.filled())
                });
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)
    })
}

/// One line of `lines_log_y`: its name and points (x, y), y above 0.
pub struct PlotLine {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// Lines with markers over a logarithmic y axis, one colour per series (errors that fall by
/// orders of magnitude, such as a calibration's against its number of stations).
pub fn lines_log_y(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[PlotLine],
) -> Result<()> {
    let all: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .filter(|(x, y)| x.is_finite() && y.is_finite() && *y > 0.0)
        .collect();
    anyhow::ensure!(!all.is_empty(), "nothing to plot");
    let (x_lo, x_hi) = all
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.0), hi.max(p.0))
        });
    let (y_lo, y_hi) = all
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        });
    let pad = ((x_hi - x_lo) * 0.05).max(0.5);
    write_png(path, (900, 600), |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 22))
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(x_lo - pad..x_hi + pad, (y_lo / 1.5..y_hi * 1.5).log_scale())
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{}", significant(*y, 2)))
            .label_style(("sans-serif", 16))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        for (k, s) in series.iter().enumerate() {
            let colour = PALETTE[k % PALETTE.len()];
            let points: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|(x, y)| x.is_finite() && y.is_finite() && *y > 0.0)
                .collect();
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(|e| anyhow!("{e}"))?
                .label(s.name.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2))
                });
            chart
                .draw_series(points.iter().map(|p| Circle::new(*p, 4, colour.filled())))
                .map_err(|e| anyhow!("{e}"))?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)
    })
}

/// `v` rounded to `digits` significant digits (a log axis' tick: 0.3, not 0.30000000000000004).
fn significant(v: f64, digits: i32) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(digits - 1 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}
