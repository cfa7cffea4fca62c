//! Effects analysis: which optical effects a scene can produce, and what the tracer may skip.
//!
//! Before rendering, the tracer inspects the scene's materials and shapes:
//!
//! | effect | detected when | what the tracer does |
//! |---|---|---|
//! | dispersion | a material's index depends on wavelength | each beam carries one wavelength |
//! | no dispersion | no such material (and every light colours all its beams by its one spectrum) | paths are wavelength-independent: one traced path carries a *bundle* of `BUNDLE` wavelengths (the same directions, a weight per wavelength), so the variance of the colour falls `BUNDLE` times faster per traced path |
//! | specular surfaces | a mirror or glass exists | specular chains are followed (caustics) |
//! | fluorescence | a material re-emits absorbed light at other wavelengths (`Fluorescent`) | at its vertices paths choose between elastic scattering and re-emission, and a bundle of wavelengths collapses to the re-emitted one; scenes without it skip the choice entirely |
//! | diffuse interreflection | a second bounce can reach a non-specular surface: more than one non-specular shape, a non-flat one, or any specular shape | beams continue after a diffuse hit; otherwise they end there (the light of later bounces can never reach the film) |
//!
//! The decision is printed by the renderer and stored in its output metadata; a scene can
//! override it (`"effects": {"mode": "off"}` simulates everything the general way, `"direct_only"`
//! ends every beam at its first non-specular hit, for quick previews).

use serde::{Deserialize, Serialize};

/// Wavelengths per traced path when no material is dispersive. Colour noise (its variance) then
/// falls `BUNDLE` times faster per traced path.
pub const BUNDLE: usize = 4;

/// What the scene contains, as the analysis sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct SceneFeatures {
    /// Some material's index of refraction depends on wavelength.
    pub dispersive: bool,
    /// Some material is purely specular (mirror, glass).
    pub specular: bool,
    /// Number of shapes with a non-specular material.
    pub non_specular_shapes: usize,
    /// Some light's colour varies between its beams (it does not draw every wavelength from
    /// its one spectrum), so paths cannot carry wavelengths drawn from that spectrum.
    #[serde(default)]
    pub light_spectra_vary: bool,
    /// Some non-specular shape can send light to itself (anything but a flat shape: a sphere
    /// seen from inside, a torus, a mesh, an open cylinder).
    pub non_convex_non_specular: bool,
    /// Lights that say nothing beyond the seed's beam generator (no `flags`, no
    /// `sample_towards`): only the light tracer can render them.
    #[serde(default)]
    pub beam_only_lights: usize,
    /// Lights with a delta position (points, spots, thin lasers): camera paths reach them only
    /// by next-event estimation, so they cannot light a caustic for a camera path.
    #[serde(default)]
    pub delta_position_lights: usize,
    /// Lights with a delta direction (lasers, skies): camera paths reach them only by
    /// next-event estimation, and only those that can be sampled towards a point (not
    /// [`unreachable_lights`](Self::unreachable_lights)), so they cannot light a caustic for a
    /// camera path.
    #[serde(default)]
    pub delta_direction_lights: usize,
    /// Lights with a delta direction that cannot be sampled towards a point (a laser of zero
    /// width: a line no camera path meets), counted among `delta_direction_lights` too: only
    /// light paths find their light.
    #[serde(default)]
    pub unreachable_lights: usize,
    /// Lights with an area (area lights, glowing objects).
    #[serde(default)]
    pub area_lights: usize,
    /// Some light's spectrum has delta lines (camera paths draw wavelengths from a density and
    /// never hit a line).
    #[serde(default)]
    pub line_spectra: bool,
    /// Some material fluoresces (re-emits absorbed light at other wavelengths): integrators
    /// then decide at its vertices between elastic scattering and re-emission. Scenes without
    /// one never draw the uniforms that decision takes.
    #[serde(default)]
    pub fluorescent: bool,
}

/// Which estimator renders the image: `settings.integrator` in a scene file, `--integrator` on
/// the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorChoice {
    /// Let the effects analysis choose (see [`IntegratorChoice::decide`]). The default.
    #[default]
    Auto,
    /// The light tracer: paths from the lights, connected to the camera.
    Light,
    /// The path tracer: paths from the camera with next-event estimation and MIS.
    Path,
    /// Bidirectional path tracing with MIS.
    Bdpt,
}

