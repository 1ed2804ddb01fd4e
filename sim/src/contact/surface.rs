//! The touched object's lower surface as the gel sees it: its height above the undeformed
//! gel plane at each point of the pad (mm, pad frame, z from the gel towards the object).
//! Primitives are exact; meshes are rasterised triangle by triangle, so any mesh and pose
//! works, the catalog fruits included.

use super::grid::{Grid, Rect};
use super::problem::{ContactError, invalid};
use crate::mesh::TriMesh;
use glam::{DVec2, DVec3};

/// An object's shape, placed over the pad.
#[derive(Clone, Debug)]
pub enum ObjectSurface {
    /// A sphere whose lowest point touches the gel plane at `centre_mm`.
    Sphere { radius_mm: f64, centre_mm: DVec2 },
    /// An ellipsoid with semi-axes (x, y, z), lowest point on the gel plane at `centre_mm`,
    /// its x axis turned by `yaw_rad` from the pad's x axis.
    Ellipsoid {
        semi_axes_mm: DVec3,
        centre_mm: DVec2,
        yaw_rad: f64,
    },
    /// A flat-bottomed box (a flat punch with sharp edges) of footprint `size_mm` resting on
    /// the gel plane, centred at `centre_mm`, turned by `yaw_rad`.
    Box {
        size_mm: DVec2,
        centre_mm: DVec2,
        yaw_rad: f64,
    },
    /// Any triangle mesh, already in the pad frame (mm).
    Mesh(TriMesh),
}

fn check_finite(name: &str, v: f64) -> Result<(), String> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(format!("{name} must be finite, got {v}"))
    }
}

fn check_positive(name: &str, v: f64) -> Result<(), String> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(format!("{name} must be a positive finite number, got {v}"))
    }
}

/// A mesh in its own frame (z up, any unit times `scale_to_mm`) in the pad frame, the
/// middle of its top at the origin: z flipped (and y, to stay right-handed), in mm. Callers
/// that place or turn it on the pad start from here.
pub fn mesh_top(mesh: &TriMesh, scale_to_mm: f64) -> TriMesh {
    let (lo, hi) = mesh.bounds();
    let centre = (lo + hi) / 2.0;
    TriMesh {
        vertices: mesh
            .vertices
            .iter()
            .map(|v| DVec3::new(v.x - centre.x, -(v.y - centre.y), hi.z - v.z) * scale_to_mm)
            .collect(),
        triangles: mesh.triangles.clone(),
    }
}

/// An object's surface given as a height map over a grid of points (Taxim's contract): the
/// surface's height in mm, larger nearer the gel (the part that touches first is the
/// highest), row-major `width` x `height` at `mm_per_px` spacing, the grid centred on the
/// origin with its points at pixel centres as a frame's are. NaN where the object is absent.
#[derive(Clone, Debug)]
pub struct HeightMap {
    pub heights_mm: Vec<f64>,
    pub width: usize,
    pub height: usize,
    pub mm_per_px: f64,
}

