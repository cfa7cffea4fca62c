//! Bidirectional path tracing (Veach 1997, chapter 10; pbrt's `BDPTIntegrator`), one wavelength
//! per sample.
//!
//! # Estimator
//! A camera sample of pixel `p` pairs a *light subpath* with a *camera subpath* and combines every
//! way of joining them, `(s, t)` with `s` light vertices and `t` camera vertices:
//! - the light subpath starts with one beam of the light set ([`LightSource::next_beam`]): its
//!   light `l` (chosen by power), origin, direction and wavelength `lambda` (drawn from the
//!   light's SPD), then a random walk ([`Transport::Importance`]) with Russian roulette;
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
//! The whole sample uses the beam's wavelength. Its density is the light set's marginal
//! `p(lambda) = sum_l pmf(l) spd_l(lambda)`, the set's SPD. Given `lambda`, the beam's light was
//! chosen with `pmf(l | lambda) = pmf(l) spd_l(lambda) / p(lambda)`, and next-event estimation
//! (`s = 1`) chooses its light with the same conditional probability, so that both ends agree on
//! the density of a light vertex. Every strategy estimates `cmf(lambda) I(lambda) / p(lambda)`,
//! divided by the integral of `ybar` as in the other integrators:
//! - the light subpath's throughput after emission is `L_e cos / (pmf(l | lambda) p_A p_w
//!   p(lambda)) = Phi * scale` (`Phi` the set's power), since a light's radiance is `Phi_l
//!   spd_l(lambda) p_A p_w / cos` by the definition of its beams;
//! - camera-side emission (`s = 0`) is `L_e spd_l(lambda) / p(lambda)`, and next-event estimation
//!   `intensity / pmf(l)` (the spectra cancel).
//!
//! Lights whose beams use `equal_wavelengths` (beam `scale != 1`) draw `lambda` from another
//! density: a sample whose beam has such a weight falls back to the light tracer's estimate
//! (every `t = 1` strategy with full weight, no camera strategies). That is exact when every
//! light of the set uses `equal_wavelengths` and only approximate for a mix. The same fallback
//! applies when `p(lambda)` is not positive (a delta line of a line spectrum), which only light
//! paths can reach.
//!
//! # Normalisation
//! A chunk is one *pass*: one sample of every pixel, in pixel order ([`Bdpt::pass_samples`]
//! items), as for the [`crate::PathTracer`]. As the path tracer's, the film holds the estimates
//! divided by the lights' total power `Phi` (the renderer's normalisation of camera integrators,
//! which keeps lights of any power in the film's fixed-point range), normalised per pixel sample:
//! [`Integrator::image_scale`] `= Phi * pixels / samples`. Camera strategies (`t >= 2`) estimate the
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

use std::f64::consts::PI;
use std::sync::Arc;
use std::time::Instant;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_geometry::{Hit, Ray};
use spectrace_lights::{LightFlags, LightId, LightSource, LightSurface, uniform};
use spectrace_materials::{Incoming, ScatterKind, Transport};
use spectrace_materials::{Material, Reemission, reemission_lobe};
use spectrace_spectrum::{CIE_Y_INTEGRAL, SpectralPowerDistribution, cmf};

use crate::light_tracer::{LightTracerScene, TraceStats, shading_correction};
use crate::path_tracer::{camera_image_scale, pass_pixel, pass_start};
use crate::{ChunkSampler, Effects, Integrator, Splat};

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
}

impl Default for BdptSettings {
    fn default() -> Self {
        Self { max_depth: 64, rr_depth: 4, only_strategy: None }
    }
}

/// One vertex of a full path, as the MIS weight sees it (see [`mis_weight`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MisVertex {
    /// Area density (m^-2; for a point, solid-angle density over distance squared) with which
    /// the light side generates this vertex from the vertices before it; for the first vertex,
    /// the density of choosing it on the light. 0 through a specular vertex.
    pub from_light: f64,
    /// Area density with which the camera side generates this vertex from the vertices after
    /// it. 0 through a specular vertex.
    pub from_camera: f64,
    /// Whether the vertex scatters by a Dirac delta (a specular surface), so that no connection
    /// can end at it; for the first vertex, a light with a delta direction.
    pub delta: bool,
}

/// The power-heuristic weight of strategy `s` (the first `s` vertices from the light, the others
/// from the camera) for the full path `path`, ordered from the light (index 0) to the camera
/// (last). Strategies that end a connection at a delta vertex are not counted, nor `s = 0`
/// when `light_is_delta` (a light a camera path cannot hit), nor `t = 0` (the camera, pinhole or
/// lens, is not part of the scene: paths never hit it). Zero densities (delta vertices) count as 1, so deltas cancel. `s` must be a valid
/// strategy; the result is in `[0, 1]`.
pub fn mis_weight(path: &[MisVertex], s: usize, light_is_delta: bool) -> f64 {
    let n = path.len();
    if n < 2 || s >= n {
        return 0.0;
    }
    let remap = |p: f64| if p != 0.0 { p } else { 1.0 };
    let mut sum = 1.0;
    // Fewer light vertices: strategy i replaces the light density of vertex i by the camera's.
    let mut r = 1.0;
    for i in (0..s).rev() {
        r *= remap(path[i].from_camera) / remap(path[i].from_light);
        let before = if i > 0 { path[i - 1].delta } else { light_is_delta };
        if !path[i].delta && !before {
            sum += r * r;
        }
    }
    // More light vertices: strategy i + 1 takes vertex i from the light side.
    let mut r = 1.0;
    for i in s..n - 1 {
        r *= remap(path[i].from_light) / remap(path[i].from_camera);
        if !path[i].delta && !path[i + 1].delta {
            sum += r * r;
        }
    }
    if sum.is_finite() { 1.0 / sum } else { 0.0 }
}

/// What a vertex is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum VertexKind {
    /// The pinhole, or a point of a thin lens.
    Camera,
    /// A point on light `id` (where a beam starts, or sampled by next-event estimation).
    Light(LightId),
    /// A surface hit (its shape's material scatters).
    Surface(Hit),
}

/// A vertex of a subpath (pbrt's `Vertex`).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Vertex {
    kind: VertexKind,
    point: DVec3,
    /// Geometric normal; zero for points not on a surface (pinhole, point lights).
    ng: DVec3,
    /// Throughput from the subpath's start up to this vertex (not including its scattering).
    beta: f64,
    /// Scatters by a delta lobe (or, for a light, emits in a delta direction).
    delta: bool,
    /// Area density of this vertex sampled from its own subpath's side.
    pdf_fwd: f64,
    /// Area density of this vertex sampled from the other side.
    pdf_rev: f64,
    /// The wavelength (nm) at which this vertex connects: the sample's own, or on a light
    /// subpath beyond a fluorescent re-emission the re-emitted one.
    lambda: f64,
    /// This vertex re-emitted (scatters with [`reemission_lobe`] instead of its material).
    reemitted: bool,
    /// This vertex or one before it on its subpath re-emitted.
    fluoresced: bool,
}

impl Vertex {
    fn camera(point: DVec3, lambda: f64) -> Self {
        Self {
            kind: VertexKind::Camera,
            point,
            ng: DVec3::ZERO,
            beta: 1.0,
            delta: false,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            lambda,
            reemitted: false,
            fluoresced: false,
        }
    }

    fn surface(hit: Hit, beta: f64, lambda: f64, fluoresced: bool) -> Self {
        Self {
            kind: VertexKind::Surface(hit),
            point: hit.point,
            ng: hit.geometric_normal,
            beta,
            delta: false,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            lambda,
            reemitted: false,
            fluoresced,
        }
    }
}

