//! Randomised press sequences drawn one by one from (seed, index) alone: what `datagen
//! tactile` writes to disk and the Python package's `generate` hands over in memory, through
//! the same code, so that the same seed and index give the same frames and labels.

use crate::app::sample_space::sample_space;
use anyhow::{Context, Result};
use serde::Serialize;
use std::path::Path;
use tactex_core::catalog::FruitCatalog;
use tactex_core::tactile::contact::ContactEvidence;
use tactex_sim::contact::ContactSolver;
use tactex_sim::datagen::press_protocol::PlannedPress;
use tactex_sim::datagen::tactile_sample::{SampleDraw, SampleSpace};
use tactex_sim::render::gel::{CpuRenderer, GelRenderer};

/// Where samples are drawn from: the sample space (shapes, hardness, poses, sensors around
/// one profile), the catalog, and the data set's seed.
pub struct TactileSampleSource {
    pub space: SampleSpace,
    pub catalog: FruitCatalog,
    pub seed: u64,
}

impl TactileSampleSource {
    /// The source `datagen tactile --fidelity F --shapes S [--sensor P] --seed N` draws from.
    pub fn new(
        fidelity: &str,
        shapes: &[String],
        sensor: Option<&Path>,
        seed: u64,
    ) -> Result<Self> {
        // The stock data sets keep their own marker grids; a profile draws around its own.
        let space = match sensor {
            Some(_) => sample_space(fidelity, shapes)?.around(crate::app::load_sensor(sensor)?),
            None => sample_space(fidelity, shapes)?,
        };
        Ok(Self {
            space,
            catalog: FruitCatalog::builtin(),
            seed,
        })
    }

    /// Draws sample `index` and plans its press (redrawing where no contact shows), rendering
    /// it on the CPU here unless `render_here` is false (a batch renderer will).
    pub fn sample(
        &self,
        solver: &mut ContactSolver,
        index: u64,
        render_here: bool,
    ) -> Result<TactileSample> {
        let (draw, press) = self
            .space
            .press(solver, &self.catalog, self.seed, index)
            .with_context(|| format!("sample {index}"))?;
        let images = if render_here {
            Some(press.render(&mut CpuRenderer, &draw.optics())?)
        } else {
            None
        };
        Ok(TactileSample {
            draw,
            press,
            images,
        })
    }
}

/// One sample: what was drawn, the press, and its frames (the no-contact reference first,
/// then the 8 recorded frames) once rendered.
pub struct TactileSample {
    pub draw: SampleDraw,
    pub press: PlannedPress,
    pub images: Option<Vec<image::RgbImage>>,
}

impl TactileSample {
    /// Renders the frames through `renderer` (a GPU batch renderer).
    pub fn render_with(&mut self, renderer: &mut dyn GelRenderer) -> Result<()> {
        self.images = Some(self.press.render(renderer, &self.draw.optics())?);
        Ok(())
    }

    /// The sample's labels and press facts as one JSON line of the data set's manifest,
    /// naming `files`.
    pub fn manifest_line(&self, files: Vec<String>) -> Result<String> {
        let mut text = serde_json::to_string(&self.labels(files))?;
        text.push('\n');
        Ok(text)
    }

    /// The labels and press facts, as the manifest line holds them; with no `files`, the
    /// labels alone (what the Python package hands over with the frames).
    pub fn labels(&self, files: Vec<String>) -> impl Serialize + '_ {
        let f = &self.press.frames;
        ManifestLine {
            files,
            draw: &self.draw,
            search_steps: self.press.search_steps,
            contact: &self.press.contact,
            press: FrameFacts {
                travel_mm: f.iter().map(|x| x.travel_mm).collect(),
                approach_mm: f.iter().map(|x| x.approach_mm).collect(),
                force_n: f.iter().map(|x| x.force_n).collect(),
                contact_radius_mm: f.iter().map(|x| x.contact_radius_mm).collect(),
                gel_max_indentation_mm: f.iter().map(|x| x.gel_max_indentation_mm).collect(),
            },
            warnings: &self.press.warnings,
        }
    }
}

#[derive(Serialize)]
struct FrameFacts {
    travel_mm: Vec<f64>,
    approach_mm: Vec<f64>,
    force_n: Vec<f64>,
    contact_radius_mm: Vec<f64>,
    gel_max_indentation_mm: Vec<f64>,
}

#[derive(Serialize)]
struct ManifestLine<'a> {
    #[serde(skip_serializing_if = "Vec::is_empty")]
    files: Vec<String>,
    #[serde(flatten)]
    draw: &'a SampleDraw,
    search_steps: usize,
    contact: &'a ContactEvidence,
    press: FrameFacts,
    warnings: &'a [String],
}
