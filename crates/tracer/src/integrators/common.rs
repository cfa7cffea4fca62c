//! The steps every estimator shares, written once: the random numbers a vertex draws, shadow
//! rays, connections to the camera, next-event estimation's light sample, the fluorescence
//! choice, Russian roulette and the power heuristic.
//!
//! # Random numbers: a fixed budget per vertex
//! Every scattering vertex of every path draws the same uniforms, whether it uses them or not
//! (pbrt's wavefront `RaySamples`): on reaching the vertex its [`VertexSamples`] (the
//! fluorescence choice, a light sample, a lens point), and when the path goes on from it its
//! [`ScatterSamples`] (the BSDF sample, and Russian roulette at the depths where it is played). Which groups a render draws is fixed
//! before it starts ([`SampleLayout`]: the fluorescence choice only in scenes that fluoresce, a
//! lens point only for a thin lens, a light sample only for estimators that sample lights), so
//! the `k`-th uniform of a path means the same thing whatever happened at earlier vertices: a
//! Sobol dimension always feeds the same decision, and a kernel that traces many paths at once
//! can reproduce the scalar one draw for draw. (A path that ends at a vertex draws nothing for
//! going on: no later draw of it exists to shift.) A camera sample starts with
//! [`CameraSamples`].
//!
//! # Shadow rays: one epsilon policy
//! [`unoccluded`] joins two [`End`]s. A surface point is left and reached at its robust offset
//! ([`Hit::spawn_origin`]), so its own surface never shadows it; a point on a light is left by
//! skipping its own surface ([`LightTracerScene::intersect_from_light`]) and reached up to
//! [`SHADOW_EPSILON`] (relative) short of it, since an area light's surface is itself geometry;
//! a free point (the camera's lens, a point light, a sensor) is reached the same way.

use glam::DVec3;
use spectrace_geometry::{Hit, Ray};
use spectrace_lights::{LightId, LightSample, uniform};
use spectrace_materials::{ExcitationSampler, Material, Reemission, Transport, reemission_lobe};

use crate::{LightTracerScene, TraceStats};

/// Relative distance short of a point on a light (or a free point) at which a shadow ray
/// stops, so that the light's own surface does not count as an occluder.
pub(crate) const SHADOW_EPSILON: f64 = 1e-9;

/// Which of the optional uniforms the vertices of a kind of path draw (fixed for the whole
/// render): each group only where some strategy uses it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct SampleLayout {
    /// Two uniforms for the fluorescence choice (paths that may re-emit, in scenes with a
    /// fluorescent material).
    pub fluorescence: bool,
    /// Two uniforms for a light sample (camera paths that sample lights).
    pub light: bool,
    /// Two uniforms for a point on the lens at each vertex (light paths connected to a thin
    /// lens).
    pub lens: bool,
    /// Two uniforms for the lens point a camera sample starts from (camera paths, thin lens).
    pub camera_lens: bool,
}

impl SampleLayout {
    /// The layout of light paths in `scene`: they may re-emit and connect to the lens.
    pub(crate) fn light_paths(scene: &LightTracerScene<'_>) -> Self {
        Self {
            fluorescence: fluoresces(scene),
            light: false,
            lens: !scene.camera.is_pinhole(),
            camera_lens: false,
        }
    }

    /// The layout of camera paths in `scene`: they start on the lens, re-emit if `reemit` (and
    /// the scene fluoresces), and sample lights if `sample_lights`.
    pub(crate) fn camera_paths(
        scene: &LightTracerScene<'_>,
        reemit: bool,
        sample_lights: bool,
    ) -> Self {
        Self {
            fluorescence: reemit && fluoresces(scene),
            light: sample_lights,
            lens: false,
            camera_lens: !scene.camera.is_pinhole(),
        }
    }

    /// A pair of uniforms if `on`, else the pair's centre (drawing nothing).
    #[inline]
    fn pair(on: bool, rng: &mut dyn rand::Rng) -> [f64; 2] {
        if on { [uniform(rng), uniform(rng)] } else { [0.5; 2] }
    }

    /// A point on the lens for a light path's connection: two uniforms for a thin lens, none
    /// for a pinhole.
    #[inline]
    pub(crate) fn lens(&self, rng: &mut dyn rand::Rng) -> [f64; 2] {
        Self::pair(self.lens, rng)
    }

