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
//! roulette ends a beam by the shared rule (survival `min(1, max_j w_j / w_j,0)` over the
//! bundle's wavelengths) and divides survivors by the survival probability, which keeps the
//! estimator unbiased.
//!
//! The film accumulates the contributions without the factor `Phi / N`; [`image_scale`] gives it.
//!
//! # Determinism
//! Work comes in chunks of beams; chunk `c` draws all its random numbers from a generator seeded
//! by `(seed, c)`, and the film adds in exact fixed point, so an image depends only on the seed
//! and the chunks rendered, never on thread count or order.

use std::time::Instant;

use serde::{Deserialize, Serialize};
use spectrace_geometry::Ray;
use spectrace_lights::{Beam, LightId, LightSource, uniform};
use spectrace_materials::Transport;
use spectrace_spectrum::{lumens_per_watt, melanopic_edi_per_watt};

use super::common::{
    CameraConnection, Direction, SampleLayout, ScatterSamples, VertexSamples, choose_lobe,
    connect_light_to_camera, connect_surface_to_camera, relative_throughput, roulette,
    shading_correction,
};
use crate::{
    ChunkSampler, ChunkWork, Effects, EffectsMode, Integrator, LightTracerScene, SensorSet, Splat,
    TraceStats,
};

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

/// Largest wavelength bundle a path can carry.
const MAX_BUNDLE: usize = 8;

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

/// The factor that turns film sums into the image: the lights' power over the beams of the
/// whole render.
pub fn image_scale(light_power: f64, total_beams: u64) -> f64 {
    if total_beams == 0 { 0.0 } else { light_power / total_beams as f64 }
}

/// The light tracer as an [`Integrator`]: beams from the lights, every non-specular hit
/// connected to the camera (see [`crate::trace_chunk`]); a work item is one beam.
#[derive(Debug, Clone)]
pub struct LightTracer<'a> {
    scene: &'a LightTracerScene<'a>,
    settings: LightTracerSettings,
    effects: Effects,
}

impl<'a> LightTracer<'a> {
    /// The light tracer's [`Integrator::name`].
    pub const NAME: &'static str = "light";

    /// A light tracer of `scene` with `settings`, following the `effects` decision.
    pub fn new(
        scene: &'a LightTracerScene<'a>,
        settings: LightTracerSettings,
        effects: Effects,
    ) -> Self {
        Self { scene, settings, effects }
    }

    /// The scene it traces.
    pub fn scene(&self) -> &'a LightTracerScene<'a> {
        self.scene
    }

    /// Its settings.
    pub fn settings(&self) -> &LightTracerSettings {
        &self.settings
    }

    /// The effects decision it follows.
    pub fn effects(&self) -> &Effects {
        &self.effects
    }
}

impl Integrator for LightTracer<'_> {
    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn resolution(&self) -> (u32, u32) {
        (self.scene.camera.width(), self.scene.camera.height())
    }

    fn render_chunk(&self, work: ChunkWork, film: &mut dyn Splat) -> TraceStats {
        trace_chunk_until(self.scene, &self.settings, &self.effects, work, film)
    }

    fn image_scale(&self, samples_done: u64) -> f64 {
        image_scale(self.scene.lights.power(), samples_done)
    }

    fn sensor_cells(&self) -> u32 {
        self.scene.sensors().map_or(0, SensorSet::total_cells)
    }
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
    let work = ChunkWork { seed, chunk, items: beams, deadline: None, ends_pass: false };
    trace_chunk_until(scene, settings, effects, work, film)
}

/// As [`trace_chunk`] (`work.items` beams), but stops early once `work.deadline` has passed: the clock is read every
/// few microseconds of work, between beams (a beam is never cut), and at least one beam is
/// traced. The returned `stats.beams` is the number of beams traced, which the image's
/// normalisation must use; the beams traced are the first ones of the chunk's random stream.
pub fn trace_chunk_until<S: Splat + ?Sized>(
    scene: &LightTracerScene<'_>,
    settings: &LightTracerSettings,
    effects: &Effects,
    work: ChunkWork,
    film: &mut S,
) -> TraceStats {
    let mut rng = ChunkSampler::new(scene.sampler().resolve(false), work.seed, work.chunk);
    let mut stats = TraceStats::default();
    let tracer = BeamTracer {
        scene,
        settings,
        effects,
        layout: SampleLayout::light_paths(scene),
        bundle: effects.wavelengths_per_path.clamp(1, MAX_BUNDLE),
    };
    let mut memo = OriginMemo::new(scene);
    let mut next_check = DEADLINE_CHECK_WORK;
    for i in 0..work.items {
        if let Some(deadline) = work.deadline {
            let done = stats.beams + stats.hits;
            if done >= next_check {
                next_check = done + DEADLINE_CHECK_WORK;
                if Instant::now() >= deadline {
                    break;
                }
            }
        }
        rng.start_path(work.chunk, i);
        stats.beams += 1;
        tracer.trace_beam(&mut rng, &mut memo, film, &mut stats);
    }
    stats
}

