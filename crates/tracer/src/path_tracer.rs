//! The path tracer: paths from the camera, with next-event estimation and multiple importance
//! sampling (pbrt's `PathIntegrator`, spectral with hero wavelengths).
//!
//! # Estimator
//! A camera sample for pixel `p` is a ray through a uniform point of the pixel (and of the lens),
//! carrying [`HERO`] wavelengths drawn by [`CameraWavelengths`]. At every surface hit `x`:
//! - **Emission**: if `x` emits (an area light's surface or a glowing object), its radiance is
//!   added, weighted by the power heuristic against the density with which next-event
//!   estimation would have chosen `x` (full weight for the camera's own ray and after a specular
//!   bounce, which next-event estimation cannot produce).
//! - **Next-event estimation** (at non-specular surfaces): every delta-position light (points,
//!   spots) once, fully weighted (only this strategy reaches them, and sampling each instead of
//!   choosing one removes the variance of the choice for a shadow ray per light); and one of the
//!   other lights chosen by power among them, a point on it by its `sample_towards`, weighted by
//!   the power heuristic against BSDF sampling.
//! - **BSDF sampling** chooses the next direction ([`spectrace_materials::Transport::Radiance`]:
//!   refraction scales radiance by `(n_i / n_t)^2`); specular chains are followed, so glass and
//!   mirrors show what they reflect and refract.
//! - After `rr_depth` bounces, Russian roulette with survival `min(1, max_j beta_j)`.
//! - **Fluorescence**: at a fluorescent surface the path first chooses between the elastic part
//!   and re-emission ([`spectrace_materials::Fluorescent::choose_adjoint`]). Re-emission draws the
//!   wavelength the light had before it was absorbed from the absorption spectrum, half the time
//!   times the lights' spectrum ([`ExcitationSampler`]: where light is both absorbed and
//!   emitted); every hero
//!   wavelength then *travels* at it (the kernel is separable) while the film still records each
//!   at its own wavelength, and next-event estimation and the next direction use the white
//!   re-emission lobe. Scenes without fluorescent materials never draw the choice's uniforms.
//!
//! The film holds the sum of the samples' XYZ (`sum_j cmf(lambda_j) L_j / (HERO p(lambda_j))`,
//! divided by the integral of `ybar`, as the light tracer's units) relative to the lights' total
//! power; [`Integrator::image_scale`] multiplies by the power and divides by the samples per
//! pixel.
//!
//! # Work items and determinism
//! A work item is one camera sample; a chunk is one *pass*: one sample of every pixel, in pixel
//! order, all drawn from the chunk's own random stream. A pass is never cut short (a time budget
//! stops the render between passes), so every pixel has had the same number of samples and the
//! image is the plain mean, bit-identical for any thread count or shard split.
//!
//! # What it cannot see
//! Lights that have no `sample_towards` (lasers, parallel skies, lights that only implement the
//! seed's beam generator) are never reached by a camera path: their light is missing from a
//! path-traced image. The effects analysis does not choose this integrator for such scenes.

use std::time::Instant;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_geometry::{Hit, Ray};
use spectrace_lights::{LightId, LightSource, uniform};
use spectrace_materials::{
    ExcitationSampler, Material, Reemission, ScatterKind, Transport, reemission_lobe,
};
use spectrace_sampling::Discrete;
use spectrace_spectrum::{CIE_Y_INTEGRAL, Xyz, cmf};

use crate::light_tracer::{LightTracerScene, TraceStats};
use crate::{CameraWavelengths, ChunkSampler, Effects, HERO, Integrator, Splat};

/// Settings of the path tracer.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PathTracerSettings {
    /// Most bounces a path may make, counted as the light tracer counts them: at most
    /// `max_depth + 1` scattering vertices (0: direct light on the first surface the camera sees).
    pub max_depth: u32,
    /// Bounces after which Russian roulette may end a path.
    pub rr_depth: u32,
    /// How camera paths draw their wavelengths.
    pub wavelengths: CameraWavelengths,
}

impl Default for PathTracerSettings {
    fn default() -> Self {
        Self { max_depth: 64, rr_depth: 4, wavelengths: CameraWavelengths::Visible }
    }
}

