//! The estimators and the interface the render loop drives: [`Integrator`], and the registry
//! of estimators ([`INTEGRATORS`], [`build_integrator`]).
//!
//! Each estimator is one module here, built from the shared steps of `common` (connections,
//! shadow rays, light samples, the fluorescence choice, Russian roulette, the random numbers of
//! a vertex) and, for the camera estimators, the pass loop of `pass`. A new estimator is one
//! module and one line of [`INTEGRATORS`] (and its name in [`IntegratorChoice`]).
//!
//! [`crate::render`] knows chunks, threads, shards, the time budget, the shared exact film and
//! the memory check, but not which estimator runs. An integrator supplies the rest:
//! - [`Integrator::render_chunk`]: the unit of work, `samples` work items of chunk `chunk`
//!   (light paths for the light tracer; camera samples for the path tracer and BDPT, whose
//!   samples each trace a light path too), drawn from the chunk's own random stream (`sampler::chunk_rng(seed, chunk)`) and
//!   splatted into the film through [`Splat`];
//! - [`Integrator::image_scale`]: the normalisation, the factor that turns the film's exact sums
//!   into the image once `samples_done` work items have been done (for the light tracer, the
//!   lights' power over the beams, [`crate::image_scale`]).
//!
//! # Film and normalisation
//! The film holds exact, unscaled fixed-point sums; the integrator owns the scale, applied once
//! when the image is made. This is what keeps images bit-identical for any thread count and
//! shard split: a chunk's contributions do not depend on how many items the whole render does.
//!
//! Pixel samples and light splats (pbrt's `AddSample` and `AddSplat`) share this one film with
//! their own normalisations: camera estimators work in *passes* (a chunk is one sample of every
//! pixel), so while every pass is whole a pixel sample's normalisation `1 / passes` is the same
//! for every pixel, and BDPT divides its light splats (`t = 1`) by the pixel count, the light
//! paths of a pass, so that `image = film x power x pixels / samples` holds for both. The light
//! tracer's `image = film x power / beams` is the same formula with the factor 1. A time budget
//! may cut a pass short; the per-pass splats then go to a layer of their own
//! ([`crate::Film::with_pass_layer`], [`Integrator::pass_splats`]) and each pixel is divided by
//! its own sample count ([`Integrator::image`], [`crate::camera_image`]).

use std::time::Instant;

use crate::{
    Bdpt, BdptSettings, Effects, IntegratorChoice, LightTracer, LightTracerScene,
    LightTracerSettings, PathTracer, PathTracerSettings, Splat, TraceStats,
};

pub(crate) mod bdpt;
pub(crate) mod common;
pub(crate) mod light_tracer;
pub(crate) mod observer;
pub(crate) mod pass;
pub(crate) mod path_tracer;
pub(crate) mod sensor_path;

/// Which work items a chunk renders: `items` items of chunk `chunk` of a render with seed
/// `seed`, stopping early (where the estimator can) once `deadline` has passed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChunkWork {
    /// The render's seed.
    pub seed: u64,
    /// The chunk.
    pub chunk: u64,
    /// Work items to render.
    pub items: u64,
    /// When to stop early (checked between items).
    pub deadline: Option<Instant>,
    /// For an estimator whose chunks are passes: whether the pass's once-per-pass work follows
    /// the items done, weighted by the share of the pass they are (a planned pass, whole, cut
    /// by a time budget or ended by the render's budget of samples); `false` for the probe's
    /// single items. Ignored by estimators whose chunks are not passes.
    pub ends_pass: bool,
}

/// An estimator the render loop drives: it renders chunks of work items into a film and says
/// how to normalise the film's sums.
pub trait Integrator: Send + Sync {
    /// A short name for reports: `"light"`, `"path"` or `"bdpt"`.
    fn name(&self) -> &'static str;

    /// The film's size in pixels (width, height): the camera's resolution.
    fn resolution(&self) -> (u32, u32);

    /// Renders `work.items` work items of chunk `work.chunk` of a render with seed `work.seed`
    /// into `film`, drawing every random number from the chunk's own stream, so that the result
    /// depends only on `(seed, chunk, items)`. With a `work.deadline`, may stop early once it
    /// has passed (checking the clock every few microseconds of work, between items, after at
    /// least one item; a camera estimator's cut pass is a prefix of the pass's item order). The
    /// returned `stats.beams` is the number of items done, which the normalisation must use.
    fn render_chunk(&self, work: ChunkWork, film: &mut dyn Splat) -> TraceStats;

    /// The factor that turns the film's exact sums into the image after `samples_done` work
    /// items over the whole render (all chunks, all shards); 0 for none. For a camera
    /// estimator, the factor when every pass is whole ([`Integrator::image`] handles cut ones).
    fn image_scale(&self, samples_done: u64) -> f64;

    /// `true` if chunks splat contributions normalised per pass ([`Splat::splat_pass`]): a
    /// render whose chunks may be cut short then gives the film a pass layer
    /// ([`crate::Film::with_pass_layer`]). `false` by default.
    fn pass_splats(&self) -> bool {
        false
    }

    /// `true` if a chunk is a pass over the image's pixels (the camera estimators): a chunk
    /// that does fewer items than a whole pass, whether a time budget cut it or the render's
    /// budget of samples ends inside it, is then a cut pass, normalised pixel by pixel. `false`
    /// by default (a light tracer's short last chunk is simply fewer beams).
    fn chunks_are_passes(&self) -> bool {
        false
    }

