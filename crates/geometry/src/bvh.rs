//! The BVH the world traverses: `obvhs`'s `Bvh2` converted into a compact array of nodes that
//! each hold both children's f32 boxes, traversed front to back with a conservative f32 slab test.
//!
//! # Why the f32 test never loses a hit
//!
//! The boxes themselves are rounded outwards from the exact f64 bounds ([`crate::World`] does
//! that before building). For a ray `O + t D` (f64) and one slab `[lo, hi]` (f32 values, exact as
//! reals), with `D >= 0` on that axis the true entry and exit are `(lo - O) / D` and
//! `(hi - O) / D`. Per ray we precompute, per axis:
//!
//! * the origin rounded to f32 **both ways**, `o_lo <= O <= o_hi`; the entry uses `o_hi` and the
//!   exit `o_lo` (mirrored for `D < 0`), so with exact arithmetic the entry can only decrease and
//!   the exit only increase: the origin's rounding to f32 (an ulp is 0.06 at 1e6) widens the
//!   interval instead of moving it;
//! * `|1/D|` rounded to f32 downwards for the entry and upwards for the exit (an infinite exit
//!   inverse for a tiny `D`, a finite entry one, so neither overflow nor division by zero loses an
//!   overlap; an exactly zero `D` gives IEEE infinities as in pbrt).
//!
//! What remains is one rounding in the subtraction and one in the product, a relative error below
//! `gamma(3)` on each distance, with the sign kept. Any `t*` in the true overlap of the three slabs
//! and `[0, t_max]` therefore satisfies `entry <= t* (1 + gamma3)` and `exit >= t* (1 - gamma3)`,
//! so the test `max(0, entries) <= min(exits, t_max) * (1 + 4 gamma3) + MIN_POSITIVE` holds (the
//! factor covers `(1 + gamma3) / (1 - gamma3)` and its own rounding; `MIN_POSITIVE` covers products
//! that underflow; `t_max` is rounded up to f32 first). NaNs (`0 * inf` for a ray in a slab's
//! plane, `inf - inf`) are replaced by the widest value (`0` for an entry, `+inf` for an exit), so
//! they can only widen.
//!
//! The boxes are stored relative to the world's centre `C` (so f32 keeps its precision for a
//! scene far from the origin, and tiny primitives there keep distinct boxes); the ray origin is
//! shifted by the same `C` in f64 and the result bracketed one f64 ulp either way before the
//! directed f32 rounding, so `o_lo <= O - C <= o_hi` holds exactly.
//!
//! Two cases would break the relative-error argument, and are traversed in f64 instead (pbrt's
//! test on the exact f64 copies of the same boxes): a world with a box coordinate beyond
//! [`F32_SAFE`] (the f32 subtraction could overflow) and a ray whose origin lies beyond it or is
//! not finite.

use glam::{BVec3A, DVec3, Vec3A, Vec4};
use obvhs::bvh2::Bvh2;

use crate::Bounds;

/// Marks a child reference as a leaf (the low bits are then its first primitive slot).
const LEAF: u32 = 1 << 31;

/// The largest coordinate (box or ray origin, absolute) the f32 slab test handles; beyond it the
/// traversal runs in f64. Differences of two such values cannot overflow f32.
pub(crate) const F32_SAFE: f32 = 1e30;

/// The f32 unit roundoff's `gamma(3)`.
const GAMMA3_F32: f32 = 3.0 * (f32::EPSILON * 0.5) / (1.0 - 3.0 * (f32::EPSILON * 0.5));

/// The factor applied to exits and `t_max` in the f32 test.
const WIDEN: f32 = 1.0 + 4.0 * GAMMA3_F32;

/// One inner node, one cache line: the boxes of its two children, with the references to them
/// in the otherwise unused fourth lanes (as f32 bit patterns).
///
/// `b[0]` = child 0's lower corner (w: child 0's reference), `b[1]` = its upper corner (w: child
/// 1's reference), `b[2]`, `b[3]` = child 1's corners (w of `b[2]`: the two leaf counts, child 0
/// in the low 16 bits). A reference is an inner node index, or `LEAF | first slot`.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct Node {
    b: [Vec4; 4],
}

