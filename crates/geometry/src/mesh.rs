//! [`Mesh`]: triangle meshes, inline or loaded from Wavefront OBJ (through `tobj`).
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `obj` | path | none | OBJ file, relative to the base directory the caller passes ([`crate::World::with_base_dir`]); polygons are triangulated, normals and texture coordinates kept when present |
//! | `ply` | path | none | PLY file (ASCII or binary), instead of `obj`, resolved the same way: `vertex` `x y z`, with `nx ny nz` and `u v` kept when present; `face` `vertex_indices` polygons triangulated (the `ply` module) |
//! | `serialized`, `shape_index` | path, index | none, `0` | a Mitsuba serialized mesh file instead, and which of its meshes (the `serialized` module) |
//! | `vertex_normals` | | `"file"` | for a mesh file: `"file"` (its normals; flat where it has none), `"computed"` (its normals, or angle-weighted averages of the faces where it has none, as Mitsuba computes) or `"none"` (flat shading) |
//! | `positions` | m, `[[x, y, z], ...]` | none | inline vertices (instead of `obj`) |
//! | `triangles` | `[[i, j, k], ...]` | required with `positions` | 0-based vertex indices, counter-clockwise seen from the outward side |
//! | `normals` | `[[x, y, z], ...]` | none | per-vertex shading normals (inline only; as many as `positions`) |
//! | `uvs` | `[[u, v], ...]` | none | per-vertex texture coordinates (inline only; as many as `positions`) |
//! | `transform` | [`Transform`] | none | any affine transform; a mirroring transform reverses the winding so outward stays outward |
//!
//! ```json
//! {"type": "Mesh", "obj": "models/bunny.obj", "transform": {"scale": 0.1}}
//! {"type": "Mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "triangles": [[0, 1, 2]]}
//! ```
//!
//! Geometric normal: `normalize((p1 - p0) x (p2 - p0))`. `uv`: interpolated `uvs` when present,
//! else the barycentric coordinates `(b1, b2)`. Texture coordinates are read as textures use them
//! (`v = 0` at the image's top row, as in Mitsuba 3): inline `uvs`, PLY and serialized files as
//! stored, OBJ's `vt` as `(u, 1 - v)` (OBJ counts `v` up from the bottom). Each triangle is one BVH primitive.
//!
//! Robustness: the watertight ray/triangle test of Woop, Benthin and Wald (2013) in f64 —
//! vertices are translated to the ray origin, permuted so the ray's largest direction component
//! is `z`, sheared, and the three edge functions decide inside/outside with a consistent rule for
//! exact zeros, so a ray through a shared edge or vertex hits at least one of the triangles
//! sharing it. The `t > 0` test is made conservative with pbrt's bound on `t`'s rounding error,
//! and the point `b0 p0 + b1 p1 + b2 p2` carries the error `gamma(7) sum |b_i p_i|`.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};
use wide::{CmpEq, CmpGt, CmpLt, f64x4};

use crate::float::{gamma, safe_length};
use crate::shape::{Primitives, SurfacePoint};
use crate::{Bounds, GeometryError, Hit, Ray, Transform};

/// The world-space data of a loaded mesh.
#[derive(Debug, Clone, PartialEq)]
struct MeshData {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    normals: Option<Vec<DVec3>>,
    uvs: Option<Vec<DVec2>>,
    /// Running sums of the triangles' areas (`cumulative_area[i]` = area of triangles `0..=i`),
    /// built once with the mesh, for sampling a triangle by area with a binary search.
    cumulative_area: Vec<f64>,
}

/// A triangle mesh. One given by an OBJ path is loaded by [`Mesh::load`] (or
/// [`crate::World::with_base_dir`]), since the path is relative to the scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "MeshRepr", into = "MeshRepr")]
pub struct Mesh {
    data: Option<Arc<MeshData>>,
    repr: Box<MeshRepr>,
}

/// The 12 triangles of a cube whose corner `i` has `x`, `y`, `z` from bits 0, 1, 2 of `i` (0 the
/// low side, 1 the high), counter-clockwise seen from outside.
pub const CUBE_TRIANGLES: [[u32; 3]; 12] = [
    [0, 2, 3],
    [0, 3, 1],
    [4, 5, 7],
    [4, 7, 6],
    [0, 1, 5],
    [0, 5, 4],
    [2, 6, 7],
    [2, 7, 3],
    [0, 4, 6],
    [0, 6, 2],
    [1, 3, 7],
    [1, 7, 5],
];