    /// The image (XYZ per pixel, row-major) of a render's output: by default the film times
    /// [`image_scale`](Self::image_scale) of the items done; camera estimators normalise each
    /// pixel by its own sample count ([`crate::camera_image`]).
    fn image(&self, output: &crate::RenderOutput) -> Vec<spectrace_spectrum::Xyz> {
        output.film.to_xyz(self.image_scale(output.beams))
    }

    /// Sensor cells this integrator fills after the film's pixels (see
    /// [`crate::Film::with_sensor_cells`]); 0 (the default) when it fills none. Their sums
    /// are normalised by the same [`image_scale`](Self::image_scale).
    fn sensor_cells(&self) -> u32 {
        0
    }
}

/// The settings of every estimator, as a scene file gives them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct IntegratorSettings {
    /// The light tracer's.
    pub light: LightTracerSettings,
    /// The path tracer's.
    pub path: PathTracerSettings,
    /// BDPT's.
    pub bdpt: BdptSettings,
}

/// An estimator the renderer can build by name.
#[derive(Debug, Clone, Copy)]
pub struct RegisteredIntegrator {
    /// Its choice (scene files' `settings.integrator`, the command line's `--integrator`).
    pub choice: IntegratorChoice,
    /// Whether it works in passes over the image (a camera estimator: its image scale
    /// multiplies by the pixel count) rather than in beams.
    pub camera_passes: bool,
    /// Builds it for a scene.
    pub build: for<'a> fn(
        &'a LightTracerScene<'a>,
        &IntegratorSettings,
        Effects,
    ) -> Box<dyn Integrator + 'a>,
}

/// Every estimator, in the order reports list them.
pub const INTEGRATORS: [RegisteredIntegrator; 3] = [
    RegisteredIntegrator {
        choice: IntegratorChoice::Light,
        camera_passes: false,
        build: |scene, settings, effects| {
            Box::new(LightTracer::new(scene, settings.light, effects))
        },
    },
    RegisteredIntegrator {
        choice: IntegratorChoice::Path,
        camera_passes: true,
        build: |scene, settings, effects| Box::new(PathTracer::new(scene, settings.path, effects)),
    },
    RegisteredIntegrator {
        choice: IntegratorChoice::Bdpt,
        camera_passes: true,
        build: |scene, settings, effects| Box::new(Bdpt::new(scene, settings.bdpt, effects)),
    },
];

/// The registry entry of `choice` (`Auto` resolves to the light tracer, which every scene can
/// use: callers decide `Auto` first with [`IntegratorChoice::decide`]).
pub fn registered(choice: IntegratorChoice) -> &'static RegisteredIntegrator {
    INTEGRATORS.iter().find(|r| r.choice == choice).unwrap_or(&INTEGRATORS[0])
}

/// Builds the estimator `choice` for `scene` with `settings`, following `effects`.
pub fn build_integrator<'a>(
    choice: IntegratorChoice,
    scene: &'a LightTracerScene<'a>,
    settings: &IntegratorSettings,
    effects: Effects,
) -> Box<dyn Integrator + 'a> {
    (registered(choice).build)(scene, settings, effects)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use std::sync::Arc;

    use glam::DVec3;
    use spectrace_geometry::{Rectangle, Shape, World};
    use spectrace_lights::{LightSet, LightSource};
    use spectrace_materials::Material;

    use super::*;
    use crate::{CameraRepr, EffectsMode, FovAxis, PinholeCamera};

    #[test]
    fn every_registered_estimator_is_built_under_its_own_name_and_normalisation() {
        let floor = Rectangle::new(DVec3::new(-1.0, 0.0, -1.0), DVec3::Z * 2.0, DVec3::X * 2.0);
        let world = World::new(vec![Shape::Rectangle(floor.unwrap())]).unwrap();
        let diffuse: Box<dyn Material> =
            serde_json::from_str(r#"{"type": "Diffuse", "reflectance": 0.5}"#).unwrap();
        let materials: Vec<Arc<dyn Material>> = vec![Arc::from(diffuse)];
        let light: Box<dyn LightSource> = serde_json::from_str(
            r#"{"type": "PointLight", "position": [0, 1, 0], "power": 7,
                "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}}"#,
        )
        .unwrap();
        let lights = LightSet::new(vec![light]).unwrap();
        let camera = PinholeCamera::new(CameraRepr {
            position: DVec3::new(0.0, 1.0, 2.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov: 50.0,
            fov_axis: FovAxis::Horizontal,
            width: 8,
            height: 6,
            aperture_radius: 0.0,
            focus_distance: None,
        })
        .unwrap();
        let scene = LightTracerScene::new(&world, &materials, &lights, &camera);
        let effects = Effects::decide(scene.features(&[false]), EffectsMode::Off);
        let settings = IntegratorSettings::default();
        let mut names = Vec::new();
        for r in &INTEGRATORS {
            let built = build_integrator(r.choice, &scene, &settings, effects);
            assert_eq!(built.name(), r.choice.name());
            assert_eq!(IntegratorChoice::from_name(built.name()), Some(r.choice));
            assert_eq!(built.resolution(), (8, 6));
            // Beams: power over beams; passes: power times the pixels over the samples.
            let expected = if r.camera_passes { 7.0 * 48.0 / 96.0 } else { 7.0 / 96.0 };
            assert!(
                (built.image_scale(96) - expected).abs() <= 1e-12 * expected,
                "{}",
                r.choice.name()
            );
            names.push(built.name());
        }
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), INTEGRATORS.len(), "names are unique");
        // `auto` is decided before building; undecided, it is the light tracer.
        assert_eq!(registered(IntegratorChoice::Auto).choice, IntegratorChoice::Light);
    }
}
