//! PLY meshes (Stanford polygon files, ASCII or binary of either byte order), read through the
//! maintained `ply-rs-bw` parser into compact vertex and face records.
//!
//! What is read: the `vertex` element's `x y z` (required), `nx ny nz` (shading normals, kept
//! when every vertex has them) and texture coordinates `u v` (also `s t` or `texture_u
//! texture_v`); the `face` element's `vertex_indices` (or `vertex_index`) lists, polygons
//! fan-triangulated. Other elements and properties (colours, edges, materials) are skipped. Every
//! index is checked against the vertex count, and the counts against the mesh limits, before
//! any triangle is built.

use std::io::BufReader;

use glam::{DVec2, DVec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{Property, PropertyAccess, PropertyAccessResult};

use crate::mesh::{MAX_MESH_TRIANGLES, MAX_MESH_VERTICES};

/// A mesh as read from a PLY file, before validation and transforms.
#[derive(Debug, Default)]
pub(crate) struct PlyMesh {
    pub(crate) positions: Vec<DVec3>,
    pub(crate) triangles: Vec<[u32; 3]>,
    pub(crate) normals: Option<Vec<DVec3>>,
    pub(crate) uvs: Option<Vec<DVec2>>,
}

/// The number in a scalar property, as `f64`; `None` for lists.
fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => f64::from(v),
        Property::UChar(v) => f64::from(v),
        Property::Short(v) => f64::from(v),
        Property::UShort(v) => f64::from(v),
        Property::Int(v) => f64::from(v),
        Property::UInt(v) => f64::from(v),
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    })
}

/// One vertex: position, and the normal and texture coordinates when present (NaN when not).
#[derive(Debug, Clone, Copy)]
struct Vertex {
    p: [f64; 3],
    n: [f64; 3],
    uv: [f64; 2],
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Self { p: [f64::NAN; 3], n: [f64::NAN; 3], uv: [f64::NAN; 2] }
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let Some(v) = scalar(&property) else { return PropertyAccessResult::Ignored };
        let slot = match name {
            "x" => &mut self.p[0],
            "y" => &mut self.p[1],
            "z" => &mut self.p[2],
            "nx" => &mut self.n[0],
            "ny" => &mut self.n[1],
            "nz" => &mut self.n[2],
            "u" | "s" | "texture_u" | "texture_s" => &mut self.uv[0],
            "v" | "t" | "texture_v" | "texture_t" => &mut self.uv[1],
            _ => return PropertyAccessResult::Ignored,
        };
        *slot = v;
        PropertyAccessResult::Set
    }
}

/// One face: its vertex indices (`u64::MAX` marks a negative index, refused later).
#[derive(Debug, Clone, Default)]
struct Face {
    indices: Vec<u64>,
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if name != "vertex_indices" && name != "vertex_index" {
            return PropertyAccessResult::Ignored;
        }
        let signed = |v: i64| u64::try_from(v).unwrap_or(u64::MAX);
        self.indices = match property {
            Property::ListChar(l) => l.into_iter().map(|v| signed(v.into())).collect(),
            Property::ListUChar(l) => l.into_iter().map(u64::from).collect(),
            Property::ListShort(l) => l.into_iter().map(|v| signed(v.into())).collect(),
            Property::ListUShort(l) => l.into_iter().map(u64::from).collect(),
            Property::ListInt(l) => l.into_iter().map(|v| signed(v.into())).collect(),
            Property::ListUInt(l) => l.into_iter().map(u64::from).collect(),
            _ => return PropertyAccessResult::UnsupportedType,
        };
        PropertyAccessResult::Set
    }
}

/// An element neither vertex nor face: read past and dropped.
struct Skipped;

impl PropertyAccess for Skipped {
    fn new() -> Self {
        Skipped
    }
}

/// Reads a PLY file's bytes into a mesh.
///
/// # Errors
/// Why the file cannot be read: the parser's message (with its position), no `vertex` element or
/// no `x y z`, a face index out of range, a face of fewer than 3 vertices, or too many vertices
/// or triangles.
pub(crate) fn read_ply(bytes: &[u8]) -> Result<PlyMesh, String> {
    let mut reader = Reader::new(BufReader::new(bytes));
    let header = Parser::<Skipped>::new().read_header(&mut reader).map_err(|e| e.to_string())?;
    let mut vertices: Option<Vec<Vertex>> = None;
    let mut faces: Vec<Face> = Vec::new();
    for def in header.elements.values() {
        match def.name.as_str() {
            "vertex" => {
                if def.count > MAX_MESH_VERTICES {
                    return Err(format!(
                        "{} vertices, more than the limit of {MAX_MESH_VERTICES}",
                        def.count
                    ));
                }
                let parser = Parser::<Vertex>::new();
                vertices = Some(
                    parser
                        .read_payload_for_element(&mut reader, def, &header)
                        .map_err(|e| e.to_string())?,
                );
            }
            "face" => {
                if def.count > MAX_MESH_TRIANGLES {
                    return Err(format!(
                        "{} faces, more than the limit of {MAX_MESH_TRIANGLES}",
                        def.count
                    ));
                }
                let parser = Parser::<Face>::new();
                faces = parser
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(|e| e.to_string())?;
            }
            _ => {
                Parser::<Skipped>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(|e| e.to_string())?;
            }
        }
    }
    let vertices = vertices.ok_or("no `vertex` element")?;
    assemble(&vertices, &faces)
}

