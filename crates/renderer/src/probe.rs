//! The pre-render probe: does the film fit in memory, and can light reach the camera at all? A
//! camera that sees no light while light reaches the scene (a sensor, or surfaces out of view or
//! black) renders a dark image, with a warning; only a scene where visible light reaches
//! nothing is an error.

use std::time::Instant;

use spectrace_lights::LightSource;

use spectrace_tracer::{
    ChunkWork, Effects, FilmError, Integrator, IntegratorChoice, MemoryLimit, RenderPlan,
    TraceStats,
};

use crate::{OUTPUT_BYTES_PER_PIXEL, Scene, SceneError, with_integrator};

/// Beams traced to check that light can reach the camera before rendering.
pub const PROBE_BEAMS: u64 = 20_000;

/// Longest the pre-render probe may run (s); with a time budget, at most a tenth of it.
pub const PROBE_SECONDS: f64 = 2.0;

/// What the pre-render probe found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeOutcome {
    /// Beams traced.
    pub beams: u64,
    /// `true`: a beam put visible light on the film; `false`: the probe ran out of time first
    /// (inconclusive: the render goes on).
    pub lit: bool,
    /// Wall time (s).
    pub seconds: f64,
    /// `true`: no probe path lit the film, but light does reach the scene (a sensor records
    /// it, or beams land on surfaces the camera does not see or that reflect nothing), so a
    /// dark image is the result, not an error.
    pub dark: bool,
}

/// A sink that only records whether visible light reached the film (no film is allocated).
struct VisibleLight {
    width: u32,
    height: u32,
    lit: bool,
}

impl spectrace_tracer::Splat for VisibleLight {
    fn splat(&mut self, x: u32, y: u32, xyz: spectrace_spectrum::Xyz) -> bool {
        // As the film would: in the frame, every component in range, and one that is positive
        // after rounding to the film's fixed point.
        let mut positive = false;
        for v in [xyz.x, xyz.y, xyz.z] {
            let mut sum = spectrace_tracer::ExactSum::default();
            if !sum.add(v) {
                return false;
            }
            positive |= sum.raw() > 0;
        }
        if x >= self.width || y >= self.height {
            return false;
        }
        self.lit |= positive;
        true
    }
}

/// Checks, before rendering, that the film fits (at most [`spectrace_tracer::MAX_PIXELS`] pixels
/// and within [`MemoryLimit::system`], see [`RenderPlan::check_memory`]; nothing is allocated)
/// and that some light reaches the camera: traces beams (on their own random
/// streams) until one puts visible light on the film, at most `min(PROBE_BEAMS, plan.beams)` of
/// them and for at most `min(PROBE_SECONDS, plan.time_budget / 10)`. Most scenes need a handful
/// of beams. A probe that runs out of time is inconclusive and lets the render go on.
///
/// # Errors
/// [`SceneError::Scene`] for a camera resolution that is not a valid film or does not fit in
/// memory, and, explaining that the image would be black, when none of the beams lit the film.
pub fn probe(
    scene: &Scene,
    effects: &Effects,
    plan: &RenderPlan,
) -> Result<ProbeOutcome, SceneError> {
    with_integrator(scene, IntegratorChoice::Light, *effects, |tracer| {
        probe_with(scene, plan, tracer)
    })
}

/// The memory a render of a `width x height` image may use: [`MemoryLimit::system`] less what
/// converting the image for writing takes after the render (the film stays allocated then).
pub(crate) fn render_memory_limit(width: u32, height: u32) -> MemoryLimit {
    let system = MemoryLimit::system();
    let writing = OUTPUT_BYTES_PER_PIXEL * u64::from(width) * u64::from(height);
    MemoryLimit {
        bytes: system.bytes.saturating_sub(writing),
        source: format!(
            "{}, less {} to convert the image for writing",
            system.source,
            spectrace_geometry::human_bytes(writing)
        ),
    }
}

/// [`probe`] with any estimator: its work items (beams, or camera samples spread over the
/// image) are traced one per chunk until one puts visible light on the film.
///
/// # Errors
/// As [`probe`].
pub fn probe_with(
    scene: &Scene,
    plan: &RenderPlan,
    tracer: &dyn Integrator,
) -> Result<ProbeOutcome, SceneError> {
    let (width, height) = (scene.camera.width(), scene.camera.height());
    let camera_error = |e: FilmError| SceneError::Scene {
        path: scene.path.clone(),
        field: "camera".to_owned(),
        message: e.to_string(),
    };
    if u64::from(width) * u64::from(height) > spectrace_tracer::MAX_PIXELS {
        return Err(camera_error(FilmError::InvalidSize(width, height)));
    }
    let limit = render_memory_limit(width, height);
    plan.check_memory(width, height, &limit).map_err(camera_error)?;
    let started = Instant::now();
    let limit = plan.time_budget.map_or(PROBE_SECONDS, |t| (t / 10.0).min(PROBE_SECONDS));
    let deadline = std::time::Duration::try_from_secs_f64(limit.max(0.0))
        .ok()
        .and_then(|d| started.checked_add(d));
    let max_beams = PROBE_BEAMS.min(plan.beams).max(1);
    let mut sink = VisibleLight { width, height, lit: false };
    let mut stats = TraceStats::default();
    let mut timed_out = false;
    for beam in 0..max_beams {
        // One beam per chunk, so that the probe can stop after any beam.
        let work =
            ChunkWork { seed: u64::MAX, chunk: beam, items: 1, deadline: None, ends_pass: false };
        stats.merge(&tracer.render_chunk(work, &mut sink));
        if sink.lit {
            break;
        }
        if deadline.is_some_and(|d| Instant::now() >= d) {
            timed_out = true;
            break;
        }
    }
    scene.lights.reset_count();
    let outcome = ProbeOutcome {
        beams: stats.beams,
        lit: sink.lit,
        seconds: started.elapsed().as_secs_f64(),
        dark: false,
    };
    if sink.lit || (timed_out && stats.beams < max_beams) {
        return Ok(outcome);
    }
    if light_reaches_the_scene(scene, max_beams) {
        return Ok(ProbeOutcome { dark: true, ..outcome });
    }
    Err(SceneError::Scene {
        path: scene.path.clone(),
        field: "lights".to_owned(),
        message: format!(
            "no light can reach the camera or anything else: none of {} probe paths (beams or camera samples) lit a point the camera sees \
             with visible light ({} hit a surface, {} reached the film), no visible light lands on any surface, and no sensor \
             records it. Check that the lights face the objects, that their spectra lie in 360-830 nm, and that the camera \
             looks at the lit objects.",
            stats.beams, stats.hits, stats.splats
        ),
    })
}

/// Whether visible light reaches anything in the scene: some light has a visible spectrum, and
/// there is a sensor to record it or one of up to `beams` light-tracer beams lands on a surface.
fn light_reaches_the_scene(scene: &Scene, beams: u64) -> bool {
    let visible = scene
        .lights
        .lights()
        .iter()
        .any(|l| spectrace_spectrum::luminous_efficacy(l.spd().as_ref()) > 0.0);
    if !visible {
        return false;
    }
    if !scene.sensors.is_empty() {
        return true;
    }
    let effects = crate::decide_effects(scene, None);
    let hit = with_integrator(scene, IntegratorChoice::Light, effects, |tracer| {
        let mut sink = VisibleLight { width: 1, height: 1, lit: false };
        let work = ChunkWork {
            seed: u64::MAX - 1,
            chunk: 0,
            items: beams,
            deadline: None,
            ends_pass: false,
        };
        tracer.render_chunk(work, &mut sink).hits > 0
    });
    scene.lights.reset_count();
    hit
}
