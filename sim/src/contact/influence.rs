//! Influence coefficients: the surface displacement at one cell centre due to a unit
//! uniform pressure on another cell, per unit compliance c = (1 - nu^2) / E.
//!
//! Half-space: the point-load responses are w = c / (pi r) (Boussinesq) and the radial
//! u_r = T_inf c / (pi r) with T_inf = -(1 - 2 nu) / (2 (1 - nu)). Integrated exactly over a
//! square cell (Love 1929; Johnson 1985 eq. 3.25 and its tangential analogue).
//!
//! Bonded layer of thickness h: by Hankel transform of the Fourier-space response
//! (`crate::layer`), w = (c / pi) [1/r + C_w(r)] and u_r = (c / pi) [T_inf / r + C_u(r)] with
//! the smooth corrections
//!   C_w(r) = int_0^inf (K(kh) - 1) J0(kr) dk,
//!   C_u(r) = int_0^inf (T(kh) K(kh) - T_inf) J1(kr) dk.
//! Adding and subtracting T e^{-kb} terms with known transforms makes both integrands vanish
//! at k = 0 and decay exponentially, so plain quadrature converges; the corrections are
//! tabulated in r and averaged over a cell with 2 x 2 Gauss points.

use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};
use tactex_core::hardness::layer_compliance::{lateral_ratio, normal_compliance_ratio};

/// The half-space radial-to-normal displacement ratio T_inf (negative: inward).
pub fn half_space_lateral_ratio(nu: f64) -> f64 {
    -(1.0 - 2.0 * nu) / (2.0 * (1.0 - nu))
}

/// t asinh(s / |t|), continuous at t = 0.
fn t_asinh(t: f64, s: f64) -> f64 {
    if t == 0.0 {
        0.0
    } else {
        t * (s / t.abs()).asinh()
    }
}

/// Normal displacement at offset (x, y) from the centre of a square cell of half side `a`
/// under unit pressure, unit compliance.
pub fn love_normal(x: f64, y: f64, a: f64) -> f64 {
    // F(X, Y) = double antiderivative of 1 / sqrt(X^2 + Y^2).
    let f = |u: f64, v: f64| t_asinh(u, v) + t_asinh(v, u);
    (f(x + a, y + a) - f(x - a, y + a) - f(x + a, y - a) + f(x - a, y - a)) / PI
}

/// Displacement along x at offset (x, y) from a cell of half side `a` for a point response
/// x / (pi r^2) (the half-space lateral kernel without its factor T_inf).
fn love_lateral_x(x: f64, y: f64, a: f64) -> f64 {
    // H(X, Y) = double antiderivative of X / (X^2 + Y^2).
    let h = |u: f64, v: f64| {
        let r2 = u * u + v * v;
        let log_term = if v == 0.0 { 0.0 } else { 0.5 * v * r2.ln() };
        let atan_term = if u == 0.0 { 0.0 } else { u * (v / u).atan() };
        log_term + atan_term
    };
    (h(x + a, y + a) - h(x - a, y + a) - h(x + a, y - a) + h(x - a, y - a)) / PI
}

/// C_w and C_u of a layer of unit thickness, at radii rho = m / SAMPLES_PER_THICKNESS.
/// Every quantity in the integrals scales with the thickness h (k h, r / h, b = h), so
/// C(r; h) = c(r / h) / h: one table serves every thickness of a given Poisson's ratio.
#[derive(Debug)]
struct UnitLayer {
    normal: Vec<f64>,
    lateral: Vec<f64>,
}

const SAMPLES_PER_THICKNESS: f64 = 48.0;

/// A unit table's key: the bits of (Poisson's ratio, extent in thicknesses).
type TableKey = (u64, u64);

