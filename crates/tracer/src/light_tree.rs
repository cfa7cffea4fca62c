//! [`LightTree`]: a bounding volume hierarchy over lights that chooses one for a receiving
//! point in proportion to an estimate of what each sends there (Conty Estevez and Kulla 2018;
//! pbrt-v4's `BVHLightSampler`), in `O(log n)`, with the exact probability of every choice.
//!
//! Each node holds a [`LightBounds`] of the lights under it. A choice walks down from the
//! root: at each node it goes to one of the two children with probability proportional to its
//! importance at the receiving point and its surface normal
//! ([`spectrace_lights::PreparedBounds::importance_at`]), remapping the uniform so that what is left of it
//! chooses further down (and then the point on the light). The probability of a light is the
//! product of the probabilities along its path from the root, recomputed from the same
//! importances by [`LightTree::pmf`], so a strategy weighted by multiple importance sampling
//! sees exactly the density that chose it. Each light's path is stored as bits (left or
//! right at each depth), so that `pmf` visits only the nodes above the light.
//!
//! Lights without finite bounds (skies, environments, plugins that do not say) are not in the
//! tree: with `k` of them, a choice takes one of them with probability `k / (k + 1)`, by
//! power among them, and walks the tree otherwise.
//!
//! # Build
//! Top-down: the lights are split at the bucket boundary (12 buckets along each axis of the box
//! of their centres) that minimises the cost of Conty and Kulla, power times the orientation
//! measure of the normals' cone times the surface area of the box (a nearly flat box counts by
//! its diagonal so points still split). Lights whose centres coincide are split in halves, and so
//! are all lights below depth [`MEDIAN_DEPTH`], which bounds the depth by `MEDIAN_DEPTH + 64`.

use std::f64::consts::PI;

use glam::DVec3;
use spectrace_lights::{LightBounds, LightId, LightSet, PreparedBounds};
use spectrace_sampling::{Discrete, ONE_MINUS_EPSILON};

use crate::light_sampler::SampledLight;

/// Depth below which the build splits lights in halves, whatever their cost.
const MEDIAN_DEPTH: usize = 48;

/// Buckets per axis when the build looks for a split.
const BUCKETS: usize = 12;

/// A node of the tree: its bounds (prepared for importance queries) and either a light or the
/// index of its second child (the first child follows it).
#[derive(Debug, Clone)]
struct Node {
    bounds: PreparedBounds,
    kind: NodeKind,
}

#[derive(Debug, Clone, Copy)]
enum NodeKind {
    Leaf(LightId),
    Inner { second: u32 },
}

/// Where a light sits in the tree: its leaf's depth and the turns from the root (bit `d` set:
/// the second child at depth `d`).
#[derive(Debug, Clone, Copy, Default)]
struct Trail {
    bits: u128,
    depth: u8,
}

/// A light tree over a set of lights (see the module documentation).
#[derive(Debug, Clone, Default)]
pub struct LightTree {
    nodes: Vec<Node>,
    /// Per light of the set: its trail, for lights in the tree.
    trails: Vec<Option<Trail>>,
    /// The lights outside the tree, with their choice by power.
    unbounded: Vec<LightId>,
    unbounded_choice: Option<Discrete>,
    /// Per light of the set: its entry among the unbounded ones.
    unbounded_entry: Vec<Option<u32>>,
    /// Probability of choosing among the unbounded lights rather than walking the tree.
    p_unbounded: f64,
}

