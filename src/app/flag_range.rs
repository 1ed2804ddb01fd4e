//! Numeric flags checked where clap reads them: finite, within the range the flag's help
//! states, the range named in the error (clap names the flag). One parser for every
//! physical quantity a user types, so that NaN, infinities and 1e300 never reach a solver.

/// A number shown short: 1e300 as "1e300", not 301 digits.
pub use tactex_core::printable::short_number as show;

fn parse(text: &str, span: &str) -> Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .map_err(|_| format!("expected a number in {span}"))
}

/// A value in [lo, hi].
pub fn within(lo: f64, hi: f64) -> impl Fn(&str) -> Result<f64, String> + Clone {
    move |text| {
        let span = format!("[{}, {}]", show(lo), show(hi));
        let v = parse(text, &span)?;
        if v.is_finite() && (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(format!("{} is outside {span}", show(v)))
        }
    }
}

/// A value in (lo, hi]: above lo, e.g. a length or modulus above zero.
pub fn above(lo: f64, hi: f64) -> impl Fn(&str) -> Result<f64, String> + Clone {
    move |text| {
        let span = format!("({}, {}]", show(lo), show(hi));
        let v = parse(text, &span)?;
        if v.is_finite() && v > lo && v <= hi {
            Ok(v)
        } else {
            Err(format!("{} is outside {span}", show(v)))
        }
    }
}

/// A whole number in [lo, hi]: a count, a repetition, a table's nodes.
pub fn count<T: TryFrom<u64> + Clone + Send + Sync + 'static>(
    lo: u64,
    hi: u64,
) -> impl Fn(&str) -> Result<T, String> + Clone {
    move |text| {
        let span = format!("[{lo}, {hi}]");
        let v: u64 = text
            .trim()
            .parse()
            .map_err(|_| format!("expected a whole number in {span}"))?;
        if (lo..=hi).contains(&v) {
            T::try_from(v).map_err(|_| format!("{v} is outside {span}"))
        } else {
            Err(format!("{v} is outside {span}"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_infinities_and_huge_values_are_refused_with_the_range() {
        let p = above(0.0, 1000.0);
        assert_eq!(p("2.5"), Ok(2.5));
        for bad in ["NaN", "inf", "-inf", "1e300", "-1", "0", "abc"] {
            let e = p(bad).unwrap_err();
            assert!(e.contains("(0, 1000]"), "{bad}: {e}");
        }
        assert_eq!(p("1e300").unwrap_err(), "1e300 is outside (0, 1000]");
        let w = within(-360.0, 360.0);
        assert_eq!(w("-360"), Ok(-360.0));
        assert!(w("361").is_err());
        let c = count::<u32>(1, 1000);
        assert_eq!(c("5"), Ok(5));
        assert_eq!(c("0").unwrap_err(), "0 is outside [1, 1000]");
        assert!(c("-1").unwrap_err().contains("[1, 1000]"));
        assert!(c("1e3").unwrap_err().contains("whole number"));
    }
}
