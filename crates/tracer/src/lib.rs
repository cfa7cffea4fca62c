//! Camera, spectral film and the estimators of Spectrace: the light tracer (seed 2.4.4), the path
//! tracer and bidirectional path tracing, behind one [`Integrator`] interface.
//!
//! This crate sits on all the others (sampling, spectrum, lights, geometry, materials) and under
//! the renderer. A [`LightTracerScene`] holds what every estimator needs: the
//! [`spectrace_geometry::World`], one [`spectrace_materials::Material`] per shape, the
//! [`spectrace_lights::LightSet`] with the light samplers the estimators ask (by power,
//! [`PowerLightSampler`], and for next-event estimation among many lights a [`LightTree`], both
//! behind [`NextEventLights`]), what each shape emits ([`Emitter`]: area lights' own surfaces and
//! glowing objects, [`ObjectLight`]) and the [`PinholeCamera`] (a pinhole or a thin lens).
//! [`LightTracer`] follows beams from the lights and connects them to the camera; [`PathTracer`]
//! follows camera paths with next-event estimation and multiple importance sampling, carrying
//! [`HERO`] wavelengths; [`Bdpt`] joins a camera path and a light path in every way and weighs the
//! strategies by MIS. [`IntegratorChoice::decide`] picks one from what the scene holds, the
//! registry ([`INTEGRATORS`], [`build_integrator`]) builds it, and the render loop ([`render`])
//! drives any of them.
//!
//! The layout follows the jobs: `scene` (what is traced), `light_sampler`, `light_tree` and
//! `next_event` (which light a connection goes to), `integrators` (one module per estimator,
//! over `integrators/common`, the transport steps they share, and `integrators/pass`, the camera
//! estimators' pass loop), `batch` (the path tracer's batched kernel: many paths moved through
//! the same steps stage by stage, giving the scalar kernel's image bit for bit; [`Kernel`]),
//! `film` (exact sums, their size rules and the error from the spread between chunks), `render`
//! (threads, chunks, memory), `sampler` (the random streams: one per chunk, one per camera
//! path), `effects` (what the scene needs).
//!
//! The key design decisions: the film adds contributions in exact fixed point ([`ExactSum`]), so
//! an image is bit-identical whatever the thread count, chunk order or number of machines
//! ([`render`] splits work into chunks with their own random streams; sharded renders merge
//! exactly), and every estimator writes the same film units, so their images can be compared
//! pixel by pixel; every transport step (a shadow ray, a connection to the camera, a light
//! sample, the fluorescence choice, Russian roulette) is written once and shared, and every
//! vertex draws a fixed set of uniforms, so that the estimators differ only in how they combine
//! the steps; and an [`Effects`] analysis decides, before rendering, what the scene needs (which
//! estimator, a bundle of wavelengths per path when nothing is dispersive, beams that stop at the
//! first diffuse hit when no interreflection is possible, and whether any surface fluoresces,
//! which makes every estimator choose between elastic scattering and re-emission at a new
//! wavelength before it connects a vertex), reports it, and can be overridden. Because chunks
//! are independent, the render loop also estimates the image's error as it goes, from the spread
//! between chunks ([`Moments`]), with no reference.

mod batch;
mod camera;
mod effects;
mod environment;
mod film;
mod integrators;
mod light_sampler;
mod light_tree;
mod next_event;
mod object_light;
mod observer;
mod render;
mod sampler;
mod scene;
mod sensor;
mod stats;
mod wavelengths;

// The scene and what it is made of.
pub use batch::{Kernel, LANES};
pub use camera::{
    CameraError, CameraRay, CameraRepr, CameraSample, FovAxis, PinholeCamera, Projection,
};
pub use environment::{Environment, EnvironmentMap, EnvironmentSpec, MAX_ENVIRONMENT_TEXELS};
pub use light_sampler::{LightSampler, PowerLightSampler, SampledLight};
pub use light_tree::LightTree;
pub use next_event::{AUTO_TREE_ABOVE, LightChoice, LightSamplerKind, NextEventLights};
pub use object_light::{ObjectEmission, ObjectLight};
pub use scene::{Emitter, LightTracerScene};
pub use sensor::{
    IrradianceSensor, MAX_SENSOR_CELLS, MAX_SENSOR_CELLS_PER_EDGE, SensorSet, SensorSums,
};
pub use wavelengths::{
    CAMERA_LAMBDA_MAX, CAMERA_LAMBDA_MIN, CameraWavelengths, HERO, VISIBLE_STEPS,
};

// The estimators, their settings and their registry.
pub use effects::{BUNDLE, Effects, EffectsMode, IntegratorChoice, SceneFeatures};
pub use integrators::bdpt::{Bdpt, BdptSettings, BdptWavelengths};
pub use integrators::light_tracer::{
    LightTracer, LightTracerSettings, MAX_DEPTH, image_scale, trace_chunk, trace_chunk_until,
};
pub use integrators::observer::ObserverTracer;
pub use integrators::pass::{SampleCounts, camera_image};
pub use integrators::path_tracer::{PathTracer, PathTracerSettings};
pub use integrators::sensor_path::{Response, SensorPathTracer};
pub use integrators::{
    ChunkWork, INTEGRATORS, Integrator, IntegratorSettings, RegisteredIntegrator, build_integrator,
    registered,
};
pub use observer::{MAX_OBSERVERS, OBSERVER_QUANTITIES, Observer, check_observers};

// The film, the render loop and its error estimate.
pub use film::{
    ByMeasure, CHUNK_TALLY_BYTES_PER_PIXEL, ErrorEstimate, ErrorMeasure, ExactSum, Film, FilmError,
    FilmWriter, MAX_PIXELS, MAX_TRUSTED_UNCERTAINTY, MIN_BATCHES, Moments, RELMSE_EPSILON,
    SENSOR_SLOTS, Splat, relative_error, spectral_xyz,
};
pub use render::{
    DEFAULT_CHUNK_BEAMS, FALLBACK_MEMORY_LIMIT, LiveEstimates, MemoryLimit, Progress,
    RESERVED_THREADS, RenderOutput, RenderPlan, THREAD_ADDRESS_RESERVE, render, render_observed,
};
pub use sampler::{ChunkSampler, SamplerKind};
pub use stats::TraceStats;
