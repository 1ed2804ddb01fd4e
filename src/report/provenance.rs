//! Where a generated report came from: the date, the commit of the build and the command
//! line, as the first line of every markdown table a command writes (docs/results/ keeps
//! them), so that a figure can always be traced to what made it.
//!
//! The date honours `SOURCE_DATE_EPOCH` (the reproducible-builds convention), so a run that
//! sets it writes the same bytes on any day.

use crate::report::output::write_bytes_atomic;
use anyhow::Result;
use std::path::Path;

/// The commit the binary was built from (build.rs), or "unknown" outside a checkout.
pub const BUILD_COMMIT: &str = env!("TACTEX_BUILD_COMMIT");

/// `body` written to `path` whole, headed by the provenance line.
pub fn write_markdown_report(path: &Path, body: &str) -> Result<()> {
    write_bytes_atomic(path, format!("{}\n\n{body}", provenance_line()).as_bytes())
}

/// "_Made on 2026-11-25 from commit 1084872 by `tactex bench ask --out docs/results/bench`._"
fn provenance_line() -> String {
    let command = command_line(std::env::args().skip(1));
    format!(
        "_Made on {} from commit {BUILD_COMMIT} by `{command}`._",
        utc_date(unix_seconds())
    )
}

fn unix_seconds() -> i64 {
    if let Some(s) = std::env::var("SOURCE_DATE_EPOCH")
        .ok()
        .and_then(|v| v.trim().parse::<i64>().ok())
    {
        return s;
    }
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() as i64)
}

/// `tactex ARGS`, each argument quoted for a POSIX shell where it needs it.
fn command_line(args: impl Iterator<Item = String>) -> String {
    let mut line = String::from("tactex");
    for a in args {
        line.push(' ');
        let plain = !a.is_empty()
            && a.chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_./,=:+@%".contains(c));
        if plain {
            line.push_str(&a);
        } else {
            line.push('\'');
            line.push_str(&a.replace('\'', r"'\''"));
            line.push('\'');
        }
    }
    tactex_core::printable::printable(&line)
}

/// The proleptic Gregorian date of a Unix time, as YYYY-MM-DD (Hinnant's civil_from_days).
fn utc_date(unix_s: i64) -> String {
    let z = unix_s.div_euclid(86_400) + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_match_the_calendar_across_leap_days_and_the_epoch() {
        assert_eq!(utc_date(0), "1970-01-01");
        // 2000-02-29 12:00 UTC (a leap day of a century leap year), from `date -u -d`.
        assert_eq!(utc_date(951_825_600), "2000-02-29");
        assert_eq!(utc_date(1_709_164_800), "2024-02-29");
        assert_eq!(utc_date(1_795_564_800), "2026-11-25");
        assert_eq!(utc_date(-1), "1969-12-31");
    }

    #[test]
    fn a_command_line_can_be_pasted_back_into_a_shell() {
        let args = ["ask", "Which fruit is the softest?", "--seed", "3", "it's"];
        assert_eq!(
            command_line(args.iter().map(|s| s.to_string())),
            r"tactex ask 'Which fruit is the softest?' --seed 3 'it'\''s'"
        );
    }
}
