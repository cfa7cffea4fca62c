//! The configurations the sweep renders: each accuracy knob's name, what it changes, and the
//! estimator, sampler and effects mode it renders with ([`knobs::apply`](super::apply) sets
//! them on the typed scene).

use super::*;

/// One accuracy knob setting the sweep renders.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Configuration {
    /// The scene as written, effects analysis `auto`.
    Baseline,
    /// Every light samples wavelengths uniformly with weights.
    EqualWavelengths,
    /// Every tabulated SPD of the lights becomes piecewise constant (the seed's `Binned`).
    PiecewiseConstantSpd,
    /// The effects analysis off.
    EffectsOff,
    /// The scene as written, rendered by the path tracer.
    Path,
    /// The scene as written, rendered by bidirectional path tracing.
    Bdpt,
    /// The scene as written, rendered by the estimator `auto` picks.
    Auto,
    /// Every light draws wavelengths from SPD x observer sensitivity (light tracer).
    ObserverWavelengths,
    /// The Sobol sampler (light tracer).
    Sobol,
    /// The Sobol sampler with the path tracer.
    PathSobol,
    /// The Sobol sampler with bidirectional path tracing.
    BdptSobol,
    /// The path tracer with camera wavelengths uniform over 360-830 nm instead of the visible
    /// density: the camera side's wavelength strategy.
    PathUniformWavelengths,
    /// BDPT with the beam's one wavelength per sample instead of hero wavelengths.
    BdptBeam,
}

impl Configuration {
    /// Every configuration, in report order.
    pub const ALL: [Configuration; 13] = [
        Configuration::Baseline,
        Configuration::EqualWavelengths,
        Configuration::PiecewiseConstantSpd,
        Configuration::EffectsOff,
        Configuration::Path,
        Configuration::Bdpt,
        Configuration::Auto,
        Configuration::ObserverWavelengths,
        Configuration::Sobol,
        Configuration::PathSobol,
        Configuration::BdptSobol,
        Configuration::PathUniformWavelengths,
        Configuration::BdptBeam,
    ];

    /// The estimator knob: the light tracer (`baseline`), `path`, `bdpt` and `auto`.
    pub const INTEGRATORS: [Configuration; 4] =
        [Configuration::Baseline, Configuration::Path, Configuration::Bdpt, Configuration::Auto];

