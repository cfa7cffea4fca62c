//! The BVH the world traverses: `obvhs`'s `Bvh2` collapsed into a wide tree whose nodes hold the
//! f32 boxes of up to eight children side by side, so that one node test checks all eight boxes
//! at once in SIMD lanes (`wide::f32x8`), with the same conservative slab test in every lane; the
//! children a ray meets are visited nearest first.
//!
//! # The wide tree
//!
//! Each wide node stands for one `Bvh2` subtree cut at up to eight children: starting from the
//! subtree's root, the inner child of largest surface area is replaced by its two children until
//! there are eight or only leaves remain (the greedy collapse of Embree's BVH8 and of the CWBVH
//! literature; it keeps `obvhs`'s SAH-optimised splits and leaves). Boxes are stored as structure
//! of arrays (six rows of eight f32: the lower x, y, z and upper x, y, z of every child), so the
//! per-ray choice of entry and exit planes (by the sign of the direction) is a choice of rows,
//! not a per-node shuffle. Unused lanes hold an empty box (`+inf` lower, `-inf` upper), which no
//! ray enters.
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

use arrayvec::ArrayVec;
use glam::{BVec3A, DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use wide::{CmpGt, CmpLe, CmpLt, f32x8};

use crate::Bounds;

/// Marks a child reference as a leaf (the low bits are then its leaf index).
const LEAF: u32 = 1 << 31;

/// Children per wide node (the SIMD width of the node test).
pub(crate) const WIDTH: usize = 8;

/// The largest coordinate (box or ray origin, absolute) the f32 slab test handles; beyond it the
/// traversal runs in f64. Differences of two such values cannot overflow f32.
pub(crate) const F32_SAFE: f32 = 1e30;

/// The f32 unit roundoff's `gamma(3)`.
const GAMMA3_F32: f32 = 3.0 * (f32::EPSILON * 0.5) / (1.0 - 3.0 * (f32::EPSILON * 0.5));

/// The factor applied to exits and `t_max` in the f32 test.
const WIDEN: f32 = 1.0 + 4.0 * GAMMA3_F32;

/// One wide node: the boxes of up to [`WIDTH`] children as six SIMD rows (lower x, y, z, then
/// upper x, y, z) and each child's reference (an inner node index, or `LEAF | leaf index`; an
/// unused lane refers to no leaf, its box being empty).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct Node {
    planes: [f32x8; 6],
    child: [u32; WIDTH],
}

impl Node {
    /// A node whose lanes are all empty (empty boxes, empty leaves).
    fn empty() -> Self {
        let lo = f32x8::splat(f32::INFINITY);
        let hi = f32x8::splat(f32::NEG_INFINITY);
        Self { planes: [lo, lo, lo, hi, hi, hi], child: [LEAF; WIDTH] }
    }

    /// Sets lane `lane` to a child with box `[min, max]`.
    fn set(&mut self, lane: usize, min: Vec3A, max: Vec3A, child: u32) {
        for (axis, (lo, hi)) in min.to_array().into_iter().zip(max.to_array()).enumerate() {
            self.planes[axis].as_array_mut()[lane] = lo;
            self.planes[axis + 3].as_array_mut()[lane] = hi;
        }
        self.child[lane] = child;
    }

    /// Child `lane`'s box.
    fn bounds(&self, lane: usize) -> (Vec3A, Vec3A) {
        let row = |r: usize| self.planes[r].as_array_ref()[lane];
        (Vec3A::new(row(0), row(1), row(2)), Vec3A::new(row(3), row(4), row(5)))
    }
}

/// The `obvhs` nodes that become the children of one wide node: starting from `root`, the inner
/// node of largest surface area is replaced by its two children until there are [`WIDTH`] or
/// only leaves.
fn collapse(bvh: &Bvh2, root: usize) -> Vec<usize> {
    let mut children = vec![root];
    while children.len() < WIDTH {
        let area = |&&i: &&usize| bvh.nodes[i].aabb().half_area();
        let widest = children
            .iter()
            .filter(|&&i| !bvh.nodes[i].is_leaf())
            .max_by(|a, b| area(a).total_cmp(&area(b)));
        let Some(&i) = widest else { break };
        let first = bvh.nodes[i].first_index as usize;
        children.retain(|&c| c != i);
        children.extend([first, first + 1]);
    }
    children
}

/// One leaf of the tree: a run of primitive slots (`obvhs`'s `primitive_indices` positions).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Leaf {
    /// The first slot.
    pub(crate) first: u32,
    /// The number of slots.
    pub(crate) count: u32,
}

