//! The light tracer (seed section 2.4.4): beams from the lights, followed through the scene, every
//! non-specular hit connected to the camera.
//!
//! # Estimator
//! A beam of power `P_b = Phi / N * scale` (the light's power over the beams of the whole render)
//! that reaches a non-specular surface point `x` from direction `wi` adds, to the pixel `x`
//! projects into, the estimate `P_b * f(wi, wo) * cos(theta_x) * importance` of the pixel's mean
//! spectral radiance (see [`crate::PinholeCamera`] for `importance`), weighted by the CIE 1931
//! functions at the beam's wavelength and divided by the integral of `ybar`: the film's XYZ, in
//! which a constant spectral radiance of 1 W m^-2 sr^-1 nm^-1 gives `Y = 1`. The beam then
//! continues by sampling the material (its weight multiplied by `f cos / pdf`); mirrors and glass
//! reflect and refract it, so caustics and dispersion appear. After `rr_depth` bounces Russian
//! roulette ends a beam with probability `1 - min(1, weight)` and divides survivors by the
//! survival probability, which keeps the estimator unbiased.
//!
//! The film accumulates the contributions without the factor `Phi / N`; [`image_scale`] gives it.
//!
//! # Determinism
//! Work comes in chunks of beams; chunk `c` draws all its random numbers from a generator seeded
//! by `(seed, c)`, and the film adds in exact fixed point, so an image depends only on the seed
//! and the chunks rendered, never on thread count or order.

use std::sync::Arc;
use std::time::Instant;

use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use serde::{Deserialize, Serialize};
use spectrace_geometry::{Ray, World};
use spectrace_lights::{LightId, LightSet, LightSource, uniform};
use spectrace_materials::{Material, Reemission, Transport, reemission_lobe};

/// The factor that makes particle (importance) transport exact with shading normals:
/// `|wi . n_s| |wo . n_g| / (|wi . n_g| |wo . n_s|)`, 1 where the normals agree (Veach 1997,
/// section 5.3). `wi` points back to where the particle came from, `wo` where it goes.
pub(crate) fn shading_correction(hit: &spectrace_geometry::Hit, wi: DVec3, wo: DVec3) -> f64 {
    let (ns, ng) = (hit.shading_normal, hit.geometric_normal);
    if ns == ng {
        return 1.0;
    }
    let denominator = wi.dot(ng).abs() * wo.dot(ns).abs();
    if denominator > 0.0 { wi.dot(ns).abs() * wo.dot(ng).abs() / denominator } else { 0.0 }
}
use spectrace_spectrum::{CIE_Y_INTEGRAL, SpectralPowerDistribution, cmf};

use crate::{ChunkSampler, Effects, PinholeCamera, SamplerKind, SceneFeatures, SensorSet, Splat};
use spectrace_spectrum::lumens_per_watt;

/// Largest `max_depth` a scene may ask for (the renderer refuses more; the tracer clamps
/// nothing). Russian roulette ends almost every beam long before: only a lossless closed scene
/// (mirrors or white walls all round) keeps beams going, and there a path that keeps even 99.9%
/// of its power per bounce has kept 4.5e-5 of it after 10,000 bounces, so deeper paths add
/// nothing visible. The bound also keeps one beam short (10,000 bounces take about 3 ms), which
/// is the granularity at which a time budget and the pre-render probe can stop.
pub const MAX_DEPTH: u32 = 10_000;

/// Work units (beams and surface hits) traced between two looks at the clock when a chunk has
/// a deadline: a few microseconds of work, so the look (~25 ns) costs under 1%.
const DEADLINE_CHECK_WORK: u64 = 64;

/// Settings of the light tracer.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightTracerSettings {
    /// Most bounces a beam may make (0: only direct illumination of the first surface hit);
    /// scenes may ask for at most [`MAX_DEPTH`].
    pub max_depth: u32,
    /// Bounces after which Russian roulette may end a beam.
    pub rr_depth: u32,
}

impl Default for LightTracerSettings {
    fn default() -> Self {
        Self { max_depth: 64, rr_depth: 4 }
    }
}

