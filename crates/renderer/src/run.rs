//! Rendering a scene with its overrides: the plan, the probe, the render and the written outputs
//! (or a shard's part file); and renders kept in memory.

use std::path::Path;

use spectrace_lights::LightSource;
use spectrace_tracer::{
    Effects, Integrator, IntegratorChoice, Kernel, MemoryLimit, RenderOutput, RenderPlan, render,
};

/// Lights listed one by one under `--verbose`; the rest are summed on one line.
const LIGHTS_LISTED: usize = 8;

use crate::integrators::{
    bdpt_wavelengths_text, kernel_of, light_sampler_of, light_sampler_text, sampler_of,
    sampler_text, with_kernel,
};
use crate::measured::measure_choice;

use crate::plan::scene_normalisation;
use crate::progress::render_with_progress;
use crate::report::{LightReport, report};
use crate::say::tell;
use crate::sensors::render_sensors;
use crate::shard::write_part;
use crate::warnings::{black_image_warning, render_warnings};
use crate::write::{part_path, planned_outputs, write_sidecar};
use crate::{
    LoadOptions, MAX_PART_BYTES, PARTIAL_VERSION, PartialFilm, ProbeOutcome, RenderError,
    RenderOptions, RenderReport, Scene, Written, check_sensor_names, choose_integrator,
    decide_effects, image, plan_with, planned_sensor_outputs, probe_with, sensor_summary,
    write_outputs,
};

/// Renders a scene file with overrides and writes its outputs (or, with a shard, its partial film).
///
/// # Errors
/// [`RenderError`] for an invalid scene or options, or a file that cannot be written.
pub fn render_file(path: &Path, options: &RenderOptions) -> Result<RenderReport, RenderError> {
    let scene = Scene::load_with(path, LoadOptions { restrict_paths: options.restrict_paths })?;
    render_scene(&scene, options)
}

/// Renders a loaded scene with overrides and writes its outputs.
///
/// # Errors
/// As [`render_file`].
pub fn render_scene(scene: &Scene, options: &RenderOptions) -> Result<RenderReport, RenderError> {
    let fallback = choose_integrator(scene, options.integrator);
    let plan = plan_with(scene, options, fallback.0)?;
    let name = scene.output_name();
    check_sensor_names(scene, &name)?;
    planned_outputs(
        &options.out_dir,
        &name,
        &options.output_settings(scene),
        plan.shard,
        &scene.inputs,
        planned_sensor_outputs(scene, &options.out_dir),
    )?;
    let mut warnings: Vec<String> =
        scene.notes.iter().map(|n| format!("imported with an approximation: {n}")).collect();
    for (i, light) in scene.lights.lights().iter().enumerate() {
        warnings.extend(light.notes().into_iter().map(|n| format!("lights[{i}]: {n}")));
    }
    let (choice, reason, plan) = match measure_choice(scene, options, &plan, &fallback) {
        Ok(Some(m)) => {
            // The pilots' time comes out of the budget.
            let mut plan = plan_with(scene, options, m.choice)?;
            plan.time_budget = plan.time_budget.map(|t| (t - m.pilot_seconds).max(1e-3));
            (m.choice, m.reason, plan)
        }
        Ok(None) => (fallback.0, fallback.1, plan),
        Err(e) => {
            warnings.push(format!("auto's pilot failed ({e}); the analysis' pick is used"));
            (fallback.0, fallback.1, plan)
        }
    };
    let (plan, estimate_warning) = fit_estimate(scene, plan)?;
    warnings.extend(estimate_warning);
    let effects = decide_effects(scene, options.effects);
    if options.verbose {
        let lights = scene.lights.lights();
        for (i, l) in lights.iter().enumerate().take(LIGHTS_LISTED) {
            // A measured luminaire also says what its file holds: lamps and light output ratio.
            let file = l.photometric_summary().map(|s| format!(" ({s})")).unwrap_or_default();
            let r = LightReport::of(l.as_ref());
            let (w, lm) = (r.watts.unwrap_or(f64::INFINITY), r.lumens.unwrap_or(f64::INFINITY));
            tell!("lights[{i}]: {} of {w:.6} W, {lm:.2} lm{file}", r.kind);
        }
        if lights.len() > LIGHTS_LISTED {
            let watts: f64 = lights.iter().skip(LIGHTS_LISTED).map(|l| l.power()).sum();
            let more = lights.len() - LIGHTS_LISTED;
            tell!("lights[{LIGHTS_LISTED}..{}]: {more} more lights, {watts:.6} W", lights.len());
        }
        tell!("light sampler: {}", light_sampler_text(scene));
        tell!("{}", effects.summary());
        tell!("integrator: {reason}");
    }
    let kernel = options.kernel.unwrap_or(scene.settings.kernel);
    if options.verbose && choice == IntegratorChoice::Path {
        tell!("kernel: {}", kernel.name());
    }
    let error_decides = plan.target_error.is_some();
    if options.verbose {
        let text = sampler_text(scene.settings.sampler, choice, error_decides, &effects);
        tell!("sampler: {text}");
        if choice == IntegratorChoice::Bdpt {
            let text = bdpt_wavelengths_text(scene.settings.bdpt_wavelengths, &effects.features);
            tell!("wavelengths: {text}");
        }
    }
    with_kernel(scene, choice, effects, (kernel, error_decides), |tracer| {
        let setup = Setup { choice, reason: &reason, effects, plan, name: &name, kernel };
        render_with(scene, options, &setup, warnings, tracer)
    })
}

