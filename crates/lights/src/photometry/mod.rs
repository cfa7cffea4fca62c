//! Measured luminaires: readers of the photometric file formats lighting designers exchange.
//! Small and strict, written from the formats' documents (no dependency: the crates that read
//! them today are AGPL-3.0 or unlicensed). Each reader turns a file into its candela table and
//! names the file and line of anything wrong.
//!
//! Two readers, one view: [`IesFile`] (IES LM-63) and [`LdtFile`] (EULUMDAT) both give
//! [`CandelaPlanes`], the stored part of their type C table in absolute candela, with the
//! horizontal range declaring the symmetry as IES LM-63 does.

use std::fmt;

mod ies;
mod ldt;
mod lumens;
mod luminaire;

/// The luminous opening shape the readers give ([`IesFile::luminous_opening`],
/// [`LdtFile::luminous_opening`]), also at the crate root.
pub use crate::glare::LuminousOpening;
pub use ies::{IesFile, IesVersion, MAX_ANGLES, Photometry, Tilt, Units};
pub use ldt::{LampSet, LdtFile, LdtSymmetry, MAX_LAMP_SETS};
pub use lumens::LuminaireLumens;
pub use luminaire::{CandelaDistribution, EulumdatLight, IesLight, MAX_PHOTOMETRIC_BYTES};

/// Where a photometric file went wrong: the file's name as given, the line (1-based) and the
/// cause.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PhotometryError {
    /// The file name, as passed to the reader's `parse` ([`IesFile::parse`], [`LdtFile::parse`]).
    pub file: String,
    /// Line number, 1-based (the last line for a file that ends too early).
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for PhotometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.file, self.line, self.message)
    }
}

impl std::error::Error for PhotometryError {}

/// The text of a photometric file as makers ship it: UTF-8 (a byte-order mark dropped), or,
/// where the bytes are not UTF-8, Windows-1252 (the Latin-1 superset older lighting software
/// writes: a `°` or `§` in a label); every line end (CR LF, LF, or an old Mac's lone CR) made a
/// LF; DOS end-of-file marks (^Z) at the end dropped. Returns the text and what was done that a
/// reader should be told (`None` for plain UTF-8 with LF or CR LF line ends).
pub fn decode_text(bytes: &[u8]) -> (String, Option<String>) {
    let mut notes = Vec::new();
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let text = match std::str::from_utf8(bytes) {
        Ok(t) => t.to_owned(),
        Err(e) => {
            notes.push(format!(
                "not UTF-8 (byte {:#04x} at offset {}): read as Windows-1252 (Latin-1)",
                bytes[e.valid_up_to()],
                e.valid_up_to()
            ));
            encoding_rs::WINDOWS_1252.decode_without_bom_handling(bytes).0.into_owned()
        }
    };
    let trimmed = text.trim_end_matches(|c: char| c == '\u{1a}' || c.is_whitespace());
    if trimmed.len() < text.trim_end().len() {
        notes.push("a DOS end-of-file mark (^Z) at the end was ignored".to_owned());
    }
    let lone_cr = text.replace("\r\n", "").contains('\r');
    if lone_cr {
        notes.push("lines end in a lone CR (old Mac OS): read as line ends".to_owned());
    }
    let text = trimmed.replace("\r\n", "\n").replace('\r', "\n");
    (text, (!notes.is_empty()).then(|| notes.join("; ")))
}

/// The former name of [`PhotometryError`], from when the IES reader was the only one.
pub type IesError = PhotometryError;

/// The stored part of a type C candela table, absolute.
#[derive(Debug, Clone, PartialEq)]
pub struct CandelaPlanes {
    /// Horizontal (C-plane) angles in degrees, strictly increasing, in the stored range that
    /// declares the symmetry exactly as IES LM-63 does: `[0]` (rotational), 0..=90 (quadrant),
    /// 0..=180 (bilateral about C0-C180), 90..=270 (bilateral about C90-C270), 0..<=360 (none).
    pub horizontal: Vec<f64>,
    /// Vertical (gamma) angles in degrees from nadir, strictly increasing, within [0, 180].
    pub vertical: Vec<f64>,
    /// Absolute candela, `candela[h][v]`.
    pub candela: Vec<Vec<f64>>,
    /// Rated lamp lumens the table was scaled for (sum over lamps), `None` for absolute
    /// photometry.
    pub lamp_lumens: Option<f64>,
}
