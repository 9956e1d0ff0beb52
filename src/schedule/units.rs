//! Lengths with explicit units, so that a schedule never means "3.6 of
//! something".

use serde::{Deserialize, Serialize};

/// Units a length may be written in.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Unit {
    #[serde(rename = "m")]
    Metre,
    #[serde(rename = "cm")]
    Centimetre,
    #[serde(rename = "mm")]
    Millimetre,
    #[serde(rename = "um")]
    Micrometre,
}

impl Unit {
    /// The unit as schedules write it.
    pub fn name(self) -> &'static str {
        match self {
            Unit::Metre => "m",
            Unit::Centimetre => "cm",
            Unit::Millimetre => "mm",
            Unit::Micrometre => "um",
        }
    }

    pub fn in_metres(self) -> f64 {
        match self {
            Unit::Metre => 1.0,
            Unit::Centimetre => 1e-2,
            Unit::Millimetre => 1e-3,
            Unit::Micrometre => 1e-6,
        }
    }
}

/// A length: `{"value": 3.6, "unit": "mm"}`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Length {
    pub value: f64,
    pub unit: Unit,
}

impl Length {
    pub fn mm(value: f64) -> Length {
        Length {
            value,
            unit: Unit::Millimetre,
        }
    }

    pub fn metres(&self) -> f64 {
        self.value * self.unit.in_metres()
    }
}