impl LightTree {
    /// A tree over the lights of `lights` that `admit` accepts and that have power; those
    /// with valid [`spectrace_lights::LightSource::light_bounds`] go into the tree, the rest
    /// beside it.
    pub fn new(
        lights: &LightSet,
        admit: impl Fn(LightId, &dyn spectrace_lights::LightSource) -> bool,
    ) -> Self {
        let count = lights.lights().len();
        let mut bounded = Vec::new();
        let (mut unbounded, mut unbounded_powers) = (Vec::new(), Vec::new());
        let mut unbounded_entry = vec![None; count];
        for (i, light) in lights.lights().iter().enumerate() {
            let power = light.power();
            let id = LightId(i as u32);
            if !(admit(id, light.as_ref()) && power > 0.0 && power.is_finite()) {
                continue;
            }
            match light.light_bounds().filter(LightBounds::is_valid) {
                Some(b) => bounded.push((id, b)),
                None => {
                    unbounded_entry[i] = Some(unbounded.len() as u32);
                    unbounded.push(id);
                    unbounded_powers.push(power);
                }
            }
        }
        // Powers relative to the largest, so that importances stay far from overflow.
        let peak = bounded.iter().map(|(_, b)| b.phi).fold(0.0, f64::max);
        for (_, b) in &mut bounded {
            b.phi /= peak;
        }
        let mut tree = Self {
            nodes: Vec::with_capacity(2 * bounded.len()),
            trails: vec![None; count],
            unbounded_choice: Discrete::new(&unbounded_powers).ok(),
            unbounded,
            unbounded_entry,
            p_unbounded: 0.0,
        };
        if !bounded.is_empty() {
            tree.build(&mut bounded, Trail::default());
        }
        let k = tree.unbounded.len() as f64;
        tree.p_unbounded = if tree.nodes.is_empty() { 1.0 } else { k / (k + 1.0) };
        if tree.unbounded_choice.is_none() {
            tree.p_unbounded = 0.0;
        }
        tree
    }

    /// How many lights the tree can choose (in it and beside it).
    pub fn len(&self) -> usize {
        self.nodes.len().div_ceil(2) + self.unbounded.len()
    }

    /// Whether no light can be chosen.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty() && self.unbounded_choice.is_none()
    }

    /// The depth of the deepest leaf (0 for a tree of one light or none).
    pub fn depth(&self) -> usize {
        self.trails.iter().flatten().map(|t| usize::from(t.depth)).max().unwrap_or(0)
    }

    /// Builds the subtree of `lights` at the end of `nodes`, whose trail from the root is
    /// `trail`; returns its bounds.
    fn build(&mut self, lights: &mut [(LightId, LightBounds)], trail: Trail) -> LightBounds {
        if let [(id, bounds)] = lights {
            self.trails[id.0 as usize] = Some(trail);
            self.nodes.push(Node { bounds: bounds.prepare(), kind: NodeKind::Leaf(*id) });
            return *bounds;
        }
        let at = self.nodes.len();
        // A placeholder, filled once both children are built.
        self.nodes
            .push(Node { bounds: lights[0].1.prepare(), kind: NodeKind::Inner { second: 0 } });
        let split = split_point(lights, usize::from(trail.depth));
        let (first, second) = lights.split_at_mut(split);
        let depth = trail.depth + 1;
        let a = self.build(first, Trail { bits: trail.bits, depth });
        let second_index = self.nodes.len() as u32;
        let turn = 1u128 << trail.depth;
        let b = self.build(second, Trail { bits: trail.bits | turn, depth });
        let union = a.union(&b);
        self.nodes[at] =
            Node { bounds: union.prepare(), kind: NodeKind::Inner { second: second_index } };
        union
    }

    /// Chooses a light for a receiver at `point` with unit surface `normal` (`DVec3::ZERO`:
    /// none) from the uniform `u`; `None` when no light can send light there (every importance
    /// is 0) or there is none.
    pub fn sample(&self, (point, normal): (DVec3, DVec3), u: f64) -> Option<SampledLight> {
        let mut u = u.clamp(0.0, ONE_MINUS_EPSILON);
        if u < self.p_unbounded {
            let choice = self.unbounded_choice.as_ref()?;
            let (k, remapped) = choice.sample_remapped(u / self.p_unbounded);
            let id = *self.unbounded.get(k)?;
            return Some(SampledLight { id, pmf: self.p_unbounded * choice.pmf(k), u: remapped });
        }
        if self.nodes.is_empty() {
            return None;
        }
        u = ((u - self.p_unbounded) / (1.0 - self.p_unbounded)).min(ONE_MINUS_EPSILON);
        let mut pmf = 1.0 - self.p_unbounded;
        let mut node = 0;
        loop {
            match self.nodes[node].kind {
                NodeKind::Leaf(id) => {
                    let reaches = self.nodes[node].bounds.importance_at(point, normal) > 0.0;
                    return reaches.then_some(SampledLight { id, pmf, u });
                }
                NodeKind::Inner { second } => {
                    let p_first = self.first_share(node, second as usize, (point, normal))?;
                    if u < p_first {
                        u = (u / p_first).min(ONE_MINUS_EPSILON);
                        pmf *= p_first;
                        node += 1;
                    } else {
                        u = ((u - p_first) / (1.0 - p_first)).min(ONE_MINUS_EPSILON);
                        pmf *= 1.0 - p_first;
                        node = second as usize;
                    }
                }
            }
        }
    }

    /// The probability that [`sample`](Self::sample) chooses light `id` for a receiver at
    /// `point` with `normal` (0 for a light it never chooses there).
    pub fn pmf(&self, (point, normal): (DVec3, DVec3), id: LightId) -> f64 {
        if let Some(k) = self.unbounded_entry.get(id.0 as usize).copied().flatten() {
            return self
                .unbounded_choice
                .as_ref()
                .map_or(0.0, |c| self.p_unbounded * c.pmf(k as usize));
        }
        let Some(trail) = self.trails.get(id.0 as usize).copied().flatten() else { return 0.0 };
        let mut pmf = 1.0 - self.p_unbounded;
        let mut node = 0;
        for depth in 0..trail.depth {
            let NodeKind::Inner { second } = self.nodes[node].kind else { return 0.0 };
            let Some(p_first) = self.first_share(node, second as usize, (point, normal)) else {
                return 0.0;
            };
            if trail.bits & (1u128 << depth) == 0 {
                pmf *= p_first;
                node += 1;
            } else {
                pmf *= 1.0 - p_first;
                node = second as usize;
            }
        }
        if self.nodes[node].bounds.importance_at(point, normal) > 0.0 { pmf } else { 0.0 }
    }

    /// The probability of going to the first child of inner node `node` (whose second child is
    /// `second`) for a receiver at `point` with `normal`; `None` when neither child reaches it.
    #[inline]
    fn first_share(
        &self,
        node: usize,
        second: usize,
        (point, normal): (DVec3, DVec3),
    ) -> Option<f64> {
        // Halved so that two importances near the largest double still add.
        let a = 0.5 * self.nodes[node + 1].bounds.importance_at(point, normal);
        let b = 0.5 * self.nodes[second].bounds.importance_at(point, normal);
        let total = a + b;
        (total > 0.0).then(|| a / total)
    }
}