    /// A point on the lens for a camera path's own connection to the camera (its point lights
    /// seen directly): two uniforms for a thin lens, none for a pinhole.
    #[inline]
    pub(crate) fn camera_lens(&self, rng: &mut dyn rand::Rng) -> [f64; 2] {
        Self::pair(self.camera_lens, rng)
    }
}

/// Whether any surface of `scene` fluoresces.
fn fluoresces(scene: &LightTracerScene<'_>) -> bool {
    scene.materials.iter().any(|m| m.fluorescence().is_some())
}

/// The uniforms a vertex draws when a path reaches it, in the order they are drawn: those of
/// its choice of lobe and its connections.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct VertexSamples {
    /// Elastic or re-emitted, and the re-emitted wavelength.
    pub fluorescence: [f64; 2],
    /// Next-event estimation: the light (remapped for reuse) and the point on it.
    pub light: [f64; 2],
    /// A point on the lens for the connection to the camera.
    pub lens: [f64; 2],
}

impl VertexSamples {
    /// Draws the uniforms of a vertex of a path of `layout`.
    #[inline]
    pub(crate) fn draw(layout: &SampleLayout, rng: &mut dyn rand::Rng) -> Self {
        let fluorescence = SampleLayout::pair(layout.fluorescence, rng);
        let light = SampleLayout::pair(layout.light, rng);
        let lens = SampleLayout::pair(layout.lens, rng);
        Self { fluorescence, light, lens }
    }
}

/// The uniforms a vertex draws when the path goes on from it: three for the BSDF, and one for
/// Russian roulette at the vertices where roulette is played (past `rr_depth`, which depends
/// on the vertex's depth alone, never on what a path met).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ScatterSamples {
    /// The BSDF sample.
    pub scatter: [f64; 3],
    /// Russian roulette (0.5, not drawn, where it is not played).
    pub roulette: f64,
}

impl ScatterSamples {
    /// Draws them: the roulette uniform only if `roulette` is played at this vertex.
    #[inline]
    pub(crate) fn draw(rng: &mut dyn rand::Rng, roulette: bool) -> Self {
        let scatter = [uniform(rng), uniform(rng), uniform(rng)];
        Self { scatter, roulette: if roulette { uniform(rng) } else { 0.5 } }
    }
}

/// The uniforms that start a camera sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CameraSamples {
    /// A point in the pixel.
    pub film: [f64; 2],
    /// A point on the lens.
    pub lens: [f64; 2],
    /// The hero wavelength.
    pub wavelength: f64,
}

impl CameraSamples {
    /// Draws a camera sample's uniforms under `layout`.
    #[inline]
    pub(crate) fn draw(layout: &SampleLayout, rng: &mut dyn rand::Rng) -> Self {
        let film = [uniform(rng), uniform(rng)];
        let lens = layout.camera_lens(rng);
        Self { film, lens, wavelength: uniform(rng) }
    }
}

/// One end of a shadow ray.
#[derive(Debug, Clone, Copy)]
pub(crate) enum End<'h> {
    /// A surface hit.
    Surface(&'h Hit),
    /// A point on a light of the set (its own surface, if it has one, is skipped).
    Light(LightId, DVec3),
    /// A point that is not on any surface: the lens, a point light, a sensor.
    Point(DVec3),
}

impl End<'_> {
    /// The point itself.
    #[inline(always)]
    fn point(&self) -> DVec3 {
        match *self {
            End::Surface(h) => h.point,
            End::Light(_, p) | End::Point(p) => p,
        }
    }

    /// Where a segment towards `other` leaves or reaches this end.
    #[inline(always)]
    fn offset_towards(&self, other: DVec3) -> DVec3 {
        match *self {
            End::Surface(h) => h.spawn_origin(other - h.point),
            End::Light(_, p) | End::Point(p) => p,
        }
    }
}

/// Whether nothing blocks the segment from `from` to `to` (the one shadow ray of every
/// estimator; see the module docs for its epsilon policy; connections to the camera use the
/// same policy with the lens sample's direction).
#[inline(always)]
pub(crate) fn unoccluded(scene: &LightTracerScene<'_>, from: End<'_>, to: End<'_>) -> bool {
    ShadowRay::between(from, to).visible(scene)
}

/// The shadow ray between two [`End`]s, built apart from its test so that a batched kernel can
/// queue it ([`unoccluded`] is both steps).
#[derive(Debug, Clone, Copy)]
pub(crate) enum ShadowRay {
    /// No ray is needed: the ends coincide (visible) or are not a finite distance apart.
    Decided(bool),
    /// Test `ray` up to `reach`, skipping light `skip`'s own surface where it leaves a light.
    Ray {
        /// The ray, from the offset origin towards the other end.
        ray: Ray,
        /// How far it must be clear.
        reach: f64,
        /// The light it leaves from, whose surface does not occlude it.
        skip: Option<LightId>,
    },
}