/// The mesh from vertex and face records: fan-triangulated faces with every index checked.
fn assemble(vertices: &[Vertex], faces: &[Face]) -> Result<PlyMesh, String> {
    if vertices.iter().any(|v| v.p.iter().any(|c| c.is_nan())) {
        return Err("a vertex lacks `x`, `y` or `z`".to_owned());
    }
    let positions = vertices.iter().map(|v| DVec3::from_array(v.p)).collect();
    let normals = vertices
        .iter()
        .all(|v| v.n.iter().all(|c| !c.is_nan()))
        .then(|| vertices.iter().map(|v| DVec3::from_array(v.n)).collect());
    let uvs = vertices
        .iter()
        .all(|v| v.uv.iter().all(|c| !c.is_nan()))
        .then(|| vertices.iter().map(|v| DVec2::from_array(v.uv)).collect());
    let mut triangles = Vec::with_capacity(faces.len());
    for (f, face) in faces.iter().enumerate() {
        if face.indices.len() < 3 {
            return Err(format!(
                "face {f} has {} vertices; at least 3 are needed",
                face.indices.len()
            ));
        }
        let index = |i: u64| {
            u32::try_from(i).ok().filter(|&i| (i as usize) < vertices.len()).ok_or_else(|| {
                format!(
                    "face {f} names vertex {}, but there are {} vertices",
                    if i == u64::MAX { "-1 (negative)".to_owned() } else { i.to_string() },
                    vertices.len()
                )
            })
        };
        let first = index(face.indices[0])?;
        for pair in face.indices[1..].windows(2) {
            triangles.push([first, index(pair[0])?, index(pair[1])?]);
        }
        if triangles.len() > MAX_MESH_TRIANGLES {
            return Err(format!("more than {MAX_MESH_TRIANGLES} triangles"));
        }
    }
    if triangles.is_empty() {
        return Err("no faces".to_owned());
    }
    Ok(PlyMesh { positions, triangles, normals, uvs })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    const QUAD: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
        property float z\nproperty float u\nproperty float v\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n";

    #[test]
    fn an_ascii_quad_is_two_triangles_with_uvs() {
        let m = read_ply(QUAD.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.uvs.unwrap()[2], DVec2::new(1.0, 1.0));
        assert!(m.normals.is_none());
    }

    #[test]
    fn a_binary_triangle_reads_in_either_byte_order() {
        for (format, le) in [("binary_little_endian", true), ("binary_big_endian", false)] {
            let mut bytes = format!(
                "ply\nformat {format} 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                 property float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
            )
            .into_bytes();
            for v in [0.0f32, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 3.0, 0.0] {
                bytes.extend(if le { v.to_le_bytes() } else { v.to_be_bytes() });
            }
            bytes.push(3);
            for i in [0u32, 1, 2] {
                bytes.extend(if le { i.to_le_bytes() } else { i.to_be_bytes() });
            }
            let m = read_ply(&bytes).unwrap();
            assert_eq!(m.positions[2], DVec3::new(0.0, 3.0, 0.0), "{format}");
            assert_eq!(m.triangles, vec![[0, 1, 2]]);
        }
    }

    /// Bad files are refused with the cause: an index past the end, a two-vertex face, a
    /// missing coordinate, a truncated binary body, a vertex count past the limit, not a PLY.
    #[test]
    fn bad_files_are_refused_with_the_cause() {
        let cases = [
            (QUAD.replace("4 0 1 2 3", "4 0 1 2 9"), "vertex 9"),
            (QUAD.replace("4 0 1 2 3", "2 0 1"), "at least 3"),
            (
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                 element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0\n1 0\n0 1\n3 0 1 2\n"
                    .to_owned(),
                "lacks",
            ),
            (QUAD.replace("element vertex 4", &format!("element vertex {}", MAX_MESH_VERTICES + 1)), "limit"),
            ("hello".to_owned(), ""),
        ];
        for (text, cause) in cases {
            let e = read_ply(text.as_bytes()).unwrap_err();
            assert!(e.contains(cause), "{e}");
        }
        let truncated = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
            property float y\nproperty float z\nend_header\n\0\0\0\0";
        assert!(read_ply(truncated.as_bytes()).is_err());
    }
}