/// The power heuristic (exponent 2) weight of a strategy with density `a` against one with
/// density `b`.
#[inline]
pub(crate) fn power_heuristic(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if !(a2 > 0.0) {
        return 0.0;
    }
    if !b2.is_finite() {
        return 0.0;
    }
    if !a2.is_finite() {
        return 1.0;
    }
    a2 / (a2 + b2)
}

/// The path tracer as an [`Integrator`]; a work item is one camera sample, a chunk one pass over
/// the image.
#[derive(Debug, Clone)]
pub struct PathTracer<'a> {
    scene: &'a LightTracerScene<'a>,
    settings: PathTracerSettings,
    effects: Effects,
    /// The lights with a delta position (points, spots): next-event estimation samples every
    /// one of them at every vertex (BSDF sampling can never hit them, so there is nothing to
    /// weigh them against, and choosing one at random would only add variance).
    delta_lights: Vec<LightId>,
    /// The light sampler for the other lights (area lights, glowing objects): chosen by power,
    /// `None` when there are none.
    area_lights: Option<(Discrete, Vec<LightId>)>,
    /// Per material (by shape index), for fluorescent ones: the sampler of the wavelength light
    /// had before re-emission, guided by the lights' spectrum (empty without fluorescence).
    excitation: Vec<Option<ExcitationSampler>>,
}

impl<'a> PathTracer<'a> {
    /// The path tracer's [`Integrator::name`].
    pub const NAME: &'static str = "path";

    /// A path tracer of `scene`, following the `effects` decision (interreflection or not).
    pub fn new(
        scene: &'a LightTracerScene<'a>,
        settings: PathTracerSettings,
        effects: Effects,
    ) -> Self {
        let mut delta_lights = Vec::new();
        let (mut ids, mut powers) = (Vec::new(), Vec::new());
        for (i, light) in scene.lights.lights().iter().enumerate() {
            let id = LightId(i as u32);
            match light.flags() {
                Some(f) if f.delta_position && !f.delta_direction => delta_lights.push(id),
                // Lights camera paths cannot reach (delta direction, beam generators only) are
                // left out: the effects analysis does not choose the path tracer for them.
                Some(f) if f.delta_direction => {}
                None => {}
                Some(_) => {
                    ids.push(id);
                    powers.push(light.power());
                }
            }
        }
        let area_lights = Discrete::new(&powers).ok().map(|d| (d, ids));
        let excitation = if scene.materials.iter().any(|m| m.fluorescence().is_some()) {
            let lights = LightSource::spd(scene.lights);
            let spectrum = |l: f64| lights.value(l);
            scene
                .materials
                .iter()
                .map(|m| m.fluorescence().map(|f| f.excitation_sampler(&spectrum)))
                .collect()
        } else {
            Vec::new()
        };
        Self { scene, settings, effects, delta_lights, area_lights, excitation }
    }

    /// Probability with which next-event estimation chooses light `id` among the area lights.
    fn area_pmf(&self, id: LightId) -> f64 {
        self.area_lights
            .as_ref()
            .map_or(0.0, |(d, ids)| ids.iter().position(|&i| i == id).map_or(0.0, |k| d.pmf(k)))
    }

    /// Pixels in the image: the work items of one pass (one chunk).
    pub fn pass_samples(&self) -> u64 {
        u64::from(self.scene.camera.width()) * u64::from(self.scene.camera.height())
    }

    /// The radiance estimate of one camera ray at the path's wavelengths, as XYZ.
    fn sample_pixel(
        &self,
        px: u32,
        py: u32,
        rng: &mut dyn rand::Rng,
        stats: &mut TraceStats,
    ) -> Xyz {
        let camera = self.scene.camera;
        let u_film = [uniform(rng), uniform(rng)];
        let u_lens = if camera.is_pinhole() { [0.5; 2] } else { [uniform(rng), uniform(rng)] };
        let camera_ray = camera.generate_ray(px, py, u_film, u_lens);
        let ray = Ray { origin: camera_ray.origin, direction: camera_ray.direction };
        let (mut lambdas, mut lambda_weights) = self.settings.wavelengths.sample_hero(uniform(rng));
        let radiance = self.radiance(ray, &mut lambdas, &mut lambda_weights, rng, stats);
        let mut xyz = Xyz::default();
        // The film holds radiance relative to the lights' total power (see `image_scale`).
        let inv_y = 1.0 / (*CIE_Y_INTEGRAL * self.scene.lights.power());
        for j in 0..HERO {
            if lambda_weights[j] > 0.0 && radiance[j] != 0.0 {
                xyz += cmf(lambdas[j]) * (radiance[j] * lambda_weights[j] * inv_y);
            }
        }
        xyz
    }

