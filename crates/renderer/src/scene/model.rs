//! The typed scene both front ends produce (the JSON reader and the Mitsuba importer): its
//! objects, lights, camera, settings, effects, outputs and sensors, and the checks the types
//! alone do not make.

use std::path::Path;

use serde::{Deserialize, Serialize};
use spectrace_geometry::{Shape, Transform};
use spectrace_lights::LightSource;
use spectrace_materials::Material;
use spectrace_tracer::IrradianceSensor;
use spectrace_tracer::{
    BdptWavelengths, CameraWavelengths, DEFAULT_CHUNK_BEAMS, EffectsMode, EnvironmentMap,
    ErrorMeasure, IntegratorChoice, Kernel, LightSamplerKind, MAX_DEPTH, ObjectEmission, Observer,
    PinholeCamera, SamplerKind,
};

use super::{SceneError, scene_error};
use crate::files::check_output_name;

/// A scene file, as written (see `scenes/README.md` for every field).
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// The camera.
    pub camera: PinholeCamera,
    /// The objects: a shape and its material each.
    pub objects: Vec<Object>,
    /// The light sources (any `LightSource` type, including third-party ones); may be empty
    /// (or left out) when objects glow.
    #[serde(default)]
    pub lights: Vec<Box<dyn LightSource>>,
    /// Light from every direction at infinite distance, read from a latitude-longitude image
    /// (`spectrace_tracer::Environment`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<EnvironmentMap>,
    /// How much to render and how.
    #[serde(default)]
    pub settings: Settings,
    /// The effects analysis (see the tracer's `effects` module).
    #[serde(default)]
    pub effects: EffectsSettings,
    /// What to write.
    #[serde(default)]
    pub output: OutputSettings,
    /// Illuminance sensors beside the camera (`{"type": "IrradianceSensor", ...}`).
    #[serde(default)]
    pub sensors: Vec<IrradianceSensor>,
    /// Eye positions with a line of sight (`spectrace_tracer::Observer`): vertical, cylindrical
    /// and semi-cylindrical illuminance, melanopic EDI and the unified glare rating there.
    #[serde(default)]
    pub observers: Vec<Observer>,
}

/// One object: a shape and what its surface does.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Object {
    /// A name for messages (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The shape (`{"type": "Sphere", ...}`).
    pub shape: Shape,
    /// The material (`{"type": "Diffuse", ...}`).
    pub material: Box<dyn Material>,
    /// Makes the object glow: a Lambertian emitter over its whole surface
    /// (`{"power": W, "spd": {...}, "two_sided": false}`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<ObjectEmission>,
    /// An optional transform of the whole object, applied after the shape's own `transform`
    /// (same forms: `{"matrix": [...]}` row-major, or `translate`/`rotate`/`scale`).
    #[serde(default, skip_serializing)]
    pub transform: Option<Transform>,
}

/// Which effort settings a scene file gives itself, rather than leaving them at their defaults.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SettingsGiven {
    /// `settings.beams`.
    pub beams: bool,
    /// `settings.spp`.
    pub spp: bool,
}

impl SettingsGiven {
    /// What the scene file's JSON gives.
    pub(super) fn of(value: &serde_json::Value) -> Self {
        let given = |key: &str| value.get("settings").and_then(|s| s.get(key)).is_some();
        Self { beams: given("beams"), spp: given("spp") }
    }
}