impl HeightMap {
    /// Why no surface can be made of it, naming the field: sizes, spacing, values.
    pub fn validate(&self) -> Result<(), ContactError> {
        if self.width < 2 || self.height < 2 {
            return Err(invalid(
                "height_map_mm",
                format!(
                    "{} x {} points; a surface needs at least 2 x 2",
                    self.height, self.width
                ),
            ));
        }
        if self.heights_mm.len() != self.width * self.height {
            return Err(invalid(
                "height_map_mm",
                format!(
                    "{} values for {} x {} points",
                    self.heights_mm.len(),
                    self.height,
                    self.width
                ),
            ));
        }
        if !(self.mm_per_px.is_finite() && self.mm_per_px > 0.0) {
            return Err(invalid(
                "mm_per_px",
                format!(
                    "must be a positive finite number, got {}",
                    tactex_core::printable::short_number(self.mm_per_px)
                ),
            ));
        }
        if let Some(k) = self.heights_mm.iter().position(|h| h.is_infinite()) {
            return Err(invalid(
                "height_map_mm",
                format!(
                    "infinite at row {}, column {} (NaN marks where the object is absent)",
                    k / self.width,
                    k % self.width
                ),
            ));
        }
        // A sheet of more triangles than a mesh may have, or wider or deeper than any object
        // on a table, is a mistake of units or sampling, not a surface to rasterise for minutes.
        let triangles = 2 * (self.width - 1) * (self.height - 1);
        if triangles > crate::mesh::MAX_TRIANGLES {
            return Err(invalid(
                "height_map_mm",
                format!(
                    "{} x {} points make {triangles} triangles, over the {} a surface may have; sample it coarser (a larger mm_per_px)",
                    self.height,
                    self.width,
                    crate::mesh::MAX_TRIANGLES
                ),
            ));
        }
        let most_mm = tactex_core::scene::OBJECT_SIZE_M[1] * 1e3;
        let span_mm = self.width.max(self.height) as f64 * self.mm_per_px;
        if span_mm > most_mm {
            return Err(invalid(
                "mm_per_px",
                format!(
                    "{} mm a point makes the map {} mm across, wider than an object on a table ({most_mm:.0} mm)",
                    tactex_core::printable::short_number(self.mm_per_px),
                    tactex_core::printable::short_number(span_mm.round())
                ),
            ));
        }
        let (lo, hi) = self
            .heights_mm
            .iter()
            .filter(|h| !h.is_nan())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &h| {
                (lo.min(h), hi.max(h))
            });
        if hi - lo > most_mm {
            return Err(invalid(
                "height_map_mm",
                format!(
                    "heights span {:.3e} mm, deeper than an object on a table ({most_mm:.0} mm); give them in mm",
                    hi - lo
                ),
            ));
        }
        if self.heights_mm.iter().all(|h| h.is_nan()) {
            return Err(invalid(
                "height_map_mm",
                "every value is NaN; there is no surface",
            ));
        }
        Ok(())
    }

    /// The surface as the pad sees it: a sheet of two triangles per grid cell whose four
    /// corners are all present, z measured down from the highest point (which touches the gel
    /// first), in the pad frame.
    pub fn sheet(&self) -> Result<TriMesh, ContactError> {
        self.validate()?;
        let top = self
            .heights_mm
            .iter()
            .copied()
            .filter(|h| !h.is_nan())
            .fold(f64::NEG_INFINITY, f64::max);
        let (w, h) = (self.width, self.height);
        let vertices = self
            .heights_mm
            .iter()
            .enumerate()
            .map(|(k, z)| {
                let (i, j) = ((k % w) as f64, (k / w) as f64);
                DVec3::new(
                    (i + 0.5 - w as f64 / 2.0) * self.mm_per_px,
                    (j + 0.5 - h as f64 / 2.0) * self.mm_per_px,
                    top - z,
                )
            })
            .collect::<Vec<_>>();
        let mut triangles = Vec::with_capacity(2 * (w - 1) * (h - 1));
        for j in 0..h - 1 {
            for i in 0..w - 1 {
                let at = |di: usize, dj: usize| ((j + dj) * w + i + di) as u32;
                let corners = [at(0, 0), at(1, 0), at(0, 1), at(1, 1)];
                if corners.iter().any(|&c| vertices[c as usize].z.is_nan()) {
                    continue;
                }
                triangles.push([corners[0], corners[1], corners[3]]);
                triangles.push([corners[0], corners[3], corners[2]]);
            }
        }
        if triangles.is_empty() {
            return Err(invalid(
                "height_map_mm",
                "no grid cell has all four corners present (not NaN)",
            ));
        }
        // Only the points triangles use: an absent (NaN) point is no vertex.
        let mut index = vec![u32::MAX; vertices.len()];
        let mut kept = Vec::new();
        for t in &mut triangles {
            for v in t.iter_mut() {
                let k = *v as usize;
                if index[k] == u32::MAX {
                    index[k] = kept.len() as u32;
                    kept.push(vertices[k]);
                }
                *v = index[k];
            }
        }
        Ok(TriMesh {
            vertices: kept,
            triangles,
        })
    }
}

