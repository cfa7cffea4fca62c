//! A render watched by a progress bar on stderr, with its live error message.

use std::time::Instant;

use spectrace_tracer::{Integrator, LiveEstimates, RenderOutput, RenderPlan, render_observed};

use crate::{RenderError, duration};

/// Renders `plan` with `tracer`, showing a progress bar when `visible`; returns the output and
/// the wall time (s).
///
/// # Errors
/// [`RenderError::Options`] if the film cannot be made.
pub(crate) fn render_with_progress(
    tracer: &dyn Integrator,
    plan: &RenderPlan,
    visible: bool,
) -> Result<(RenderOutput, f64), RenderError> {
    let bar = progress_bar(plan, visible);
    let started = Instant::now();
    let target = plan.shard_target_error();
    let update = |p: &spectrace_tracer::Progress| {
        bar.set_position(p.items.min(bar.length().unwrap_or(u64::MAX)));
        if let Some(e) = &p.estimate {
            bar.set_message(progress_message(e, target, p.seconds));
        }
    };
    // A hidden bar (`--quiet`, or stderr not a terminal) reads no live estimate.
    let live = if bar.is_hidden() { LiveEstimates::ForTarget } else { LiveEstimates::Reported };
    let output = render_observed(tracer, plan, &update, live)
        .map_err(|e| RenderError::Options(e.to_string()))?;
    bar.finish_and_clear();
    Ok((output, started.elapsed().as_secs_f64()))
}

/// The progress bar: hidden unless `visible`; a spinner for open-ended renders (a time budget
/// or a target), else a bar with an ETA.
fn progress_bar(plan: &RenderPlan, visible: bool) -> indicatif::ProgressBar {
    if !visible {
        return indicatif::ProgressBar::hidden();
    }
    let open_ended = plan.time_budget.is_some() || plan.target_error.is_some();
    let bar = indicatif::ProgressBar::new(plan.shard_beams());
    let template = if open_ended {
        "{spinner} {elapsed_precise} {pos} items ({per_sec}) {msg}"
    } else {
        "{bar:30} {percent:>3}% {pos}/{len} items, {per_sec}, ETA {eta} {msg}"
    };
    if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
        bar.set_style(style);
    }
    bar
}

/// The progress bar's message for a live estimate: the error and, with a target, the time
/// still needed (error falling as `1 / sqrt(time)`).
fn progress_message(
    e: &spectrace_tracer::ErrorEstimate,
    target: Option<f64>,
    seconds: f64,
) -> String {
    let Some(r) = e.relative_error else {
        return format!("error: waiting for batches ({})", e.batches);
    };
    let mut m = format!("{} {:.2}%", e.measure.name(), r * 100.0);
    if !e.is_trusted() {
        m.push_str(&format!(" ({} of {} batches)", e.batches, spectrace_tracer::MIN_BATCHES));
    }
    if let Some(t) = target {
        let left = (seconds * (r / t).powi(2) - seconds).max(0.0);
        m.push_str(&format!(" -> {:.2}%, ~{} to go", t * 100.0, duration(left)));
    }
    m
}
