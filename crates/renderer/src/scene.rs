//! The scene file: its JSON form, loading with errors that name the file, line, column and field,
//! and assembly into what the tracer needs.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};
use spectrace_geometry::{Disk, Rectangle};
use spectrace_geometry::{Shape, Transform, World};
use spectrace_lights::{LightId, LightSurface};
use spectrace_lights::{LightSet, LightSource};
use spectrace_materials::Diffuse;
use spectrace_materials::Material;
use spectrace_spectrum::Reflectance;
use spectrace_tracer::{
    BdptSettings, BdptWavelengths, CameraWavelengths, DEFAULT_CHUNK_BEAMS, EffectsMode, Emitter,
    ErrorMeasure, IntegratorChoice, Kernel, LightTracerSettings, MAX_DEPTH, ObjectEmission,
    ObjectLight, PathTracerSettings, PinholeCamera, RenderPlan, SamplerKind, SceneFeatures,
};
use spectrace_tracer::{IrradianceSensor, SensorSet};

use crate::files::{MAX_SCENE_BYTES, check_output_name, read_bounded};
use spectrace_sampling::files::{check_inside, with_scene_folder};

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
    fn of(value: &serde_json::Value) -> Self {
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

/// Why a scene could not be loaded. Every message starts with `file:line:column:` where the file
/// has a position, and names the field (`objects[3].material.ior`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The file cannot be read within its limits (missing, not a regular file, too large).
    #[error("{path}: {message}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// The file is not valid JSON.
    #[error("{path}:{line}:{column}: syntax error: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// Line (1-based).
        line: usize,
        /// Column (1-based).
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A value is missing, of the wrong type, unknown or out of range.
    #[error("{path}:{line}:{column}: {field}: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Line (1-based).
        line: usize,
        /// Column (1-based).
        column: usize,
        /// The field path, e.g. `objects[3].material.ior`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A scene file of another renderer (Mitsuba XML) cannot be imported.
    #[error("{0}")]
    Import(crate::ImportError),
    /// The scene is well-formed but cannot be rendered as it is.
    #[error("{path}: {field}: {message}")]
    Scene {
        /// The file.
        path: PathBuf,
        /// The field concerned.
        field: String,
        /// What is wrong.
        message: String,
    },
}

/// A scene ready for the tracer.
#[derive(Debug)]
pub struct Scene {
    /// The scene file it came from.
    pub path: PathBuf,
    /// The file's contents, canonicalised (for fingerprints and the sidecar).
    pub canonical_json: String,
    /// The camera.
    pub camera: PinholeCamera,
    /// All shapes in one BVH.
    pub world: World,
    /// One material per shape.
    pub materials: Vec<Arc<dyn Material>>,
    /// Whether each shape can send light to itself (every shape but a flat one), for the
    /// effects analysis.
    pub non_convex: Vec<bool>,
    /// What each shape emits (indexed like `materials`): the surfaces of area lights, which
    /// follow the objects' shapes, and glowing objects.
    pub emitters: Vec<Option<Emitter>>,
    /// How many shapes are the scene's objects (the first ones; the rest are light surfaces).
    pub object_shapes: usize,
    /// The lights.
    pub lights: LightSet,
    /// Render settings.
    pub settings: Settings,
    /// Which of the effort settings the scene file gives (the rest are defaults).
    pub settings_given: SettingsGiven,
    /// Effects setting.
    pub effects: EffectsSettings,
    /// Output settings.
    pub output: OutputSettings,
    /// Every file the scene was read from: the scene file (when loaded from one), its OBJ
    /// meshes and luminaire files. Outputs may never replace any of them.
    pub inputs: Vec<PathBuf>,
    /// The illuminance sensors.
    pub sensors: SensorSet,
    /// The approximations made when the scene was imported from another renderer's file
    /// (`file:line: what`); empty for a native scene.
    pub notes: Vec<String>,
}

