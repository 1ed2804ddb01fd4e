//! Hardness on the Shore A and Shore 00 durometer scales, or as a Young's modulus, and the
//! documented conversions between them.
//!
//! * Shore A, S >= 40: Gent (1958), E[MPa] = (15.729 + 2.14124 S) / (100 - S).
//! * Shore A, S < 40 (where Gent is not valid): a C1 continuation, quadratic in ln E, that
//!   matches Gent's value and slope at 40 A and puts 0 A at the modulus of 40 on the 00 scale
//!   (durometer conversion charts place 0 A near 40 00). Monotone and positive.
//! * Shore 00: the type-00 durometer read through Hertz contact, after Mix & Giacomin (2011,
//!   "Standardized polymer durometry", J. Testing and Evaluation 39(4)): ASTM D2240 type 00
//!   has a hemispherical indenter of radius 1.19 mm, 2.54 mm extension at 0, and a spring force
//!   of 0.203 N + 9.08 mN per point; an incompressible half-space (nu = 0.5) indented to
//!   d = 2.54 mm (1 - S/100) by that force gives E = 3 (1 - nu^2) F / (4 sqrt(R) d^1.5).
//!   It agrees with Gent near the scales' overlap (80 00 -> 1.3 MPa vs Gent's 30 A -> 1.1 MPa).
//!
//! 100 on either scale means rigid; rigid is its own variant, never a huge number.

use serde::{Deserialize, Serialize};
use std::fmt;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Hardness {
    ShoreA(f64),
    Shore00(f64),
    ModulusMpa(f64),
    Rigid,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HardnessError {
    #[error(
        "'{0}' is not a hardness: use e.g. \"35A\", \"55 00\", \"rigid\" or a modulus like \"0.8 MPa\""
    )]
    Unparsed(String),
    #[error("Shore value {0} is outside [0, 100]")]
    ShoreOutOfRange(f64),
    #[error("modulus {0} MPa must be finite and positive")]
    BadModulus(f64),
}

const GENT_FROM: f64 = 40.0;
const ZERO_A_IN_00: f64 = 40.0;

fn gent_mpa(s: f64) -> f64 {
    (15.729 + 2.14124 * s) / (100.0 - s)
}

fn gent_slope(s: f64) -> f64 {
    229.853 / ((100.0 - s) * (100.0 - s))
}

/// Shore A to Young's modulus in MPa; None means rigid (S = 100).
pub fn shore_a_to_modulus_mpa(s: f64) -> Option<f64> {
    if s >= 100.0 {
        return None;
    }
    let s = s.max(0.0);
    if s >= GENT_FROM {
        return Some(gent_mpa(s));
    }
    let l40 = gent_mpa(GENT_FROM).ln();
    let k = gent_slope(GENT_FROM) / gent_mpa(GENT_FROM);
    let l0 = shore_00_to_modulus_mpa(ZERO_A_IN_00)
        .expect("finite below 100")
        .ln();
    let c = (l0 - l40 + GENT_FROM * k) / (GENT_FROM * GENT_FROM);
    let x = s - GENT_FROM;
    Some((l40 + k * x + c * x * x).exp())
}

/// Shore 00 to Young's modulus in MPa; None means rigid (S = 100).
pub fn shore_00_to_modulus_mpa(s: f64) -> Option<f64> {
    if s >= 100.0 {
        return None;
    }
    let s = s.max(0.0);
    let force_n = 0.203 + 0.00908 * s;
    let depth_m = 2.54e-3 * (1.0 - s / 100.0);
    let radius_m: f64 = 1.19e-3;
    let nu: f64 = 0.5;
    let e_pa = 3.0 * (1.0 - nu * nu) * force_n / (4.0 * radius_m.sqrt() * depth_m.powf(1.5));
    Some(e_pa * 1e-6)
}

/// Inverts a monotone increasing Shore map by bisection; 0 below the scale, towards 100 above.
fn invert(map: fn(f64) -> Option<f64>, e_mpa: f64) -> f64 {
    let e0 = map(0.0).expect("finite at 0");
    if e_mpa <= e0 {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0_f64, 100.0_f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        match map(mid) {
            Some(e) if e < e_mpa => lo = mid,
            _ => hi = mid,
        }
    }
    0.5 * (lo + hi)
}

pub fn modulus_to_shore_a(e_mpa: f64) -> f64 {
    invert(shore_a_to_modulus_mpa, e_mpa)
}

pub fn modulus_to_shore_00(e_mpa: f64) -> f64 {
    invert(shore_00_to_modulus_mpa, e_mpa)
}

