//! PNG plots (plotters, bitmap backend, with an embedded font so that they render the same
//! on any machine).

use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
use std::path::Path;
use std::sync::Once;

static FONT: Once = Once::new();

fn register() {
    FONT.call_once(|| {
        // The embedded DejaVu Sans (assets/fonts/README.md) under the family plotters asks for.
        let bytes: &'static [u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
        if register_font("sans-serif", FontStyle::Normal, bytes).is_err() {
            eprintln!("warning: embedded font rejected; plot text may be missing");
        }
    });
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
    register();
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
    let tmp = path.with_extension("partial.png");
    {
        let root = BitMapBackend::new(&tmp, (1000, 700)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let mut chart = ChartBuilder::on(&root)
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
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 16))
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    std::fs::rename(&tmp, path).with_context(|| format!("{}: cannot write", path.display()))
}
