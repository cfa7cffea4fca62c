//! The path tracer: paths from the camera, with next-event estimation and multiple importance
//! sampling (pbrt's `PathIntegrator`, spectral with hero wavelengths).
//!
//! # Estimator
//! A camera sample for pixel `p` is a ray through a uniform point of the pixel (and of the lens),
//! carrying [`HERO`] wavelengths drawn by [`CameraWavelengths`]. At every surface hit `x`:
//! - **Emission**: if `x` emits (an area light's surface or a glowing object), its radiance is
//!   added, weighted by the power heuristic against the density with which next-event
//!   estimation would have chosen `x` ([`LightTracerScene::emitter_pdf`]; full weight for the
//!   camera's own ray and after a specular bounce, which next-event estimation cannot produce).
//! - **Next-event estimation** (at non-specular surfaces): every delta-position light (points,
//!   spots) once, fully weighted (only this strategy reaches them, and sampling each instead of
//!   choosing one removes the variance of the choice for a shadow ray per light); and one of the
//!   other lights chosen by the scene's light sampler ([`LightTracerScene::area_lights`]), a
//!   point on it by its `sample_towards`, weighted by the power heuristic against BSDF sampling.
//! - **BSDF sampling** chooses the next direction ([`spectrace_materials::Transport::Radiance`]:
//!   refraction scales radiance by `(n_i / n_t)^2`); specular chains are followed, so glass and
//!   mirrors show what they reflect and refract.
//! - After `rr_depth` bounces, Russian roulette by the shared rule (survival
//!   `min(1, max_j beta_j)`).
//! - **Fluorescence**: at a fluorescent surface the path first chooses between the elastic part
//!   and re-emission ([`spectrace_materials::Fluorescent::choose_adjoint`]). Re-emission draws the
//!   wavelength the light had before it was absorbed from the absorption spectrum, half the time
//!   times the lights' spectrum ([`ExcitationSampler`]: where light is both absorbed and
//!   emitted); every hero wavelength then *travels* at it (the kernel is separable) while the
//!   film still records each at its own wavelength, and next-event estimation and the next
//!   direction use the white re-emission lobe.
//!
//! The film holds the sum of the samples' XYZ (`sum_j cmf(lambda_j) L_j / (HERO p(lambda_j))`,
//! divided by the integral of `ybar`, as the light tracer's units) relative to the lights' total
//! power; [`crate::Integrator::image_scale`] multiplies by the power and divides by the samples per
//! pixel.
//!
//! # Work items and determinism
//! A work item is one camera sample; a chunk is one *pass* (see `pass`): one sample of every
//! pixel (a prefix of them when a time budget cuts it short: each pixel is then normalised by
//! its own count), so the image is each pixel's plain mean, bit-identical for any thread count
//! or shard split.
//!
//! # Two kernels, one set of steps
//! A sample is a sequence of steps: `start` (camera ray and wavelengths), then per vertex
//! `arrive` (emission, the vertex's uniforms and lobe), `connection` and `connect` for each light
//! next-event estimation samples (the shadow ray in between), `go_on` (BSDF sample, roulette),
//! and `finish` (the splat). The scalar kernel (`trace`, the default, [`Kernel::Scalar`]) runs
//! them for one path to its end; the batched kernel (`crate::batch`, [`Kernel::Batched`]) runs
//! each for 16 paths before the next. Every camera path draws from its own sampler, so both give
//! the same film.
//!
//! # What it cannot see
//! Lights that have no `sample_towards` (lasers, parallel skies, lights that only implement the
//! seed's beam generator) are never reached by a camera path: their light is missing from a
//! path-traced image. The effects analysis does not choose this integrator for such scenes.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_geometry::{Hit, Ray};
use spectrace_lights::{LightId, LightSource};
use spectrace_materials::{
    ExcitationSampler, Material, MaterialAt, ScatterKind, Transport, reemission_lobe,
};

use super::common::{
    CameraSamples, Direction, End, Lobe, SampleLayout, ScatterSamples, ShadowRay, VertexSamples,
    choose_lobe, connect_light_to_camera, power_heuristic, relative_throughput, roulette,
    sample_light,
};
use super::pass::{PassEstimator, pixel_of, scalar_items};
use crate::batch::path::render_pass;
use crate::{
    CameraWavelengths, ChunkSampler, ChunkWork, Effects, HERO, Kernel, LightChoice,
    LightTracerScene, Splat, TraceStats,
};

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
    /// Which kernel traces the paths (the same image either way).
    pub kernel: Kernel,
}

