//! The one place the renderer knows its estimators: the tracer's view of a scene and each
//! estimator built on it.

use spectrace_tracer::{
    Bdpt, Effects, Integrator, IntegratorChoice, LightTracer, LightTracerScene, PathTracer,
};

use crate::Scene;

/// The tracer's view of a scene.
pub fn tracer_scene(scene: &Scene) -> LightTracerScene<'_> {
    LightTracerScene::new(&scene.world, &scene.materials, &scene.lights, &scene.camera)
        .with_emitters(scene.emitters.clone(), scene.object_shapes)
        .with_sampler(scene.settings.sampler)
        .with_sensors(&scene.sensors)
}

/// Runs `f` with the estimator `choice` for `scene`, following `effects`.
pub fn with_integrator<R>(
    scene: &Scene,
    choice: IntegratorChoice,
    effects: Effects,
    f: impl FnOnce(&dyn Integrator) -> R,
) -> R {
    with_integrator_filling(scene, choice, effects, true, f)
}

/// As [`with_integrator`]; with `sensors` false the light tracer leaves the scene's sensors
/// alone (a shard's part holds the image only).
pub fn with_integrator_filling<R>(
    scene: &Scene,
    choice: IntegratorChoice,
    effects: Effects,
    sensors: bool,
    f: impl FnOnce(&dyn Integrator) -> R,
) -> R {
    let none = spectrace_tracer::SensorSet::default();
    let tracer_scene =
        if sensors { tracer_scene(scene) } else { tracer_scene(scene).with_sensors(&none) };
    match choice {
        IntegratorChoice::Path => {
            f(&PathTracer::new(&tracer_scene, scene.path_settings(), effects))
        }
        IntegratorChoice::Bdpt => f(&Bdpt::new(&tracer_scene, scene.bdpt_settings(), effects)),
        IntegratorChoice::Light | IntegratorChoice::Auto => {
            f(&LightTracer::new(&tracer_scene, scene.tracer_settings(), effects))
        }
    }
}