/// Where a mesh file's shading normals come from (`vertex_normals`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VertexNormals {
    /// The file's own normals; flat shading where it has none (the default).
    #[default]
    File,
    /// The file's normals, or where it has none the angle-weighted average of the faces around
    /// each vertex (Thuermer and Wuethrich 1998; what Mitsuba computes for such files).
    Computed,
    /// Flat shading: the file's normals are not used (Mitsuba's `face_normals`).
    None,
}

impl VertexNormals {
    fn is_file(&self) -> bool {
        *self == VertexNormals::File
    }
}

/// Angle-weighted vertex normals of a triangle mesh: each face's unit normal weighted by its
/// angle at the vertex; zero for a vertex of degenerate faces only (shading then falls back to
/// the face's own normal).
fn angle_weighted_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut normals = vec![DVec3::ZERO; positions.len()];
    for t in triangles {
        let p = t.map(|i| positions[i as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        for k in 0..3 {
            let a = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
            let b = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
            let angle = a.dot(b).clamp(-1.0, 1.0).acos();
            normals[t[k] as usize] += n * angle;
        }
    }
    normals.into_iter().map(DVec3::normalize_or_zero).collect()
}

/// Scene-file form of [`Mesh`].
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshRepr {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    obj: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    ply: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    serialized: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    shape_index: Option<usize>,
    #[serde(default, skip_serializing_if = "VertexNormals::is_file")]
    vertex_normals: VertexNormals,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    positions: Option<Vec<DVec3>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    triangles: Option<Vec<[u32; 3]>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    normals: Option<Vec<DVec3>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    uvs: Option<Vec<DVec2>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    transform: Option<Transform>,
}

impl TryFrom<MeshRepr> for Mesh {
    type Error = GeometryError;
    fn try_from(r: MeshRepr) -> Result<Self, GeometryError> {
        const S: &str = "Mesh";
        let files = [("ply", &r.ply), ("serialized", &r.serialized)];
        if let Some((key, Some(path))) = files.iter().find(|(_, p)| p.is_some()) {
            let sources =
                [r.obj.is_some(), r.ply.is_some(), r.serialized.is_some(), r.positions.is_some()];
            if sources.iter().filter(|&&s| s).count() > 1 || r.triangles.is_some() {
                return Err(GeometryError::parameter(
                    S,
                    key,
                    path,
                    "give one of obj, ply, serialized, or positions and triangles",
                ));
            }
            if r.normals.is_some() || r.uvs.is_some() {
                return Err(GeometryError::parameter(
                    S,
                    "normals",
                    path,
                    "normals/uvs are inline only; a mesh file brings its own",
                ));
            }
            if r.shape_index.is_some() && r.serialized.is_none() {
                return Err(GeometryError::parameter(
                    S,
                    "shape_index",
                    path,
                    "only with serialized",
                ));
            }
            return Ok(Self { data: None, repr: Box::new(r) });
        }
        if r.shape_index.is_some() {
            return Err(GeometryError::parameter(
                S,
                "shape_index",
                "given",
                "only with serialized",
            ));
        }
        match (&r.obj, &r.positions, &r.triangles) {
            (Some(path), None, None) => {
                if r.normals.is_some() || r.uvs.is_some() {
                    return Err(GeometryError::parameter(
                        S,
                        "normals",
                        path,
                        "normals/uvs are inline only; an OBJ file brings its own",
                    ));
                }
                Ok(Self { data: None, repr: Box::new(r) })
            }
            (None, Some(p), Some(t)) => {
                let data = build(
                    p.clone(),
                    t.clone(),
                    r.normals.clone(),
                    r.uvs.clone(),
                    r.transform.as_ref(),
                )?;
                Ok(Self { data: Some(Arc::new(data)), repr: Box::new(r) })
            }
            (None, Some(_), None) => {
                Err(GeometryError::parameter(S, "triangles", "missing", "required with positions"))
            }
            (None, None, _) => Err(GeometryError::parameter(
                S,
                "positions",
                "missing",
                "give either obj or positions and triangles",
            )),
            (Some(path), _, _) => Err(GeometryError::parameter(
                S,
                "obj",
                path,
                "give either obj or positions/triangles, not both",
            )),
        }
    }
}

impl From<Mesh> for MeshRepr {
    fn from(m: Mesh) -> Self {
        *m.repr
    }
}

/// Validates and transforms mesh data.
fn build(
    positions: Vec<DVec3>,
    mut triangles: Vec<[u32; 3]>,
    normals: Option<Vec<DVec3>>,
    uvs: Option<Vec<DVec2>>,
    transform: Option<&Transform>,
) -> Result<MeshData, GeometryError> {
    const S: &str = "Mesh";
    if triangles.is_empty() {
        return Err(GeometryError::parameter(S, "triangles", "[]", "must not be empty"));
    }
    if positions.len() > MAX_MESH_VERTICES {
        return Err(GeometryError::parameter(
            S,
            "positions",
            positions.len(),
            "too many vertices: the limit is MAX_MESH_VERTICES = 2^25",
        ));
    }
    if triangles.len() > MAX_MESH_TRIANGLES {
        return Err(GeometryError::parameter(
            S,
            "triangles",
            triangles.len(),
            "too many triangles: the limit is MAX_MESH_TRIANGLES = 2^25",
        ));
    }
    if let Some((i, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
        return Err(GeometryError::parameter(S, "positions", (i, p), "must be finite"));
    }
    let count = positions.len();
    for (triangle, tri) in triangles.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= count) {
            return Err(GeometryError::IndexOutOfRange { triangle, index, count });
        }
    }
    if let Some(n) = &normals {
        if n.len() != count {
            return Err(GeometryError::parameter(S, "normals", n.len(), "one per position"));
        }
        if let Some((i, v)) = n.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(GeometryError::parameter(S, "normals", (i, v), "must be finite"));
        }
    }
    if let Some(uv) = &uvs
        && uv.len() != count
    {
        return Err(GeometryError::parameter(S, "uvs", uv.len(), "one per position"));
    }
    let t = transform.copied().unwrap_or_default();
    let positions: Vec<DVec3> = positions.into_iter().map(|p| t.point(p)).collect();
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(GeometryError::parameter(S, "transform", t.to_rows(), "overflows positions"));
    }
    let normals = normals.map(|n| n.into_iter().map(|v| t.normal(v).normalize_or_zero()).collect());
    if t.flips_orientation() {
        for tri in &mut triangles {
            tri.swap(1, 2);
        }
    }
    let cumulative_area = triangles
        .iter()
        .scan(0.0, |sum, tri| {
            *sum += triangle_area(tri.map(|i| positions[i as usize]));
            Some(*sum)
        })
        .collect();
    Ok(MeshData { positions, triangles, normals, uvs, cumulative_area })
}

