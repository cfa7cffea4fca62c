//! Partial films: what `spectrace render --shard K/N` writes and `spectrace merge` reads.
//!
//! A part file is input like a scene file, possibly made or altered by someone else, so reading one
//! is bounded and every field is validated like a scene field: [`PartialFilm::decode`] refuses
//! anything larger than [`MAX_PART_BYTES`](crate::MAX_PART_BYTES), any claimed length beyond
//! that limit, trailing bytes, and any value a render could not have produced (non-finite or
//! non-positive light power, a pixel array that does not match the image size, negative pixel
//! sums, a pass layer no render of the part's kind keeps, sensor and observer sums that do not
//! match their definitions, chunks outside the plan, cut chunks
//! not among them or not cut, beams other than the chunks hold, an inconsistent effects
//! decision, an output name that is not a plain file name).

use std::path::Path;

use serde::{Deserialize, Serialize};
use spectrace_tracer::{Effects, IntegratorChoice, Moments, RenderOutput, RenderPlan, SamplerKind};

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
    /// The shard's share of the sensors and observers (empty lists for a scene without them).
    pub receivers: crate::part_receivers::ReceiversPart,
}

/// Current [`PartialFilm::version`].
pub const PARTIAL_VERSION: u32 = 9;

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
        self.receivers.validate()?;
        validate_film(out, self.receivers.image_cells())?;
        let plan = &self.plan;
        let passes_may_be_cut = plan.time_budget.is_some() || plan.ends_inside_a_chunk();
        if out.film.has_pass_layer()
            && (!passes_may_be_cut || !crate::integrators::is_camera_integrator(self.integrator))
        {
            return bad(
                "output.film",
                "has a pass layer, which only a camera estimator's render with a time budget, or \
                 a budget of samples that ends inside a pass, keeps"
                    .to_owned(),
            );
        }
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
pub(crate) fn validate_plan(plan: &RenderPlan) -> Result<(), String> {
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

/// The film: a valid image size, exactly its pixels and `cells` sensor cells (those the light
/// tracer's beams fill), no negative sum.
fn validate_film(out: &RenderOutput, cells: usize) -> Result<(), String> {
    let (w, h) = (out.film.width(), out.film.height());
    if w == 0 || h == 0 || u64::from(w) * u64::from(h) > 1 << 25 {
        return bad("output.film", format!("size {w}x{h} is not a valid image size"));
    }
    out.film.check_sums().or_else(|e| bad("output.film", e))?;
    let extra = out.film.sums_after_pixels();
    let expected = spectrace_tracer::SENSOR_SLOTS * cells;
    if extra != expected {
        return bad(
            "output.film",
            format!(
                "holds {} sums, but a {w}x{h} image has {} pixels and its sensors {expected} sums",
                u64::from(w * h) + extra as u64,
                w * h
            ),
        );
    }
    Ok(())
}

/// The chunks: strictly increasing, in the plan; the cut ones among them, cut, and only with a
/// time budget; and exactly the beams counted: the whole chunks' plus the cut ones' counts.
pub(crate) fn validate_chunks(plan: &RenderPlan, out: &RenderOutput) -> Result<(), String> {
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
    validate_cut(plan, out)?;
    let capacity = out
        .chunks
        .iter()
        .try_fold(0u64, |acc, &c| acc.checked_add(plan.beams_in_chunk(c)))
        .unwrap_or(u64::MAX);
    // Every cut chunk is listed with its count, so the beams are known exactly.
    let shortfall = out.cut.iter().fold(0u64, |sum, &(c, done)| {
        sum.saturating_add(plan.beams_in_chunk(c).saturating_sub(done))
    });
    if out.beams != capacity.saturating_sub(shortfall) || out.stats.beams != out.beams {
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

/// The cut chunks: strictly increasing, each among the chunks and cut: at least one item and
/// fewer than the chunk's (only with a time budget), or all of the plan's last chunk where it
/// is shorter than the others (a camera estimator's pass that the budget of samples ends
/// inside).
fn validate_cut(plan: &RenderPlan, out: &RenderOutput) -> Result<(), String> {
    if out.cut.is_empty() {
        return Ok(());
    }
    if let Some(pair) = out.cut.windows(2).find(|p| p[0].0 >= p[1].0) {
        return bad(
            "output.cut",
            format!("not strictly increasing (chunk {} then {})", pair[0].0, pair[1].0),
        );
    }
    for &(c, done) in &out.cut {
        if out.chunks.binary_search(&c).is_err() {
            return bad("output.cut", format!("chunk {c} is not among the part's chunks"));
        }
        let planned = plan.beams_in_chunk(c);
        let budget_ends_inside = done == planned && planned < plan.chunk_beams;
        if done == 0 || done > planned || (done == planned && !budget_ends_inside) {
            return bad(
                "output.cut",
                format!("chunk {c} did {done} of its {planned} items: not a cut chunk"),
            );
        }
        if done < planned && plan.time_budget.is_none() {
            return bad("output.cut", "chunks cut short without a time budget".to_owned());
        }
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
    let cut_items = out.cut.iter().fold(0u64, |sum, &(_, done)| sum.saturating_add(done));
    let chunks = out.chunks.len().saturating_sub(out.cut.len()) as u64;
    let items = out.beams.saturating_sub(cut_items);
    let matches = m.chunks() == chunks && m.items() == items;
    // The whole chunks of the split-half estimate's first half.
    let first = out
        .chunks
        .iter()
        .filter(|&&c| Moments::in_first_half(c) && !out.cut.iter().any(|&(cut, _)| cut == c))
        .fold([0u64; 2], |[n, items], &c| [n + 1, items.saturating_add(plan.beams_in_chunk(c))]);
    if matches && m.first_half_chunks() != first {
        return bad(
            "output.moments",
            format!(
                "{:?} chunks and items in the first half, but the part rendered {first:?}",
                m.first_half_chunks()
            ),
        );
    }
    if !matches {
        return bad(
            "output.moments",
            format!(
                "{} chunks of {} items, but the part rendered {chunks} whole chunks of {items} items",
                m.chunks(),
                m.items()
            ),
        );
    }
    m.validate().or_else(|e| bad("output.moments", e))
}
