//! IES LM-63 photometric files (1986, 1991, 1995, 2002 and 2019 dialects): the header,
//! the tilt data and the candela table, ready to become a
//! [`GoniometricTable`](candela_core::photometry::GoniometricTable).
//!
//! Only type C photometry (photometric type 1, the one luminaires for interiors and
//! streets use) is supported; type B (floodlights) and type A (automotive) files are
//! rejected with a clear error.
//!
//! Files are read as bytes and decoded leniently (UTF-8 where valid, Latin-1 otherwise);
//! a DOS end-of-file byte (^Z) and an `END` line after the data are ignored. Numbers may
//! be separated by spaces, tabs, commas or line breaks anywhere after the `TILT=` line.

mod analysis;
mod parse;

use std::path::Path;

use candela_core::desc::Span;
use candela_core::photometry::{GoniometricTable, HorizontalSymmetry};

pub use analysis::{polar_plot, summary, IesSummary};
pub use parse::parse_ies;

use crate::LoadError;

/// Which edition of LM-63 a file follows, from its first line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IesVersion {
    /// No version line: free-text header lines up to `TILT=`.
    Lm63_1986,
    /// `IESNA91`.
    Lm63_1991,
    /// `IESNA:LM-63-1995`.
    Lm63_1995,
    /// `IESNA:LM-63-2002`.
    Lm63_2002,
    /// `IES:LM-63-2019`.
    Lm63_2019,
}

/// Units of the luminous opening's dimensions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IesUnits {
    Feet,
    Meters,
}

/// Lamp tilt data: how the lamp's output changes with the tilt of the luminaire as
/// installed (`TILT=INCLUDE` or `TILT=<file>`).
#[derive(Clone, Debug, PartialEq)]
pub struct TiltTable {
    /// 1: lamp vertical base up or down; 2: horizontal, tilting in the C0 plane keeps it
    /// horizontal; 3: horizontal, tilting in the C0 plane tilts it.
    pub lamp_geometry: u32,
    /// Increasing tilt angles (degrees).
    pub angles: Vec<f64>,
    /// Multiplying factor at each angle.
    pub factors: Vec<f64>,
}

impl TiltTable {
    /// The factor at tilt angle `deg`, interpolated linearly and held at the ends.
    pub fn factor(&self, deg: f64) -> f64 {
        let (a, f) = (&self.angles, &self.factors);
        if deg <= a[0] {
            return f[0];
        }
        let k = a.partition_point(|&x| x < deg);
        if k >= a.len() {
            return f[f.len() - 1];
        }
        let t = (deg - a[k - 1]) / (a[k] - a[k - 1]);
        (1.0 - t) * f[k - 1] + t * f[k]
    }
}

/// The `TILT=` line.
#[derive(Clone, Debug, PartialEq)]
pub enum Tilt {
    None,
    /// Tilt data inside the file.
    Include(TiltTable),
    /// Tilt data read from the named file, next to the IES file.
    File(String, TiltTable),
}

/// A parsed IES file.
///
/// `candela` holds the luminaire's intensities as the file means them: the raw values
/// multiplied by the candela multiplier, the ballast factor, the ballast-lamp photometric
/// factor (only in the 1986–1995 editions; 2002 made that field "future use" and 2019 the
/// "file generation type", so it is not applied there) and, with tilt data, the tilt
/// factor at 0° (the luminaire installed as measured). Stated lumens are not scaled.
#[derive(Clone, Debug, PartialEq)]
pub struct IesFile {
    pub version: IesVersion,
    /// Keyword lines (`[TEST]`, `[MANUFAC]`, …) in file order, keys without brackets;
    /// `[MORE]` lines are appended to the previous keyword's value after a newline.
    pub keywords: Vec<(String, String)>,
    /// Free-text header lines of 1986 files (no keywords).
    pub text: Vec<String>,
    pub tilt: Tilt,
    pub lamp_count: u32,
    /// Rated lumens per lamp; −1 for absolute photometry.
    pub lumens_per_lamp: f64,
    pub multiplier: f64,
    /// 1 = type C, 2 = type B, 3 = type A. Only type C is accepted.
    pub photometric_type: u32,
    pub units: IesUnits,
    /// Width, length and height of the luminous opening, in `units` (negative = round).
    pub dimensions: [f64; 3],
    pub ballast_factor: f64,
    /// Ballast-lamp photometric factor (1995 and before), "future use" (2002) or file
    /// generation type (2019): the second number of the ballast line.
    pub ballast_lamp_factor: f64,
    pub input_watts: f64,
    pub vertical_angles: Vec<f64>,
    pub horizontal_angles: Vec<f64>,
    /// Scaled candela values, `candela[h * vertical_angles.len() + v]`.
    pub candela: Vec<f64>,
    /// Where the file came from, for errors about it after parsing.
    pub span: Span,
}

impl IesFile {
    /// The value of keyword `key` (without brackets), if present.
    pub fn keyword(&self, key: &str) -> Option<&str> {
        self.keywords
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(key))
            .map(|(_, v)| v.as_str())
    }

    /// Total rated lamp lumens (lamps × lumens per lamp); `None` for absolute photometry.
    pub fn stated_lumens(&self) -> Option<f64> {
        (self.lumens_per_lamp > 0.0).then_some(self.lumens_per_lamp * self.lamp_count as f64)
    }

    /// The luminous opening in metres.
    pub fn dimensions_m(&self) -> [f64; 3] {
        let s = match self.units {
            IesUnits::Feet => 0.3048,
            IesUnits::Meters => 1.0,
        };
        self.dimensions.map(|d| d * s)
    }

    pub fn symmetry(&self) -> HorizontalSymmetry {
        HorizontalSymmetry::classify(&self.horizontal_angles)
            .expect("angles were validated by the parser")
    }

    /// The candela table over the whole sphere (the file's angles were validated when it
    /// was parsed, so this only fails for an `IesFile` edited by hand).
    pub fn table(&self) -> Result<GoniometricTable, LoadError> {
        GoniometricTable::new(
            &self.vertical_angles,
            &self.horizontal_angles,
            &self.candela,
        )
        .map_err(|e| LoadError {
            span: self.span.clone(),
            message: e.0,
        })
    }
}

/// Reads and parses an IES file; a `TILT=<file>` is looked up next to it.
pub fn load_ies(path: &Path) -> Result<IesFile, LoadError> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| LoadError {
        span: Span::new(name.clone(), 0, 0),
        message: format!("cannot read: {e}"),
    })?;
    parse_ies(&bytes, &name)
}