/// The camera connections of the beam origins of a chunk's lights with a delta position
/// (points, spots, measured luminaires: every beam of one starts at one point). Through a
/// pinhole the connection is a function of the light and the point alone
/// (`connect_light_to_camera` reads no uniform, and a light's emission density at a point is
/// its own, whatever beam asks), so such a light's origin is connected once per chunk, with the
/// same result bit for bit. Other lights' origins move from beam to beam, and a thin lens draws
/// its lens point per beam: those are connected every time.
struct OriginMemo {
    /// Per light: `None` if its connections are not kept, else its last one (`None` before
    /// the first).
    slots: Vec<Option<Option<KeptOrigin>>>,
}

/// A point's coordinates (bits) and its connection and value (`None`: not seen).
type KeptOrigin = ([u64; 3], Option<(CameraConnection, f64)>);

impl OriginMemo {
    /// The memo of a chunk of `scene`'s beams: slots for its delta-position lights, none for a
    /// thin-lens camera.
    fn new(scene: &LightTracerScene<'_>) -> Self {
        let mut slots = vec![None; scene.lights.lights().len()];
        if scene.camera.is_pinhole() {
            for &id in scene.delta_lights() {
                if !scene.parallel_sampled(id)
                    && let Some(slot) = slots.get_mut(id.0 as usize)
                {
                    *slot = Some(None);
                }
            }
        }
        Self { slots }
    }

    /// [`connect_light_to_camera`] of light `id`'s point `point`, kept for the light's next
    /// beam if it has a slot.
    #[inline]
    fn connect(
        &mut self,
        scene: &LightTracerScene<'_>,
        id: LightId,
        point: glam::DVec3,
        u_lens: [f64; 2],
    ) -> Option<(CameraConnection, f64)> {
        let Some(Some(slot)) = self.slots.get_mut(id.0 as usize) else {
            return connect_light_to_camera(scene, id, point, u_lens);
        };
        let key = point.to_array().map(f64::to_bits);
        match slot {
            Some((kept, seen)) if *kept == key => *seen,
            _ => {
                let seen = connect_light_to_camera(scene, id, point, u_lens);
                *slot = Some((key, seen));
                seen
            }
        }
    }
}

/// What one beam's trace needs, fixed for the chunk.
struct BeamTracer<'s, 'a> {
    scene: &'s LightTracerScene<'a>,
    settings: &'s LightTracerSettings,
    effects: &'s Effects,
    layout: SampleLayout,
    /// Wavelengths per beam.
    bundle: usize,
}

/// A beam's wavelengths and their weights (each an independent estimate; all share the path).
struct Bundle {
    lambdas: [f64; MAX_BUNDLE],
    weights: [f64; MAX_BUNDLE],
    /// The weights the beam started with (for Russian roulette).
    start: [f64; MAX_BUNDLE],
    len: usize,
}

impl BeamTracer<'_, '_> {
    /// The bundle of `beam`, whose wavelength its light drew from `u_lambda`
    /// ([`LightSource::next_beam_at`]; unused for a bundle of one, whose beam comes from
    /// `next_beam`): that wavelength and weight, plus `bundle - 1` companions
    /// drawn by the light ([`LightSource::sample_wavelength`]) from `u_lambda + j / bundle` (mod
    /// 1), with the weight of that density. The bundle's wavelengths are thus stratified
    /// together, one in each `1 / bundle` of the light's wavelength density (Mitsuba's shifted
    /// wavelengths; a camera path's hero wavelengths do the same). Each is still distributed by
    /// that density alone, and `u_lambda` decides nothing else of the beam, so every
    /// wavelength's estimate stays unbiased.
    fn bundle(&self, beam: &Beam, u_lambda: f64) -> Bundle {
        let k = self.bundle;
        let mut b = Bundle {
            lambdas: [beam.lambda; MAX_BUNDLE],
            weights: [0.0; MAX_BUNDLE],
            start: [0.0; MAX_BUNDLE],
            len: k,
        };
        b.weights[0] = beam.scale / k as f64;
        if k > 1 {
            let own = self.scene.lights.light(beam.parent);
            for j in 1..k {
                let u = spectrace_sampling::shifted_uniform(u_lambda, j, k);
                let (lambda, scale) = own.map_or((beam.lambda, 0.0), |l| l.sample_wavelength(u));
                b.lambdas[j] = lambda;
                b.weights[j] = scale / k as f64;
            }
        }
        b.start = b.weights;
        b
    }