impl Node {
    /// A node whose children are both empty leaves with empty boxes (placeholder).
    fn empty() -> Self {
        Self::new([Vec3A::INFINITY; 2], [Vec3A::NEG_INFINITY; 2], [LEAF; 2], [0; 2])
    }

    /// Packs two children.
    fn new(min: [Vec3A; 2], max: [Vec3A; 2], child: [u32; 2], count: [u16; 2]) -> Self {
        let lane = |v: Vec3A, w: u32| Vec4::new(v.x, v.y, v.z, f32::from_bits(w));
        let counts = count[0] as u32 | (count[1] as u32) << 16;
        Self {
            b: [
                lane(min[0], child[0]),
                lane(max[0], child[1]),
                lane(min[1], counts),
                lane(max[1], 0),
            ],
        }
    }

    /// Child `c`'s lower corner.
    #[inline(always)]
    fn min(&self, c: usize) -> Vec3A {
        Vec3A::from_vec4(self.b[2 * c])
    }

    /// Child `c`'s upper corner.
    #[inline(always)]
    fn max(&self, c: usize) -> Vec3A {
        Vec3A::from_vec4(self.b[2 * c + 1])
    }

    /// Child `c`'s reference and leaf primitive count.
    #[inline(always)]
    fn child(&self, c: usize) -> (u32, u32) {
        let child = self.b[c].w.to_bits();
        let count = (self.b[2].w.to_bits() >> (16 * c)) & 0xffff;
        (child, count)
    }
}

/// The converted BVH. Node 0 is a pseudo-root whose first child is the real root (so a root that
/// is a leaf needs no special case) and whose second child is an empty leaf with an empty box.
#[derive(Debug, Clone, Default)]
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    /// The point the f32 boxes are relative to (world coordinates = box + `center`).
    center: DVec3,
    /// Some box coordinate is beyond [`F32_SAFE`]: always traverse in f64.
    wide: bool,
}

impl Bvh {
    /// Converts `bvh`, whose boxes are relative to `center` (its primitive slots are
    /// `bvh.primitive_indices`' positions).
    pub(crate) fn from_bvh2(bvh: &Bvh2, center: DVec3) -> Self {
        if bvh.nodes.is_empty() {
            return Self::default();
        }
        let mut nodes = vec![Node::empty()];
        let mut work: Vec<(usize, usize)> = Vec::new();
        let mut wide = false;
        // The reference, count and box of obvhs node `i`, queueing it if it is an inner node.
        let mut child = |nodes: &mut Vec<Node>, work: &mut Vec<(usize, usize)>, i: usize| {
            let n = &bvh.nodes[i];
            let a = n.aabb();
            let too_big = |v: Vec3A| !(v.abs().max_element() <= F32_SAFE);
            wide |= too_big(a.min) || too_big(a.max);
            if n.is_leaf() {
                // obvhs leaves hold at most `max_prims_per_leaf` (<= 255) primitives.
                let count = u16::try_from(n.prim_count).unwrap_or(u16::MAX);
                (LEAF | n.first_index, count, a.min, a.max)
            } else {
                let index = nodes.len();
                nodes.push(Node::empty());
                work.push((i, index));
                (index as u32, 0, a.min, a.max)
            }
        };
        let (c0, n0, lo0, hi0) = child(&mut nodes, &mut work, 0);
        nodes[0] =
            Node::new([lo0, Vec3A::INFINITY], [hi0, Vec3A::NEG_INFINITY], [c0, LEAF], [n0, 0]);
        while let Some((i, k)) = work.pop() {
            let first = bvh.nodes[i].first_index as usize;
            let (c0, n0, lo0, hi0) = child(&mut nodes, &mut work, first);
            let (c1, n1, lo1, hi1) = child(&mut nodes, &mut work, first + 1);
            nodes[k] = Node::new([lo0, lo1], [hi0, hi1], [c0, c1], [n0, n1]);
        }
        Self { nodes, center, wide }
    }

