//! [`World`]: all shapes in one BVH (built by `obvhs`), traversed in f32 with conservatively
//! rounded boxes (see `bvh.rs`); every primitive test runs in f64.

use std::path::Path;
use std::time::Duration;

use glam::{DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2;

use crate::bvh::{Bvh, Leaf};
use crate::leaves::{Leaves, Nearest};
use crate::{Bounds, GeometryError, Hit, Ray, Shape};

/// The build settings of the BVH: `obvhs`'s medium-quality PLOC build with leaves of at most
/// `MAX_PRIMS_PER_LEAF` primitives, and the reinsertion passes of its slow build (four times the
/// nodes reconsidered, from one level higher). On the geometry benchmark's 102,400 triangles
/// that tree answers 4-5% more closest-hit and shadow rays per second, for a build of 108 ms
/// instead of 65 ms (`ray_rate`, five alternating runs). The slow build's spatial pre-splits
/// are left out: they clip primitives' boxes inside `obvhs`, outside the outward rounding that
/// keeps every box here conservative (`conservative_aabb`).
fn build_params() -> BvhBuildParams {
    BvhBuildParams {
        max_prims_per_leaf: MAX_PRIMS_PER_LEAF,
        reinsertion_batch_ratio: 0.2,
        search_depth_threshold: 2,
        ..BvhBuildParams::medium_build()
    }
}

/// Worlds of at most this many primitives, none of them a torus, are not traversed: every
/// primitive is tested (the same tests, so the same hits). The wide tree's per-ray setup (the
/// SIMD slab's broadcasts) costs more than a plane or quadric test, and a light tracer's beams
/// over one plane would pay it for nothing; a torus's quartic is worth culling.
const DIRECT_PRIMITIVES: usize = 2;

/// The most primitives per BVH leaf (chosen by benchmark, see the crate README).
const MAX_PRIMS_PER_LEAF: u32 = 4;

/// Rounds an f64 box, relative to `center`, outwards to f32, with a small margin relative to its
/// world coordinates, so that it contains the f64 box and every point an f64 intersection routine
/// could report for it (the margin also covers the rounding of the shift by `center`).
fn conservative_aabb(b: Bounds, center: DVec3) -> Aabb {
    let scale = b.min.abs().max(b.max.abs()).max_element() + b.diagonal().max_element();
    let margin = DVec3::splat(1e-9 * scale);
    let (lo, hi) = (b.min - margin - center, b.max + margin - center);
    let down = |x: f64| (x as f32).next_down();
    let up = |x: f64| (x as f32).next_up();
    Aabb::new(
        Vec3A::new(down(lo.x), down(lo.y), down(lo.z)),
        Vec3A::new(up(hi.x), up(hi.y), up(hi.z)),
    )
}

/// The scene's geometry: shapes and one BVH over all their primitives.
///
/// The BVH is built by `obvhs` from f32 boxes that are rounded outwards from the exact f64 bounds
/// (so no hit is lost); traversal and every intersection run in f64.
#[derive(Clone)]
pub struct World {
    shapes: Vec<Shape>,
    /// The primitives of the BVH's leaves.
    pub(crate) leaves: Leaves,
    /// Test every leaf instead of traversing (see [`DIRECT_PRIMITIVES`]).
    direct: bool,
    bvh2: Bvh2,
    bvh: Bvh,
    bounds: Bounds,
}

impl std::fmt::Debug for World {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("World")
            .field("shapes", &self.shapes.len())
            .field("primitives", &self.leaves.slot_count())
            .field("bvh_nodes", &self.bvh.node_count())
            .field("bounds", &self.bounds)
            .finish()
    }
}
impl World {
    /// Builds the BVH over all primitives of `shapes` (every OBJ mesh must already be loaded).
    ///
    /// # Errors
    /// [`GeometryError::UnloadedMesh`] for an OBJ mesh not yet loaded;
    /// [`GeometryError::TooManyPrimitives`] beyond `u32` indices.
    pub fn new(shapes: Vec<Shape>) -> Result<Self, GeometryError> {
        let mut prims = Vec::new();
        for (i, s) in shapes.iter().enumerate() {
            if let Shape::Mesh(m) = s
                && !m.is_loaded()
            {
                let path = m.file_path().map(Path::to_path_buf).unwrap_or_default();
                return Err(GeometryError::UnloadedMesh { index: i, path });
            }
            let shape = u32::try_from(i)
                .map_err(|_| GeometryError::TooManyPrimitives { count: shapes.len() })?;
            let n = s.primitive_count();
            let n32 =
                u32::try_from(n).map_err(|_| GeometryError::TooManyPrimitives { count: n })?;
            prims.extend((0..n32).map(|index| (shape, index)));
        }
        if u32::try_from(prims.len()).is_err() {
            return Err(GeometryError::TooManyPrimitives { count: prims.len() });
        }
        // Slots address primitives by `LEAF | index` in the converted BVH.
        if prims.len() >= 1 << 31 {
            return Err(GeometryError::TooManyPrimitives { count: prims.len() });
        }
        let exact: Vec<Bounds> =
            prims.iter().map(|&(s, i)| shapes[s as usize].primitives().bounds(i)).collect();
        let bounds = exact.iter().fold(Bounds::EMPTY, |a, &b| a.union(b));
        // Boxes relative to the scene's centre keep f32 precision for scenes far from the origin.
        let center = if bounds.is_empty() || !bounds.center().is_finite() {
            DVec3::ZERO
        } else {
            bounds.center()
        };
        let aabbs: Vec<Aabb> = exact.into_iter().map(|b| conservative_aabb(b, center)).collect();
        let bvh2 = if aabbs.is_empty() {
            Bvh2::default()
        } else {
            build_bvh2(&aabbs, build_params(), &mut Duration::default())
        };
        // Leaves holding an analytic shape are split over free lanes; triangles stay together,
        // filtered four at a time by one SIMD test.
        let analytic = |slot: u32| {
            let (shape, _) = prims[bvh2.primitive_indices[slot as usize] as usize];
            shapes[shape as usize].triangle_mesh().is_none()
        };
        let split = |leaf: Leaf| (leaf.first..leaf.first + leaf.count).any(analytic);
        let (bvh, leaves) = Bvh::from_bvh2(&bvh2, center, &aabbs, split);
        let leaves = Leaves::new(&shapes, &prims, &bvh2.primitive_indices, &leaves);
        let direct = leaves.slot_count() <= DIRECT_PRIMITIVES
            && !shapes.iter().any(|s| matches!(s, Shape::Torus(_)));
        Ok(Self { shapes, leaves, direct, bvh2, bvh, bounds })
    }