/// Area of a triangle (m^2): `|(p1 - p0) x (p2 - p0)| / 2`, the length taken without overflow in
/// its squares; `+inf` if it does not fit in an f64, 0 for a degenerate triangle.
fn triangle_area(p: [DVec3; 3]) -> f64 {
    let area = 0.5 * safe_length((p[1] - p[0]).cross(p[2] - p[0]));
    if area.is_nan() { f64::INFINITY } else { area }
}

/// The unit geometric normal of a triangle as [`Mesh`]'s hits report it,
/// `normalize((p1 - p0) x (p2 - p0))`; computed from the edges scaled to unit size when the cross
/// product over- or underflows, and `+z` for a degenerate triangle (which no ray hits).
fn triangle_normal(p: [DVec3; 3]) -> DVec3 {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let len = n.length();
    if len > 0.0 && len.is_finite() {
        return n / len;
    }
    let scaled = |e: DVec3| {
        let m = e.abs().max_element();
        if m > 0.0 && m.is_finite() { e / m } else { e }
    };
    let n = scaled(p[1] - p[0]).cross(scaled(p[2] - p[0])).normalize_or_zero();
    if n == DVec3::ZERO || !n.is_finite() { DVec3::Z } else { n }
}

/// The largest OBJ file [`Mesh::load`] reads: 1 GiB. A longer file, or a device that never ends,
/// is refused with an error instead of exhausting memory.
pub const MAX_OBJ_BYTES: u64 = 1 << 30;