/// How a scene file may refer to other files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LoadOptions {
    /// Refuse any file (OBJ mesh, luminaire file) outside the scene file's folder, symlinks resolved: for
    /// render farms that accept scenes from others (`--restrict-paths`).
    pub restrict_paths: bool,
}

impl Scene {
    /// Reads and validates a scene file (at most [`MAX_SCENE_BYTES`] bytes).
    ///
    /// # Errors
    /// [`SceneError`] with the file, line, column and field of the first problem.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        Self::load_with(path, LoadOptions::default())
    }

    /// As [`Scene::load`], with options.
    ///
    /// # Errors
    /// As [`Scene::load`]; with `restrict_paths`, also a mesh outside the scene's folder.
    pub fn load_with(path: &Path, options: LoadOptions) -> Result<Self, SceneError> {
        if crate::is_mitsuba_scene(path) {
            return Self::import_with(path, &[], options);
        }
        let bytes = read_bounded(path, MAX_SCENE_BYTES, "scene")
            .map_err(|message| SceneError::Read { path: path.to_owned(), message })?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let line = valid.iter().filter(|&&b| b == b'\n').count() + 1;
            let column = valid.iter().rev().take_while(|&&b| b != b'\n').count() + 1;
            SceneError::Syntax {
                path: path.to_owned(),
                line,
                column,
                message: "the file is not UTF-8 text (a scene file is JSON in UTF-8)".to_owned(),
            }
        })?;
        let mut scene = Self::from_json_with(&text, path, options)?;
        scene.inputs.insert(0, path.to_owned());
        Ok(scene)
    }

    /// Reads a Mitsuba scene file (`.xml`) with `defines` (`-D name=value`) through the importer
    /// and loads the native scene it becomes; its approximations are in [`Scene::notes`].
    ///
    /// # Errors
    /// [`SceneError::Import`] with the XML file and line, or the errors of the native scene.
    pub fn import_with(
        path: &Path,
        defines: &[(String, String)],
        options: LoadOptions,
    ) -> Result<Self, SceneError> {
        let imported = crate::import_mitsuba(path, defines).map_err(SceneError::Import)?;
        let text = serde_json::to_string_pretty(&imported.scene).unwrap_or_default();
        let mut scene = Self::from_json_with(&text, path, options).map_err(|e| match e {
            SceneError::Invalid { path, line, field, message, .. } => SceneError::Scene {
                path,
                field: format!("{field} (line {line} of the scene `spectrace convert` writes)"),
                message,
            },
            other => other,
        })?;
        scene.notes = imported.notes.iter().map(ToString::to_string).collect();
        scene.inputs.splice(0..0, imported.files);
        Ok(scene)
    }

    /// Validates a scene given as JSON text; `path` names it in errors and resolves relative
    /// files (OBJ meshes, luminaire files).
    ///
    /// # Errors
    /// [`SceneError`] with the line, column and field of the first problem.
    pub fn from_json(text: &str, path: &Path) -> Result<Self, SceneError> {
        Self::from_json_with(text, path, LoadOptions::default())
    }

    /// As [`Scene::from_json`], with options.
    ///
    /// # Errors
    /// As [`Scene::from_json`].
    pub fn from_json_with(
        text: &str,
        path: &Path,
        options: LoadOptions,
    ) -> Result<Self, SceneError> {
        // Editors on some systems start UTF-8 files with a byte-order mark; JSON does not allow
        // one, but it carries no meaning, so it is skipped.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let value = parse_syntax(text, path)?;
        let base = path.parent().unwrap_or_else(|| Path::new("."));
        let (file, light_inputs) = deserialize(text, path, base, options)?;
        check_settings(&file, path)?;
        let mut parts = Assembly::new(path, base, options, light_inputs);
        let mut object_lights = Vec::new();
        for (index, object) in file.objects.into_iter().enumerate() {
            if let Some(light) = parts.add_object(index, object)? {
                object_lights.push((index, light));
            }
        }
        let object_shapes = parts.shapes.len();
        let lights = parts.add_lights(file.lights, object_lights)?;
        let sensors = sensor_set(file.sensors, path)?;
        let world = World::with_base_dir(parts.shapes, base)
            .map_err(|e| scene_error(path, "objects", e.to_string()))?;
        let canonical_json = serde_json::to_string(&value).unwrap_or_default();
        Ok(Self {
            path: path.to_owned(),
            canonical_json,
            camera: file.camera,
            world,
            materials: parts.materials,
            non_convex: parts.non_convex,
            emitters: parts.emitters,
            object_shapes,
            lights,
            settings: file.settings,
            settings_given: SettingsGiven::of(&value),
            effects: file.effects,
            output: file.output,
            inputs: parts.inputs,
            sensors,
            notes: Vec::new(),
        })
    }

    /// What the scene contains (its lights, materials and shapes), for the effects analysis, the
    /// choice of estimator and the warnings: the one place it is found. Not cached, since the
    /// lights are a public field that experiments change after loading (the lab's knobs); a scan
    /// of the lights and materials costs nothing next to a render.
    pub fn features(&self) -> SceneFeatures {
        crate::tracer_scene(self).features(&self.non_convex)
    }

    /// Whether a point can sample every light (no laser of zero width, no beam-only light): what
    /// the path tracer needs, from the camera or from a sensor.
    pub(crate) fn lights_sampled_from_points(&self) -> bool {
        let f = self.features();
        f.beam_only_lights == 0 && f.unreachable_lights == 0
    }

    /// The tracer settings.
    pub fn tracer_settings(&self) -> LightTracerSettings {
        LightTracerSettings { max_depth: self.settings.max_depth, rr_depth: self.settings.rr_depth }
    }

    /// The render plan from the settings, before command-line overrides.
    /// The path tracer's settings.
    pub fn path_settings(&self) -> PathTracerSettings {
        PathTracerSettings {
            max_depth: self.settings.max_depth,
            rr_depth: self.settings.rr_depth,
            wavelengths: self.settings.camera_wavelengths,
            kernel: self.settings.kernel,
        }
    }

    /// BDPT's settings.
    pub fn bdpt_settings(&self) -> BdptSettings {
        BdptSettings {
            max_depth: self.settings.max_depth,
            rr_depth: self.settings.rr_depth,
            only_strategy: None,
            wavelengths: self.settings.bdpt_wavelengths,
            camera_wavelengths: self.settings.camera_wavelengths,
        }
    }

    /// The render plan of the scene's settings (light tracer work items: beams).
    pub fn plan(&self) -> RenderPlan {
        RenderPlan {
            beams: self.settings.beams,
            chunk_beams: self.settings.chunk_beams,
            seed: self.settings.seed,
            threads: self.settings.threads,
            shard: None,
            time_budget: self.settings.time_seconds,
            error_estimate: true,
            target_error: self.settings.target_error,
            error_measure: self.settings.error_measure,
        }
    }

    /// The base name of the output files.
    pub fn output_name(&self) -> String {
        self.output.name.clone().unwrap_or_else(|| {
            self.path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "image".to_owned())
        })
    }

    /// A 64-bit FNV-1a fingerprint of the canonical scene, to check that partial films belong
    /// together.
    pub fn fingerprint(&self) -> u64 {
        self.canonical_json
            .bytes()
            .fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
    }
}

