//! BDPT's path vertices and the densities between them: [`Vertex`], the light end of a path
//! ([`LightEnd`]), and pbrt's `Vertex::Pdf` ([`Bdpt::pdf`]) with the conversions to area density.

use std::f64::consts::PI;

use glam::DVec3;
use spectrace_geometry::Hit;
use spectrace_lights::{LightFlags, LightId, LightSource, LightSurface};
use spectrace_materials::{MaterialAt, Transport, reemission_lobe};

use super::Bdpt;
use crate::HERO;

/// A value per wavelength a sample carries: its first [`Wavelengths::n`] entries are used.
pub(super) type Lanes = [f64; HERO];

/// What a vertex is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum VertexKind {
    /// The pinhole, or a point of a thin lens.
    Camera,
    /// A point on light `id` (where a beam starts, or sampled by next-event estimation).
    Light(LightId),
    /// A surface hit (its shape's material scatters).
    Surface(Hit),
}

/// A vertex of a subpath (pbrt's `Vertex`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Vertex {
    pub kind: VertexKind,
    pub point: DVec3,
    /// Geometric normal; zero for points not on a surface (pinhole, point lights).
    pub ng: DVec3,
    /// Throughput per wavelength from the subpath's start up to this vertex (not including its
    /// scattering).
    pub beta: Lanes,
    /// Scatters by a delta lobe (or, for a light, emits in a delta direction).
    pub delta: bool,
    /// Area density of this vertex sampled from its own subpath's side.
    pub pdf_fwd: f64,
    /// Area density of this vertex sampled from the other side.
    pub pdf_rev: f64,
    /// The wavelength (nm) at which this vertex's densities are evaluated and, with one
    /// wavelength per sample, at which it connects: the sample's own (its hero), or on a light
    /// subpath beyond a fluorescent re-emission the re-emitted one.
    pub lambda: f64,
    /// This vertex re-emitted (scatters with [`reemission_lobe`] instead of its material).
    pub reemitted: bool,
    /// This vertex or one before it on its subpath re-emitted.
    pub fluoresced: bool,
    /// The uniforms of the vertex's one connection, drawn when it was made: a light vertex's
    /// lens point for `t = 1`, a camera vertex's light sample for `s = 1`.
    pub u: [f64; 2],
}

impl Vertex {
    /// The camera's vertex at `point` (the pinhole or a lens point).
    pub(super) fn camera(point: DVec3, lambda: f64) -> Self {
        Self::at(VertexKind::Camera, point, DVec3::ZERO, [1.0; HERO], lambda, NO_SAMPLES)
    }

    /// A vertex of `kind` at `point` with normal `ng`, throughput `beta` and uniforms `u`.
    pub(super) fn at(
        kind: VertexKind,
        point: DVec3,
        ng: DVec3,
        beta: Lanes,
        lambda: f64,
        u: [f64; 2],
    ) -> Self {
        Self {
            kind,
            point,
            ng,
            beta,
            delta: false,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            lambda,
            reemitted: false,
            fluoresced: false,
            u,
        }
    }
}

/// The connection uniforms of a vertex that draws none (the camera's, and vertices sampled by
/// a connection).
pub(super) const NO_SAMPLES: [f64; 2] = [0.5; 2];

/// A light as a path end: its id, its flags, and the probability of choosing it given the
/// sample's wavelength.
#[derive(Debug, Clone, Copy)]
pub(super) struct LightEnd {
    pub id: LightId,
    pub flags: LightFlags,
    pub pmf: f64,
    /// Whether it sends parallel beams that a point can sample
    /// ([`crate::LightTracerScene::parallel_sampled`]): next-event estimation (`s = 1`) reaches
    /// it.
    pub parallel_sampled: bool,
}

impl LightEnd {
    /// Whether a camera path can never hit it (strategy `s = 0` impossible).
    pub(super) fn is_delta(&self, on_surface: bool) -> bool {
        self.flags.delta_position || self.flags.delta_direction || !on_surface
    }