impl Default for PathTracerSettings {
    fn default() -> Self {
        Self {
            max_depth: 64,
            rr_depth: 4,
            wavelengths: CameraWavelengths::Visible,
            kernel: Kernel::Scalar,
        }
    }
}

/// The path tracer as an [`crate::Integrator`]; a work item is one camera sample, a chunk one
/// pass over the image.
#[derive(Debug, Clone)]
pub struct PathTracer<'a> {
    scene: &'a LightTracerScene<'a>,
    settings: PathTracerSettings,
    effects: Effects,
    layout: SampleLayout,
    /// Per material (by shape index), for fluorescent ones: the sampler of the wavelength light
    /// had before re-emission, guided by the lights' spectrum (empty without fluorescence).
    excitation: Vec<Option<ExcitationSampler>>,
    /// Through a pinhole: the delta lights' splats seen directly, found on the first pass.
    pinhole_splats: std::sync::OnceLock<Vec<DeltaSplat>>,
}

/// A vertex as next-event estimation sees it: the hit, the direction back along the path and
/// what scatters there.
#[derive(Clone, Copy)]
pub(crate) struct Shading<'h> {
    /// The surface point.
    pub hit: &'h Hit,
    /// The direction back along the path.
    pub wo: DVec3,
    /// The lobe that scatters there.
    pub material: &'h dyn Material,
}

/// A scattering vertex a path has reached ([`PathTracer::arrive`]): its lobe, its light
/// uniforms and whether next-event estimation runs there.
#[derive(Clone)]
pub(crate) struct Vertex<'m> {
    /// The lobe that scatters (the material there, or the re-emission lobe).
    pub material: MaterialAt<'m>,
    /// The uniforms of next-event estimation's light choice.
    pub light: [f64; 2],
    /// The lobe is not specular: next-event estimation samples lights here.
    pub next_event: bool,
}

/// A light sample seen from a vertex, waiting for its shadow ray.
#[derive(Clone, Copy)]
pub(crate) struct Connection {
    /// The light.
    pub id: LightId,
    /// The point of the light and the unit direction from it to the vertex.
    pub from: (DVec3, DVec3),
    /// The direction from the vertex to the light.
    pub wi: DVec3,
    /// Intensity, cosine, inverse square and MIS weight over the light's probability.
    pub g: f64,
    /// The shadow ray that decides it.
    pub shadow: ShadowRay,
}

/// A camera sample: its pixel, wavelengths and path.
pub(crate) struct CameraPath {
    /// Pixel column.
    pub px: u32,
    /// Pixel row.
    pub py: u32,
    /// The path's film wavelengths.
    pub lambdas: [f64; HERO],
    /// Their film weights (the hero's alone after a dispersive surface).
    pub lambda_weights: [f64; HERO],
    /// The path.
    pub state: PathState,
}

/// The state of one camera path between bounces.
pub(crate) struct PathState {
    /// The ray it follows next.
    pub ray: Ray,
    /// Throughput per hero wavelength.
    beta: [f64; HERO],
    /// Radiance gathered so far per hero wavelength.
    radiance: [f64; HERO],
    /// The wavelengths light travels at along the path; they differ from the film's beyond a
    /// fluorescent re-emission.
    transport: [f64; HERO],
    /// The previous vertex, its shading normal and the density of the direction that left it
    /// (for MIS on emission).
    prev_point: DVec3,
    prev_normal: DVec3,
    prev_pdf: f64,
    /// The direction that reached this vertex came from a delta lobe (or the camera).
    specular: bool,
    depth: u32,
    /// Only the emission the next ray hits is still wanted.
    last_bounce: bool,
    /// A dispersive surface has left the hero alone.
    collapsed: bool,
    /// The light spectra already evaluated at `transport` (wavelengths that change only at a
    /// fluorescent re-emission).
    spd_cache: SpdCache,
}

/// Lights whose spectrum [`SpdCache`] keeps per path.
const SPD_CACHE: usize = 8;