    /// Radiance arriving along `ray` at each of the path's wavelengths (spectral, W m^-2 sr^-1
    /// nm^-1). A dispersive surface collapses the wavelengths to the hero (`lambda_weights[0]`
    /// multiplied by [`HERO`], the others set to 0).
    fn radiance(
        &self,
        mut ray: Ray,
        lambdas: &mut [f64; HERO],
        lambda_weights: &mut [f64; HERO],
        rng: &mut dyn rand::Rng,
        stats: &mut TraceStats,
    ) -> [f64; HERO] {
        let scene = self.scene;
        let mut beta = [1.0; HERO];
        let mut radiance = [0.0; HERO];
        // The previous vertex and the density of the direction that left it, for MIS on
        // emission; `specular` when it was a delta lobe (or the camera).
        let mut prev_point = ray.origin;
        let mut prev_pdf = 0.0;
        let mut specular = true;
        let mut depth = 0u32;
        let mut last_bounce = false;
        let mut collapsed = false;
        // The wavelengths light travels at along the path; they differ from the film's
        // `lambdas` beyond a fluorescent re-emission.
        let mut transport = *lambdas;
        while let Some(hit) = scene.world.intersect(&ray, f64::INFINITY) {
            stats.hits += 1;
            let wo = -ray.direction;
            if let Some((light, le)) = scene.emitted(&hit, wo) {
                let weight = if specular {
                    1.0
                } else {
                    // The scene's density uses the whole set's pmf; next-event estimation
                    // chooses among the area lights only.
                    let set_pmf = scene.lights.pmf(light);
                    let nee = if set_pmf > 0.0 {
                        scene.emitter_pdf(prev_point, &hit) / set_pmf * self.area_pmf(light)
                    } else {
                        0.0
                    };
                    power_heuristic(prev_pdf, nee)
                };
                if weight > 0.0
                    && let Some(spd) = scene.light_spd(light)
                {
                    for j in 0..HERO {
                        if beta[j] != 0.0 {
                            radiance[j] += beta[j] * le * spd.value(transport[j]) * weight;
                        }
                    }
                }
            }
            if last_bounce {
                break;
            }
            let Some(material) = scene.materials.get(hit.primitive as usize) else { break };
            let mut material: &dyn Material = material.as_ref();
            if let Some(fluorescent) = material.fluorescence() {
                // Elastic or re-emitted, decided before next-event estimation so that both it
                // and the BSDF sample use the same lobe at the same wavelength.
                let (u_choice, u_lambda) = (uniform(rng), uniform(rng));
                let guide = self.excitation.get(hit.primitive as usize).and_then(Option::as_ref);
                match fluorescent.choose_adjoint(
                    &mut transport,
                    &mut beta,
                    u_choice,
                    u_lambda,
                    guide,
                ) {
                    Reemission::Elastic => {}
                    Reemission::Reemitted { .. } => {
                        stats.reemissions += 1;
                        material = reemission_lobe();
                    }
                    Reemission::Absorbed => break,
                }
            }
            if material.is_dispersive() && !collapsed {
                // Directions now depend on the wavelength: the hero alone continues.
                collapsed = true;
                lambda_weights[0] *= HERO as f64;
                for j in 1..HERO {
                    lambda_weights[j] = 0.0;
                    beta[j] = 0.0;
                }
            }
            let non_specular = !material.is_specular();
            if non_specular {
                self.next_event(&hit, wo, material, &transport, &beta, &mut radiance, rng, stats);
                if !self.effects.continue_after_diffuse {
                    // No light can come back to a non-specular surface by interreflection: only
                    // an emitter seen by the BSDF-sampled ray remains (for MIS).
                    last_bounce = true;
                }
            }
            if depth >= self.settings.max_depth && !last_bounce {
                // The deepest vertex: one more ray, only for the emission it may hit (the BSDF
                // half of this vertex's MIS pair), as the light tracer's deepest connection.
                stats.depth_limited += 1;
                last_bounce = true;
            }
            let u = [uniform(rng), uniform(rng), uniform(rng)];
            let Some(scattered) = material.scatter_bundle(
                ray.direction,
                hit.shading_normal,
                &transport[..],
                &mut beta,
                u,
                Transport::Radiance,
            ) else {
                break;
            };
            let (direction, kind, pdf) = (scattered.direction, scattered.kind, scattered.pdf);
            specular = kind == ScatterKind::Specular;
            prev_pdf = pdf;
            prev_point = hit.point;
            depth += 1;
            if depth > self.settings.rr_depth && !last_bounce {
                let survive = beta.iter().copied().fold(0.0, f64::max).min(1.0);
                if !(uniform(rng) < survive) {
                    stats.roulette_kills += 1;
                    break;
                }
                for b in &mut beta {
                    *b /= survive;
                }
            }
            if beta.iter().all(|&b| b == 0.0) {
                break;
            }
            ray = hit.spawn_ray(direction);
        }
        radiance
    }