/// What a light tracer traces: geometry, one material per shape, the lights and the camera.
#[derive(Debug, Clone)]
pub struct LightTracerScene<'a> {
    /// All shapes, in one BVH.
    pub world: &'a World,
    /// The material of each shape, indexed like the shapes given to the world.
    pub materials: &'a [Arc<dyn Material>],
    /// The lights the beams come from.
    pub lights: &'a LightSet,
    /// The camera that receives the connections.
    pub camera: &'a PinholeCamera,
    /// The spectrum of each light of the set, cached (bundled wavelengths are drawn from the
    /// spectrum of the beam's own light).
    spds: Vec<Arc<dyn SpectralPowerDistribution>>,
    /// What each shape emits, indexed like `materials` (empty: nothing emits).
    emitters: Vec<Option<Emitter>>,
    /// The shape that is the surface of each light of the set, if any.
    light_shapes: Vec<Option<u32>>,
    /// How many of the shapes are the scene's objects (the first ones); the rest are the
    /// surfaces of area lights, which the effects analysis does not count.
    object_shapes: usize,
    /// Where the integrators' random numbers come from.
    sampler: SamplerKind,
    /// The illuminance sensors the light paths fill (see [`crate::IrradianceSensor`]).
    sensors: Option<&'a SensorSet>,
    /// Fill only the sensors: no connections to the camera (a sensor pass beside a camera
    /// integrator's image).
    sensors_only: bool,
}

/// Light leaving a shape's surface: which light of the set it belongs to, so that camera paths
/// that hit the shape see it and weigh it against next-event estimation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Emitter {
    /// The surface of an area light of the set (see [`spectrace_lights::LightSource::surface`]):
    /// its radiance is the light's [`spectrace_lights::LightSource::emitted_radiance`].
    Light(LightId),
    /// An object made to glow (`objects[i].emission`): a Lambertian emitter of `radiance`
    /// (W m^-2 sr^-1, whole spectrum: times the light's SPD) on the outward side of its
    /// geometric normal (both sides when `two_sided`), sampled uniformly over its `area` (m^2)
    /// by light `light` of the set.
    Object {
        /// The light of the set that emits beams from this shape.
        light: LightId,
        /// Radiance (whole spectrum).
        radiance: f64,
        /// Whether both sides emit.
        two_sided: bool,
        /// Area (m^2).
        area: f64,
    },
}

impl Emitter {
    /// The light of the set this emitter belongs to.
    pub fn light(&self) -> LightId {
        match *self {
            Emitter::Light(id) | Emitter::Object { light: id, .. } => id,
        }
    }
}

impl<'a> LightTracerScene<'a> {
    /// Assembles a scene.
    pub fn new(
        world: &'a World,
        materials: &'a [Arc<dyn Material>],
        lights: &'a LightSet,
        camera: &'a PinholeCamera,
    ) -> Self {
        let spds = lights.lights().iter().map(|l| l.spd()).collect();
        Self {
            world,
            materials,
            lights,
            camera,
            spds,
            emitters: Vec::new(),
            light_shapes: Vec::new(),
            object_shapes: materials.len(),
            sampler: SamplerKind::Independent,
            sensors: None,
            sensors_only: false,
        }
    }

    /// The same scene with illuminance sensors, which the light tracer fills (through
    /// [`Splat::splat_sensor`], into cells after the film's pixels: see
    /// [`crate::Film::with_sensor_cells`]).
    pub fn with_sensors(mut self, sensors: &'a SensorSet) -> Self {
        self.sensors = (!sensors.is_empty()).then_some(sensors);
        self
    }

    /// The same scene traced for its sensors only: beams are not connected to the camera, so
    /// the image stays black and the sensors fill at less cost.
    pub fn sensors_only(mut self) -> Self {
        self.sensors_only = true;
        self
    }

