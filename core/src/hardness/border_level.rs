//! What a reading's peak is of the gel's indentation: a frame's indentation map is zeroed on
//! the frame's border (`tactile::depth::zero_level`), and a thin, near-incompressible gel
//! rises round a wide contact, so where the contact fills the frame the border stands above
//! the undisturbed gel and the peak reads deeper than the gel was pressed (the deeper, the
//! more). The layer model (`layer_compliance::hertz_surface_over_centre`) gives the gel's
//! surface round a contact of the size read; zeroed on the same border as the reading, its
//! peak is the share of the true indentation the reading shows.

use crate::hardness::layer_compliance::hertz_surface_over_centre;
use crate::tactile::depth::zero_level;
use crate::tactile::frame_reading::FrameReading;

/// Columns of the model's map: the border level needs the border's shape, not every pixel.
const MAP_COLUMNS: usize = 64;
/// Radii the surface is tabulated at (in contact radii), to `MAX_RHO`.
const PROFILE_SAMPLES: usize = 160;
const MAX_RHO: f64 = 16.0;

/// The reading's peak over the gel's centre indentation, for a reading whose contact has
/// radius `contact_radius_mm` (the circle of its area) on a gel of `thickness_mm` and
/// Poisson ratio `poisson`; 1 where the reading has no imprint middle to centre it on.
pub fn read_share_of_indentation(
    reading: &FrameReading,
    contact_radius_mm: f64,
    thickness_mm: f64,
    poisson: f64,
) -> f64 {
    let Some([cx, cy]) = reading.imprint_middle_px else {
        return 1.0;
    };
    if !(contact_radius_mm > 0.0 && thickness_mm > 0.0) {
        return 1.0;
    }
    let aoh = contact_radius_mm / thickness_mm;
    let profile: Vec<f64> = (0..PROFILE_SAMPLES)
        .map(|i| {
            let rho = MAX_RHO * i as f64 / (PROFILE_SAMPLES - 1) as f64;
            hertz_surface_over_centre(rho, aoh, poisson)
        })
        .collect();
    let surface = |rho: f64| {
        let t = (rho / MAX_RHO * (PROFILE_SAMPLES - 1) as f64).min((PROFILE_SAMPLES - 1) as f64);
        let i = (t.floor() as usize).min(PROFILE_SAMPLES - 2);
        let f = t - i as f64;
        profile[i] * (1.0 - f) + profile[i + 1] * f
    };
    let (w, h) = (reading.width, reading.height);
    let nx = MAP_COLUMNS.min(w).max(2);
    let ny = ((nx as f64 * h as f64 / w as f64).round() as usize).clamp(2, h.max(2));
    let map: Vec<f64> = (0..ny)
        .flat_map(|j| (0..nx).map(move |i| (i, j)))
        .map(|(i, j)| {
            let x = i as f64 * (w - 1) as f64 / (nx - 1) as f64;
            let y = j as f64 * (h - 1) as f64 / (ny - 1) as f64;
            let r_mm = (x - cx).hypot(y - cy) * reading.mm_per_px;
            surface(r_mm / contact_radius_mm)
        })
        .collect();
    let share = 1.0 - zero_level(&map, nx, ny);
    // A reading never shows less than a tenth of the press, nor ten times it.
    share.clamp(0.1, 10.0)
}
