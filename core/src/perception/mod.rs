//! Perception on device frames: RGB-D grounding (detection, mask refinement, depth median,
//! centroids) and tactile helpers (SSIM, markers, surface slopes, the contact circle). All of it works on real
//! frames as well as on the twin's.

pub mod centroid;
pub mod circle_fit;
mod closing;
pub mod colour_name;
pub mod contact;
pub mod contact_circle;
pub mod depth;
pub mod detect;
pub mod grounding;
pub mod height_split;
pub mod marker_grid;
pub mod markers;
pub mod mask;
pub mod neck_split;
pub mod press_site;
pub mod slopes;
pub mod ssim;
