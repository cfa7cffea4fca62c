//! Measured luminaires: readers of the photometric file formats lighting designers exchange.
//! Small and strict, written from the formats' documents (no dependency: the crates that read
//! them today are AGPL-3.0 or unlicensed). Each reader turns a file into its candela table and
//! names the file and line of anything wrong.

mod ies;
mod luminaire;

pub use ies::{IesError, IesFile, IesVersion, MAX_ANGLES, Tilt, Units};
pub use luminaire::{CandelaDistribution, IesLight, MAX_PHOTOMETRIC_BYTES};