/// The most vertices (positions) a mesh may have, inline or from an OBJ file: 2^25 (33,554,432),
/// which bounds a mesh's memory to about 2 GiB.
pub const MAX_MESH_VERTICES: usize = 1 << 25;

/// The most triangles a mesh may have, inline or from an OBJ file: 2^25 (33,554,432).
pub const MAX_MESH_TRIANGLES: usize = 1 << 25;

/// Reads an OBJ file into mesh data (all models merged), at most [`MAX_OBJ_BYTES`] long.
fn read_obj(path: &Path, transform: Option<&Transform>) -> Result<MeshData, GeometryError> {
    read_obj_limited(path, transform, MAX_OBJ_BYTES)
}

/// [`read_obj`] with the byte limit as a parameter (tests use a small one). Material libraries
/// (`mtllib`) are never opened: Spectrace takes materials from the scene file.
fn read_obj_limited(
    path: &Path,
    transform: Option<&Transform>,
    limit: u64,
) -> Result<MeshData, GeometryError> {
    let err = |reason: String| GeometryError::Obj { path: path.to_path_buf(), reason };
    let bytes = crate::read_bounded(path, limit, "OBJ file").map_err(err)?;
    let (models, _materials) =
        tobj::load_obj_buf(&mut bytes.as_slice(), &tobj::GPU_LOAD_OPTIONS, |_mtl_path| {
            Ok((Vec::new(), Default::default()))
        })
        .map_err(|e| err(e.to_string()))?;
    drop(bytes);
    let vertex_count: usize = models.iter().map(|m| m.mesh.positions.len() / 3).sum();
    if vertex_count > MAX_MESH_VERTICES {
        return Err(err(format!(
            "{vertex_count} vertices, more than the limit of {MAX_MESH_VERTICES}"
        )));
    }
    let triangle_count: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    if triangle_count > MAX_MESH_TRIANGLES {
        return Err(err(format!(
            "{triangle_count} triangles, more than the limit of {MAX_MESH_TRIANGLES}"
        )));
    }
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut normals = Some(Vec::new());
    let mut uvs = Some(Vec::new());
    for model in &models {
        let m = &model.mesh;
        let base = u32::try_from(positions.len()).map_err(|_| err("too many vertices".into()))?;
        let n = m.positions.len() / 3;
        positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|c| DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2]))),
        );
        normals = normals.filter(|_| m.normals.len() == 3 * n).map(|mut v| {
            v.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|c| DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2]))),
            );
            v
        });
        uvs = uvs.filter(|_| m.texcoords.len() == 2 * n).map(|mut v| {
            v.extend(
                // OBJ's `v` points up the image; textures read `v` down from the top row.
                m.texcoords
                    .chunks_exact(2)
                    .map(|c| DVec2::new(f64::from(c[0]), 1.0 - f64::from(c[1]))),
            );
            v
        });
        triangles
            .extend(m.indices.chunks_exact(3).map(|c| [c[0] + base, c[1] + base, c[2] + base]));
    }
    if triangles.is_empty() {
        return Err(err("no triangles".into()));
    }
    build(positions, triangles, normals, uvs, transform)
}

/// Reads a PLY file into mesh data, at most [`MAX_OBJ_BYTES`] long (the OBJ limit).
fn read_ply_file(path: &Path, transform: Option<&Transform>) -> Result<MeshData, GeometryError> {
    let err = |reason: String| GeometryError::Ply { path: path.to_path_buf(), reason };
    let bytes = crate::read_bounded(path, MAX_OBJ_BYTES, "PLY file").map_err(err)?;
    let m = crate::ply::read_ply(&bytes).map_err(err)?;
    drop(bytes);
    build(m.positions, m.triangles, m.normals, m.uvs, transform)
}

/// Reads mesh `index` of a Mitsuba serialized file, at most [`MAX_OBJ_BYTES`] long.
fn read_serialized_file(
    path: &Path,
    index: usize,
    transform: Option<&Transform>,
) -> Result<MeshData, GeometryError> {
    let err = |reason: String| GeometryError::Serialized { path: path.to_path_buf(), reason };
    let bytes = crate::read_bounded(path, MAX_OBJ_BYTES, "serialized mesh file").map_err(err)?;
    let m = crate::serialized::read_serialized(&bytes, index).map_err(err)?;
    drop(bytes);
    build(m.positions, m.triangles, m.normals, m.uvs, transform)
}

