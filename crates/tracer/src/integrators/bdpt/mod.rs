//! Bidirectional path tracing (Veach 1997, chapter 10; pbrt's `BDPTIntegrator`), with four hero
//! wavelengths per sample where the scene allows it and one elsewhere.
//!
//! # Estimator
//! A camera sample of pixel `p` pairs a *light subpath* with a *camera subpath* and combines every
//! way of joining them, `(s, t)` with `s` light vertices and `t` camera vertices:
//! - the light subpath starts with one beam of the light set ([`LightSource::next_beam`]): its
//!   light `l` (chosen by power), origin, direction and (with one wavelength per sample)
//!   wavelength `lambda` (drawn from the light's SPD), then a random walk
//!   ([`Transport::Importance`]) with Russian roulette;
//! - the camera subpath is a ray through a uniform point of pixel `p` from the pinhole, or from a
//!   uniform point of a thin lens ([`crate::PinholeCamera::generate_ray`]; a pinhole draws no
//!   lens uniforms), then a random walk ([`Transport::Radiance`]);
//! - `s = 0`: the camera subpath hits an emitter ([`LightTracerScene::emitted`]);
//! - `s = 1, t >= 2`: a light point sampled afresh towards the camera vertex
//!   ([`LightSource::sample_towards`]; next-event estimation);
//! - `t = 1`: a light vertex connected to the pinhole, or to a point of the lens sampled towards
//!   it ([`crate::PinholeCamera::sample_wi`]), splatted into the pixel that ray lands in (the
//!   light tracer's estimate);
//! - `s, t >= 2`: a shadow ray between two non-specular vertices.
//!
//! Every strategy is weighted by the power heuristic over all strategies that could have made
//! the same path ([`mis_weight`]), from the area densities each vertex was (or would have been)
//! sampled with from either end.
//!
//! # Wavelengths and units
//! A sample carries either [`HERO`] wavelengths or one.
//!
//! **Hero wavelengths** ([`BdptWavelengths::Hero`], the default, wherever
//! [`Bdpt::hero_possible`]): the camera sample's wavelength uniform (drawn first, with the pixel
//! point) gives four stratified wavelengths from the
//! camera's density `p` ([`CameraWavelengths::sample_hero`], as the path tracer's), shared by
//! both subpaths. The light subpath starts from a beam of the light set (its light `l` chosen by
//! power, `pmf(l) = Phi_l / Phi`; its origin and direction, which for a light with
//! [`LightSource::uniform_spectrum`] do not depend on the beam's wavelength, whose own value
//! and weight are not used), with throughput `Phi_l spd_l(lambda_j) / pmf(l) = Phi
//! spd_l(lambda_j)` per wavelength. Next-event estimation chooses its light by power too and
//! multiplies by its spectrum; a camera path that hits an emitter multiplies by the emitter's.
//! So no density of any vertex depends on the wavelength, and one set of MIS weights serves all
//! four; each wavelength's value is divided by `HERO p(lambda_j)` when it is splatted. A
//! vertex's scattering is sampled by the hero (a bundle, [`spectrace_materials::Material::scatter_bundle`]),
//! and the vertex's densities are evaluated at the hero. This needs a scene where nothing
//! disperses or fluoresces (one path must serve every wavelength) and every light has a
//! continuous spectrum, the same over all its beams.
//!
//! **One wavelength** (elsewhere, or [`BdptWavelengths::Beam`]): the beam's wavelength. Its
//! density is the light set's marginal
//! `p(lambda) = sum_l pmf(l) spd_l(lambda)`, the set's SPD. Given `lambda`, the beam's light was
//! chosen with `pmf(l | lambda) = pmf(l) spd_l(lambda) / p(lambda)`, and next-event estimation
//! (`s = 1`) chooses its light with the same conditional probability (the scene's light sampler,
//! [`crate::PowerLightSampler::sample_given`]), so that both ends agree on
//! the density of a light vertex. Every strategy estimates `cmf(lambda) I(lambda) / p(lambda)`,
//! divided by the integral of `ybar` as in the other integrators:
//! - the light subpath's throughput after emission is `L_e cos / (pmf(l | lambda) p_A p_w
//!   p(lambda)) = Phi * scale` (`Phi` the set's power), since a light's radiance is `Phi_l
//!   spd_l(lambda) p_A p_w / cos` by the definition of its beams;
//! - camera-side emission (`s = 0`) is `L_e spd_l(lambda) / p(lambda)`, and next-event estimation
//!   `intensity / pmf(l)` (the spectra cancel).
//!
//! Lights whose beams use `equal_wavelengths` (beam `scale != 1`) draw `lambda` from another
//! density: with one wavelength, a sample whose beam has such a weight falls back to the light
//! tracer's estimate (every `t = 1` strategy with full weight, no camera strategies). That is
//! exact when every light of the set uses `equal_wavelengths` and only approximate for a mix.
//! The same fallback applies when `p(lambda)` is not positive (a delta line of a line
//! spectrum), which only light paths can reach. Hero samples do not use the beam's weight.
//!
//! # Normalisation
//! A chunk is one *pass*: one sample of every pixel, in pixel order ([`Bdpt::pass_samples`]
//! items), as for the [`crate::PathTracer`]. As the path tracer's, the film holds the estimates
//! divided by the lights' total power `Phi` (the renderer's normalisation of camera integrators,
//! which keeps lights of any power in the film's fixed-point range), normalised per pixel sample:
//! [`crate::Integrator::image_scale`] `= Phi * pixels / samples`. Camera strategies (`t >= 2`) estimate the
//! pixel of their camera sample directly. A `t = 1` connection estimates the pixel it lands in,
//! and one light path is traced per camera sample: a pass traces `pixels` light paths, which
//! together make *one* light-tracing estimate of the whole image (each path's splat divided by
//! the number of paths). So `t = 1` splats are divided by the number of pixels, and after `n`
//! passes every pixel holds the mean of `n` such estimates, as for the camera strategies.
//!
//! The same count enters the MIS weights: the camera's direction density
//! ([`crate::PinholeCamera::pdf_we`], from the vertex's pinhole or lens point) is taken over the
//! whole image, `1 / (A_image cos^3 theta)` with `A_image = width * height * pixel_area`, which is the
//! per-pixel density `1 / (A_pixel cos^3 theta)` of one camera sample compared with `pixels`
//! light paths.
//!
//! # Fluorescence
//! Only light subpaths re-emit ([`spectrace_materials::Fluorescent::choose_forward`], decided
//! at the vertex before any connection, so connections from it use the re-emission lobe at the
//! new wavelength). Camera subpaths scatter at fluorescent surfaces by the elastic part alone:
//! the sample's wavelength comes from the lights' spectra, where a re-emission spectrum
//! usually has no density. A path that re-emitted on its light subpath can then only be
//! joined to the camera (`t = 1`, recorded at the re-emitted wavelength), which is the one
//! strategy that makes it (MIS weight 1). So BDPT renders fluorescent light as the light
//! tracer does: a fluorescent surface seen only through a mirror or glass is missing (the
//! renderer warns; the path tracer re-emits on camera paths and sees it).
//!
//! # Limits
//! `max_depth` counts bounces as the light tracer does: a path has at most `max_depth + 1`
//! scattering vertices (its `max_depth = 0` is direct illumination of the first surface). Lights that do not report their [`LightSource::flags`]
//! are treated as deltas in position and direction (only light subpaths reach them; their
//! `s = 0` and `s = 1` strategies are off). A light's densities come from
//! [`LightSource::pdf_emission`]; a light that does not implement it is given `1 / area` of its
//! [`LightSource::surface`] (1 for a delta position) and its
//! [`LightSource::emission_density`]. The effects analysis' `continue_after_diffuse` is not used:
//! paths always continue.