/// Where to split `lights` (reordered so that the split is a prefix), at depth `depth`.
fn split_point(lights: &mut [(LightId, LightBounds)], depth: usize) -> usize {
    let half = lights.len() / 2;
    let (lo, hi) = lights.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), (_, b)| (lo.min(b.centre()), hi.max(b.centre())),
    );
    let extent = hi - lo;
    if depth >= MEDIAN_DEPTH || !(extent.max_element() > 0.0) {
        return half;
    }
    let whole = lights.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), (_, b)| (lo.min(b.min), hi.max(b.max)),
    );
    let mut best: Option<(f64, usize, usize)> = None;
    for axis in 0..3 {
        if !(extent[axis] > 0.0) {
            continue;
        }
        let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
        for (_, b) in lights.iter() {
            let slot = &mut buckets[bucket_of(b, axis, lo, extent)];
            *slot = Some(slot.map_or(*b, |s| s.union(b)));
        }
        let scale = long_side_ratio(whole, axis);
        // The cost of the buckets below each cut and of those above it, by two sweeps.
        let sweep = |order: &mut dyn Iterator<Item = &Option<LightBounds>>| {
            let mut acc: Option<LightBounds> = None;
            order
                .map(|b| {
                    if let Some(b) = b {
                        acc = Some(acc.map_or(*b, |a| a.union(b)));
                    }
                    acc.map(|a| cost_of(&a))
                })
                .collect::<Vec<_>>()
        };
        let below = sweep(&mut buckets.iter());
        let mut above = sweep(&mut buckets.iter().rev());
        above.reverse();
        for cut in 1..BUCKETS {
            let (Some(below), Some(above)) = (below[cut - 1], above[cut]) else { continue };
            let cost = scale * (below + above);
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, cut));
            }
        }
    }
    let Some((_, axis, cut)) = best else { return half };
    let mut first = 0;
    for i in 0..lights.len() {
        if bucket_of(&lights[i].1, axis, lo, extent) < cut {
            lights.swap(i, first);
            first += 1;
        }
    }
    if first == 0 || first == lights.len() { half } else { first }
}

/// The bucket along `axis` of a bound's centre, in the box of centres from `lo` spanning
/// `extent`.
fn bucket_of(b: &LightBounds, axis: usize, lo: DVec3, extent: DVec3) -> usize {
    let t = (b.centre()[axis] - lo[axis]) / extent[axis];
    ((t * BUCKETS as f64) as usize).min(BUCKETS - 1)
}