    /// Next-event estimation at a non-specular `hit` seen from `wo`: every delta-position light
    /// (points, spots) once, and one area light chosen by power, weighted by the power heuristic
    /// against BSDF sampling; added to `radiance`.
    #[allow(clippy::too_many_arguments)]
    fn next_event(
        &self,
        hit: &Hit,
        wo: DVec3,
        material: &dyn Material,
        lambdas: &[f64; HERO],
        beta: &[f64; HERO],
        radiance: &mut [f64; HERO],
        rng: &mut dyn rand::Rng,
        stats: &mut TraceStats,
    ) {
        for &id in &self.delta_lights {
            self.connect_light(
                hit,
                wo,
                material,
                lambdas,
                beta,
                radiance,
                id,
                1.0,
                [0.5, 0.5],
                stats,
            );
        }
        if let Some((choice, ids)) = &self.area_lights {
            let (k, u0) = choice.sample_remapped(uniform(rng));
            let u1 = uniform(rng);
            if let Some(&id) = ids.get(k) {
                let pmf = choice.pmf(k);
                self.connect_light(
                    hit,
                    wo,
                    material,
                    lambdas,
                    beta,
                    radiance,
                    id,
                    pmf,
                    [u0, u1],
                    stats,
                );
            }
        }
    }

    /// One light sample of light `id` (chosen with probability `pmf`) seen from `hit`, weighted
    /// by the power heuristic against BSDF sampling (fully for a delta light), added to
    /// `radiance`.
    #[allow(clippy::too_many_arguments)]
    fn connect_light(
        &self,
        hit: &Hit,
        wo: DVec3,
        material: &dyn Material,
        lambdas: &[f64; HERO],
        beta: &[f64; HERO],
        radiance: &mut [f64; HERO],
        id: LightId,
        pmf: f64,
        u: [f64; 2],
        stats: &mut TraceStats,
    ) {
        let scene = self.scene;
        let Some(light) = scene.lights.light(id) else { return };
        let Some(sample) = light.sample_towards(hit.point, u) else { return };
        if !(sample.intensity > 0.0 && pmf > 0.0 && sample.distance > 0.0) {
            return;
        }
        let wi = -sample.direction;
        let n = hit.shading_normal;
        let cos = wi.dot(n).abs();
        if !(cos > 0.0) {
            return;
        }
        let weight = if sample.delta {
            1.0
        } else {
            power_heuristic(pmf * sample.pdf, material.pdf(wo, wi, n, lambdas[0]))
        };
        if !(weight > 0.0) {
            return;
        }
        let (shadow, distance) = hit.spawn_ray_to(sample.position);
        // Stop short of the light's own surface.
        if scene.world.occluded(&shadow, distance * (1.0 - 1e-9)) {
            return;
        }
        stats.splats += 1;
        let Some(spd) = scene.light_spd(id) else { return };
        let g = sample.intensity * cos / (sample.distance * sample.distance * pmf) * weight;
        let mut f = [0.0; HERO];
        material.eval_bundle(wi, wo, n, lambdas, Transport::Radiance, &mut f);
        for j in 0..HERO {
            if beta[j] != 0.0 && f[j] > 0.0 {
                radiance[j] += beta[j] * f[j] * g * spd.value(lambdas[j]);
            }
        }
    }
}

