//! The knobs, set on the typed scene: the camera resolution, the lights' wavelength sampling and
//! SPDs, the sampler.

use super::*;
use spectrace_tracer::{Bdpt, BdptWavelengths, CameraWavelengths};

/// Scales the camera down so the image is at most `max_width` pixels wide, keeping the aspect
/// ratio (a new camera from the same [`CameraRepr`]). Returns whether it changed anything.
pub(super) fn limit_resolution(scene: &mut Scene, max_width: u32) -> Result<bool, String> {
    let mut repr: CameraRepr = scene.camera.clone().into();
    let max = max_width.max(1);
    if repr.width <= max {
        return Ok(false);
    }
    let height = (f64::from(repr.height) * f64::from(max) / f64::from(repr.width)).round();
    repr.height = (height as u32).max(1);
    repr.width = max;
    scene.camera = PinholeCamera::new(repr).map_err(|e| format!("camera: {e}"))?;
    Ok(true)
}

/// "`n` light(s)", with the lights left as written and why.
pub(super) fn lights_changed(changed: usize, lines: usize, unsupported: usize) -> String {
    let mut text = format!("{changed} light(s)");
    if lines > 0 {
        text += &format!("; {lines} with delta lines left on importance");
    }
    if unsupported > 0 {
        text += &format!("; {unsupported} of a type without the hook left as written");
    }
    text
}

/// Sets every light's wavelength sampling (lights whose SPD has delta lines keep importance:
/// lines have no density to weight by). Returns (changed, skipped for lines, without the hook).
pub(super) fn set_wavelength_sampling(
    scene: &mut Scene,
    sampling: WavelengthSampling,
) -> Result<(usize, usize, usize), String> {
    let (mut changed, mut lines, mut unsupported) = (0, 0, 0);
    let mut failure = None;
    scene
        .lights
        .modify_lights(&mut |id, light| {
            let spd = light.spd();
            let has_lines = spd.is_delta() || (integral_of_density(&*spd) - 1.0).abs() > 1e-6;
            if has_lines {
                lines += 1;
                return;
            }
            match light.set_wavelength_sampling(sampling) {
                Ok(()) => changed += 1,
                Err(spectrace_lights::LightError::Unsupported { .. }) => unsupported += 1,
                Err(e) => failure = Some(format!("lights[{}]: {e}", id.0)),
            }
        })
        .map_err(|e| format!("lights: {e}"))?;
    failure.map_or(Ok((changed, lines, unsupported)), Err)
}

/// The integral of an SPD's density alone (its delta lines excluded): 1 without lines.
pub(super) fn integral_of_density(spd: &dyn SpectralPowerDistribution) -> f64 {
    let (lo, hi) = spd.range();
    spectrace_spectrum::integrate_panels(&|l| spd.value(l), lo, hi, &spd.breakpoints())
}

/// Replaces every light's tabulated SPD by its piecewise-constant counterpart. Returns (lights
/// changed, lights without the hook).
pub(super) fn set_piecewise_constant(scene: &mut Scene) -> Result<(usize, usize), String> {
    let (mut changed, mut unsupported) = (0, 0);
    let mut failure = None;
    scene
        .lights
        .modify_lights(&mut |id, light| match light.map_spd(
            &|spd: &dyn SpectralPowerDistribution| {
                spd.piecewise_constant().map(std::sync::Arc::from)
            },
        ) {
            Ok(true) => changed += 1,
            Ok(false) => {}
            Err(spectrace_lights::LightError::Unsupported { .. }) => unsupported += 1,
            Err(e) => failure = Some(format!("lights[{}]: {e}", id.0)),
        })
        .map_err(|e| format!("lights: {e}"))?;
    failure.map_or(Ok((changed, unsupported)), Err)
}

/// Sets the knobs of `configuration` on the typed scene (the estimator and the effects mode are
/// chosen when rendering, see [`Configuration::integrator`]). Returns what changed (empty for
/// the scene as written), or why the configuration does not apply to the scene.
///
/// # Errors
/// Why the configuration does not apply (e.g. no light with a tabulated SPD).
pub fn apply(configuration: Configuration, scene: &mut Scene) -> Result<String, String> {
    if configuration == Configuration::PathUniformWavelengths {
        if scene.settings.camera_wavelengths == CameraWavelengths::Uniform {
            return Err("the scene already draws camera wavelengths uniformly".to_owned());
        }
        // Independent sampling, as its peer `path` (configuration.rs).
        scene.settings.sampler = SamplerKind::Independent;
        scene.settings.camera_wavelengths = CameraWavelengths::Uniform;
        return Ok("settings.camera_wavelengths = uniform".to_owned());
    }
    if configuration == Configuration::BdptBeam {
        let hero = scene.settings.bdpt_wavelengths == BdptWavelengths::Hero;
        if !(hero && Bdpt::hero_possible(&scene.features()).is_ok()) {
            return Err("BDPT already carries the beam's one wavelength in this scene".to_owned());
        }
        scene.settings.sampler = SamplerKind::Independent;
        scene.settings.bdpt_wavelengths = BdptWavelengths::Beam;
        return Ok("settings.bdpt_wavelengths = beam".to_owned());
    }
    if let Some(sampler) = configuration.sampler() {
        scene.settings.sampler = sampler;
        if sampler == SamplerKind::Sobol {
            return Ok("settings.sampler = sobol".to_owned());
        }
    }
    if let Some(sampling) = configuration.wavelength_sampling() {
        return match set_wavelength_sampling(scene, sampling)? {
            (0, 0, 0) => Err(format!("every light already samples {}", sampling.name())),
            (0, _, 0) => Err("every light's SPD contains delta lines (kept as lines)".to_owned()),
            (0, _, _) => Err("no light offers the wavelength-sampling hook".to_owned()),
            (changed, lines, unsupported) => Ok(lights_changed(changed, lines, unsupported)),
        };
    }
    if configuration == Configuration::PiecewiseConstantSpd {
        return match set_piecewise_constant(scene)? {
            (0, _) => Err("no light has a Tabulated SPD or a tabulated CieIlluminant (nothing \
                 piecewise linear to make piecewise constant)"
                .to_owned()),
            (changed, unsupported) => Ok(lights_changed(changed, 0, unsupported)),
        };
    }
    Ok(String::new())
}