/// The plan without the error estimate when its moments would not fit in memory but the
/// render would, or would make a shard's part file larger than a part may be (a very large
/// image), with a warning saying so; the plan unchanged otherwise.
///
/// # Errors
/// [`RenderError::Options`] when a target error needs the estimate that does not fit.
fn fit_estimate(
    scene: &Scene,
    plan: RenderPlan,
) -> Result<(RenderPlan, Option<String>), RenderError> {
    if !plan.keeps_estimate() {
        return Ok((plan, None));
    }
    let (w, h) = (scene.camera.width(), scene.camera.height());
    // With some slack: the process takes a little more address space before the probe checks
    // the plan again.
    let limit = crate::probe::render_memory_limit(w, h);
    let limit = MemoryLimit { bytes: limit.bytes.saturating_sub(64 << 20), ..limit };
    let without = RenderPlan { error_estimate: false, ..plan };
    let estimate_bytes = plan.memory_bytes(w, h).saturating_sub(without.memory_bytes(w, h));
    // A part file holds the film (up to 48 bytes per pixel) and the moments (72).
    let part_bytes = (u64::from(w) * u64::from(h)).saturating_mul(48 + 72);
    let why = if plan.shard.is_some() && part_bytes > MAX_PART_BYTES {
        format!(
            "a part file of a {w}x{h} image with its moments would exceed the {} part-file limit",
            spectrace_geometry::human_bytes(MAX_PART_BYTES)
        )
    } else if plan.check_memory(w, h, &limit).is_err() && without.check_memory(w, h, &limit).is_ok()
    {
        // Each thread keeps a chunk tally for the estimate: with fewer threads it may fit.
        let threads = plan.worker_threads();
        if let Some(fits) = plan.with_threads_fitting(w, h, &limit) {
            let warning = format!(
                "{} threads instead of {threads}: the error estimate keeps a chunk tally of {} \
                 bytes per pixel for each thread, and more do not fit in the memory a render \
                 may use ({})",
                fits.threads,
                spectrace_tracer::CHUNK_TALLY_BYTES_PER_PIXEL,
                limit.source
            );
            return Ok((fits, Some(warning)));
        }
        format!(
            "its moments for a {w}x{h} image ({} more) do not fit in the memory a render may \
             use ({})",
            spectrace_geometry::human_bytes(estimate_bytes),
            limit.source
        )
    } else {
        return Ok((plan, None));
    };
    // A target needs the estimate.
    if plan.target_error.is_some() {
        return Err(RenderError::Options(format!(
            "--target-error / settings.target_error needs the error estimate, but {why}"
        )));
    }
    Ok((without, Some(format!("no error estimate: {why}"))))
}