/// The last [`SPD_CACHE`] light spectra a path evaluated, at one set of wavelengths: a path in a
/// room of luminaires samples several lights, one per bounce, and a Planckian or tabulated
/// spectrum costs an exponential or a table search per wavelength, so each light's values are
/// computed once per path instead of once per connection.
#[derive(Clone, Copy)]
struct SpdCache {
    /// The wavelengths the values are at.
    at: [f64; HERO],
    /// The lights (`u32::MAX`: an empty entry).
    ids: [u32; SPD_CACHE],
    /// Each light's spectrum at `at`.
    values: [[f64; HERO]; SPD_CACHE],
    /// The entry the next new light replaces.
    next: usize,
}

impl SpdCache {
    /// An empty cache for wavelengths `at`.
    fn new(at: [f64; HERO]) -> Self {
        Self { at, ids: [u32::MAX; SPD_CACHE], values: [[0.0; HERO]; SPD_CACHE], next: 0 }
    }

    /// Empties the cache for wavelengths `at`: only the ids are reset (a value is read only
    /// where its id matched), so a path reusing a cache writes 40 bytes, not 300.
    #[inline]
    fn clear(&mut self, at: [f64; HERO]) {
        (self.at, self.ids, self.next) = (at, [u32::MAX; SPD_CACHE], 0);
    }

    /// Light `light`'s values at `at`, if kept.
    #[inline]
    fn get(&self, light: LightId, at: &[f64; HERO]) -> Option<[f64; HERO]> {
        if self.at != *at {
            return None;
        }
        let k = self.ids.iter().position(|&id| id == light.0)?;
        Some(self.values[k])
    }

    /// Keeps `values`, light `light`'s spectrum at `at` (forgetting every light if the
    /// wavelengths changed, else the oldest entry).
    #[inline]
    fn put(&mut self, light: LightId, at: &[f64; HERO], values: [f64; HERO]) {
        if self.at != *at {
            self.clear(*at);
        }
        self.ids[self.next] = light.0;
        self.values[self.next] = values;
        self.next = (self.next + 1) % SPD_CACHE;
    }
}

impl PathState {
    fn new(ray: Ray, lambdas: &[f64; HERO]) -> Self {
        Self {
            ray,
            beta: [1.0; HERO],
            radiance: [0.0; HERO],
            transport: *lambdas,
            prev_point: ray.origin,
            prev_normal: DVec3::ZERO,
            prev_pdf: 0.0,
            specular: true,
            depth: 0,
            last_bounce: false,
            collapsed: false,
            spd_cache: SpdCache::new(*lambdas),
        }
    }

    /// The state of [`PathState::new`] written in place (its light cache emptied, not
    /// rebuilt): no path state is built elsewhere and copied in.
    #[inline]
    fn reset(&mut self, ray: Ray, lambdas: &[f64; HERO]) {
        // Every field named: a new one does not compile until it is reset here too.
        let Self {
            ray: path_ray,
            beta,
            radiance,
            transport,
            prev_point,
            prev_normal,
            prev_pdf,
            specular,
            depth,
            last_bounce,
            collapsed,
            spd_cache,
        } = self;
        (*path_ray, *beta, *radiance, *transport) = (ray, [1.0; HERO], [0.0; HERO], *lambdas);
        (*prev_point, *prev_normal, *prev_pdf) = (ray.origin, DVec3::ZERO, 0.0);
        (*specular, *depth, *last_bounce, *collapsed) = (true, 0, false, false);
        spd_cache.clear(*lambdas);
    }

    /// Light `light`'s spectrum at the path's transport wavelengths for light leaving
    /// `position` along `direction` (kept in [`SpdCache`] while the wavelengths stay the same,
    /// for a light whose colour does not vary); `None` for a light without one.
    #[inline]
    fn light_values(
        &mut self,
        scene: &LightTracerScene<'_>,
        light: LightId,
        position: DVec3,
        direction: DVec3,
    ) -> Option<[f64; HERO]> {
        if scene.spectrum_varies(light) {
            scene.light_spd(light)?;
            return Some(scene.light_spectra(light, position, direction, &self.transport));
        }
        if let Some(values) = self.spd_cache.get(light, &self.transport) {
            return Some(values);
        }
        let spd = scene.light_spd(light)?;
        let values = self.transport.map(|l| spd.value(l));
        self.spd_cache.put(light, &self.transport, values);
        Some(values)
    }

