//! How a scene is rendered: the estimator, the effects decision, the plan after overrides, and
//! the normalisation that turns the film into the image.

use spectrace_lights::LightSource;
use spectrace_spectrum::Xyz;
use spectrace_tracer::{
    Effects, EffectsMode, IntegratorChoice, RenderOutput, RenderPlan, camera_image, image_scale,
};

use crate::integrators::is_camera_integrator;
use crate::{RenderError, RenderOptions, Scene};

/// Most worker threads a render accepts.
pub const MAX_THREADS: usize = 256;

/// The estimator for a scene (with an optional override) and the reason, in words.
pub fn choose_integrator(
    scene: &Scene,
    choice: Option<IntegratorChoice>,
) -> (IntegratorChoice, String) {
    choice.unwrap_or(scene.settings.integrator).decide(&scene.features())
}

/// What turns a film's exact sums into the image: `light_power * factor / items`, where the
/// items are the work items done (see [`normalisation`]), or for a camera render with passes
/// cut short by a time budget, each pixel over its own sample count
/// ([`Normalisation::image`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Normalisation {
    /// Total power of the lights (W): every integrator's film holds sums relative to it, so
    /// that lights of any power keep the film's fixed point in range.
    pub light_power: f64,
    /// 1 for the light tracer (items are beams, each carrying `light_power / beams`); the pixel
    /// count for camera integrators (items are camera samples: the image is the mean per pixel).
    pub factor: f64,
    /// A camera integrator's render (its chunks are passes over the pixels).
    pub camera: bool,
}

impl Normalisation {
    /// The factor for `items` work items (0 for none; may overflow to infinity, which
    /// [`encode_image`](crate::encode_image) handles).
    pub fn scale(&self, items: u64) -> f64 {
        image_scale(self.light_power, items) * self.factor
    }

    /// The image of a render's output, XYZ per pixel: the film times [`Normalisation::scale`]
    /// of the items done, or for a camera render [`spectrace_tracer::camera_image`] (the same
    /// when every pass is whole; each pixel over its own sample count when a pass was cut).
    pub fn image(&self, output: &RenderOutput) -> Vec<Xyz> {
        if self.camera {
            camera_image(output, self.light_power, self.factor as u64)
        } else {
            output.film.to_xyz(self.scale(output.beams))
        }
    }
}

/// The normalisation of a render by `integrator` of an image of `pixels` pixels.
pub fn normalisation(integrator: IntegratorChoice, light_power: f64, pixels: u64) -> Normalisation {
    let camera = is_camera_integrator(integrator);
    let factor = if camera { pixels as f64 } else { 1.0 };
    Normalisation { light_power, factor, camera }
}

/// The normalisation of a render of `scene` by `choice`.
pub(crate) fn scene_normalisation(scene: &Scene, choice: IntegratorChoice) -> Normalisation {
    let pixels = u64::from(scene.camera.width()) * u64::from(scene.camera.height());
    normalisation(choice, scene.lights.power(), pixels)
}

/// The effects decision for a scene (with an optional override).
pub fn decide_effects(scene: &Scene, mode: Option<EffectsMode>) -> Effects {
    Effects::decide(scene.features(), mode.unwrap_or(scene.effects.mode))
}

/// The plan after command-line overrides.
///
/// # Errors
/// [`RenderError::Options`] for zero beams, a non-positive time, or an invalid shard.
pub fn plan_for(scene: &Scene, options: &RenderOptions) -> Result<RenderPlan, RenderError> {
    let (integrator, _) = choose_integrator(scene, options.integrator);
    plan_with(scene, options, integrator)
}

/// The plan for a given estimator. The light tracer's work items are beams (`--beams`,
/// `settings.beams`, in chunks of `settings.chunk_beams`). A camera integrator's are camera
/// samples in passes of one sample per pixel (a chunk is a pass): `--spp` / `settings.spp`
/// passes, or with only `--beams N` given, exactly `N` samples: `N / pixels` whole passes and,
/// for the remainder, the first pixels of one more pass in its scrambled order (each pixel is
/// normalised by its own count), so that a budget smaller than a pass is kept rather than
/// rounded up to a whole pass.
///
/// # Errors
/// As [`plan_for`].
pub fn plan_with(
    scene: &Scene,
    options: &RenderOptions,
    integrator: IntegratorChoice,
) -> Result<RenderPlan, RenderError> {
    let mut plan = plan_light(scene, options)?;
    if is_camera_integrator(integrator) {
        let pixels = u64::from(scene.camera.width()) * u64::from(scene.camera.height());
        let pixels = pixels.max(1);
        let spp = match (options.spp, options.beams) {
            (Some(0), _) => {
                return Err(RenderError::Options("--spp must be at least 1".to_owned()));
            }
            (Some(n), _) => n,
            (None, Some(beams)) => beams.div_ceil(pixels),
            (None, None) => scene.settings.spp,
        };
        plan.chunk_beams = pixels;
        let open_ended = options.time.is_some() || plan.target_error.is_some();
        plan.beams = if open_ended && options.spp.is_none() && options.beams.is_none() {
            (u64::MAX / 2 / pixels) * pixels
        } else if let (None, Some(beams)) = (options.spp, options.beams) {
            beams
        } else {
            spp.checked_mul(pixels).ok_or_else(|| {
                RenderError::Options(format!(
                    "settings.spp / --spp = {spp}: {spp} samples of {pixels} pixels overflow"
                ))
            })?
        };
    }
    Ok(plan)
}

/// The light tracer's plan after overrides.
fn plan_light(scene: &Scene, options: &RenderOptions) -> Result<RenderPlan, RenderError> {
    let mut plan = scene.plan();
    if let Some(b) = options.beams {
        plan.beams = b;
        plan.time_budget = None;
    }
    if let Some(t) = options.time {
        if !(t > 0.0 && t.is_finite()) {
            return Err(RenderError::Options(format!(
                "--time {t}: must be a positive number of seconds"
            )));
        }
        plan.time_budget = Some(t);
        if options.beams.is_none() {
            plan.beams = u64::MAX / 2;
        }
    }
    if let Some(m) = options.error_measure {
        plan.error_measure = m;
    }
    if let Some(e) = options.target_error {
        crate::check_target_error(e)
            .map_err(|m| RenderError::Options(format!("--target-error {m}")))?;
        plan.target_error = Some(e);
    }
    if plan.target_error.is_some() {
        // The target decides how much to render; --beams caps it.
        plan.error_estimate = true;
        if options.beams.is_none() {
            plan.beams = u64::MAX / 2;
        }
    }
    if plan.beams == 0 {
        return Err(RenderError::Options("--beams must be at least 1".to_owned()));
    }
    if let Some(s) = options.seed {
        plan.seed = s;
    }
    if let Some(t) = options.threads {
        plan.threads = t;
    }
    if plan.threads > MAX_THREADS {
        return Err(RenderError::Options(format!(
            "settings.threads / --threads = {}: at most {MAX_THREADS}",
            plan.threads
        )));
    }
    if plan.threads == 0 {
        plan.threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    }
    if let Some((k, n)) = options.shard {
        if n == 0 || k >= n {
            return Err(RenderError::Options(format!("--shard {k}/{n}: need 0 <= K < N")));
        }
        plan.shard = Some((k, n));
    }
    Ok(plan)
}
