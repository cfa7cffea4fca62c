//! The reference cache: one file of XYZ pixels per scene and reference settings.

use super::*;

pub(super) const CACHE_MAGIC: &[u8; 8] = b"SPXYZREF";
pub(super) const CACHE_VERSION: u32 = 3;
pub(super) const CACHE_HEADER: usize = 8 + 4 + 4 + 4 + 8 + 8;

/// FNV-1a over the scene file and the reference's settings (and the crate version, so a changed
/// tracer renders a new reference).
pub(super) fn cache_key(
    scene_text: &str,
    integrator: IntegratorChoice,
    beams: u64,
    seed: u64,
    width: u32,
    height: u32,
) -> u64 {
    let settings = format!(
        "|{}|beams={beams}|seed={seed}|{width}x{height}|v{}|cache{CACHE_VERSION}",
        integrator.name(),
        env!("CARGO_PKG_VERSION")
    );
    scene_text
        .bytes()
        .chain(settings.bytes())
        .fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

/// Layout (little-endian): magic, version u32, width u32, height u32, beams u64, seconds f64,
/// then x, y, z f64 per pixel, row-major.
pub(super) fn write_reference(
    path: &Path,
    width: u32,
    height: u32,
    beams: u64,
    seconds: f64,
    image: &[Xyz],
) -> Result<(), String> {
    let mut bytes = Vec::with_capacity(CACHE_HEADER + image.len() * 24);
    bytes.extend_from_slice(CACHE_MAGIC);
    bytes.extend_from_slice(&CACHE_VERSION.to_le_bytes());
    bytes.extend_from_slice(&width.to_le_bytes());
    bytes.extend_from_slice(&height.to_le_bytes());
    bytes.extend_from_slice(&beams.to_le_bytes());
    bytes.extend_from_slice(&seconds.to_le_bytes());
    for p in image {
        for v in [p.x, p.y, p.z] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// The cached image and its render time, if the file exists and matches the size.
pub(super) fn read_reference(path: &Path, width: u32, height: u32) -> Option<(Vec<Xyz>, f64)> {
    let bytes = std::fs::read(path).ok()?;
    let pixels = width as usize * height as usize;
    if bytes.len() != CACHE_HEADER + pixels * 24 || &bytes[..8] != CACHE_MAGIC {
        return None;
    }
    let u32_at = |i: usize| bytes.get(i..i + 4)?.try_into().ok().map(u32::from_le_bytes);
    let f64_at = |i: usize| bytes.get(i..i + 8)?.try_into().ok().map(f64::from_le_bytes);
    if u32_at(8)? != CACHE_VERSION || u32_at(12)? != width || u32_at(16)? != height {
        return None;
    }
    let seconds = f64_at(28)?;
    let image = (0..pixels)
        .map(|i| {
            let at = CACHE_HEADER + i * 24;
            Some(Xyz::new(f64_at(at)?, f64_at(at + 8)?, f64_at(at + 16)?))
        })
        .collect::<Option<Vec<_>>>()?;
    Some((image, seconds))
}
