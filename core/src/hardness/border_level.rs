//! What a reading's peak is of the gel's indentation: a frame's indentation map is zeroed on
//! the frame's border (`tactile::depth::zero_level`), and a thin, near-incompressible gel
//! rises round a wide contact, so where the contact fills the frame the border stands above
//! the undisturbed gel and the peak reads deeper than the gel was pressed (the deeper, the
//! more). The layer model (`layer_compliance::hertz_surface_profile`) gives the gel's
//! surface round a contact of the size read; zeroed on the same border as the reading, its
//! peak is the share of the true indentation the reading shows.

use crate::hardness::interval_calibration::ELONGATED_ASPECT;
use crate::hardness::layer_compliance::hertz_surface_profile;
use crate::tactile::depth::zero_level_of_border;
use crate::tactile::frame_reading::FrameReading;
use crate::tactile::spec::GelSpec;

/// Points along the frame's long sides (the short ones in proportion): the level needs the
/// border's shape, not every pixel.
const SIDE_SAMPLES: usize = 64;
/// Radii the surface is computed at between the border's nearest and furthest points: it is
/// smooth there (outside the contact or across a wide one), and each costs an integral.
const PROFILE_SAMPLES: usize = 24;

/// The reading's peak over the gel's centre indentation, its contact taken as the circle of
/// its area on `gel`; 1 where the reading has no imprint middle to centre it on, or where its
/// contact is elongated (aspect `ELONGATED_ASPECT` or more, a banana's): that one reaches the
/// border along its long axis, where the circle does not, and is recentred by its own
/// calibration group instead.
pub fn read_share_of_indentation(reading: &FrameReading, gel: &GelSpec) -> f64 {
    let Some(middle_px) = reading.imprint_middle_px else {
        return 1.0;
    };
    let [wide, narrow] = reading.contact_axes_mm;
    if wide >= ELONGATED_ASPECT * narrow {
        return 1.0;
    }
    share_in_frame(
        [reading.width, reading.height],
        reading.mm_per_px,
        middle_px,
        reading.contact_radius_mm(),
        gel.thickness_mm,
        gel.poisson,
    )
}

