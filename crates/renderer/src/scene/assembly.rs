//! Assembling a read scene into what the tracer needs: meshes loaded under the path policy,
//! transforms applied, glowing objects and area lights' surfaces made shapes, one BVH.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;
use spectrace_geometry::{Bounds, Disk, Rectangle, Sphere};
use spectrace_geometry::{Shape, Transform};
use spectrace_lights::{LightId, LightSurface};
use spectrace_lights::{LightSet, LightSource};
use spectrace_materials::Diffuse;
use spectrace_materials::Material;
use spectrace_spectrum::{Reflectance, SpectralPowerDistribution};
use spectrace_tracer::{Emitter, Environment, EnvironmentMap, ObjectLight};
use spectrace_tracer::{IrradianceSensor, SensorSet};

use super::{LoadOptions, Object, SceneError, scene_error};
use crate::files::check_output_name;
use spectrace_sampling::files::check_inside;

/// A scene being assembled: its shapes (the objects' first, then the area lights' surfaces)
/// with one material, convexity and emitter each, and every file read.
pub(super) struct Assembly<'a> {
    /// The scene file, for errors.
    path: &'a Path,
    /// Its folder, against which meshes resolve.
    base: &'a Path,
    options: LoadOptions,
    pub(super) shapes: Vec<Shape>,
    pub(super) materials: Vec<Arc<dyn Material>>,
    pub(super) non_convex: Vec<bool>,
    pub(super) emitters: Vec<Option<Emitter>>,
    pub(super) inputs: Vec<PathBuf>,
}

impl<'a> Assembly<'a> {
    /// An empty scene from `path`, whose lights read `inputs`.
    pub(super) fn new(
        path: &'a Path,
        base: &'a Path,
        options: LoadOptions,
        inputs: Vec<PathBuf>,
    ) -> Self {
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
    pub(super) fn add_object(
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

    /// The scene's environment placed on a sphere around the objects and the `receivers` (the
    /// camera, the sensors): 1.5 times the radius of their bounding sphere, so no receiver lies
    /// on the sphere itself; its choice does not change the image.
    pub(super) fn environment(
        &mut self,
        map: EnvironmentMap,
        receivers: &[DVec3],
    ) -> Result<Box<dyn LightSource>, SceneError> {
        let bounds = self
            .shapes
            .iter()
            .map(Shape::bounds)
            .fold(Bounds::from_points(receivers.iter().copied()), Bounds::union);
        let center = bounds.center();
        let radius = ((bounds.max - bounds.min).length() / 2.0).max(1e-3) * 1.5;
        let light = Environment::new(map, center, radius)
            .map_err(|e| self.error("environment", e.to_string()))?;
        Ok(Box::new(light))
    }

    /// The light set: the file's lights, then the glowing objects' (`(object index, light)`),
    /// which become those objects' emitters; then the area lights' surfaces as shapes.
    pub(super) fn add_lights(
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
        share_equal_spectra(&mut all_lights);
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
                LightSurface::Sphere { center, radius } => {
                    Sphere::new(center, radius).map(Shape::from)
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
pub(super) fn sensor_set(
    sensors: Vec<IrradianceSensor>,
    path: &Path,
) -> Result<SensorSet, SceneError> {
    for (i, sensor) in sensors.iter().enumerate() {
        check_output_name(sensor.name())
            .map_err(|e| scene_error(path, &format!("sensors[{i}].name"), e))?;
    }
    SensorSet::new(sensors).map_err(|e| scene_error(path, "sensors", e))
}

/// The material of a light's own surface: it absorbs everything.
fn black() -> Result<Arc<dyn Material>, String> {
    let none = Reflectance::constant(0.0).map_err(|e| e.to_string())?;
    Ok(Arc::new(Diffuse::new(none)))
}

/// The shape with `t` applied after its own transform (re-validated, since a curved shape only
/// accepts similarities).
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

/// Gives lights whose spectra are equal (the same value in the scene file) one spectrum
/// object, so that what weighs lights by spectrum (the light set's mixture, BDPT's choice of a
/// light given a wavelength) weighs each distinct spectrum once: a scene of 20,000 lamps of
/// one spectrum then costs what one lamp's spectrum costs. Lights that cannot change their
/// spectrum (a plugin that does not implement `map_spd`) keep their own.
fn share_equal_spectra(lights: &mut [Box<dyn LightSource>]) {
    let mut seen: std::collections::HashMap<String, Arc<dyn SpectralPowerDistribution>> =
        std::collections::HashMap::new();
    for light in lights.iter_mut() {
        let spd = light.spd();
        let Ok(key) = serde_json::to_string(&spd) else { continue };
        match seen.get(&key) {
            Some(shared) if !Arc::ptr_eq(shared, &spd) => {
                let shared = shared.clone();
                // A light that cannot take it keeps its own (equal) spectrum.
                let _ = light.map_spd(&|_| Some(shared.clone()));
            }
            Some(_) => {}
            None => {
                seen.insert(key, spd);
            }
        }
    }
}
