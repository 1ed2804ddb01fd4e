//! The predefined ArUco dictionaries a board's markers come from: OpenCV's, bit for bit, so
//! a board printed here is detected by any ArUco detector told the same name.

use serde::{Deserialize, Serialize};
use std::str::FromStr;

/// One of OpenCV's predefined dictionaries (the names OpenCV gives them).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ArucoDictionary {
    #[serde(rename = "DICT_4X4_50")]
    Dict4x4_50,
    #[serde(rename = "DICT_5X5_100")]
    Dict5x5_100,
    #[serde(rename = "DICT_6X6_250")]
    Dict6x6_250,
}

impl ArucoDictionary {
    pub const ALL: [ArucoDictionary; 3] = [Self::Dict4x4_50, Self::Dict5x5_100, Self::Dict6x6_250];

    /// OpenCV's name for it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Dict4x4_50 => "DICT_4X4_50",
            Self::Dict5x5_100 => "DICT_5X5_100",
            Self::Dict6x6_250 => "DICT_6X6_250",
        }
    }

    /// Inner bits per side of a marker (its black border not counted).
    pub fn marker_bits(self) -> usize {
        match self {
            Self::Dict4x4_50 => 4,
            Self::Dict5x5_100 => 5,
            Self::Dict6x6_250 => 6,
        }
    }

    /// How many markers it holds.
    pub fn marker_count(self) -> usize {
        self.table().lines().count()
    }

    /// Marker `id`'s inner bits, row by row (true is white); None past the dictionary's end.
    pub fn marker(self, id: usize) -> Option<Vec<bool>> {
        let line = self.table().lines().nth(id)?;
        Some(line.bytes().map(|b| b == b'1').collect())
    }

    fn table(self) -> &'static str {
        match self {
            Self::Dict4x4_50 => include_str!("dictionaries/4x4_50.txt"),
            Self::Dict5x5_100 => include_str!("dictionaries/5x5_100.txt"),
            Self::Dict6x6_250 => include_str!("dictionaries/6x6_250.txt"),
        }
    }
}

impl FromStr for ArucoDictionary {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|d| d.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|d| d.name()).collect();
                format!(
                    "unknown ArUco dictionary {s:?}; one of {}",
                    names.join(", ")
                )
            })
    }
}

impl std::fmt::Display for ArucoDictionary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