/// A light as a path end: its id, its flags, and the probability of choosing it given the
/// sample's wavelength.
#[derive(Debug, Clone, Copy)]
struct LightEnd {
    id: LightId,
    flags: LightFlags,
    pmf: f64,
}

impl LightEnd {
    /// Whether a camera path can never hit it (strategy `s = 0` impossible).
    fn is_delta(&self, on_surface: bool) -> bool {
        self.flags.delta_position || self.flags.delta_direction || !on_surface
    }
}

/// The wavelength of a sample and what depends on it.
#[derive(Debug, Clone, Copy)]
struct Wavelength {
    lambda: f64,
    /// The light set's SPD at `lambda`: the density the wavelength was drawn with.
    density: f64,
}

/// The bidirectional path tracer as an [`Integrator`]; a work item is one camera sample (with
/// its light path), a chunk one pass over the image.
#[derive(Debug, Clone)]
pub struct Bdpt<'a> {
    scene: &'a LightTracerScene<'a>,
    settings: BdptSettings,
    effects: Effects,
    /// The light set's SPD (the marginal density of a beam's wavelength).
    set_spd: Arc<dyn SpectralPowerDistribution>,
}

/// Reused storage of one chunk: no allocation per sample.
struct Buffers {
    light: Vec<Vertex>,
    camera: Vec<Vertex>,
    mis: Vec<MisVertex>,
}

impl<'a> Bdpt<'a> {
    /// The bidirectional path tracer's [`Integrator::name`].
    pub const NAME: &'static str = "bdpt";

