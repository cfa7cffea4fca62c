//! [`MaterialError`]: which material, which field, what is wrong.

/// Why a material (or an index of refraction) could not be built. Raised by constructors and at
/// deserialisation, so a scene file with a bad material is rejected with the material type and
/// the field path named, e.g. `Dielectric.ior.sellmeier.c[2] = 0.25: ...`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MaterialError {
    /// A parameter is out of its valid range.
    #[error("{} = {value}: {reason}", path(material, field))]
    Parameter {
        /// The type at fault, e.g. `"Dielectric"` or `"Ior"`.
        material: &'static str,
        /// The field path inside it, e.g. `"ior.sellmeier.c[2]"` (empty for the value itself).
        field: String,
        /// The rejected value, formatted.
        value: String,
        /// What the value must satisfy.
        reason: String,
    },
    /// A glass name that the catalog does not know.
    #[error("{}: unknown glass `{name}`; known: {known}", path(material, field))]
    UnknownGlass {
        /// The type at fault.
        material: &'static str,
        /// The field path, e.g. `"ior.glass"`.
        field: String,
        /// The name given.
        name: String,
        /// The catalog's names and aliases, comma-separated.
        known: String,
    },
    /// A metal symbol that the catalog does not know.
    #[error("{}: unknown metal `{name}`; known: {known}", path(material, field))]
    UnknownMetal {
        /// The type at fault.
        material: &'static str,
        /// The field path, e.g. `"metal"`.
        field: String,
        /// The symbol given.
        name: String,
        /// The catalog's symbols, comma-separated.
        known: String,
    },
    /// A texture that could not be built: its file unreadable or undecodable, or a field bad.
    #[error("texture.{field}: {reason}")]
    Texture {
        /// The texture's field, e.g. `"file"`.
        field: &'static str,
        /// What is wrong, naming the file where there is one.
        reason: String,
    },
}

/// `material.field`, or `material` alone for an empty field.
fn path(material: &str, field: &str) -> String {
    if field.is_empty() { material.to_owned() } else { format!("{material}.{field}") }
}

impl MaterialError {
    /// A parameter error.
    pub fn parameter(
        material: &'static str,
        field: impl Into<String>,
        value: impl std::fmt::Debug,
        reason: impl Into<String>,
    ) -> Self {
        Self::Parameter {
            material,
            field: field.into(),
            value: format!("{value:?}"),
            reason: reason.into(),
        }
    }

    /// Re-homes an error raised by a component (e.g. an [`Ior`](crate::Ior)) inside the field
    /// `field` of `material`: `Ior.sellmeier.c[2]` becomes `Dielectric.ior.sellmeier.c[2]`.
    pub fn within(self, material: &'static str, field: &str) -> Self {
        let nest = |inner: String| {
            if inner.is_empty() { field.to_owned() } else { format!("{field}.{inner}") }
        };
        match self {
            Self::Parameter { field: inner, value, reason, .. } => {
                Self::Parameter { material, field: nest(inner), value, reason }
            }
            Self::UnknownGlass { field: inner, name, known, .. } => {
                Self::UnknownGlass { material, field: nest(inner), name, known }
            }
            Self::UnknownMetal { field: inner, name, known, .. } => {
                Self::UnknownMetal { material, field: nest(inner), name, known }
            }
            texture @ Self::Texture { .. } => texture,
        }
    }

    /// The same error attributed to `material`, field path unchanged: an error of a component
    /// whose fields are written at the top level of the material (`ComplexIor.eta.values[3]`
    /// becomes `RoughConductor.eta.values[3]`).
    pub fn in_material(self, material: &'static str) -> Self {
        match self {
            Self::Parameter { field, value, reason, .. } => {
                Self::Parameter { material, field, value, reason }
            }
            Self::UnknownGlass { field, name, known, .. } => {
                Self::UnknownGlass { material, field, name, known }
            }
            Self::UnknownMetal { field, name, known, .. } => {
                Self::UnknownMetal { material, field, name, known }
            }
            texture @ Self::Texture { .. } => texture,
        }
    }

    /// The full path of the offending field, e.g. `"Dielectric.ior.sellmeier.c[2]"`.
    pub fn field_path(&self) -> String {
        match self {
            Self::Parameter { material, field, .. }
            | Self::UnknownGlass { material, field, .. }
            | Self::UnknownMetal { material, field, .. } => path(material, field),
            Self::Texture { field, .. } => format!("texture.{field}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nesting_prefixes_the_path() {
        let e = MaterialError::parameter("Ior", "sellmeier.c[2]", 0.25, "pole");
        assert_eq!(e.to_string(), "Ior.sellmeier.c[2] = 0.25: pole");
        let e = e.within("Dielectric", "ior");
        assert_eq!(e.field_path(), "Dielectric.ior.sellmeier.c[2]");
        assert_eq!(e.to_string(), "Dielectric.ior.sellmeier.c[2] = 0.25: pole");
        let bare =
            MaterialError::parameter("Ior", "", 0.5, "must be >= 1").within("Dielectric", "ior");
        assert_eq!(bare.to_string(), "Dielectric.ior = 0.5: must be >= 1");
    }
}