impl IntegratorChoice {
    /// The name as in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Light => "light",
            Self::Path => "path",
            Self::Bdpt => "bdpt",
        }
    }

    /// Parses a name as in scene files.
    pub fn from_name(name: &str) -> Option<Self> {
        [Self::Auto, Self::Light, Self::Path, Self::Bdpt].into_iter().find(|c| c.name() == name)
    }

    /// The estimator for a scene with `features`: this choice, or for [`IntegratorChoice::Auto`]
    /// the effects analysis' pick, with the reason in words. Never returns `Auto`.
    ///
    /// The rule (measured: see the accuracy report):
    /// - **light** when a light only generates beams (a plugin without `sample_towards` or
    ///   emission densities): no other estimator can use it;
    /// - **path** when every light can be reached from the camera: no laser of zero width, no
    ///   spectral lines, and no point, spot, sky or laser shining on mirrors or glass (its
    ///   caustics);
    /// - otherwise **bdpt** when the scene has mirrors or glass (the light tracer would show
    ///   them black: light paths cannot reach a pinhole through a specular surface, and BDPT's
    ///   camera paths can),
    /// - and **light** for the rest (thin lasers or lines on diffuse scenes): the light
    ///   tracer is BDPT's light-side strategies alone, at a fraction of the cost.
    pub fn decide(self, features: &SceneFeatures) -> (IntegratorChoice, String) {
        if self != Self::Auto {
            return (self, format!("{} (asked for)", self.name()));
        }
        let f = features;
        if f.beam_only_lights > 0 {
            return (
                Self::Light,
                "light: a light only generates beams (no sample_towards), which only the light \
                 tracer can use"
                    .to_owned(),
            );
        }
        let unreachable = if f.unreachable_lights > 0 {
            Some(
                "a laser of zero width (a line no point can sample) is never reached by camera paths",
            )
        } else if f.line_spectra {
            Some("a light has spectral lines, which camera paths cannot sample")
        } else if f.delta_position_lights + f.delta_direction_lights > 0 && f.specular {
            Some(
                "a point, spot, sky or laser shines on mirrors or glass, whose caustics only light \
                 paths find",
            )
        } else {
            None
        };
        if let Some(why) = unreachable {
            return if f.specular {
                (Self::Bdpt, format!("bdpt: {why}, and mirrors or glass need camera paths"))
            } else {
                (Self::Light, format!("light: {why}, and nothing specular needs camera paths"))
            };
        }
        (Self::Path, "path: every light can be reached from the camera".to_owned())
    }
}

/// How the scene asks the analysis to behave.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EffectsMode {
    /// Decide from the scene (the default).
    #[default]
    Auto,
    /// Simulate everything the general way: one wavelength per path, beams continue after
    /// diffuse hits.
    Off,
    /// Direct light only (plus specular chains before the first diffuse hit): a quick preview.
    DirectOnly,
}

/// The analysis' decision: what the tracer does for this scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Effects {
    /// The mode that produced this decision.
    pub mode: EffectsMode,
    /// What was found in the scene.
    pub features: SceneFeatures,
    /// Wavelengths carried by one traced path (1, or [`BUNDLE`] without dispersion).
    pub wavelengths_per_path: usize,
    /// Whether beams continue after their first non-specular hit.
    pub continue_after_diffuse: bool,
}

impl Effects {
    /// Decides from the scene's features and the requested mode.
    pub fn decide(features: SceneFeatures, mode: EffectsMode) -> Self {
        let interreflection = features.non_specular_shapes > 1
            || features.non_convex_non_specular
            || features.specular;
        match mode {
            EffectsMode::Auto => Self {
                mode,
                features,
                wavelengths_per_path: if features.dispersive || features.light_spectra_vary {
                    1
                } else {
                    BUNDLE
                },
                continue_after_diffuse: interreflection,
            },
            EffectsMode::Off => {
                Self { mode, features, wavelengths_per_path: 1, continue_after_diffuse: true }
            }
            EffectsMode::DirectOnly => Self {
                mode,
                features,
                wavelengths_per_path: if features.dispersive || features.light_spectra_vary {
                    1
                } else {
                    BUNDLE
                },
                continue_after_diffuse: false,
            },
        }
    }