//!
//! # Layout
//! `vertex` (vertices and the densities between them), `subpath` (the two subpaths and their
//! random walk), `connect` (one function per strategy), `mis` (the weights); this file holds the
//! estimator and its loop over strategies. Every vertex draws its uniforms when it is made
//! (`common::VertexSamples`), and a strategy uses those of the vertex it connects: a light
//! vertex's lens point for `t = 1`, a camera vertex's light sample for `s = 1`.

use std::sync::Arc;

use serde::{Deserialize, Serialize};
use spectrace_lights::LightSource;
use spectrace_spectrum::{SpectralPowerDistribution, Xyz};

use super::common::{CameraSamples, SampleLayout};
use super::pass::{PassEstimator, pixel_of};
use crate::{
    CameraWavelengths, ChunkSampler, Effects, HERO, LightTracerScene, SceneFeatures, Splat,
    TraceStats,
};
use subpath::Buffers;
use vertex::{Lanes, Vertex, Wavelengths};

mod connect;
mod mis;
mod subpath;
#[cfg(test)]
mod tests;
mod vertex;

use mis::MisVertex;

/// Settings of the bidirectional path tracer.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BdptSettings {
    /// Most bounces a path may make (0: only direct illumination of the first surface seen).
    pub max_depth: u32,
    /// Bounces after which Russian roulette may end a subpath.
    pub rr_depth: u32,
    /// For checking the estimator: render only the strategy `(s, t)`, *unweighted* (every
    /// strategy alone estimates all paths it can sample, so strategies of the same path length
    /// give the same image where each can sample every path). Not a scene setting.
    #[serde(skip)]
    pub only_strategy: Option<(usize, usize)>,
    /// How a sample chooses its wavelengths (`settings.bdpt_wavelengths`).
    #[serde(default)]
    pub wavelengths: BdptWavelengths,
    /// The density hero wavelengths are drawn from (`settings.camera_wavelengths`).
    #[serde(default)]
    pub camera_wavelengths: CameraWavelengths,
}