impl Mesh {
    /// A mesh from world-space positions and counter-clockwise triangles.
    ///
    /// # Errors
    /// [`GeometryError::IndexOutOfRange`] naming the triangle and index, or
    /// [`GeometryError::Parameter`] naming `positions` or `triangles`.
    pub fn from_triangles(
        positions: Vec<DVec3>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Self, GeometryError> {
        MeshRepr { positions: Some(positions), triangles: Some(triangles), ..Default::default() }
            .try_into()
    }

    /// A mesh to be read from the OBJ file `path` (relative paths resolve against the base
    /// directory given to [`Mesh::load`]); not loaded yet.
    pub fn from_obj(path: impl Into<PathBuf>, transform: Option<Transform>) -> Self {
        Self {
            data: None,
            repr: Box::new(MeshRepr { obj: Some(path.into()), transform, ..Default::default() }),
        }
    }

    /// This mesh with `transform` applied after its own (an OBJ mesh must be reloaded).
    ///
    /// # Errors
    /// As [`Mesh::from_triangles`].
    pub fn transformed(&self, transform: &Transform) -> Result<Self, GeometryError> {
        let t = self.repr.transform.map_or(*transform, |own| own.then(transform));
        MeshRepr { transform: Some(t), ..(*self.repr).clone() }.try_into()
    }

    /// Reads the OBJ file (if this mesh names one and is not yet loaded), resolving a relative
    /// path against `base_dir`.
    ///
    /// # Errors
    /// [`GeometryError::Obj`] if the file cannot be read or has no triangles, or the validation
    /// errors of [`Mesh::from_triangles`].
    pub fn load(&mut self, base_dir: &Path) -> Result<(), GeometryError> {
        if self.data.is_some() {
            return Ok(());
        }
        let transform = self.repr.transform.as_ref();
        let mut data = if let Some(obj) = &self.repr.obj {
            read_obj(&base_dir.join(obj), transform)?
        } else if let Some(ply) = &self.repr.ply {
            read_ply_file(&base_dir.join(ply), transform)?
        } else if let Some(file) = &self.repr.serialized {
            let index = self.repr.shape_index.unwrap_or(0);
            read_serialized_file(&base_dir.join(file), index, transform)?
        } else {
            return Ok(());
        };
        match self.repr.vertex_normals {
            VertexNormals::File => {}
            VertexNormals::Computed => {
                if data.normals.is_none() {
                    data.normals = Some(angle_weighted_normals(&data.positions, &data.triangles));
                }
            }
            VertexNormals::None => data.normals = None,
        }
        self.data = Some(Arc::new(data));
        Ok(())
    }

    /// Whether the triangles are available (inline, or an OBJ already loaded).
    pub fn is_loaded(&self) -> bool {
        self.data.is_some()
    }

    /// The OBJ path, if the mesh comes from an OBJ file.
    pub fn obj_path(&self) -> Option<&Path> {
        self.repr.obj.as_deref()
    }

    /// The mesh file's path (OBJ, PLY or serialized), if the mesh comes from a file.
    pub fn file_path(&self) -> Option<&Path> {
        self.repr.obj.as_deref().or(self.repr.ply.as_deref()).or(self.repr.serialized.as_deref())
    }

    /// A mesh to be read from the PLY file `path` (resolved as [`Mesh::from_obj`]); not loaded.
    pub fn from_ply(path: impl Into<PathBuf>, transform: Option<Transform>) -> Self {
        Self {
            data: None,
            repr: Box::new(MeshRepr { ply: Some(path.into()), transform, ..Default::default() }),
        }
    }

    /// World-space vertex positions (empty until loaded).
    pub fn positions(&self) -> &[DVec3] {
        self.data.as_ref().map_or(&[], |d| &d.positions)
    }

    /// Vertex indices of each triangle (empty until loaded).
    pub fn triangles(&self) -> &[[u32; 3]] {
        self.data.as_ref().map_or(&[], |d| &d.triangles)
    }

    /// Total area of the triangles (m^2): 0 until loaded or if every triangle is degenerate,
    /// `+inf` if it exceeds `f64::MAX`.
    pub(crate) fn area(&self) -> f64 {
        self.data.as_ref().and_then(|d| d.cumulative_area.last().copied()).unwrap_or(0.0)
    }

    /// A point uniform by area, from uniforms already in `[0, 1)`: the triangle by area (`u0`,
    /// binary search of the cumulative areas; zero-area triangles are never chosen), then the
    /// square-root warp on it (`u1`, `u2`); normal the triangle's geometric one. A mesh of zero
    /// or infinite total area picks its triangle uniformly instead; an unloaded one gives the
    /// origin.
    pub(crate) fn sample_area(&self, u: [f64; 3]) -> SurfacePoint {
        let Some(d) = self.data.as_ref() else {
            return SurfacePoint { point: DVec3::ZERO, normal: DVec3::Z };
        };
        let cumulative = &d.cumulative_area;
        let count = cumulative.len();
        let total = cumulative.last().copied().unwrap_or(0.0);
        let index = if total > 0.0 && total.is_finite() {
            let x = u[0] * total;
            let i = cumulative.partition_point(|&c| c <= x);
            // `u0 * total` may round up to `total`: take the last triangle of non-zero area.
            if i < count { i } else { cumulative.partition_point(|&c| c < total) }
        } else {
            (u[0] * count as f64) as usize
        };
        let index = index.min(count.saturating_sub(1));
        let Some(tri) = d.triangles.get(index) else {
            return SurfacePoint { point: DVec3::ZERO, normal: DVec3::Z };
        };
        let p = tri.map(|i| d.positions[i as usize]);
        let su = u[1].sqrt();
        let (b1, b2) = (su * (1.0 - u[2]), su * u[2]);
        let point = p[0] * (1.0 - su) + p[1] * b1 + p[2] * b2;
        SurfacePoint { point, normal: triangle_normal(p) }
    }

    /// The three vertices of triangle `index`.
    fn vertices(d: &MeshData, index: u32) -> ([u32; 3], [DVec3; 3]) {
        let tri = d.triangles[index as usize];
        (tri, tri.map(|i| d.positions[i as usize]))
    }
}

/// The watertight ray/triangle test: `(t, [b0, b1, b2])` with `0 < t < t_max`.
pub(crate) fn intersect_triangle(p: [DVec3; 3], ray: &Ray, t_max: f64) -> Option<(f64, [f64; 3])> {
    TriangleRay::new(ray).intersect(&p.map(|v| v.to_array()), t_max)
}

/// Four triangles as SIMD lanes, `[vertex][axis]`, for [`TriangleRay::candidates4`].
pub(crate) type Triangles4 = [[f64x4; 3]; 3];

/// The per-ray part of the watertight triangle test (Woop, Benthin and Wald 2013): the axis
/// permutation that makes the ray's largest direction component `z`, and the shear that maps the
/// ray onto `+z`. Computed once per ray; [`TriangleRay::intersect`] then does only the
/// per-triangle work, with exactly the arithmetic of the single-triangle test.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TriangleRay {
    /// The origin, permuted (`[o[kx], o[ky], o[kz]]`).
    origin: [f64; 3],
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f64,
    sy: f64,
    sz: f64,
}