    /// Loads every OBJ mesh relative to `base_dir` (the scene file's directory), then builds.
    ///
    /// # Errors
    /// [`GeometryError::Obj`] for an unreadable file, else as [`World::new`].
    pub fn with_base_dir(mut shapes: Vec<Shape>, base_dir: &Path) -> Result<Self, GeometryError> {
        for s in &mut shapes {
            s.load(base_dir)?;
        }
        Self::new(shapes)
    }

    /// The shapes, indexed by [`Hit::primitive`].
    pub fn shapes(&self) -> &[Shape] {
        &self.shapes
    }

    /// Number of BVH primitives (triangles count one each).
    pub fn primitive_count(&self) -> usize {
        self.leaves.slot_count()
    }

    /// The box around all shapes (empty for an empty world).
    pub fn bounds(&self) -> Bounds {
        self.bounds
    }

    /// The `obvhs` BVH (over the primitives numbered shape by shape, triangle by triangle) that
    /// the traversal structure was converted from: for comparisons such as the benchmark against
    /// `obvhs`'s own traversal.
    pub fn obvhs_bvh(&self) -> &Bvh2 {
        &self.bvh2
    }

    /// The nearest hit with `0 < t < t_max`, or `None`.
    ///
    /// A leaf's triangles are filtered four at a time by the first half of the watertight test
    /// in SIMD (with the ray's permutation and shear set up once), and the survivors run the
    /// whole scalar test; the full [`Hit`] of the winning triangle is built once, from the
    /// distance and barycentrics that test found: the same test on the same vertices as the
    /// mesh's own routine, so it is the hit a primitive-by-primitive search reports. An analytic shape
    /// that is closer than the best so far returns its full hit directly (rather than solving
    /// its quadratic or quartic a second time for the winner: scenes hold few of them).
    ///
    /// # Performance
    /// `O(log n)` box tests per ray on typical scenes, in f32 (conservative); primitives in f64.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let triangle_ray = self.leaves.triangle_ray(ray);
        let mut best = Nearest::None;
        let tr = triangle_ray.as_ref();
        if self.direct {
            let mut limit = t_max;
            for leaf in 0..self.leaves.leaf_count() as u32 {
                if let Some(t) = self.leaves.nearest(leaf, &self.shapes, ray, tr, limit, &mut best)
                {
                    limit = t;
                }
            }
        } else {
            self.bvh.traverse(ray.origin, ray.direction, t_max, |leaf, limit| {
                self.leaves.nearest(leaf, &self.shapes, ray, tr, limit, &mut best)
            });
        }
        self.leaves.hit(best, &self.shapes)
    }

    /// Whether anything lies on the ray with `0 < t < t_max` (shadow rays): stops at the first
    /// primitive hit and builds no [`Hit`].
    pub fn occluded(&self, ray: &Ray, t_max: f64) -> bool {
        let triangle_ray = self.leaves.triangle_ray(ray);
        let tr = triangle_ray.as_ref();
        if self.direct {
            return (0..self.leaves.leaf_count() as u32)
                .any(|leaf| self.leaves.any(leaf, &self.shapes, ray, tr, t_max));
        }
        let mut hit = false;
        self.bvh.traverse(ray.origin, ray.direction, t_max, |leaf, limit| {
            hit = self.leaves.any(leaf, &self.shapes, ray, tr, limit);
            hit.then_some(-1.0)
        });
        hit
    }

    /// The nearest hit by testing every primitive (no BVH), each through the shape's full
    /// intersection routine: a reference for tests and benchmarks.
    pub fn intersect_brute_force(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for (shape, s) in self.shapes.iter().enumerate() {
            let p = s.primitives();
            for index in 0..p.count() as u32 {
                let limit = best.map_or(t_max, |h| h.t);
                if let Some(mut h) = p.intersect(index, ray, limit) {
                    h.primitive = shape as u32;
                    best = Some(h);
                }
            }
        }
        best
    }
}
