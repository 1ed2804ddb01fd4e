//! The arm's end as the scene camera sees it: the GelSight's housing above the gel, the
//! flange it is mounted on and the wrist link above, in approximate sizes (the camera needs
//! the extent they occlude the table by, not their detail). They carry instance id 0: the
//! arm is not an object a question is about.

use super::geometry::{SceneTriangle, flat_quad};
use glam::DVec3;
use tactex_core::geometry::Pose;

/// The sensor's housing (GelSight Mini, about 32 x 28 mm across, 24 mm from the gel up).
const HOUSING_MM: [f64; 3] = [32.0, 28.0, 24.0];
const HOUSING_COLOR: [f64; 3] = [0.07, 0.07, 0.08];
/// The mounting adapter and the arm's tool flange: a cylinder of 63 mm across, 15 mm tall.
const FLANGE_RADIUS_MM: f64 = 31.5;
const FLANGE_MM: f64 = 15.0;
const FLANGE_COLOR: [f64; 3] = [0.55, 0.56, 0.58];
/// The last link of the wrist above the flange: white, 75 mm across, the 110 mm of it
/// nearest the flange.
const WRIST_RADIUS_MM: f64 = 37.5;
const WRIST_MM: f64 = 110.0;
const WRIST_COLOR: [f64; 3] = [0.86, 0.86, 0.84];
/// Sides of a cylinder's prism: 2 mm from a true circle at the wrist's radius.
const CYLINDER_SIDES: usize = 24;

/// The triangles of the arm's end at the pad's pose `tool` (the gel's centre, tool z
/// pointing out of the gel at what it presses), world frame.
pub(super) fn tool_triangles(tool: &Pose) -> Vec<SceneTriangle> {
    let mut out = Vec::new();
    let [hx, hy, hz] = HOUSING_MM.map(|v| v * 1e-3);
    // The body rises from the gel along the tool's -z.
    cuboid(
        [-hx / 2.0, -hy / 2.0, -hz],
        [hx / 2.0, hy / 2.0, 0.0],
        HOUSING_COLOR,
        &mut out,
    );
    let flange_top = -hz - FLANGE_MM * 1e-3;
    cylinder(
        FLANGE_RADIUS_MM * 1e-3,
        flange_top,
        -hz,
        FLANGE_COLOR,
        &mut out,
    );
    let wrist_top = flange_top - WRIST_MM * 1e-3;
    cylinder(
        WRIST_RADIUS_MM * 1e-3,
        wrist_top,
        flange_top,
        WRIST_COLOR,
        &mut out,
    );
    for t in &mut out {
        t.p = t.p.map(|p| tool.transform_point(p));
        t.n = t.n.map(|n| tool.transform_vector(n).normalize_or(DVec3::Z));
    }
    out
}

/// An axis-aligned box between corners `lo` and `hi` (tool frame, m).
fn cuboid(lo: [f64; 3], hi: [f64; 3], color: [f64; 3], out: &mut Vec<SceneTriangle>) {
    let at = |x: usize, y: usize, z: usize| {
        DVec3::new([lo[0], hi[0]][x], [lo[1], hi[1]][y], [lo[2], hi[2]][z])
    };
    for axis in 0..3 {
        for side in 0..2 {
            // The face where coordinate `axis` is at `side`, its corners round the other two.
            let corner = |a: usize, b: usize| {
                let mut c = [0; 3];
                c[axis] = side;
                c[(axis + 1) % 3] = a;
                c[(axis + 2) % 3] = b;
                at(c[0], c[1], c[2])
            };
            let mut normal = DVec3::ZERO;
            normal[axis] = if side == 1 { 1.0 } else { -1.0 };
            flat_quad(
                [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)],
                normal,
                color,
                out,
            );
        }
    }
}

/// A cylinder about the tool's z axis from `z0` to `z1` (m), capped, its sides smooth.
fn cylinder(radius: f64, z0: f64, z1: f64, color: [f64; 3], out: &mut Vec<SceneTriangle>) {
    let ring = |k: usize| {
        let a = std::f64::consts::TAU * k as f64 / CYLINDER_SIDES as f64;
        DVec3::new(a.cos(), a.sin(), 0.0)
    };
    for k in 0..CYLINDER_SIDES {
        let (u, v) = (ring(k), ring(k + 1));
        let side = [
            u * radius + DVec3::Z * z0,
            v * radius + DVec3::Z * z0,
            v * radius + DVec3::Z * z1,
            u * radius + DVec3::Z * z1,
        ];
        for idx in [[0, 1, 2], [0, 2, 3]] {
            out.push(SceneTriangle {
                p: idx.map(|i| side[i]),
                n: idx.map(|i| if i == 0 || i == 3 { u } else { v }),
                c: [color; 3],
                id: 0,
            });
        }
        for (z, normal) in [(z0, DVec3::NEG_Z), (z1, DVec3::Z)] {
            out.push(SceneTriangle {
                p: [
                    DVec3::Z * z,
                    u * radius + DVec3::Z * z,
                    v * radius + DVec3::Z * z,
                ],
                n: [normal; 3],
                c: [color; 3],
                id: 0,
            });
        }
    }
}