    /// The scene's sensors (none if it has none).
    pub fn sensors(&self) -> Option<&'a SensorSet> {
        self.sensors
    }

    /// The same scene, rendered with random numbers from `sampler`.
    pub fn with_sampler(mut self, sampler: SamplerKind) -> Self {
        self.sampler = sampler;
        self
    }

    /// Where the integrators' random numbers come from.
    pub fn sampler(&self) -> SamplerKind {
        self.sampler
    }

    /// The same scene where shape `i` emits `emitters[i]` (missing entries emit nothing), and
    /// only the first `object_shapes` shapes are the scene's objects (the rest are the surfaces
    /// of area lights).
    pub fn with_emitters(mut self, emitters: Vec<Option<Emitter>>, object_shapes: usize) -> Self {
        let mut light_shapes = vec![None; self.lights.lights().len()];
        for (shape, e) in emitters.iter().enumerate() {
            if let Some(e) = e
                && let Some(slot) = light_shapes.get_mut(e.light().0 as usize)
            {
                *slot = Some(shape as u32);
            }
        }
        self.light_shapes = light_shapes;
        self.emitters = emitters;
        self.object_shapes = object_shapes.min(self.materials.len());
        self
    }

    /// The first hit of a ray that starts on the surface of light `light` (a beam's emission
    /// point): a hit of the light's own surface within rounding distance of the start is the
    /// start itself, and is skipped by continuing from it with the geometry's robust offset.
    pub fn intersect_from_light(
        &self,
        ray: &Ray,
        light: LightId,
        t_max: f64,
    ) -> Option<spectrace_geometry::Hit> {
        let hit = self.world.intersect(ray, t_max)?;
        let own = self.light_shapes.get(light.0 as usize).copied().flatten();
        let scale = 1.0 + ray.origin.abs().max_element();
        if own == Some(hit.primitive) && hit.t <= 1e-9 * scale {
            let next = hit.spawn_ray(ray.direction);
            let travelled = (next.origin - ray.origin).length();
            return self.world.intersect(&next, t_max - travelled);
        }
        Some(hit)
    }

    /// What shape `primitive` emits.
    #[inline]
    pub fn emitter(&self, primitive: u32) -> Option<&Emitter> {
        self.emitters.get(primitive as usize).and_then(Option::as_ref)
    }

    /// The spectrum of light `id` of the set.
    #[inline]
    pub fn light_spd(&self, id: LightId) -> Option<&Arc<dyn SpectralPowerDistribution>> {
        self.spds.get(id.0 as usize)
    }

    /// Radiance (whole spectrum; times the light's SPD) leaving `hit` towards the unit
    /// `direction`, with the light it belongs to; `None` where the shape does not emit.
    pub fn emitted(
        &self,
        hit: &spectrace_geometry::Hit,
        direction: DVec3,
    ) -> Option<(LightId, f64)> {
        let emitter = self.emitter(hit.primitive)?;
        let radiance = match *emitter {
            Emitter::Light(id) => self.lights.light(id)?.emitted_radiance(hit.point, direction),
            Emitter::Object { radiance, two_sided, .. } => {
                let c = direction.dot(hit.geometric_normal);
                if c > 0.0 || (two_sided && c < 0.0) { radiance } else { 0.0 }
            }
        };
        (radiance > 0.0).then_some((emitter.light(), radiance))
    }

    /// Solid-angle density (at `receiver`) with which next-event estimation (light chosen by
    /// [`LightSet::sample_light`], then its `sample_towards`) picks the emitting point `hit`.
    pub fn emitter_pdf(&self, receiver: DVec3, hit: &spectrace_geometry::Hit) -> f64 {
        let Some(emitter) = self.emitter(hit.primitive) else { return 0.0 };
        let pmf = self.lights.pmf(emitter.light());
        match *emitter {
            Emitter::Light(id) => {
                self.lights.light(id).map_or(0.0, |l| pmf * l.pdf_towards(receiver, hit.point))
            }
            Emitter::Object { area, .. } => {
                let to = receiver - hit.point;
                let d2 = to.length_squared();
                let cos = (to.dot(hit.geometric_normal) / d2.sqrt()).abs();
                if cos > 0.0 && area > 0.0 { pmf * d2 / (area * cos) } else { 0.0 }
            }
        }
    }

    /// What the scene contains, for the effects analysis.
    pub fn features(&self, shapes_non_convex: &[bool]) -> SceneFeatures {
        let mut f = SceneFeatures {
            light_spectra_vary: self.lights.lights().iter().any(|l| !l.uniform_spectrum()),
            ..SceneFeatures::default()
        };
        for light in self.lights.lights() {
            match light.flags() {
                None => f.beam_only_lights += 1,
                Some(flags) if flags.delta_direction => f.delta_direction_lights += 1,
                Some(flags) if flags.delta_position => f.delta_position_lights += 1,
                Some(_) => f.area_lights += 1,
            }
            let spd = light.spd();
            let (lo, hi) = spd.range();
            f.line_spectra |= !(hi > lo)
                || (spectrace_spectrum::integrate_panels(
                    &|l| spd.value(l),
                    lo,
                    hi,
                    &spd.breakpoints(),
                ) - 1.0)
                    .abs()
                    > 1e-6;
        }
        for (i, m) in self.materials.iter().enumerate().take(self.object_shapes) {
            f.dispersive |= m.is_dispersive();
            f.fluorescent |= m.fluorescence().is_some();
            if m.is_specular() {
                f.specular = true;
            } else {
                f.non_specular_shapes += 1;
                f.non_convex_non_specular |= shapes_non_convex.get(i).copied().unwrap_or(true);
            }
        }
        f
    }
}