/// The ratio of the longest side of the box `(min, max)` to its side along `axis` (Conty and
/// Kulla's `K_r`, favouring cuts across long boxes), 1 for a flat side.
fn long_side_ratio((min, max): (DVec3, DVec3), axis: usize) -> f64 {
    let d = max - min;
    if d[axis] > 0.0 { d.max_element() / d[axis] } else { 1.0 }
}

/// Conty and Kulla's cost of a node: power times the orientation measure of its cone times the
/// surface area of its box (at least the square of its diagonal over a million, so that a
/// cluster of points that is flat along an axis still has a cost).
fn cost_of(b: &LightBounds) -> f64 {
    let d = b.max - b.min;
    let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
    let area = area.max(1e-6 * d.length_squared());
    if b.cos_theta_o <= -1.0 {
        // Every direction: theta_w = pi whatever the spread, M = 4 pi.
        return b.phi * 4.0 * PI * area;
    }
    let theta_o = b.cos_theta_o.clamp(-1.0, 1.0).acos();
    let theta_e = b.cos_theta_e.clamp(-1.0, 1.0).acos();
    let theta_w = (theta_o + theta_e).min(PI);
    let sin_o = theta_o.sin();
    let m_omega = 2.0 * PI * (1.0 - b.cos_theta_o)
        + 0.5
            * PI
            * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                + b.cos_theta_o);
    b.phi * m_omega.max(0.0) * area
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;
    use crate::light_sampler::tests::set;

    /// 40 lights of every bounded kind, spread over a 4 m cube, and a sky beside them.
    fn mixed(with_sky: bool) -> LightSet {
        let mut lights = Vec::new();
        for i in 0..40 {
            let t = f64::from(i);
            let p = [2.0 * (t * 0.61).sin(), 1.0 + (t * 0.37).cos(), 2.0 * (t * 0.23).sin()];
            let d = "{\"type\": \"CieIlluminant\", \"name\": \"D65\"}";
            lights.push(match i % 4 {
                0 => format!(r#"{{"type": "PointLight", "position": {p:?}, "power": {}, "spd": {d}}}"#, 1.0 + t),
                1 => format!(r#"{{"type": "UniformSpotLight", "position": {p:?}, "direction": [0.1, -1, 0], "cone_angle": 30, "power": 5, "spd": {d}}}"#),
                2 => format!(r#"{{"type": "RectangleLight", "corner": {p:?}, "edge_u": [0.2, 0, 0], "edge_v": [0, 0, 0.3], "power": 3, "spd": {d}}}"#),
                _ => format!(r#"{{"type": "DiskLight", "center": {p:?}, "normal": [0, -1, 0.3], "radius": 0.1, "power": 2, "two_sided": true, "spd": {d}}}"#),
            });
        }
        if with_sky {
            lights.push(r#"{"type": "Sky", "corner": [-5, 10, -5], "edge_u": [10, 0, 0], "edge_v": [0, 0, 10], "direction": [0, -1, 0], "power": 50, "spd": {"type": "CieIlluminant", "name": "D65"}}"#.to_owned());
        }
        set(&format!("[{}]", lights.join(",")))
    }

    /// Receivers around and among the lights.
    fn receivers() -> Vec<DVec3> {
        (0..50)
            .map(|i| {
                let t = f64::from(i);
                DVec3::new(3.0 * (t * 0.77).sin(), 2.5 * (t * 0.41).cos(), 3.0 * (t * 1.3).cos())
            })
            .collect()
    }

    #[test]
    fn the_pmf_of_every_light_sums_to_one_and_is_what_sampling_returns() {
        for with_sky in [false, true] {
            let lights = mixed(with_sky);
            let tree = LightTree::new(&lights, |_, _| true);
            assert_eq!(tree.len(), lights.lights().len());
            for p in receivers() {
                let pmfs: Vec<f64> = (0..lights.lights().len())
                    .map(|i| tree.pmf((p, DVec3::ZERO), LightId(i as u32)))
                    .collect();
                // At most 1: a walk that reaches a node none of whose lights shine on `p`
                // chooses nothing (those lights would add nothing).
                let total: f64 = pmfs.iter().sum();
                assert!(total <= 1.0 + 1e-12 && total > 0.5, "{p}: the pmf sums to {total}");
                // Stratified uniforms: each light's count (and that of no choice) is its
                // probability to within a few strata (one per level of the tree it descends).
                let n = 20_000;
                let (mut counts, mut none) = (vec![0u32; pmfs.len()], 0u32);
                for k in 0..n {
                    let Some(s) =
                        tree.sample((p, DVec3::ZERO), (f64::from(k) + 0.5) / f64::from(n))
                    else {
                        none += 1;
                        continue;
                    };
                    assert!((0.0..1.0).contains(&s.u));
                    assert_eq!(s.pmf, tree.pmf((p, DVec3::ZERO), s.id), "{p}: light {:?}", s.id);
                    assert!(s.pmf > 0.0);
                    counts[s.id.0 as usize] += 1;
                }
                let slack = tree.depth() as f64 + 2.0;
                for (i, (&c, &pmf)) in counts.iter().zip(&pmfs).enumerate() {
                    let expected = f64::from(n) * pmf;
                    assert!(
                        (f64::from(c) - expected).abs() <= slack,
                        "{p}: light {i}: {c} vs {expected}"
                    );
                }
                let expected_none = f64::from(n) * (1.0 - total);
                assert!(
                    (f64::from(none) - expected_none).abs() <= slack * 4.0,
                    "{p}: {none} vs {expected_none}"
                );
            }
        }
    }

    #[test]
    fn a_light_that_cannot_reach_a_point_is_never_chosen_for_it() {
        // Two rectangles facing down at heights 1 and 3: a point between them sees only the
        // upper one (the lower one's back faces it).
        let lights = set(r#"[
          {"type": "RectangleLight", "corner": [0, 1, 0], "edge_u": [1, 0, 0], "edge_v": [0, 0, 1], "power": 1, "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}},
          {"type": "RectangleLight", "corner": [0, 3, 0], "edge_u": [1, 0, 0], "edge_v": [0, 0, 1], "power": 1, "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}}
        ]"#);
        let normal = lights.lights()[0].light_bounds().unwrap().axis;
        assert!(normal.y < -0.99, "the rectangles face down: {normal}");
        let tree = LightTree::new(&lights, |_, _| true);
        let p = DVec3::new(0.5, 2.0, 0.5);
        assert_eq!(tree.pmf((p, DVec3::ZERO), LightId(0)), 0.0);
        assert_eq!(tree.pmf((p, DVec3::ZERO), LightId(1)), 1.0);
        for k in 0..100 {
            assert_eq!(tree.sample((p, DVec3::ZERO), f64::from(k) / 100.0).unwrap().id, LightId(1));
        }
        // Above both, neither reaches: no choice at all.
        assert!(tree.sample((DVec3::new(0.5, 4.0, 0.5), DVec3::ZERO), 0.3).is_none());
    }

    #[test]
    fn coincident_lights_split_in_halves_and_the_depth_stays_logarithmic() {
        let one = r#"{"type": "PointLight", "position": [1, 2, 3], "power": 1, "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}}"#;
        let lights = set(&format!("[{}]", vec![one; 5000].join(",")));
        let tree = LightTree::new(&lights, |_, _| true);
        assert_eq!(tree.depth(), 13, "5000 lights in halves: ceil(log2 5000) levels");
        let p = DVec3::new(0.0, 0.0, 0.0);
        for i in [0, 1234, 4999] {
            assert!((tree.pmf((p, DVec3::ZERO), LightId(i)) - 1.0 / 5000.0).abs() < 1e-15);
        }
    }

    #[test]
    fn admitted_lights_only_and_unbounded_lights_beside_the_tree() {
        let lights = mixed(true);
        let sky = LightId(40);
        let tree = LightTree::new(&lights, |id, _| id.0 % 2 == 0 || id == sky);
        let p = DVec3::new(0.0, 0.5, 0.0);
        assert_eq!(tree.pmf((p, DVec3::ZERO), LightId(1)), 0.0);
        // One unbounded light: chosen half the time, as pbrt-v4 does.
        assert!((tree.pmf((p, DVec3::ZERO), sky) - 0.5).abs() < 1e-15);
        let total: f64 = (0..41).map(|i| tree.pmf((p, DVec3::ZERO), LightId(i))).sum();
        assert!((total - 1.0).abs() < 1e-12);
    }
}