/// Render settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Settings {
    /// Beams for the whole image (the upper limit when `time_seconds` is set).
    pub beams: u64,
    /// Optional time budget (s): stop starting new work after this long.
    pub time_seconds: Option<f64>,
    /// Seed of every random stream.
    pub seed: u64,
    /// Worker threads; 0 means one per available core.
    pub threads: usize,
    /// Most bounces per beam.
    pub max_depth: u32,
    /// Bounces after which Russian roulette applies.
    pub rr_depth: u32,
    /// Beams per work chunk (the unit of random streams and of sharding).
    pub chunk_beams: u64,
    /// Beams of a light-tracer sensor pass (default: `beams`).
    pub sensor_beams: Option<u64>,
    /// Samples per sensor cell of a path-tracer sensor pass (default 64).
    pub sensor_spp: Option<u64>,
    /// Samples per quantity of each observer (default [`DEFAULT_OBSERVER_SPP`]).
    pub observer_spp: Option<u64>,
    /// Run the sensor pass until every cell at or above `sensor_floor_lux` has a relative
    /// standard error of at most this (e.g. `0.01`), instead of `sensor_spp` / `sensor_beams`.
    pub sensor_target_error: Option<f64>,
    /// The illuminance (lux) below which `sensor_target_error` does not look at a cell
    /// (default 1 lx).
    pub sensor_floor_lux: f64,
    /// How sensors are filled when the image is rendered by a camera integrator: `"auto"` (the
    /// default: `"path"` when every light can be sampled from a point, else `"light"`), `"path"`
    /// (the path tracer samples points on the sensors, `sensor_spp` per cell) or `"light"` (a
    /// light-tracer pass of `sensor_beams`). The light tracer always fills them with the
    /// image's own beams.
    pub sensor_integrator: SensorIntegrator,
    /// The estimator: `"auto"` (the effects analysis chooses), `"light"`, `"path"` or `"bdpt"`.
    pub integrator: IntegratorChoice,
    /// Camera samples per pixel for the camera integrators (`path`, `bdpt`); the upper limit
    /// when `time_seconds` is set.
    pub spp: u64,
    /// How the path tracer's camera paths, and BDPT's hero wavelengths, draw their
    /// wavelengths: `"visible"` (in proportion to the observer's sensitivity, the default) or
    /// `"uniform"` (360-830 nm).
    pub camera_wavelengths: CameraWavelengths,
    /// How many wavelengths a BDPT sample carries: `"hero"` (the default: four, drawn like
    /// the path tracer's and shared by both subpaths, wherever nothing disperses or fluoresces
    /// and no light has spectral lines; the beam's one elsewhere) or `"beam"` (always the
    /// beam's one wavelength, drawn from the lights' spectrum).
    pub bdpt_wavelengths: BdptWavelengths,
    /// Where every integrator's random numbers come from: `"auto"` (the default: Sobol points
    /// for the camera estimators unless a target error stops the render, independent streams
    /// otherwise; see [`spectrace_tracer::SamplerKind::resolve`]), `"independent"` (each
    /// chunk's own stream) or `"sobol"` (Owen-scrambled Sobol points, see
    /// [`spectrace_tracer::ChunkSampler`]).
    pub sampler: SamplerKind,
    /// Render until the estimated relative error of the image (in `error_measure`) is at most
    /// this (e.g. `0.05`), instead of a fixed number of beams or samples; `time_seconds` caps
    /// it.
    pub target_error: Option<f64>,
    /// What "relative error" means for the estimate's headline and the target: `"relmse"`
    /// (the default: per-pixel relative error), `"energy"` or `"mean"` (see
    /// [`spectrace_tracer::ErrorMeasure`]).
    pub error_measure: ErrorMeasure,
    /// Which kernel traces the path tracer's camera paths: `"scalar"` (one path at a time, the
    /// reference and the default) or `"batched"` (many paths stage by stage); the image is the
    /// same, bit for bit.
    pub kernel: Kernel,
    /// How next-event estimation (the path tracer's and the path-traced sensor and observer
    /// passes') chooses the lights it samples at a vertex: `"auto"` (the default: `"each"` up
    /// to 16 such lights, `"tree"` beyond), `"each"`, `"power"` or `"tree"` (see
    /// [`spectrace_tracer::LightSamplerKind`]).
    pub light_sampler: LightSamplerKind,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            beams: 1_000_000,
            time_seconds: None,
            seed: 1,
            threads: 0,
            max_depth: 64,
            rr_depth: 4,
            chunk_beams: DEFAULT_CHUNK_BEAMS,
            sensor_beams: None,
            sensor_spp: None,
            observer_spp: None,
            sensor_target_error: None,
            sensor_floor_lux: DEFAULT_SENSOR_FLOOR_LUX,
            sensor_integrator: SensorIntegrator::Auto,
            integrator: IntegratorChoice::Auto,
            spp: DEFAULT_SPP,
            camera_wavelengths: CameraWavelengths::Visible,
            bdpt_wavelengths: BdptWavelengths::Hero,
            sampler: SamplerKind::Auto,
            target_error: None,
            error_measure: ErrorMeasure::RelMse,
            kernel: Kernel::Scalar,
            light_sampler: LightSamplerKind::Auto,
        }
    }
}