    /// Parses a name as in reports (`baseline`, `equal_wavelengths`, ..., `path`, `bdpt`, `auto`;
    /// `light` is accepted for `baseline`).
    pub fn from_name(name: &str) -> Option<Self> {
        if name == "light" {
            return Some(Configuration::Baseline);
        }
        Configuration::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The estimator the configuration renders with (the light-tracer knobs use the light
    /// tracer).
    pub fn integrator(self) -> IntegratorChoice {
        match self {
            Configuration::Path
            | Configuration::PathSobol
            | Configuration::PathUniformWavelengths => IntegratorChoice::Path,
            Configuration::Bdpt | Configuration::BdptSobol | Configuration::BdptBeam => {
                IntegratorChoice::Bdpt
            }
            Configuration::Auto => IntegratorChoice::Auto,
            _ => IntegratorChoice::Light,
        }
    }

    /// The estimator's name in the integrator tables (`light` for `baseline`).
    pub fn integrator_label(self) -> &'static str {
        match self {
            Configuration::Baseline => "light",
            other => other.name(),
        }
    }

    /// The name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            Configuration::Baseline => "baseline",
            Configuration::EqualWavelengths => "equal_wavelengths",
            Configuration::PiecewiseConstantSpd => "piecewise_constant_spd",
            Configuration::EffectsOff => "effects_off",
            Configuration::Path => "path",
            Configuration::Bdpt => "bdpt",
            Configuration::Auto => "auto",
            Configuration::ObserverWavelengths => "observer_wavelengths",
            Configuration::Sobol => "sobol",
            Configuration::PathSobol => "path_sobol",
            Configuration::BdptSobol => "bdpt_sobol",
            Configuration::PathUniformWavelengths => "path_uniform_wavelengths",
            Configuration::BdptBeam => "bdpt_beam",
        }
    }

    /// What the configuration changes, in words.
    pub fn description(self) -> &'static str {
        match self {
            Configuration::Baseline => {
                "the light tracer on the scene as written: wavelengths by importance, SPDs as \
                 given, effects analysis auto, independent sampling, as every light-tracer knob \
                 but `sobol` (the `light` of the integrator tables)"
            }
            Configuration::EqualWavelengths => {
                "every light draws wavelengths uniformly over its SPD's range, weighted by the SPD \
                 (lights whose SPD has delta lines keep importance sampling)"
            }
            Configuration::PiecewiseConstantSpd => {
                "every Tabulated SPD of the lights (and every tabulated CieIlluminant) replaced by a \
                 Binned SPD with bins centred on the table's nodes and the same values: the seed's \
                 choppy generator instead of piecewise linear"
            }
            Configuration::EffectsOff => {
                "effects analysis off: one wavelength per path, beams continue after diffuse hits"
            }
            Configuration::Path => {
                "the path tracer (camera paths, next-event estimation, MIS) on the scene as \
                 written, with independent sampling; N paths are ceil(N / pixels) samples per \
                 pixel"
            }
            Configuration::Bdpt => {
                "bidirectional path tracing with MIS on the scene as written, with independent \
                 sampling; N paths are ceil(N / pixels) samples per pixel"
            }
            Configuration::Auto => {
                "the estimator `auto` picks (`IntegratorChoice::decide`) with the default \
                 sampler, with its own seeds"
            }
            Configuration::ObserverWavelengths => {
                "every light draws wavelengths in proportion to SPD x (xbar + ybar + zbar), \
                 weighted by SPD / density (lights whose SPD has delta lines keep importance \
                 sampling); the light tracer"
            }
            Configuration::Sobol => {
                "the light tracer with Owen-scrambled Sobol points (settings.sampler \"sobol\") \
                 instead of independent uniforms"
            }
            Configuration::PathSobol => {
                "the path tracer with Owen-scrambled Sobol points (settings.sampler \"sobol\"); \
                 N paths are ceil(N / pixels) samples per pixel"
            }
            Configuration::BdptSobol => {
                "bidirectional path tracing with Owen-scrambled Sobol points (settings.sampler \
                 \"sobol\"); N paths are ceil(N / pixels) samples per pixel"
            }
            Configuration::PathUniformWavelengths => {
                "the path tracer with camera wavelengths uniform over 360-830 nm \
                 (settings.camera_wavelengths \"uniform\") instead of the visible density, with \
                 independent sampling: the camera side's wavelength strategy, the peer of `path`"
            }
            Configuration::BdptBeam => {
                "bidirectional path tracing with one wavelength per sample, the beam's \
                 (settings.bdpt_wavelengths \"beam\") instead of four hero wavelengths, with \
                 independent sampling: the peer of `bdpt` for BDPT's colour noise"
            }
        }
    }

    /// The sampler the configuration sets (`settings.sampler`; `None`: as written, which
    /// `auto` resolves per estimator): Sobol for the `*sobol` configurations, `auto` as written,
    /// and independent sampling for every other one (`baseline` and the light tracer's knobs,
    /// whose peer it is, `path`, `bdpt` and their peers `bdpt_beam` and
    /// `path_uniform_wavelengths`), so that each knob is measured against its peer alone
    /// whatever `auto` would draw for the scene.
    pub fn sampler(self) -> Option<SamplerKind> {
        match self {
            Configuration::Sobol | Configuration::PathSobol | Configuration::BdptSobol => {
                Some(SamplerKind::Sobol)
            }
            Configuration::Auto => None,
            _ => Some(SamplerKind::Independent),
        }
    }

    /// The wavelength sampling the configuration gives every light (`None`: as written).
    pub fn wavelength_sampling(self) -> Option<WavelengthSampling> {
        match self {
            Configuration::EqualWavelengths => Some(WavelengthSampling::EqualWavelengths),
            Configuration::ObserverWavelengths => Some(WavelengthSampling::Observer),
            _ => None,
        }
    }

    /// The effects mode the configuration renders with.
    pub fn effects_mode(self) -> EffectsMode {
        match self {
            Configuration::EffectsOff => EffectsMode::Off,
            _ => EffectsMode::Auto,
        }
    }
}
