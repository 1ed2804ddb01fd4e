//! The touched object's lower surface as the gel sees it: its height above the undeformed
//! gel plane at each point of the pad (mm, pad frame, z from the gel towards the object).
//! Primitives are exact; meshes are rasterised triangle by triangle, so any mesh and pose
//! works, the catalog fruits included.

use super::grid::{Grid, Rect};
use crate::mesh::TriMesh;
use glam::{DVec2, DVec3};
use tactex_core::geometry::Pose;

/// An object's shape, placed over the pad.
#[derive(Clone, Debug)]
pub enum ObjectSurface {
    /// A sphere whose lowest point touches the gel plane at `centre_mm`.
    Sphere { radius_mm: f64, centre_mm: DVec2 },
    /// An ellipsoid with semi-axes (x, y, z), lowest point on the gel plane at `centre_mm`.
    Ellipsoid {
        semi_axes_mm: DVec3,
        centre_mm: DVec2,
    },
    /// A flat-bottomed box (a flat punch with sharp edges) of footprint `size_mm` resting on
    /// the gel plane, centred at `centre_mm`.
    Box { size_mm: DVec2, centre_mm: DVec2 },
    /// Any triangle mesh, already in the pad frame (mm).
    Mesh(TriMesh),
}

fn check_positive(name: &str, v: f64) -> Result<(), String> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(format!("{name} must be a positive finite number, got {v}"))
    }
}

impl ObjectSurface {
    /// A mesh in world coordinates (m) seen from a pad at `tool` (its z axis pointing from the
    /// gel into the object).
    pub fn from_world_mesh(mesh: &TriMesh, tool: &Pose) -> Self {
        let to_tool = tool.inverse();
        ObjectSurface::Mesh(TriMesh {
            vertices: mesh
                .vertices
                .iter()
                .map(|v| to_tool.transform_point(*v) * 1e3)
                .collect(),
            triangles: mesh.triangles.clone(),
        })
    }

    /// A mesh in its own frame (z up, any unit times `scale_to_mm`) pressed from above at the
    /// middle of its top: the pad frame flips z (and y, to stay right-handed).
    pub fn from_mesh_top(mesh: &TriMesh, scale_to_mm: f64) -> Self {
        let (lo, hi) = mesh.bounds();
        let centre = (lo + hi) / 2.0;
        ObjectSurface::Mesh(TriMesh {
            vertices: mesh
                .vertices
                .iter()
                .map(|v| DVec3::new(v.x - centre.x, -(v.y - centre.y), hi.z - v.z) * scale_to_mm)
                .collect(),
            triangles: mesh.triangles.clone(),
        })
    }

    /// Rejects shapes no solver can use (non-positive or non-finite sizes, empty meshes).
    pub fn validate(&self) -> Result<(), String> {
        match self {
            ObjectSurface::Sphere { radius_mm, .. } => check_positive("radius_mm", *radius_mm),
            ObjectSurface::Ellipsoid { semi_axes_mm, .. } => {
                for (name, v) in ["x", "y", "z"].iter().zip(semi_axes_mm.to_array()) {
                    check_positive(&format!("semi_axes_mm.{name}"), v)?;
                }
                Ok(())
            }
            ObjectSurface::Box { size_mm, .. } => {
                check_positive("size_mm.x", size_mm.x)?;
                check_positive("size_mm.y", size_mm.y)
            }
            ObjectSurface::Mesh(mesh) => {
                if mesh.triangles.is_empty() {
                    return Err("mesh has no triangles".into());
                }
                if mesh.vertices.iter().any(|v| !v.is_finite()) {
                    return Err("mesh has non-finite vertices".into());
                }
                let has_area = mesh.triangles.iter().any(|t| {
                    let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
                    (b - a).cross(c - a).length() > 1e-12
                });
                if has_area {
                    Ok(())
                } else {
                    Err("mesh is degenerate (all triangles have zero area)".into())
                }
            }
        }
    }