impl ShadowRay {
    /// The shadow ray from `from` to `to` under the module's epsilon policy.
    #[inline(always)]
    pub(crate) fn between(from: End<'_>, to: End<'_>) -> Self {
        let origin = from.offset_towards(to.point());
        let target = to.offset_towards(from.point());
        let d = target - origin;
        let distance = d.length();
        if !(distance > 0.0 && distance.is_finite()) {
            return Self::Decided(distance == 0.0);
        }
        let ray = Ray { origin, direction: d / distance };
        let reach = match to {
            End::Surface(_) => distance,
            End::Light(..) | End::Point(_) => distance * (1.0 - SHADOW_EPSILON),
        };
        let skip = match from {
            End::Light(id, _) => Some(id),
            End::Surface(_) | End::Point(_) => None,
        };
        Self::Ray { ray, reach, skip }
    }

    /// Whether nothing blocks it.
    #[inline(always)]
    pub(crate) fn visible(&self, scene: &LightTracerScene<'_>) -> bool {
        match *self {
            Self::Decided(visible) => visible,
            Self::Ray { ray, reach, skip: Some(id) } => {
                scene.intersect_from_light(&ray, id, reach).is_none()
            }
            Self::Ray { ray, reach, skip: None } => !scene.world.occluded(&ray, reach),
        }
    }
}

/// A point on the camera's lens seeing a light-side point: the pixel, the importance (film
/// units) and the direction to the lens.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CameraConnection {
    /// Pixel column.
    pub x: u32,
    /// Pixel row.
    pub y: u32,
    /// Unit direction from the point to the lens.
    pub to_camera: DVec3,
    /// The lens point.
    pub lens: DVec3,
    /// The camera's importance over its density (see [`crate::PinholeCamera::sample_wi`]).
    pub importance: f64,
}

/// The connection of `from` to the lens point `seen` (sampled towards it), when nothing blocks
/// it: the shadow ray of [`unoccluded`], with the direction and distance `seen` already has
/// where `from` is not on a surface.
#[inline]
fn connect_camera(
    scene: &LightTracerScene<'_>,
    from: End<'_>,
    seen: &crate::CameraSample,
) -> Option<CameraConnection> {
    if !(seen.pdf > 0.0 && seen.importance > 0.0) {
        return None;
    }
    let reach = seen.distance * (1.0 - SHADOW_EPSILON);
    let visible = match from {
        End::Surface(_) => unoccluded(scene, from, End::Point(seen.position)),
        End::Light(id, point) => {
            let ray = Ray { origin: point, direction: seen.to_camera };
            scene.intersect_from_light(&ray, id, reach).is_none()
        }
        End::Point(point) => {
            !scene.world.occluded(&Ray { origin: point, direction: seen.to_camera }, reach)
        }
    };
    visible.then_some(CameraConnection {
        x: seen.x,
        y: seen.y,
        to_camera: seen.to_camera,
        lens: seen.position,
        importance: seen.importance,
    })
}

/// A point `point` on light `id` seen by the camera: the connection and the light's emission
/// density towards the lens times the importance (multiply by the light's power and spectrum
/// for the contribution); `None` when the light does not emit that way or it is not seen.
pub(crate) fn connect_light_to_camera(
    scene: &LightTracerScene<'_>,
    id: LightId,
    point: DVec3,
    u_lens: [f64; 2],
) -> Option<(CameraConnection, f64)> {
    let light = scene.lights.light(id)?;
    let seen = scene.camera.sample_wi(point, u_lens)?;
    let density = light.emission_density(point, seen.to_camera);
    if !(density > 0.0) {
        return None;
    }
    let connection = connect_camera(scene, End::Light(id, point), &seen)?;
    Some((connection, density * connection.importance))
}

/// The cosine of importance transport at `hit` for light arriving from `wi` and leaving
/// towards `wo` (both unit, away from the surface): `|wo . n|`, with Veach's shading-normal
/// correction `|wo . n_g| |wi . n_s| / |wi . n_g|` where the normals differ; `None` when `wi`
/// grazes the true surface.
#[inline]
pub(crate) fn importance_cosine(hit: &Hit, wi: DVec3, wo: DVec3) -> Option<f64> {
    let (ns, ng) = (hit.shading_normal, hit.geometric_normal);
    if ns == ng {
        return Some(wo.dot(ns).abs());
    }
    let cos_in = wi.dot(ng).abs();
    (cos_in > 0.0).then(|| wo.dot(ng).abs() * wi.dot(ns).abs() / cos_in)
}