    /// The bundle's values at the beam's origin seen along `to_camera` (`value` the light's
    /// emission density times the camera's importance): the beam's own wavelength weighs the
    /// origin alone ([`LightSource::origin_weight`]), and a light whose colour varies gives its
    /// spectrum that way.
    fn origin_values(
        &self,
        beam: &Beam,
        b: &Bundle,
        to_camera: glam::DVec3,
        value: f64,
    ) -> [f64; MAX_BUNDLE] {
        let scene = self.scene;
        let mut weights = b.weights;
        weights[0] = LightSource::origin_weight(scene.lights, beam) / b.len as f64;
        let varying = scene.spectrum_varies(beam.parent);
        let own = scene.lights.light(beam.parent);
        std::array::from_fn(|j| {
            let factor = match own {
                Some(l) if varying && j < b.len => {
                    l.spectral_factor(beam.origin, to_camera, b.lambdas[j])
                }
                _ => 1.0,
            };
            weights[j] * value * factor
        })
    }

    /// Traces one beam: its emission point seen by the camera, then every non-specular hit.
    fn trace_beam<S: Splat + ?Sized>(
        &self,
        rng: &mut ChunkSampler,
        memo: &mut OriginMemo,
        film: &mut S,
        stats: &mut TraceStats,
    ) {
        let scene = self.scene;
        let light: &dyn LightSource = scene.lights;
        // A bundle of one (dispersion, fluorescence, lights whose colour varies) needs no
        // uniform of its own: the beam draws its wavelength as it always has.
        let (beam, u_lambda) = if self.bundle > 1 {
            let u = uniform(rng);
            (light.next_beam_at(u, rng), u)
        } else {
            (light.next_beam(rng), 0.0)
        };
        let mut b = self.bundle(&beam, u_lambda);
        let u_lens = self.layout.lens(rng);
        if !scene.is_sensors_only()
            && let Some((seen, value)) = memo.connect(scene, beam.parent, beam.origin, u_lens)
        {
            let values = self.origin_values(&beam, &b, seen.to_camera, value);
            if film.splat_spectral(seen.x, seen.y, &b.lambdas[..b.len], &values[..b.len]) {
                stats.splats += 1;
            }
        }
        let mut ray = Ray { origin: beam.origin, direction: beam.direction };
        let mut next_hit = scene.intersect_from_light(&ray, beam.parent, f64::INFINITY);
        self.fill_sensors(&ray, next_hit.as_ref().map(|h| h.t), &b, film);
        let mut depth = 0u32;
        while let Some(hit) = next_hit.take() {
            stats.hits += 1;
            let Some(material) = scene.material_at(&hit) else { break };
            let u = VertexSamples::draw(&self.layout, rng);
            let (lambdas, weights) = (&mut b.lambdas[..b.len], &mut b.weights[..b.len]);
            let Some(lobe) = choose_lobe(
                &*material,
                Direction::Forward,
                lambdas,
                weights,
                u.fluorescence,
                stats,
            ) else {
                break;
            };
            let material = lobe.material();
            if !material.is_specular() {
                if !scene.is_sensors_only() {
                    let mut values = [0.0; MAX_BUNDLE];
                    let wi = -ray.direction;
                    if let Some(seen) = connect_surface_to_camera(
                        scene,
                        &hit,
                        material,
                        wi,
                        lambdas,
                        u.lens,
                        &mut values,
                    ) {
                        for (v, w) in values.iter_mut().zip(weights.iter()) {
                            *v *= w;
                        }
                        let values = &values[..lambdas.len()];
                        if film.splat_spectral(seen.x, seen.y, lambdas, values) {
                            stats.splats += 1;
                        }
                    }
                }
                if self.stops_after_diffuse() {
                    break;
                }
            }
            if depth >= self.settings.max_depth {
                stats.depth_limited += 1;
                break;
            }
            let go = ScatterSamples::draw(rng, depth >= self.settings.rr_depth);
            // One scatter for the whole bundle: without dispersion every wavelength takes the
            // same direction, each with its own weight; a wavelength the surface absorbs drops
            // out alone, and a dispersive surface keeps only the first live one.
            let Some(scattered) = material.scatter_bundle(
                ray.direction,
                hit.shading_normal,
                lambdas,
                weights,
                go.scatter,
                Transport::Importance,
            ) else {
                break;
            };
            // Shading normals: the adjoint correction for particles (Veach 1997, section 5.3).
            let correction = shading_correction(&hit, -ray.direction, scattered.direction);
            for w in weights.iter_mut() {
                *w *= correction;
            }
            depth += 1;
            if depth > self.settings.rr_depth {
                let relative = relative_throughput(weights, &b.start[..b.len]);
                let Some(survive) = roulette(relative, go.roulette, stats) else { break };
                for w in weights.iter_mut() {
                    *w /= survive;
                }
            }
            if weights.iter().all(|&w| w <= 0.0) {
                break;
            }
            ray = hit.spawn_ray(scattered.direction);
            next_hit = scene.world.intersect(&ray, f64::INFINITY);
            self.fill_sensors(&ray, next_hit.as_ref().map(|h| h.t), &b, film);
        }
    }

