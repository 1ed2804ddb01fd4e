//! The square-celled grid a contact is solved on, in the pad frame (mm; x along image
//! columns, y along rows, origin at the pad centre).

use glam::DVec2;

/// An axis-aligned rectangle in the pad frame (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub min: DVec2,
    pub max: DVec2,
}

impl Rect {
    pub fn centred(half: DVec2) -> Self {
        Self {
            min: -half,
            max: half,
        }
    }

    pub fn size(&self) -> DVec2 {
        self.max - self.min
    }

    pub fn intersect(&self, other: &Rect) -> Option<Rect> {
        let r = Rect {
            min: self.min.max(other.min),
            max: self.max.min(other.max),
        };
        (r.max.x > r.min.x && r.max.y > r.min.y).then_some(r)
    }

    pub fn grown(&self, by: f64) -> Rect {
        Rect {
            min: self.min - DVec2::splat(by),
            max: self.max + DVec2::splat(by),
        }
    }

    pub fn contains(&self, other: &Rect) -> bool {
        other.min.cmpge(self.min).all() && other.max.cmple(self.max).all()
    }

    pub fn contains_point(&self, p: DVec2) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
}

/// A row-major grid of `nx` x `ny` square cells of side `cell_mm`; cell (i, j) is centred at
/// `origin + (i, j) * cell`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub origin_mm: DVec2,
    pub cell_mm: f64,
    pub nx: usize,
    pub ny: usize,
}

impl Grid {
    /// The grid of cells of side `cell_mm` covering `rect`, aligned to the lattice through
    /// the pad centre so that grids of one cell size share their cell centres.
    pub fn covering(rect: &Rect, cell_mm: f64) -> Grid {
        let lo = (rect.min / cell_mm - 0.5).floor();
        let hi = (rect.max / cell_mm - 0.5).ceil();
        Grid {
            origin_mm: (lo + 0.5) * cell_mm,
            cell_mm,
            nx: (hi.x - lo.x) as usize + 1,
            ny: (hi.y - lo.y) as usize + 1,
        }
    }

    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn centre(&self, i: usize, j: usize) -> DVec2 {
        self.origin_mm + DVec2::new(i as f64, j as f64) * self.cell_mm
    }

    pub fn cell_area_mm2(&self) -> f64 {
        self.cell_mm * self.cell_mm
    }

    /// The rectangle the cells cover.
    pub fn rect(&self) -> Rect {
        let half = DVec2::splat(self.cell_mm / 2.0);
        Rect {
            min: self.origin_mm - half,
            max: self.centre(self.nx - 1, self.ny - 1) + half,
        }
    }

    /// Offset (in cells) of this grid's cell (0, 0) in `outer`, when it lies on outer's
    /// lattice and inside it.
    pub fn offset_in(&self, outer: &Grid) -> Option<(usize, usize)> {
        if (self.cell_mm - outer.cell_mm).abs() > 1e-12 * self.cell_mm {
            return None;
        }
        let d = (self.origin_mm - outer.origin_mm) / self.cell_mm;
        let (i, j) = (d.x.round(), d.y.round());
        let aligned = (d.x - i).abs() < 1e-6 && (d.y - j).abs() < 1e-6;
        let inside = i >= 0.0
            && j >= 0.0
            && i as usize + self.nx <= outer.nx
            && j as usize + self.ny <= outer.ny;
        (aligned && inside).then_some((i as usize, j as usize))
    }

    /// Bilinear sample of a field on this grid at `p` (clamped to the grid).
    pub fn sample(&self, field: &[f64], p: DVec2) -> f64 {
        let q = (p - self.origin_mm) / self.cell_mm;
        let x = q.x.clamp(0.0, (self.nx - 1) as f64);
        let y = q.y.clamp(0.0, (self.ny - 1) as f64);
        let (i, j) = (x.floor() as usize, y.floor() as usize);
        let (i1, j1) = ((i + 1).min(self.nx - 1), (j + 1).min(self.ny - 1));
        let (fx, fy) = (x - i as f64, y - j as f64);
        let at = |i: usize, j: usize| field[j * self.nx + i];
        (at(i, j) * (1.0 - fx) + at(i1, j) * fx) * (1.0 - fy)
            + (at(i, j1) * (1.0 - fx) + at(i1, j1) * fx) * fy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covering_grid_contains_the_rect_and_shares_the_lattice() {
        let rect = Rect {
            min: DVec2::new(-1.03, 0.2),
            max: DVec2::new(2.5, 0.9),
        };
        let g = Grid::covering(&rect, 0.1);
        assert!(g.rect().contains(&rect.grown(-1e-9)));
        let outer = Grid::covering(&Rect::centred(DVec2::new(5.0, 5.0)), 0.1);
        assert!(g.offset_in(&outer).is_some());
        // Cell centres are on the lattice (k + 1/2) * cell.
        let c = g.centre(0, 0) / 0.1 - 0.5;
        assert!((c.x - c.x.round()).abs() < 1e-9 && (c.y - c.y.round()).abs() < 1e-9);
    }
}
