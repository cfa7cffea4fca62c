//! Official CIE colorimetric data: the CIE 1931 2° standard observer colour
//! matching functions ([`cie1931`]), CIE illuminants A, D65, the daylight basis
//! S0/S1/S2 and F1–F12 ([`illuminants`]), and reference chromaticities for tests
//! ([`reference`](mod@reference)).
//!
//! Sources: the 1 nm table of ISO/CIE 11664-1:2019 (CIE S 014-1) for the observer;
//! CIE 15:2004 Tables T.1, T.2 and T.6 for the illuminants; all numbers were
//! extracted from (or, for [`reference`](mod@reference), computed with) colour-science 0.4.7's bundled copy of
//! the CIE tables by `extract_cie.py` in this directory, which regenerates
//! these files.

pub mod cie1931;
pub mod illuminants;
pub mod melanopic;
pub mod reference;
