//! Camera, spectral film and integrators of Spectrace; today the light tracer (seed 2.4.4).
//!
//! This crate sits on all the others (sampling, spectrum, lights, geometry, materials) and under
//! the renderer. Beams come from a [`spectrace_lights::LightSet`], travel through a
//! [`spectrace_geometry::World`], scatter by each shape's [`spectrace_materials::Material`], and
//! every non-specular hit (and every emission point) is connected to the [`PinholeCamera`] and
//! splatted into the [`Film`] (see [`light_tracer`](trace_chunk) for the estimator). The render
//! loop ([`render`]) drives any [`Integrator`]; [`LightTracer`] is the light tracer behind it.
//!
//! The key design decisions: the film adds contributions in exact fixed point ([`ExactSum`]), so
//! an image is bit-identical whatever the thread count, chunk order or number of machines
//! ([`render`] splits work into chunks with their own random streams; sharded renders merge
//! exactly); and an [`Effects`] analysis decides, before rendering, what the scene needs (a bundle
//! of wavelengths per path when nothing is dispersive; beams that stop at the first diffuse hit
//! when no interreflection is possible), reports it, and can be overridden.

mod bdpt;
mod camera;
mod effects;
mod film;
mod integrator;
mod light_tracer;
mod object_light;
mod path_tracer;
mod render;
mod wavelengths;

pub use bdpt::{Bdpt, BdptSettings, MisVertex, mis_weight};
pub use camera::{
    CameraError, CameraRay, CameraRepr, CameraSample, FovAxis, PinholeCamera, Projection,
};
pub use effects::{BUNDLE, Effects, EffectsMode, IntegratorChoice, SceneFeatures};
pub use film::{ExactSum, Film, FilmError, FilmWriter, MAX_PIXELS, Splat};
pub use integrator::{Integrator, LightTracer};
pub use light_tracer::{
    Emitter, LightTracerScene, LightTracerSettings, MAX_DEPTH, TraceStats, chunk_rng, image_scale,
    trace_chunk, trace_chunk_until,
};
pub use object_light::{ObjectEmission, ObjectLight};
pub use path_tracer::{PathTracer, PathTracerSettings};
pub use render::{
    DEFAULT_CHUNK_BEAMS, FALLBACK_MEMORY_LIMIT, MemoryLimit, RenderOutput, RenderPlan, render,
};
pub use wavelengths::{CAMERA_LAMBDA_MAX, CAMERA_LAMBDA_MIN, CameraWavelengths, HERO};