    /// Height of the surface above the gel plane at `p`, None where nothing is above.
    pub fn height_at(&self, p: DVec2) -> Option<f64> {
        match self {
            ObjectSurface::Sphere {
                radius_mm,
                centre_mm,
            } => {
                let r2 = (p - *centre_mm).length_squared();
                // R - sqrt(R^2 - r^2), written to keep precision for r << R.
                (r2 <= radius_mm * radius_mm)
                    .then(|| r2 / (radius_mm + (radius_mm * radius_mm - r2).sqrt()))
            }
            ObjectSurface::Ellipsoid {
                semi_axes_mm: s,
                centre_mm,
            } => {
                let d = p - *centre_mm;
                let rho2 = (d.x / s.x).powi(2) + (d.y / s.y).powi(2);
                (rho2 <= 1.0).then(|| s.z * rho2 / (1.0 + (1.0 - rho2).sqrt()))
            }
            ObjectSurface::Box { size_mm, centre_mm } => {
                let d = (p - *centre_mm).abs();
                (d.x <= size_mm.x / 2.0 && d.y <= size_mm.y / 2.0).then_some(0.0)
            }
            ObjectSurface::Mesh(_) => {
                let grid = Grid {
                    origin_mm: p,
                    cell_mm: 1.0,
                    nx: 1,
                    ny: 1,
                };
                let h = self.heights(&grid)[0];
                h.is_finite().then_some(h)
            }
        }
    }

    /// Heights at the grid's cell centres (row-major; infinity where nothing is above).
    pub fn heights(&self, grid: &Grid) -> Vec<f64> {
        match self {
            ObjectSurface::Mesh(mesh) => rasterise_lower_envelope(mesh, grid),
            _ => (0..grid.ny)
                .flat_map(|j| (0..grid.nx).map(move |i| (i, j)))
                .map(|(i, j)| self.height_at(grid.centre(i, j)).unwrap_or(f64::INFINITY))
                .collect(),
        }
    }

    /// The lowest height over `region` (where the gel first touches), None if the object is
    /// not above the region at all.
    pub fn lowest_over(&self, region: &Rect) -> Option<f64> {
        match self {
            ObjectSurface::Sphere { centre_mm, .. } | ObjectSurface::Box { centre_mm, .. } => {
                self.height_at(centre_mm.clamp(region.min, region.max))
            }
            ObjectSurface::Ellipsoid {
                semi_axes_mm: s,
                centre_mm,
            } => {
                // Height grows with the elliptic radius; clamp in scaled coordinates.
                let scale = s.truncate();
                let q = ((DVec2::ZERO).clamp(
                    (region.min - *centre_mm) / scale,
                    (region.max - *centre_mm) / scale,
                )) * scale;
                self.height_at(*centre_mm + q)
            }
            ObjectSurface::Mesh(mesh) => clipped_polygons(mesh, region, f64::INFINITY)
                .flatten()
                .map(|v| v.z)
                .min_by(f64::total_cmp),
        }
    }

    /// The bounding rectangle of where the surface lies below `level` within `region`.
    pub fn below_level_bounds(&self, level: f64, region: &Rect) -> Option<Rect> {
        let disc = |centre: DVec2, half: DVec2| {
            Rect {
                min: centre - half,
                max: centre + half,
            }
            .intersect(region)
        };
        match self {
            ObjectSurface::Sphere {
                radius_mm: r,
                centre_mm,
            } => {
                let l = level.min(*r);
                (level > 0.0)
                    .then(|| disc(*centre_mm, DVec2::splat((2.0 * r * l - l * l).sqrt())))?
            }
            ObjectSurface::Ellipsoid {
                semi_axes_mm: s,
                centre_mm,
            } => {
                let t = (level / s.z).min(1.0);
                let rho = (2.0 * t - t * t).sqrt();
                (level > 0.0).then(|| disc(*centre_mm, s.truncate() * rho))?
            }
            ObjectSurface::Box { size_mm, centre_mm } => {
                (level > 0.0).then(|| disc(*centre_mm, *size_mm / 2.0))?
            }
            ObjectSurface::Mesh(mesh) => {
                let mut bounds: Option<Rect> = None;
                for v in clipped_polygons(mesh, region, level).flatten() {
                    let p = v.truncate();
                    bounds = Some(match bounds {
                        None => Rect { min: p, max: p },
                        Some(b) => Rect {
                            min: b.min.min(p),
                            max: b.max.max(p),
                        },
                    });
                }
                bounds.filter(|b| b.size().x > 0.0 || b.size().y > 0.0)
            }
        }
    }
}

/// Sutherland-Hodgman clip of a polygon by the half-space `keep`, interpolating along edges.
fn clip(poly: &[DVec3], value: impl Fn(DVec3) -> f64) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for (k, &a) in poly.iter().enumerate() {
        let b = poly[(k + 1) % poly.len()];
        let (va, vb) = (value(a), value(b));
        if va <= 0.0 {
            out.push(a);
        }
        if (va <= 0.0) != (vb <= 0.0) {
            out.push(a + (b - a) * (va / (va - vb)));
        }
    }
    out
}

