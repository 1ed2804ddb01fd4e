//! Camera noise that both renderers draw identically: a counter-based generator (the PCG hash
//! of Jarzynski & Olano 2020) keyed by frame seed, pixel and channel, so a pixel's noise does
//! not depend on the order pixels are computed in, on threads or on the device.

pub(crate) fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// A uniform in (0, 1] from a hash (24 bits).
fn unit(h: u32) -> f32 {
    ((h >> 8) as f32 + 1.0) / 16_777_216.0
}

/// Three independent standard normal draws for (frame seed, pixel), one per colour channel,
/// by Box-Muller: the first pair gives red and green (cosine and sine), the second blue. In
/// f32, the same operations as the shader.
pub fn gaussian3(seed: u32, pixel: u32) -> [f32; 3] {
    let key = pcg(seed ^ pcg(pixel));
    let r1 = (-2.0 * unit(pcg(key)).ln()).sqrt();
    let t1 = std::f32::consts::TAU * unit(pcg(key ^ 0x9e37_79b9));
    let r2 = (-2.0 * unit(pcg(key ^ 0x85eb_ca6b)).ln()).sqrt();
    let t2 = std::f32::consts::TAU * unit(pcg(key ^ 0xc2b2_ae35));
    [r1 * t1.cos(), r1 * t1.sin(), r2 * t2.cos()]
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
}
