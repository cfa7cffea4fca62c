//! Partial films: what `spectrace render --shard K/N` writes and `spectrace merge` reads.
//!
//! A part file is input like a scene file, possibly made or altered by someone else, so reading one
//! is bounded and every field is validated like a scene field: [`PartialFilm::decode`] refuses
//! anything larger than [`MAX_PART_BYTES`](crate::MAX_PART_BYTES), any claimed length beyond
//! that limit, trailing bytes, and any value a render could not have produced (non-finite or
//! non-positive light power, a pixel array that does not match the image size, negative pixel
//! sums, chunks outside the plan, more beams than the chunks hold, an inconsistent effects
//! decision, an output name that is not a plain file name).

use std::path::Path;

use serde::{Deserialize, Serialize};
use spectrace_tracer::{Effects, IntegratorChoice, RenderOutput, RenderPlan, SamplerKind};

use crate::OutputSettings;
use crate::files::{MAX_PART_BYTES, check_output_name, read_bounded};

/// A shard's result, written by `spectrace render --shard K/N` and read by `spectrace merge`.
/// Lossless: the film's exact fixed-point sums.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartialFilm {
    /// Format version ([`PARTIAL_VERSION`]).
    pub version: u32,
    /// Fingerprint of the scene (all parts of one image must share it).
    pub scene_fingerprint: u64,
    /// The scene file, for the final image's metadata.
    pub scene_path: String,
    /// The plan (beams, chunk size, seed) every part must share.
    pub plan: RenderPlan,
    /// Total power of the scene's lights (W), for the image's normalisation.
    pub light_power: f64,
    /// The estimator that rendered the part (never `auto`): it decides the normalisation.
    pub integrator: IntegratorChoice,
    /// The sampler the part was rendered with (`settings.sampler`; parts must agree).
    pub sampler: SamplerKind,
    /// The effects decision the parts were rendered with.
    pub effects: Effects,
    /// Output settings of the scene.
    pub output_settings: OutputSettings,
    /// Base name of the output files.
    pub name: String,
    /// The shard's render.
    pub output: RenderOutput,
}

/// Current [`PartialFilm::version`].
pub const PARTIAL_VERSION: u32 = 6;

/// bincode's configuration for part files: the standard encoding, with every claimed length
/// bounded by the file-size limit so a forged length cannot make the decoder reserve memory.
fn config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<{ MAX_PART_BYTES as usize }>()
}

impl PartialFilm {
    /// The part as bytes (what [`PartialFilm::decode`] reads).
    ///
    /// # Errors
    /// bincode's error, as text.
    pub fn encode(&self) -> Result<Vec<u8>, String> {
        bincode::serde::encode_to_vec(self, config()).map_err(|e| e.to_string())
    }

    /// Reads and validates a part file (bounded by [`MAX_PART_BYTES`](crate::MAX_PART_BYTES)).
    ///
    /// # Errors
    /// Why the file is not a valid part.
    pub fn read(path: &Path) -> Result<Self, String> {
        Self::decode(&read_bounded(path, MAX_PART_BYTES, "partial film")?)
    }

    /// Decodes and validates a part from bytes.
    ///
    /// # Errors
    /// Why the bytes are not a valid part: not bincode of a part, trailing bytes, another
    /// version, or a field no render could have written (see [`PartialFilm::validate`]).
    pub fn decode(bytes: &[u8]) -> Result<Self, String> {
        // The version comes first: check it before decoding the rest, whose layout may differ.
        let version: Result<(u32, usize), _> = bincode::decode_from_slice(bytes, config());
        match version {
            Ok((PARTIAL_VERSION, _)) => {}
            Ok((v, _)) => {
                return Err(format!(
                    "partial film version {v}; this Spectrace reads version {PARTIAL_VERSION}"
                ));
            }
            Err(e) => return Err(format!("not a Spectrace partial film: {e}")),
        }
        let (part, used): (PartialFilm, usize) = bincode::serde::decode_from_slice(bytes, config())
            .map_err(|e| format!("not a Spectrace partial film: {e}"))?;
        if used != bytes.len() {
            return Err(format!(
                "not a Spectrace partial film: {} unexpected bytes after the film",
                bytes.len() - used
            ));
        }
        part.validate()?;
        Ok(part)
    }

    /// Checks every field as a scene field would be checked.
    ///
    /// # Errors
    /// The first field that no render could have written, named as `part.field`.
    pub fn validate(&self) -> Result<(), String> {
        self.validate_settings()?;
        validate_plan(&self.plan)?;
        let decided = Effects::decide(self.effects.features, self.effects.mode);
        if decided != self.effects {
            return bad(
                "effects",
                "the decision does not follow from the scene features it names".to_owned(),
            );
        }
        let out = &self.output;
        validate_film(out)?;
        validate_chunks(&self.plan, out)?;
        validate_moments(&self.plan, out)?;
        if !(out.seconds >= 0.0 && out.seconds.is_finite()) {
            return bad(
                "output.seconds",
                format!("{}: must be finite and non-negative", out.seconds),
            );
        }
        Ok(())
    }