/// The wide BVH. Node 0 is the root (a root that is a leaf becomes a node with one child).
#[derive(Debug, Clone, Default)]
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    /// The point the f32 boxes are relative to (world coordinates = box + `center`).
    center: DVec3,
    /// Some box coordinate is beyond [`F32_SAFE`]: always traverse in f64.
    wide: bool,
}

impl Bvh {
    /// Collapses `bvh`, whose boxes are relative to `center` (its primitive slots are
    /// `bvh.primitive_indices`' positions, `boxes` its primitives' boxes by primitive index),
    /// into wide nodes; and its leaves, numbered as the traversal reports them.
    ///
    /// A node's lanes left free by the collapse are not wasted: a leaf for which `split` says
    /// so is split into one leaf per primitive, each with its own box, as long as lanes remain
    /// (the box test of eight lanes costs the same as of one, and a primitive test saved is
    /// worth far more: analytic shapes in a Cornell box otherwise share leaves whose boxes span
    /// the room).
    pub(crate) fn from_bvh2(
        bvh: &Bvh2,
        center: DVec3,
        boxes: &[Aabb],
        split: impl Fn(Leaf) -> bool,
    ) -> (Self, Vec<Leaf>) {
        let mut leaves = Vec::new();
        if bvh.nodes.is_empty() {
            return (Self::default(), leaves);
        }
        let mut nodes = vec![Node::empty()];
        let mut work: Vec<(usize, usize)> = vec![(0, 0)];
        let mut wide = false;
        let too_big = |v: Vec3A| !(v.abs().max_element() <= F32_SAFE);
        while let Some((root, k)) = work.pop() {
            let children = collapse(bvh, root);
            let mut free = WIDTH - children.len();
            let mut lane = 0;
            for i in children {
                let n = &bvh.nodes[i];
                let a = n.aabb();
                wide |= too_big(a.min) || too_big(a.max);
                if n.is_leaf() {
                    let leaf = Leaf { first: n.first_index, count: n.prim_count };
                    let parts = n.prim_count as usize;
                    let singles = if parts > 1 && parts - 1 <= free && split(leaf) {
                        free -= parts - 1;
                        (leaf.first..leaf.first + leaf.count)
                            .map(|s| Leaf { first: s, count: 1 })
                            .collect()
                    } else {
                        vec![leaf]
                    };
                    for part in singles {
                        let b = if part.count == 1 && leaf.count > 1 {
                            boxes[bvh.primitive_indices[part.first as usize] as usize]
                        } else {
                            *a
                        };
                        // Fewer leaves than primitives (< 2^31, checked by `World::new`).
                        let id = leaves.len() as u32;
                        leaves.push(part);
                        nodes[k].set(lane, b.min, b.max, LEAF | id);
                        lane += 1;
                    }
                } else {
                    let index = nodes.len();
                    nodes.push(Node::empty());
                    work.push((i, index));
                    nodes[k].set(lane, a.min, a.max, index as u32);
                    lane += 1;
                }
            }
        }
        (Self { nodes, center, wide }, leaves)
    }

    /// Number of wide nodes.
    pub(crate) fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Calls `on_leaf(leaf, t_max)` for every leaf whose box the ray may meet within the current
    /// `t_max`, nearest boxes first. `on_leaf` returns `None` (no closer hit), the new `t_max`
    /// (a closer hit), or a negative value to stop.
    #[inline]
    pub(crate) fn traverse(
        &self,
        origin: DVec3,
        direction: DVec3,
        t_max: f64,
        on_leaf: impl FnMut(u32, f64) -> Option<f64>,
    ) {
        if self.nodes.is_empty() || !(t_max > 0.0) {
            return;
        }
        if !self.wide
            && let Some(mut slab) = SlabF32::new(origin - self.center, direction, t_max)
        {
            return self.walk(&mut slab, t_max, on_leaf);
        }
        let mut slab = SlabF64::new(origin, self.center, direction, t_max);
        self.walk(&mut slab, t_max, on_leaf);
    }

