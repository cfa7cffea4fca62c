//! The one place the renderer knows its estimators: which there are, how each counts its work,
//! and each built on the tracer's view of a scene, all read from the tracer's registry
//! ([`spectrace_tracer::INTEGRATORS`]). The rest of the renderer lists and builds estimators only
//! through these, and names them by [`IntegratorChoice::name`] and [`Integrator::name`]; only
//! what each cannot render (`warnings`) and the sensor passes' sensor-only tracers (`sensors`)
//! are said elsewhere.

use spectrace_tracer::{
    AUTO_TREE_ABOVE, Bdpt, BdptWavelengths, Effects, HERO, INTEGRATORS, Integrator,
    IntegratorChoice, IntegratorSettings, Kernel, LightSamplerKind, LightTracerScene, SamplerKind,
    SceneFeatures, build_integrator, registered,
};

use crate::Scene;

/// Every estimator a render can use, in the order reports list them (`auto` picks one of them):
/// the tracer's registry.
pub(crate) const ESTIMATORS: [IntegratorChoice; INTEGRATORS.len()] = {
    let mut choices = [IntegratorChoice::Auto; INTEGRATORS.len()];
    let mut i = 0;
    while i < INTEGRATORS.len() {
        choices[i] = INTEGRATORS[i].choice;
        i += 1;
    }
    choices
};

/// Whether `choice`'s work items are camera samples, in passes of one sample per pixel (path
/// tracer, BDPT), rather than beams from the lights (the light tracer, and `auto` before it is
/// decided, which [`with_integrator`] also builds as the light tracer).
pub(crate) fn is_camera_integrator(choice: IntegratorChoice) -> bool {
    registered(choice).camera_passes
}

/// The scene's settings of every estimator.
pub(crate) fn integrator_settings(scene: &Scene) -> IntegratorSettings {
    IntegratorSettings {
        light: scene.tracer_settings(),
        path: scene.path_settings(),
        bdpt: scene.bdpt_settings(),
    }
}

/// The names `--integrator` and `settings.integrator` accept, in words: `auto, light, path or
/// bdpt`.
pub(crate) fn choice_names() -> String {
    let mut names: Vec<&str> = std::iter::once(IntegratorChoice::Auto)
        .chain(ESTIMATORS)
        .map(IntegratorChoice::name)
        .collect();
    let last = names.pop().unwrap_or_default();
    format!("{} or {last}", names.join(", "))
}

/// The tracer's view of a scene.
pub fn tracer_scene(scene: &Scene) -> LightTracerScene<'_> {
    LightTracerScene::new(&scene.world, &scene.materials, &scene.lights, &scene.camera)
        .with_emitters(scene.emitters.clone(), scene.object_shapes)
        .with_sampler(scene.settings.sampler)
        .with_light_sampler(scene.settings.light_sampler)
        .with_sensors(&scene.sensors)
}

/// Runs `f` with the estimator `choice` for `scene`, following `effects`.
pub fn with_integrator<R>(
    scene: &Scene,
    choice: IntegratorChoice,
    effects: Effects,
    f: impl FnOnce(&dyn Integrator) -> R,
) -> R {
    with_kernel(scene, choice, effects, (scene.settings.kernel, false), f)
}

/// As [`with_integrator`], with the path tracer's camera paths traced by `kernel`, and
/// `settings.sampler` resolved knowing whether the error estimate decides the stop
/// ([`sampler_of`]).
pub(crate) fn with_kernel<R>(
    scene: &Scene,
    choice: IntegratorChoice,
    effects: Effects,
    (kernel, error_decides): (Kernel, bool),
    f: impl FnOnce(&dyn Integrator) -> R,
) -> R {
    let sampler = sampler_of(scene.settings.sampler, choice, error_decides, &effects);
    let tracer_scene = tracer_scene(scene).with_sampler(sampler);
    let mut settings = integrator_settings(scene);
    settings.path.kernel = kernel;
    let integrator = build_integrator(choice, &tracer_scene, &settings, effects);
    f(integrator.as_ref())
}

/// The sampler `choice` draws from: `settings.sampler` as set, or for `auto` Sobol points where
/// they pay and the error estimate stays the error itself:
/// - the camera estimators, unless the render's error estimate decides when it stops
///   (`error_decides`: a target error, or a pilot measuring error against time): a pixel's
///   passes are the points of one sequence, so they are not independent batches and the
///   estimate would be the independent sampler's error, an upper bound; a render that stops on
///   it would gain nothing from Sobol points and would report an error it does not have;
/// - the light tracer where the effects analysis stops beams after their first diffuse hit
///   (`effects`), with or without a target: each beam is then a few dimensions (its wavelength,
///   direction and one connection to the camera) that a sequence stratifies over the whole
///   image, and each chunk of beams is its own independently scrambled sequence, so chunks stay
///   independent batches. Measured at equal beams, 8 seeds each (variance across seeds): 0.389x
///   the independent variance on the race's spot_plane at 786,432 beams and 0.688x on
///   `scenes/fading_spot.json` at 1,000,000, for 1.18x and 1.12x the time: 0.46x and 0.77x at
///   equal time. Where beams go on bouncing the accuracy sweep's gain was mixed
///   (`docs/accuracy.md`), so they stay independent.
pub(crate) fn sampler_of(
    setting: SamplerKind,
    choice: IntegratorChoice,
    error_decides: bool,
    effects: &Effects,
) -> SamplerKind {
    let sobol_pays =
        if is_camera_integrator(choice) { !error_decides } else { !effects.continue_after_diffuse };
    setting.resolve(sobol_pays)
}