/// How sensors are filled beside a camera integrator's image (`settings.sensor_integrator`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SensorIntegrator {
    /// `Path` when every light can be sampled from a point (no laser, sky or beam-only light),
    /// else `Light`.
    #[default]
    Auto,
    /// The path tracer sampling points on the sensors.
    Path,
    /// A light-tracer pass.
    Light,
}

/// Samples per sensor cell of a path-tracer sensor pass when a scene does not say.
pub const DEFAULT_SENSOR_SPP: u64 = 64;

/// Samples per quantity of an observer when `settings.observer_spp` is not given: observers
/// are few points, so their figures can afford about 1% noise.
pub const DEFAULT_OBSERVER_SPP: u64 = 16_384;

/// Camera samples per pixel when a scene does not say (`settings.spp`).
pub const DEFAULT_SPP: u64 = 64;

/// `settings.sensor_floor_lux` by default: cells below 1 lx do not hold up a sensor target.
pub const DEFAULT_SENSOR_FLOOR_LUX: f64 = 1.0;

/// The effects analysis' setting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EffectsSettings {
    /// `"auto"` (decide from the scene), `"off"` (simulate everything the general way) or
    /// `"direct_only"` (end beams at their first non-specular hit: a quick preview).
    pub mode: EffectsMode,
}

/// Output settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OutputSettings {
    /// Base name of the files (default: the scene file's name without extension).
    pub name: Option<String>,
    /// Exposure of the PNG in stops (the PNG shows `linear * 2^exposure`); the EXR is unscaled.
    pub exposure: f64,
    /// Write the sRGB PNG.
    pub png: bool,
    /// Write the linear EXR.
    pub exr: bool,
    /// Write `NAME.error.exr`: `true` or `"absolute"` for the standard error of every pixel of
    /// the image, per linear sRGB channel, in the image's units; `"relative"` for it over the
    /// pixel's value; `false` (the default) for none.
    pub error_image: ErrorImage,
}

impl Default for OutputSettings {
    fn default() -> Self {
        Self { name: None, exposure: 0.0, png: true, exr: true, error_image: ErrorImage::Off }
    }
}

/// What `NAME.error.exr` holds (`output.error_image`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ErrorImage {
    /// No error image (`false`).
    #[default]
    Off,
    /// Each pixel's standard error in the image's units (`true` or `"absolute"`).
    Absolute,
    /// Each pixel's standard error over its value, `se / max(|value|, eps)` per channel, `eps`
    /// 1% of the image's mean level (`"relative"`).
    Relative,
}

impl ErrorImage {
    /// Its name in scene files (`"off"`, `"absolute"`, `"relative"`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Off => "off",
            Self::Absolute => "absolute",
            Self::Relative => "relative",
        }
    }

    /// `true` unless [`ErrorImage::Off`].
    pub fn wanted(self) -> bool {
        self != Self::Off
    }
}

impl Serialize for ErrorImage {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        // JSON keeps the documented `false` / `true` / `"relative"`; binary formats a name.
        match (serializer.is_human_readable(), self) {
            (true, Self::Off) => serializer.serialize_bool(false),
            (true, Self::Absolute) => serializer.serialize_bool(true),
            _ => serializer.serialize_str(self.name()),
        }
    }
}