/// The same for a frame of `size_px` pixels of `mm_per_px` with the contact's middle at
/// `middle_px`.
fn share_in_frame(
    size_px: [usize; 2],
    mm_per_px: f64,
    [cx, cy]: [f64; 2],
    contact_radius_mm: f64,
    thickness_mm: f64,
    poisson: f64,
) -> f64 {
    if !(contact_radius_mm > 0.0 && thickness_mm > 0.0 && mm_per_px > 0.0) {
        return 1.0;
    }
    let (w, h) = (size_px[0] as f64, size_px[1] as f64);
    // The border's points, side by side (top, bottom, left, right), as radii in contact radii.
    // Each side at points in proportion to its pixels, as the reading's border weighs them.
    let rows = ((SIDE_SAMPLES as f64 * h / w).round() as usize).max(2);
    let along = |n: f64, k: usize| (0..k).map(move |i| i as f64 * (n - 1.0) / (k - 1) as f64);
    let rho = |x: f64, y: f64| (x - cx).hypot(y - cy) * mm_per_px / contact_radius_mm;
    let sides: [Vec<f64>; 4] = [
        along(w, SIDE_SAMPLES).map(|x| rho(x, 0.0)).collect(),
        along(w, SIDE_SAMPLES).map(|x| rho(x, h - 1.0)).collect(),
        along(h, rows).map(|y| rho(0.0, y)).collect(),
        along(h, rows).map(|y| rho(w - 1.0, y)).collect(),
    ];
    let (near, far) = sides
        .iter()
        .flatten()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), r| {
            (lo.min(*r), hi.max(*r))
        });
    let radii: Vec<f64> = (0..PROFILE_SAMPLES)
        .map(|i| near + (far - near) * i as f64 / (PROFILE_SAMPLES - 1) as f64)
        .collect();
    let profile = hertz_surface_profile(&radii, contact_radius_mm / thickness_mm, poisson);
    let surface = |r: f64| {
        let t = ((r - near) / (far - near).max(1e-12) * (PROFILE_SAMPLES - 1) as f64)
            .clamp(0.0, (PROFILE_SAMPLES - 1) as f64);
        let i = (t.floor() as usize).min(PROFILE_SAMPLES - 2);
        let f = t - i as f64;
        profile[i] * (1.0 - f) + profile[i + 1] * f
    };
    let sides = sides.map(|side| side.into_iter().map(surface).collect());
    // The surface is highest at the contact's middle, in the frame: 1 by construction.
    let share = 1.0 - zero_level_of_border(&sides, 1.0);
    // A reading never shows less than a tenth of the press, nor ten times it.
    share.clamp(0.1, 10.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The FOTS frame: 257 x 194 px of 0.0634 mm (16.3 x 12.3 mm).
    const FRAME: [usize; 2] = [257, 194];
    const MM_PER_PX: f64 = 0.0634;
    const MIDDLE: [f64; 2] = [128.0, 96.5];

    #[test]
    fn a_small_contact_reads_its_whole_depth_and_a_frame_filling_one_reads_deep() {
        // Half a millimetre on a 4 mm gel: the border, 6 mm away, is undisturbed gel.
        let small = share_in_frame(FRAME, MM_PER_PX, MIDDLE, 0.5, 4.0, 0.49);
        assert!((small - 1.0).abs() < 0.01, "{small}");
        // Wider contacts push the border up on the gel they press out: the deeper the share.
        let shares: Vec<f64> = [2.0, 4.0, 6.0]
            .iter()
            .map(|a| share_in_frame(FRAME, MM_PER_PX, MIDDLE, *a, 4.0, 0.49))
            .collect();
        assert!(shares.windows(2).all(|p| p[0] < p[1]), "{shares:?}");
        assert!(shares[2] > 1.05, "{shares:?}");
        // A compressible gel (nu = 0.3) keeps less of its volume: it rises less.
        let soft = share_in_frame(FRAME, MM_PER_PX, MIDDLE, 6.0, 4.0, 0.3);
        assert!(soft < shares[2], "{soft} vs {}", shares[2]);
    }

    #[test]
    fn the_share_is_the_surface_at_the_border_for_a_centred_contact() {
        // Centred, the border's median is the surface at the median of its points' radii:
        // the share is 1 minus it (the surface is below zero where the gel rises).
        let a = 5.0;
        let share = share_in_frame(FRAME, MM_PER_PX, MIDDLE, a, 4.0, 0.49);
        let mut radii: Vec<f64> = (0..FRAME[0])
            .flat_map(|x| [(x as f64, 0.0), (x as f64, (FRAME[1] - 1) as f64)])
            .chain((0..FRAME[1]).flat_map(|y| [(0.0, y as f64), ((FRAME[0] - 1) as f64, y as f64)]))
            .map(|(x, y)| (x - MIDDLE[0]).hypot(y - MIDDLE[1]) * MM_PER_PX / a)
            .collect();
        radii.sort_by(f64::total_cmp);
        let rho = radii[radii.len() / 2];
        let expected = 1.0 - hertz_surface_profile(&[rho], a / 4.0, 0.49)[0];
        assert!(
            (share - expected).abs() < 0.01 * expected,
            "{share} vs {expected}"
        );
    }

    #[test]
    fn a_reading_takes_the_share_of_its_round_contact_and_none_for_an_elongated_one() {
        let gel = GelSpec {
            modulus_mpa: 0.3,
            poisson: 0.49,
            thickness_mm: 4.0,
        };
        let reading = |axes: [f64; 2], middle: Option<[f64; 2]>| FrameReading {
            width: FRAME[0],
            height: FRAME[1],
            indentation_mm: vec![0.0; FRAME[0] * FRAME[1]],
            valid: vec![true; FRAME[0] * FRAME[1]],
            peak_mm: 0.5,
            contact_axes_mm: axes,
            contact_outline_px: None,
            within_frame: true,
            imprint_middle_px: middle,
            mm_per_px: MM_PER_PX,
            drift: None,
        };
        // A round contact: the share of the circle of its area (5 mm).
        let round = read_share_of_indentation(&reading([6.25, 4.0], Some(MIDDLE)), &gel);
        let circle = share_in_frame(FRAME, MM_PER_PX, MIDDLE, 5.0, 4.0, 0.49);
        assert!(
            (round - circle).abs() < 1e-12 && round > 1.05,
            "{round} vs {circle}"
        );
        // A banana's contact of the same area, and a reading with no imprint: as read.
        assert_eq!(
            read_share_of_indentation(&reading([10.0, 2.5], Some(MIDDLE)), &gel),
            1.0
        );
        assert_eq!(
            read_share_of_indentation(&reading([6.25, 4.0], None), &gel),
            1.0
        );
    }
}
