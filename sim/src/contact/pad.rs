//! The pad against the world's objects: which object the pad at a pose presses and how deep
//! (the sim GelSight renders it, the sim arm's crush limit reads it), and the elastic solve
//! of a press at a chosen fidelity, one solver grid (with warm starts) per press.

use crate::contact::{
    ContactError, ContactProblem, ContactSolution, ContactSolver, Fidelity, Grid, ObjectSurface,
    Rect,
};
use crate::mesh::TriMesh;
use crate::world::SimWorld;
use glam::{DQuat, DVec2, DVec3};
use tactex_core::geometry::Pose;
use tactex_core::tactile::spec::{GelSpec, TactileSpec};

/// A press's frames share one solver grid, planned at its first contact for this much more
/// approach: the paper's search rarely runs past 2 mm beyond first touch and its 8 frames
/// span 1.75 mm, so a press is solved on one grid with warm starts.
pub const PRESS_GRID_REACH_MM: f64 = 4.0;
/// Only the object's surface up to this far above the gel plane can meet the gel within a
/// press (mm): the rest of the mesh (its top, far sides) is left out of the solve.
const SURFACE_REACH_MM: f64 = 15.0;
/// How far the sensor's housing, its mount and the wrist reach behind the gel (mm; the
/// 24 + 15 + 110 mm of `render::scene::tool_body`).
const BODY_BEHIND_GEL_MM: f64 = 150.0;
/// Triangles this far beyond the pad's edge are kept, so that a contact cut by the edge is
/// seen to be.
const PAD_MARGIN_MM: f64 = 3.0;

/// The gel pad of a sensor (pad frame, mm): its frame's field of view.
pub fn pad_of(spec: &TactileSpec) -> Rect {
    Rect::centred(DVec2::new(spec.width_px as f64, spec.height_px as f64) * spec.mm_per_px / 2.0)
}

/// The object the pad presses deepest.
#[derive(Clone, Debug)]
pub struct PadTouch {
    /// Index into `SimWorld::objects`.
    pub object: usize,
    /// How far the pad is pushed past first touch (mm).
    pub approach_mm: f64,
    /// Its surface under the pad (pad frame, mm; lowest point at `-approach_mm`).
    pub surface: ObjectSurface,
}

/// `mesh` (world, m) in the pad frame of a pad at `tool` (mm), only the triangles that can
/// meet the gel over `pad`; None when none can.
fn surface_under_pad(mesh: &TriMesh, tool: &Pose, pad: &Rect) -> Option<ObjectSurface> {
    let to_pad = tool.inverse();
    let reach = pad.grown(PAD_MARGIN_MM);
    // Cheap rejection on the world bounding box's corners first.
    let (lo, hi) = mesh.bounds();
    let corners = (0..8).map(|k| {
        let pick = |bit: usize, a: f64, b: f64| if k >> bit & 1 == 0 { a } else { b };
        to_pad.transform_point(DVec3::new(
            pick(0, lo.x, hi.x),
            pick(1, lo.y, hi.y),
            pick(2, lo.z, hi.z),
        )) * 1e3
    });
    let (blo, bhi) = corners.fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(a, b), c| (a.min(c), b.max(c)),
    );
    if bhi.x < reach.min.x || blo.x > reach.max.x || bhi.y < reach.min.y || blo.y > reach.max.y {
        return None;
    }
    // An object wholly behind the sensor's body (a pad turned up over the table, holding a
    // calibration board) is not under the pad, however far its surface lies behind the gel.
    if blo.z > SURFACE_REACH_MM || bhi.z < -BODY_BEHIND_GEL_MM {
        return None;
    }
    let vertices: Vec<DVec3> = mesh
        .vertices
        .iter()
        .map(|v| to_pad.transform_point(*v) * 1e3)
        .collect();
    let triangles: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            let (tlo, thi) = (a.min(b).min(c), a.max(b).max(c));
            tlo.z < SURFACE_REACH_MM
                && thi.x >= reach.min.x
                && tlo.x <= reach.max.x
                && thi.y >= reach.min.y
                && tlo.y <= reach.max.y
        })
        .copied()
        .collect();
    (!triangles.is_empty()).then_some(ObjectSurface::Mesh(TriMesh {
        vertices,
        triangles,
    }))
}

/// The object the pad at `tool` presses deepest, if it presses any.
pub fn deepest_touch(world: &SimWorld, tool: &Pose, pad: &Rect) -> Option<PadTouch> {
    let mut best: Option<PadTouch> = None;
    for (object, o) in world.objects.iter().enumerate() {
        let Some(surface) = surface_under_pad(&o.mesh, tool, pad) else {
            continue;
        };
        let Some(lowest) = surface.lowest_over(pad) else {
            continue;
        };
        let approach_mm = -lowest;
        if approach_mm > 0.0 && best.as_ref().is_none_or(|b| approach_mm > b.approach_mm) {
            best = Some(PadTouch {
                object,
                approach_mm,
                surface,
            });
        }
    }
    best
}

/// Where a press happens: which object, and the pad's place across the descent (its
/// position across the tool axis and its turn). Frames at one spot share a solver grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spot {
    pub object: usize,
    pub across_m: DVec2,
    pub rotation: DQuat,
}

impl Spot {
    /// The spot of a pad at `tool` pressing `object` straight down the world's z.
    pub fn of(object: usize, tool: &Pose) -> Self {
        Self {
            object,
            across_m: tool.position.truncate(),
            rotation: tool.rotation,
        }
    }
}

/// What a press keeps between frames.
#[derive(Clone)]
struct Kept {
    spot: Spot,
    fidelity: Fidelity,
    cell_mm: Option<f64>,
    gel: GelSpec,
    grid: Grid,
    planned_mm: f64,
    previous: ContactSolution,
}

/// A press's solver grid and warm start, kept between its frames (see
/// [`PRESS_GRID_REACH_MM`]): the sim GelSight and the solver-only press protocol both solve
/// through it, so a press is gridded the same way whichever runs it.
#[derive(Clone, Default)]
pub struct PressGrid {
    kept: Option<Kept>,
}

impl PressGrid {
    /// Solves `problem` at `spot`: on the grid of the spot's press while its approach stays
    /// within what that grid was planned for (warm-started from the frame before), else on a
    /// new grid planned [`PRESS_GRID_REACH_MM`] deeper.
    pub fn solve(
        &mut self,
        solver: &mut ContactSolver,
        problem: &ContactProblem,
        fidelity: Fidelity,
        spot: Spot,
    ) -> Result<ContactSolution, ContactError> {
        let kept = self.kept.take().filter(|k| {
            k.spot == spot
                && k.fidelity == fidelity
                && k.cell_mm == problem.cell_mm
                && k.gel == problem.gel
                && problem.approach_mm <= k.planned_mm
        });
        let (grid, planned_mm, previous) = match kept {
            Some(k) => (Some(k.grid), k.planned_mm, Some(k.previous)),
            None => {
                let planned = problem.approach_mm + PRESS_GRID_REACH_MM;
                (solver.plan_grid(problem, fidelity, planned)?, planned, None)
            }
        };
        let solution = solver.solve_on(problem, fidelity, grid, previous.as_ref())?;
        if let Some(grid) = grid {
            self.kept = Some(Kept {
                spot,
                fidelity,
                cell_mm: problem.cell_mm,
                gel: problem.gel,
                grid,
                planned_mm,
                previous: solution.clone(),
            });
        }
        Ok(solution)
    }
}
