//! BDPT's subpaths: the camera subpath from a pixel, the light subpath from a beam, and the
//! random walk both continue with (pbrt's `GenerateCameraSubpath`, `GenerateLightSubpath`,
//! `RandomWalk`). Every vertex draws its [`VertexSamples`] when it is made.

use spectrace_geometry::{Hit, Ray};
use spectrace_lights::{Beam, LightSource};
use spectrace_materials::{Incoming, ScatterKind, Transport};

use super::Bdpt;
use super::vertex::{LightEnd, Vertex, VertexKind, Wavelength, light_normal};
use crate::TraceStats;
use crate::integrators::common::{
    CameraSamples, Direction, ScatterSamples, VertexSamples, choose_lobe, roulette,
    shading_correction,
};

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
    beta: f64,
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
    /// the pixel ([`crate::PinholeCamera::generate_ray`]).
    pub(super) fn camera_subpath(
        &self,
        px: u32,
        py: u32,
        wl: &Wavelength,
        rng: &mut dyn rand::Rng,
        buffers: &mut Buffers,
        stats: &mut TraceStats,
    ) {
        let camera = self.scene.camera;
        let u = CameraSamples::draw(&self.camera_layout, rng);
        let camera_ray = camera.generate_ray(px, py, u.film, u.lens);
        let ray = Ray { origin: camera_ray.origin, direction: camera_ray.direction };
        buffers.camera.clear();
        buffers.camera.push(Vertex::camera(ray.origin, wl.lambda));
        let pdf_dir = camera.pdf_we(&camera_ray).1;
        let first = self.scene.world.intersect(&ray, f64::INFINITY);
        let walk =
            Walk { transport: Transport::Radiance, reemit: false, max: self.max_vertices().0 };
        let start = WalkStart { ray, first, beta: 1.0, pdf_dir };
        self.random_walk(start, walk, &mut buffers.camera, rng, stats);
    }

    /// The light subpath of `beam` into `buffers.light`: the beam's origin on its light, then a
    /// random walk along the beam.
    pub(super) fn light_subpath(
        &self,
        beam: &Beam,
        light: &LightEnd,
        wl: &Wavelength,
        rng: &mut dyn rand::Rng,
        buffers: &mut Buffers,
        stats: &mut TraceStats,
    ) {
        let camera_strategies = Self::camera_strategies(beam, wl);
        let scene = self.scene;
        buffers.light.clear();
        let u = VertexSamples::draw(&self.light_layout, rng);
        let Some(source) = scene.lights.light(light.id) else { return };
        let (pdf_pos, pdf_dir) = self.light_pdfs(light.id, beam.origin, beam.direction);
        let beta = scene.lights.power() * beam.scale;
        let ng = light_normal(source, beam.origin);
        let mut start =
            Vertex::at(VertexKind::Light(light.id), beam.origin, ng, beta, wl.lambda, u.lens);
        start.delta = light.first_vertex_delta();
        start.pdf_fwd = if camera_strategies { light.pmf * pdf_pos } else { 1.0 };
        buffers.light.push(start);
        let ray = Ray { origin: beam.origin, direction: beam.direction };
        let first = scene.intersect_from_light(&ray, light.id, f64::INFINITY);
        let pdf_dir = if light.flags.delta_direction { 0.0 } else { pdf_dir };
        let walk =
            Walk { transport: Transport::Importance, reemit: true, max: self.max_vertices().1 };
        let start = WalkStart { ray, first, beta, pdf_dir };
        self.random_walk(start, walk, &mut buffers.light, rng, stats);
        if light.parallel_sampled && camera_strategies && buffers.light.len() >= 2 {
            // The first hit of a parallel beam has a planar density, not a solid-angle one.
            let (origin, first) = (buffers.light[0], buffers.light[1]);
            buffers.light[1].pdf_fwd = self.parallel_area_pdf(light.id, &origin, &first);
        }
    }

    /// Follows `start.ray` (whose first hit is `start.first`) through the scene, appending a
    /// vertex per surface hit to `path` (which holds the subpath's start) until it has
    /// `walk.max` vertices, the path is absorbed or Russian roulette ends it.
    fn random_walk(
        &self,
        start: WalkStart,
        walk: Walk,
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
            let mut v =
                Vertex::at(kind, hit.point, hit.geometric_normal, beta, prev.lambda, connect);
            v.fluoresced = prev.fluoresced;
            v.pdf_fwd = Self::to_area(pdf_dir, prev.point, &v);
            let Some(material) = self.scene.materials.get(hit.primitive as usize) else {
                path.push(v);
                return;
            };
            let mut material = material.as_ref();
            if walk.reemit {
                // Elastic or re-emitted (light subpaths only), decided before any connection to
                // this vertex; the branch's factor belongs to the vertex's scattering, so it
                // enters `beta` here.
                let (mut l, mut w) = ([v.lambda], [beta]);
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
                beta = w[0];
                v.beta = beta;
            }
            path.push(v);
            if path.len() >= walk.max {
                stats.depth_limited += 1;
                return;
            }
            let go = ScatterSamples::draw(rng, path.len() > self.settings.rr_depth as usize + 1);
            let incoming =
                Incoming { direction: ray.direction, normal: hit.shading_normal, lambda: v.lambda };
            let Some(s) = material.scatter_with(&incoming, go.scatter, walk.transport) else {
                return;
            };
            let wp = -ray.direction;
            let mut weight = s.weight;
            if walk.transport == Transport::Importance {
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
            path[n - 2].pdf_rev = Self::to_area(pdf_rev, hit.point, &prev);
            if (n - 1) as u32 > self.settings.rr_depth {
                let relative = if start > 0.0 { beta / start } else { 0.0 };
                let Some(survive) = roulette(relative, go.roulette, stats) else { return };
                beta /= survive;
            }
            if !(beta > 0.0 && beta.is_finite()) {
                return;
            }
            ray = hit.spawn_ray(s.direction);
            next = self.scene.world.intersect(&ray, f64::INFINITY);
        }
    }
}