impl Hardness {
    /// Parses "35A", "35 A", "55 00", "55OO", "shore 00 55", "rigid", "0.8 MPa", "800 kPa".
    pub fn parse(text: &str) -> Result<Hardness, HardnessError> {
        let t = text.trim().to_ascii_lowercase().replace("shore", "");
        let t = t.trim();
        let bad = || HardnessError::Unparsed(text.to_string());
        if t == "rigid" {
            return Ok(Hardness::Rigid);
        }
        let compact: String = t.chars().filter(|c| !c.is_whitespace()).collect();
        let (number, scale) = if let Some(n) = compact.strip_suffix("mpa") {
            (n.to_string(), "mpa")
        } else if let Some(n) = compact.strip_suffix("kpa") {
            (n.to_string(), "kpa")
        } else if let Some(n) = compact
            .strip_prefix("00")
            .or_else(|| compact.strip_prefix("oo"))
        {
            (n.to_string(), "00")
        } else if let Some(n) = compact
            .strip_suffix("00")
            .or_else(|| compact.strip_suffix("oo"))
        {
            // "5500" is ambiguous without a separator; require one unless the scale is "oo".
            if compact.ends_with("00") && !t.contains(char::is_whitespace) {
                return Err(bad());
            }
            (n.to_string(), "00")
        } else if let Some(n) = compact
            .strip_suffix('a')
            .or_else(|| compact.strip_prefix('a'))
        {
            (n.to_string(), "a")
        } else {
            return Err(bad());
        };
        let value: f64 = number.parse().map_err(|_| bad())?;
        match scale {
            "mpa" => Hardness::from_modulus_mpa(value),
            "kpa" => Hardness::from_modulus_mpa(value / 1000.0),
            "00" => Hardness::shore(value, Hardness::Shore00),
            _ => Hardness::shore(value, Hardness::ShoreA),
        }
    }

    fn shore(value: f64, make: fn(f64) -> Hardness) -> Result<Hardness, HardnessError> {
        if !(0.0..=100.0).contains(&value) {
            return Err(HardnessError::ShoreOutOfRange(value));
        }
        Ok(if value >= 100.0 {
            Hardness::Rigid
        } else {
            make(value)
        })
    }

    pub fn from_modulus_mpa(e: f64) -> Result<Hardness, HardnessError> {
        if e.is_finite() && e > 0.0 {
            Ok(Hardness::ModulusMpa(e))
        } else {
            Err(HardnessError::BadModulus(e))
        }
    }

    /// Young's modulus in MPa; None when rigid.
    pub fn modulus_mpa(&self) -> Option<f64> {
        match *self {
            Hardness::ShoreA(s) => shore_a_to_modulus_mpa(s),
            Hardness::Shore00(s) => shore_00_to_modulus_mpa(s),
            Hardness::ModulusMpa(e) => Some(e),
            Hardness::Rigid => None,
        }
    }

    pub fn shore_a(&self) -> f64 {
        match *self {
            Hardness::ShoreA(s) => s,
            _ => self.modulus_mpa().map_or(100.0, modulus_to_shore_a),
        }
    }

    pub fn shore_00(&self) -> f64 {
        match *self {
            Hardness::Shore00(s) => s,
            _ => self.modulus_mpa().map_or(100.0, modulus_to_shore_00),
        }
    }
}

impl fmt::Display for Hardness {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Hardness::ShoreA(s) => write!(f, "{s:.1} Shore A"),
            Hardness::Shore00(s) => write!(f, "{s:.1} Shore 00"),
            Hardness::ModulusMpa(e) => write!(f, "{e:.3} MPa"),
            Hardness::Rigid => write!(f, "rigid"),
        }
    }
}

/// The three numbers every report carries for a hardness.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HardnessReport {
    pub shore_a: f64,
    pub shore_00: f64,
    /// None when rigid.
    pub modulus_mpa: Option<f64>,
}

impl HardnessReport {
    /// The Shore reading on the scale that resolves it: "36 Shore A", or "55 Shore 00" for
    /// objects too soft for Shore A.
    pub fn shore_words(&self) -> String {
        if self.shore_a < 10.0 {
            format!("{:.0} Shore 00", self.shore_00)
        } else {
            format!("{:.0} Shore A", self.shore_a)
        }
    }
}