impl TriangleRay {
    /// The permutation and shear of `ray`.
    #[inline]
    pub(crate) fn new(ray: &Ray) -> Self {
        let d = ray.direction;
        let ad = d.abs();
        let kz = if ad.x > ad.y {
            if ad.x > ad.z { 0 } else { 2 }
        } else if ad.y > ad.z {
            1
        } else {
            2
        };
        let kx = (kz + 1) % 3;
        let ky = (kx + 1) % 3;
        let d = d.to_array();
        let o = ray.origin.to_array();
        let (dx, dy, dz) = (d[kx], d[ky], d[kz]);
        Self { origin: [o[kx], o[ky], o[kz]], kx, ky, kz, sx: -dx / dz, sy: -dy / dz, sz: 1.0 / dz }
    }

    /// The lanes (bit `i` for lane `i`) of four triangles `p` (`p[vertex][axis]`, world space)
    /// that [`TriangleRay::intersect`] may accept: its first half (the edge signs and the
    /// determinant) in SIMD, with exactly its arithmetic in every lane, so a lane rejected here
    /// is rejected there. A lane of zeros is rejected. The range of `t` is left to the scalar
    /// test: a ray rarely crosses two triangles of one leaf, and checking it here cost more
    /// than the scalar tests it saved (measured with the `ray_rate` example).
    #[inline]
    pub(crate) fn candidates4(&self, p: &Triangles4) -> u32 {
        let (o, kx, ky, kz) = (&self.origin, self.kx.min(2), self.ky.min(2), self.kz.min(2));
        let (sx, sy) = (f64x4::splat(self.sx), f64x4::splat(self.sy));
        let (ox, oy, oz) = (f64x4::splat(o[0]), f64x4::splat(o[1]), f64x4::splat(o[2]));
        let sheared = |v: &[f64x4; 3]| {
            let z = v[kz] - oz;
            (v[kx] - ox + sx * z, v[ky] - oy + sy * z)
        };
        let (x0, y0) = sheared(&p[0]);
        let (x1, y1) = sheared(&p[1]);
        let (x2, y2) = sheared(&p[2]);
        let e0 = x1 * y2 - y1 * x2;
        let e1 = x2 * y0 - y2 * x0;
        let e2 = x0 * y1 - y0 * x1;
        let zero = f64x4::ZERO;
        // Some edge negative and some positive: the least below 0 and the greatest above. A
        // SIMD min or max returns one of its operands (NaN at worst, which compares false), so
        // a lane rejected here has a negative and a positive edge for the scalar test too.
        let negative = e0.fast_min(e1).fast_min(e2).cmp_lt(zero);
        let positive = e0.fast_max(e1).fast_max(e2).cmp_gt(zero);
        let det = e0 + e1 + e2;
        let rejected = (negative & positive) | det.cmp_eq(zero) | !det.is_finite();
        !(rejected.move_mask() as u32) & 0b1111
    }