impl Default for BdptSettings {
    fn default() -> Self {
        Self {
            max_depth: 64,
            rr_depth: 4,
            only_strategy: None,
            wavelengths: BdptWavelengths::default(),
            camera_wavelengths: CameraWavelengths::default(),
        }
    }
}

/// How many wavelengths a BDPT sample carries (`settings.bdpt_wavelengths` in scene files).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BdptWavelengths {
    /// [`HERO`] wavelengths from the camera's density, shared by both subpaths, where the
    /// scene allows it ([`Bdpt::carries_hero`]); the beam's one wavelength elsewhere. The
    /// default.
    #[default]
    Hero,
    /// The beam's one wavelength, drawn from the lights' spectrum.
    Beam,
}

impl BdptWavelengths {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Hero => "hero",
            Self::Beam => "beam",
        }
    }
}

/// The bidirectional path tracer as an [`crate::Integrator`]; a work item is one camera sample (with
/// its light path), a chunk one pass over the image.
#[derive(Debug, Clone)]
pub struct Bdpt<'a> {
    scene: &'a LightTracerScene<'a>,
    settings: BdptSettings,
    effects: Effects,
    /// The light set's SPD (the marginal density of a beam's wavelength).
    set_spd: Arc<dyn SpectralPowerDistribution>,
    /// The uniforms of camera-subpath vertices (a light sample for `s = 1`, no re-emission).
    camera_layout: SampleLayout,
    /// The uniforms of light-subpath vertices (re-emission, a lens point for `t = 1`).
    light_layout: SampleLayout,
    /// Whether samples carry [`HERO`] wavelengths ([`Bdpt::carries_hero`]).
    hero: bool,
}

/// A strategy: `s` vertices of the light subpath `light` joined to `t` of the camera
/// subpath `camera`.
#[derive(Debug, Clone, Copy)]
struct Strategy<'v> {
    light: &'v [Vertex],
    camera: &'v [Vertex],
    s: usize,
    t: usize,
}

impl<'a> Bdpt<'a> {
    /// The bidirectional path tracer's [`crate::Integrator::name`].
    pub const NAME: &'static str = "bdpt";

