//! Spectrace's experiment harness: measurements of the renderer that are not part of rendering.
//!
//! Today that is the accuracy report ([`accuracy::run`], `cargo xtask accuracy` or
//! `spectrace-lab accuracy`): for every shipped scene, error against wall time for every knob
//! (estimator, wavelength strategy, SPD sampler, sampler, effects analysis), log-log plots with
//! the fitted slopes beside the Monte Carlo -1/2, the fastest configuration to 10% and to 2%
//! relative RMSE, and how far `auto` is from it. The main type is
//! [`accuracy::Configuration`], one knob setting.
//!
//! The key design decision: configurations are applied to the renderer's *typed* scene
//! ([`spectrace_renderer::Scene`]), never by rewriting scene JSON, through small hooks in the
//! crates that own each knob ([`spectrace_lights::LightSource::set_wavelength_sampling`],
//! [`spectrace_lights::LightSource::map_spd`],
//! [`spectrace_spectrum::SpectralPowerDistribution::piecewise_constant`]), so the report follows
//! the scene format as it changes. The harness lives in its own crate so that the renderer does
//! not pull the plotting library into every program that renders; it depends on the renderer and
//! nothing depends on it.

pub mod accuracy;
pub mod cli;
