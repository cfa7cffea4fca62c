//! [`LightError`]: which light, which field, what is wrong.

use spectrace_spectrum::SpectrumError;

/// Why a light could not be built. Raised by constructors and at deserialisation, so a scene file
/// with a bad light is rejected with the light type and field named.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LightError {
    /// A parameter is out of its valid range.
    #[error("{light}.{field} = {value}: {reason}")]
    Parameter {
        /// The light type, e.g. `"Laser"`.
        light: &'static str,
        /// The field, e.g. `"direction"`.
        field: &'static str,
        /// The rejected value, formatted.
        value: String,
        /// What the value must satisfy.
        reason: &'static str,
    },
    /// The light's spectrum is invalid.
    #[error("{light}.spd: {source}")]
    Spectrum {
        /// The light type.
        light: &'static str,
        /// What is wrong with the spectrum.
        source: SpectrumError,
    },
    /// A file the light reads (a measured luminaire's photometric file) cannot be read or is
    /// malformed; the message names the file and, for a malformed one, the line.
    #[error("{light}.{field}: {message}")]
    File {
        /// The light type, e.g. `"IesLight"`.
        light: &'static str,
        /// The field naming the file, e.g. `"file"`.
        field: &'static str,
        /// What is wrong, naming the file (and line).
        message: String,
    },
    /// An experiment hook (e.g. [`crate::LightSource::set_wavelength_sampling`]) that this light
    /// type does not offer.
    #[error("{field}: this light type cannot change it once built")]
    Unsupported {
        /// The field that could not be changed, e.g. `"wavelength_sampling"`.
        field: &'static str,
    },
    /// A light set without lights, or whose lights have no power.
    #[error("LightSet.lights: {reason}")]
    EmptySet {
        /// Why the set cannot emit.
        reason: &'static str,
    },
}

impl LightError {
    /// A parameter error.
    pub fn parameter(
        light: &'static str,
        field: &'static str,
        value: impl std::fmt::Debug,
        reason: &'static str,
    ) -> Self {
        Self::Parameter { light, field, value: format!("{value:?}"), reason }
    }
}
