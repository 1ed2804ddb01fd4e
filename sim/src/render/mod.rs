//! Image synthesis: `gel` (GelSight frames from the gel's fields) and `scene` (RGB-D frames
//! of the table), each with a CPU reference and a wgpu path under one contract; `device`
//! chooses between them.

pub mod board_view;
pub mod device;
pub mod gel;
pub mod scene;