/// Counters of one chunk (or a whole render, summed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct TraceStats {
    /// Beams emitted.
    pub beams: u64,
    /// Surface hits.
    pub hits: u64,
    /// Connections to the camera that reached the film.
    pub splats: u64,
    /// Beams ended by Russian roulette.
    pub roulette_kills: u64,
    /// Beams that reached `max_depth`.
    pub depth_limited: u64,
    /// Fluorescent re-emissions (a path continuing at a new wavelength).
    #[serde(default)]
    pub reemissions: u64,
}

impl TraceStats {
    /// Adds another chunk's counters.
    pub fn merge(&mut self, o: &TraceStats) {
        self.beams += o.beams;
        self.hits += o.hits;
        self.splats += o.splats;
        self.roulette_kills += o.roulette_kills;
        self.depth_limited += o.depth_limited;
        self.reemissions += o.reemissions;
    }
}

/// The generator of chunk `chunk` of a render with seed `seed` (SplitMix64 of both, so nearby
/// seeds and chunks give unrelated streams).
pub fn chunk_rng(seed: u64, chunk: u64) -> Pcg64 {
    let mut z = seed ^ chunk.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    Pcg64::seed_from_u64(z ^ (z >> 31))
}

/// The factor that turns film sums into the image: the lights' power over the beams of the
/// whole render.
pub fn image_scale(light_power: f64, total_beams: u64) -> f64 {
    if total_beams == 0 { 0.0 } else { light_power / total_beams as f64 }
}

/// Traces `beams` beams of chunk `chunk` into `film` (a [`crate::Film`] or a
/// [`crate::FilmWriter`]), following `effects`.
pub fn trace_chunk<S: Splat + ?Sized>(
    scene: &LightTracerScene<'_>,
    settings: &LightTracerSettings,
    effects: &Effects,
    seed: u64,
    chunk: u64,
    beams: u64,
    film: &mut S,
) -> TraceStats {
    trace_chunk_until(scene, settings, effects, seed, chunk, beams, None, film)
}

