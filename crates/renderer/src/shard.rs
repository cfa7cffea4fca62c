//! Sharded renders: a shard's part file, and merging the parts into the outputs one machine
//! would write.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use spectrace_tracer::{Film, MemoryLimit, RenderOutput, RenderPlan, TraceStats};

use crate::integrators::sampler_of;
use crate::part_receivers::MergedReceivers;
use crate::report::report;
use crate::say::tell;
use crate::write::{planned_outputs, write_sidecar};
use crate::{
    PartialFilm, RenderError, RenderReport, normalisation, write_atomically, write_outputs,
};

/// Merges the partial films of a sharded render into the final outputs, bit-identical to a
/// one-machine render with the same seed.
///
/// Every part is read with a size limit and validated field by field ([`PartialFilm::decode`]);
/// parts must come from the same render, may not share a chunk, and (without a time budget) must
/// cover every chunk. Outputs go into `out_dir` under the parts' validated name and never replace
/// a part file.
///
/// # Errors
/// [`RenderError::File`] for an unreadable or invalid part (naming the file and the field);
/// [`RenderError::Options`] when the parts do not belong together, overlap, miss chunks, or their
/// counts overflow.
pub fn merge_parts(parts: &[PathBuf], out_dir: &Path) -> Result<RenderReport, RenderError> {
    let Some(first_path) = parts.first() else {
        return Err(RenderError::Options("merge needs at least one partial film".to_owned()));
    };
    // Parts are read one at a time: memory holds the merged film and one part, whatever their
    // number. The first part's film becomes the merged film.
    let mut first = read_part(first_path)?;
    let size = (first.output.film.width(), first.output.film.height());
    check_merge_memory(size, first.output.film.has_pass_layer())?;
    let mut receivers = MergedReceivers::new(std::mem::take(&mut first.receivers));
    let sensor_files = receivers.planned_files(out_dir);
    planned_outputs(out_dir, &first.name, &first.output_settings, None, parts, sensor_files)?;
    let mut merged = take_output(&mut first)?;
    // Which part holds each chunk: coverage is checked by chunk identity, not by count.
    let mut owner: BTreeMap<u64, usize> = merged.chunks.iter().map(|&c| (c, 0)).collect();
    let mut seconds = vec![merged.seconds];
    for (index, path) in parts.iter().enumerate().skip(1) {
        let part = read_part(path)?;
        let what = difference(&first, &part, size)
            .or_else(|| (!receivers.same_kind(&part.receivers)).then_some("sensors or observers"));
        if let Some(what) = what {
            return Err(RenderError::Options(format!(
                "{}: belongs to another render: its {what} differs from {}",
                path.display(),
                first_path.display()
            )));
        }
        claim_chunks(&mut owner, &part.output, index, parts)?;
        add_part(&mut merged, &part.output, path)?;
        receivers.add(&part.receivers, index, parts)?;
        seconds.push(part.output.seconds);
    }
    check_coverage(&first.plan, &owner)?;
    receivers.check_coverage()?;
    write_merged(out_dir, &first, &merged, &seconds, (&receivers, parts))
}

/// Reads and validates one part, naming the file in errors.
fn read_part(path: &Path) -> Result<PartialFilm, RenderError> {
    PartialFilm::read(path).map_err(|message| RenderError::File { path: path.to_owned(), message })
}

/// Checks that the merged film and one part of `width x height` (with or without a pass layer)
/// fit in memory.
fn check_merge_memory((w, h): (u32, u32), pass_layer: bool) -> Result<(), RenderError> {
    let limit = MemoryLimit::system();
    let film = if pass_layer { Film::bytes_with_pass_layer(w, h) } else { Film::bytes_for(w, h) };
    let needed = film.saturating_mul(2);
    if needed > limit.bytes {
        return Err(RenderError::Options(format!(
            "merging {w}x{h} films needs {} (the merged film and one part), more than the {} \
             this machine may use ({})",
            spectrace_geometry::human_bytes(needed),
            spectrace_geometry::human_bytes(limit.bytes),
            limit.source
        )));
    }
    Ok(())
}

/// Moves the part's output out (it becomes the merged film), leaving an empty one behind.
fn take_output(part: &mut PartialFilm) -> Result<RenderOutput, RenderError> {
    let placeholder = RenderOutput {
        film: Film::new(1, 1).map_err(|e| RenderError::Options(e.to_string()))?,
        stats: TraceStats::default(),
        chunks: Vec::new(),
        beams: 0,
        seconds: 0.0,
        moments: None,
        cut: Vec::new(),
    };
    Ok(std::mem::replace(&mut part.output, placeholder))
}

/// What differs between `part` and the `first` part (whose image is `size`), if anything: the
/// parts of one render share everything but their chunks.
fn difference(first: &PartialFilm, part: &PartialFilm, size: (u32, u32)) -> Option<&'static str> {
    if part.scene_fingerprint != first.scene_fingerprint {
        Some("scene")
    } else if part.plan != first.plan {
        Some("plan (beams, chunk size, seed or time budget)")
    } else if part.effects != first.effects {
        Some("effects decision")
    } else if part.name != first.name || part.output_settings != first.output_settings {
        Some("output settings")
    } else if part.integrator != first.integrator {
        Some("integrator")
    } else if part.sampler != first.sampler {
        Some("sampler")
    } else if part.light_power.to_bits() != first.light_power.to_bits() {
        Some("light power")
    } else if (part.output.film.width(), part.output.film.height()) != size {
        Some("image size")
    } else {
        None
    }
}