    /// The watertight test against the triangle `p` (world-space vertices): `(t, [b0, b1, b2])`
    /// with `0 < t < t_max`, `t` above pbrt's conservative bound on its rounding error.
    #[inline]
    pub(crate) fn intersect(&self, p: &[[f64; 3]; 3], t_max: f64) -> Option<(f64, [f64; 3])> {
        let (o, kx, ky, kz) = (&self.origin, self.kx.min(2), self.ky.min(2), self.kz.min(2));
        let mut q = [[0.0; 3]; 3];
        for (q, v) in q.iter_mut().zip(p) {
            *q = [v[kx] - o[0], v[ky] - o[1], v[kz] - o[2]];
            q[0] += self.sx * q[2];
            q[1] += self.sy * q[2];
        }
        let e0 = q[1][0] * q[2][1] - q[1][1] * q[2][0];
        let e1 = q[2][0] * q[0][1] - q[2][1] * q[0][0];
        let e2 = q[0][0] * q[1][1] - q[0][1] * q[1][0];
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        for v in &mut q {
            v[2] *= self.sz;
        }
        let t_scaled = e0 * q[0][2] + e1 * q[1][2] + e2 * q[2][2];
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
            return None;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
            return None;
        }
        let inv_det = 1.0 / det;
        let b = [e0 * inv_det, e1 * inv_det, e2 * inv_det];
        let t = t_scaled * inv_det;
        // Conservative t > 0 (pbrt-v3, section 3.9.6).
        let max_z = q.iter().map(|v| v[2].abs()).fold(0.0, f64::max);
        let max_x = q.iter().map(|v| v[0].abs()).fold(0.0, f64::max);
        let max_y = q.iter().map(|v| v[1].abs()).fold(0.0, f64::max);
        let delta_z = gamma(3) * max_z;
        let delta_x = gamma(5) * (max_x + max_z);
        let delta_y = gamma(5) * (max_y + max_z);
        let delta_e = 2.0 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t =
            3.0 * (gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv_det.abs();
        if !(t > delta_t && t < t_max) {
            return None;
        }
        Some((t, b))
    }
}