    /// A bidirectional path tracer of `scene` with `settings` (the `effects` decision is kept
    /// for reports; paths always continue after diffuse hits).
    pub fn new(scene: &'a LightTracerScene<'a>, settings: BdptSettings, effects: Effects) -> Self {
        Self { scene, settings, effects, set_spd: LightSource::spd(scene.lights) }
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

    /// Most vertices of a camera subpath (pinhole included) and of a light subpath.
    fn max_vertices(&self) -> (usize, usize) {
        let d = self.settings.max_depth.min(crate::MAX_DEPTH) as usize;
        (d + 3, d + 2)
    }

    /// The light `id` as a path end for wavelength `wl`.
    fn light_end(&self, id: LightId, wl: &Wavelength) -> Option<LightEnd> {
        let light = self.scene.lights.light(id)?;
        let flags =
            light.flags().unwrap_or(LightFlags { delta_position: true, delta_direction: true });
        let spd = self.scene.light_spd(id)?;
        let pmf = if wl.density > 0.0 {
            self.scene.lights.pmf(id) * spd.value(wl.lambda) / wl.density
        } else {
            0.0
        };
        Some(LightEnd { id, flags, pmf })
    }

    /// Solid-angle density of a camera ray leaving the lens at `origin` (the pinhole for a
    /// pinhole camera) towards `point` (over the whole image: [`crate::PinholeCamera::pdf_we`]),
    /// 0 when it misses the image.
    fn camera_pdf(&self, origin: DVec3, point: DVec3) -> f64 {
        let ray = crate::CameraRay { origin, direction: point - origin };
        self.scene.camera.pdf_we(&ray).1
    }

    /// Area density at `vertex` of a vertex `v` that chooses the direction towards it with
    /// solid-angle density `pdf`.
    fn to_area(pdf: f64, from: DVec3, vertex: &Vertex) -> f64 {
        let to = vertex.point - from;
        let d2 = to.length_squared();
        if !(d2 > 0.0) {
            return 0.0;
        }
        let mut p = pdf / d2;
        if vertex.ng != DVec3::ZERO {
            p *= (to.dot(vertex.ng) / d2.sqrt()).abs();
        }
        p
    }

    /// Area density with which `v`, reached from `prev`, samples `next` (pbrt's `Vertex::Pdf`).
    /// Light vertices ignore `prev`; `light` is the light of a vertex that emits.
    fn pdf(&self, v: &Vertex, prev: Option<&Vertex>, next: &Vertex, light: Option<LightId>) -> f64 {
        let solid = match v.kind {
            VertexKind::Camera => self.camera_pdf(v.point, next.point),
            VertexKind::Light(id) => self.light_pdfs(id, v.point, next.point - v.point).1,
            VertexKind::Surface(hit) => {
                if let Some(id) = light.filter(|_| prev.is_none()) {
                    self.light_pdfs(id, v.point, next.point - v.point).1
                } else {
                    let Some(prev) = prev else { return 0.0 };
                    let Some(material) = self.lobe(v, &hit) else { return 0.0 };
                    let wp = (prev.point - v.point).normalize();
                    let wn = (next.point - v.point).normalize();
                    material.pdf(wp, wn, hit.shading_normal, v.lambda)
                }
            }
        };
        if solid > 0.0 { Self::to_area(solid, v.point, next) } else { 0.0 }
    }

    /// What scatters at surface vertex `v` (on `hit`): its material, or the white Lambertian
    /// lobe of a fluorescent re-emission.
    fn lobe(&self, v: &Vertex, hit: &Hit) -> Option<&dyn Material> {
        if v.reemitted {
            return Some(reemission_lobe());
        }
        self.scene.materials.get(hit.primitive as usize).map(|m| m.as_ref())
    }

    /// A light's `(position, direction)` emission densities from `point` along `direction`
    /// (any length).
    fn light_pdfs(&self, id: LightId, point: DVec3, direction: DVec3) -> (f64, f64) {
        let Some(light) = self.scene.lights.light(id) else { return (0.0, 0.0) };
        let direction = direction.normalize();
        if let Some(p) = light.pdf_emission(point, direction) {
            return p;
        }
        let flags = light.flags().unwrap_or_default();
        let position = if flags.delta_position {
            1.0
        } else {
            let area = surface_area(light);
            if area > 0.0 { 1.0 / area } else { 0.0 }
        };
        let dir =
            if flags.delta_direction { 1.0 } else { light.emission_density(point, direction) };
        (position, dir)
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
        let beam = LightSource::next_beam(scene.lights, rng);
        let density = self.set_spd.value(beam.lambda);
        let wl = Wavelength { lambda: beam.lambda, density };
        let camera_strategies = beam.scale == 1.0 && density > 0.0 && density.is_finite();
        let Some(light) = self.light_end(beam.parent, &wl) else { return };
        // The film holds values relative to the lights' total power (see `image_scale`).
        let power = scene.lights.power();
        let inv_y = if power > 0.0 { 1.0 / (*CIE_Y_INTEGRAL * power) } else { 0.0 };
        let pixels = self.pass_samples().max(1) as f64;

        generate_light_subpath(self, &beam, &light, &wl, camera_strategies, rng, buffers, stats);
        buffers.camera.clear();
        if camera_strategies {
            generate_camera_subpath(self, px, py, &wl, rng, buffers, stats);
        } else {
            buffers.camera.push(Vertex::camera(scene.camera.position(), wl.lambda));
        }

        let max_len = self.settings.max_depth.min(crate::MAX_DEPTH) as usize + 3;
        let mut radiance = 0.0;
        let Buffers { light: lv, camera: cv, mis } = buffers;
        for t in 1..=cv.len() {
            if !camera_strategies && t > 1 {
                break;
            }
            for s in 0..=lv.len() {
                if s + t < 2 || s + t > max_len {
                    continue;
                }
                if self.settings.only_strategy.is_some_and(|only| only != (s, t)) {
                    continue;
                }
                let Some(mut c) =
                    connect(self, lv, cv, s, t, &light, &wl, camera_strategies, rng, mis)
                else {
                    continue;
                };
                if self.settings.only_strategy.is_some() {
                    // Unweighted: undo the MIS weight.
                    c.value = if c.weight > 0.0 { c.value / c.weight } else { 0.0 };
                }
                if !(c.value > 0.0 && c.value.is_finite()) {
                    continue;
                }
                match c.raster {
                    Some((x, y)) => {
                        let xyz = cmf(c.lambda) * (c.value * inv_y / pixels);
                        if film.splat(x, y, xyz) {
                            stats.splats += 1;
                        }
                    }
                    None => radiance += c.value,
                }
            }
        }
        if radiance != 0.0 {
            film.splat(px, py, cmf(wl.lambda) * (radiance * inv_y));
        }
    }
}

/// Area of a light's emitting surface, 0 when it has none.
fn surface_area(light: &dyn LightSource) -> f64 {
    match light.surface() {
        Some(LightSurface::Rectangle { edge_u, edge_v, .. }) => edge_u.cross(edge_v).length(),
        Some(LightSurface::Disk { radius, .. }) => PI * radius * radius,
        _ => 0.0,
    }
}

/// Unit normal of a light's surface at `point`, zero when it has none.
fn light_normal(light: &dyn LightSource, point: DVec3) -> DVec3 {
    light.normal_at(point).unwrap_or_else(|| surface_normal(light))
}

/// Unit normal of a light's emitting surface, zero when it has none.
fn surface_normal(light: &dyn LightSource) -> DVec3 {
    match light.surface() {
        Some(LightSurface::Rectangle { edge_u, edge_v, .. }) => {
            edge_u.cross(edge_v).normalize_or_zero()
        }
        Some(LightSurface::Disk { normal, .. }) => normal.normalize_or_zero(),
        _ => DVec3::ZERO,
    }
}

/// The camera subpath of a sample of pixel `(px, py)` into `buffers.camera`: the pinhole (or a
/// uniform point of the lens), then a random walk from a ray through a uniform point of the pixel
/// ([`crate::PinholeCamera::generate_ray`]).
fn generate_camera_subpath(
    bdpt: &Bdpt<'_>,
    px: u32,
    py: u32,
    wl: &Wavelength,
    rng: &mut dyn rand::Rng,
    buffers: &mut Buffers,
    stats: &mut TraceStats,
) {
    let camera = bdpt.scene.camera;
    let u_film = [uniform(rng), uniform(rng)];
    // A pinhole draws no lens uniforms, so that its images keep their random streams.
    let u_lens = if camera.is_pinhole() { [0.5; 2] } else { [uniform(rng), uniform(rng)] };
    let camera_ray = camera.generate_ray(px, py, u_film, u_lens);
    let ray = Ray { origin: camera_ray.origin, direction: camera_ray.direction };
    buffers.camera.push(Vertex::camera(ray.origin, wl.lambda));
    let pdf_dir = camera.pdf_we(&camera_ray).1;
    let first = bdpt.scene.world.intersect(&ray, f64::INFINITY);
    let max = bdpt.max_vertices().0;
    random_walk(
        bdpt,
        ray,
        first,
        1.0,
        pdf_dir,
        Transport::Radiance,
        false,
        max,
        &mut buffers.camera,
        rng,
        stats,
    );
}

/// The light subpath of `beam` into `buffers.light`: the beam's origin on its light, then a
/// random walk along the beam.
#[allow(clippy::too_many_arguments)]
fn generate_light_subpath(
    bdpt: &Bdpt<'_>,
    beam: &spectrace_lights::Beam,
    light: &LightEnd,
    wl: &Wavelength,
    camera_strategies: bool,
    rng: &mut dyn rand::Rng,
    buffers: &mut Buffers,
    stats: &mut TraceStats,
) {
    let scene = bdpt.scene;
    buffers.light.clear();
    let Some(source) = scene.lights.light(light.id) else { return };
    let (pdf_pos, pdf_dir) = bdpt.light_pdfs(light.id, beam.origin, beam.direction);
    let beta = scene.lights.power() * beam.scale;
    buffers.light.push(Vertex {
        kind: VertexKind::Light(light.id),
        point: beam.origin,
        ng: light_normal(source, beam.origin),
        beta,
        delta: light.flags.delta_direction,
        pdf_fwd: if camera_strategies { light.pmf * pdf_pos } else { 1.0 },
        pdf_rev: 0.0,
        lambda: wl.lambda,
        reemitted: false,
        fluoresced: false,
    });
    let ray = Ray { origin: beam.origin, direction: beam.direction };
    let first = scene.intersect_from_light(&ray, light.id, f64::INFINITY);
    let pdf_dir = if light.flags.delta_direction { 0.0 } else { pdf_dir };
    let max = bdpt.max_vertices().1;
    random_walk(
        bdpt,
        ray,
        first,
        beta,
        pdf_dir,
        Transport::Importance,
        true,
        max,
        &mut buffers.light,
        rng,
        stats,
    );
}

/// Follows `ray` (whose first hit is `first`) through the scene, appending a vertex per surface
/// hit to `path` (which holds the subpath's start) until it has `max` vertices, the path is
/// absorbed or Russian roulette ends it. `beta` is the throughput on leaving the start, `pdf_dir`
/// the solid-angle density of the ray's direction (0 for a delta).
#[allow(clippy::too_many_arguments)]
fn random_walk(
    bdpt: &Bdpt<'_>,
    mut ray: Ray,
    first: Option<Hit>,
    mut beta: f64,
    mut pdf_dir: f64,
    transport: Transport,
    reemit: bool,
    max: usize,
    path: &mut Vec<Vertex>,
    rng: &mut dyn rand::Rng,
    stats: &mut TraceStats,
) {
    let scene = bdpt.scene;
    let start = beta;
    let mut next = first;
    while let Some(hit) = next.take() {
        stats.hits += 1;
        let Some(prev) = path.last().copied() else { return };
        let mut v = Vertex::surface(hit, beta, prev.lambda, prev.fluoresced);
        v.pdf_fwd = Bdpt::to_area(pdf_dir, prev.point, &v);
        let Some(material) = scene.materials.get(hit.primitive as usize) else {
            path.push(v);
            return;
        };
        let mut material: &dyn Material = material.as_ref();
        if reemit && let Some(fluorescent) = material.fluorescence() {
            // Elastic or re-emitted (light subpaths only), decided before any connection to
            // this vertex; the branch's factor belongs to the vertex's scattering, so it enters
            // `beta` here.
            let (u_choice, u_lambda) = (uniform(rng), uniform(rng));
            let (mut l, mut w) = ([v.lambda], [beta]);
            match fluorescent.choose_forward(&mut l, &mut w, u_choice, u_lambda) {
                Reemission::Elastic => {}
                Reemission::Reemitted { lambda } => {
                    stats.reemissions += 1;
                    material = reemission_lobe();
                    v.lambda = lambda;
                    v.reemitted = true;
                    v.fluoresced = true;
                }
                Reemission::Absorbed => {
                    path.push(v);
                    return;
                }
            }
            beta = w[0];
            v.beta = beta;
        }
        path.push(v);
        if path.len() >= max {
            stats.depth_limited += 1;
            return;
        }
        let u = [uniform(rng), uniform(rng), uniform(rng)];
        let incoming =
            Incoming { direction: ray.direction, normal: hit.shading_normal, lambda: v.lambda };
        let Some(s) = material.scatter_with(&incoming, u, transport) else { return };
        let wp = -ray.direction;
        let mut weight = s.weight;
        if transport == Transport::Importance {
            weight *= shading_correction(&hit, wp, s.direction);
        }
        beta *= weight;
        let n = path.len();
        let pdf_rev = if s.kind == ScatterKind::Specular {
            path[n - 1].delta = true;
            pdf_dir = 0.0;
            0.0
        } else {
            pdf_dir = s.pdf;
            material.pdf(s.direction, wp, hit.shading_normal, v.lambda)
        };
        path[n - 2].pdf_rev = Bdpt::to_area(pdf_rev, hit.point, &prev);
        if (n - 1) as u32 > bdpt.settings.rr_depth {
            let survive = if start > 0.0 { (beta / start).min(1.0) } else { 0.0 };
            if !(uniform(rng) < survive) {
                stats.roulette_kills += 1;
                return;
            }
            beta /= survive;
        }
        if !(beta > 0.0 && beta.is_finite()) {
            return;
        }
        ray = hit.spawn_ray(s.direction);
        next = scene.world.intersect(&ray, f64::INFINITY);
    }
}

/// What one strategy gives: the value (film units before the colour matching), and the pixel
/// for a `t = 1` splat (`None`: the sample's own pixel).
struct Contribution {
    value: f64,
    raster: Option<(u32, u32)>,
    /// The wavelength a `t = 1` splat is recorded at (the light subpath's, which differs from
    /// the sample's beyond a re-emission).
    lambda: f64,
    /// The MIS weight applied (included in `value`).
    #[cfg_attr(not(test), allow(dead_code))]
    weight: f64,
    /// Whether the path's light cannot be hit by a camera path (for tests of the weights).
    #[cfg_attr(not(test), allow(dead_code))]
    light_is_delta: bool,
}

/// The BSDF at surface vertex `v` for light arriving from `from` and leaving towards `to`, with
/// `transport`'s adjoint; 0 for other vertices.
fn bsdf(bdpt: &Bdpt<'_>, v: &Vertex, from: DVec3, to: DVec3, transport: Transport) -> f64 {
    let VertexKind::Surface(hit) = v.kind else { return 0.0 };
    let Some(material) = bdpt.lobe(v, &hit) else { return 0.0 };
    let wi = (from - v.point).normalize();
    let wo = (to - v.point).normalize();
    material.eval_with(wi, wo, hit.shading_normal, v.lambda, transport)
}

/// Strategy `(s, t)` for the subpaths `light` and `camera` (pbrt's `ConnectBDPT`), weighted by
/// [`mis_weight`]; `None` when it gives nothing.
#[allow(clippy::too_many_arguments)]
fn connect(
    bdpt: &Bdpt<'_>,
    light: &[Vertex],
    camera: &[Vertex],
    s: usize,
    t: usize,
    beam_light: &LightEnd,
    wl: &Wavelength,
    camera_strategies: bool,
    rng: &mut dyn rand::Rng,
    mis: &mut Vec<MisVertex>,
) -> Option<Contribution> {
    let scene = bdpt.scene;
    if s >= 2 && light[s - 1].delta {
        return None;
    }
    if s > 0 && t > 1 && camera[t - 1].delta {
        return None;
    }
    let mut raster = None;
    let mut sampled: Option<Vertex> = None;
    let mut sampled_camera: Option<Vertex> = None;
    let mut end = *beam_light;
    // The wavelength a `t = 1` splat is recorded at: the sample's, or beyond a re-emission
    // on the light subpath the re-emitted one.
    let mut splat_lambda = wl.lambda;
    let value;
    if s == 0 {
        // The camera subpath hits an emitter.
        let pt = &camera[t - 1];
        let VertexKind::Surface(hit) = pt.kind else { return None };
        let wo = (camera[t - 2].point - pt.point).normalize();
        let (id, le) = scene.emitted(&hit, wo)?;
        let spd = scene.light_spd(id)?;
        end = bdpt.light_end(id, wl)?;
        value = pt.beta * le * spd.value(wl.lambda) / wl.density;
    } else if t == 1 {
        // A light vertex seen by the camera, through a point of the lens sampled towards it
        // (the pinhole for a pinhole camera: no uniforms drawn).
        let qs = &light[s - 1];
        let lens = scene.camera;
        let u_lens = if lens.is_pinhole() { [0.5; 2] } else { [uniform(rng), uniform(rng)] };
        let cs = lens.sample_wi(qs.point, u_lens)?;
        if !(cs.pdf > 0.0 && cs.importance > 0.0) {
            return None;
        }
        match qs.kind {
            VertexKind::Light(id) => {
                let density = bdpt.light_pdfs(id, qs.point, cs.to_camera).1;
                if !(density > 0.0) || beam_light.flags.delta_direction {
                    return None;
                }
                let shadow = Ray { origin: qs.point, direction: cs.to_camera };
                if scene.intersect_from_light(&shadow, id, cs.distance).is_some() {
                    return None;
                }
                value = qs.beta * density * cs.importance;
            }
            VertexKind::Surface(hit) => {
                let (shadow, distance) = hit.spawn_ray_to(cs.position);
                if scene.world.occluded(&shadow, distance) {
                    return None;
                }
                let wi = (light[s - 2].point - qs.point).normalize();
                let cos = if hit.shading_normal == hit.geometric_normal {
                    cs.to_camera.dot(hit.shading_normal).abs()
                } else {
                    let cos_in = wi.dot(hit.geometric_normal).abs();
                    if !(cos_in > 0.0) {
                        return None;
                    }
                    cs.to_camera.dot(hit.geometric_normal).abs() * wi.dot(hit.shading_normal).abs()
                        / cos_in
                };
                let f = bsdf(bdpt, qs, light[s - 2].point, cs.position, Transport::Importance);
                value = qs.beta * f * cos * cs.importance;
                splat_lambda = qs.lambda;
            }
            VertexKind::Camera => return None,
        }
        raster = Some((cs.x, cs.y));
        sampled_camera = Some(Vertex::camera(cs.position, qs.lambda));
    } else if s == 1 {
        // Next-event estimation: a light chosen by pmf(l | lambda), a point on it.
        let pt = &camera[t - 1];
        let VertexKind::Surface(hit) = pt.kind else { return None };
        let id = choose_light(bdpt, wl, uniform(rng))?;
        end = bdpt.light_end(id, wl)?;
        let u = [uniform(rng), uniform(rng)];
        let source = scene.lights.light(id)?;
        let sample = source.sample_towards(pt.point, u)?;
        let pmf = scene.lights.pmf(id);
        if !(sample.intensity > 0.0 && sample.distance > 0.0 && pmf > 0.0 && end.pmf > 0.0) {
            return None;
        }
        let wi = -sample.direction;
        let f = bsdf(bdpt, pt, sample.position, camera[t - 2].point, Transport::Radiance);
        let cos = wi.dot(hit.shading_normal).abs();
        if !(f > 0.0 && cos > 0.0) {
            return None;
        }
        let (shadow, distance) = hit.spawn_ray_to(sample.position);
        if scene.world.occluded(&shadow, distance * (1.0 - 1e-9)) {
            return None;
        }
        value = pt.beta * f * cos * sample.intensity / (sample.distance * sample.distance * pmf);
        let (pdf_pos, _) = bdpt.light_pdfs(id, sample.position, sample.direction);
        sampled = Some(Vertex {
            kind: VertexKind::Light(id),
            point: sample.position,
            ng: light_normal(source, sample.position),
            beta: 0.0,
            delta: end.flags.delta_direction,
            pdf_fwd: end.pmf * pdf_pos,
            pdf_rev: 0.0,
            lambda: wl.lambda,
            reemitted: false,
            fluoresced: false,
        });
    } else {
        // Two surface vertices joined by a shadow ray.
        let (qs, pt) = (&light[s - 1], &camera[t - 1]);
        let (VertexKind::Surface(hq), VertexKind::Surface(hp)) = (qs.kind, pt.kind) else {
            return None;
        };
        if qs.fluoresced {
            // Beyond a re-emission the light subpath travels at another wavelength than the
            // camera subpath: only its connection to the camera (`t = 1`) joins them.
            return None;
        }
        let f_light = bsdf(bdpt, qs, light[s - 2].point, pt.point, Transport::Importance);
        if !(f_light > 0.0) {
            return None;
        }
        let f_camera = bsdf(bdpt, pt, qs.point, camera[t - 2].point, Transport::Radiance);
        if !(f_camera > 0.0) {
            return None;
        }
        let d = pt.point - qs.point;
        let d2 = d.length_squared();
        if !(d2 > 0.0) {
            return None;
        }
        let w = d / d2.sqrt();
        let wi = (light[s - 2].point - qs.point).normalize();
        let cos_in = wi.dot(hq.geometric_normal).abs();
        if !(cos_in > 0.0) {
            return None;
        }
        // The light side's cosine with the shading-normal correction of importance transport.
        let cos_q = wi.dot(hq.shading_normal).abs() * w.dot(hq.geometric_normal).abs() / cos_in;
        let cos_p = w.dot(hp.shading_normal).abs();
        let target = hp.spawn_origin(qs.point - pt.point);
        let (shadow, distance) = hq.spawn_ray_to(target);
        if scene.world.occluded(&shadow, distance) {
            return None;
        }
        value = qs.beta * f_light * cos_q * cos_p / d2 * f_camera * pt.beta;
    }
    if !(value > 0.0 && value.is_finite()) {
        return None;
    }
    let fluoresced = s > 0 && light[s - 1].fluoresced;
    let (weight, light_is_delta) = if camera_strategies && !fluoresced {
        let sampled = Sampled { light: sampled.as_ref(), camera: sampled_camera.as_ref() };
        let delta = build_mis_path(bdpt, light, camera, s, t, sampled, &end, mis);
        (mis_weight(mis, s, delta), delta)
    } else {
        // Without camera strategies, or for a path that fluoresced on its light subpath, the
        // connection to the camera is the only strategy that makes the path.
        (1.0, true)
    };
    Some(Contribution {
        value: value * weight,
        raster,
        lambda: splat_lambda,
        weight,
        light_is_delta,
    })
}

/// Chooses a light with probability `pmf(l | lambda)` from a uniform `u`.
fn choose_light(bdpt: &Bdpt<'_>, wl: &Wavelength, u: f64) -> Option<LightId> {
    let lights = bdpt.scene.lights;
    let weight = |i: usize| {
        let id = LightId(i as u32);
        let spd = bdpt.scene.light_spd(id).map_or(0.0, |s| s.value(wl.lambda));
        lights.pmf(id) * spd
    };
    let n = lights.lights().len();
    let total: f64 = (0..n).map(weight).sum();
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    let target = u * total;
    let mut acc = 0.0;
    let mut last = None;
    for i in 0..n {
        let w = weight(i);
        if w > 0.0 {
            acc += w;
            last = Some(LightId(i as u32));
            if target < acc {
                return last;
            }
        }
    }
    last
}

/// The vertices a strategy sampled afresh: the light vertex of next-event estimation (`s = 1`),
/// the lens point of a connection to the camera (`t = 1`).
#[derive(Clone, Copy)]
struct Sampled<'v> {
    light: Option<&'v Vertex>,
    camera: Option<&'v Vertex>,
}