    /// Whether a beam ends at its first non-specular hit: when no interreflection can reach
    /// the camera, unless sensors may still see light leaving that surface (and the user did
    /// not ask for direct light only).
    fn stops_after_diffuse(&self) -> bool {
        !self.effects.continue_after_diffuse
            && (self.scene.sensors().is_none() || self.effects.mode == EffectsMode::DirectOnly)
    }

    /// Adds a path segment's bundle (reaching `reach`, or infinity) to every sensor cell it
    /// crosses on the front side: the radiant weight, the luminous weight (times `683 ybar`),
    /// its square and the melanopic weight (see [`crate::SensorSums`]).
    #[inline]
    fn fill_sensors<S: Splat + ?Sized>(
        &self,
        ray: &Ray,
        reach: Option<f64>,
        b: &Bundle,
        film: &mut S,
    ) {
        let Some(sensors) = self.scene.sensors() else { return };
        let (lambdas, weights) = (&b.lambdas[..b.len], &b.weights[..b.len]);
        let reach = reach.unwrap_or(f64::INFINITY);
        sensors.crossings(ray.origin, ray.direction, reach, |cell| {
            let radiant: f64 = weights.iter().sum();
            let luminous: f64 =
                lambdas.iter().zip(weights).map(|(&l, &w)| w * lumens_per_watt(l)).sum();
            let melanopic: f64 =
                lambdas.iter().zip(weights).map(|(&l, &w)| w * melanopic_edi_per_watt(l)).sum();
            film.splat_sensor(cell, [radiant, luminous, luminous * luminous, melanopic]);
        });
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use glam::DVec3;
    use spectrace_geometry::{Rectangle, Shape, World};
    use spectrace_lights::LightSet;
    use spectrace_materials::Material;
    use std::sync::Arc;

    use super::*;
    use crate::{CameraRepr, FovAxis, PinholeCamera};

    fn camera(aperture_radius: f64) -> PinholeCamera {
        PinholeCamera::new(CameraRepr {
            position: DVec3::new(0.0, 1.0, 3.0),
            look_at: DVec3::new(0.0, 0.5, 0.0),
            up: DVec3::Y,
            fov: 60.0,
            fov_axis: FovAxis::Horizontal,
            width: 16,
            height: 16,
            aperture_radius,
            focus_distance: (aperture_radius > 0.0).then_some(3.0),
        })
        .unwrap()
    }

    fn point(x: f64) -> Box<dyn LightSource> {
        let json = format!(
            r#"{{"type": "PointLight", "position": [{x}, 1, 0], "power": 10,
               "spd": {{"type": "Blackbody", "kelvin": 3000}}}}"#
        );
        serde_json::from_str(&json).unwrap()
    }

    #[test]
    fn a_kept_origin_connection_is_the_one_made_anew() {
        let floor = Rectangle::new(DVec3::new(-2.0, 0.0, -2.0), 4.0 * DVec3::Z, 4.0 * DVec3::X);
        let world = World::new(vec![Shape::Rectangle(floor.unwrap())]).unwrap();
        let diffuse: Box<dyn Material> =
            serde_json::from_str(r#"{"type": "Diffuse", "reflectance": 0.5}"#).unwrap();
        let materials = vec![Arc::from(diffuse)];
        let lights = LightSet::new(vec![point(-0.5), point(0.5)]).unwrap();
        for (aperture, kept) in [(0.0, true), (0.05, false)] {
            let camera = camera(aperture);
            let scene = LightTracerScene::new(&world, &materials, &lights, &camera);
            let mut memo = OriginMemo::new(&scene);
            assert_eq!(memo.slots.iter().all(Option::is_some), kept, "aperture {aperture}");
            // The lights in turn, a point moved (a light's slot must not answer for it), the
            // lens point varying (it matters only through a thin lens).
            let calls = [(0, -0.5, 0.1), (1, 0.5, 0.2), (0, -0.5, 0.3), (0, -0.25, 0.4)];
            for (k, x, u) in calls.into_iter().chain(calls) {
                let (id, p) = (LightId(k), DVec3::new(x, 1.0, 0.0));
                let fresh = connect_light_to_camera(&scene, id, p, [u, 0.7]);
                assert!(fresh.is_some(), "the test's points are seen");
                assert_eq!(memo.connect(&scene, id, p, [u, 0.7]), fresh, "{k} at {x}, {u}");
            }
        }
    }
}