/// An error in a scene that is well-formed but cannot be rendered as it is.
fn scene_error(path: &Path, field: &str, message: String) -> SceneError {
    SceneError::Scene { path: path.to_owned(), field: field.to_owned(), message }
}

/// The scene's JSON, checked for syntax first so that syntax errors are reported as such, with
/// their position.
fn parse_syntax(text: &str, path: &Path) -> Result<serde_json::Value, SceneError> {
    serde_json::from_str(text).map_err(|e| SceneError::Syntax {
        path: path.to_owned(),
        line: e.line(),
        column: e.column(),
        message: strip_position(&e.to_string()),
    })
}

/// The scene file's fields, with errors naming the field path, and the files its lights read.
/// Files named inside the scene (measured luminaires) resolve against its folder `base` while
/// it is deserialised, under the same path policy as OBJ meshes.
fn deserialize(
    text: &str,
    path: &Path,
    base: &Path,
    options: LoadOptions,
) -> Result<(SceneFile, Vec<PathBuf>), SceneError> {
    let (file, light_inputs) = with_scene_folder(base, options.restrict_paths, || {
        let mut de = serde_json::Deserializer::from_str(text);
        serde_path_to_error::deserialize::<_, SceneFile>(&mut de)
    });
    let file = file.map_err(|e| {
        let field = e.path().to_string();
        let inner = e.into_inner();
        SceneError::Invalid {
            path: path.to_owned(),
            line: inner.line(),
            column: inner.column(),
            field: if field.is_empty() || field == "." { "(scene)".to_owned() } else { field },
            message: strip_position(&inner.to_string()),
        }
    })?;
    Ok((file, light_inputs))
}