impl<'de> Deserialize<'de> for ErrorImage {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = ErrorImage;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("true, false, \"absolute\" or \"relative\"")
            }
            fn visit_bool<E: serde::de::Error>(self, v: bool) -> Result<ErrorImage, E> {
                Ok(if v { ErrorImage::Absolute } else { ErrorImage::Off })
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<ErrorImage, E> {
                match v {
                    "off" => Ok(ErrorImage::Off),
                    "absolute" => Ok(ErrorImage::Absolute),
                    "relative" => Ok(ErrorImage::Relative),
                    _ => Err(E::invalid_value(serde::de::Unexpected::Str(v), &self)),
                }
            }
        }
        if deserializer.is_human_readable() {
            deserializer.deserialize_any(Visitor)
        } else {
            deserializer.deserialize_str(Visitor)
        }
    }
}

/// Checks what the types alone do not: some objects, and settings and output settings in range.
pub(super) fn check_settings(file: &SceneFile, path: &Path) -> Result<(), SceneError> {
    let error = |field: &str, message: String| scene_error(path, field, message);
    if file.objects.is_empty() {
        return Err(error(
            "objects",
            "the scene has no objects: nothing can reflect light to the camera".to_owned(),
        ));
    }
    let s = &file.settings;
    if s.beams == 0 {
        return Err(error("settings.beams", "must be at least 1".to_owned()));
    }
    if s.max_depth > MAX_DEPTH {
        return Err(error(
            "settings.max_depth",
            format!(
                "{}: at most {MAX_DEPTH} bounces (longer paths carry no measurable light, \
                 and one beam could outlast a time budget)",
                s.max_depth
            ),
        ));
    }
    if s.spp == 0 {
        return Err(error("settings.spp", "must be at least 1".to_owned()));
    }
    if s.sensor_spp == Some(0) {
        return Err(error("settings.sensor_spp", "must be at least 1".to_owned()));
    }
    if s.observer_spp == Some(0) {
        return Err(error("settings.observer_spp", "must be at least 1".to_owned()));
    }
    if s.sensor_beams == Some(0) {
        return Err(error("settings.sensor_beams", "must be at least 1".to_owned()));
    }
    if let Some(e) = s.sensor_target_error {
        check_target_error(e).map_err(|m| error("settings.sensor_target_error", m))?;
    }
    if !(s.sensor_floor_lux >= 0.0 && s.sensor_floor_lux.is_finite()) {
        return Err(error(
            "settings.sensor_floor_lux",
            format!("{}: must be a finite illuminance of at least 0 lx", s.sensor_floor_lux),
        ));
    }
    if s.chunk_beams == 0 {
        return Err(error("settings.chunk_beams", "must be at least 1".to_owned()));
    }
    if let Some(t) = s.time_seconds
        && !(t > 0.0 && t.is_finite())
    {
        return Err(error(
            "settings.time_seconds",
            format!("{t}: must be a positive number of seconds"),
        ));
    }
    if let Some(e) = s.target_error {
        check_target_error(e).map_err(|m| error("settings.target_error", m))?;
    }
    if let Some(name) = &file.output.name {
        check_output_name(name).map_err(|e| error("output.name", e))?;
    }
    if !file.output.exposure.is_finite() {
        return Err(error("output.exposure", "must be finite".to_owned()));
    }
    Ok(())
}

/// Checks a target relative error (`settings.target_error`, `--target-error`): a number in
/// (0, 1), i.e. above 0% and below 100%.
///
/// # Errors
/// Why it is not.
pub fn check_target_error(e: f64) -> Result<(), String> {
    if e > 0.0 && e < 1.0 {
        Ok(())
    } else {
        Err(format!(
            "{e}: must be a relative error between 0 and 1 (0.05 is 5%); 1 or more is no accuracy \
             at all"
        ))
    }
}