impl Mesh {
    /// The world-space vertices of triangle `index` and whether a hit on it is reported at all
    /// (its normal `(p1 - p0) x (p2 - p0)` must have a length `> 0`, as [`Primitives::intersect`]
    /// requires); `None` for an unloaded mesh or an index out of range.
    pub(crate) fn triangle(&self, index: u32) -> Option<([[f64; 3]; 3], bool)> {
        let d = self.data.as_ref()?;
        let tri = d.triangles.get(index as usize)?;
        let p = tri.map(|i| d.positions[i as usize]);
        let valid = (p[1] - p[0]).cross(p[2] - p[0]).length() > 0.0;
        Some((p.map(|v| v.to_array()), valid))
    }
}

impl Primitives for Mesh {
    fn count(&self) -> usize {
        self.triangles().len()
    }

    fn bounds(&self, index: u32) -> Bounds {
        match &self.data {
            Some(d) => Bounds::from_points(Self::vertices(d, index).1),
            None => Bounds::EMPTY,
        }
    }

    fn intersect(&self, index: u32, ray: &Ray, t_max: f64) -> Option<Hit> {
        let d = self.data.as_ref()?;
        let p = Self::vertices(d, index).1;
        let (t, b) = intersect_triangle(p, ray, t_max)?;
        self.hit_at(index, p, t, b)
    }
}

impl Mesh {
    /// The full hit on triangle `index` (vertices `p`) at distance `t` and barycentrics `b`, as
    /// the watertight test found them (so [`Primitives::intersect`] and a BVH that ran the test
    /// on its own copy of the vertices build the same hit); `None` for a triangle with a
    /// zero-length normal. The vertex indices are read only for normals and texture coordinates.
    pub(crate) fn hit_at(&self, index: u32, p: [DVec3; 3], t: f64, b: [f64; 3]) -> Option<Hit> {
        let d = self.data.as_ref()?;
        let tri = || d.triangles[index as usize];
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let len = n.length();
        if !(len > 0.0) {
            return None;
        }
        let n = n / len;
        let terms = [p[0] * b[0], p[1] * b[1], p[2] * b[2]];
        let point = terms[0] + terms[1] + terms[2];
        let error = (terms[0].abs() + terms[1].abs() + terms[2].abs()) * gamma(7);
        let shading_normal = d
            .normals
            .as_ref()
            .map(|ns| {
                let tri = tri();
                let s = (ns[tri[0] as usize] * b[0]
                    + ns[tri[1] as usize] * b[1]
                    + ns[tri[2] as usize] * b[2])
                    .normalize_or_zero();
                if s == DVec3::ZERO {
                    n
                } else if s.dot(n) < 0.0 {
                    -s
                } else {
                    s
                }
            })
            .unwrap_or(n);
        let uv = d.uvs.as_ref().map_or(DVec2::new(b[1], b[2]), |uvs| {
            let tri = tri();
            uvs[tri[0] as usize] * b[0] + uvs[tri[1] as usize] * b[1] + uvs[tri[2] as usize] * b[2]
        });
        Some(Hit {
            t,
            point,
            geometric_normal: n,
            shading_normal,
            uv,
            primitive: 0,
            triangle: index,
            error,
        })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn an_obj_one_byte_over_the_limit_is_refused() {
        let dir = std::env::temp_dir().join(format!("spectrace-obj-limit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("tri.obj");
        let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        std::fs::write(&path, obj).unwrap();
        let len = obj.len() as u64;
        let data = read_obj_limited(&path, None, len).unwrap();
        assert_eq!(data.triangles.len(), 1);
        let e = read_obj_limited(&path, None, len - 1).unwrap_err().to_string();
        assert!(e.contains(&format!("larger than the {} bytes limit", len - 1)), "{e}");
        assert!(e.contains("Mesh.obj"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// At a cube's corner the three faces meet at right angles: the angle-weighted normal is
    /// the diagonal, whatever the triangulation (two triangles of one face share the angle).
    #[test]
    fn angle_weighted_normals_of_a_cube_corner_are_its_diagonal() {
        let p: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        let t = CUBE_TRIANGLES.to_vec();
        let n = super::angle_weighted_normals(&p, &t);
        let d = 1.0 / 3f64.sqrt();
        assert!((n[0] - DVec3::splat(-d)).length() < 1e-12, "{}", n[0]);
        assert!((n[7] - DVec3::splat(d)).length() < 1e-12, "{}", n[7]);
    }
}