impl PathTracer<'_> {
    /// Point and spot lights seen directly: a camera ray never hits a point, but the pixel a
    /// point light projects into receives its intensity towards the camera times the camera's
    /// importance (a finite pixel value, as the light tracer and BDPT show it). Once per pass,
    /// exactly (the light's colour is its SPD's XYZ integral, not a sampled wavelength), or with
    /// one lens sample per pass for a thin lens.
    fn splat_delta_lights(
        &self,
        rng: &mut dyn rand::Rng,
        film: &mut dyn Splat,
        stats: &mut TraceStats,
    ) {
        let scene = self.scene;
        let camera = scene.camera;
        let inv = 1.0 / (*CIE_Y_INTEGRAL * scene.lights.power());
        for &id in &self.delta_lights {
            let Some(light) = scene.lights.light(id) else { continue };
            let Some(origin) = light.sample_emission([0.5; 4]).map(|e| e.position) else {
                continue;
            };
            let u_lens = if camera.is_pinhole() { [0.5; 2] } else { [uniform(rng), uniform(rng)] };
            let Some(seen) = camera.sample_wi(origin, u_lens) else { continue };
            let density = light.emission_density(origin, seen.to_camera);
            if !(density > 0.0) {
                continue;
            }
            let shadow = Ray { origin, direction: seen.to_camera };
            if scene.world.occluded(&shadow, seen.distance * (1.0 - 1e-9)) {
                continue;
            }
            let Some(spd) = scene.light_spd(id) else { continue };
            let value = light.power() * density * seen.importance * inv;
            if film.splat(seen.x, seen.y, spectrace_spectrum::xyz_of(spd.as_ref()) * value) {
                stats.splats += 1;
            }
        }
    }
}

/// The pixel a pass starts at: the chunk index scrambled (a Fibonacci hash), so that passes of
/// one sample spread over the image.
pub(crate) fn pass_start(chunk: u64, pixels: u64) -> u64 {
    chunk.wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(32) % pixels.max(1)
}

/// The pixel `(x, y)` of item `i` of a pass that starts at pixel `start` (row-major, wrapping),
/// for an image `width` pixels wide of `pixels` pixels: the one mapping of camera estimators.
pub(crate) fn pass_pixel(start: u64, i: u64, pixels: u64, width: u64) -> (u32, u32) {
    let p = (i + start) % pixels.max(1);
    let width = width.max(1);
    ((p % width) as u32, (p / width) as u32)
}

/// The image scale of a camera estimator: the lights' `power` times the `pixels` over the
/// samples done (its film holds estimates relative to the lights' power, one per pixel sample).
pub(crate) fn camera_image_scale(power: f64, pixels: u64, samples_done: u64) -> f64 {
    if samples_done == 0 { 0.0 } else { power * pixels as f64 / samples_done as f64 }
}

