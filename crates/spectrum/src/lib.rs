//! Spectra and colour for Spectrace: spectral power distributions that lights sample wavelengths
//! from, reflectance spectra that materials apply, and the CIE 1931 colorimetry that turns
//! sampled wavelengths into XYZ and sRGB on the film.
//!
//! This crate sits on `spectrace-sampling` (whose exact inverse-CDF generators draw the
//! wavelengths) and under `spectrace-lights` (every light owns an SPD) and the tracer (whose film
//! uses [`cmf`] and [`Xyz`]). Its main type is the [`SpectralPowerDistribution`] trait (seed
//! 2.1.1): normalised to integral 1 over its [`range`](SpectralPowerDistribution::range),
//! evaluated by [`value`](SpectralPowerDistribution::value) and importance-sampled by its own shape
//! with [`sample_lambda`](SpectralPowerDistribution::sample_lambda) from an explicit uniform `u`.
//! The trait is typetag-serialisable, so scene files name any SPD by type and third parties can
//! add their own.
//!
//! | SPD | shape | sampling |
//! |---|---|---|
//! | [`Tabulated`] | piecewise linear through `(nm, value)` points | exact (cancellation-free quadratic) |
//! | [`Binned`] | piecewise constant bins | exact |
//! | [`Blackbody`] | Planck's law, 100 K to 10^6 K and beyond | exact (tabulated inverse CDF, O(1)) |
//! | [`Gaussian`] | truncated Gaussian line, fwhm down to 1e-6 nm | exact (tabulated inverse CDF, O(1)) |
//! | [`Monochromatic`] | a delta line | trivially exact |
//! | [`Uniform`] | equal energy | exact |
//! | [`Mixture`] | weighted sum of SPDs | its own tabulated inverse CDF; with delta lines, component by power |
//! | [`CieIlluminant`] | A, D50, D55, D65, D75, E, F1-F12 | as their shapes |
//!
//! The key design decision is that spectra are *normalised densities*, not radiometric
//! quantities: a light multiplies its SPD by its power. [`Reflectance`] (and its alias
//! [`Transmittance`]) is a separate type, a fraction in `[0, 1]` per wavelength that is never
//! normalised. The CIE 1931 2-degree observer is embedded from the official 1 nm table
//! ([`data::cie1931`], source named there).
//!
//! Colours given in RGB become spectra through Jakob and Hanika's sigmoid model: [`rgb`] fits one
//! colour exactly (scene colours), [`RgbTable`] interpolates a coefficient table the project's own
//! solver fits on first use (texture texels), and [`Reflectance::from_sigmoid`] carries either
//! without allocating.
//!
//! # Example
//! ```
//! use spectrace_spectrum::{Blackbody, SpectralPowerDistribution, xyz_of};
//! let sun = Blackbody::new(5778.0).unwrap();
//! let lambda = sun.sample_lambda(0.5); // the median wavelength
//! assert!((360.0..830.0).contains(&lambda));
//! let (x, y) = xyz_of(&sun).chromaticity().unwrap();
//! assert!((x - 0.326).abs() < 0.002 && (y - 0.337).abs() < 0.002);
//! ```

mod analytic;
mod blackbody;
mod cie;
pub mod data;
mod error;
mod illuminant;
mod inverse;
mod melanopic;
mod mixture;
mod photometric;
mod reflectance;
pub mod rgb;
mod rgb_table;
mod spd;
mod tabulated;

pub use analytic::{DEFAULT_MAX_NM, DEFAULT_MIN_NM, Gaussian, Monochromatic, Uniform};
pub use blackbody::{Blackbody, PLANCK_C2_NM_K};
pub use cie::{
    CIE_Y_INTEGRAL, SRGB_PRIMARIES, SRGB_WHITE, XYZ_TO_SRGB, Xyz, XyzEstimator, cmf, srgb_decode,
    srgb_encode, srgb_to_xyz_matrix, xyz_of,
};
pub use error::SpectrumError;
pub use illuminant::{CieIlluminant, KNOWN_ILLUMINANTS, daylight};
pub use melanopic::{MELANOPIC_EFFICACY_D65, melanopic_action, melanopic_edi_per_watt};
pub use mixture::{Component, MAX_TABLE_COMPONENTS, MAX_TABLE_PANELS, Mixture};
pub use photometric::{
    PEAK_LUMINOUS_EFFICACY, lumens_per_watt, luminous_efficacy, watts_from_lumens,
};
pub use reflectance::{Reflectance, Transmittance};
pub use rgb_table::RgbTable;
pub use spd::{MAX_NM_PANELS, SpectralPowerDistribution, integrate_panels};
pub use tabulated::{Binned, Tabulated};

/// Clamps a uniform variate into `[0, 1)`; out-of-range or NaN `u` is a caller bug (debug
/// builds panic, release builds clamp).
#[inline]
pub(crate) fn unit(u: f64) -> f64 {
    debug_assert!((0.0..1.0).contains(&u), "uniform variate u = {u} is outside [0, 1)");
    spectrace_sampling::clamp_uniform(u)
}