/// The factor that makes particle (importance) transport exact with shading normals:
/// `|wi . n_s| |wo . n_g| / (|wi . n_g| |wo . n_s|)`, 1 where the normals agree (Veach 1997,
/// section 5.3). `wi` points back to where the particle came from, `wo` where it goes.
#[inline]
pub(crate) fn shading_correction(hit: &Hit, wi: DVec3, wo: DVec3) -> f64 {
    let (ns, ng) = (hit.shading_normal, hit.geometric_normal);
    if ns == ng {
        return 1.0;
    }
    let denominator = wi.dot(ng).abs() * wo.dot(ns).abs();
    if denominator > 0.0 { wi.dot(ns).abs() * wo.dot(ng).abs() / denominator } else { 0.0 }
}

/// A light-side surface vertex seen by the camera: `f * cos * importance` per wavelength of
/// `lambdas` into `values` (light arriving from `wi`, scattered by `material`), and the
/// connection; `None` when nothing reaches the film.
#[inline]
pub(crate) fn connect_surface_to_camera(
    scene: &LightTracerScene<'_>,
    hit: &Hit,
    material: &dyn Material,
    wi: DVec3,
    lambdas: &[f64],
    u_lens: [f64; 2],
    values: &mut [f64],
) -> Option<CameraConnection> {
    let seen = scene.camera.sample_wi(hit.point, u_lens)?;
    let seen = connect_camera(scene, End::Surface(hit), &seen)?;
    // The camera measures area on the true surface; the reflected light uses the shading normal.
    let cos = importance_cosine(hit, wi, seen.to_camera)?;
    let values = &mut values[..lambdas.len()];
    let n = hit.shading_normal;
    material.eval_bundle(wi, seen.to_camera, n, lambdas, Transport::Importance, values);
    let mut any = false;
    for v in values.iter_mut() {
        if *v > 0.0 {
            *v *= cos * seen.importance;
            any = true;
        } else {
            *v = 0.0;
        }
    }
    any.then_some(seen)
}

/// A point on light `id` sampled towards `receiver` (next-event estimation), when it gives
/// light: positive intensity at a positive distance (a non-finite value is the film's to
/// refuse). Visibility is the caller's
/// ([`unoccluded`] with [`End::Light`]), after it has checked the sample is worth a ray.
#[inline]
pub(crate) fn sample_light(
    scene: &LightTracerScene<'_>,
    id: LightId,
    receiver: DVec3,
    u: [f64; 2],
) -> Option<LightSample> {
    scene
        .lights
        .light(id)?
        .sample_towards(receiver, u)
        .filter(|s| s.intensity > 0.0 && s.distance > 0.0)
}

/// The lobe a path scatters with at a fluorescent surface, chosen before any connection
/// (ARCHITECTURE invariant 11).
#[derive(Debug, Clone, Copy)]
pub(crate) enum Lobe<'m> {
    /// The material itself (or its elastic part).
    Elastic(&'m dyn Material),
    /// Re-emission at a new wavelength (nm): the white lobe scatters.
    Reemitted(f64),
}

impl<'m> Lobe<'m> {
    /// What scatters.
    #[inline]
    pub(crate) fn material(&self) -> &'m dyn Material {
        match *self {
            Lobe::Elastic(m) => m,
            Lobe::Reemitted(_) => reemission_lobe(),
        }
    }
}

/// Which way fluorescence is decided: forwards on light paths, adjointly on camera paths with
/// the excitation sampler of the surface.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Direction<'g> {
    /// Light paths ([`spectrace_materials::Fluorescent::choose_forward`]).
    Forward,
    /// Camera paths ([`spectrace_materials::Fluorescent::choose_adjoint`]).
    Adjoint(Option<&'g ExcitationSampler>),
}

