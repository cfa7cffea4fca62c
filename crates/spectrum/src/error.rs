//! The error type of this crate: which spectrum, which field, what is wrong.

use spectrace_sampling::SamplingError;

/// Why a spectrum could not be built. Messages name the spectrum type and the field at fault, so
/// a scene loader can prefix them with the path of the spectrum in the file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SpectrumError {
    /// A table (wavelengths and values) is malformed; the source names the array and index.
    #[error("{spectrum}: {source}")]
    Table {
        /// The spectrum type, e.g. `"Tabulated"`.
        spectrum: &'static str,
        /// What is wrong with the table.
        source: SamplingError,
    },
    /// A scalar parameter is out of its valid range.
    #[error("{spectrum}.{field} = {value}: {reason}")]
    Parameter {
        /// The spectrum type, e.g. `"Blackbody"`.
        spectrum: &'static str,
        /// The parameter's field name, e.g. `"kelvin"`.
        field: &'static str,
        /// The rejected value.
        value: f64,
        /// What the value must satisfy.
        reason: &'static str,
    },
    /// A reflectance or transmittance value is outside `[0, 1]`.
    #[error("{field}[{index}] = {value}: a {quantity} must lie in [0, 1]")]
    ReflectanceOutOfRange {
        /// `"reflectance"` or `"transmittance"`.
        quantity: &'static str,
        /// The field name (`"values"` or `"constant"`).
        field: &'static str,
        /// Index of the offending value (0 for a constant).
        index: usize,
        /// The rejected value.
        value: f64,
    },
    /// A CIE illuminant name that this crate does not know.
    #[error("unknown CIE illuminant `{name}`; known: {known}")]
    UnknownIlluminant {
        /// The name given.
        name: String,
        /// The names this crate knows, comma-separated.
        known: &'static str,
    },
    /// A mixture without components.
    #[error("Mixture.components is empty")]
    EmptyMixture,
}

impl SpectrumError {
    /// Wraps a sampling-table error, renaming the sampler's generic arrays to the spectrum's field
    /// names (e.g. `xs` -> `nm`, `ys` -> `values`).
    pub(crate) fn table(
        spectrum: &'static str,
        renames: &[(&'static str, &'static str)],
        source: SamplingError,
    ) -> Self {
        let source = renames.iter().fold(source, |e, (from, to)| e.with_array(from, to));
        Self::Table { spectrum, source }
    }

    /// A parameter error.
    pub(crate) fn parameter(
        spectrum: &'static str,
        field: &'static str,
        value: f64,
        reason: &'static str,
    ) -> Self {
        Self::Parameter { spectrum, field, value, reason }
    }
}

/// Checks a wavelength range `[min_nm, max_nm]`: finite, positive, increasing.
pub(crate) fn check_range(
    spectrum: &'static str,
    min_nm: f64,
    max_nm: f64,
) -> Result<(), SpectrumError> {
    if !(min_nm.is_finite() && min_nm > 0.0) {
        return Err(SpectrumError::parameter(
            spectrum,
            "min_nm",
            min_nm,
            "must be a positive, finite wavelength",
        ));
    }
    if !(max_nm.is_finite() && max_nm > min_nm) {
        return Err(SpectrumError::parameter(
            spectrum,
            "max_nm",
            max_nm,
            "must be finite and greater than min_nm",
        ));
    }
    Ok(())
}
