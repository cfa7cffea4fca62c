//! BDPT's subpaths: the camera subpath from a pixel, the light subpath from a beam, and the
//! random walk both continue with (pbrt's `GenerateCameraSubpath`, `GenerateLightSubpath`,
//! `RandomWalk`). Every vertex draws its [`VertexSamples`] when it is made.

use spectrace_geometry::{Hit, Ray};
use spectrace_lights::{Beam, LightSource};
use spectrace_materials::{Incoming, ScatterKind, Transport};

use super::Bdpt;
use super::vertex::{
    Lanes, LightEnd, Vertex, VertexKind, Wavelengths, light_normal, scaled, useful,
};
use crate::integrators::common::{
    CameraSamples, Direction, ScatterSamples, VertexSamples, choose_lobe, relative_throughput,
    roulette, shading_correction,
};
use crate::{HERO, TraceStats};

/// Reused storage of one chunk: no allocation per sample.
pub(crate) struct Buffers {
    pub(super) light: Vec<Vertex>,
    pub(super) camera: Vec<Vertex>,
    pub(super) mis: Vec<super::MisVertex>,
}

/// Where a walk starts: the ray leaving the subpath's first vertex, its first hit, the
/// throughput on leaving and the solid-angle density of the ray's direction (0 for a delta).
#[derive(Debug, Clone, Copy)]
struct WalkStart {
    ray: Ray,
    first: Option<Hit>,
    beta: Lanes,
    pdf_dir: f64,
}

/// How a walk continues: the transport it follows, whether it may re-emit, and its length.
#[derive(Debug, Clone, Copy)]
struct Walk {
    transport: Transport,
    /// Light subpaths choose fluorescent re-emission; camera subpaths stay elastic.
    reemit: bool,
    /// Most vertices the subpath may have.
    max: usize,
}