impl UnitLayer {
    /// Tables out to `extent` thicknesses: a few hundred radii, each a quadrature over
    /// ~800 wavenumbers of two Bessel functions (tens of ms, so radii run in parallel).
    fn new(poisson: f64, extent: f64) -> Self {
        let t_inf = half_space_lateral_ratio(poisson);
        let dr = 1.0 / SAMPLES_PER_THICKNESS;
        let n_r = (extent / dr).ceil() as usize + 2;
        let r_max = dr * n_r as f64;
        // Resolve both the integrand (scale 1/h) and the Bessel oscillation (period 2 pi / r).
        let k_max = 40.0;
        let dk = 0.05f64.min(2.0 * PI / (12.0 * r_max));
        let n_k = ((k_max / dk).ceil() as usize).div_ceil(2) * 2;
        let dk = k_max / n_k as f64;
        let ks: Vec<f64> = (0..=n_k).map(|q| q as f64 * dk).collect();
        // The integrands with their e^{-k} (b = h = 1) terms, zero at k = 0.
        let g_w: Vec<f64> = ks
            .iter()
            .map(|&k| {
                if k == 0.0 {
                    0.0
                } else {
                    normal_compliance_ratio(k, poisson) - 1.0 + (-k).exp()
                }
            })
            .collect();
        let g_u: Vec<f64> = ks
            .iter()
            .map(|&k| {
                if k == 0.0 {
                    0.0
                } else {
                    lateral_ratio(k, poisson) * normal_compliance_ratio(k, poisson) - t_inf
                        + t_inf * (-k).exp()
                }
            })
            .collect();
        // Simpson weights.
        let weight = |q: usize| {
            if q == 0 || q == n_k {
                dk / 3.0
            } else if q % 2 == 1 {
                4.0 * dk / 3.0
            } else {
                2.0 * dk / 3.0
            }
        };
        let (normal, lateral) = (0..=n_r)
            .into_par_iter()
            .map(|m| {
                let r = m as f64 * dr;
                let (mut cw, mut cu) = (0.0, 0.0);
                for (q, &k) in ks.iter().enumerate() {
                    let w = weight(q);
                    cw += w * g_w[q] * libm::j0(k * r);
                    cu += w * g_u[q] * libm::j1(k * r);
                }
                let root = (1.0 + r * r).sqrt();
                cw -= 1.0 / root;
                // int e^{-kb} J1(kr) dk = (1 - b / sqrt(b^2 + r^2)) / r = r / (root (root + b)).
                cu -= t_inf * r / (root * (root + 1.0));
                (cw, cu)
            })
            .unzip();
        UnitLayer { normal, lateral }
    }

    /// The table for (Poisson's ratio, at least `extent` thicknesses), built once per process:
    /// extents are rounded up to a power of two so that nearby thicknesses share one, and
    /// looked up by that extent exactly (never a larger table), because the sampling depends
    /// on the extent: otherwise a press would depend on what the process solved before it
    /// (and parallel data generation on thread scheduling).
    fn shared(poisson: f64, extent: f64) -> Arc<UnitLayer> {
        static TABLES: Mutex<Vec<(TableKey, Arc<UnitLayer>)>> = Mutex::new(Vec::new());
        let extent = extent.max(1.0).log2().ceil().exp2();
        let key = (poisson.to_bits(), extent.to_bits());
        let find = |tables: &[(TableKey, Arc<UnitLayer>)]| {
            tables
                .iter()
                .find(|(k, _)| *k == key)
                .map(|(_, t)| t.clone())
        };
        // A poisoned lock only means another thread panicked mid-build; the list is intact.
        if let Some(t) = find(&TABLES.lock().unwrap_or_else(|e| e.into_inner())) {
            return t;
        }
        // Built with the lock released: the build is parallel, and a rayon thread waiting
        // in it runs other presses' work, which would take the lock again and deadlock.
        let table = Arc::new(UnitLayer::new(poisson, extent));
        let mut tables = TABLES.lock().unwrap_or_else(|e| e.into_inner());
        // Another thread may have built the same table meanwhile; both are the same bits.
        if let Some(t) = find(&tables) {
            return t;
        }
        // Bound the cache for long randomised runs (Poisson's ratio drawn per sample).
        if tables.len() >= 32 {
            tables.clear();
        }
        tables.push((key, table.clone()));
        table
    }
}

/// Tabulated layer corrections C_w and C_u for one thickness and Poisson ratio.
#[derive(Clone, Debug)]
pub struct LayerCorrection {
    pub thickness_mm: f64,
    pub poisson: f64,
    unit: Arc<UnitLayer>,
}

impl LayerCorrection {
    /// Tables out to `r_max_mm`.
    pub fn new(thickness_mm: f64, poisson: f64, r_max_mm: f64) -> Self {
        Self {
            thickness_mm,
            poisson,
            unit: UnitLayer::shared(poisson, r_max_mm / thickness_mm),
        }
    }

    fn lookup(table: &[f64], rho: f64) -> f64 {
        let x = rho * SAMPLES_PER_THICKNESS;
        let i = (x.floor() as usize).min(table.len() - 2);
        let f = (x - i as f64).min(1.0);
        table[i] * (1.0 - f) + table[i + 1] * f
    }

    /// (C_w, C_u) at radius r (mm).
    pub fn at(&self, r: f64) -> (f64, f64) {
        let (h, rho) = (self.thickness_mm, r / self.thickness_mm);
        (
            Self::lookup(&self.unit.normal, rho) / h,
            Self::lookup(&self.unit.lateral, rho) / h,
        )
    }
}

