//! The grid a recording was made on.

/// The nominal grid frequency: given, or detected from the data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Nominal {
    /// Decide between 50 and 60 Hz from the spectrum.
    Auto,
    /// A known grid frequency, Hz.
    Hz(f64),
}

impl Nominal {
    /// The grid frequency when it is given, Hz; `None` when it is to be detected.
    pub fn hz(self) -> Option<f64> {
        match self {
            Nominal::Hz(f) => Some(f),
            Nominal::Auto => None,
        }
    }
}

impl std::str::FromStr for Nominal {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "auto" => Ok(Nominal::Auto),
            "50" => Ok(Nominal::Hz(50.0)),
            "60" => Ok(Nominal::Hz(60.0)),
            _ => Err(format!("expected 50, 60 or auto, got {s:?}")),
        }
    }
}
