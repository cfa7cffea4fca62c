//! What a render is asked (the command-line overrides of a scene's settings) and why it fails.

use std::path::PathBuf;

use spectrace_tracer::{EffectsMode, IntegratorChoice, Kernel};

use crate::SceneError;

/// Command-line overrides of a scene's settings.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RenderOptions {
    /// Beams for the whole image (overrides `settings.beams`).
    pub beams: Option<u64>,
    /// Time budget in seconds (overrides `settings.time_seconds`).
    pub time: Option<f64>,
    /// Threads (overrides `settings.threads`; 0 = one per core).
    pub threads: Option<usize>,
    /// Seed (overrides `settings.seed`).
    pub seed: Option<u64>,
    /// Render only chunks `k` mod `n` and write a partial film.
    pub shard: Option<(u64, u64)>,
    /// Effects mode (overrides `effects.mode`).
    pub effects: Option<EffectsMode>,
    /// Where the outputs go.
    pub out_dir: PathBuf,
    /// Show a progress bar and print the effects decision.
    pub verbose: bool,
    /// Refuse files (OBJ meshes, luminaire files) outside the scene file's folder (see
    /// [`LoadOptions`](crate::LoadOptions)).
    pub restrict_paths: bool,
    /// The estimator (overrides `settings.integrator`).
    pub integrator: Option<IntegratorChoice>,
    /// Camera samples per pixel for `path` and `bdpt` (overrides `settings.spp`).
    pub spp: Option<u64>,
    /// Render until the estimated relative error reaches this (overrides
    /// `settings.target_error`).
    pub target_error: Option<f64>,
    /// The kernel of the path tracer's camera paths (overrides `settings.kernel`).
    pub kernel: Option<Kernel>,
    /// The error measure of the estimate and the target (overrides `settings.error_measure`).
    pub error_measure: Option<spectrace_tracer::ErrorMeasure>,
    /// The error image to write (overrides `output.error_image`).
    pub error_image: Option<crate::ErrorImage>,
}

impl RenderOptions {
    /// The scene's output settings with these options' overrides.
    pub fn output_settings(&self, scene: &crate::Scene) -> crate::OutputSettings {
        let mut settings = scene.output.clone();
        if let Some(e) = self.error_image {
            settings.error_image = e;
        }
        settings
    }
}

/// Why a render failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// The scene is invalid (or cannot produce light at the camera).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// An option is invalid.
    #[error("{0}")]
    Options(String),
    /// Writing or reading a file failed.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}