impl Bdpt<'_> {
    /// The camera subpath of a sample of pixel `(px, py)` into `buffers.camera`: the pinhole (or
    /// a uniform point of the lens), then a random walk from a ray through a uniform point of
    /// the pixel ([`crate::PinholeCamera::generate_ray`]), from the sample's camera uniforms `u`
    /// (drawn first in the sample).
    pub(super) fn camera_subpath(
        &self,
        (px, py): (u32, u32),
        u: &CameraSamples,
        wl: &Wavelengths,
        rng: &mut dyn rand::Rng,
        buffers: &mut Buffers,
        stats: &mut TraceStats,
    ) {
        let camera = self.scene.camera;
        let camera_ray = camera.generate_ray(px, py, u.film, u.lens);
        let ray = Ray { origin: camera_ray.origin, direction: camera_ray.direction };
        buffers.camera.clear();
        buffers.camera.push(Vertex::camera(ray.origin, wl.lambda()));
        let pdf_dir = camera.pdf_we(&camera_ray).1;
        let first = self.scene.world.intersect(&ray, f64::INFINITY);
        let walk =
            Walk { transport: Transport::Radiance, reemit: false, max: self.max_vertices().0 };
        let start = WalkStart { ray, first, beta: [1.0; HERO], pdf_dir };
        self.random_walk(start, walk, wl, &mut buffers.camera, rng, stats);
    }

    /// The light subpath of `beam` into `buffers.light`: the beam's origin on its light, then a
    /// random walk along the beam.
    pub(super) fn light_subpath(
        &self,
        beam: &Beam,
        light: &LightEnd,
        wl: &Wavelengths,
        rng: &mut dyn rand::Rng,
        buffers: &mut Buffers,
        stats: &mut TraceStats,
    ) {
        let camera_strategies = self.camera_strategies(beam, wl);
        let scene = self.scene;
        buffers.light.clear();
        let u = VertexSamples::draw(&self.light_layout, rng);
        let Some(source) = scene.lights.light(light.id) else { return };
        let (pdf_pos, pdf_dir) = self.light_pdfs(light.id, beam.origin, beam.direction);
        let Some(beta) = self.light_start_beta(beam, beam.scale, source, light, wl) else {
            return;
        };
        // The light vertex weighs its origin alone: connections from it take other directions
        // than the beam's (see `LightSource::origin_weight`).
        let weight = source.origin_weight(beam);
        let Some(at_origin) = self.light_start_beta(beam, weight, source, light, wl) else {
            return;
        };
        let ng = light_normal(source, beam.origin);
        let mut start = Vertex::at(
            VertexKind::Light(light.id),
            beam.origin,
            ng,
            at_origin,
            wl.lambda(),
            u.lens,
        );
        start.delta = light.first_vertex_delta();
        start.pdf_fwd = if camera_strategies { light.pmf * pdf_pos } else { 1.0 };
        buffers.light.push(start);
        let ray = Ray { origin: beam.origin, direction: beam.direction };
        let first = scene.intersect_from_light(&ray, light.id, f64::INFINITY);
        let pdf_dir = if light.flags.delta_direction { 0.0 } else { pdf_dir };
        let walk =
            Walk { transport: Transport::Importance, reemit: true, max: self.max_vertices().1 };
        let start = WalkStart { ray, first, beta, pdf_dir };
        self.random_walk(start, walk, wl, &mut buffers.light, rng, stats);
        if light.parallel_sampled && camera_strategies && buffers.light.len() >= 2 {
            // The first hit of a parallel beam has a planar density, not a solid-angle one.
            let (origin, first) = (buffers.light[0], buffers.light[1]);
            buffers.light[1].pdf_fwd = self.parallel_area_pdf(light.id, &origin, &first);
        }
    }

    /// The throughput a light subpath starts with: with one wavelength the lights' power `Phi`
    /// times the beam's weight (its spectrum cancels the density its wavelength was drawn
    /// with); with hero wavelengths `Phi_l spd_l(lambda_j) / pmf(l)` for the light `l` chosen
    /// by power (`Phi spd_l(lambda_j)`), the wavelengths' density left to their film weights.
    fn light_start_beta(
        &self,
        beam: &Beam,
        scale: f64,
        source: &dyn LightSource,
        light: &LightEnd,
        wl: &Wavelengths,
    ) -> Option<Lanes> {
        if !wl.is_hero() {
            let mut beta = [0.0; HERO];
            beta[0] = self.scene.lights.power() * scale;
            return Some(beta);
        }
        // The light set chose the beam's light by power.
        let pmf = self.scene.lights.pmf(light.id);
        if !(pmf > 0.0) {
            return None;
        }
        let power = source.power() / pmf;
        let spectrum = self.scene.light_spectra(light.id, beam.origin, beam.direction, &wl.lambdas);
        Some(spectrum.map(|s| power * s))
    }

    /// Follows `start.ray` (whose first hit is `start.first`) through the scene, appending a
    /// vertex per surface hit to `path` (which holds the subpath's start) until it has
    /// `walk.max` vertices, the path is absorbed or Russian roulette ends it.
    fn random_walk(
        &self,
        start: WalkStart,
        walk: Walk,
        wl: &Wavelengths,
        path: &mut Vec<Vertex>,
        rng: &mut dyn rand::Rng,
        stats: &mut TraceStats,
    ) {
        let WalkStart { mut ray, first, mut beta, mut pdf_dir } = start;
        let start = beta;
        let mut next = first;
        while let Some(hit) = next.take() {
            stats.hits += 1;
            let Some(prev) = path.last().copied() else { return };
            let layout = if walk.reemit { &self.light_layout } else { &self.camera_layout };
            let u = VertexSamples::draw(layout, rng);
            let kind = VertexKind::Surface(hit);
            // A light vertex keeps its lens point, a camera vertex its light sample.
            let connect = if walk.reemit { u.lens } else { u.light };
            // A re-emission (one wavelength only) changes the wavelength for the rest of the path.
            let lambda = if wl.is_hero() { wl.lambda() } else { prev.lambda };
            let mut v = Vertex::at(kind, hit.point, hit.geometric_normal, beta, lambda, connect);
            v.fluoresced = prev.fluoresced;
            v.pdf_fwd = Self::to_area(pdf_dir, prev.point, &v);
            let Some(resolved) = self.scene.material_at(&hit) else {
                path.push(v);
                return;
            };
            let mut material = &*resolved;
            if walk.reemit && !wl.is_hero() {
                // Elastic or re-emitted (light subpaths only), decided before any connection to
                // this vertex; the branch's factor belongs to the vertex's scattering, so it
                // enters `beta` here.
                let (mut l, mut w) = ([v.lambda], [beta[0]]);
                let lobe = choose_lobe(
                    material,
                    Direction::Forward,
                    &mut l,
                    &mut w,
                    u.fluorescence,
                    stats,
                );
                let Some(lobe) = lobe else {
                    path.push(v);
                    return;
                };
                if let super::super::common::Lobe::Reemitted(lambda) = lobe {
                    v.lambda = lambda;
                    v.reemitted = true;
                    v.fluoresced = true;
                }
                material = lobe.material();
                beta[0] = w[0];
                v.beta = beta;
            }
            path.push(v);
            if path.len() >= walk.max {
                stats.depth_limited += 1;
                return;
            }
            let go = ScatterSamples::draw(rng, path.len() > self.settings.rr_depth as usize + 1);
            let at = Arrival { ray: &ray, hit: &hit, lambda: v.lambda };
            let Some(s) = scatter(material, at, wl, &mut beta, go.scatter, walk.transport) else {
                return;
            };
            let last = path.len() - 1;
            path[last].lambda = s.lambda;
            let wp = -ray.direction;
            if walk.transport == Transport::Importance {
                beta = scaled(beta, shading_correction(&hit, wp, s.direction));
            }
            let n = path.len();
            let pdf_rev = if s.kind == ScatterKind::Specular {
                path[n - 1].delta = true;
                pdf_dir = 0.0;
                0.0
            } else {
                pdf_dir = s.pdf;
                material.pdf(s.direction, wp, hit.shading_normal, s.lambda)
            };
            path[n - 2].pdf_rev = Self::to_area(pdf_rev, hit.point, &prev);
            if (n - 1) as u32 > self.settings.rr_depth {
                let relative = relative_throughput(&beta[..wl.n], &start[..wl.n]);
                let Some(survive) = roulette(relative, go.roulette, stats) else { return };
                beta = scaled(beta, 1.0 / survive);
            }
            if !useful(&beta[..wl.n]) {
                return;
            }
            ray = hit.spawn_ray(s.direction);
            next = self.scene.world.intersect(&ray, f64::INFINITY);
        }
    }
}