    /// Number of nodes (each with two children).
    pub(crate) fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Calls `on_prim(slot, t_max)` for every primitive slot whose leaf box the ray may meet
    /// within the current `t_max`, nearest boxes first. `on_prim` returns `None` (no hit), the
    /// new `t_max` (a closer hit), or a negative value to stop.
    #[inline]
    pub(crate) fn traverse(
        &self,
        origin: DVec3,
        direction: DVec3,
        t_max: f64,
        on_prim: impl FnMut(u32, f64) -> Option<f64>,
    ) {
        if self.nodes.is_empty() || !(t_max > 0.0) {
            return;
        }
        if !self.wide
            && let Some(mut slab) = SlabF32::new(origin - self.center, direction, t_max)
        {
            return self.walk(&mut slab, t_max, on_prim);
        }
        let mut slab = SlabF64::new(origin, self.center, direction, t_max);
        self.walk(&mut slab, t_max, on_prim);
    }

    /// The traversal loop, generic over the box test.
    #[inline]
    fn walk<S: Slab>(
        &self,
        slab: &mut S,
        mut t_max: f64,
        mut on_prim: impl FnMut(u32, f64) -> Option<f64>,
    ) {
        let mut stack = Stack::<S::T>::new();
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            let [h0, h1] = slab.test(n);
            let mut next = match (h0, h1) {
                (Some(a), Some(b)) => {
                    let (near, far, far_t) = if b < a { (1, 0, a) } else { (0, 1, b) };
                    let (child, count) = n.child(far);
                    stack.push((child, count, far_t));
                    Some(n.child(near))
                }
                (Some(_), None) => Some(n.child(0)),
                (None, Some(_)) => Some(n.child(1)),
                (None, None) => None,
            };
            loop {
                match next {
                    Some((child, _)) if child & LEAF == 0 => {
                        node = child as usize;
                        break;
                    }
                    Some((child, count)) => {
                        let first = child & !LEAF;
                        for slot in first..first + count {
                            match on_prim(slot, t_max) {
                                Some(t) if t < 0.0 => return,
                                Some(t) => {
                                    t_max = t;
                                    slab.set_limit(t);
                                }
                                None => {}
                            }
                        }
                        next = None;
                    }
                    None => loop {
                        let Some((child, count, near)) = stack.pop() else { return };
                        if slab.alive(near) {
                            next = Some((child, count));
                            break;
                        }
                    },
                }
            }
        }
    }
}

/// A ray/box test for both children of a node.
trait Slab {
    /// The entry distance type (for ordering and culling).
    type T: Copy + PartialOrd + Default;
    /// The entry distances of the children the ray may meet within the current limit.
    fn test(&self, node: &Node) -> [Option<Self::T>; 2];
    /// A closer hit was found at `t_max`.
    fn set_limit(&mut self, t_max: f64);
    /// Whether a child entered at `near` (as `test` returned it) may still hold a closer hit.
    fn alive(&self, near: Self::T) -> bool;
}

/// Relative widening of the fast per-ray bounds (see [`SlabF32::new`]): four f32 half-ulps.
const FAST_REL: f32 = 1.0 / (1u32 << 22) as f32;
/// Smallest `1/|d|` the fast bounds take: well inside the normal f32 range (smaller ones would
/// round to subnormals, whose relative error the widening does not cover).
const FAST_INV_MIN: f64 = 1e-30;

/// `x` rounded to f32 downwards (so the result is `<= x`; NaN stays NaN).
fn f32_down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { f.next_down() } else { f }
}