    /// Adds `le` (whole spectrum, times light `light`'s spectrum leaving `position` along
    /// `direction`) weighted by `weight`.
    #[inline]
    fn add_emission(
        &mut self,
        scene: &LightTracerScene<'_>,
        light: LightId,
        (position, direction): (DVec3, DVec3),
        le: f64,
        weight: f64,
    ) {
        if weight > 0.0 {
            let Some(spd) = self.light_values(scene, light, position, direction) else { return };
            for ((r, &b), s) in self.radiance.iter_mut().zip(&self.beta).zip(spd) {
                if b != 0.0 {
                    *r += b * le * s * weight;
                }
            }
        }
    }

    /// At a dispersive surface: the hero alone continues (its film weight times [`HERO`]).
    fn collapse(&mut self, lambda_weights: &mut [f64; HERO]) {
        self.collapsed = true;
        lambda_weights[0] *= HERO as f64;
        lambda_weights[1..].fill(0.0);
        self.beta[1..].fill(0.0);
    }
}

impl<'a> PathTracer<'a> {
    /// The path tracer's [`crate::Integrator::name`].
    pub const NAME: &'static str = "path";

    /// A path tracer of `scene`, following the `effects` decision (interreflection or not).
    pub fn new(
        scene: &'a LightTracerScene<'a>,
        settings: PathTracerSettings,
        effects: Effects,
    ) -> Self {
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
        let layout = SampleLayout::camera_paths(scene, true, scene.next_event().chooses());
        Self { scene, settings, effects, layout, excitation, pinhole_splats: Default::default() }
    }

    /// Pixels in the image: the work items of one pass (one chunk).
    pub fn pass_samples(&self) -> u64 {
        u64::from(self.scene.camera.width()) * u64::from(self.scene.camera.height())
    }

    /// Starts the camera sample of pixel `(px, py)`: its ray, wavelengths and state, from the
    /// path's own sampler `rng`.
    #[inline]
    pub(crate) fn start(&self, px: u32, py: u32, rng: &mut ChunkSampler) -> CameraPath {
        let (ray, lambdas, lambda_weights) = self.first_ray(px, py, rng);
        CameraPath { px, py, lambdas, lambda_weights, state: PathState::new(ray, &lambdas) }
    }

    /// [`PathTracer::start`] written into `path` in place (the batched kernel's slots and the
    /// scalar kernel's one path: a path built elsewhere and copied in costs a copy of its whole
    /// state).
    #[inline]
    pub(crate) fn restart(&self, path: &mut CameraPath, px: u32, py: u32, rng: &mut ChunkSampler) {
        let (ray, lambdas, lambda_weights) = self.first_ray(px, py, rng);
        (path.px, path.py, path.lambdas, path.lambda_weights) = (px, py, lambdas, lambda_weights);
        path.state.reset(ray, &lambdas);
    }

    /// A camera sample's first draws: its ray through pixel `(px, py)`, its hero wavelengths
    /// and their weights.
    #[inline]
    fn first_ray(
        &self,
        px: u32,
        py: u32,
        rng: &mut ChunkSampler,
    ) -> (Ray, [f64; HERO], [f64; HERO]) {
        let u = CameraSamples::draw(&self.layout, rng);
        let camera_ray = self.scene.camera.generate_ray(px, py, u.film, u.lens);
        let ray = Ray { origin: camera_ray.origin, direction: camera_ray.direction };
        let (lambdas, lambda_weights) = self.settings.wavelengths.sample_hero(u.wavelength);
        (ray, lambdas, lambda_weights)
    }

    /// Adds a finished camera sample to the film.
    #[inline]
    pub(crate) fn finish(&self, path: &CameraPath, film: &mut dyn Splat) {
        // The film holds radiance relative to the lights' total power (see `image_scale`).
        let inv_power = 1.0 / self.scene.lights.power();
        let radiance = &path.state.radiance;
        let values: [f64; HERO] =
            std::array::from_fn(|j| radiance[j] * path.lambda_weights[j] * inv_power);
        film.splat_spectral(path.px, path.py, &path.lambdas, &values);
    }