/// Records that part `index` holds its chunks; a chunk another part holds is an error.
fn claim_chunks(
    owner: &mut BTreeMap<u64, usize>,
    part: &RenderOutput,
    index: usize,
    parts: &[PathBuf],
) -> Result<(), RenderError> {
    for &c in &part.chunks {
        if let Some(&other) = owner.get(&c) {
            return Err(RenderError::Options(format!(
                "{}: chunk {c} is also in {} (the same shard twice?)",
                parts[index].display(),
                parts[other].display()
            )));
        }
        owner.insert(c, index);
    }
    Ok(())
}

/// Adds a part's film and counters to the merged ones.
fn add_part(
    merged: &mut RenderOutput,
    part: &RenderOutput,
    path: &Path,
) -> Result<(), RenderError> {
    add_counts(merged, part).map_err(|what| {
        RenderError::Options(format!(
            "{}: adding its {what} to the other parts' overflows: not parts of one render",
            path.display()
        ))
    })?;
    merged.merge(part).map_err(|e| RenderError::Options(format!("{}: {e}", path.display())))
}

/// Checks that the parts cover every chunk of `plan`: time budgets and targets stop early, so
/// only they may leave chunks out.
pub(crate) fn check_coverage(
    plan: &RenderPlan,
    owner: &BTreeMap<u64, usize>,
) -> Result<(), RenderError> {
    if plan.time_budget.is_some() || plan.target_error.is_some() {
        return Ok(());
    }
    let expected = plan.chunks();
    if owner.len() as u64 != expected {
        let missing = (0..expected).filter(|c| !owner.contains_key(c)).take(10).collect::<Vec<_>>();
        return Err(RenderError::Options(format!(
            "the parts cover {} of {expected} chunks; missing e.g. {missing:?}",
            owner.len()
        )));
    }
    Ok(())
}

/// Writes the merged render's outputs and sidecar: its wall time is the slowest shard's, its
/// speed the beams over all shards' time.
fn write_merged(
    out_dir: &Path,
    first: &PartialFilm,
    merged: &RenderOutput,
    seconds: &[f64],
    (receivers, parts): (&MergedReceivers, &[PathBuf]),
) -> Result<RenderReport, RenderError> {
    let (w, h) = (merged.film.width(), merged.film.height());
    let numerator = normalisation(first.integrator, first.light_power, u64::from(w) * u64::from(h));
    let written = write_outputs(out_dir, &first.name, &first.output_settings, numerator, merged)?;
    let total_seconds: f64 = seconds.iter().sum();
    let mut report = report(
        first.scene_path.clone(),
        (w, h),
        first.plan,
        first.effects,
        first.integrator.name(),
        merged,
        seconds.iter().copied().fold(0.0, f64::max),
        first.light_power,
        written,
    );
    report.beams_per_second =
        if total_seconds > 0.0 { merged.beams as f64 / total_seconds } else { 0.0 };
    let error_decides = first.plan.target_error.is_some();
    report.sampler = sampler_of(first.sampler, first.integrator, error_decides, &first.effects)
        .name()
        .to_owned();
    let (sensors, observers) = receivers.finish(out_dir, merged, first.light_power, parts)?;
    for r in &sensors {
        report.outputs.extend(r.files.iter().cloned());
    }
    for r in &observers {
        tell!("{}", crate::observer_summary(r));
    }
    report.sensors = sensors;
    report.observers = observers;
    write_sidecar(out_dir, &first.name, &report)?;
    Ok(report)
}

/// Writes a shard's part file (encoded, then written to a temporary name and renamed); the part
/// is dropped once encoded, so its film is not held twice.
///
/// # Errors
/// [`RenderError::File`] if it cannot be encoded or written.
pub(crate) fn write_part(path: &Path, part: PartialFilm) -> Result<(), RenderError> {
    let file_error = |message| RenderError::File { path: path.to_owned(), message };
    let bytes = part.encode().map_err(file_error)?;
    drop(part);
    write_atomically(path, |p| std::fs::write(p, &bytes).map_err(|e| e.to_string()))
        .map_err(file_error)
}

/// Checks that adding `part`'s counters to `merged`'s cannot overflow (tampered parts could make
/// them wrap); names the counter that would.
fn add_counts(merged: &RenderOutput, part: &RenderOutput) -> Result<(), &'static str> {
    let fits = |a: u64, b: u64, what: &'static str| a.checked_add(b).map(|_| ()).ok_or(what);
    fits(merged.beams, part.beams, "beams")?;
    fits(merged.stats.beams, part.stats.beams, "beam count")?;
    fits(merged.stats.hits, part.stats.hits, "hit count")?;
    fits(merged.stats.splats, part.stats.splats, "splat count")?;
    fits(merged.stats.roulette_kills, part.stats.roulette_kills, "roulette count")?;
    fits(merged.stats.depth_limited, part.stats.depth_limited, "depth-limit count")?;
    fits(merged.stats.reemissions, part.stats.reemissions, "re-emission count")?;
    fits(merged.film.accepted(), part.film.accepted(), "accepted-contribution count")?;
    fits(merged.film.rejected(), part.film.rejected(), "rejected-contribution count")?;
    Ok(())
}