/// As [`trace_chunk`], but stops early once `deadline` has passed: the clock is read every few
/// microseconds of work, between beams (a beam is never cut), and at least one beam is traced.
/// The returned `stats.beams` is the number of beams traced, which the image's normalisation
/// must use; the beams traced are the first ones of the chunk's random stream.
#[allow(clippy::too_many_arguments)]
pub fn trace_chunk_until<S: Splat + ?Sized>(
    scene: &LightTracerScene<'_>,
    settings: &LightTracerSettings,
    effects: &Effects,
    seed: u64,
    chunk: u64,
    beams: u64,
    deadline: Option<Instant>,
    film: &mut S,
) -> TraceStats {
    let mut rng = ChunkSampler::new(scene.sampler, seed, chunk);
    let mut stats = TraceStats::default();
    let inv_y = 1.0 / *CIE_Y_INTEGRAL;
    let k = effects.wavelengths_per_path.clamp(1, MAX_BUNDLE);
    let light: &dyn LightSource = scene.lights;
    let mut next_check = DEADLINE_CHECK_WORK;
    for i in 0..beams {
        if let Some(deadline) = deadline {
            let work = stats.beams + stats.hits;
            if work >= next_check {
                next_check = work + DEADLINE_CHECK_WORK;
                if Instant::now() >= deadline {
                    break;
                }
            }
        }
        rng.start_path(chunk, i);
        let beam = light.next_beam(&mut rng);
        stats.beams += 1;
        // The bundle: the beam's own wavelength and weight, plus k - 1 wavelengths drawn from the
        // spectrum of the beam's light, each an independent estimate; all share the path.
        let mut lambdas = [beam.lambda; MAX_BUNDLE];
        let mut weights = [0.0; MAX_BUNDLE];
        weights[0] = beam.scale / k as f64;
        if k > 1 {
            // Drawn as the light draws its companions (its SPD, or SPD x observer), with the
            // weight of that density.
            let own = scene.lights.light(beam.parent);
            for j in 1..k {
                // Stratified: one uniform per stratum of [0, 1).
                let u = ((j - 1) as f64 + uniform(&mut rng)) / (k - 1) as f64;
                let u = u.min(spectrace_sampling::ONE_MINUS_EPSILON);
                let (lambda, scale) = own.map_or((beam.lambda, 0.0), |l| l.sample_wavelength(u));
                lambdas[j] = lambda;
                weights[j] = scale / k as f64;
            }
        }
        // Lights seen directly: connect the emission point to the camera.
        if !scene.sensors_only
            && let Some((x, y, value)) =
                connect_emission(scene, &beam, lens_uniforms(scene, &mut rng))
        {
            let mut xyz = spectrace_spectrum::Xyz::default();
            for j in 0..k {
                xyz += cmf(lambdas[j]) * (weights[j] * value * inv_y);
            }
            if film.splat(x, y, xyz) {
                stats.splats += 1;
            }
        }
        let mut ray = Ray { origin: beam.origin, direction: beam.direction };
        let mut depth = 0u32;
        let mut next_hit = scene.intersect_from_light(&ray, beam.parent, f64::INFINITY);
        if let Some(sensors) = scene.sensors {
            let reach = next_hit.as_ref().map_or(f64::INFINITY, |h| h.t);
            fill_sensors(sensors, &ray, reach, &lambdas[..k], &weights[..k], film);
        }
        while let Some(hit) = next_hit.take() {
            stats.hits += 1;
            let Some(material) = scene.materials.get(hit.primitive as usize) else { break };
            let mut material: &dyn Material = material.as_ref();
            if let Some(fluorescent) = material.fluorescence() {
                // Elastic or re-emitted, decided before the camera connection so that both use
                // the same lobe; re-emission collapses the bundle to one new wavelength.
                let (u_choice, u_lambda) = (uniform(&mut rng), uniform(&mut rng));
                match fluorescent.choose_forward(
                    &mut lambdas[..k],
                    &mut weights[..k],
                    u_choice,
                    u_lambda,
                ) {
                    Reemission::Elastic => {}
                    Reemission::Reemitted { .. } => {
                        stats.reemissions += 1;
                        material = reemission_lobe();
                    }
                    Reemission::Absorbed => break,
                }
            }
            let specular = material.is_specular();
            if !specular {
                if !scene.sensors_only
                    && let Some((x, y, value)) = connect_to_camera(
                        scene,
                        material,
                        &hit,
                        ray.direction,
                        &lambdas[..k],
                        lens_uniforms(scene, &mut rng),
                    )
                {
                    let mut xyz = spectrace_spectrum::Xyz::default();
                    for j in 0..k {
                        xyz += cmf(lambdas[j]) * (weights[j] * value[j] * inv_y);
                    }
                    if film.splat(x, y, xyz) {
                        stats.splats += 1;
                    }
                }
                // With sensors, light leaving the only diffuse surface may still cross one
                // (unless the user asked for direct light only).
                if !effects.continue_after_diffuse
                    && (scene.sensors.is_none() || effects.mode == crate::EffectsMode::DirectOnly)
                {
                    break;
                }
            }
            if depth >= settings.max_depth {
                stats.depth_limited += 1;
                break;
            }
            let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
            // One scatter for the whole bundle: without dispersion every wavelength takes the
            // same direction, each with its own weight; a wavelength the surface absorbs drops
            // out alone, and a dispersive surface keeps only the first live one.
            let Some(scattered) = material.scatter_bundle(
                ray.direction,
                hit.shading_normal,
                &lambdas[..k],
                &mut weights[..k],
                u,
                Transport::Importance,
            ) else {
                break;
            };
            let new_direction = scattered.direction;
            // Shading normals: the adjoint correction for particles (Veach 1997, section 5.3).
            let correction = shading_correction(&hit, -ray.direction, new_direction);
            for w in &mut weights[..k] {
                *w *= correction;
            }
            depth += 1;
            if depth > settings.rr_depth {
                // The bundle's weights sum to the path's throughput relative to its start.
                let survive = weights[..k].iter().sum::<f64>().min(1.0);
                if !(uniform(&mut rng) < survive) {
                    stats.roulette_kills += 1;
                    break;
                }
                for w in &mut weights[..k] {
                    *w /= survive;
                }
            }
            if weights[..k].iter().all(|&w| w <= 0.0) {
                break;
            }
            ray = hit.spawn_ray(new_direction);
            next_hit = scene.world.intersect(&ray, f64::INFINITY);
            if let Some(sensors) = scene.sensors {
                let reach = next_hit.as_ref().map_or(f64::INFINITY, |h| h.t);
                fill_sensors(sensors, &ray, reach, &lambdas[..k], &weights[..k], film);
            }
        }
    }
    stats
}