/// Each triangle clipped to the region's prism and below `level`.
fn clipped_polygons<'a>(
    mesh: &'a TriMesh,
    region: &'a Rect,
    level: f64,
) -> impl Iterator<Item = Vec<DVec3>> + 'a {
    mesh.triangles.iter().filter_map(move |t| {
        let mut poly: Vec<DVec3> = t.map(|i| mesh.vertices[i as usize]).to_vec();
        let (lo, hi) = (region.min, region.max);
        poly = clip(&poly, |v| lo.x - v.x);
        poly = clip(&poly, |v| v.x - hi.x);
        poly = clip(&poly, |v| lo.y - v.y);
        poly = clip(&poly, |v| v.y - hi.y);
        if level.is_finite() {
            poly = clip(&poly, |v| v.z - level);
        }
        (!poly.is_empty()).then_some(poly)
    })
}

/// The lowest surface over each cell centre: each triangle's plane, where the centre falls
/// inside its projection.
fn rasterise_lower_envelope(mesh: &TriMesh, grid: &Grid) -> Vec<f64> {
    let mut heights = vec![f64::INFINITY; grid.len()];
    let cell = grid.cell_mm;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        let det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
        if det.abs() < 1e-18 {
            continue; // seen edge-on from the pad
        }
        let lo = a.truncate().min(b.truncate()).min(c.truncate());
        let hi = a.truncate().max(b.truncate()).max(c.truncate());
        let i0 = ((lo.x - grid.origin_mm.x) / cell).ceil().max(0.0);
        let j0 = ((lo.y - grid.origin_mm.y) / cell).ceil().max(0.0);
        let i1 = ((hi.x - grid.origin_mm.x) / cell)
            .floor()
            .min(grid.nx as f64 - 1.0);
        let j1 = ((hi.y - grid.origin_mm.y) / cell)
            .floor()
            .min(grid.ny as f64 - 1.0);
        if i0 > i1 || j0 > j1 {
            continue;
        }
        for j in j0 as usize..=j1 as usize {
            for i in i0 as usize..=i1 as usize {
                let p = grid.centre(i, j);
                let u = ((p.x - a.x) * (c.y - a.y) - (c.x - a.x) * (p.y - a.y)) / det;
                let v = ((b.x - a.x) * (p.y - a.y) - (p.x - a.x) * (b.y - a.y)) / det;
                // A small tolerance so that centres on shared edges are not lost.
                if u >= -1e-9 && v >= -1e-9 && u + v <= 1.0 + 1e-9 {
                    let z = a.z + u * (b.z - a.z) + v * (c.z - a.z);
                    let h = &mut heights[j * grid.nx + i];
                    if z < *h {
                        *h = z;
                    }
                }
            }
        }
    }
    heights
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh;

    #[test]
    fn a_mesh_sphere_matches_the_analytic_sphere_near_its_apex() {
        let radius = 10.0;
        let sphere = mesh::ellipsoid(DVec3::splat(radius / 1e3));
        let surface = ObjectSurface::from_mesh_top(&sphere, 1e3);
        let exact = ObjectSurface::Sphere {
            radius_mm: radius,
            centre_mm: DVec2::ZERO,
        };
        let pad = Rect::centred(DVec2::new(10.0, 7.5));
        let lowest = surface.lowest_over(&pad).unwrap();
        assert!(lowest.abs() < 1e-9, "apex is a vertex: {lowest}");
        let grid = Grid::covering(&Rect::centred(DVec2::splat(3.0)), 0.5);
        for (m, e) in surface.heights(&grid).iter().zip(exact.heights(&grid)) {
            // Facets lie inside the sphere by at most the chord sag.
            assert!((m - e).abs() < 0.05, "{m} vs {e}");
        }
        let bounds = surface.below_level_bounds(0.5, &pad).unwrap();
        let expected = (2.0 * radius * 0.5 - 0.25f64).sqrt();
        assert!((bounds.max.x - expected).abs() < 0.2, "{bounds:?}");
    }

    #[test]
    fn lowest_point_over_the_pad_is_at_its_edge_for_an_object_beside_it() {
        let s = ObjectSurface::Sphere {
            radius_mm: 5.0,
            centre_mm: DVec2::new(12.0, 0.0),
        };
        let pad = Rect::centred(DVec2::new(10.0, 7.5));
        let h = s.lowest_over(&pad).unwrap();
        assert!((h - (5.0 - (25.0f64 - 4.0).sqrt())).abs() < 1e-12);
        assert!(s.below_level_bounds(h / 2.0, &pad).is_none() || h > 0.0);
    }
}