/// A render kept in memory: the film, the image and the estimator that made it.
#[derive(Debug, Clone)]
pub struct InMemoryRender {
    /// The film and counters.
    pub output: RenderOutput,
    /// The image (XYZ per pixel, film units).
    pub image: Vec<spectrace_spectrum::Xyz>,
    /// The estimator.
    pub integrator: IntegratorChoice,
}

/// Renders a scene with overrides without writing anything (no probe, no progress bar): for
/// tests, benchmarks and the accuracy report. `auto` is the effects analysis' rule here, never
/// measured ([`crate::measured`] is [`render_scene`]'s), so the estimator is reproducible.
///
/// # Errors
/// [`RenderError::Options`] for invalid options or a film that cannot be made.
pub fn render_in_memory(
    scene: &Scene,
    options: &RenderOptions,
) -> Result<InMemoryRender, RenderError> {
    let (choice, _) = choose_integrator(scene, options.integrator);
    let plan = plan_with(scene, options, choice)?;
    let effects = decide_effects(scene, options.effects);
    let kernel = options.kernel.unwrap_or(scene.settings.kernel);
    let build = (kernel, plan.target_error.is_some());
    let output =
        with_kernel(scene, choice, effects, build, |tracer| render(tracer, &plan, &|_| {}))
            .map_err(|e| RenderError::Options(e.to_string()))?;
    scene.lights.reset_count();
    let image = image(&output, scene_normalisation(scene, choice));
    Ok(InMemoryRender { output, image, integrator: choice })
}

/// What [`render_scene`] decided before building the estimator.
struct Setup<'a> {
    choice: IntegratorChoice,
    reason: &'a str,
    effects: Effects,
    plan: RenderPlan,
    name: &'a str,
    /// The path tracer's kernel (the setting, or its command-line override).
    kernel: Kernel,
}

/// The rest of [`render_scene`], once the estimator is built; `warnings` are the ones found so
/// far.
fn render_with(
    scene: &Scene,
    options: &RenderOptions,
    setup: &Setup<'_>,
    mut warnings: Vec<String>,
    tracer: &dyn Integrator,
) -> Result<RenderReport, RenderError> {
    warnings.extend(render_warnings(scene, setup.choice, &setup.plan));
    let probed = probe_noting(scene, &setup.plan, tracer, options.verbose)?;
    let (output, wall) = render_with_progress(tracer, &setup.plan, options.verbose)?;
    let finished = Finished { scene, setup, integrator: tracer.name(), wall, warnings };
    match setup.plan.shard {
        Some(shard) => write_shard(&finished, options, shard, tracer, output),
        None => write_render(&finished, options, tracer, probed, &output),
    }
}

/// The pre-render probe with the render's estimator (see [`probe_with`]); a probe that ran out
/// of time is noted on stderr when `verbose` (and an image that then comes out black is
/// reported after the render).
fn probe_noting(
    scene: &Scene,
    plan: &RenderPlan,
    tracer: &dyn Integrator,
    verbose: bool,
) -> Result<ProbeOutcome, RenderError> {
    let probed = probe_with(scene, plan, tracer)?;
    if verbose && !probed.lit && !probed.dark {
        tell!(
            "note: the pre-render probe ran out of time after {} paths without seeing light reach \
             the camera; rendering anyway",
            probed.beams
        );
    }
    Ok(probed)
}

/// A render that is done: what its reports share.
struct Finished<'a> {
    scene: &'a Scene,
    setup: &'a Setup<'a>,
    /// The estimator's [`Integrator::name`].
    integrator: &'static str,
    /// Wall time of the render (s).
    wall: f64,
    /// The warnings found before and while rendering.
    warnings: Vec<String>,
}

