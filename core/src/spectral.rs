//! The 2-D FFT both sides need: the twin's layer transfer functions (sim) and the slope
//! integration of tactile perception (core).

use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

thread_local! {
    /// Plans are kept per thread: a frame's reading runs several transforms of one size.
    static PLANNER: std::cell::RefCell<FftPlanner<f64>> = std::cell::RefCell::new(FftPlanner::new());
}

/// 2-D FFT in place (row-major nx x ny); the inverse is unnormalised.
pub fn fft2(data: &mut [Complex<f64>], nx: usize, ny: usize, inverse: bool) {
    let (row, col) = PLANNER.with_borrow_mut(|planner| {
        if inverse {
            (planner.plan_fft_inverse(nx), planner.plan_fft_inverse(ny))
        } else {
            (planner.plan_fft_forward(nx), planner.plan_fft_forward(ny))
        }
    });
    row.process(data);
    let mut column = vec![Complex::default(); ny];
    for i in 0..nx {
        for j in 0..ny {
            column[j] = data[j * nx + i];
        }
        col.process(&mut column);
        for j in 0..ny {
            data[j * nx + i] = column[j];
        }
    }
}