    /// A bidirectional path tracer of `scene` with `settings` (the `effects` decision is kept
    /// for reports; paths always continue after diffuse hits).
    pub fn new(scene: &'a LightTracerScene<'a>, settings: BdptSettings, effects: Effects) -> Self {
        let camera_layout =
            SampleLayout::camera_paths(scene, false, !scene.all_lights().is_empty());
        let light_layout = SampleLayout::light_paths(scene);
        let set_spd = LightSource::spd(scene.lights);
        let hero = settings.wavelengths == BdptWavelengths::Hero
            && Self::hero_possible(&effects.features).is_ok();
        Self { scene, settings, effects, set_spd, camera_layout, light_layout, hero }
    }

    /// Whether a scene with `features` lets BDPT samples carry hero wavelengths, or why not:
    /// nothing disperses or fluoresces (both subpaths must follow one path for all
    /// wavelengths, at the wavelengths the camera drew), and every light can say what it
    /// emits at any wavelength (no spectral lines, one spectrum over its whole surface, flags
    /// for its densities).
    pub fn hero_possible(features: &SceneFeatures) -> Result<(), &'static str> {
        let f = features;
        if f.dispersive {
            Err("a dispersive material sends each wavelength its own way")
        } else if f.fluorescent {
            Err("a fluorescent material changes wavelengths")
        } else if f.line_spectra {
            Err("a light has spectral lines, which drawn wavelengths cannot hit")
        } else if f.light_spectra_vary {
            Err("a light's colour varies over its beams")
        } else if f.beam_only_lights > 0 {
            Err("a light only generates beams")
        } else {
            Ok(())
        }
    }

    /// Whether its samples carry [`HERO`] wavelengths (else the beam's one).
    pub fn carries_hero(&self) -> bool {
        self.hero
    }

    /// Its settings.
    pub fn settings(&self) -> &BdptSettings {
        &self.settings
    }

    /// The effects decision it was given.
    pub fn effects(&self) -> &Effects {
        &self.effects
    }

    /// Pixels in the image: the work items of one pass (one chunk).
    pub fn pass_samples(&self) -> u64 {
        u64::from(self.scene.camera.width()) * u64::from(self.scene.camera.height())
    }

    /// Whether a sample with `beam` at `wl` may use camera strategies: always with hero
    /// wavelengths; with one, a beam of weight 1 at a wavelength the lights' spectrum has a
    /// density for (see the module docs).
    fn camera_strategies(&self, beam: &spectrace_lights::Beam, wl: &Wavelengths) -> bool {
        let weight = LightSource::origin_weight(self.scene.lights, beam);
        wl.is_hero() || (weight == 1.0 && wl.density > 0.0 && wl.density.is_finite())
    }

    /// The sample's wavelengths: [`HERO`] of them from the camera's density, drawn with
    /// `hero_u` (the camera sample's wavelength uniform) when the render carries hero
    /// wavelengths, else the beam's own.
    fn wavelengths(&self, beam_lambda: f64, hero_u: Option<f64>) -> Wavelengths {
        match hero_u {
            Some(u) => {
                let (lambdas, weights) = self.settings.camera_wavelengths.sample_hero(u);
                Wavelengths::hero(lambdas, weights)
            }
            None => Wavelengths::single(beam_lambda, self.set_spd.value(beam_lambda)),
        }
    }

    /// Most vertices of a camera subpath (pinhole included) and of a light subpath.
    fn max_vertices(&self) -> (usize, usize) {
        let d = self.settings.max_depth.min(crate::MAX_DEPTH) as usize;
        (d + 3, d + 2)
    }

    /// One sample of pixel `(px, py)`: camera strategies are added to that pixel, light-tracing
    /// strategies splatted where they land.
    fn sample_pixel(
        &self,
        px: u32,
        py: u32,
        rng: &mut dyn rand::Rng,
        buffers: &mut Buffers,
        film: &mut dyn Splat,
        stats: &mut TraceStats,
    ) {
        let scene = self.scene;
        // The camera sample's uniforms come first, as in the path tracer: the pixel point takes
        // Sobol dimensions 0 and 1 (the best stratified pair) and the hero wavelength a fixed
        // dimension, whatever the beam draws after them.
        let camera_u = CameraSamples::draw(&self.camera_layout, rng);
        let beam = LightSource::next_beam(scene.lights, rng);
        let wl = self.wavelengths(beam.lambda, self.hero.then_some(camera_u.wavelength));
        let camera_strategies = self.camera_strategies(&beam, &wl);
        let Some(light) = self.light_end(beam.parent, &wl) else { return };
        self.light_subpath(&beam, &light, &wl, rng, buffers, stats);
        if camera_strategies {
            self.camera_subpath((px, py), &camera_u, &wl, rng, buffers, stats);
        } else {
            buffers.camera.clear();
            buffers.camera.push(Vertex::camera(scene.camera.position(), wl.lambda()));
        }
        // The film holds values relative to the lights' total power (see `image_scale`).
        let power = scene.lights.power();
        let inv_power = if power > 0.0 { 1.0 / power } else { 0.0 };
        let pixels = self.pass_samples().max(1) as f64;
        let max_len = self.settings.max_depth.min(crate::MAX_DEPTH) as usize + 3;
        let mut radiance: Lanes = [0.0; HERO];
        let Buffers { light: lv, camera: cv, mis } = buffers;
        let t_max = if camera_strategies { cv.len() } else { 1 };
        for t in 1..=t_max {
            for s in 0..=lv.len() {
                if s + t < 2
                    || s + t > max_len
                    || self.settings.only_strategy.is_some_and(|only| only != (s, t))
                {
                    continue;
                }
                let strategy = Strategy { light: lv, camera: cv, s, t };
                let Some(mut c) = self.connect(strategy, &light, &wl, camera_strategies, mis)
                else {
                    continue;
                };
                if self.settings.only_strategy.is_some() {
                    // Unweighted: undo the MIS weight.
                    let undo = if c.weight > 0.0 { 1.0 / c.weight } else { 0.0 };
                    c.value = vertex::scaled(c.value, undo);
                }
                if !vertex::useful(&c.value[..wl.n]) {
                    continue;
                }
                match c.raster {
                    Some((x, y)) => {
                        let k = inv_power / pixels;
                        let value = vertex::scaled(vertex::times(c.value, wl.weights), k);
                        let lambdas = if wl.is_hero() { &wl.lambdas[..] } else { &[c.lambda][..] };
                        // Normalised per pass (the pass's light paths together are one
                        // estimate of the image): the film's pass layer.
                        let xyz = crate::spectral_xyz(lambdas, &value[..wl.n]);
                        if xyz != Xyz::default() && film.splat_pass(x, y, xyz) {
                            stats.splats += 1;
                        }
                    }
                    None => {
                        for (r, v) in radiance.iter_mut().zip(c.value) {
                            *r += v;
                        }
                    }
                }
            }
        }
        let value = vertex::scaled(vertex::times(radiance, wl.weights), inv_power);
        film.splat_spectral(px, py, &wl.lambdas[..wl.n], &value[..wl.n]);
    }
}

impl PassEstimator for Bdpt<'_> {
    const NAME: &'static str = Bdpt::NAME;
    type Scratch = Buffers;

    fn scene(&self) -> &LightTracerScene<'_> {
        self.scene
    }

    /// Its `t = 1` strategies splat light paths to the camera, normalised per pass.
    fn pass_splats(&self) -> bool {
        true
    }

    fn scratch(&self) -> Buffers {
        let (camera_max, light_max) = self.max_vertices();
        Buffers {
            light: Vec::with_capacity(light_max.min(64)),
            camera: Vec::with_capacity(camera_max.min(64)),
            mis: Vec::with_capacity((camera_max + light_max).min(128)),
        }
    }

    /// A sample of the item's pixel, with its light path.
    fn sample(
        &self,
        item: u64,
        buffers: &mut Buffers,
        rng: &mut ChunkSampler,
        film: &mut dyn Splat,
        stats: &mut TraceStats,
    ) {
        let (px, py) = pixel_of(item, u64::from(self.scene.camera.width()));
        self.sample_pixel(px, py, rng, buffers, film, stats);
    }
}