/// `x` rounded to f32 upwards (so the result is `>= x`; NaN stays NaN).
fn f32_up(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

/// The conservative f32 slab test (see the module documentation).
struct SlabF32 {
    /// Per axis: the ray direction is negative (sign bit set, so `-0` counts).
    negative: BVec3A,
    /// The origin bound used for entries (`o_hi` for positive axes, `o_lo` for negative).
    o_near: Vec3A,
    /// The origin bound used for exits.
    o_far: Vec3A,
    /// `1/D` rounded towards zero in magnitude.
    inv_near: Vec3A,
    /// `1/D` rounded away from zero in magnitude.
    inv_far: Vec3A,
    /// `t_max` rounded up, widened, plus `MIN_POSITIVE`.
    t_max: f32,
}

impl SlabF32 {
    /// The per-ray setup from the origin relative to the boxes' centre, rounded once in f64 (so
    /// the exact value lies within one f64 ulp of it); `None` when it is beyond [`F32_SAFE`] or
    /// not finite.
    #[inline]
    fn new(origin: DVec3, direction: DVec3, t_max: f64) -> Option<Self> {
        if !(origin.abs().max_element() <= f64::from(F32_SAFE)) {
            return None;
        }
        let d = direction.to_array();
        let negative =
            BVec3A::new(d[0].is_sign_negative(), d[1].is_sign_negative(), d[2].is_sign_negative());
        let inv = direction.abs().recip();
        // The fast, branch-free bounds (the common case): round to nearest in f32, then widen by
        // 2^-22 relative plus the smallest normal f32. Rounding to nearest errs by at most 2^-24
        // relative (the f64 origin's own ulp is far below that), and widening `f` by `|f| 2^-22`
        // moves it at least `3 * 2^-24 |f|` after its own rounding, so `o_lo <= o <= o_hi` and
        // `inv_near <= 1/|d| <= inv_far`; zero and subnormal values are covered by `MIN_POSITIVE`.
        // Reciprocals below the normal f32 range take the exact directed roundings below.
        let (o_lo, o_hi, inv_lo, inv_hi) = if inv.cmpge(DVec3::splat(FAST_INV_MIN)).all() {
            let o = origin.as_vec3a();
            let o_margin = o.abs() * FAST_REL + Vec3A::splat(f32::MIN_POSITIVE);
            // `1/|d|` beyond f32 (a zero or tiny component) rounds to infinity: the lower bound
            // takes the largest finite f32 instead (any finite value is below the truth), the
            // upper bound stays infinite.
            let g = inv.as_vec3a();
            let g_low = g.min(Vec3A::splat(f32::MAX));
            (o - o_margin, o + o_margin, g_low - g_low * FAST_REL, g + g * FAST_REL)
        } else {
            let o = origin.to_array();
            let i = inv.to_array();
            (
                Vec3A::from(o.map(|x| f32_down(x.next_down()))),
                Vec3A::from(o.map(|x| f32_up(x.next_up()))),
                Vec3A::from(i.map(f32_down)),
                Vec3A::from(i.map(f32_up)),
            )
        };
        let signs = Vec3A::select(negative, Vec3A::NEG_ONE, Vec3A::ONE);
        let inv_near = inv_lo * signs;
        let inv_far = inv_hi * signs;
        let mut s = Self {
            negative,
            o_near: Vec3A::select(negative, o_lo, o_hi),
            o_far: Vec3A::select(negative, o_hi, o_lo),
            inv_near,
            inv_far,
            t_max: 0.0,
        };
        s.set_limit(t_max);
        Some(s)
    }

    /// The entry distance of one child box, if the ray may meet it within `t_max`.
    #[inline(always)]
    fn child(&self, min: Vec3A, max: Vec3A) -> Option<f32> {
        let near_plane = Vec3A::select(self.negative, max, min);
        let far_plane = Vec3A::select(self.negative, min, max);
        let near = (near_plane - self.o_near) * self.inv_near;
        let far = (far_plane - self.o_far) * self.inv_far;
        // NaN lanes (and negative entries) become 0; NaN exits become +inf: only wider.
        let near = Vec3A::select(near.cmpgt(Vec3A::ZERO), near, Vec3A::ZERO);
        let far = Vec3A::select(far.cmplt(Vec3A::INFINITY), far, Vec3A::INFINITY);
        let t0 = near.max_element();
        let t1 = far.min_element() * WIDEN + f32::MIN_POSITIVE;
        let t1 = if t1 < self.t_max { t1 } else { self.t_max };
        if t0 <= t1 { Some(t0) } else { None }
    }
}

impl Slab for SlabF32 {
    type T = f32;

    #[inline(always)]
    fn test(&self, node: &Node) -> [Option<f32>; 2] {
        [self.child(node.min(0), node.max(0)), self.child(node.min(1), node.max(1))]
    }

    #[inline]
    fn set_limit(&mut self, t_max: f64) {
        self.t_max = f32_up(t_max) * WIDEN + f32::MIN_POSITIVE;
    }

    #[inline(always)]
    fn alive(&self, near: f32) -> bool {
        near <= self.t_max
    }
}

/// pbrt's conservative slab test in f64 on exact f64 copies of the f32 boxes (the fallback for
/// huge coordinates).
struct SlabF64 {
    origin: DVec3,
    center: DVec3,
    inv: DVec3,
    t_max: f64,
}

impl SlabF64 {
    /// The per-ray setup.
    fn new(origin: DVec3, center: DVec3, direction: DVec3, t_max: f64) -> Self {
        Self { origin, center, inv: direction.recip(), t_max }
    }

    /// The entry distance of one child box (moved back to world coordinates, rounded outwards),
    /// if the ray may meet it within `t_max`.
    fn child(&self, min: Vec3A, max: Vec3A) -> Option<f64> {
        let (lo, hi) = (min.as_dvec3() + self.center, max.as_dvec3() + self.center);
        let b = Bounds {
            min: DVec3::new(lo.x.next_down(), lo.y.next_down(), lo.z.next_down()),
            max: DVec3::new(hi.x.next_up(), hi.y.next_up(), hi.z.next_up()),
        };
        b.ray_interval(self.origin, self.inv, self.t_max).map(|(t0, _)| t0)
    }
}

impl Slab for SlabF64 {
    type T = f64;

    fn test(&self, node: &Node) -> [Option<f64>; 2] {
        [self.child(node.min(0), node.max(0)), self.child(node.min(1), node.max(1))]
    }

    fn set_limit(&mut self, t_max: f64) {
        self.t_max = t_max;
    }

    fn alive(&self, near: f64) -> bool {
        near <= self.t_max
    }
}

/// The traversal stack of `(child, count, entry distance)`: a fixed array on the call stack,
/// spilling to the heap only for trees deeper than it (so a ray costs no allocation).
struct Stack<T> {
    inline: [(u32, u32, T); 32],
    len: usize,
    spill: Vec<(u32, u32, T)>,
}

impl<T: Copy + Default> Stack<T> {
    #[inline(always)]
    fn new() -> Self {
        Self { inline: [(0, 0, T::default()); 32], len: 0, spill: Vec::new() }
    }

    #[inline(always)]
    fn push(&mut self, entry: (u32, u32, T)) {
        if self.len < self.inline.len() {
            self.inline[self.len] = entry;
            self.len += 1;
        } else {
            self.spill.push(entry);
        }
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<(u32, u32, T)> {
        if let Some(entry) = self.spill.pop() {
            return Some(entry);
        }
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        Some(self.inline[self.len])
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn directed_f32_rounding_brackets_the_f64_value() {
        for x in [0.1, -0.1, 1e6 + 0.3, -1e6 - 0.3, 1e-40, 3.0, 1e39, -1e39, 0.0] {
            let (lo, hi) = (f32_down(x), f32_up(x));
            assert!(f64::from(lo) <= x && x <= f64::from(hi), "{x}: {lo} {hi}");
            assert!(hi == lo || hi == lo.next_up(), "{x}: {lo} {hi}");
        }
    }

    #[test]
    fn a_box_touched_only_by_origin_rounding_is_still_entered() {
        // A thin box just beside a ray far from the origin, closer than the f32 ulp there.
        let origin = DVec3::new(1e6 + 0.01, 5.0, 0.0);
        let x = (1e6_f32 + 0.0625) as f64; // the next f32 above 1e6
        assert!(x > origin.x);
        let node = Node::new(
            [Vec3A::new(1e6, 0.0, -1.0), Vec3A::INFINITY],
            [Vec3A::new(x as f32, 1.0, 1.0), Vec3A::NEG_INFINITY],
            [LEAF; 2],
            [1, 0],
        );
        let slab = SlabF32::new(origin, DVec3::new(0.0, -1.0, 0.0), f64::INFINITY).unwrap();
        let [a, b] = slab.test(&node);
        assert!(a.is_some_and(|t| t <= 4.0), "{a:?}");
        assert!(b.is_none());
    }
}
