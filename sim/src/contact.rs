//! Gel-object contact at the Hertz level: the object's surface under the pad is fitted by a
//! quadric at its closest point, giving the approach and the local radii; both bodies take
//! their compliance share of the approach (Johnson 1985), the gel's share being its normal
//! indentation field. The lateral field comes from the bonded-layer transfer (`layer`).
//! Later fidelity levels (half-space and layer solvers) replace this behind the same fields.

use crate::elastic::hertz_level::fit_quadric;
use crate::layer::lateral_displacement;
use crate::world::SimWorld;
use glam::{DVec2, DVec3};
use tactex_core::geometry::Pose;
use tactex_core::hertz::{Elastic, Hertz, gel_share};
use tactex_core::tactile_spec::TactileSpec;

/// The contact of the pad with one object.
#[derive(Clone, Copy, Debug)]
pub struct GelContact {
    pub object: usize,
    /// Total approach of gel and object past first touch (mm).
    pub approach_mm: f64,
    /// Equivalent radius sqrt(R1 R2) of the object's surface at the contact (mm).
    pub radius_mm: f64,
    /// Contact point in the pad frame (mm; x along image columns, y along rows).
    pub centre_mm: DVec2,
    /// The gel's share of the approach.
    pub gel_share: f64,
    pub force_n: f64,
    pub contact_radius_mm: f64,
}

/// Gel surface fields over the sensor image (row-major, width x height), in mm.
pub struct GelFields {
    pub contact: GelContact,
    /// Normal indentation (into the gel, towards the camera).
    pub normal_mm: Vec<f64>,
    /// Lateral displacement along image x and y.
    pub lateral_x_mm: Vec<f64>,
    pub lateral_y_mm: Vec<f64>,
}

/// The contact the pad at `tool` makes, if any (the object pressed deepest).
pub fn gel_contact(world: &SimWorld, tool: &Pose, spec: &TactileSpec) -> Option<GelContact> {
    let to_tool = tool.inverse();
    let half = DVec2::new(spec.width_px as f64, spec.height_px as f64) * spec.mm_per_px / 2.0;
    let mut best: Option<GelContact> = None;
    for (index, object) in world.objects.iter().enumerate() {
        // Object surface in the pad frame, mm; z is the gap to the gel surface.
        let near: Vec<DVec3> = object
            .mesh
            .vertices
            .iter()
            .map(|v| to_tool.transform_point(*v) * 1e3)
            .filter(|p| p.x.abs() < half.x + 30.0 && p.y.abs() < half.y + 30.0 && p.z < 30.0)
            .collect();
        let Some(closest) = near
            .iter()
            .filter(|p| p.x.abs() <= half.x && p.y.abs() <= half.y)
            .min_by(|a, b| a.z.total_cmp(&b.z))
        else {
            continue;
        };
        let mut patch = Vec::new();
        for radius in [3.0, 4.5, 6.0, 9.0, 13.0, 20.0] {
            patch = near
                .iter()
                .filter(|p| (p.truncate() - closest.truncate()).length() <= radius)
                .map(|p| *p - DVec3::new(closest.x, closest.y, 0.0))
                .collect();
            if patch.len() >= 15 {
                break;
            }
        }
        let (mut centre, mut gap, mut radius_mm) = (closest.truncate(), closest.z, 1e4);
        let points: Vec<(DVec2, f64)> = patch.iter().map(|p| (p.truncate(), p.z)).collect();
        if let Some(c) = fit_quadric(&points) {
            let (h11, h12, h22) = (2.0 * c[3], c[4], 2.0 * c[5]);
            let mean = (h11 + h22) / 2.0;
            let spread = (((h11 - h22) / 2.0).powi(2) + h12 * h12).sqrt();
            let (k1, k2) = (mean + spread, mean - spread);
            if k1 > 1e-6 {
                let det = h11 * h22 - h12 * h12;
                // A cap has a stationary point; on a saddle (the inside of a banana's bend) the
                // closest vertex stands in for it.
                let offset = if det > 0.0 {
                    DVec2::new(
                        (-c[1] * h22 + c[2] * h12) / det,
                        (-c[2] * h11 + c[1] * h12) / det,
                    )
                } else {
                    DVec2::ZERO
                };
                // Grazing contact at the pad edge: the closest point of the pad, on the quadric.
                let apex = (closest.truncate() + offset).clamp(-half, half);
                let d = apex - closest.truncate();
                centre = apex;
                gap = c[0]
                    + c[1] * d.x
                    + c[2] * d.y
                    + c[3] * d.x * d.x
                    + c[4] * d.x * d.y
                    + c[5] * d.y * d.y;
                // Hertz needs two positive curvatures; cap their ratio at 20 for near-cylinders
                // and saddles.
                radius_mm = (1.0 / (k1 * k2.max(k1 / 20.0)).sqrt()).clamp(0.5, 1e4);
            }
        }
        let approach_mm = -gap;
        if approach_mm <= 0.0 || best.is_some_and(|b| b.approach_mm >= approach_mm) {
            continue;
        }
        let gel = Elastic {
            modulus_mpa: Some(spec.gel.modulus_mpa),
            poisson: spec.gel.poisson,
        };
        let body = Elastic {
            modulus_mpa: object.hardness.modulus_mpa(),
            poisson: object.poisson,
        };
        let hertz = Hertz {
            radius_mm,
            approach_mm,
            contact_modulus_mpa: tactex_core::hertz::contact_modulus_mpa(gel, body),
        };
        best = Some(GelContact {
            object: index,
            approach_mm,
            radius_mm,
            centre_mm: centre,
            gel_share: gel_share(gel, body),
            force_n: hertz.force_n(),
            contact_radius_mm: hertz.contact_radius_mm(),
        });
    }
    best
}

/// The gel's displacement fields over the sensor image, or None without contact.
pub fn gel_fields(world: &SimWorld, tool: &Pose, spec: &TactileSpec) -> Option<GelFields> {
    let contact = gel_contact(world, tool, spec)?;
    let hertz = Hertz {
        radius_mm: contact.radius_mm,
        approach_mm: contact.approach_mm,
        contact_modulus_mpa: 1.0,
    };
    let (w, h) = (spec.width_px as usize, spec.height_px as usize);
    // The lateral transfer is a convolution: solve on a domain twice the pad so that the
    // periodic FFT does not wrap the imprint onto itself, then crop.
    let (nx, ny) = (2 * w, 2 * h);
    let px = spec.mm_per_px;
    let mut normal = vec![0.0; nx * ny];
    for j in 0..ny {
        for i in 0..nx {
            let x = (i as f64 + 0.5 - nx as f64 / 2.0) * px;
            let y = (j as f64 + 0.5 - ny as f64 / 2.0) * px;
            let r = (DVec2::new(x, y) - contact.centre_mm).length();
            normal[j * nx + i] = contact.gel_share * hertz.total_displacement_mm(r);
        }
    }
    let (lx, ly) =
        lateral_displacement(&normal, nx, ny, px, spec.gel.thickness_mm, spec.gel.poisson);
    let crop = |f: &[f64]| -> Vec<f64> {
        let (ox, oy) = (w / 2, h / 2);
        (0..h)
            .flat_map(|j| (0..w).map(move |i| (j, i)))
            .map(|(j, i)| f[(j + oy) * nx + i + ox])
            .collect()
    };
    Some(GelFields {
        contact,
        normal_mm: crop(&normal),
        lateral_x_mm: crop(&lx),
        lateral_y_mm: crop(&ly),
    })
}
