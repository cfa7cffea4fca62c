//! The progress bar on stderr and its live error message.

use spectrace_tracer::RenderPlan;

use crate::duration;

pub(crate) fn progress_bar(plan: &RenderPlan, visible: bool) -> indicatif::ProgressBar {
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
pub(crate) fn progress_message(
    e: &spectrace_tracer::ErrorEstimate,
    target: Option<f64>,
    seconds: f64,
) -> String {
    let Some(r) = e.relative_rmse else {
        return format!("error: waiting for batches ({})", e.batches);
    };
    let mut m = format!("error {:.2}%", r * 100.0);
    if !e.is_trusted() {
        m.push_str(&format!(" ({} of {} batches)", e.batches, spectrace_tracer::MIN_BATCHES));
    }
    if let Some(t) = target {
        let left = (seconds * (r / t).powi(2) - seconds).max(0.0);
        m.push_str(&format!(" -> {:.2}%, ~{} to go", t * 100.0, duration(left)));
    }
    m
}