/// Influence coefficients of one cell on another at offset (x, y) mm, per unit compliance.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellResponse {
    pub normal: f64,
    pub lateral_x: f64,
    pub lateral_y: f64,
}

/// Love's integrals for a cell of unit side at whole-cell offsets (i, j) >= 0: the normal
/// response and the lateral one along the offset's first axis (without T_inf). Both are
/// homogeneous of degree one in (x, y, a), so a grid of cell c takes c times these: one
/// table serves every cell size, and nearly all the transcendental work of a new grid's
/// kernels is done once per process.
struct UnitCells {
    side: usize,
    normal: Vec<f64>,
    lateral: Vec<f64>,
}

/// Tables up to this side are kept for the process (4 MB); larger grids compute their own.
const SHARED_UNIT_CELLS: usize = 512;

impl UnitCells {
    fn entry(i: usize, j: usize) -> (f64, f64) {
        let (x, y) = (i as f64, j as f64);
        (love_normal(x, y, 0.5), love_lateral_x(x, y, 0.5))
    }

    fn new(side: usize) -> Self {
        let (normal, lateral) = (0..side * side)
            .into_par_iter()
            .map(|k| Self::entry(k % side, k / side))
            .unzip();
        Self {
            side,
            normal,
            lateral,
        }
    }

    /// A table covering offsets below `side`, grown by doubling. Every entry is computed by
    /// the same formula whatever the table's size, so what a grid gets does not depend on
    /// which grids the process built before it.
    fn shared(side: usize) -> Arc<UnitCells> {
        static TABLE: Mutex<Option<Arc<UnitCells>>> = Mutex::new(None);
        if side > SHARED_UNIT_CELLS {
            return Arc::new(UnitCells::new(side));
        }
        let covering = |slot: &Option<Arc<UnitCells>>| slot.clone().filter(|t| t.side >= side);
        // A poisoned lock only means another thread panicked mid-build; the slot is intact.
        if let Some(t) = covering(&TABLE.lock().unwrap_or_else(|e| e.into_inner())) {
            return t;
        }
        // Built with the lock released, for the reason given in `UnitLayer::shared`.
        let built = Arc::new(UnitCells::new(side.next_power_of_two().max(64)));
        let mut table = TABLE.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(t) = covering(&table) {
            return t;
        }
        *table = Some(built.clone());
        built
    }
}

/// The half-space responses of a grid of `cell` mm at offsets (di, dj) in [0, nx) x [0, ny),
/// row-major.
pub fn half_space_cells(nx: usize, ny: usize, cell: f64, poisson: f64) -> Vec<CellResponse> {
    let unit = UnitCells::shared(nx.max(ny));
    let t_inf = half_space_lateral_ratio(poisson);
    let at = |i: usize, j: usize| i + j * unit.side;
    (0..nx * ny)
        .map(|k| {
            let (i, j) = (k % nx, k / nx);
            CellResponse {
                normal: cell * unit.normal[at(i, j)],
                lateral_x: t_inf * cell * unit.lateral[at(i, j)],
                lateral_y: t_inf * cell * unit.lateral[at(j, i)],
            }
        })
        .collect()
}

