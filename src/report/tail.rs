//! How every command hands its report to the terminal: one JSON object on stdout with
//! `--json` (what scripts and the Python package read), else the text a person reads.

use anyhow::{Context, Result};
use serde::Serialize;

/// Prints `report` as one pretty JSON object when `json`, else runs `text`, which prints what
/// a person reads.
pub fn print_json_or_text<R: Serialize + ?Sized>(
    report: &R,
    json: bool,
    text: impl FnOnce() -> Result<()>,
) -> Result<()> {
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(report).context("serialising the report")?
        );
        Ok(())
    } else {
        text()
    }
}
