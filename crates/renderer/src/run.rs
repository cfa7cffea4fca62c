//! Rendering a scene with its overrides: the plan, the probe, the render and the written outputs
//! (or a shard's part file); and renders kept in memory.

use std::path::Path;
use std::time::Instant;

use spectrace_lights::LightSource;
use spectrace_tracer::{
    Effects, Integrator, IntegratorChoice, MemoryLimit, RenderOutput, RenderPlan, render,
    render_observed,
};

use crate::progress::{progress_bar, progress_message};
use crate::report::report;
use crate::warnings::integrator_warnings;
use crate::write::{planned_outputs, write_sidecar};
use crate::{
    DEFAULT_SENSOR_SPP, LoadOptions, MAX_PART_BYTES, PARTIAL_VERSION, PartialFilm, RenderError,
    RenderOptions, RenderReport, Scene, SensorIntegrator, SensorSource, Written,
    check_sensor_names, choose_integrator, decide_effects, image, normalisation, plan_with,
    planned_sensor_outputs, probe_with, sensor_integrator, sensor_pass, sensor_pass_path,
    sensor_plan, sensor_summary, with_integrator, with_integrator_filling, write_atomically,
    write_outputs, write_sensors,
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
    let (choice, reason) = choose_integrator(scene, options.integrator);
    let plan = plan_with(scene, options, choice)?;
    let name = scene.output_name();
    check_sensor_names(scene, &name)?;
    planned_outputs(
        &options.out_dir,
        &name,
        &scene.output,
        plan.shard,
        &scene.inputs,
        planned_sensor_outputs(scene, &options.out_dir),
    )?;
    let (plan, estimate_warning) = fit_estimate(scene, plan)?;
    let effects = decide_effects(scene, options.effects);
    if options.verbose {
        eprintln!("{}", effects.summary());
        eprintln!("integrator: {reason}");
    }
    with_integrator_filling(scene, choice, effects, plan.shard.is_none(), |tracer| {
        let setup = Setup { choice, reason: &reason, effects, plan, name: &name };
        render_with(scene, options, &setup, estimate_warning.into_iter().collect(), tracer)
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
    let limit = MemoryLimit::system();
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
/// tests, benchmarks and the accuracy report.
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
    let output = with_integrator(scene, choice, effects, |tracer| render(tracer, &plan, &|_| {}))
        .map_err(|e| RenderError::Options(e.to_string()))?;
    scene.lights.reset_count();
    let pixels = u64::from(scene.camera.width()) * u64::from(scene.camera.height());
    let image = image(&output, normalisation(choice, scene.lights.power(), pixels));
    Ok(InMemoryRender { output, image, integrator: choice })
}

/// What [`render_scene`] decided before building the estimator.
struct Setup<'a> {
    choice: IntegratorChoice,
    reason: &'a str,
    effects: Effects,
    plan: RenderPlan,
    name: &'a str,
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
    let Setup { choice, reason, effects, plan, name } = *setup;
    let name = name.to_owned();
    warnings.extend(integrator_warnings(scene, choice));
    if !scene.sensors.is_empty()
        && scene.settings.sensor_integrator == SensorIntegrator::Path
        && !scene.lights_sampled_from_points()
    {
        warnings.push(
            "settings.sensor_integrator \"path\": lasers, skies and beam-only lights cannot be \
             sampled from a point, so the sensors miss their light; use \"light\" or \"auto\""
                .to_owned(),
        );
    }
    if !scene.sensors.is_empty() && plan.shard.is_some() {
        warnings.push(
            "sensors are written by unsharded renders only (merge-parts writes the image): \
             render without --shard for the sensors' files"
                .to_owned(),
        );
    }
    // The light tracer's probe checks that light can reach the camera (for camera integrators a
    // black image is reported after the render).
    let probed = probe_with(scene, &plan, tracer)?;
    if options.verbose && !probed.lit {
        eprintln!(
            "note: the pre-render probe ran out of time after {} paths without seeing light reach \
             the camera; rendering anyway",
            probed.beams
        );
    }
    let bar = progress_bar(&plan, options.verbose);
    let started = Instant::now();
    let target = plan.shard_target_error();
    let update = |p: &spectrace_tracer::Progress| {
        bar.set_position(p.items.min(bar.length().unwrap_or(u64::MAX)));
        if let Some(e) = &p.estimate {
            bar.set_message(progress_message(e, target, p.seconds));
        }
    };
    let output =
        render_observed(tracer, &plan, &update).map_err(|e| RenderError::Options(e.to_string()))?;
    let pixels = u64::from(scene.camera.width()) * u64::from(scene.camera.height());
    let numerator = normalisation(choice, scene.lights.power(), pixels);
    bar.finish_and_clear();
    let wall = started.elapsed().as_secs_f64();
    let make_report = |output: &RenderOutput, mut written: Written| {
        written.warnings.append(&mut warnings.clone());
        let mut r = report(
            scene.path.display().to_string(),
            (scene.camera.width(), scene.camera.height()),
            plan,
            effects,
            tracer.name(),
            output,
            wall,
            scene.lights.power(),
            written,
        );
        r.integrator_reason = reason.to_owned();
        r.sampler = scene.settings.sampler.name().to_owned();
        r
    };
    if let Some((k, n)) = plan.shard {
        let path = options.out_dir.join(format!("{name}.part-{k}-of-{n}.bin"));
        let shard_report = make_report(
            &output,
            Written { files: vec![path.display().to_string()], ..Written::default() },
        );
        // The film moves into the part (no copy of what may be 1.5 GiB).
        let part = PartialFilm {
            version: PARTIAL_VERSION,
            scene_fingerprint: scene.fingerprint(),
            scene_path: scene.path.display().to_string(),
            plan: RenderPlan { shard: None, threads: 0, ..plan },
            light_power: scene.lights.power(),
            integrator: choice,
            sampler: scene.settings.sampler,
            effects,
            output_settings: scene.output.clone(),
            name: name.clone(),
            output,
        };
        let bytes =
            part.encode().map_err(|message| RenderError::File { path: path.clone(), message })?;
        drop(part);
        write_atomically(&path, |p| std::fs::write(p, &bytes).map_err(|e| e.to_string()))
            .map_err(|message| RenderError::File { path: path.clone(), message })?;
        return Ok(shard_report);
    }
    let mut written = write_outputs(&options.out_dir, &name, &scene.output, numerator, &output)?;
    if !probed.lit && output.film.accepted() == 0 {
        written.warnings.push(format!(
            "no light reached the camera: the image is black (the pre-render probe ran out of \
             time after {} paths, and none of the {} paths rendered lit a point the camera sees)",
            probed.beams, output.beams
        ));
    }
    let sensors = if scene.sensors.is_empty() {
        Vec::new()
    } else if tracer.sensor_cells() > 0 {
        let source = SensorSource {
            film: &output.film,
            beams: output.beams,
            seconds: output.seconds,
            filled_by: "image beams (light tracer)",
        };
        write_sensors(scene, &options.out_dir, source)?
    } else if sensor_integrator(scene) == SensorIntegrator::Light {
        let (film, beams, seconds) =
            sensor_pass(scene, &sensor_plan(scene, plan.threads), effects)?;
        let source =
            SensorSource { film: &film, beams, seconds, filled_by: "sensor pass (light tracer)" };
        write_sensors(scene, &options.out_dir, source)?
    } else {
        let passes = scene.settings.sensor_spp.unwrap_or(DEFAULT_SENSOR_SPP);
        let (film, beams, seconds) = sensor_pass_path(scene, passes, plan.threads, effects)?;
        let source = SensorSource {
            film: &film,
            beams,
            seconds,
            filled_by: "points sampled on the sensor (path tracer)",
        };
        write_sensors(scene, &options.out_dir, source)?
    };
    for r in &sensors {
        written.files.extend(r.files.iter().cloned());
        if options.verbose {
            eprintln!("{}", sensor_summary(r));
        }
    }
    let mut report = make_report(&output, written);
    report.sensors = sensors;
    write_sidecar(&options.out_dir, &name, &report)?;
    Ok(report)
}