/// Checks what the types alone do not: some objects, and settings and output settings in range.
fn check_settings(file: &SceneFile, path: &Path) -> Result<(), SceneError> {
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

/// A scene being assembled: its shapes (the objects' first, then the area lights' surfaces)
/// with one material, convexity and emitter each, and every file read.
struct Assembly<'a> {
    /// The scene file, for errors.
    path: &'a Path,
    /// Its folder, against which meshes resolve.
    base: &'a Path,
    options: LoadOptions,
    shapes: Vec<Shape>,
    materials: Vec<Arc<dyn Material>>,
    non_convex: Vec<bool>,
    emitters: Vec<Option<Emitter>>,
    inputs: Vec<PathBuf>,
}

impl<'a> Assembly<'a> {
    /// An empty scene from `path`, whose lights read `inputs`.
    fn new(path: &'a Path, base: &'a Path, options: LoadOptions, inputs: Vec<PathBuf>) -> Self {
        Self {
            path,
            base,
            options,
            shapes: Vec::new(),
            materials: Vec::new(),
            non_convex: Vec::new(),
            emitters: Vec::new(),
            inputs,
        }
    }

    /// An error about `field` of this scene.
    fn error(&self, field: &str, message: String) -> SceneError {
        scene_error(self.path, field, message)
    }

    /// Adds object `index`: its mesh file (checked against the path policy), its transform
    /// applied, its shape loaded; returns its light when it glows.
    fn add_object(
        &mut self,
        index: usize,
        mut object: Object,
    ) -> Result<Option<ObjectLight>, SceneError> {
        if let Shape::Mesh(mesh) = &object.shape
            && let Some(obj) = mesh.file_path()
        {
            let resolved = self.base.join(obj);
            if self.options.restrict_paths {
                check_inside(self.base, &resolved).map_err(|message| {
                    self.error(&format!("objects[{index}].shape.obj"), message)
                })?;
            }
            self.inputs.push(resolved);
        }
        if let Some(t) = object.transform.take() {
            object.shape = apply_transform(object.shape, &t)
                .map_err(|message| self.error(&format!("objects[{index}].transform"), message))?;
        }
        // Only flat shapes can never send light to themselves; a sphere sees its own inside.
        self.non_convex.push(!matches!(object.shape, Shape::Rectangle(_) | Shape::Disk(_)));
        object
            .shape
            .load(self.base)
            .map_err(|e| self.error(&format!("objects[{index}].shape"), e.to_string()))?;
        let light = match &object.emission {
            Some(emission) => {
                Some(ObjectLight::new(object.shape.clone(), emission).map_err(|e| {
                    self.error(&format!("objects[{index}].emission"), e.to_string())
                })?)
            }
            None => None,
        };
        self.shapes.push(object.shape);
        self.materials.push(Arc::from(object.material));
        Ok(light)
    }