    /// The radiance estimate of one camera ray at the path's wavelengths, added to the film;
    /// the path is traced in `slot` (the chunk's one path, restarted in place).
    fn sample_pixel(
        &self,
        px: u32,
        py: u32,
        slot: &mut Option<CameraPath>,
        rng: &mut ChunkSampler,
        film: &mut dyn Splat,
        stats: &mut TraceStats,
    ) {
        let path = match slot {
            Some(path) => {
                self.restart(path, px, py, rng);
                path
            }
            None => slot.insert(self.start(px, py, rng)),
        };
        self.trace(&mut path.state, &mut path.lambda_weights, rng, stats);
        self.finish(path, film);
    }

    /// Radiance arriving along `ray` at each of the path's wavelengths (spectral, W m^-2 sr^-1
    /// nm^-1). A dispersive surface collapses the wavelengths to the hero (`lambda_weights[0]`
    /// multiplied by [`HERO`], the others set to 0).
    pub(crate) fn radiance(
        &self,
        ray: Ray,
        lambdas: &[f64; HERO],
        lambda_weights: &mut [f64; HERO],
        rng: &mut dyn rand::Rng,
        stats: &mut TraceStats,
    ) -> [f64; HERO] {
        let mut p = PathState::new(ray, lambdas);
        self.trace(&mut p, lambda_weights, rng, stats);
        p.radiance
    }

    /// The scalar kernel: follows one path to its end, one vertex at a time, through the same
    /// steps the batched kernel runs over many paths ([`Self::arrive`],
    /// [`Self::connection`] and [`Self::connect`], [`Self::go_on`]).
    fn trace(
        &self,
        p: &mut PathState,
        lambda_weights: &mut [f64; HERO],
        rng: &mut dyn rand::Rng,
        stats: &mut TraceStats,
    ) {
        while let Some(hit) = self.scene.world.intersect(&p.ray, f64::INFINITY) {
            let Some(vertex) = self.arrive(p, &hit, lambda_weights, rng, stats) else {
                break;
            };
            if vertex.next_event {
                let at = Shading { hit: &hit, wo: -p.ray.direction, material: &*vertex.material };
                self.for_each_light(&hit, vertex.light, |light| {
                    if let Some(c) = self.connection(p, &at, light)
                        && c.shadow.visible(self.scene)
                    {
                        self.connect(p, &at, &c, stats);
                    }
                });
            }
            if !self.go_on(p, &hit, vertex, rng, stats) {
                break;
            }
        }
    }

