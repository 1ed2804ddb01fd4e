//! The numbers a request takes, each with the range its help states: one `Field` per
//! quantity, checked by the same code where clap reads the CLI's flag and where the library
//! checks a request built in code (Python, a user's program), so that NaN, infinities and
//! 1e300 never reach a solver and the range is written once.

/// A number shown short: 1e300 as "1e300", not 301 digits.
pub use tactex_core::printable::short_number as show;

/// A request's field that is out of range or ill-formed. `field` is the request's own name
/// for it (`depth_mm`); each front end says it in its caller's words (`--depth-mm` on the
/// command line, as `Display` does; `depth_mm` in Python).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}: {problem}", flag(field))]
pub struct FieldError {
    pub field: String,
    pub problem: String,
}

impl FieldError {
    pub fn new(field: &str, problem: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            problem: problem.into(),
        }
    }
}

/// A field as the command line names it: `depth_mm` -> `--depth-mm`.
pub fn flag(field: &str) -> String {
    format!("--{}", field.replace('_', "-"))
}

/// A number a request takes and the range it may lie in: [lo, hi], or (lo, hi] where a
/// value must be above lo (a length, a modulus).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Field {
    pub name: &'static str,
    lo: f64,
    hi: f64,
    open_below: bool,
}

impl Field {
    /// A value in [lo, hi].
    pub const fn within(name: &'static str, lo: f64, hi: f64) -> Self {
        Self {
            name,
            lo,
            hi,
            open_below: false,
        }
    }

    /// A value in (lo, hi].
    pub const fn above(name: &'static str, lo: f64, hi: f64) -> Self {
        Self {
            name,
            lo,
            hi,
            open_below: true,
        }
    }

    /// The range as the errors and help write it: "[0, 30]", "(0, 1000]".
    pub fn span(&self) -> String {
        let open = if self.open_below { '(' } else { '[' };
        format!("{open}{}, {}]", show(self.lo), show(self.hi))
    }

    fn holds(&self, v: f64) -> bool {
        let above_lo = if self.open_below {
            v > self.lo
        } else {
            v >= self.lo
        };
        v.is_finite() && above_lo && v <= self.hi
    }

    /// `v` when it lies in the range; else the error naming the field and the range.
    pub fn check(&self, v: f64) -> Result<f64, FieldError> {
        if self.holds(v) {
            Ok(v)
        } else {
            Err(FieldError::new(
                self.name,
                format!("{} is outside {}", show(v), self.span()),
            ))
        }
    }

    /// Clap's parser for the field's flag: the same check, the message without the name
    /// (clap names the flag).
    pub fn parser(self) -> impl Fn(&str) -> Result<f64, String> + Clone {
        move |text| {
            let v = text
                .trim()
                .parse::<f64>()
                .map_err(|_| format!("expected a number in {}", self.span()))?;
            self.check(v).map_err(|e| e.problem)
        }
    }
}

/// Clap's parser for a value in [lo, hi], for a flag with no request field of its own.
pub fn within(lo: f64, hi: f64) -> impl Fn(&str) -> Result<f64, String> + Clone {
    Field::within("", lo, hi).parser()
}

/// Clap's parser for a value in (lo, hi]: above lo, e.g. a length or modulus above zero.
pub fn above(lo: f64, hi: f64) -> impl Fn(&str) -> Result<f64, String> + Clone {
    Field::above("", lo, hi).parser()
}

/// Clap's parser for a choice among `names` (shown in `--help` and in the error), read by
/// the choice's own `FromStr`: the one parse the library, Python and files use too.
pub fn choice<T>(names: &'static [&'static str]) -> impl clap::builder::TypedValueParser<Value = T>
where
    T: std::str::FromStr<Err = String> + Clone + Send + Sync + 'static,
{
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(names).try_map(|s| s.parse::<T>())
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

    #[test]
    fn a_field_checked_in_code_is_named_as_the_flag_that_sets_it() {
        let depth = Field::within("depth_mm", 0.0, 30.0);
        assert_eq!(depth.check(30.0), Ok(30.0));
        let e = depth.check(f64::NAN).unwrap_err();
        assert_eq!(e.field, "depth_mm");
        assert_eq!(e.to_string(), "--depth-mm: NaN is outside [0, 30]");
        assert_eq!(depth.parser()("31").unwrap_err(), "31 is outside [0, 30]");
    }
}
