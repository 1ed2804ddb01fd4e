//! The four fidelity levels a contact can be solved at, cheapest first.

use std::fmt;
use std::str::FromStr;

/// How much physics a contact solve models.
/// `Default` is the layer model, the one every command takes unless told.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Fidelity {
    Rigid,
    Hertz,
    Halfspace,
    #[default]
    Layer,
}

impl Fidelity {
    pub const ALL: [Fidelity; 4] = [
        Fidelity::Rigid,
        Fidelity::Hertz,
        Fidelity::Halfspace,
        Fidelity::Layer,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            Fidelity::Rigid => "rigid",
            Fidelity::Hertz => "hertz",
            Fidelity::Halfspace => "halfspace",
            Fidelity::Layer => "layer",
        }
    }
}

impl fmt::Display for Fidelity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl serde::Serialize for Fidelity {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl FromStr for Fidelity {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Fidelity::ALL
            .into_iter()
            .find(|f| f.name() == s.trim().to_ascii_lowercase())
            .ok_or_else(|| format!("unknown fidelity {s:?} (use rigid, hertz, halfspace or layer)"))
    }
}
