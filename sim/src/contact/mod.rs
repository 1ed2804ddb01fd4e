//! Elastic soft contact of the GelSight gel with an object: one interface, four fidelity
//! levels that trade speed for accuracy (see docs/design.md, "The elastic contact model").
//!
//! * `rigid`: the object's heightmap clipped at the gel surface and smoothed, the gel taking
//!   the whole approach (what TACTO, Taxim and FOTS do); pressure from a Winkler bed
//!   p = E_gel w / h. Hardness-blind: the baseline to beat.
//! * `hertz`: the equivalent sphere at the lowest point, Hertz pressure, each body taking its
//!   compliance share of the approach.
//! * `halfspace`: frictionless contact of any shape, both bodies half-spaces of composite
//!   compliance, solved by Polonsky-Keer conjugate gradient with DC-FFT.
//! * `layer`: as `halfspace` with the gel a layer of finite thickness bonded to the rigid
//!   acrylic, which stiffens it and makes its surface move outward around the contact.
//!
//! Units: mm, MPa, N. The solver grid covers only where the object dips below the gel
//! surface plus a margin; `fields_over` extends the gel's displacement to any part of the pad.

//! One file per level: `rigid`, `hertz`, and `elastic` for `halfspace` and `layer` (one
//! Polonsky-Keer solve over two kernels, see `kernels` and `influence`). `solver` plans the
//! grid and dispatches; `problem` and `solution` are what goes in and comes out.

pub mod convolution;
mod elastic;
mod fidelity;
pub mod grid;
pub mod hertz;
pub mod influence;
pub mod kernels;
pub mod pad;
pub mod polonsky_keer;
mod problem;
mod rigid;
mod solution;
mod solver;
pub mod surface;
mod warm_start;

pub use fidelity::Fidelity;
pub use grid::{Grid, Rect};
pub use problem::{ContactError, ContactProblem};
pub use rigid::RIGID_SMOOTHING_MM;
pub use solution::{ContactSolution, GelFields};
pub use solver::{
    ContactSolver, DEFAULT_CELLS_ACROSS, DEFAULT_MAX_CELLS, MAX_CELLS, field_pooling,
};
pub use surface::{HeightMap, ObjectSurface, mesh_top};
