//! The reference cache: one file of XYZ pixels per scene and reference settings.

use super::*;

pub(super) const CACHE_MAGIC: &[u8; 8] = b"SPXYZREF";
pub(super) const CACHE_VERSION: u32 = 3;
pub(super) const CACHE_HEADER: usize = 8 + 4 + 4 + 4 + 8 + 8;

/// Largest `.error` file read: three numbers as text.
const ERRORS_BYTES: u64 = 256;

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

/// A cached reference: its image, render time and paths.
pub(super) struct Cached {
    /// The image.
    pub image: Vec<Xyz>,
    /// Its render time (s).
    pub seconds: f64,
    /// Its paths.
    pub paths: u64,
}

/// The cached image with its render time and paths, if the file exists and matches the size
/// (any other length, checked before reading, is not read).
pub(super) fn read_reference(path: &Path, width: u32, height: u32) -> Option<Cached> {
    let pixels = width as usize * height as usize;
    let expected = CACHE_HEADER + pixels * 24;
    if std::fs::metadata(path).ok()?.len() != expected as u64 {
        return None;
    }
    let bytes = std::fs::read(path).ok()?;
    if bytes.len() != expected || &bytes[..8] != CACHE_MAGIC {
        return None;
    }
    let u32_at = |i: usize| bytes.get(i..i + 4)?.try_into().ok().map(u32::from_le_bytes);
    let f64_at = |i: usize| bytes.get(i..i + 8)?.try_into().ok().map(f64::from_le_bytes);
    if u32_at(8)? != CACHE_VERSION || u32_at(12)? != width || u32_at(16)? != height {
        return None;
    }
    let paths = u64::from_le_bytes(bytes.get(20..28)?.try_into().ok()?);
    let seconds = f64_at(28)?;
    let image = (0..pixels)
        .map(|i| {
            let at = CACHE_HEADER + i * 24;
            Some(Xyz::new(f64_at(at)?, f64_at(at + 8)?, f64_at(at + 16)?))
        })
        .collect::<Option<Vec<_>>>()?;
    Some(Cached { image, seconds, paths })
}

/// The estimate check's reference of at least `paths` paths ([`check::CHECK_REFERENCE_FACTOR`]
/// times the check render's): rendered by `integrator` with independent sampling at the next
/// power of two of paths (so reruns find it in the cache), with its own error estimate in every
/// measure kept beside it (`FILE.error`: three numbers, `-` for none). `independent` is the
/// scene with `settings.sampler` independent, so that the reference's own estimate holds.
///
/// # Errors
/// A message when the render or the cache fails.
pub(super) fn deep_reference(
    independent: &Scene,
    scene_text: &str,
    name: &str,
    integrator: IntegratorChoice,
    paths: u64,
    options: &AccuracyOptions,
    threads: usize,
) -> Result<check::CheckReference, String> {
    let paths = paths.max(1).checked_next_power_of_two().unwrap_or(paths);
    let (width, height) = (independent.camera.width(), independent.camera.height());
    let seed = options.seed ^ 0xDEE9;
    let key = cache_key(scene_text, integrator, paths, seed, width, height);
    let file = options.cache_dir.join(format!("{name}-check-{key:016x}.xyz"));
    let error_file = file.with_extension("xyz.error");
    let cached = read_reference(&file, width, height).zip(read_errors(&error_file));
    if let Some((cached, own_error)) = cached {
        eprintln!("accuracy: {name}: check reference {} paths from the cache", cached.paths);
        return Ok(check::CheckReference { image: cached.image, own_error, paths: cached.paths });
    }
    eprintln!(
        "accuracy: {name}: rendering the check reference, {paths} paths by {}...",
        integrator.name()
    );
    let render = spectrace_renderer::render_in_memory(
        independent,
        &spectrace_renderer::RenderOptions {
            beams: Some(paths),
            seed: Some(seed),
            threads: Some(threads),
            integrator: Some(integrator),
            error_measure: Some(ErrorMeasure::RelMse),
            ..spectrace_renderer::RenderOptions::default()
        },
    )
    .map_err(|e| format!("accuracy: {name}: check reference: {e}"))?;
    let own_error =
        render.output.estimate(ErrorMeasure::RelMse).map(|e| e.by_measure).unwrap_or_default();
    let paths = render.output.beams;
    write_reference(&file, width, height, paths, render.output.seconds, &render.image)?;
    let text = ErrorMeasure::ALL
        .map(|m| own_error.get(m).map_or("-".to_owned(), |e| e.to_string()))
        .join(" ");
    std::fs::write(&error_file, text).map_err(|e| format!("{}: {e}", error_file.display()))?;
    eprintln!("accuracy: {name}: check reference took {:.1} s", render.output.seconds);
    Ok(check::CheckReference { image: render.image, own_error, paths })
}

/// The three numbers of a `.error` file (relmse, energy, mean; `-` for none); `None` for a
/// missing, malformed or oversized file (at most [`ERRORS_BYTES`], checked before reading).
fn read_errors(path: &Path) -> Option<ByMeasure> {
    if std::fs::metadata(path).ok()?.len() > ERRORS_BYTES {
        return None;
    }
    let text = std::fs::read_to_string(path).ok()?;
    let v: Vec<Option<f64>> = text.split_whitespace().map(|w| w.parse().ok()).collect();
    let [relmse, energy, mean] = v.as_slice().try_into().ok()?;
    Some(ByMeasure { relmse, energy, mean })
}