impl Integrator for PathTracer<'_> {
    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn resolution(&self) -> (u32, u32) {
        (self.scene.camera.width(), self.scene.camera.height())
    }

    /// One pass: item `i` is a sample of pixel `(i + pass_start(chunk)) mod pixels`
    /// (row-major), so a whole pass (`samples` = the pixel count) samples every pixel once, and
    /// chunks of one item (the pre-render probe) spread over the image. The deadline is not
    /// looked at: a pass is never cut.
    fn render_chunk(
        &self,
        seed: u64,
        chunk: u64,
        samples: u64,
        _deadline: Option<Instant>,
        film: &mut dyn Splat,
    ) -> TraceStats {
        let mut rng = ChunkSampler::new(self.scene.sampler(), seed, chunk);
        let mut stats = TraceStats::default();
        let width = u64::from(self.scene.camera.width().max(1));
        let pixels = self.pass_samples().max(1);
        let start = pass_start(chunk, pixels);
        if samples >= pixels {
            self.splat_delta_lights(&mut rng, film, &mut stats);
        }
        for i in 0..samples {
            let (px, py) = pass_pixel(start, i, pixels, width);
            // Sobol: the pixel's own sequence, one point per pass.
            rng.start_path(u64::from(py) * width + u64::from(px), chunk);
            let xyz = self.sample_pixel(px, py, &mut rng, &mut stats);
            stats.beams += 1;
            // A rejected (non-finite) sample is counted by the film, never added.
            if xyz.x != 0.0 || xyz.y != 0.0 || xyz.z != 0.0 {
                film.splat(px, py, xyz);
            }
        }
        stats
    }

    /// The lights' power times the pixels over the samples: the film holds each sample's
    /// radiance divided by the lights' total power (so that lights of any power keep the exact
    /// film in range), and the image is the mean per pixel.
    fn image_scale(&self, samples_done: u64) -> f64 {
        camera_image_scale(self.scene.lights.power(), self.pass_samples(), samples_done)
    }
}

// ---------------------------------------------------------------------------------------------

/// The path tracer estimating the scene's illuminance sensors by sampling points on them (no
/// image): a work item is one sample of one sensor cell, a chunk one pass over every cell of
/// every sensor.
///
/// # Estimator
/// At a point `x` drawn uniformly in the cell, with the sensor's front normal `n`, the
/// irradiance is `E = integral of L_i(x, w) (w . n) dw` over the front hemisphere. Point and
/// spot lights (which no ray can hit) add exactly `I(w) cos / d^2` when visible; everything else
/// arrives along one cosine-weighted direction, `E = pi L` in expectation, with `L` the path
/// tracer's radiance estimate along that ray (emitters it hits count fully, since nothing else
/// samples them at `x`). Wavelengths are drawn from the lights' own spectrum, [`HERO`] of them
/// stratified, each weighted by one over its density, so the radiant and the luminous sums are
/// both unbiased over the lights' whole range. The sensor blocks nothing: rays start at `x`.
/// The film keeps `E x cell area / P` per sample (`P` the lights' power) in the cell's
/// `[radiant, luminous, luminous^2]`, so that the light tracer's normalisation (`P / N / area`,
/// with `N` the passes) gives the mean irradiance.
#[derive(Debug, Clone)]
pub struct SensorPathTracer<'a> {
    tracer: PathTracer<'a>,
    sensors: &'a crate::SensorSet,
    /// The lights' spectrum, which the wavelengths are drawn from.
    spectrum: std::sync::Arc<dyn spectrace_spectrum::SpectralPowerDistribution>,
}

impl<'a> SensorPathTracer<'a> {
    /// Its [`Integrator::name`].
    pub const NAME: &'static str = "path (sensors)";

    /// The path tracer `tracer`, estimating `sensors`.
    pub fn new(tracer: PathTracer<'a>, sensors: &'a crate::SensorSet) -> Self {
        let spectrum = LightSource::spd(tracer.scene.lights);
        Self { tracer, sensors, spectrum }
    }