    /// A path reaches `hit`: the emission found there (weighted by MIS), then the vertex's
    /// uniforms and its lobe (the fluorescence choice; a dispersive lobe collapses the
    /// wavelengths). `None` when the path ends here.
    #[inline]
    pub(crate) fn arrive(
        &self,
        p: &mut PathState,
        hit: &Hit,
        lambda_weights: &mut [f64; HERO],
        rng: &mut dyn rand::Rng,
        stats: &mut TraceStats,
    ) -> Option<Vertex<'a>> {
        let scene = self.scene;
        stats.hits += 1;
        if let Some((light, le)) = scene.emitted(hit, -p.ray.direction) {
            let weight = if p.specular {
                1.0
            } else {
                power_heuristic(p.prev_pdf, scene.emitter_pdf((p.prev_point, p.prev_normal), hit))
            };
            p.add_emission(scene, light, (hit.point, -p.ray.direction), le, weight);
        }
        if p.last_bounce {
            return None;
        }
        let material = scene.material_at(hit)?;
        let u = VertexSamples::draw(&self.layout, rng);
        let guide = self.excitation.get(hit.primitive as usize).and_then(Option::as_ref);
        let lobe = choose_lobe(
            &*material,
            Direction::Adjoint(guide),
            &mut p.transport,
            &mut p.beta,
            u.fluorescence,
            stats,
        )?;
        let reemitted = matches!(lobe, Lobe::Reemitted(_));
        let material = if reemitted { MaterialAt::Shared(reemission_lobe()) } else { material };
        if material.is_dispersive() && !p.collapsed {
            p.collapse(lambda_weights);
        }
        let next_event = !material.is_specular();
        Some(Vertex { material, light: u.light, next_event })
    }

    /// Calls `f` with every light next-event estimation samples at the vertex `hit` whose
    /// light uniforms are `u` (see [`crate::NextEventLights`]).
    #[inline]
    pub(crate) fn for_each_light(&self, hit: &Hit, u: [f64; 2], f: impl FnMut(LightChoice)) {
        self.scene.next_event().for_each((hit.point, hit.shading_normal), u, f);
    }

    /// Next-event estimation's light sample `light` seen from the vertex `at`, weighted by the
    /// power heuristic against BSDF sampling (fully for a delta light), with the shadow ray that
    /// decides it; `None` when it gives no light whatever the shadow ray finds.
    #[inline]
    pub(crate) fn connection(
        &self,
        p: &PathState,
        at: &Shading<'_>,
        light: LightChoice,
    ) -> Option<Connection> {
        let Shading { hit, wo, material } = *at;
        let LightChoice { id, pmf, u } = light;
        let sample = sample_light(self.scene, id, hit.point, u)?;
        let wi = -sample.direction;
        let n = hit.shading_normal;
        let cos = wi.dot(n).abs();
        if !(cos > 0.0 && pmf > 0.0) {
            return None;
        }
        let weight = if sample.delta {
            1.0
        } else {
            power_heuristic(pmf * sample.pdf, material.pdf(wo, wi, n, p.transport[0]))
        };
        if !(weight > 0.0) {
            return None;
        }
        let g = sample.intensity * cos / (sample.distance * sample.distance * pmf) * weight;
        let shadow = ShadowRay::between(End::Surface(hit), End::Light(id, sample.position));
        Some(Connection { id, from: (sample.position, sample.direction), wi, g, shadow })
    }

    /// Adds an unoccluded connection's light to the path's radiance.
    #[inline]
    pub(crate) fn connect(
        &self,
        p: &mut PathState,
        at: &Shading<'_>,
        c: &Connection,
        stats: &mut TraceStats,
    ) {
        stats.splats += 1;
        let Some(spd) = p.light_values(self.scene, c.id, c.from.0, c.from.1) else { return };
        let mut f = [0.0; HERO];
        let n = at.hit.shading_normal;
        at.material.eval_bundle(c.wi, at.wo, n, &p.transport, Transport::Radiance, &mut f);
        for (j, f) in f.into_iter().enumerate() {
            if p.beta[j] != 0.0 && f > 0.0 {
                p.radiance[j] += p.beta[j] * f * c.g * spd[j];
            }
        }
    }

    /// After next-event estimation at `vertex`: whether the path goes on (without
    /// interreflection, only the emission the BSDF-sampled ray hits is still wanted, and without
    /// emitting surfaces not even that), then the vertex's scatter uniforms, the BSDF sample and
    /// Russian roulette. `false` when the path ends here.
    #[inline]
    pub(crate) fn go_on(
        &self,
        p: &mut PathState,
        hit: &Hit,
        vertex: Vertex<'_>,
        rng: &mut dyn rand::Rng,
        stats: &mut TraceStats,
    ) -> bool {
        if vertex.next_event && !self.effects.continue_after_diffuse {
            p.last_bounce = true;
            if !self.scene.surfaces_emit() {
                return false;
            }
        }
        let go = ScatterSamples::draw(rng, p.depth >= self.settings.rr_depth);
        self.bounce(p, hit, &*vertex.material, &go, stats)
    }

    /// The BSDF sample and Russian roulette at a vertex (after its next-event estimation);
    /// `false` when the path ends here.
    #[inline]
    fn bounce(
        &self,
        p: &mut PathState,
        hit: &Hit,
        material: &dyn Material,
        u: &ScatterSamples,
        stats: &mut TraceStats,
    ) -> bool {
        if p.depth >= self.settings.max_depth && !p.last_bounce {
            // The deepest vertex: one more ray, only for the emission it may hit (the BSDF
            // half of this vertex's MIS pair), as the light tracer's deepest connection.
            stats.depth_limited += 1;
            p.last_bounce = true;
        }
        let Some(scattered) = material.scatter_bundle(
            p.ray.direction,
            hit.shading_normal,
            &p.transport[..],
            &mut p.beta,
            u.scatter,
            Transport::Radiance,
        ) else {
            return false;
        };
        p.specular = scattered.kind == ScatterKind::Specular;
        p.prev_pdf = scattered.pdf;
        p.prev_point = hit.point;
        p.prev_normal = hit.shading_normal;
        p.depth += 1;
        if p.depth > self.settings.rr_depth && !p.last_bounce {
            let relative = relative_throughput(&p.beta, &[1.0; HERO]);
            let Some(survive) = roulette(relative, u.roulette, stats) else { return false };
            for b in &mut p.beta {
                *b /= survive;
            }
        }
        if p.beta.iter().all(|&b| b == 0.0) {
            return false;
        }
        p.ray = hit.spawn_ray(scattered.direction);
        true
    }

    /// Point and spot lights seen directly: a camera ray never hits a point, but the pixel a
    /// point light projects into receives its intensity towards the camera times the camera's
    /// importance (a finite pixel value, as the light tracer and BDPT show it). Once per pass,
    /// exactly (the light's colour is its SPD's XYZ integral, not a sampled wavelength), or with
    /// one lens sample per pass for a thin lens; weighted by `share`, the part of the pass done,
    /// into the film's pass layer. Through a pinhole these splats are the same every pass, so
    /// they are found (a shadow ray each) on the first pass and reused: a scene of thousands of
    /// point lights does not trace thousands of rays per pass.
    fn splat_delta_lights(
        &self,
        share: f64,
        rng: &mut dyn rand::Rng,
        film: &mut dyn Splat,
        stats: &mut TraceStats,
    ) {
        let mut splat = |(x, y, xyz, value): DeltaSplat| {
            if film.splat_pass(x, y, xyz * (value * share)) {
                stats.splats += 1;
            }
        };
        if self.layout.camera_lens {
            for &id in self.scene.delta_lights() {
                // One lens point per light and pass.
                let u_lens = self.layout.camera_lens(rng);
                if let Some(s) = self.delta_splat(id, u_lens) {
                    splat(s);
                }
            }
        } else {
            let cached = self.pinhole_splats.get_or_init(|| {
                let ids = self.scene.delta_lights();
                ids.iter().filter_map(|&id| self.delta_splat(id, [0.5; 2])).collect()
            });
            cached.iter().copied().for_each(splat);
        }
    }

    /// Delta light `id` seen directly through the lens point `u_lens`: its pixel, its colour
    /// and its value per pass (relative to the lights' total power, as every sample of this
    /// film); `None` when the camera does not see it.
    fn delta_splat(&self, id: LightId, u_lens: [f64; 2]) -> Option<DeltaSplat> {
        let scene = self.scene;
        let inv_y = 1.0 / *spectrace_spectrum::CIE_Y_INTEGRAL;
        let light = scene.lights.light(id)?;
        let origin = light.sample_emission([0.5; 4])?.position;
        let (seen, value) = connect_light_to_camera(scene, id, origin, u_lens)?;
        let value = value * light.power() / scene.lights.power() * inv_y;
        Some((seen.x, seen.y, scene.light_xyz(id), value))
    }
}