    /// Whether no connection can end at its vertex: a delta direction that no point samples (a
    /// laser of zero width), so strategies with `s = 1` are impossible. A sky's or a wide
    /// laser's vertex is reached by next-event estimation along the one beam through the
    /// receiver.
    pub(super) fn first_vertex_delta(&self) -> bool {
        self.flags.delta_direction && !self.parallel_sampled
    }
}

/// The wavelengths of a sample and what depends on them.
///
/// With one wavelength (`n = 1`, the beam's own, drawn from the light set's SPD) every value
/// carries the density `1 / p(lambda)` inside it, as the light tracer's do. With [`HERO`]
/// wavelengths (drawn from the observer's density, [`crate::CameraWavelengths::sample_hero`])
/// values are per unit of wavelength density, and each lane's film weight
/// `1 / (HERO p(lambda_j))` is applied when it is splatted.
#[derive(Debug, Clone, Copy)]
pub(super) struct Wavelengths {
    /// The wavelengths (nm), the hero first.
    pub lambdas: Lanes,
    /// Each wavelength's film weight (1 with one wavelength).
    pub weights: Lanes,
    /// How many are carried: 1 or [`HERO`].
    pub n: usize,
    /// With one wavelength, the light set's SPD at it (the density it was drawn with); 1 with
    /// hero wavelengths.
    pub density: f64,
}

impl Wavelengths {
    /// The one wavelength `lambda` of a beam, drawn with density `density`.
    pub(super) fn single(lambda: f64, density: f64) -> Self {
        let mut lambdas = [0.0; HERO];
        lambdas[0] = lambda;
        let mut weights = [0.0; HERO];
        weights[0] = 1.0;
        Self { lambdas, weights, n: 1, density }
    }

    /// [`HERO`] wavelengths with their film weights.
    pub(super) fn hero(lambdas: Lanes, weights: Lanes) -> Self {
        Self { lambdas, weights, n: HERO, density: 1.0 }
    }

    /// Whether the sample carries hero wavelengths.
    pub(super) fn is_hero(&self) -> bool {
        self.n > 1
    }

    /// The hero (or only) wavelength.
    pub(super) fn lambda(&self) -> f64 {
        self.lambdas[0]
    }

    /// The wavelengths at which vertex `v` connects: the sample's, or with one wavelength the
    /// vertex's own (a re-emitted one beyond a fluorescent surface).
    pub(super) fn at<'w>(&'w self, v: &'w Vertex) -> &'w [f64] {
        if self.is_hero() { &self.lambdas } else { std::slice::from_ref(&v.lambda) }
    }
}

/// `a * k`, lane by lane.
pub(super) fn scaled(a: Lanes, k: f64) -> Lanes {
    a.map(|x| x * k)
}

/// Whether some lane of `values` is positive and none is infinite or NaN.
pub(super) fn useful(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite()) && values.iter().any(|&v| v > 0.0)
}

/// `a * b`, lane by lane.
pub(super) fn times(a: Lanes, b: Lanes) -> Lanes {
    std::array::from_fn(|j| a[j] * b[j])
}

