//! `tactex`: the TactEx twin command line. Parses, runs the command from the `tactex`
//! library, and prints any error as one line.

use clap::Parser;
use std::process::ExitCode;
use tactex::cli::{Cli, Command, error_line, process, usage_error_line};

// Frames, fields and FFT scratch are allocated and freed by the hundred per press; glibc
// returns blocks this size to the kernel on every free and faults them back in, which cost
// a third of the gel-fields stage (measured with `bench render`).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    process::ensure_runtime_dir();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // Help and the version are what was asked for.
        Err(e)
            if matches!(
                e.kind(),
                clap::error::ErrorKind::DisplayHelp
                    | clap::error::ErrorKind::DisplayVersion
                    | clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) =>
        {
            e.exit()
        }
        // A bad value, a flag missing or in conflict: bad input like any other, one line
        // (clap quotes values as given: escape codes and bidirectional overrides shown).
        Err(e) => {
            eprintln!("{}", usage_error_line(&e));
            return ExitCode::FAILURE;
        }
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