impl From<Hardness> for HardnessReport {
    fn from(h: Hardness) -> Self {
        HardnessReport {
            shore_a: h.shore_a(),
            shore_00: h.shore_00(),
            modulus_mpa: h.modulus_mpa(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn gent_reference_values() {
        // Gent (1958) evaluated by hand: 50 A -> (15.729 + 107.062) / 50.
        assert!((shore_a_to_modulus_mpa(50.0).unwrap() - 2.45582).abs() < 1e-5);
        assert!((shore_a_to_modulus_mpa(60.0).unwrap() - 3.605085).abs() < 1e-5);
    }

    #[test]
    fn continuation_below_40_a_is_c1_at_the_join() {
        let below = shore_a_to_modulus_mpa(40.0 - 1e-6).unwrap();
        let at = shore_a_to_modulus_mpa(40.0).unwrap();
        assert!((below - at).abs() < 1e-6);
        let slope_below = (at - shore_a_to_modulus_mpa(40.0 - 1e-4).unwrap()) / 1e-4;
        assert!((slope_below - gent_slope(40.0)).abs() / gent_slope(40.0) < 1e-3);
        assert!(
            (shore_a_to_modulus_mpa(0.0).unwrap() - shore_00_to_modulus_mpa(40.0).unwrap()).abs()
                < 1e-12
        );
    }

    #[test]
    fn shore_00_map_matches_the_hertz_durometer_formula() {
        // 50 00: F = 0.657 N, d = 1.27 mm, E = 0.5625 F / (sqrt(1.19e-3) d^1.5).
        let expected = 0.5625 * 0.657 / (1.19e-3_f64.sqrt() * 1.27e-3_f64.powf(1.5)) * 1e-6;
        assert!((shore_00_to_modulus_mpa(50.0).unwrap() - expected).abs() < 1e-12);
    }

    #[test]
    fn parses_the_scene_file_spellings() {
        assert_eq!(Hardness::parse("35A").unwrap(), Hardness::ShoreA(35.0));
        assert_eq!(Hardness::parse("35 A").unwrap(), Hardness::ShoreA(35.0));
        assert_eq!(Hardness::parse("55 00").unwrap(), Hardness::Shore00(55.0));
        assert_eq!(Hardness::parse("55OO").unwrap(), Hardness::Shore00(55.0));
        assert_eq!(Hardness::parse("55oo").unwrap(), Hardness::Shore00(55.0));
        assert_eq!(
            Hardness::parse("Shore 00 55").unwrap(),
            Hardness::Shore00(55.0)
        );
        assert_eq!(Hardness::parse("rigid").unwrap(), Hardness::Rigid);
        assert_eq!(Hardness::parse("100A").unwrap(), Hardness::Rigid);
        assert_eq!(
            Hardness::parse("0.8 MPa").unwrap(),
            Hardness::ModulusMpa(0.8)
        );
        assert_eq!(
            Hardness::parse("800 kPa").unwrap(),
            Hardness::ModulusMpa(0.8)
        );
        for bad in ["", "soft", "120A", "-3A", "5500", "nanA", "0 MPa", "A"] {
            assert!(Hardness::parse(bad).is_err(), "{bad:?} must not parse");
        }
    }

    #[test]
    fn round_trip_through_modulus() {
        for s in [0.5, 10.0, 39.9, 40.0, 65.0, 99.0] {
            let e = shore_a_to_modulus_mpa(s).unwrap();
            assert!((modulus_to_shore_a(e) - s).abs() < 1e-9, "A {s}");
            let e = shore_00_to_modulus_mpa(s).unwrap();
            assert!((modulus_to_shore_00(e) - s).abs() < 1e-9, "00 {s}");
        }
    }

    proptest! {
        #[test]
        fn maps_are_finite_positive_and_monotone(a in 0.0f64..100.0, b in 0.0f64..100.0) {
            for map in [shore_a_to_modulus_mpa, shore_00_to_modulus_mpa] {
                let (ea, eb) = (map(a).unwrap(), map(b).unwrap());
                prop_assert!(ea.is_finite() && ea > 0.0 && eb.is_finite() && eb > 0.0);
                if a < b { prop_assert!(ea < eb); }
            }
        }

        #[test]
        fn inverse_is_finite_for_any_modulus(log_e in -12.0f64..12.0) {
            let e = 10f64.powf(log_e);
            let (a, oo) = (modulus_to_shore_a(e), modulus_to_shore_00(e));
            prop_assert!((0.0..=100.0).contains(&a) && (0.0..=100.0).contains(&oo));
        }
    }

    #[test]
    fn extremes_stay_finite() {
        for s in [0.0, 1e-9, 99.9999, 100.0] {
            for h in [Hardness::ShoreA(s), Hardness::Shore00(s)] {
                let r = HardnessReport::from(h);
                assert!(r.shore_a.is_finite() && r.shore_00.is_finite());
                assert!(r.modulus_mpa.is_none_or(|e| e.is_finite() && e > 0.0));
            }
        }
        assert_eq!(Hardness::Rigid.modulus_mpa(), None);
        assert_eq!(HardnessReport::from(Hardness::Rigid).shore_a, 100.0);
    }
}
