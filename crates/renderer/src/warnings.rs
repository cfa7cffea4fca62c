//! Warnings about a result that is not an error: light the chosen estimator cannot reach,
//! sensors that miss light or are not written, a black image, pixels a time budget left without
//! a sample, contributions the film left out.

use spectrace_tracer::{IntegratorChoice, RenderOutput, RenderPlan, SampleCounts};

use crate::{Normalisation, ProbeOutcome, Scene, SensorIntegrator};

/// What a user should know before a render by `choice` with `plan`: light the estimator cannot
/// reach, and sensors that will miss light or not be written.
pub(crate) fn render_warnings(
    scene: &Scene,
    choice: IntegratorChoice,
    plan: &RenderPlan,
) -> Vec<String> {
    let mut warnings = integrator_warnings(scene, choice);
    if !scene.sensors.is_empty()
        && scene.settings.sensor_integrator == SensorIntegrator::Path
        && !scene.lights_sampled_from_points()
    {
        warnings.push(
            "settings.sensor_integrator \"path\": lasers of zero width and beam-only lights \
             cannot be sampled from a point, so the sensors miss their light; use \"light\" or \
             \"auto\""
                .to_owned(),
        );
    }
    if !scene.observers.is_empty() && !scene.lights_sampled_from_points() {
        warnings.push(
            "observers: lasers of zero width and beam-only lights cannot be sampled from a \
             point, so the observers' figures miss their light"
                .to_owned(),
        );
    }
    warnings.extend(beams_warning(scene, choice, plan));
    if !scene.sensors.is_empty()
        && plan.shard.is_some()
        && scene.settings.sensor_target_error.is_some()
        && choice != IntegratorChoice::Light
    {
        warnings.push(
            "settings.sensor_target_error: a sharded render runs the fixed sensor pass \
             (sensor_spp samples per cell, or sensor_beams) split over its shards, since a pass \
             to a target decides its rounds from the whole pass; render unsharded for the target"
                .to_owned(),
        );
    }
    warnings
}

/// The warning for a scene file that gives `settings.beams` but not `settings.spp` when a
/// camera estimator renders it with a fixed effort from the scene: that effort is
/// `settings.spp` samples per pixel (its default), not the beams asked for.
fn beams_warning(scene: &Scene, choice: IntegratorChoice, plan: &RenderPlan) -> Option<String> {
    let fixed = plan.time_budget.is_none() && plan.target_error.is_none();
    let pixels = u64::from(scene.camera.width()) * u64::from(scene.camera.height());
    let spp = plan.beams / pixels.max(1);
    let asked = scene.settings.beams;
    let camera = crate::integrators::is_camera_integrator(choice);
    let given = scene.settings_given;
    (camera && fixed && given.beams && !given.spp && spp == scene.settings.spp).then(|| {
        format!(
            "settings.beams = {asked} counts the light tracer's beams: {} renders \
                 settings.spp = {spp} samples per pixel ({} paths); set settings.spp, or give \
                 --spp or --beams on the command line (camera estimators turn --beams into \
                 samples per pixel)",
            choice.name(),
            plan.beams
        )
    })
}

/// What a user should know about the chosen estimator: light a camera integrator cannot reach.
pub(crate) fn integrator_warnings(scene: &Scene, choice: IntegratorChoice) -> Vec<String> {
    let mut warnings = Vec::new();
    let features = scene.features();
    if choice == IntegratorChoice::Light && features.specular {
        warnings.push(
            "the light tracer cannot see into mirrors and glass: what they reflect or refract \
             toward the camera is missing from this image (use --integrator bdpt or auto)"
                .to_owned(),
        );
    }
    if choice == IntegratorChoice::Bdpt && features.fluorescent && features.specular {
        warnings.push(
            "BDPT re-emits fluorescent light on light paths only: a fluorescent surface seen \
             only through mirrors or glass is missing from this image (use --integrator path)"
                .to_owned(),
        );
    }
    if choice != IntegratorChoice::Path {
        return warnings;
    }
    if !scene.lights_sampled_from_points() {
        warnings.push(
            "the path tracer cannot reach lasers of zero width or lights that only generate beams: \
             their light is missing from this image (use --integrator light or auto)"
                .to_owned(),
        );
    }
    if features.line_spectra {
        warnings.push(
            "the path tracer draws wavelengths from a density and misses spectral lines: \
             their light is missing from this image (use --integrator light or auto)"
                .to_owned(),
        );
    }
    if features.delta_position_lights + features.delta_direction_lights > 0 && features.specular {
        warnings.push(
            "the path tracer cannot see caustics of point, spot, sky or laser lights (their light \
             through mirrors and glass onto other surfaces is missing; use --integrator light or \
             auto)"
                .to_owned(),
        );
    }
    warnings
}

/// The warning for an image that came out black: a dark result, or after an inconclusive probe.
pub(crate) fn black_image_warning(probed: &ProbeOutcome, output: &RenderOutput) -> Option<String> {
    let black = || {
        output.film.accepted() == 0
            || output.film.to_xyz(1.0).iter().all(|p| p.x == 0.0 && p.y == 0.0 && p.z == 0.0)
    };
    if probed.dark && black() {
        return Some(
            "the camera sees no light: the image is dark, although light reaches the scene (a \
             sensor records it, or it lands on surfaces the camera does not see or that reflect \
             nothing)"
                .to_owned(),
        );
    }
    (!probed.lit && output.film.accepted() == 0).then(|| {
        format!(
            "no light reached the camera: the image is black (the pre-render probe ran out of \
             time after {} paths, and none of the {} paths rendered lit a point the camera sees)",
            probed.beams, output.beams
        )
    })
}

/// The warning for a camera render whose budget (time, or `--beams` fewer than the pixels) ran
/// out inside its first pass, so that some pixels got no camera sample (`None` when every
/// pixel got one, and for the light tracer).
pub(crate) fn unsampled_warning(output: &RenderOutput, norm: Normalisation) -> Option<String> {
    if !norm.camera || output.cut.is_empty() {
        return None;
    }
    let pixels = norm.factor as u64;
    let unsampled = SampleCounts::of(output, pixels).unsampled();
    (unsampled > 0).then(|| {
        format!(
            "{unsampled} of {pixels} pixels ({:.1}%) got no camera sample: the budget ran out \
             inside the first pass over the image (one pass takes longer than --time, or \
             --beams is fewer than the pixels); they show only light joined to the camera from \
             light paths (BDPT), or black. Give more time (--time) or samples (--beams, --spp), \
             or lower the resolution",
            100.0 * unsampled as f64 / pixels.max(1) as f64
        )
    })
}

/// The warning for `n` contributions the film left out.
pub(crate) fn rejected_warning(n: u64) -> String {
    format!(
        "{n} contributions were not finite or beyond the film's range and were left out: \
         the image is darker than it should be where they fell"
    )
}
