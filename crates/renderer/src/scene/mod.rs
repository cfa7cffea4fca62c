//! The scene: [`Scene`], what the tracer renders, read from Spectrace's JSON (`json`) or from a
//! Mitsuba file through the importer (`crate::import`), both producing the typed scene of `model`,
//! then assembled (`assembly`).

mod assembly;
mod json;
mod model;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use spectrace_geometry::World;
use spectrace_lights::LightSet;
use spectrace_materials::Material;
use spectrace_tracer::SensorSet;
use spectrace_tracer::{
    BdptSettings, Emitter, LightTracerSettings, PathTracerSettings, PinholeCamera, RenderPlan,
    SceneFeatures,
};

use crate::files::{MAX_SCENE_BYTES, read_bounded};

use assembly::{Assembly, sensor_set};
use json::{deserialize, parse_syntax};
pub use model::*;

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
    /// The observers (eye positions).
    pub observers: Vec<spectrace_tracer::Observer>,
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
        let imported = crate::import::import_mitsuba_with(path, defines, options.restrict_paths)
            .map_err(SceneError::Import)?;
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
        let mut file_lights = file.lights;
        if let Some(map) = file.environment {
            // Everything that receives light lies inside its sphere: the camera and the
            // sensors' corners too.
            let receivers: Vec<glam::DVec3> = std::iter::once(file.camera.position())
                .chain(file.sensors.iter().flat_map(|s| {
                    let (c, u, v) = (s.corner(), s.edge_u(), s.edge_v());
                    [c, c + u, c + v, c + u + v]
                }))
                .chain(file.observers.iter().map(|o| o.position()))
                .collect();
            file_lights.push(parts.environment(map, &receivers)?);
        }
        let lights = parts.add_lights(file_lights, object_lights)?;
        let sensors = sensor_set(file.sensors, path)?;
        spectrace_tracer::check_observers(&file.observers)
            .map_err(|e| scene_error(path, "observers", e))?;
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
            observers: file.observers,
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
pub(crate) fn scene_error(path: &Path, field: &str, message: String) -> SceneError {
    SceneError::Scene { path: path.to_owned(), field: field.to_owned(), message }
}
