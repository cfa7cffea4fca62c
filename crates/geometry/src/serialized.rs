//! Mitsuba's `serialized` meshes: a file of one or more zlib-compressed triangle meshes, read
//! (with `miniz_oxide`) into the same records as PLY files.
//!
//! The format (Mitsuba 0.6 and 3, little-endian): a header `u16` 0x041C and `u16` version (3 or
//! 4), then a zlib stream holding `u32` flags (0x0001 vertex normals, 0x0002 texture coordinates,
//! 0x0008 vertex colours, 0x0010 face normals, 0x1000 single precision, 0x2000 double
//! precision), in version 4 the shape's name (UTF-8, NUL-terminated), `u64` vertex and `u64`
//! triangle counts, the positions, normals, texture coordinates and colours as flagged, and the
//! indices (`u32`, or `u64` beyond 2^32 vertices). A file of several meshes ends with the byte
//! offset of each (`u64` in version 4, `u32` in 3) and their count (`u32`); `shape_index`
//! chooses one. Colours are skipped; face normals mean the file's normals are not used. Every
//! count is checked against the bytes present and the mesh limits before anything is allocated,
//! and decompression stops at the mesh size the counts allow.

use glam::{DVec2, DVec3};

use crate::mesh::{MAX_MESH_TRIANGLES, MAX_MESH_VERTICES};
use crate::ply::PlyMesh;

const MAGIC: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const SINGLE: u32 = 0x1000;
const DOUBLE: u32 = 0x2000;

/// A little-endian cursor over bytes that refuses to read past the end.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len()).ok_or_else(|| {
            format!(
                "the data ends early (at byte {} of {}, {n} more needed)",
                self.at,
                self.bytes.len()
            )
        })?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u16(&mut self) -> Result<u16, String> {
        Ok(u16::from_le_bytes(self.take(2)?.try_into().map_err(|_| "short")?))
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().map_err(|_| "short")?))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().map_err(|_| "short")?))
    }
    fn real(&mut self, double: bool) -> Result<f64, String> {
        Ok(if double {
            f64::from_le_bytes(self.take(8)?.try_into().map_err(|_| "short")?)
        } else {
            f64::from(f32::from_le_bytes(self.take(4)?.try_into().map_err(|_| "short")?))
        })
    }
}

/// The byte offset of mesh `index` in a file of version `version` (0 for a single mesh).
fn mesh_offset(bytes: &[u8], version: u16, index: usize) -> Result<usize, String> {
    let n = bytes.len();
    if n < 4 {
        return Err("too short for a mesh".to_owned());
    }
    let count =
        u32::from_le_bytes([bytes[n - 4], bytes[n - 3], bytes[n - 2], bytes[n - 1]]) as usize;
    let width = if version >= 4 { 8 } else { 4 };
    // A dictionary is present only when the count and its offsets fit and the first offset is 0.
    let table = count.checked_mul(width).and_then(|t| t.checked_add(4)).filter(|&t| t <= n);
    let Some(table) = table.filter(|_| count >= 1) else {
        return if index == 0 {
            Ok(0)
        } else {
            Err(format!("shape_index {index}: the file holds one mesh"))
        };
    };
    let start = n - table;
    let at = |i: usize| -> usize {
        let b = &bytes[start + i * width..start + (i + 1) * width];
        if width == 8 {
            u64::from_le_bytes(b.try_into().unwrap_or([0; 8])) as usize
        } else {
            u32::from_le_bytes(b.try_into().unwrap_or([0; 4])) as usize
        }
    };
    if at(0) != 0 {
        return if index == 0 {
            Ok(0)
        } else {
            Err(format!("shape_index {index}: the file holds one mesh"))
        };
    }
    if index >= count {
        return Err(format!("shape_index {index}: the file holds {count} meshes"));
    }
    let offset = at(index);
    if offset >= start {
        return Err(format!("mesh {index}'s offset {offset} lies past the data"));
    }
    Ok(offset)
}