/// How many wavelengths a BDPT sample carries in a scene with `features` under `setting`,
/// and why: `"hero: ..."` or `"beam: ..."` (the verbose line and the sidecar's
/// `bdpt_wavelengths`).
pub(crate) fn bdpt_wavelengths_text(setting: BdptWavelengths, features: &SceneFeatures) -> String {
    let beam = "beam: one wavelength per sample, the beam's";
    match (setting, Bdpt::hero_possible(features)) {
        (BdptWavelengths::Beam, _) => format!("{beam} (settings.bdpt_wavelengths)"),
        (BdptWavelengths::Hero, Err(why)) => format!("{beam} ({why})"),
        (BdptWavelengths::Hero, Ok(())) => format!(
            "hero: {HERO} wavelengths per sample from the camera's density, shared by both \
             subpaths"
        ),
    }
}

/// The sampler line of a verbose render: the sampler `choice` draws from, and why.
pub(crate) fn sampler_text(
    setting: SamplerKind,
    choice: IntegratorChoice,
    error_decides: bool,
    effects: &Effects,
) -> String {
    let used = sampler_of(setting, choice, error_decides, effects);
    let camera = is_camera_integrator(choice);
    let why = match (setting, used) {
        (SamplerKind::Auto, SamplerKind::Sobol) if camera => {
            "auto: a pixel's passes are the points of one Owen-scrambled Sobol sequence; the \
             error estimate is an upper bound"
        }
        (SamplerKind::Auto, SamplerKind::Sobol) => {
            "auto: beams stop after a diffuse hit, so Owen-scrambled Sobol points stratify them \
             over the image; each chunk is its own sequence, so the error estimate is unchanged"
        }
        (SamplerKind::Auto, _) if camera => {
            "auto: a target error stops this render, and only independent passes estimate the \
             error itself rather than an upper bound"
        }
        (SamplerKind::Auto, _) => {
            "auto: the light tracer's beams go on bouncing, so they stay independent"
        }
        _ => "settings.sampler",
    };
    format!("{} ({why})", used.name())
}

/// How next-event estimation chooses lights in `scene` (`settings.light_sampler` resolved,
/// never `auto`).
pub(crate) fn light_sampler_of(scene: &Scene) -> LightSamplerKind {
    tracer_scene(scene).light_sampler_kind()
}

/// [`light_sampler_of`] with its reason, for `--verbose`.
pub(crate) fn light_sampler_text(scene: &Scene) -> String {
    let used = light_sampler_of(scene);
    let why = match (scene.settings.light_sampler, used) {
        (LightSamplerKind::Auto, LightSamplerKind::Tree) => format!(
            "auto: more than {AUTO_TREE_ABOVE} lights to sample; one per vertex, chosen by a \
             light tree"
        ),
        (LightSamplerKind::Auto, _) => format!(
            "auto: at most {AUTO_TREE_ABOVE} lights to sample; every point, spot and luminaire \
             at every vertex"
        ),
        _ => "settings.light_sampler".to_owned(),
    };
    format!("{} ({why})", used.name())
}

/// The kernel that traces `choice`'s paths given the path tracer's `kernel` setting: only the
/// path tracer has a batched kernel; the others are scalar.
pub(crate) fn kernel_of(choice: IntegratorChoice, kernel: Kernel) -> Kernel {
    if choice == IntegratorChoice::Path { kernel } else { Kernel::Scalar }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_names_in_words_are_every_choice_the_command_line_accepts() {
        assert_eq!(choice_names(), "auto, light, path or bdpt");
        for choice in ESTIMATORS {
            assert_eq!(IntegratorChoice::from_name(choice.name()), Some(choice));
        }
        // Auto is built as the light tracer until it is decided; each estimator's own name is
        // its choice's.
        assert!(!is_camera_integrator(IntegratorChoice::Auto));
        assert!(is_camera_integrator(IntegratorChoice::Path));
        assert!(is_camera_integrator(IntegratorChoice::Bdpt));
        assert!(!is_camera_integrator(IntegratorChoice::Light));
    }
}
