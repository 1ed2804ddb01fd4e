//! What a question returns: the answer, each object's report (or why it was not
//! measured), stage timings, and the progress events a live view follows.

use crate::hardness::estimate::{Evidence, ModulusInterval, PressSequence};
use crate::hardness::scale::HardnessReport;
use crate::query::Query;
use crate::tactile::contact::ContactEvidence;
use serde::Serialize;

#[derive(Clone, Debug, Serialize)]
pub struct StageTiming {
    pub stage: String,
    pub wall_ms: Option<f64>,
    pub sim_s: Option<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct ObjectReport {
    pub label: String,
    /// What the fruit asked about are held against ("than the banana on the left"), pressed
    /// for its reading, not asked about itself.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub reference: bool,
    pub detection_score: f64,
    /// Centre estimate: x, y of the refined-mask centroid, z half the top height (it rests on
    /// the table).
    pub position_m: [f64; 3],
    /// The paper's centroid: median of the refined mask's back-projected points.
    pub surface_centroid_m: [f64; 3],
    pub location: String,
    pub hardness: Option<HardnessReport>,
    /// The estimate's 68% and 95% intervals and what they rest on.
    pub interval: Option<ModulusInterval>,
    pub ripeness: Option<String>,
    pub evidence: Option<Evidence>,
    /// Press facts: travel from the search start to the first contact frame, and the contact
    /// criterion's evidence there.
    pub contact_search_mm: Option<f64>,
    pub contact: Option<ContactEvidence>,
    /// Why the object has no hardness, when it has none.
    pub not_measured: Option<NotMeasured>,
    pub warnings: Vec<String>,
}

/// Why an object the camera found was not measured. The rest of the question is answered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NotMeasuredReason {
    /// The contact criterion never fired within the search.
    NoContact,
    /// The arm refused a move of the press (out of its workspace, or past its crush limit).
    ArmRefused,
    /// The first contact frame's imprint crosses the frame's edge: the pad came down beside
    /// the object, and no estimator reads a cut imprint.
    ImprintCut,
    /// The estimator could not read the press.
    Estimator,
    /// A frame of the press (its no-contact reference or a pressed one) carries no shading:
    /// blank, or blown out. Read, it would show a deep imprint everywhere.
    UnreadableFrame,
    /// The press was read, but where the estimator cannot resolve a modulus (its fit failed,
    /// or the object is too soft against the gel): no number is better than a wrong one.
    OutsideCompetence,
}

/// The reason for machines, and the detail for people.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NotMeasured {
    pub reason: NotMeasuredReason,
    pub detail: String,
}

impl NotMeasured {
    pub(super) fn no_contact(travel_mm: f64) -> Self {
        Self {
            reason: NotMeasuredReason::NoContact,
            detail: format!("no contact within {travel_mm} mm of descent"),
        }
    }

    pub(super) fn arm_refused(reason: &str) -> Self {
        Self {
            reason: NotMeasuredReason::ArmRefused,
            detail: format!("the arm refused the press: {reason}"),
        }
    }
}

impl std::fmt::Display for NotMeasured {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.detail)
    }
}

/// What a running question has got to, for a live view: the stage it entered, what the camera
/// found, which object the arm is pressing, and each stage's time as it ends.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Progress {
    StageStarted {
        stage: String,
    },
    Detected {
        objects: Vec<Sighting>,
    },
    Pressing {
        index: usize,
        of: usize,
        label: String,
    },
    Pressed {
        index: usize,
        label: String,
        /// Press frames recorded; 0 when the object could not be pressed.
        frames: usize,
        not_measured: Option<NotMeasured>,
    },
    StageFinished(StageTiming),
}

/// One grounded object as the camera saw it, in the order the arm will press them.
#[derive(Clone, Debug, Serialize)]
pub struct Sighting {
    pub label: String,
    pub score: f64,
    /// x0, y0, x1, y1 in colour-image pixels (inclusive).
    pub bbox: [u32; 4],
    pub position_m: [f64; 3],
}

#[derive(Clone, Debug, Serialize)]
pub struct Answer {
    pub query: Query,
    pub objects: Vec<ObjectReport>,
    pub selected: Vec<usize>,
    pub answer: String,
    pub not_found: Vec<String>,
    pub estimator: String,
    /// The contact criterion every press ran (see `tactile::contact`).
    pub contact_criterion: String,
    /// The twin's contact physics (rigid, hertz, halfspace, layer); None on real or replayed
    /// devices.
    pub fidelity: Option<String>,
    /// The tactile sensor's profile (name and content hash) the presses were rendered or
    /// read through, when one is known.
    pub sensor: Option<crate::tactile::sensor_profile::ProfileId>,
    /// "template", or "llm:<model>" when a model's grounded reply is the answer.
    pub explainer: String,
    /// Why a model's reply was not used, when the template stood in for it.
    pub explain_notice: Option<String>,
    /// "rules", or "llm:<model>" when a model's reading of the prompt is the query.
    pub parser: String,
    /// Why a model's reading was not used, when the rules stood in for it.
    pub parse_notice: Option<String>,
    pub timing: Vec<StageTiming>,
    /// Each object's press (no-contact reference and press frames), in `objects`' order;
    /// None where no contact was found. Left out of the JSON: images belong in image files.
    #[serde(skip)]
    pub presses: Vec<Option<PressSequence>>,
}
