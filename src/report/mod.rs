//! What the commands write: files that appear whole or not at all (`output`), plots
//! (`plot`), NumPy archives (`npz`), comparison images, overlay colours and summaries.

pub mod indentation_view;
#[cfg(feature = "npz")]
pub mod npz;
pub mod output;
pub mod palette;
#[cfg(feature = "plots")]
pub mod plot;
pub mod provenance;
pub mod side_by_side;
pub mod summary;
pub mod tail;