/// The full path of strategy `(s, t)` as [`MisVertex`]es into `mis`, from the light to the
/// camera, with the densities at the connection updated; returns whether its light cannot be
/// hit by a camera path.
#[allow(clippy::too_many_arguments)]
fn build_mis_path(
    bdpt: &Bdpt<'_>,
    light: &[Vertex],
    camera: &[Vertex],
    s: usize,
    t: usize,
    sampled: Sampled<'_>,
    end: &LightEnd,
    mis: &mut Vec<MisVertex>,
) -> bool {
    mis.clear();
    let qs = if s == 1 {
        sampled.light.copied().or_else(|| light.first().copied())
    } else if s > 0 {
        Some(light[s - 1])
    } else {
        None
    };
    let pt = match sampled.camera {
        Some(c) if t == 1 => *c,
        _ => camera[t - 1],
    };
    let qs_minus = if s >= 2 { Some(light[s - 2]) } else { None };
    let pt_minus = if t >= 2 { Some(camera[t - 2]) } else { None };
    for (i, v) in light.iter().take(s).enumerate() {
        let v = if i + 1 == s { qs.unwrap_or(*v) } else { *v };
        mis.push(MisVertex { from_light: v.pdf_fwd, from_camera: v.pdf_rev, delta: v.delta });
    }
    for (j, v) in camera[..t].iter().enumerate().rev() {
        let v = if j + 1 == t { pt } else { *v };
        mis.push(MisVertex { from_light: v.pdf_rev, from_camera: v.pdf_fwd, delta: v.delta });
    }
    let ip = s; // index of pt in the full path
    let light_id = if s == 0 { Some(end.id) } else { None };
    // pt as sampled from the light side.
    mis[ip].from_light = match qs.as_ref() {
        Some(q) => bdpt.pdf(q, qs_minus.as_ref(), &pt, None),
        None => {
            let dir = pt_minus.map_or(DVec3::ZERO, |m| m.point - pt.point);
            end.pmf * bdpt.light_pdfs(end.id, pt.point, dir).0
        }
    };
    mis[ip].delta = if s == 0 { end.flags.delta_direction } else { false };
    if let Some(m) = pt_minus.as_ref() {
        mis[ip + 1].from_light = match qs.as_ref() {
            Some(q) => bdpt.pdf(&pt, Some(q), m, None),
            None => bdpt.pdf(&pt, None, m, light_id),
        };
    }
    if let Some(q) = qs.as_ref() {
        mis[s - 1].from_camera = bdpt.pdf(&pt, pt_minus.as_ref(), q, None);
        mis[s - 1].delta = if s == 1 { end.flags.delta_direction } else { false };
        if let Some(qm) = qs_minus.as_ref() {
            mis[s - 2].from_camera = bdpt.pdf(q, Some(&pt), qm, None);
        }
    }
    let on_surface = match s {
        0 => true,
        1 => qs.is_some_and(|q| q.ng != DVec3::ZERO),
        _ => light[0].ng != DVec3::ZERO,
    };
    end.is_delta(on_surface)
}