    /// The light power, the output name and the output settings.
    fn validate_settings(&self) -> Result<(), String> {
        if !(self.light_power > 0.0 && self.light_power.is_finite()) {
            return bad(
                "light_power",
                format!("{}: must be positive and finite", self.light_power),
            );
        }
        check_output_name(&self.name).or_else(|e| bad("name", e))?;
        if let Some(name) = &self.output_settings.name {
            check_output_name(name).or_else(|e| bad("output_settings.name", e))?;
        }
        if !self.output_settings.exposure.is_finite() {
            return bad(
                "output_settings.exposure",
                format!("{}: must be finite", self.output_settings.exposure),
            );
        }
        Ok(())
    }
}

/// The error for `field` of a part: `field: why`.
fn bad<T>(field: &str, why: String) -> Result<T, String> {
    Err(format!("{field}: {why}"))
}

/// The plan: work to do, no shard (a part stores the whole plan), a valid budget and target.
fn validate_plan(plan: &RenderPlan) -> Result<(), String> {
    if plan.beams == 0 || plan.chunk_beams == 0 {
        return bad(
            "plan",
            format!("beams {} and chunk_beams {} must be at least 1", plan.beams, plan.chunk_beams),
        );
    }
    if plan.shard.is_some() {
        return bad("plan.shard", "a part stores the whole plan, without its shard".to_owned());
    }
    if let Some(t) = plan.time_budget
        && !(t > 0.0 && t.is_finite())
    {
        return bad("plan.time_budget", format!("{t}: must be a positive number of seconds"));
    }
    if let Some(e) = plan.target_error {
        crate::check_target_error(e).or_else(|m| bad("plan.target_error", m))?;
    }
    Ok(())
}

/// The film: a valid image size, exactly its pixels (shards fill no sensors), no negative sum.
fn validate_film(out: &RenderOutput) -> Result<(), String> {
    let (w, h) = (out.film.width(), out.film.height());
    if w == 0 || h == 0 || u64::from(w) * u64::from(h) > 1 << 25 {
        return bad("output.film", format!("size {w}x{h} is not a valid image size"));
    }
    let pixels = out.film.to_xyz(1.0);
    // Shards fill no sensors, so a part's film is its pixels and nothing more.
    let extra = out.film.sensor_cells();
    if pixels.len() as u64 != u64::from(w) * u64::from(h) || extra != 0 {
        return bad(
            "output.film",
            format!(
                "holds {} pixels, but a {w}x{h} image has {}",
                pixels.len() + extra as usize,
                w * h
            ),
        );
    }
    if let Some(i) = pixels.iter().position(|p| !(p.x >= 0.0 && p.y >= 0.0 && p.z >= 0.0)) {
        return bad(
            "output.film",
            format!(
                "pixel {i} has a negative sum ({:?}): light adds, it never subtracts",
                pixels[i]
            ),
        );
    }
    Ok(())
}

/// The chunks: strictly increasing, in the plan, and holding exactly the beams counted (at most
/// them with a time budget, which cuts the last chunks short).
fn validate_chunks(plan: &RenderPlan, out: &RenderOutput) -> Result<(), String> {
    let total_chunks = plan.chunks();
    if let Some(pair) = out.chunks.windows(2).find(|p| p[0] >= p[1]) {
        return bad(
            "output.chunks",
            format!("not strictly increasing ({} then {})", pair[0], pair[1]),
        );
    }
    if let Some(&c) = out.chunks.iter().find(|&&c| c >= total_chunks) {
        return bad(
            "output.chunks",
            format!("chunk {c} does not exist: the plan has {total_chunks} chunks"),
        );
    }
    let capacity = out
        .chunks
        .iter()
        .try_fold(0u64, |acc, &c| acc.checked_add(plan.beams_in_chunk(c)))
        .unwrap_or(u64::MAX);
    let consistent =
        if plan.time_budget.is_some() { out.beams <= capacity } else { out.beams == capacity };
    if !consistent || out.stats.beams != out.beams {
        return bad(
            "output.beams",
            format!(
                "{} beams (counted {}) do not match the {} beams of its {} chunks",
                out.beams,
                out.stats.beams,
                capacity,
                out.chunks.len()
            ),
        );
    }
    Ok(())
}

/// The error estimate's moments: the film's size, the chunks and items rendered (fewer with a
/// time budget), valid sums; present whenever the plan has a target.
fn validate_moments(plan: &RenderPlan, out: &RenderOutput) -> Result<(), String> {
    let (w, h) = (out.film.width(), out.film.height());
    let Some(m) = &out.moments else {
        if plan.target_error.is_some() {
            return bad(
                "output.moments",
                "missing: a render to a target error keeps its estimate".to_owned(),
            );
        }
        return Ok(());
    };
    if (m.width(), m.height()) != (w, h) {
        return bad(
            "output.moments",
            format!("size {}x{} differs from the film's {w}x{h}", m.width(), m.height()),
        );
    }
    // Chunks cut short by a time budget are rendered but not in the moments.
    let cut_short_allowed = plan.time_budget.is_some();
    let (chunks, items) = (out.chunks.len() as u64, out.beams);
    let matches = if cut_short_allowed {
        m.chunks() <= chunks && m.items() <= items
    } else {
        m.chunks() == chunks && m.items() == items
    };
    if !matches {
        return bad(
            "output.moments",
            format!(
                "{} chunks of {} items, but the part rendered {} chunks of {} items",
                m.chunks(),
                m.items(),
                out.chunks.len(),
                out.beams
            ),
        );
    }
    m.validate().or_else(|e| bad("output.moments", e))
}