impl Bdpt<'_> {
    /// The light `id` as a path end for the sample's wavelengths `wl`: chosen given the one
    /// wavelength, or by power alone for hero wavelengths.
    pub(super) fn light_end(&self, id: LightId, wl: &Wavelengths) -> Option<LightEnd> {
        let light = self.scene.lights.light(id)?;
        let flags =
            light.flags().unwrap_or(LightFlags { delta_position: true, delta_direction: true });
        let lights = self.scene.all_lights();
        let pmf = if wl.is_hero() {
            crate::light_sampler::LightSampler::pmf(lights, id)
        } else if wl.density > 0.0 {
            lights.pmf_given(id, wl.lambda(), wl.density)
        } else {
            0.0
        };
        let parallel_sampled = self.scene.parallel_sampled(id);
        Some(LightEnd { id, flags, pmf, parallel_sampled })
    }

    /// Area density at `next` of the parallel beams of light `id` (a delta direction: a sky, a
    /// wide laser) from its vertex `light`: the density of the beam origins over the light's
    /// surface, carried along the beams onto `next`, `pdf_position |cos next| / |cos light|`
    /// (the cosines of the surfaces' normals with the beams; 1 at a vertex without a normal).
    /// Next-event estimation (`s = 1`) picks the light's vertex as a function of `next`, and a
    /// light subpath picks `next` as a function of its origin: both carry the same delta, so
    /// this density is what the two strategies' weights compare.
    pub(super) fn parallel_area_pdf(&self, id: LightId, light: &Vertex, next: &Vertex) -> f64 {
        let d = (next.point - light.point).normalize_or_zero();
        let (pdf_position, _) = self.light_pdfs(id, light.point, d);
        let cos_light = light.ng.dot(d).abs();
        let cos_next = if next.ng == DVec3::ZERO { 1.0 } else { next.ng.dot(d).abs() };
        let p = pdf_position * cos_next / cos_light;
        if cos_light > 0.0 && p.is_finite() { p } else { 0.0 }
    }

    /// Solid-angle density of a camera ray leaving the lens at `origin` (the pinhole for a
    /// pinhole camera) towards `point` (over the whole image: [`crate::PinholeCamera::pdf_we`]),
    /// 0 when it misses the image.
    fn camera_pdf(&self, origin: DVec3, point: DVec3) -> f64 {
        let ray = crate::CameraRay { origin, direction: point - origin };
        self.scene.camera.pdf_we(&ray).1
    }

    /// Area density at `vertex` of a vertex at `from` that chooses the direction towards it
    /// with solid-angle density `pdf`.
    pub(super) fn to_area(pdf: f64, from: DVec3, vertex: &Vertex) -> f64 {
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
    pub(super) fn pdf(
        &self,
        v: &Vertex,
        prev: Option<&Vertex>,
        next: &Vertex,
        light: Option<LightId>,
    ) -> f64 {
        let solid = match v.kind {
            VertexKind::Camera => self.camera_pdf(v.point, next.point),
            VertexKind::Light(id) => {
                if self.scene.parallel_sampled(id) {
                    return self.parallel_area_pdf(id, v, next);
                }
                self.light_pdfs(id, v.point, next.point - v.point).1
            }
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
    pub(super) fn lobe(&self, v: &Vertex, hit: &Hit) -> Option<MaterialAt<'_>> {
        if v.reemitted {
            return Some(MaterialAt::Shared(reemission_lobe()));
        }
        self.scene.material_at(hit)
    }

    /// The BSDF at surface vertex `v` for light arriving from `from` and leaving towards `to`,
    /// with `transport`'s adjoint, at the wavelengths `wl` carries there
    /// ([`Wavelengths::at`]); 0 for other vertices.
    pub(super) fn bsdf(
        &self,
        v: &Vertex,
        wl: &Wavelengths,
        from: DVec3,
        to: DVec3,
        transport: Transport,
    ) -> Lanes {
        let mut f = [0.0; HERO];
        let VertexKind::Surface(hit) = v.kind else { return f };
        let Some(material) = self.lobe(v, &hit) else { return f };
        let wi = (from - v.point).normalize();
        let wo = (to - v.point).normalize();
        let lambdas = wl.at(v);
        material.eval_bundle(
            wi,
            wo,
            hit.shading_normal,
            lambdas,
            transport,
            &mut f[..lambdas.len()],
        );
        f
    }

    /// A light's `(position, direction)` emission densities from `point` along `direction`
    /// (any length).
    pub(super) fn light_pdfs(&self, id: LightId, point: DVec3, direction: DVec3) -> (f64, f64) {
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
pub(super) fn light_normal(light: &dyn LightSource, point: DVec3) -> DVec3 {
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