    /// The light set: the file's lights, then the glowing objects' (`(object index, light)`),
    /// which become those objects' emitters; then the area lights' surfaces as shapes.
    fn add_lights(
        &mut self,
        lights: Vec<Box<dyn LightSource>>,
        object_lights: Vec<(usize, ObjectLight)>,
    ) -> Result<LightSet, SceneError> {
        self.emitters = vec![None; self.shapes.len()];
        let mut all_lights = lights;
        let glowing: Vec<(usize, f64, bool, f64)> = object_lights
            .iter()
            .map(|(i, l)| (*i, l.radiance(), l.two_sided(), l.area()))
            .collect();
        all_lights
            .extend(object_lights.into_iter().map(|(_, l)| Box::new(l) as Box<dyn LightSource>));
        if all_lights.is_empty() {
            return Err(self.error(
                "lights",
                "the scene has no lights and no object with an `emission`".to_owned(),
            ));
        }
        let lights = LightSet::new(all_lights).map_err(|e| self.error("lights", e.to_string()))?;
        // Glowing objects' lights are the set's last ones.
        let first_glowing = lights.lights().len() - glowing.len();
        for (k, &(index, radiance, two_sided, area)) in glowing.iter().enumerate() {
            self.emitters[index] = Some(Emitter::Object {
                light: LightId((first_glowing + k) as u32),
                radiance,
                two_sided,
                area,
            });
        }
        self.add_light_surfaces(&lights, first_glowing)?;
        Ok(lights)
    }

    /// Adds the surfaces of the first `count` lights that have one. Area lights are part of the
    /// scene: their surfaces block light and camera paths, and camera paths that hit them see
    /// their radiance. They reflect nothing.
    fn add_light_surfaces(&mut self, lights: &LightSet, count: usize) -> Result<(), SceneError> {
        for (index, light) in lights.lights().iter().enumerate().take(count) {
            let Some(surface) = light.surface() else { continue };
            let shape = match surface {
                LightSurface::Rectangle { corner, edge_u, edge_v } => {
                    Rectangle::new(corner, edge_u, edge_v).map(Shape::from)
                }
                LightSurface::Disk { center, normal, radius } => {
                    Disk::new(center, normal, radius).map(Shape::from)
                }
                _ => continue,
            }
            .map_err(|e| self.error(&format!("lights[{index}]"), e.to_string()))?;
            self.shapes.push(shape);
            self.materials.push(black().map_err(|e| self.error(&format!("lights[{index}]"), e))?);
            self.non_convex.push(false);
            self.emitters.push(Some(Emitter::Light(LightId(index as u32))));
        }
        Ok(())
    }
}

/// The sensors, whose names must be plain file names.
fn sensor_set(sensors: Vec<IrradianceSensor>, path: &Path) -> Result<SensorSet, SceneError> {
    for (i, sensor) in sensors.iter().enumerate() {
        check_output_name(sensor.name())
            .map_err(|e| scene_error(path, &format!("sensors[{i}].name"), e))?;
    }
    SensorSet::new(sensors).map_err(|e| scene_error(path, "sensors", e))
}

/// The shape with `t` applied after its own transform (re-validated, since a curved shape only
/// accepts similarities).
/// The material of a light's own surface: it absorbs everything.
fn black() -> Result<Arc<dyn Material>, String> {
    let none = Reflectance::constant(0.0).map_err(|e| e.to_string())?;
    Ok(Arc::new(Diffuse::new(none)))
}

fn apply_transform(shape: Shape, t: &Transform) -> Result<Shape, String> {
    let mut value = serde_json::to_value(&shape).map_err(|e| e.to_string())?;
    let own: Option<Transform> = match value.get("transform") {
        Some(v) if !v.is_null() => {
            Some(serde_json::from_value(v.clone()).map_err(|e| e.to_string())?)
        }
        _ => None,
    };
    let combined = match own {
        Some(own) => own.then(t),
        None => *t,
    };
    let rows = combined.to_rows();
    if let Some(map) = value.as_object_mut() {
        map.insert("transform".to_owned(), serde_json::json!({ "matrix": rows }));
    }
    serde_json::from_value(value).map_err(|e| e.to_string())
}

/// serde_json appends " at line L column C"; the position is reported separately.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
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