impl ObjectSurface {
    /// A mesh in its own frame (z up, any unit times `scale_to_mm`) pressed from above at the
    /// middle of its top: the pad frame flips z (and y, to stay right-handed).
    pub fn from_mesh_top(mesh: &TriMesh, scale_to_mm: f64) -> Self {
        ObjectSurface::Mesh(mesh_top(mesh, scale_to_mm))
    }

    /// The footprint corners of a box, counter-clockwise (empty for other shapes).
    pub fn corners(&self) -> Vec<DVec2> {
        match self {
            ObjectSurface::Box {
                size_mm,
                centre_mm,
                yaw_rad,
            } => [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .iter()
                .map(|(sx, sy)| {
                    *centre_mm
                        + DVec2::from_angle(*yaw_rad)
                            .rotate(DVec2::new(sx * size_mm.x, sy * size_mm.y) / 2.0)
                })
                .collect(),
            _ => Vec::new(),
        }
    }

    /// Rejects shapes no solver can use (non-positive or non-finite sizes, empty meshes).
    pub fn validate(&self) -> Result<(), String> {
        match self {
            ObjectSurface::Sphere { radius_mm, .. } => check_positive("radius_mm", *radius_mm),
            ObjectSurface::Ellipsoid {
                semi_axes_mm,
                yaw_rad,
                ..
            } => {
                for (name, v) in ["x", "y", "z"].iter().zip(semi_axes_mm.to_array()) {
                    check_positive(&format!("semi_axes_mm.{name}"), v)?;
                }
                check_finite("yaw_rad", *yaw_rad)
            }
            ObjectSurface::Box {
                size_mm, yaw_rad, ..
            } => {
                check_positive("size_mm.x", size_mm.x)?;
                check_positive("size_mm.y", size_mm.y)?;
                check_finite("yaw_rad", *yaw_rad)
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
                yaw_rad,
            } => {
                let d = to_body(p - *centre_mm, *yaw_rad);
                let rho2 = (d.x / s.x).powi(2) + (d.y / s.y).powi(2);
                (rho2 <= 1.0).then(|| s.z * rho2 / (1.0 + (1.0 - rho2).sqrt()))
            }
            ObjectSurface::Box {
                size_mm,
                centre_mm,
                yaw_rad,
            } => {
                let d = to_body(p - *centre_mm, *yaw_rad).abs();
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

    /// Height of the widest section above the gel plane, where the model's lower half of a
    /// sphere or ellipsoid ends; None for shapes held whole (a box's sides, a mesh's top).
    pub fn equator_height_mm(&self) -> Option<f64> {
        match self {
            ObjectSurface::Sphere { radius_mm, .. } => Some(*radius_mm),
            ObjectSurface::Ellipsoid { semi_axes_mm, .. } => Some(semi_axes_mm.z),
            ObjectSurface::Box { .. } | ObjectSurface::Mesh(_) => None,
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
            ObjectSurface::Sphere { centre_mm, .. } => {
                self.height_at(centre_mm.clamp(region.min, region.max))
            }
            ObjectSurface::Ellipsoid {
                semi_axes_mm: s,
                centre_mm,
                yaw_rad,
            } => {
                if region.contains_point(*centre_mm) {
                    return Some(0.0);
                }
                if *yaw_rad == 0.0 {
                    // Height grows with the elliptic radius; clamp in scaled coordinates.
                    let scale = s.truncate();
                    let q = ((DVec2::ZERO).clamp(
                        (region.min - *centre_mm) / scale,
                        (region.max - *centre_mm) / scale,
                    )) * scale;
                    return self.height_at(*centre_mm + q);
                }
                // Turned: the lowest point over the region lies on its boundary.
                boundary_points(region)
                    .filter_map(|p| self.height_at(p))
                    .min_by(f64::total_cmp)
            }
            ObjectSurface::Box { centre_mm, .. } => {
                // Flat: the region sees height 0 wherever it overlaps the footprint.
                let inside = region.contains_point(*centre_mm)
                    || boundary_points(region).any(|p| self.height_at(p).is_some())
                    || self.corners().iter().any(|c| region.contains_point(*c));
                inside.then_some(0.0)
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
                yaw_rad,
            } => {
                let t = (level / s.z).min(1.0);
                let rho = (2.0 * t - t * t).sqrt();
                // Half-extents of the turned ellipse of semi-axes a, b.
                let (a, b) = (s.x * rho, s.y * rho);
                let (sin, cos) = yaw_rad.sin_cos();
                let half = DVec2::new(
                    (a * a * cos * cos + b * b * sin * sin).sqrt(),
                    (a * a * sin * sin + b * b * cos * cos).sqrt(),
                );
                (level > 0.0).then(|| disc(*centre_mm, half))?
            }
            ObjectSurface::Box {
                size_mm,
                centre_mm,
                yaw_rad,
            } => {
                let (sin, cos) = yaw_rad.sin_cos();
                let half = DVec2::new(
                    size_mm.x * cos.abs() + size_mm.y * sin.abs(),
                    size_mm.x * sin.abs() + size_mm.y * cos.abs(),
                ) / 2.0;
                (level > 0.0).then(|| disc(*centre_mm, half))?
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

/// A pad-frame offset in the body frame of a shape turned by `yaw`.
fn to_body(d: DVec2, yaw: f64) -> DVec2 {
    DVec2::from_angle(-yaw).rotate(d)
}

/// Points along a rectangle's edges, dense enough (4096 per edge) for the minimum of a
/// smooth height over them to be within a micrometre on any pad-sized region.
fn boundary_points(region: &Rect) -> impl Iterator<Item = DVec2> + '_ {
    const N: usize = 4096;
    let corners = [
        region.min,
        DVec2::new(region.max.x, region.min.y),
        region.max,
        DVec2::new(region.min.x, region.max.y),
    ];
    (0..4).flat_map(move |e| {
        let (a, b) = (corners[e], corners[(e + 1) % 4]);
        (0..N).map(move |k| a + (b - a) * (k as f64 / N as f64))
    })
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
    fn a_quarter_turn_swaps_the_axes_of_ellipsoids_and_boxes() {
        let c = DVec2::new(0.7, -0.4);
        let turned = ObjectSurface::Ellipsoid {
            semi_axes_mm: DVec3::new(6.0, 3.0, 4.0),
            centre_mm: c,
            yaw_rad: std::f64::consts::FRAC_PI_2,
        };
        let swapped = ObjectSurface::Ellipsoid {
            semi_axes_mm: DVec3::new(3.0, 6.0, 4.0),
            centre_mm: c,
            yaw_rad: 0.0,
        };
        let box_turned = ObjectSurface::Box {
            size_mm: DVec2::new(5.0, 2.0),
            centre_mm: c,
            yaw_rad: std::f64::consts::FRAC_PI_2,
        };
        let box_swapped = ObjectSurface::Box {
            size_mm: DVec2::new(2.0, 5.0),
            centre_mm: c,
            yaw_rad: 0.0,
        };
        for k in 0..400 {
            let p = c + DVec2::new((k % 20) as f64 * 0.61 - 6.0, (k / 20) as f64 * 0.61 - 6.0);
            let (a, b) = (turned.height_at(p), swapped.height_at(p));
            assert_eq!(a.is_some(), b.is_some(), "{p}");
            if let (Some(a), Some(b)) = (a, b) {
                assert!((a - b).abs() < 1e-9, "{p}: {a} vs {b}");
            }
            // Points exactly on the box edge may fall either way after the turn's rounding.
            let d = (p - c).abs();
            if (d.x - 1.0).abs() > 1e-9 && (d.y - 2.5).abs() > 1e-9 {
                assert_eq!(box_turned.height_at(p), box_swapped.height_at(p), "{p}");
            }
        }
    }

    #[test]
    fn a_turned_shapes_dip_lies_inside_its_bounds() {
        let pad = Rect::centred(DVec2::new(10.0, 7.6));
        let shapes = [
            ObjectSurface::Ellipsoid {
                semi_axes_mm: DVec3::new(8.0, 3.0, 5.0),
                centre_mm: DVec2::new(1.0, 0.5),
                yaw_rad: 0.6,
            },
            ObjectSurface::Box {
                size_mm: DVec2::new(6.0, 2.0),
                centre_mm: DVec2::new(-1.0, 0.5),
                yaw_rad: 0.3,
            },
        ];
        for shape in &shapes {
            assert_eq!(shape.lowest_over(&pad), Some(0.0));
            let level = 0.8;
            let bounds = shape.below_level_bounds(level, &pad).unwrap();
            let grid = Grid::covering(&pad, 0.05);
            let heights = shape.heights(&grid);
            let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
            for j in 0..grid.ny {
                for i in 0..grid.nx {
                    if heights[j * grid.nx + i] < level {
                        let p = grid.centre(i, j);
                        lo = lo.min(p);
                        hi = hi.max(p);
                    }
                }
            }
            // Tight: the dip's cells reach the bounds to within a cell.
            assert!(bounds.min.cmple(lo + 1e-9).all() && bounds.max.cmpge(hi - 1e-9).all());
            assert!(
                (bounds.min - lo).max_element() < 0.06 && (hi - bounds.max).min_element() > -0.06
            );
        }
        // A turned ellipsoid off the pad: its lowest point over the pad is on the pad's edge.
        let off = ObjectSurface::Ellipsoid {
            semi_axes_mm: DVec3::new(8.0, 3.0, 5.0),
            centre_mm: DVec2::new(13.0, 0.0),
            yaw_rad: 0.5,
        };
        let lowest = off.lowest_over(&pad).unwrap();
        let grid = Grid::covering(&pad, 0.02);
        let heights = off.heights(&grid);
        let sampled = (0..heights.len())
            .filter(|&k| pad.contains_point(grid.centre(k % grid.nx, k / grid.nx)))
            .map(|k| heights[k])
            .fold(f64::INFINITY, f64::min);
        assert!(
            lowest <= sampled + 1e-9 && sampled - lowest < 0.05,
            "{lowest} vs {sampled}"
        );
    }

    #[test]
    fn a_height_map_of_a_sphere_is_the_sphere() {
        let (r, w, h, px) = (20.0f64, 40usize, 30usize, 0.2f64);
        let heights_mm = (0..w * h)
            .map(|k| {
                let x = ((k % w) as f64 + 0.5 - w as f64 / 2.0) * px;
                let y = ((k / w) as f64 + 0.5 - h as f64 / 2.0) * px;
                (r * r - x * x - y * y).sqrt()
            })
            .collect();
        let map = HeightMap {
            heights_mm,
            width: w,
            height: h,
            mm_per_px: px,
        };
        let sheet = ObjectSurface::Mesh(map.sheet().unwrap());
        let sphere = ObjectSurface::Sphere {
            radius_mm: r,
            centre_mm: DVec2::ZERO,
        };
        let grid = Grid {
            origin_mm: DVec2::new(-2.0, -1.5),
            cell_mm: 0.13,
            nx: 30,
            ny: 23,
        };
        // The sheet's points are at pixel centres; the sphere's top (0.1 mm off the nearest)
        // is 0.1^2 / 2R = 2.5e-4 mm below its highest point.
        for (a, b) in sheet.heights(&grid).iter().zip(sphere.heights(&grid)) {
            assert!((a - b).abs() < 1e-3, "{a} vs {b}");
        }
    }

    #[test]
    fn a_height_map_that_cannot_be_a_surface_names_why() {
        let map = |heights_mm: Vec<f64>, width, height, mm_per_px| HeightMap {
            heights_mm,
            width,
            height,
            mm_per_px,
        };
        let bad = [
            (map(vec![0.0; 3], 3, 1, 0.1), "at least 2 x 2"),
            (map(vec![0.0; 5], 2, 2, 0.1), "5 values"),
            (map(vec![0.0; 4], 2, 2, f64::NAN), "mm_per_px"),
            (
                map(vec![0.0, f64::INFINITY, 0.0, 0.0], 2, 2, 0.1),
                "infinite at row 0, column 1",
            ),
            (map(vec![f64::NAN; 4], 2, 2, 0.1), "every value is NaN"),
            (
                map(vec![0.0, f64::NAN, 0.0, 0.0], 2, 2, 0.1),
                "four corners",
            ),
        ];
        for (m, says) in bad {
            let e = m.sheet().unwrap_err().to_string();
            assert!(e.contains(says), "{e}");
        }
    }

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