impl Finished<'_> {
    /// The sidecar's contents for `output` and what was written (whose warnings come first).
    fn report(&self, output: &RenderOutput, mut written: Written) -> RenderReport {
        let (scene, setup) = (self.scene, self.setup);
        written.warnings.extend(self.warnings.iter().cloned());
        let mut r = report(
            scene.path.display().to_string(),
            (scene.camera.width(), scene.camera.height()),
            setup.plan,
            setup.effects,
            self.integrator,
            output,
            self.wall,
            scene.lights.power(),
            written,
        );
        r.integrator_reason = setup.reason.to_owned();
        r.lights = LightReport::all(scene.lights.lights());
        let error_decides = setup.plan.target_error.is_some();
        r.sampler = sampler_of(scene.settings.sampler, setup.choice, error_decides, &setup.effects)
            .name()
            .to_owned();
        r.kernel = kernel_of(setup.choice, setup.kernel).name().to_owned();
        r.light_sampler = light_sampler_of(scene).name().to_owned();
        r.bdpt_wavelengths = (setup.choice == IntegratorChoice::Bdpt).then(|| {
            bdpt_wavelengths_text(scene.settings.bdpt_wavelengths, &setup.effects.features)
        });
        r
    }
}

/// A shard's end: its part file (the film moves into it) and its report, which has no sidecar.
fn write_shard(
    finished: &Finished<'_>,
    options: &RenderOptions,
    shard: (u64, u64),
    tracer: &dyn Integrator,
    output: RenderOutput,
) -> Result<RenderReport, RenderError> {
    let (scene, setup) = (finished.scene, finished.setup);
    let fills = tracer.sensor_cells() > 0;
    let receivers = crate::part_receivers::shard_receivers(
        scene,
        fills,
        setup.plan.threads,
        setup.effects,
        shard,
    )?;
    let path = part_path(&options.out_dir, setup.name, shard);
    let report = finished
        .report(&output, Written { files: vec![path.display().to_string()], ..Written::default() });
    let part = PartialFilm {
        version: PARTIAL_VERSION,
        scene_fingerprint: scene.fingerprint(),
        scene_path: scene.path.display().to_string(),
        plan: RenderPlan { shard: None, threads: 0, ..setup.plan },
        light_power: scene.lights.power(),
        integrator: setup.choice,
        sampler: scene.settings.sampler,
        effects: setup.effects,
        output_settings: options.output_settings(scene),
        name: setup.name.to_owned(),
        output,
        receivers,
    };
    write_part(&path, part)?;
    Ok(report)
}

/// An unsharded render's end: the image files, the sensors' files and the sidecar.
fn write_render(
    finished: &Finished<'_>,
    options: &RenderOptions,
    tracer: &dyn Integrator,
    probed: ProbeOutcome,
    output: &RenderOutput,
) -> Result<RenderReport, RenderError> {
    let (scene, setup) = (finished.scene, finished.setup);
    let numerator = scene_normalisation(scene, setup.choice);
    let settings = options.output_settings(scene);
    let mut written = write_outputs(&options.out_dir, setup.name, &settings, numerator, output)?;
    written.warnings.extend(black_image_warning(&probed, output));
    let sensors =
        render_sensors(scene, &options.out_dir, tracer, output, &setup.plan, setup.effects)?;
    for r in &sensors {
        written.files.extend(r.files.iter().cloned());
        if options.verbose {
            tell!("{}", sensor_summary(r));
        }
    }
    let observers = crate::render_observers(scene, setup.plan.threads, setup.effects)?;
    if options.verbose {
        for r in &observers {
            tell!("{}", crate::observer_summary(r));
        }
    }
    let mut report = finished.report(output, written);
    report.sensors = sensors;
    report.observers = observers;
    write_sidecar(&options.out_dir, setup.name, &report)?;
    Ok(report)
}
