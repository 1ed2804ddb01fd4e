//! `tactex`: the TactEx twin command line, a thin shell over the `tactex` library's
//! [`tactex::cli::main`].

use std::process::ExitCode;

// Frames, fields and FFT scratch are allocated and freed by the hundred per press; glibc
// returns blocks this size to the kernel on every free and faults them back in, which cost
// a third of the gel-fields stage (measured with `bench render`).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    tactex::cli::main()
}