    /// The traversal loop, generic over the box test. The nearest child a node's test accepts
    /// is visited next without going through the stack (tested at once if it is a node, its
    /// primitives run at once if it is a leaf); the others are pushed farthest first, so the
    /// nearest of them is popped next.
    #[inline]
    fn walk<S: Slab>(
        &self,
        slab: &mut S,
        mut t_max: f64,
        mut on_leaf: impl FnMut(u32, f64) -> Option<f64>,
    ) {
        let mut stack = Stack::<S::T>::new();
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            let (mask, near) = slab.test(n);
            let next = if mask == 0 {
                None
            } else if mask & (mask - 1) == 0 {
                Some(n.child[mask.trailing_zeros() as usize])
            } else if (mask & (mask - 1)).count_ones() == 1 {
                // Two children met (a quarter of all nodes): the farther is pushed by a select,
                // not a sort loop (ties keep the sort's order: the higher lane is visited first).
                let (i, j) = (mask.trailing_zeros() as usize, (31 - mask.leading_zeros()) as usize);
                let (a, b) = ((n.child[i], near[i]), (n.child[j], near[j]));
                let (far, nearest) = if a.1 < b.1 { (b, a) } else { (a, b) };
                stack.push(far);
                Some(nearest.0)
            } else {
                let mut hits = [(0, S::T::default()); WIDTH];
                let mut len = 0;
                let mut bits = mask;
                while bits != 0 {
                    let lane = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    hits[len] = (n.child[lane], near[lane]);
                    len += 1;
                }
                sort_farthest_first(&mut hits[..len]);
                stack.push_all(&hits[..len - 1]);
                Some(hits[len - 1].0)
            };
            if let Some(child) = next {
                if child & LEAF == 0 {
                    node = child as usize;
                    continue;
                }
                if lowered(on_leaf(child & !LEAF, t_max), &mut t_max, slab) {
                    return;
                }
            }
            loop {
                let Some((child, near)) = stack.pop() else { return };
                if !slab.alive(near) {
                    continue;
                }
                if child & LEAF == 0 {
                    node = child as usize;
                    break;
                }
                if lowered(on_leaf(child & !LEAF, t_max), &mut t_max, slab) {
                    return;
                }
            }
        }
    }
}

/// Applies what a leaf's test returned (see [`Bvh::traverse`]): a closer hit lowers `t_max` and
/// the box test's limit; `true` when the walk must stop.
#[inline(always)]
fn lowered<S: Slab>(found: Option<f64>, t_max: &mut f64, slab: &mut S) -> bool {
    match found {
        Some(t) if t < 0.0 => true,
        Some(t) => {
            *t_max = t;
            slab.set_limit(t);
            false
        }
        None => false,
    }
}

/// Sorts `entries` (at most [`WIDTH`]) by entry distance, farthest first (insertion sort: most
/// nodes have two or three children met).
#[inline(always)]
fn sort_farthest_first<T: PartialOrd>(entries: &mut [(u32, T)]) {
    for i in 1..entries.len() {
        let mut j = i;
        while j > 0 && entries[j - 1].1 < entries[j].1 {
            entries.swap(j - 1, j);
            j -= 1;
        }
    }
}

/// A ray/box test for all children of a wide node.
trait Slab {
    /// The entry distance type (for ordering and culling).
    type T: Copy + PartialOrd + Default;
    /// The lanes (bit `i` for child `i`) the ray may meet within the current limit, and every
    /// lane's entry distance.
    fn test(&self, node: &Node) -> (u32, [Self::T; WIDTH]);
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

/// `x > 0` (not NaN) rounded to f32 upwards, without a branch: the nearest f32, or the next
/// one up if that is below `x` (one more in the bits of a non-negative float; infinity stays
/// infinity, being above every f64).
#[inline(always)]
fn positive_f32_up(x: f64) -> f32 {
    let f = x as f32;
    f32::from_bits(f.to_bits() + u32::from(f64::from(f) < x))
}

/// `x` rounded to f32 upwards (so the result is `>= x`; NaN stays NaN).
fn f32_up(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

/// The conservative f32 slab test (see the module documentation), on all lanes of a node.
struct SlabF32 {
    /// Per axis: the row of the entry plane (lower for a positive direction, upper for a
    /// negative one: the sign bit decides, so `-0` counts as negative).
    near_row: [usize; 3],
    /// Per axis: the row of the exit plane.
    far_row: [usize; 3],
    /// The origin bound used for entries (`o_hi` for positive axes, `o_lo` for negative).
    o_near: [f32x8; 3],
    /// The origin bound used for exits.
    o_far: [f32x8; 3],
    /// `1/D` rounded towards zero in magnitude.
    inv_near: [f32x8; 3],
    /// `1/D` rounded away from zero in magnitude.
    inv_far: [f32x8; 3],
    /// `t_max` rounded up, widened, plus `MIN_POSITIVE`.
    t_max: f32x8,
}

impl SlabF32 {
    /// The per-ray setup from the origin relative to the boxes' centre, rounded once in f64 (so
    /// the exact value lies within one f64 ulp of it); `None` when it is beyond [`F32_SAFE`] or
    /// not finite.
    #[inline(always)]
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
        let lanes = |v: Vec3A| v.to_array().map(f32x8::splat);
        let neg = d.map(|x| usize::from(x.is_sign_negative()));
        let mut s = Self {
            near_row: [0, 1, 2].map(|a| a + 3 * neg[a]),
            far_row: [0, 1, 2].map(|a| a + 3 * (1 - neg[a])),
            o_near: lanes(Vec3A::select(negative, o_lo, o_hi)),
            o_far: lanes(Vec3A::select(negative, o_hi, o_lo)),
            inv_near: lanes(inv_lo * signs),
            inv_far: lanes(inv_hi * signs),
            t_max: f32x8::ZERO,
        };
        s.set_limit(t_max);
        Some(s)
    }
}

impl Slab for SlabF32 {
    type T = f32;