    /// One line for people: what was found and what the tracer does.
    pub fn summary(&self) -> String {
        let f = &self.features;
        format!(
            "effects ({mode}): dispersion {}, fluorescence {}, specular surfaces {}, {} \
             non-specular shape(s){}; {} wavelength(s) per path, beams {} after a diffuse hit",
            if f.dispersive { "yes" } else { "no" },
            if f.fluorescent { "yes" } else { "no" },
            if f.specular { "yes" } else { "no" },
            f.non_specular_shapes,
            if f.non_convex_non_specular { " (some can light themselves)" } else { "" },
            self.wavelengths_per_path,
            if self.continue_after_diffuse { "continue" } else { "stop" },
            mode = match self.mode {
                EffectsMode::Auto => "auto",
                EffectsMode::Off => "off",
                EffectsMode::DirectOnly => "direct_only",
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_integrator_follows_the_lights_and_surfaces() {
        let pick = |f: SceneFeatures| IntegratorChoice::Auto.decide(&f).0;
        let area = SceneFeatures { area_lights: 1, non_specular_shapes: 3, ..Default::default() };
        assert_eq!(pick(area), IntegratorChoice::Path);
        assert_eq!(pick(SceneFeatures { specular: true, ..area }), IntegratorChoice::Path);
        let spot = SceneFeatures { delta_position_lights: 1, ..area };
        assert_eq!(pick(spot), IntegratorChoice::Path);
        assert_eq!(pick(SceneFeatures { specular: true, ..spot }), IntegratorChoice::Bdpt);
        // A sky (or a laser of finite width) is reached by next-event estimation, but its
        // caustics are not; a laser of zero width is not reached at all.
        let sky = SceneFeatures { delta_direction_lights: 1, ..area };
        assert_eq!(pick(sky), IntegratorChoice::Path);
        assert_eq!(pick(SceneFeatures { specular: true, ..sky }), IntegratorChoice::Bdpt);
        let thin = SceneFeatures { unreachable_lights: 1, ..sky };
        assert_eq!(pick(thin), IntegratorChoice::Light);
        assert_eq!(pick(SceneFeatures { specular: true, ..thin }), IntegratorChoice::Bdpt);
        let lines = SceneFeatures { line_spectra: true, ..area };
        assert_eq!(pick(lines), IntegratorChoice::Light);
        let plugin = SceneFeatures { beam_only_lights: 1, specular: true, ..area };
        let (choice, why) = IntegratorChoice::Auto.decide(&plugin);
        assert_eq!(choice, IntegratorChoice::Light);
        assert!(why.contains("only generates beams"), "{why}");
        // An explicit choice is kept and says so.
        assert_eq!(
            IntegratorChoice::Bdpt.decide(&area),
            (IntegratorChoice::Bdpt, "bdpt (asked for)".to_owned())
        );
        for c in ["auto", "light", "path", "bdpt"] {
            assert_eq!(IntegratorChoice::from_name(c).map(IntegratorChoice::name), Some(c));
        }
        assert_eq!(IntegratorChoice::from_name("mlt"), None);
    }

    #[test]
    fn decisions_follow_the_features() {
        let plane_only = SceneFeatures { non_specular_shapes: 1, ..Default::default() };
        let e = Effects::decide(plane_only, EffectsMode::Auto);
        assert_eq!((e.wavelengths_per_path, e.continue_after_diffuse), (BUNDLE, false));
        let prism = SceneFeatures {
            dispersive: true,
            specular: true,
            non_specular_shapes: 1,
            ..Default::default()
        };
        let e = Effects::decide(prism, EffectsMode::Auto);
        assert_eq!((e.wavelengths_per_path, e.continue_after_diffuse), (1, true));
        let torus = SceneFeatures {
            non_specular_shapes: 2,
            non_convex_non_specular: true,
            ..Default::default()
        };
        assert!(Effects::decide(torus, EffectsMode::Auto).continue_after_diffuse);
        let off = Effects::decide(plane_only, EffectsMode::Off);
        assert_eq!((off.wavelengths_per_path, off.continue_after_diffuse), (1, true));
        let preview = Effects::decide(torus, EffectsMode::DirectOnly);
        assert!(!preview.continue_after_diffuse);
        assert!(preview.summary().contains("stop after a diffuse hit"));
    }
}