impl Integrator for Bdpt<'_> {
    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn resolution(&self) -> (u32, u32) {
        (self.scene.camera.width(), self.scene.camera.height())
    }

    /// One pass, mapped to pixels as the path tracer's (`pass_pixel`: whole passes sample every
    /// pixel once, one-item probe chunks spread over the image), each sample with its light
    /// path. The deadline is not looked at: a pass is never cut.
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
        let (camera_max, light_max) = self.max_vertices();
        let mut buffers = Buffers {
            light: Vec::with_capacity(light_max.min(64)),
            camera: Vec::with_capacity(camera_max.min(64)),
            mis: Vec::with_capacity((camera_max + light_max).min(128)),
        };
        let start = pass_start(chunk, pixels);
        for i in 0..samples {
            let (px, py) = pass_pixel(start, i, pixels, width);
            // Sobol: the pixel's own sequence, one point per pass.
            rng.start_path(u64::from(py) * width + u64::from(px), chunk);
            self.sample_pixel(px, py, &mut rng, &mut buffers, film, &mut stats);
            stats.beams += 1;
        }
        stats
    }

    /// The lights' power times the pixels over the samples: the film holds each sample's
    /// estimate divided by the lights' total power, as the path tracer's (the renderer's
    /// normalisation of camera integrators), and the image is the mean per pixel.
    fn image_scale(&self, samples_done: u64) -> f64 {
        camera_image_scale(self.scene.lights.power(), self.pass_samples(), samples_done)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use rand::SeedableRng;
    use rand_pcg::Pcg64;
    use spectrace_geometry::{Rectangle, Shape, Sphere, World};
    use spectrace_lights::LightSet;
    use spectrace_materials::Material;

    use super::*;
    use crate::light_tracer::Emitter;
    use crate::{
        CameraRepr, EffectsMode, FovAxis, LightTracer, LightTracerSettings, PathTracer,
        PathTracerSettings, PinholeCamera, RenderPlan, render,
    };

    /// A scene built in code: shapes (with their materials), lights, camera, emitters.
    struct Fixture {
        world: World,
        materials: Vec<Arc<dyn Material>>,
        lights: LightSet,
        camera: PinholeCamera,
        emitters: Vec<Option<Emitter>>,
        objects: usize,
    }

    impl Fixture {
        fn scene(&self) -> LightTracerScene<'_> {
            LightTracerScene::new(&self.world, &self.materials, &self.lights, &self.camera)
                .with_emitters(self.emitters.clone(), self.objects)
        }
    }

    fn material(json: &str) -> Arc<dyn Material> {
        let m: Box<dyn Material> = serde_json::from_str(json).unwrap();
        Arc::from(m)
    }

    fn light(json: &str) -> Box<dyn LightSource> {
        serde_json::from_str(json).unwrap()
    }

    fn rect(corner: [f64; 3], u: [f64; 3], v: [f64; 3]) -> Shape {
        Shape::Rectangle(
            Rectangle::new(DVec3::from(corner), DVec3::from(u), DVec3::from(v)).unwrap(),
        )
    }

    fn camera(position: [f64; 3], look_at: [f64; 3]) -> PinholeCamera {
        PinholeCamera::new(CameraRepr {
            position: DVec3::from(position),
            look_at: DVec3::from(look_at),
            up: DVec3::Y,
            fov: 50.0,
            fov_axis: FovAxis::Horizontal,
            width: 16,
            height: 16,
            aperture_radius: 0.0,
            focus_distance: None,
        })
        .unwrap()
    }

    const DIFFUSE: &str = r#"{"type": "Diffuse", "reflectance": 0.7}"#;
    const SPOT: &str = r#"{"type": "FadingSpotLight", "position": [0, 1.5, 0], "direction": [0, -1, 0],
        "cone_angle": 35, "fade_per_angle": 0.2, "power": 10, "spd": {"type": "Blackbody", "kelvin": 4000}}"#;

    /// A fading spot over a diffuse floor.
    fn spot_scene() -> Fixture {
        let shapes = vec![rect([-2.0, 0.0, -2.0], [0.0, 0.0, 4.0], [4.0, 0.0, 0.0])];
        Fixture {
            world: World::new(shapes).unwrap(),
            materials: vec![material(DIFFUSE)],
            lights: LightSet::new(vec![light(SPOT)]).unwrap(),
            camera: camera([0.0, 1.2, 2.0], [0.0, 0.0, 0.0]),
            emitters: Vec::new(),
            objects: 1,
        }
    }

    /// A Cornell-like box (open at the front) lit by a rectangle under its ceiling, which the
    /// camera sees.
    fn box_scene() -> Fixture {
        let shapes = vec![
            rect([-1.0, 0.0, -1.0], [0.0, 0.0, 2.0], [2.0, 0.0, 0.0]), // floor
            rect([-1.0, 2.0, -1.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0]), // ceiling
            rect([-1.0, 0.0, -1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]), // back
            rect([-1.0, 0.0, -1.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]), // left
            rect([1.0, 0.0, -1.0], [0.0, 0.0, 2.0], [0.0, 2.0, 0.0]),  // right
            // The light's surface, just below the ceiling.
            rect([-0.3, 1.98, -0.3], [0.6, 0.0, 0.0], [0.0, 0.0, 0.6]),
        ];
        let materials = vec![
            material(DIFFUSE),
            material(DIFFUSE),
            material(DIFFUSE),
            material(r#"{"type": "Diffuse", "reflectance": 0.5}"#),
            material(r#"{"type": "Diffuse", "reflectance": 0.3}"#),
            material(r#"{"type": "Diffuse", "reflectance": 0.0}"#),
        ];
        let area = light(
            r#"{"type": "RectangleLight", "corner": [-0.3, 1.98, -0.3], "edge_u": [0.6, 0, 0],
            "edge_v": [0, 0, 0.6], "power": 20, "spd": {"type": "Blackbody", "kelvin": 5000}}"#,
        );
        let mut emitters = vec![None; 6];
        emitters[5] = Some(Emitter::Light(LightId(0)));
        Fixture {
            world: World::new(shapes).unwrap(),
            materials,
            lights: LightSet::new(vec![area]).unwrap(),
            camera: camera([0.0, 1.0, 3.2], [0.0, 1.0, 0.0]),
            emitters,
            objects: 5,
        }
    }

    /// A glass sphere under the spot, over the floor: a caustic.
    fn caustic_scene() -> Fixture {
        let shapes = vec![
            rect([-2.0, 0.0, -2.0], [0.0, 0.0, 4.0], [4.0, 0.0, 0.0]),
            Shape::Sphere(Sphere::new(DVec3::new(0.0, 0.6, 0.0), 0.35).unwrap()),
        ];
        Fixture {
            world: World::new(shapes).unwrap(),
            materials: vec![material(DIFFUSE), material(r#"{"type": "Dielectric", "ior": 1.5}"#)],
            lights: LightSet::new(vec![light(SPOT)]).unwrap(),
            camera: camera([0.0, 1.4, 1.6], [0.0, 0.2, 0.0]),
            emitters: Vec::new(),
            objects: 2,
        }
    }

    /// A closed diffuse sphere of reflectance `a` whose surface glows on both sides (radiance
    /// `L`), with the camera inside: every pixel sees `L / (1 - a)` (the white furnace).
    fn furnace_scene(a: f64) -> Fixture {
        let sphere = Shape::Sphere(Sphere::new(DVec3::ZERO, 1.5).unwrap());
        let emission: crate::ObjectEmission = serde_json::from_str(
            r#"{"power": 30, "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700},
            "two_sided": true}"#,
        )
        .unwrap();
        let light = crate::ObjectLight::new(sphere.clone(), &emission).unwrap();
        let emitter = Emitter::Object {
            light: LightId(0),
            radiance: light.radiance(),
            two_sided: true,
            area: light.area(),
        };
        let mut camera = camera([0.3, -0.2, 0.1], [0.0, 0.0, -1.0]);
        camera = PinholeCamera::new(CameraRepr { fov: 100.0, ..camera.into() }).unwrap();
        Fixture {
            world: World::new(vec![sphere]).unwrap(),
            materials: vec![material(&format!(r#"{{"type": "Diffuse", "reflectance": {a}}}"#))],
            lights: LightSet::new(vec![Box::new(light)]).unwrap(),
            camera,
            emitters: vec![Some(emitter)],
            objects: 1,
        }
    }

    fn effects(scene: &LightTracerScene<'_>) -> Effects {
        Effects::decide(scene.features(&[false; 8]), EffectsMode::Off)
    }

    /// Mean Y over the image (the pixels `mask` keeps) of `runs` independent renders (seeds
    /// 1..=runs) of `items` work items each (chunks of `chunk`), and its standard error.
    fn mean_y(
        integrator: &dyn Integrator,
        runs: u64,
        items: u64,
        chunk: u64,
        mask: &[bool],
    ) -> (f64, f64) {
        let means: Vec<f64> = (1..=runs)
            .map(|seed| {
                let plan = RenderPlan {
                    beams: items,
                    chunk_beams: chunk,
                    seed,
                    threads: 2,
                    shard: None,
                    time_budget: None,
                    error_estimate: false,
                    target_error: None,
                };
                let out = render(integrator, &plan, &|_| {}).unwrap();
                let image = out.film.to_xyz(integrator.image_scale(out.beams));
                let kept = image.iter().zip(mask).filter(|(_, keep)| **keep);
                let n = kept.clone().count();
                kept.map(|(p, _)| p.y).sum::<f64>() / n as f64
            })
            .collect();
        let k = means.len() as f64;
        let mean = means.iter().sum::<f64>() / k;
        let var = means.iter().map(|m| (m - mean) * (m - mean)).sum::<f64>() / (k - 1.0);
        (mean, (var / k).sqrt())
    }

    fn assert_agree(name: &str, a: (f64, f64), b: (f64, f64)) {
        let combined = (a.1 * a.1 + b.1 * b.1).sqrt();
        assert!(a.0 > 0.0 && b.0 > 0.0, "{name}: {a:?} {b:?}");
        // The test is only meaningful if the estimates are precise.
        assert!(combined < 0.05 * a.0, "{name}: standard errors too large: {a:?} {b:?}");
        assert!((a.0 - b.0).abs() < 3.0 * combined, "{name}: {a:?} vs {b:?}");
    }

    const ALL: [bool; 256] = [true; 256];

    fn bdpt_mean(
        scene: &LightTracerScene<'_>,
        runs: u64,
        passes: u64,
        mask: &[bool],
    ) -> (f64, f64) {
        let bdpt = Bdpt::new(scene, BdptSettings::default(), effects(scene));
        let pixels = bdpt.pass_samples();
        mean_y(&bdpt, runs, passes * pixels, pixels, mask)
    }

    fn light_mean(
        scene: &LightTracerScene<'_>,
        runs: u64,
        beams: u64,
        mask: &[bool],
    ) -> (f64, f64) {
        let lt = LightTracer::new(scene, LightTracerSettings::default(), effects(scene));
        mean_y(&lt, runs, beams, 20_000, mask)
    }

    fn path_mean(scene: &LightTracerScene<'_>, runs: u64, passes: u64) -> (f64, f64) {
        let pt = PathTracer::new(scene, PathTracerSettings::default(), effects(scene));
        let pixels = pt.pass_samples();
        mean_y(&pt, runs, passes * pixels, pixels, &ALL)
    }

    /// The pixels in which no camera ray (on an 8 x 8 grid) sees shape `shape` first.
    fn pixels_not_seeing(fixture: &Fixture, shape: u32) -> Vec<bool> {
        let camera = &fixture.camera;
        let mut mask = vec![true; 256];
        for (p, keep) in mask.iter_mut().enumerate() {
            let (px, py) = ((p % 16) as f64, (p / 16) as f64);
            for k in 0..64 {
                let (u, v) = ((k % 8) as f64 / 7.0, (k / 8) as f64 / 7.0);
                let ray =
                    Ray { origin: camera.position(), direction: camera.direction(px + u, py + v) };
                if fixture
                    .world
                    .intersect(&ray, f64::INFINITY)
                    .is_some_and(|h| h.primitive == shape)
                {
                    *keep = false;
                }
            }
        }
        mask
    }

    #[test]
    fn mis_weight_counts_only_possible_strategies() {
        let v = |from_light, from_camera, delta| MisVertex { from_light, from_camera, delta };
        // Light, one diffuse vertex, camera: strategies s = 0, 1, 2 with densities
        // p0 = 2 * 3, p1 = 1 * 3, p2 = 1 * 4 (products of the chosen sides' densities).
        let path = [v(1.0, 2.0, false), v(4.0, 3.0, false), v(0.0, 0.0, false)];
        let (p0, p1, p2) = (6.0f64, 3.0f64, 4.0f64);
        let total = p0 * p0 + p1 * p1 + p2 * p2;
        for (s, p) in [(0, p0), (1, p1), (2, p2)] {
            assert!((mis_weight(&path, s, false) - p * p / total).abs() < 1e-15, "s = {s}");
        }
        // A delta light: s = 0 is impossible.
        let total = p1 * p1 + p2 * p2;
        assert!((mis_weight(&path, 1, true) - p1 * p1 / total).abs() < 1e-15);
        // A specular middle vertex: only s = 0 (the camera path hits the light) remains.
        let path = [v(1.0, 2.0, false), v(0.0, 0.0, true), v(0.0, 0.0, false)];
        assert_eq!(mis_weight(&path, 0, false), 1.0);
        assert_eq!(mis_weight(&[], 0, false), 0.0);
    }

    #[test]
    fn mis_weights_of_all_strategies_of_sampled_paths_sum_to_one() {
        for fixture in [box_scene(), caustic_scene(), spot_scene(), furnace_scene(0.6)] {
            let scene = fixture.scene();
            let bdpt = Bdpt::new(&scene, BdptSettings::default(), effects(&scene));
            let mut rng = Pcg64::seed_from_u64(11);
            let mut buffers = Buffers { light: Vec::new(), camera: Vec::new(), mis: Vec::new() };
            let mut stats = TraceStats::default();
            let mut checked = 0;
            let mut strategies = [0usize; 4];
            for i in 0..4000u32 {
                let beam = LightSource::next_beam(scene.lights, &mut rng);
                let density = bdpt.set_spd.value(beam.lambda);
                let wl = Wavelength { lambda: beam.lambda, density };
                let end = bdpt.light_end(beam.parent, &wl).unwrap();
                generate_light_subpath(
                    &bdpt,
                    &beam,
                    &end,
                    &wl,
                    true,
                    &mut rng,
                    &mut buffers,
                    &mut stats,
                );
                buffers.camera.clear();
                generate_camera_subpath(
                    &bdpt,
                    i % 16,
                    (i / 16) % 16,
                    &wl,
                    &mut rng,
                    &mut buffers,
                    &mut stats,
                );
                let (lv, cv) = (buffers.light.clone(), buffers.camera.clone());
                for t in 1..=cv.len() {
                    for s in 0..=lv.len() {
                        if s + t < 2 {
                            continue;
                        }
                        let mis = &mut buffers.mis;
                        let Some(c) =
                            connect(&bdpt, &lv, &cv, s, t, &end, &wl, true, &mut rng, mis)
                        else {
                            continue;
                        };
                        let n = mis.len();
                        assert_eq!(n, s + t);
                        let valid = |k: usize| {
                            if k == 0 {
                                !mis[0].delta && !c.light_is_delta
                            } else {
                                !mis[k - 1].delta && !mis[k].delta
                            }
                        };
                        assert!(valid(s), "strategy ({s}, {t}) gave light but is not counted");
                        assert!(c.weight > 0.0 && c.weight <= 1.0);
                        assert_eq!(c.weight, mis_weight(mis, s, c.light_is_delta));
                        let sum: f64 = (0..n)
                            .filter(|&k| valid(k))
                            .map(|k| mis_weight(mis, k, c.light_is_delta))
                            .sum();
                        assert!((sum - 1.0).abs() < 1e-9, "({s}, {t}): weights sum to {sum}");
                        checked += 1;
                        strategies[match (s, t) {
                            (0, _) => 0,
                            (1, _) => 1,
                            (_, 1) => 2,
                            _ => 3,
                        }] += 1;
                    }
                }
            }
            assert!(checked > 1000, "only {checked} connections");
            assert!(strategies[1] > 0 && strategies[2] > 0, "{strategies:?}");
            // Only the box has two diffuse surfaces that see each other, and a visible emitter.
            if fixture.objects == 5 || fixture.emitters.iter().any(Option::is_some) {
                assert!(strategies[0] > 0 && strategies[3] > 0, "{strategies:?}");
            }
        }
    }

    #[test]
    fn spot_over_a_plane_matches_the_light_and_path_tracers() {
        let fixture = spot_scene();
        let scene = fixture.scene();
        let bdpt = bdpt_mean(&scene, 8, 16, &ALL);
        assert_agree("bdpt vs light", bdpt, light_mean(&scene, 8, 200_000, &ALL));
        assert_agree("bdpt vs path", bdpt, path_mean(&scene, 8, 32));
    }

    #[test]
    fn cornell_box_matches_the_light_and_path_tracers() {
        let fixture = box_scene();
        let scene = fixture.scene();
        let bdpt = bdpt_mean(&scene, 8, 10, &ALL);
        assert_agree("bdpt vs light", bdpt, light_mean(&scene, 8, 80_000, &ALL));
        assert_agree("bdpt vs path", bdpt, path_mean(&scene, 8, 12));
    }

    #[test]
    fn glass_caustic_matches_the_light_tracer() {
        let fixture = caustic_scene();
        let scene = fixture.scene();
        // The light tracer cannot see anything through the glass (its paths end at a diffuse
        // vertex connected to the pinhole): compare the pixels where the sphere is not seen.
        let mask = pixels_not_seeing(&fixture, 1);
        let kept = mask.iter().filter(|k| **k).count();
        assert!((100..240).contains(&kept), "{kept} pixels kept");
        let bdpt = bdpt_mean(&scene, 8, 10, &mask);
        assert_agree("bdpt vs light", bdpt, light_mean(&scene, 8, 80_000, &mask));
        // The caustic is there: the floor under the sphere is brighter than without it.
        let plain = spot_scene();
        let plain_scene = plain.scene();
        let without = light_mean(&plain_scene, 4, 40_000, &mask);
        assert!(bdpt.0 > without.0 + 3.0 * (bdpt.1 + without.1), "{bdpt:?} vs {without:?}");
    }

    #[test]
    fn glowing_furnace_matches_the_closed_form_in_the_renderers_units() {
        // A closed two-sided glowing diffuse sphere seen from inside: L / (1 - a) everywhere.
        let a = 0.6;
        let fixture = furnace_scene(a);
        let scene = fixture.scene();
        let bdpt = Bdpt::new(&scene, BdptSettings::default(), effects(&scene));
        let pt = PathTracer::new(&scene, PathTracerSettings::default(), effects(&scene));
        // The renderer turns every camera integrator's film into an image with the lights'
        // power times the pixels over the samples: BDPT's film must be in the path tracer's
        // units (it was in absolute units, 30x too bright here, the lights' power).
        let (power, pixels) = (scene.lights.power(), bdpt.pass_samples());
        for samples in [256, 4096, 12_345] {
            let renderer = crate::image_scale(power, samples) * pixels as f64;
            assert!((bdpt.image_scale(samples) - renderer).abs() <= 1e-12 * renderer);
            assert_eq!(bdpt.image_scale(samples), pt.image_scale(samples));
        }
        let spd = spectrace_spectrum::Uniform::new(400.0, 700.0).unwrap();
        let l = 30.0 / (2.0 * PI * 4.0 * PI * 1.5 * 1.5);
        let expected = l / (1.0 - a) * spectrace_spectrum::xyz_of(&spd).y / *CIE_Y_INTEGRAL;
        let (mean, se) = mean_y(&bdpt, 6, 8 * pixels, pixels, &ALL);
        assert!((mean - expected).abs() < 4.0 * se, "{mean} vs {expected} (standard error {se})");
        assert!(se < 0.02 * expected, "standard error {se} vs {expected}");
    }

    #[test]
    fn thin_lens_matches_the_path_tracer() {
        // The spot over the plane through a thin lens (aperture 0.05) focused on the plane: camera
        // subpaths start on the lens, t = 1 connections sample the lens; the image mean is the
        // path tracer's within 4 combined standard errors.
        let mut fixture = spot_scene();
        let (position, look_at) = (DVec3::new(0.0, 1.2, 2.0), DVec3::ZERO);
        fixture.camera = PinholeCamera::new(CameraRepr {
            aperture_radius: 0.05,
            focus_distance: Some((look_at - position).length()),
            ..fixture.camera.clone().into()
        })
        .unwrap();
        assert!(!fixture.camera.is_pinhole());
        let scene = fixture.scene();
        let bdpt = bdpt_mean(&scene, 8, 16, &ALL);
        let path = path_mean(&scene, 8, 32);
        let combined = (bdpt.1 * bdpt.1 + path.1 * path.1).sqrt();
        assert!(combined < 0.03 * path.0, "standard errors too large: {bdpt:?} {path:?}");
        assert!((bdpt.0 - path.0).abs() < 4.0 * combined, "bdpt {bdpt:?} vs path {path:?}");
        // The MIS weights of the lens's strategies still sum to one.
        let mut rng = Pcg64::seed_from_u64(3);
        let bdpt = Bdpt::new(&scene, BdptSettings::default(), effects(&scene));
        let mut buffers = Buffers { light: Vec::new(), camera: Vec::new(), mis: Vec::new() };
        let mut stats = TraceStats::default();
        let mut lens_connections = 0;
        for i in 0..2000u32 {
            let beam = LightSource::next_beam(scene.lights, &mut rng);
            let wl = Wavelength { lambda: beam.lambda, density: bdpt.set_spd.value(beam.lambda) };
            let end = bdpt.light_end(beam.parent, &wl).unwrap();
            generate_light_subpath(
                &bdpt,
                &beam,
                &end,
                &wl,
                true,
                &mut rng,
                &mut buffers,
                &mut stats,
            );
            buffers.camera.clear();
            let (px, py) = (i % 16, (i / 16) % 16);
            generate_camera_subpath(&bdpt, px, py, &wl, &mut rng, &mut buffers, &mut stats);
            // The camera subpath starts on the lens.
            let start = buffers.camera[0].point;
            assert!((start - position).length() <= 0.05 + 1e-12);
            let (lv, cv) = (buffers.light.clone(), buffers.camera.clone());
            for t in 1..=cv.len() {
                for s in 0..=lv.len() {
                    if s + t < 2 {
                        continue;
                    }
                    let mis = &mut buffers.mis;
                    let Some(c) = connect(&bdpt, &lv, &cv, s, t, &end, &wl, true, &mut rng, mis)
                    else {
                        continue;
                    };
                    let n = mis.len();
                    let valid = |k: usize| {
                        if k == 0 {
                            !mis[0].delta && !c.light_is_delta
                        } else {
                            !mis[k - 1].delta && !mis[k].delta
                        }
                    };
                    let sum: f64 = (0..n)
                        .filter(|&k| valid(k))
                        .map(|k| mis_weight(mis, k, c.light_is_delta))
                        .sum();
                    assert!((sum - 1.0).abs() < 1e-9, "({s}, {t}): weights sum to {sum}");
                    if t == 1 {
                        lens_connections += 1;
                    }
                }
            }
        }
        assert!(lens_connections > 100, "only {lens_connections} connections to the lens");
    }

    #[test]
    fn passes_are_normalised_per_pixel() {
        let fixture = spot_scene();
        let scene = fixture.scene();
        let bdpt = Bdpt::new(&scene, BdptSettings::default(), effects(&scene));
        assert_eq!(bdpt.name(), "bdpt");
        assert_eq!(bdpt.pass_samples(), 256);
        assert_eq!(bdpt.image_scale(0), 0.0);
        // The film is relative to the lights' power (10 W), as the path tracer's.
        assert_eq!(bdpt.image_scale(512), 10.0 * 0.5);
        let s: BdptSettings = serde_json::from_str(r#"{"max_depth": 3, "rr_depth": 1}"#).unwrap();
        assert_eq!(s, BdptSettings { max_depth: 3, rr_depth: 1, only_strategy: None });
        assert!(serde_json::from_str::<BdptSettings>(r#"{"max_depth": 3, "rr": 1}"#).is_err());
    }
}
