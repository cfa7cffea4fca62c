//! Camera, spectral film and integrators of Spectrace (issue 5, in progress).
//!
//! Today this crate holds the film: [`Film`] accumulates CIE XYZ per pixel from spectral
//! contributions in exact fixed-point sums ([`ExactSum`]), so an image is bit-identical whatever
//! the order in which work chunks, threads or machines add to it. [`PinholeCamera`] defines the
//! film units (mean spectral radiance over a pixel's area) and projects scene points into the
//! film with the importance a light-tracing connection needs. The light tracer joins them next.

mod camera;
mod effects;
mod film;
mod light_tracer;
mod render;

pub use camera::{CameraError, CameraRepr, FovAxis, PinholeCamera, Projection};
pub use effects::{BUNDLE, Effects, EffectsMode, SceneFeatures};
pub use film::{ExactSum, Film, FilmError};
pub use light_tracer::{
    LightTracerScene, LightTracerSettings, TraceStats, chunk_rng, image_scale, trace_chunk,
};
pub use render::{DEFAULT_CHUNK_BEAMS, RenderOutput, RenderPlan, render};
