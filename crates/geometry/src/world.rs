//! [`World`]: all shapes in one BVH (built by `obvhs`), traversed in f32 with conservatively
//! rounded boxes (see `bvh.rs`); every primitive test runs in f64.

use std::path::Path;
use std::time::Duration;

use glam::{DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2;

use crate::bvh::Bvh;
use crate::mesh::TriangleRay;
use crate::{Bounds, GeometryError, Hit, Ray, Shape};

/// The nearest candidate so far in [`World::intersect`].
enum Best {
    /// None yet.
    None,
    /// A triangle slot with the distance and barycentrics its test found (its hit is built at
    /// the end).
    Triangle(u32, f64, [f64; 3]),
    /// An analytic shape's full hit.
    Hit(Hit),
}

/// What a BVH primitive slot holds, so the per-candidate test is an enum match.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SlotKind {
    /// A mesh triangle: the watertight test on the slot's copied vertices.
    Triangle,
    /// A triangle that no ray hits (its normal has zero length, which `Mesh` refuses).
    Never,
    /// A whole analytic shape: its `t`-only routine.
    Analytic,
}

/// One BVH primitive slot (in BVH leaf order): a whole analytic shape or one mesh triangle, with
/// the triangle's world-space vertices copied in (zeros otherwise), so a leaf's primitives are
/// contiguous and a candidate costs no further lookup.
#[derive(Debug, Clone, Copy)]
struct Slot {
    vertices: [[f64; 3]; 3],
    shape: u32,
    index: u32,
    kind: SlotKind,
}

/// The build settings of the BVH: `obvhs`'s medium-quality PLOC build with leaves of at most
/// `MAX_PRIMS_PER_LEAF` primitives.
fn build_params() -> BvhBuildParams {
    BvhBuildParams { max_prims_per_leaf: MAX_PRIMS_PER_LEAF, ..BvhBuildParams::medium_build() }
}

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
    /// Primitive slots in BVH leaf order.
    slots: Vec<Slot>,
    /// Some slot is a triangle (else the per-ray triangle setup is skipped).
    has_triangles: bool,
    bvh2: Bvh2,
    bvh: Bvh,
    bounds: Bounds,
}

impl std::fmt::Debug for World {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("World")
            .field("shapes", &self.shapes.len())
            .field("primitives", &self.slots.len())
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
                let path = m.obj_path().map(Path::to_path_buf).unwrap_or_default();
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
        let bvh = Bvh::from_bvh2(&bvh2, center);
        let mut slots = Vec::with_capacity(prims.len());
        for &p in &bvh2.primitive_indices {
            let (shape, index) = prims[p as usize];
            let (kind, vertices) = match shapes[shape as usize].triangle_mesh() {
                Some(mesh) => match mesh.triangle(index) {
                    Some((v, true)) => (SlotKind::Triangle, v),
                    _ => (SlotKind::Never, [[0.0; 3]; 3]),
                },
                None => (SlotKind::Analytic, [[0.0; 3]; 3]),
            };
            slots.push(Slot { vertices, shape, index, kind });
        }
        let has_triangles = slots.iter().any(|s| s.kind == SlotKind::Triangle);
        Ok(Self { shapes, slots, has_triangles, bvh2, bvh, bounds })
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
        self.slots.len()
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

    /// The `t` of the slot's primitive in `(0, t_max)`, without building a [`Hit`].
    #[inline(always)]
    fn slot_t(
        &self,
        slot: u32,
        ray: &Ray,
        triangle_ray: &Option<TriangleRay>,
        t_max: f64,
    ) -> Option<f64> {
        let s = &self.slots[slot as usize];
        match s.kind {
            SlotKind::Triangle => {
                triangle_ray.as_ref()?.intersect(&s.vertices, t_max).map(|(t, _)| t)
            }
            SlotKind::Analytic => self.shapes[s.shape as usize].hit_t(s.index, ray, t_max),
            SlotKind::Never => None,
        }
    }

    /// The full hit of a triangle slot at the distance and barycentrics its test found, with
    /// the world's indices filled in.
    fn triangle_hit(&self, slot: u32, t: f64, b: [f64; 3]) -> Option<Hit> {
        let s = self.slots[slot as usize];
        let p = s.vertices.map(DVec3::from_array);
        let mut hit = self.shapes[s.shape as usize].triangle_mesh()?.hit_at(s.index, p, t, b)?;
        hit.primitive = s.shape;
        Some(hit)
    }

    /// The nearest hit with `0 < t < t_max`, or `None`.
    ///
    /// Triangle candidates run only the watertight test (with the ray's permutation and shear set
    /// up once); the full [`Hit`] of the winning triangle is built once, from the distance and
    /// barycentrics that test found: the same test on the same vertices as the mesh's own
    /// routine, so it is the hit a primitive-by-primitive search reports. An analytic shape
    /// that is closer than the best so far returns its full hit directly (rather than solving
    /// its quadratic or quartic a second time for the winner: scenes hold few of them).
    ///
    /// # Performance
    /// `O(log n)` box tests per ray on typical scenes, in f32 (conservative); primitives in f64.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let triangle_ray = self.has_triangles.then(|| TriangleRay::new(ray));
        let mut best = Best::None;
        self.bvh.traverse(ray.origin, ray.direction, t_max, |slot, limit| {
            let s = &self.slots[slot as usize];
            match s.kind {
                SlotKind::Triangle => {
                    let (t, b) = triangle_ray.as_ref()?.intersect(&s.vertices, limit)?;
                    best = Best::Triangle(slot, t, b);
                    Some(t)
                }
                SlotKind::Analytic => {
                    let shape = &self.shapes[s.shape as usize];
                    let mut hit = shape.primitives().intersect(s.index, ray, limit)?;
                    hit.primitive = s.shape;
                    best = Best::Hit(hit);
                    Some(hit.t)
                }
                SlotKind::Never => None,
            }
        });
        match best {
            Best::None => None,
            Best::Hit(hit) => Some(hit),
            Best::Triangle(slot, t, b) => self.triangle_hit(slot, t, b),
        }
    }

    /// Whether anything lies on the ray with `0 < t < t_max` (shadow rays): stops at the first
    /// primitive hit and builds no [`Hit`].
    pub fn occluded(&self, ray: &Ray, t_max: f64) -> bool {
        let triangle_ray = self.has_triangles.then(|| TriangleRay::new(ray));
        let mut hit = false;
        self.bvh.traverse(ray.origin, ray.direction, t_max, |slot, limit| {
            self.slot_t(slot, ray, &triangle_ray, limit)?;
            hit = true;
            Some(-1.0)
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