/// What a bonded layer adds to the half-space response at offset (x, y) from a loaded cell
/// of side `cell`: its smooth corrections averaged over the cell with 2 x 2 Gauss-Legendre.
pub fn layer_cell_correction(x: f64, y: f64, cell: f64, layer: &LayerCorrection) -> CellResponse {
    let g = cell / 2.0 / 3f64.sqrt();
    let quarter = cell * cell / 4.0 / PI;
    let mut out = CellResponse::default();
    for (sx, sy) in [(-g, -g), (g, -g), (-g, g), (g, g)] {
        let (dx, dy) = (x - sx, y - sy);
        let r = dx.hypot(dy);
        let (cw, cu) = layer.at(r);
        out.normal += quarter * cw;
        if r > 0.0 {
            out.lateral_x += quarter * cu * dx / r;
            out.lateral_y += quarter * cu * dy / r;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_unit_cell_table_scaled_to_the_cell_is_loves_integral_at_that_cell() {
        let (nx, ny, cell, nu) = (70, 9, 0.37, 0.45);
        let t_inf = half_space_lateral_ratio(nu);
        let cells = half_space_cells(nx, ny, cell, nu);
        for (k, c) in cells.iter().enumerate() {
            let (x, y) = ((k % nx) as f64 * cell, (k / nx) as f64 * cell);
            let a = cell / 2.0;
            let expected = [
                love_normal(x, y, a),
                t_inf * love_lateral_x(x, y, a),
                t_inf * love_lateral_x(y, x, a),
            ];
            // Far away both sides lose digits to the cancelling antiderivatives alike, so
            // the bound is absolute: 1e-12 of the self response (~0.3 here).
            for (got, want) in [c.normal, c.lateral_x, c.lateral_y].iter().zip(expected) {
                assert!(
                    (got - want).abs() <= 1e-12 * cells[0].normal,
                    "{k}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn love_normal_matches_the_point_load_far_away_and_the_closed_form_at_the_centre() {
        let a = 0.5;
        // Far field: a cell of area 4a^2 acts as a point load.
        let far = love_normal(20.0, 5.0, a);
        let point = 4.0 * a * a / (PI * 20.0f64.hypot(5.0));
        assert!((far - point).abs() / point < 1e-3);
        // Centre of a square: w = (4 / pi) * 2a * ln(1 + sqrt 2) (Johnson eq. 3.25).
        let centre = love_normal(0.0, 0.0, a);
        let expected = 8.0 * a * (1.0 + 2f64.sqrt()).ln() / PI;
        assert!((centre - expected).abs() < 1e-12);
    }

    #[test]
    fn lateral_coefficient_is_odd_and_matches_the_point_load() {
        let a = 0.25;
        let (x, y) = (6.0, -3.0);
        let far = love_lateral_x(x, y, a);
        let point = 4.0 * a * a * x / (PI * (x * x + y * y));
        assert!((far - point).abs() / point.abs() < 1e-3);
        assert!((love_lateral_x(-x, y, a) + far).abs() < 1e-14);
        assert!(love_lateral_x(0.0, 1.0, a).abs() < 1e-14);
    }

    #[test]
    fn layer_corrections_cancel_the_half_space_far_away() {
        // A bonded layer carries load to its base within a few thicknesses, so far from the
        // load its surface hardly moves: C_w -> -1/r.
        let layer = LayerCorrection::new(2.0, 0.45, 40.0);
        let (cw, _) = layer.at(30.0);
        assert!((cw + 1.0 / 30.0).abs() < 2e-4, "C_w(30) = {cw}");
        // Thin near-incompressible layers are much stiffer than the half-space under a
        // load: the correction is negative at the origin.
        assert!(layer.at(0.0).0 < 0.0);
    }

    #[test]
    fn one_unit_table_gives_each_thickness_its_own_corrections() {
        // C_w(r; h) = int (K(kh) - 1 + e^{-kh}) J0(kr) dk - 1 / sqrt(h^2 + r^2), here by a
        // plain trapezoid on its own fine grid in k, for thicknesses not used by the table.
        for (h, nu) in [(1.7, 0.49), (4.3, 0.49), (3.1, 0.3)] {
            let layer = LayerCorrection::new(h, nu, 20.0);
            for r in [0.0, 0.8, 3.0, 9.5] {
                let dk = 0.002 / h;
                let direct: f64 = (1..(60.0 / h / dk) as usize)
                    .map(|q| {
                        let k = q as f64 * dk;
                        (normal_compliance_ratio(k * h, nu) - 1.0 + (-k * h).exp())
                            * libm::j0(k * r)
                            * dk
                    })
                    .sum::<f64>()
                    - 1.0 / h.hypot(r);
                let (cw, _) = layer.at(r);
                // Corrections are of order 1/h; the table interpolates linearly in r.
                assert!(
                    (cw - direct).abs() < 2e-3 / h,
                    "h {h}, nu {nu}, r {r}: {cw} vs {direct}"
                );
            }
        }
    }

    #[test]
    fn tables_first_built_inside_parallel_work_do_not_deadlock() {
        // Data generation presses many objects in parallel, each building its tables on
        // first use; a table built under its cache's lock deadlocked with 16 threads. Each
        // task here needs a table no other has built (its own Poisson's ratio and extent).
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(8)
            .build()
            .unwrap();
        let (done, finished) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let built: usize = pool.install(|| {
                (0..24)
                    .into_par_iter()
                    .map(|i| {
                        let nu = 0.3 + 0.001 * f64::from(i);
                        let layer = LayerCorrection::new(1.0, nu, 1.0);
                        let cells = half_space_cells(8 + 8 * i as usize, 8, 0.1, nu);
                        usize::from(layer.at(0.0).0 < 0.0) + usize::from(cells[0].normal > 0.0)
                    })
                    .sum()
            });
            let _ = done.send(built);
        });
        let built = finished
            .recv_timeout(std::time::Duration::from_secs(120))
            .expect("the parallel table builds deadlocked");
        assert_eq!(built, 48);
    }
}
