//! Camera noise that both renderers draw identically: a counter-based generator (the PCG hash
//! of Jarzynski & Olano 2020) keyed by frame seed, pixel and channel, so a pixel's noise does
//! not depend on the order pixels are computed in, on threads or on the device.
//!
//! Box-Muller with its logarithm and sine/cosine as short polynomials in plain f32 arithmetic
//! (no libm): the same bits on every machine and with or without AVX2 (Rust never fuses a
//! multiply-add on its own), the shader does the same operations, and a row of pixels
//! vectorises, which takes the noise from about 3 ms to 0.4 ms per 320x240 frame.

#[inline(always)]
pub(crate) fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The 24-bit count behind a uniform draw: 1..=2^24, exact in f32 (and in i32, whose
/// conversion vectorises where u32's does not).
#[inline(always)]
fn count(h: u32) -> f32 {
    ((h >> 8) + 1) as i32 as f32
}

/// ln(n / 2^24) for n = count(h): n = m 2^e with m in [1, 2), and ln m = 2 atanh(t),
/// t = (m - 1)/(m + 1) in [0, 1/3], by its series to t^9 (error below 1e-6).
#[inline(always)]
fn ln_unit(h: u32) -> f32 {
    let bits = count(h).to_bits();
    let e = ((bits >> 23) as i32 - 127 - 24) as f32;
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    let t = (m - 1.0) / (m + 1.0);
    let t2 = t * t;
    let series = 1.0 + t2 * (1.0 / 3.0 + t2 * (1.0 / 5.0 + t2 * (1.0 / 7.0 + t2 * (1.0 / 9.0))));
    e * std::f32::consts::LN_2 + 2.0 * t * series
}

/// (cos, sin) of 2 pi u, u = count(h) / 2^24, from the half angle a = pi u - pi/2 in
/// (-pi/2, pi/2] by Taylor polynomials (error below 1e-6 there): 2 pi u = 2a + pi.
#[inline(always)]
fn cis_unit(h: u32) -> (f32, f32) {
    let a = std::f32::consts::PI * (count(h) * (1.0 / 16_777_216.0) - 0.5);
    let a2 = a * a;
    let s = a
        * (1.0
            + a2 * (-1.0 / 6.0
                + a2 * (1.0 / 120.0
                    + a2 * (-1.0 / 5_040.0 + a2 * (1.0 / 362_880.0 - a2 / 39_916_800.0)))));
    let c = 1.0
        + a2 * (-0.5
            + a2 * (1.0 / 24.0
                + a2 * (-1.0 / 720.0
                    + a2 * (1.0 / 40_320.0 + a2 * (-1.0 / 3_628_800.0 + a2 / 479_001_600.0)))));
    (s * s - c * c, -2.0 * s * c)
}

/// Three independent standard normal draws for (frame seed, pixel), one per colour channel,
/// by Box-Muller: the first pair gives red and green (cosine and sine), the second blue.
#[inline(always)]
pub fn gaussian3(seed: u32, pixel: u32) -> [f32; 3] {
    let key = pcg(seed ^ pcg(pixel));
    let r1 = (-2.0 * ln_unit(pcg(key))).sqrt();
    let (c1, s1) = cis_unit(pcg(key ^ 0x9e37_79b9));
    let r2 = (-2.0 * ln_unit(pcg(key ^ 0x85eb_ca6b))).sqrt();
    let (c2, _) = cis_unit(pcg(key ^ 0xc2b2_ae35));
    [r1 * c1, r1 * s1, r2 * c2]
}

/// The draws of consecutive pixels `first, first + 1, ...`, one per element of `out`; with
/// AVX2 where the CPU has it (the same bits either way).
#[multiversion::multiversion(targets("x86_64+avx2"))]
pub fn gaussian3_row(seed: u32, first: u32, out: &mut [[f32; 3]]) {
    for (i, draw) in out.iter_mut().enumerate() {
        *draw = gaussian3(seed, first.wrapping_add(i as u32));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_are_standard_normal() {
        let n = 200_000u32;
        let draws: Vec<f64> = (0..n)
            .map(|p| gaussian3(7, p / 3)[(p % 3) as usize] as f64)
            .collect();
        let mean = draws.iter().sum::<f64>() / n as f64;
        let var = draws.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        let tail = draws.iter().filter(|x| x.abs() > 1.96).count() as f64 / n as f64;
        // Standard errors: mean 0.0022, variance 0.0032, two-sided 5% tail 0.0005.
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0).abs() < 0.015, "variance {var}");
        assert!((tail - 0.05).abs() < 0.003, "tail {tail}");
    }

    #[test]
    fn channels_of_a_pixel_are_uncorrelated() {
        let n = 20_000u32;
        let d: Vec<[f32; 3]> = (0..n).map(|p| gaussian3(3, p)).collect();
        for (i, j) in [(0, 1), (0, 2), (1, 2)] {
            let r = d.iter().map(|v| (v[i] * v[j]) as f64).sum::<f64>() / n as f64;
            // Standard error 0.007.
            assert!(r.abs() < 0.03, "channels {i}, {j}: {r}");
        }
    }

    #[test]
    fn seeds_give_independent_streams() {
        let a: Vec<f32> = (0..1000).map(|p| gaussian3(1, p)[0]).collect();
        let b: Vec<f32> = (0..1000).map(|p| gaussian3(2, p)[0]).collect();
        let r = a.iter().zip(&b).map(|(x, y)| x * y).sum::<f32>() / 1000.0;
        assert!(r.abs() < 0.1, "correlation {r}");
    }

    #[test]
    fn the_logarithm_and_the_angle_match_libm() {
        // Every 97th count, ends included: the polynomials against f64 libm.
        let counts = (0..=(1u32 << 24) - 1).step_by(97).chain([(1 << 24) - 1]);
        for k in counts {
            let h = k << 8;
            let u = (k as f64 + 1.0) / 16_777_216.0;
            let ln = ln_unit(h) as f64;
            assert!((ln - u.ln()).abs() < 2e-6, "ln at {u}: {ln} vs {}", u.ln());
            let (c, s) = cis_unit(h);
            let t = std::f64::consts::TAU * u;
            assert!((c as f64 - t.cos()).abs() < 2e-6, "cos at {u}");
            assert!((s as f64 - t.sin()).abs() < 2e-6, "sin at {u}");
        }
    }

    #[test]
    fn a_row_draws_what_its_pixels_draw() {
        let mut row = vec![[0.0f32; 3]; 333];
        gaussian3_row(11, 1000, &mut row);
        for (i, draw) in row.iter().enumerate() {
            let one = gaussian3(11, 1000 + i as u32);
            assert_eq!(draw.map(f32::to_bits), one.map(f32::to_bits), "pixel {i}");
        }
    }
}
