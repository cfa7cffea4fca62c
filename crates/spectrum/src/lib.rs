//! Spectra (placeholder while the crate is written).