/// How a path arrives at a vertex: along `ray`, at `hit`, carrying (with one wavelength)
/// `lambda`.
#[derive(Clone, Copy)]
struct Arrival<'a> {
    ray: &'a Ray,
    hit: &'a Hit,
    lambda: f64,
}

/// What one scattering step did: the direction, its lobe and density, and the wavelength that
/// chose them (the vertex's wavelength for its densities).
struct Scatter {
    direction: glam::DVec3,
    kind: ScatterKind,
    pdf: f64,
    lambda: f64,
}

/// Scatters the path arriving along `ray` at `hit`, multiplying its throughput `beta` by the
/// weight of each wavelength it carries; `None` when it is absorbed.
///
/// With hero wavelengths the hero always chooses the direction (so that every density of the
/// vertex is the hero's, whichever strategy made the path): a hero whose throughput is already
/// 0 still leads, through a stand-in weight of 1 whose result is dropped. Only where the hero
/// itself cannot scatter does the next live wavelength lead, and the vertex's densities are
/// then evaluated at that wavelength.
fn scatter(
    material: &dyn spectrace_materials::Material,
    at: Arrival<'_>,
    wl: &Wavelengths,
    beta: &mut Lanes,
    u: [f64; 3],
    transport: Transport,
) -> Option<Scatter> {
    let Arrival { ray, hit, lambda } = at;
    let normal = hit.shading_normal;
    if !wl.is_hero() {
        let incoming = Incoming { direction: ray.direction, normal, lambda };
        let s = material.scatter_with(&incoming, u, transport)?;
        beta[0] *= s.weight;
        return Some(Scatter { direction: s.direction, kind: s.kind, pdf: s.pdf, lambda });
    }
    let hero_dead = !(beta[0] > 0.0);
    if hero_dead {
        beta[0] = 1.0;
    }
    let s = material.scatter_bundle(ray.direction, normal, &wl.lambdas, beta, u, transport)?;
    let lambda = if beta[0] > 0.0 {
        wl.lambdas[0]
    } else {
        wl.lambdas
            .iter()
            .zip(beta.iter())
            .find(|(_, b)| **b > 0.0)
            .map_or(wl.lambdas[0], |(l, _)| *l)
    };
    if hero_dead {
        beta[0] = 0.0;
    }
    Some(Scatter { direction: s.direction, kind: s.kind, pdf: s.pdf, lambda })
}