/// The lobe at a surface of `material` for a bundle (`lambdas`, `weights`), from the vertex's
/// fluorescence uniforms `u`: the material when it does not fluoresce; `None` when the bundle
/// is absorbed. Re-emission updates the bundle and counts in `stats`.
pub(crate) fn choose_lobe<'m>(
    material: &'m dyn Material,
    direction: Direction<'_>,
    lambdas: &mut [f64],
    weights: &mut [f64],
    u: [f64; 2],
    stats: &mut TraceStats,
) -> Option<Lobe<'m>> {
    let Some(fluorescent) = material.fluorescence() else {
        return Some(Lobe::Elastic(material));
    };
    let choice = match direction {
        Direction::Forward => fluorescent.choose_forward(lambdas, weights, u[0], u[1]),
        Direction::Adjoint(guide) => {
            fluorescent.choose_adjoint(lambdas, weights, u[0], u[1], guide)
        }
    };
    match choice {
        Reemission::Elastic => Some(Lobe::Elastic(material)),
        Reemission::Reemitted { lambda } => {
            stats.reemissions += 1;
            Some(Lobe::Reemitted(lambda))
        }
        Reemission::Absorbed => None,
    }
}

/// Russian roulette, the one rule of every estimator: a path whose throughput is `relative`
/// times what it started with (the largest over its wavelengths) survives with probability
/// `min(1, relative)`. Returns the survival probability to divide by, or `None` when the path
/// ends (counted in `stats`).
#[inline]
pub(crate) fn roulette(relative: f64, u: f64, stats: &mut TraceStats) -> Option<f64> {
    let survive = if relative > 0.0 { relative.min(1.0) } else { 0.0 };
    if u < survive {
        Some(survive)
    } else {
        stats.roulette_kills += 1;
        None
    }
}

/// The largest of `weights[j] / start[j]` over the wavelengths that started with weight.
#[inline]
pub(crate) fn relative_throughput(weights: &[f64], start: &[f64]) -> f64 {
    weights.iter().zip(start).filter(|(_, s)| **s > 0.0).map(|(w, s)| w / s).fold(0.0, f64::max)
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

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_pcg::Pcg64;

    use super::*;

    #[test]
    fn a_vertex_draws_the_same_count_whatever_it_uses() {
        // 2 per optional group on reaching it, then 4 to go on past the roulette depth: the k-th
        // draw of a path keeps its meaning.
        for (layout, count) in [
            (SampleLayout::default(), 4),
            (SampleLayout { lens: true, ..SampleLayout::default() }, 6),
            (SampleLayout { fluorescence: true, lens: true, ..SampleLayout::default() }, 8),
            // Camera paths draw their lens point once, at the camera, not at each vertex.
            (SampleLayout { fluorescence: true, light: true, camera_lens: true, lens: false }, 8),
        ] {
            let mut a = Pcg64::seed_from_u64(3);
            let mut b = Pcg64::seed_from_u64(3);
            let _ = VertexSamples::draw(&layout, &mut a);
            let _ = ScatterSamples::draw(&mut a, true);
            for _ in 0..count {
                let _ = uniform(&mut b);
            }
            assert_eq!(uniform(&mut a), uniform(&mut b), "{layout:?}");
            // Before the roulette depth, one fewer.
            let _ = ScatterSamples::draw(&mut a, false);
            for _ in 0..3 {
                let _ = uniform(&mut b);
            }
            assert_eq!(uniform(&mut a), uniform(&mut b), "{layout:?}");
        }
    }

    #[test]
    fn roulette_keeps_the_expected_weight() {
        let mut stats = TraceStats::default();
        // Survival 0.25: u below survives and is divided by 0.25, so E[weight] is kept.
        assert_eq!(roulette(0.25, 0.1, &mut stats), Some(0.25));
        assert_eq!(roulette(0.25, 0.3, &mut stats), None);
        assert_eq!(roulette(3.0, 0.999, &mut stats), Some(1.0));
        assert_eq!(roulette(0.0, 0.0, &mut stats), None);
        assert_eq!(roulette(f64::NAN, 0.0, &mut stats), None);
        assert_eq!(stats.roulette_kills, 3);
        assert_eq!(relative_throughput(&[0.5, 0.0, 2.0], &[1.0, 0.0, 4.0]), 0.5);
        assert_eq!(relative_throughput(&[1.0], &[0.0]), 0.0);
    }

    #[test]
    fn the_power_heuristic_handles_deltas_and_infinities() {
        assert_eq!(power_heuristic(1.0, 1.0), 0.5);
        assert_eq!(power_heuristic(0.0, 1.0), 0.0);
        assert_eq!(power_heuristic(1.0, f64::INFINITY), 0.0);
        assert_eq!(power_heuristic(f64::INFINITY, 1.0), 1.0);
        assert!((power_heuristic(3.0, 1.0) - 0.9).abs() < 1e-15);
    }
}
