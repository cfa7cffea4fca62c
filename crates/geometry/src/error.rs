//! [`GeometryError`]: which shape, which field, what is wrong.

use std::path::PathBuf;

/// Why a shape, transform or world could not be built. Raised by constructors and at
/// deserialisation, so a scene file with a bad shape is rejected with the shape and field named.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GeometryError {
    /// A parameter is out of its valid range.
    #[error("{shape}.{field} = {value}: {reason}")]
    Parameter {
        /// The shape type (or `"Transform"`), e.g. `"Sphere"`.
        shape: &'static str,
        /// The field, e.g. `"radius"`.
        field: &'static str,
        /// The rejected value, formatted.
        value: String,
        /// What the value must satisfy.
        reason: &'static str,
    },
    /// A triangle names a vertex that does not exist.
    #[error("Mesh.triangles[{triangle}]: vertex index {index} out of range ({count} positions)")]
    IndexOutOfRange {
        /// Which triangle (0-based).
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// How many positions the mesh has.
        count: usize,
    },
    /// An OBJ file could not be read or is not a usable triangle mesh.
    #[error("Mesh.obj = {path:?}: {reason}")]
    Obj {
        /// The path as resolved against the base directory.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// A PLY file could not be read or is not a usable triangle mesh.
    #[error("Mesh.ply = {path:?}: {reason}")]
    Ply {
        /// The path as resolved against the base directory.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// A Mitsuba serialized mesh file could not be read or is not a usable triangle mesh.
    #[error("Mesh.serialized = {path:?}: {reason}")]
    Serialized {
        /// The path as resolved against the base directory.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// A mesh given by an OBJ path was passed to [`crate::World::new`] before being loaded.
    #[error(
        "shape {index}: Mesh.obj = {path:?} is not loaded; use World::with_base_dir or Shape::load"
    )]
    UnloadedMesh {
        /// Index of the shape in the list.
        index: usize,
        /// The unresolved path.
        path: PathBuf,
    },
    /// The world has more primitives than a `u32` can index.
    #[error("too many primitives: {count}")]
    TooManyPrimitives {
        /// How many there were.
        count: usize,
    },
}

impl GeometryError {
    /// A parameter error.
    pub fn parameter(
        shape: &'static str,
        field: &'static str,
        value: impl std::fmt::Debug,
        reason: &'static str,
    ) -> Self {
        Self::Parameter { shape, field, value: format!("{value:?}"), reason }
    }
}