    /// Per lane: entry `max(0, entries)` and exit `min(exits) * WIDEN + MIN_POSITIVE`, capped by
    /// `t_max`; NaN entries count as 0 and NaN exits as `+inf` (only wider).
    #[inline(always)]
    fn test(&self, node: &Node) -> (u32, [f32; WIDTH]) {
        let mut t0 = f32x8::ZERO;
        let mut t1 = f32x8::splat(f32::INFINITY);
        for a in 0..3 {
            let near = (node.planes[self.near_row[a]] - self.o_near[a]) * self.inv_near[a];
            let far = (node.planes[self.far_row[a]] - self.o_far[a]) * self.inv_far[a];
            t0 = max_keeping(near, t0);
            t1 = min_keeping(far, t1);
        }
        let t1 = t1 * f32x8::splat(WIDEN) + f32x8::splat(f32::MIN_POSITIVE);
        // One `minps`: neither side is ever NaN (`t1` starts at +inf and takes no NaN exit).
        let t1 = min_keeping(t1, self.t_max);
        (t0.cmp_le(t1).move_mask() as u32, t0.to_array())
    }

    #[inline]
    fn set_limit(&mut self, t_max: f64) {
        self.t_max = f32x8::splat(positive_f32_up(t_max) * WIDEN + f32::MIN_POSITIVE);
    }

    #[inline(always)]
    fn alive(&self, near: f32) -> bool {
        near <= self.t_max.as_array_ref()[0]
    }
}

/// Lane-wise `max(x, keep)`, taking `keep` where `x` is NaN (`keep` is never NaN). On x86 this
/// is one `maxps`, whose result is its second operand when either is NaN (Intel SDM, MAXPS).
#[inline(always)]
fn max_keeping(x: f32x8, keep: f32x8) -> f32x8 {
    if cfg!(any(target_arch = "x86", target_arch = "x86_64")) {
        x.fast_max(keep)
    } else {
        x.cmp_gt(keep).blend(x, keep)
    }
}

/// Lane-wise `min(x, keep)`, taking `keep` where `x` is NaN (`keep` is never NaN): one `minps`
/// on x86, as [`max_keeping`].
#[inline(always)]
fn min_keeping(x: f32x8, keep: f32x8) -> f32x8 {
    if cfg!(any(target_arch = "x86", target_arch = "x86_64")) {
        x.fast_min(keep)
    } else {
        x.cmp_lt(keep).blend(x, keep)
    }
}

/// pbrt's conservative slab test in f64 on exact f64 copies of the f32 boxes (the fallback for
/// huge coordinates), one lane at a time.
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
    /// if the ray may meet it within `t_max`; `None` for an empty lane.
    fn child(&self, min: Vec3A, max: Vec3A) -> Option<f64> {
        if !min.cmple(max).all() {
            return None;
        }
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

    fn test(&self, node: &Node) -> (u32, [f64; WIDTH]) {
        let mut mask = 0;
        let mut near = [0.0; WIDTH];
        for (lane, t) in near.iter_mut().enumerate() {
            let (min, max) = node.bounds(lane);
            if let Some(t0) = self.child(min, max) {
                *t = t0;
                mask |= 1 << lane;
            }
        }
        (mask, near)
    }

    fn set_limit(&mut self, t_max: f64) {
        self.t_max = t_max;
    }

    fn alive(&self, near: f64) -> bool {
        near <= self.t_max
    }
}

/// Entries the traversal stack holds on the call stack; deeper trees spill to the heap.
const STACK: usize = 64;

/// The traversal stack of `(child, entry distance)`: a fixed array on the call stack (not
/// zeroed per ray), spilling to the heap only for trees deeper than it (so a ray costs no
/// allocation).
struct Stack<T> {
    inline: ArrayVec<(u32, T), STACK>,
    spill: Vec<(u32, T)>,
}

impl<T: Copy + Default + PartialOrd> Stack<T> {
    #[inline(always)]
    fn new() -> Self {
        Self { inline: ArrayVec::new(), spill: Vec::new() }
    }

