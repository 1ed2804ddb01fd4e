//! `tactex`: the TactEx twin command line. Parses, runs the command from the `tactex`
//! library, and prints any error as one line.

use clap::Parser;
use std::process::ExitCode;
use tactex::cli::{Cli, Command, error_line, process};

// Frames, fields and FFT scratch are allocated and freed by the hundred per press; glibc
// returns blocks this size to the kernel on every free and faults them back in, which cost
// a third of the gel-fields stage (measured with `bench render`).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    process::ensure_runtime_dir();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // A value out of its flag's range is a bad value like any other: one line, exit 1.
        Err(e) if e.kind() == clap::error::ErrorKind::ValueValidation => {
            let text = e.render().to_string();
            let line = text.lines().next().unwrap_or("error: invalid value");
            // clap quotes the value as given: escape codes and bidirectional overrides shown.
            eprintln!("{}", tactex_core::printable::printable(line));
            return ExitCode::FAILURE;
        }
        Err(e) => e.exit(),
    };
    if !matches!(cli.command, Command::Serve(_) | Command::Twin(_)) {
        process::quiet_on_closed_pipe();
    }
    match tactex::cli::run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_line(&e));
            ExitCode::FAILURE
        }
    }
}