/// Reads mesh `index` of a serialized file's bytes.
///
/// # Errors
/// Why it cannot be read: not a serialized file, an unknown version, a missing mesh, corrupt
/// compressed data, counts beyond the limits or the data, an index out of range.
pub(crate) fn read_serialized(bytes: &[u8], index: usize) -> Result<PlyMesh, String> {
    let mut head = Cursor { bytes, at: 0 };
    let magic = head.u16()?;
    if magic != MAGIC {
        return Err(format!(
            "not a Mitsuba serialized mesh (header {magic:#06x}, expected 0x041c)"
        ));
    }
    let version = head.u16()?;
    if version != 3 && version != 4 {
        return Err(format!("format version {version}: versions 3 and 4 are read"));
    }
    let offset = mesh_offset(bytes, version, index)?;
    let mut head = Cursor { bytes, at: offset };
    if head.u16()? != MAGIC || head.u16()? != version {
        return Err(format!("mesh {index} does not start with the header"));
    }
    let limit = 64 + 24 * MAX_MESH_VERTICES * 2 + 24 * MAX_MESH_TRIANGLES;
    let data = miniz_oxide::inflate::decompress_to_vec_zlib_with_limit(&bytes[head.at..], limit)
        .map_err(|e| {
            format!("the compressed mesh data is corrupt or too large ({:?})", e.status)
        })?;
    parse(&data, version)
}

/// The mesh in the decompressed stream.
fn parse(data: &[u8], version: u16) -> Result<PlyMesh, String> {
    let mut c = Cursor { bytes: data, at: 0 };
    let flags = c.u32()?;
    if version >= 4 {
        let end =
            data[c.at..].iter().position(|&b| b == 0).ok_or("the shape name is not terminated")?;
        c.take(end + 1)?;
    }
    let double = flags & DOUBLE != 0;
    if double == (flags & SINGLE != 0) {
        return Err(format!(
            "flags {flags:#x}: exactly one of single (0x1000) and double (0x2000) precision"
        ));
    }
    let (nv, nt) = (c.u64()?, c.u64()?);
    let (nv, nt) =
        (usize::try_from(nv).unwrap_or(usize::MAX), usize::try_from(nt).unwrap_or(usize::MAX));
    if nv > MAX_MESH_VERTICES || nt > MAX_MESH_TRIANGLES {
        return Err(format!(
            "{nv} vertices and {nt} triangles, beyond the limits ({MAX_MESH_VERTICES}, {MAX_MESH_TRIANGLES})"
        ));
    }
    let real = if double { 8 } else { 4 };
    let per_vertex = 3
        + if flags & HAS_NORMALS != 0 { 3 } else { 0 }
        + if flags & HAS_TEXCOORDS != 0 { 2 } else { 0 }
        + if flags & HAS_COLORS != 0 { 3 } else { 0 };
    let wide = nv > u32::MAX as usize;
    let needed = nv * per_vertex * real + nt * 3 * if wide { 8 } else { 4 };
    if data.len() - c.at < needed {
        return Err(format!(
            "{nv} vertices and {nt} triangles need {needed} bytes; {} are left",
            data.len() - c.at
        ));
    }
    let vec3 = |c: &mut Cursor<'_>| -> Result<DVec3, String> {
        Ok(DVec3::new(c.real(double)?, c.real(double)?, c.real(double)?))
    };
    let positions = (0..nv).map(|_| vec3(&mut c)).collect::<Result<Vec<_>, _>>()?;
    let normals = if flags & HAS_NORMALS != 0 {
        let n = (0..nv).map(|_| vec3(&mut c)).collect::<Result<Vec<_>, _>>()?;
        (flags & FACE_NORMALS == 0).then_some(n)
    } else {
        None
    };
    let uvs = if flags & HAS_TEXCOORDS != 0 {
        Some(
            (0..nv)
                .map(|_| Ok(DVec2::new(c.real(double)?, c.real(double)?)))
                .collect::<Result<Vec<_>, String>>()?,
        )
    } else {
        None
    };
    if flags & HAS_COLORS != 0 {
        c.take(nv * 3 * real)?;
    }
    let mut triangles = Vec::with_capacity(nt);
    for t in 0..nt {
        let mut tri = [0u32; 3];
        for k in &mut tri {
            let i = if wide { c.u64()? } else { u64::from(c.u32()?) };
            *k = u32::try_from(i).ok().filter(|&i| (i as usize) < nv).ok_or_else(|| {
                format!("triangle {t} names vertex {i}, but there are {nv} vertices")
            })?;
        }
        triangles.push(tri);
    }
    if triangles.is_empty() {
        return Err("no triangles".to_owned());
    }
    Ok(PlyMesh { positions, triangles, normals, uvs })
}

