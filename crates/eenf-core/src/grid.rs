//! The grid a recording was made on: [`Grid`], and [`Nominal`] (a grid given, or to be
//! found from the data). One type for the grid, so that no value but 50 and 60 Hz can stand
//! for one.

/// A mains grid: its nominal frequency is 50 Hz (Europe, Africa, most of Asia, Australia) or
/// 60 Hz (the Americas, Taiwan, Korea, part of Japan, Saudi Arabia).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Grid {
    /// A 50 Hz grid.
    Hz50,
    /// A 60 Hz grid.
    Hz60,
}

impl Grid {
    /// Both grids, 50 Hz first: the order in which an undecided search tries them.
    pub const ALL: [Grid; 2] = [Grid::Hz50, Grid::Hz60];

    /// The nominal frequency, Hz.
    pub fn hz(self) -> f64 {
        match self {
            Grid::Hz50 => 50.0,
            Grid::Hz60 => 60.0,
        }
    }

    /// The grid whose nominal frequency is `hz` exactly (a value read from a file or an
    /// option); `None` for any other value.
    pub fn of_hz(hz: f64) -> Option<Grid> {
        Grid::ALL.into_iter().find(|g| g.hz() == hz)
    }

    /// The grid a frequency `hz` lies within 1 Hz of (a trace's mean: a grid strays by
    /// tenths of a hertz at most); `None` when it is near neither.
    pub fn near(hz: f64) -> Option<Grid> {
        Grid::ALL.into_iter().find(|g| (hz - g.hz()).abs() < 1.0)
    }
}

impl std::fmt::Display for Grid {
    /// `50` or `60`: as the option is written and as messages say "a 50 Hz grid".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.hz())
    }
}

/// The nominal grid frequency: given, or detected from the data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Nominal {
    /// Decide between 50 and 60 Hz from the spectrum.
    Auto,
    /// A known grid.
    Grid(Grid),
}

impl Nominal {
    /// The grid when it is given; `None` when it is to be detected.
    pub fn grid(self) -> Option<Grid> {
        match self {
            Nominal::Grid(g) => Some(g),
            Nominal::Auto => None,
        }
    }

    /// The grid frequency when it is given, Hz; `None` when it is to be detected.
    pub fn hz(self) -> Option<f64> {
        self.grid().map(Grid::hz)
    }

    /// The grids to try: the one given, or both.
    pub fn grids(self) -> &'static [Grid] {
        match self {
            Nominal::Auto => &Grid::ALL,
            Nominal::Grid(Grid::Hz50) => &[Grid::Hz50],
            Nominal::Grid(Grid::Hz60) => &[Grid::Hz60],
        }
    }
}

impl From<Grid> for Nominal {
    fn from(g: Grid) -> Nominal {
        Nominal::Grid(g)
    }
}

impl std::str::FromStr for Grid {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "50" => Ok(Grid::Hz50),
            "60" => Ok(Grid::Hz60),
            _ => Err(format!("expected 50 or 60, got {s:?}")),
        }
    }
}

impl std::str::FromStr for Nominal {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "auto" => Ok(Nominal::Auto),
            "50" | "60" => s.parse().map(Nominal::Grid),
            _ => Err(format!("expected 50, 60 or auto, got {s:?}")),
        }
    }
}