    #[inline(always)]
    fn push(&mut self, entry: (u32, T)) {
        if let Err(full) = self.inline.try_push(entry) {
            self.spill.push(full.element());
        }
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<(u32, T)> {
        self.spill.pop().or_else(|| self.inline.pop())
    }

    /// Pushes `entries` in order (the last on top).
    #[inline(always)]
    fn push_all(&mut self, entries: &[(u32, T)]) {
        for &e in entries {
            self.push(e);
        }
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
        for x in [0.1, 1e6 + 0.3, 1e-40, 1e-50, 3.0, 1e39, f64::MAX, f64::INFINITY, 0.5] {
            assert_eq!(positive_f32_up(x).to_bits(), f32_up(x).to_bits(), "{x}");
        }
    }

    #[test]
    fn a_box_touched_only_by_origin_rounding_is_still_entered() {
        // A thin box just beside a ray far from the origin, closer than the f32 ulp there.
        let origin = DVec3::new(1e6 + 0.01, 5.0, 0.0);
        let x = (1e6_f32 + 0.0625) as f64; // the next f32 above 1e6
        assert!(x > origin.x);
        let mut node = Node::empty();
        node.set(3, Vec3A::new(1e6, 0.0, -1.0), Vec3A::new(x as f32, 1.0, 1.0), LEAF);
        let slab = SlabF32::new(origin, DVec3::new(0.0, -1.0, 0.0), f64::INFINITY).unwrap();
        let (mask, near) = slab.test(&node);
        assert_eq!(mask, 1 << 3, "only the box's lane is entered");
        assert!(near[3] <= 4.0, "{near:?}");
    }

    #[test]
    fn free_lanes_take_the_primitives_of_leaves_that_may_be_split() {
        use obvhs::BvhBuildParams;
        use obvhs::bvh2::builder::build_bvh2;
        // Six boxes along x; leaves of up to four primitives.
        let boxes: Vec<Aabb> = (0..6)
            .map(|i| {
                let x = i as f32 * 2.0;
                Aabb::new(Vec3A::new(x, 0.0, 0.0), Vec3A::new(x + 1.0, 1.0, 1.0))
            })
            .collect();
        let params = BvhBuildParams { max_prims_per_leaf: 4, ..BvhBuildParams::medium_build() };
        let bvh2 = build_bvh2(&boxes, params, &mut std::time::Duration::default());
        let kept = Bvh::from_bvh2(&bvh2, DVec3::ZERO, &boxes, |_| false).1;
        assert!(kept.len() < 6, "the build groups primitives: {kept:?}");
        assert_eq!(kept.iter().map(|l| l.count).sum::<u32>(), 6);
        let (bvh, split) = Bvh::from_bvh2(&bvh2, DVec3::ZERO, &boxes, |_| true);
        assert_eq!(split.len(), 6, "{split:?}");
        assert!(split.iter().all(|l| l.count == 1));
        // Each single-primitive lane carries that primitive's own box.
        let root = &bvh.nodes[0];
        for lane in 0..WIDTH {
            let child = root.child[lane];
            let (min, max) = root.bounds(lane);
            if child & LEAF != 0 && min.cmple(max).all() {
                let leaf = split[(child & !LEAF) as usize];
                let b = boxes[bvh2.primitive_indices[leaf.first as usize] as usize];
                assert_eq!((min, max), (b.min, b.max));
            }
        }
    }

    #[test]
    fn empty_lanes_are_never_entered_by_either_test() {
        let node = Node::empty();
        for d in [DVec3::X, -DVec3::X, DVec3::new(0.0, -0.0, 1.0), DVec3::new(1e-300, 1.0, -1.0)] {
            let slab = SlabF32::new(DVec3::ZERO, d, f64::INFINITY).unwrap();
            assert_eq!(slab.test(&node).0, 0, "{d}");
            let slab = SlabF64::new(DVec3::ZERO, DVec3::ZERO, d, f64::INFINITY);
            assert_eq!(slab.test(&node).0, 0, "{d}");
        }
    }
}
