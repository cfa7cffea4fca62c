//! BDPT's multiple importance sampling: the weight of a strategy from the densities of the
//! path's vertices ([`mis_weight`], the power heuristic over every strategy that could have
//! made the same path), and the full path of a strategy as the weight sees it
//! ([`build_mis_path`]).

use glam::DVec3;

use super::Bdpt;
use super::Strategy;
use super::vertex::{LightEnd, Vertex};

/// One vertex of a full path, as the MIS weight sees it (see [`mis_weight`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct MisVertex {
    /// Area density (m^-2; for a point, solid-angle density over distance squared) with which
    /// the light side generates this vertex from the vertices before it; for the first vertex,
    /// the density of choosing it on the light. 0 through a specular vertex.
    pub(super) from_light: f64,
    /// Area density with which the camera side generates this vertex from the vertices after
    /// it. 0 through a specular vertex.
    pub(super) from_camera: f64,
    /// Whether the vertex scatters by a Dirac delta (a specular surface), so that no connection
    /// can end at it; for the first vertex, a light with a delta direction.
    pub(super) delta: bool,
}

/// The power-heuristic weight of strategy `s` (the first `s` vertices from the light, the others
/// from the camera) for the full path `path`, ordered from the light (index 0) to the camera
/// (last). Strategies that end a connection at a delta vertex are not counted, nor `s = 0`
/// when `light_is_delta` (a light a camera path cannot hit), nor `t = 0` (the camera, pinhole or
/// lens, is not part of the scene: paths never hit it). Zero densities (delta vertices) count as 1, so deltas cancel. `s` must be a valid
/// strategy; the result is in `[0, 1]`.
pub(super) fn mis_weight(path: &[MisVertex], s: usize, light_is_delta: bool) -> f64 {
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

/// The vertices a strategy sampled afresh: the light vertex of next-event estimation (`s = 1`),
/// the lens point of a connection to the camera (`t = 1`).
#[derive(Clone, Copy)]
pub(super) struct Sampled<'v> {
    pub light: Option<&'v Vertex>,
    pub camera: Option<&'v Vertex>,
}

/// The full path of strategy `(s, t)` as [`MisVertex`]es into `mis`, from the light to the
/// camera, with the densities at the connection updated; returns whether its light cannot be
/// hit by a camera path.
pub(super) fn build_mis_path(
    bdpt: &Bdpt<'_>,
    strategy: Strategy<'_>,
    sampled: Sampled<'_>,
    end: &LightEnd,
    mis: &mut Vec<MisVertex>,
) -> bool {
    let Strategy { light, camera, s, t } = strategy;
    mis.clear();
    // References, not copies: a vertex is a few hundred bytes and this runs per strategy.
    let qs: Option<&Vertex> = if s == 1 {
        sampled.light.or_else(|| light.first())
    } else if s > 0 {
        Some(&light[s - 1])
    } else {
        None
    };
    let pt: &Vertex = match sampled.camera {
        Some(c) if t == 1 => c,
        _ => &camera[t - 1],
    };
    let qs_minus = if s >= 2 { Some(&light[s - 2]) } else { None };
    let pt_minus = if t >= 2 { Some(&camera[t - 2]) } else { None };
    for (i, v) in light.iter().take(s).enumerate() {
        let v = if i + 1 == s { qs.unwrap_or(v) } else { v };
        mis.push(MisVertex { from_light: v.pdf_fwd, from_camera: v.pdf_rev, delta: v.delta });
    }
    for (j, v) in camera[..t].iter().enumerate().rev() {
        let v = if j + 1 == t { pt } else { v };
        mis.push(MisVertex { from_light: v.pdf_rev, from_camera: v.pdf_fwd, delta: v.delta });
    }
    let ip = s; // index of pt in the full path
    let light_id = if s == 0 { Some(end.id) } else { None };
    // pt as sampled from the light side.
    mis[ip].from_light = match qs {
        Some(q) => bdpt.pdf(q, qs_minus, pt, None),
        None => {
            let dir = pt_minus.map_or(DVec3::ZERO, |m| m.point - pt.point);
            end.pmf * bdpt.light_pdfs(end.id, pt.point, dir).0
        }
    };
    mis[ip].delta = if s == 0 { end.flags.delta_direction } else { false };
    if let Some(m) = pt_minus {
        mis[ip + 1].from_light = match qs {
            Some(q) => bdpt.pdf(pt, Some(q), m, None),
            None => bdpt.pdf(pt, None, m, light_id),
        };
    }
    if let Some(q) = qs {
        mis[s - 1].from_camera = bdpt.pdf(pt, pt_minus, q, None);
        mis[s - 1].delta = if s == 1 { end.first_vertex_delta() } else { false };
        if let Some(qm) = qs_minus {
            mis[s - 2].from_camera = bdpt.pdf(q, Some(pt), qm, None);
        }
    }
    let on_surface = match s {
        0 => true,
        1 => qs.is_some_and(|q| q.ng != DVec3::ZERO),
        _ => light[0].ng != DVec3::ZERO,
    };
    end.is_delta(on_surface)
}