/// Adds a path segment's bundle to every sensor cell it crosses on the front side: the radiant
/// weight, the luminous weight (times `683 ybar`) and its square.
#[inline]
fn fill_sensors<S: Splat + ?Sized>(
    sensors: &SensorSet,
    ray: &Ray,
    reach: f64,
    lambdas: &[f64],
    weights: &[f64],
    film: &mut S,
) {
    sensors.crossings(ray.origin, ray.direction, reach, |cell| {
        let radiant: f64 = weights.iter().sum();
        let luminous: f64 =
            lambdas.iter().zip(weights).map(|(&l, &w)| w * lumens_per_watt(l)).sum();
        film.splat_sensor(cell, [radiant, luminous, luminous * luminous]);
    });
}

/// Uniforms for a point on the camera's lens: none are drawn for a pinhole (so pinhole images do
/// not depend on whether the camera could have a lens).
fn lens_uniforms(scene: &LightTracerScene<'_>, rng: &mut ChunkSampler) -> [f64; 2] {
    if scene.camera.is_pinhole() { [0.5; 2] } else { [uniform(rng), uniform(rng)] }
}

/// Largest wavelength bundle a path can carry.
const MAX_BUNDLE: usize = 8;

/// The connection of an emission point to the camera: pixel and `density * importance`, or
/// `None` when the light does not emit that way, the point is outside the image, or occluded.
fn connect_emission(
    scene: &LightTracerScene<'_>,
    beam: &spectrace_lights::Beam,
    u_lens: [f64; 2],
) -> Option<(u32, u32, f64)> {
    let light = scene.lights.light(beam.parent)?;
    let projection = scene.camera.sample_wi(beam.origin, u_lens)?;
    let density = light.emission_density(beam.origin, projection.to_camera);
    if !(density > 0.0) {
        return None;
    }
    let shadow = Ray { origin: beam.origin, direction: projection.to_camera };
    if scene.intersect_from_light(&shadow, beam.parent, projection.distance).is_some() {
        return None;
    }
    Some((projection.x, projection.y, density * projection.importance))
}

/// The connection of a surface hit to the camera: pixel and `f * cos * importance` per
/// wavelength, or `None` when the point is outside the image or occluded.
fn connect_to_camera(
    scene: &LightTracerScene<'_>,
    material: &dyn Material,
    hit: &spectrace_geometry::Hit,
    arriving: DVec3,
    lambdas: &[f64],
    u_lens: [f64; 2],
) -> Option<(u32, u32, [f64; MAX_BUNDLE])> {
    let projection = scene.camera.sample_wi(hit.point, u_lens)?;
    let (shadow, distance) = hit.spawn_ray_to(projection.position);
    if scene.world.occluded(&shadow, distance) {
        return None;
    }
    // The camera measures area on the true surface (geometric normal); the reflected radiance
    // uses the shading normal, so particles are reweighted by |wi . n_s| / |wi . n_g|.
    let wi = -arriving;
    let cos = if hit.shading_normal == hit.geometric_normal {
        projection.to_camera.dot(hit.shading_normal).abs()
    } else {
        let cos_in = wi.dot(hit.geometric_normal).abs();
        if !(cos_in > 0.0) {
            return None;
        }
        projection.to_camera.dot(hit.geometric_normal).abs() * wi.dot(hit.shading_normal).abs()
            / cos_in
    };
    let mut values = [0.0; MAX_BUNDLE];
    let k = lambdas.len();
    material.eval_bundle(
        -arriving,
        projection.to_camera,
        hit.shading_normal,
        lambdas,
        Transport::Importance,
        &mut values[..k],
    );
    let mut any = false;
    for v in &mut values[..k] {
        if *v > 0.0 {
            *v = *v * cos * projection.importance;
            any = true;
        } else {
            *v = 0.0;
        }
    }
    any.then_some((projection.x, projection.y, values))
}