/// One mesh to write: single-precision positions and the triangles' vertex indices.
pub type SerializedMesh = (Vec<[f32; 3]>, Vec<[u32; 3]>);

/// The bytes of a Mitsuba serialized file (version 4, single precision, with the offset
/// dictionary) holding `meshes`, each its positions and triangles, as Mitsuba writes them.
pub fn write_serialized(meshes: &[SerializedMesh]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut offsets = Vec::new();
    for (i, (p, t)) in meshes.iter().enumerate() {
        offsets.push(out.len() as u64);
        let mut raw = Vec::new();
        raw.extend(SINGLE.to_le_bytes());
        raw.extend(format!("mesh{i}").as_bytes());
        raw.push(0);
        raw.extend((p.len() as u64).to_le_bytes());
        raw.extend((t.len() as u64).to_le_bytes());
        for v in p.iter().flatten() {
            raw.extend(v.to_le_bytes());
        }
        for k in t.iter().flatten() {
            raw.extend(k.to_le_bytes());
        }
        out.extend(MAGIC.to_le_bytes());
        out.extend(4u16.to_le_bytes());
        out.extend(miniz_oxide::deflate::compress_to_vec_zlib(&raw, 6));
    }
    for o in &offsets {
        out.extend(o.to_le_bytes());
    }
    out.extend((meshes.len() as u32).to_le_bytes());
    out
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn tri(z: f32) -> SerializedMesh {
        (vec![[0.0, 0.0, z], [1.0, 0.0, z], [0.0, 1.0, z]], vec![[0, 1, 2]])
    }

    #[test]
    fn each_mesh_of_a_file_is_read_by_its_index() {
        let bytes = write_serialized(&[tri(1.0), tri(2.0), tri(3.0)]);
        for i in 0..3 {
            let m = read_serialized(&bytes, i).unwrap();
            assert_eq!(m.positions[0].z, (i + 1) as f64);
            assert_eq!(m.triangles, vec![[0, 1, 2]]);
        }
        let e = read_serialized(&bytes, 3).unwrap_err();
        assert!(e.contains("3 meshes"), "{e}");
    }

    /// Corrupt files are refused with the cause: another header, a cut stream, an index out of
    /// range, counts beyond the data.
    #[test]
    fn corrupt_files_are_refused_with_the_cause() {
        let good = write_serialized(&[tri(0.0)]);
        let mut wrong = good.clone();
        wrong[0] = 0;
        assert!(read_serialized(&wrong, 0).unwrap_err().contains("header"));
        let cut = &good[..good.len() / 2];
        assert!(read_serialized(cut, 0).is_err());
        let (mut p, mut t) = tri(0.0);
        t[0][2] = 7;
        let bad_index = write_serialized(&[(p.clone(), t)]);
        assert!(read_serialized(&bad_index, 0).unwrap_err().contains("vertex 7"));
        p.truncate(1);
        let short = write_serialized(&[(p, vec![[0, 0, 0]])]);
        assert!(read_serialized(&short, 0).is_ok());
        assert!(
            read_serialized(&[0x1c, 0x04, 9, 0, 0, 0, 0, 0], 0).unwrap_err().contains("version 9")
        );
    }
}