/// A delta light's splat on the film: pixel, colour (XYZ of its spectrum) and value per pass.
type DeltaSplat = (u32, u32, spectrace_spectrum::Xyz, f64);

impl PassEstimator for PathTracer<'_> {
    const NAME: &'static str = PathTracer::NAME;
    /// The chunk's camera path, restarted in place for each sample.
    type Scratch = Option<CameraPath>;

    fn scene(&self) -> &LightTracerScene<'_> {
        self.scene
    }

    fn scratch(&self) -> Option<CameraPath> {
        None
    }

    fn pass_splats(&self) -> bool {
        !self.scene.delta_lights().is_empty()
    }

    fn end_pass(
        &self,
        share: f64,
        rng: &mut ChunkSampler,
        film: &mut dyn Splat,
        stats: &mut TraceStats,
    ) {
        self.splat_delta_lights(share, rng, film, stats);
    }

    fn render_items(&self, work: ChunkWork, film: &mut dyn Splat) -> TraceStats {
        match self.settings.kernel {
            Kernel::Batched => render_pass(self, work, film),
            Kernel::Scalar => scalar_items(self, work, film),
        }
    }

    fn sample(
        &self,
        item: u64,
        slot: &mut Option<CameraPath>,
        rng: &mut ChunkSampler,
        film: &mut dyn Splat,
        stats: &mut TraceStats,
    ) {
        let (px, py) = pixel_of(item, u64::from(self.scene.camera.width()));
        self.sample_pixel(px, py, slot, rng, film, stats);
    }
}