    /// One sample of the cell `cell` (numbered over all sensors): `[radiant, luminous]`
    /// irradiance times the cell's area over the lights' power.
    fn sample_cell(&self, cell: u32, rng: &mut dyn rand::Rng, stats: &mut TraceStats) -> [f64; 2] {
        let scene = self.tracer.scene;
        let sensors = self.sensors.sensors();
        let Some(index) = (0..sensors.len()).rev().find(|&i| self.sensors.offset(i) <= cell) else {
            return [0.0; 2];
        };
        let sensor = &sensors[index];
        let local = cell - self.sensors.offset(index);
        let [nu, nv] = sensor.cells();
        let (iu, iv) = (local % nu, local / nu);
        let (a, b) = (uniform(rng), uniform(rng));
        let x = sensor.corner()
            + sensor.edge_u() * ((f64::from(iu) + a) / f64::from(nu))
            + sensor.edge_v() * ((f64::from(iv) + b) / f64::from(nv));
        let n = sensor.front();
        // Wavelengths from the lights' spectrum, stratified.
        let u = uniform(rng);
        let mut lambdas = [0.0; HERO];
        let mut weights = [0.0; HERO];
        for j in 0..HERO {
            let stratum = ((j as f64 + u) / HERO as f64).min(spectrace_sampling::ONE_MINUS_EPSILON);
            let lambda = self.spectrum.sample_lambda(stratum);
            let q = self.spectrum.value(lambda);
            lambdas[j] = lambda;
            weights[j] = if q > 0.0 { 1.0 / (HERO as f64 * q) } else { 0.0 };
        }
        let mut irradiance = [0.0; HERO];
        // Point and spot lights, exactly.
        for &id in &self.tracer.delta_lights {
            let Some(light) = scene.lights.light(id) else { continue };
            let Some(s) = light.sample_towards(x, [0.5, 0.5]) else { continue };
            let cos = -s.direction.dot(n);
            if !(cos > 0.0 && s.intensity > 0.0) {
                continue;
            }
            let shadow = Ray { origin: s.position, direction: s.direction };
            if scene.world.occluded(&shadow, s.distance * (1.0 - 1e-9)) {
                continue;
            }
            let Some(spd) = scene.light_spd(id) else { continue };
            let e = s.intensity * cos / (s.distance * s.distance);
            for j in 0..HERO {
                irradiance[j] += e * spd.value(lambdas[j]);
            }
        }
        // Everything else along one cosine-weighted direction: E = pi L.
        let local_dir = spectrace_sampling::sample_cosine_hemisphere([uniform(rng), uniform(rng)]);
        let direction = spectrace_sampling::Frame::from_normal(n).to_world(local_dir).normalize();
        let ray = Ray { origin: x, direction };
        let radiance = self.tracer.radiance(ray, &mut lambdas, &mut weights, rng, stats);
        for j in 0..HERO {
            irradiance[j] += std::f64::consts::PI * radiance[j];
        }
        let scale = sensor.cell_area() / LightSource::power(scene.lights);
        let (mut radiant, mut luminous) = (0.0, 0.0);
        for j in 0..HERO {
            if weights[j] > 0.0 && irradiance[j] != 0.0 {
                radiant += irradiance[j] * weights[j];
                luminous +=
                    irradiance[j] * weights[j] * spectrace_spectrum::lumens_per_watt(lambdas[j]);
            }
        }
        [radiant * scale, luminous * scale]
    }
}

impl Integrator for SensorPathTracer<'_> {
    fn name(&self) -> &'static str {
        Self::NAME
    }

    /// No image: a film of one pixel, which stays black.
    fn resolution(&self) -> (u32, u32) {
        (1, 1)
    }

    /// One pass: item `i` samples cell `(i + pass_start(chunk)) mod cells`.
    fn render_chunk(
        &self,
        seed: u64,
        chunk: u64,
        samples: u64,
        _deadline: Option<Instant>,
        film: &mut dyn Splat,
    ) -> TraceStats {
        let mut rng = ChunkSampler::new(self.tracer.scene.sampler(), seed, chunk);
        let mut stats = TraceStats::default();
        let cells = u64::from(self.sensors.total_cells()).max(1);
        let start = pass_start(chunk, cells);
        for i in 0..samples {
            let cell = ((i + start) % cells) as u32;
            rng.start_path(u64::from(cell), chunk);
            let [radiant, luminous] = self.sample_cell(cell, &mut rng, &mut stats);
            stats.beams += 1;
            if radiant != 0.0 || luminous != 0.0 {
                film.splat_sensor(cell, [radiant, luminous, luminous * luminous]);
            }
        }
        stats
    }

    fn image_scale(&self, samples_done: u64) -> f64 {
        camera_image_scale(
            LightSource::power(self.tracer.scene.lights),
            u64::from(self.sensors.total_cells()),
            samples_done,
        )
    }

    fn sensor_cells(&self) -> u32 {
        self.sensors.total_cells()
    }
}
