//! [`World`]: all shapes in one BVH (built by `obvhs`), traversed in f64.

use std::path::Path;
use std::time::Duration;

use glam::{DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2;

use crate::{Bounds, GeometryError, Hit, Ray, Shape};

/// One BVH primitive: a whole analytic shape or one triangle of a mesh.
#[derive(Debug, Clone, Copy)]
struct PrimRef {
    shape: u32,
    index: u32,
}

/// Rounds an f64 box outwards to f32, with a small relative margin, so that it contains the f64
/// box and every point an f64 intersection routine could report for it.
fn conservative_aabb(b: Bounds) -> Aabb {
    let scale = b.min.abs().max(b.max.abs()).max_element() + b.diagonal().max_element();
    let margin = DVec3::splat(1e-9 * scale);
    let (lo, hi) = (b.min - margin, b.max + margin);
    let down = |x: f64| (x as f32).next_down();
    let up = |x: f64| (x as f32).next_up();
    Aabb::new(
        Vec3A::new(down(lo.x), down(lo.y), down(lo.z)),
        Vec3A::new(up(hi.x), up(hi.y), up(hi.z)),
    )
}

/// The f64 copy of an obvhs node's f32 box (exact conversion).
fn node_bounds(a: &Aabb) -> Bounds {
    Bounds { min: a.min.as_dvec3(), max: a.max.as_dvec3() }
}

/// The scene's geometry: shapes and one BVH over all their primitives.
///
/// The BVH is built by `obvhs` from f32 boxes that are rounded outwards from the exact f64 bounds
/// (so no hit is lost); traversal and every intersection run in f64.
#[derive(Clone)]
pub struct World {
    shapes: Vec<Shape>,
    prims: Vec<PrimRef>,
    bvh: Bvh2,
    boxes: Vec<Bounds>,
    bounds: Bounds,
}

impl std::fmt::Debug for World {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("World")
            .field("shapes", &self.shapes.len())
            .field("primitives", &self.prims.len())
            .field("bvh_nodes", &self.bvh.nodes.len())
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
            prims.extend((0..n32).map(|index| PrimRef { shape, index }));
        }
        if u32::try_from(prims.len()).is_err() {
            return Err(GeometryError::TooManyPrimitives { count: prims.len() });
        }
        let exact: Vec<Bounds> =
            prims.iter().map(|p| shapes[p.shape as usize].primitives().bounds(p.index)).collect();
        let bounds = exact.iter().fold(Bounds::EMPTY, |a, &b| a.union(b));
        let aabbs: Vec<Aabb> = exact.into_iter().map(conservative_aabb).collect();
        let bvh = if aabbs.is_empty() {
            Bvh2::default()
        } else {
            build_bvh2(&aabbs, BvhBuildParams::medium_build(), &mut Duration::default())
        };
        let boxes = bvh.nodes.iter().map(|n| node_bounds(n.aabb())).collect();
        Ok(Self { shapes, prims, bvh, boxes, bounds })
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
        self.prims.len()
    }

    /// The box around all shapes (empty for an empty world).
    pub fn bounds(&self) -> Bounds {
        self.bounds
    }

    /// Exact intersection of one primitive, with the world's indices filled in.
    fn intersect_primitive(&self, prim: u32, ray: &Ray, t_max: f64) -> Option<Hit> {
        let p = self.prims[prim as usize];
        let mut hit = self.shapes[p.shape as usize].primitives().intersect(p.index, ray, t_max)?;
        hit.primitive = p.shape;
        Some(hit)
    }

    /// Traverses the BVH; `on_leaf` tests one primitive with the current `t_max` and returns
    /// whether to stop.
    fn traverse(&self, ray: &Ray, t_max: f64, mut on_prim: impl FnMut(u32, f64) -> Option<f64>) {
        if self.boxes.is_empty() || !(t_max > 0.0) {
            return;
        }
        let inv = ray.direction.recip();
        let mut t_max = t_max;
        let mut stack = NodeStack::new();
        stack.push(0);
        while let Some(i) = stack.pop() {
            let node = &self.bvh.nodes[i as usize];
            if self.boxes[i as usize].ray_interval(ray.origin, inv, t_max).is_none() {
                continue;
            }
            if node.is_leaf() {
                for k in node.first_index..node.first_index + node.prim_count {
                    match on_prim(self.bvh.primitive_indices[k as usize], t_max) {
                        Some(t) if t < 0.0 => return,
                        Some(t) => t_max = t,
                        None => {}
                    }
                }
            } else {
                let (l, r) = (node.first_index, node.first_index + 1);
                let tl = self.boxes[l as usize].ray_interval(ray.origin, inv, t_max);
                let tr = self.boxes[r as usize].ray_interval(ray.origin, inv, t_max);
                match (tl, tr) {
                    (Some(a), Some(b)) => {
                        if a.0 <= b.0 {
                            stack.push(r);
                            stack.push(l);
                        } else {
                            stack.push(l);
                            stack.push(r);
                        }
                    }
                    (Some(_), None) => stack.push(l),
                    (None, Some(_)) => stack.push(r),
                    (None, None) => {}
                }
            }
        }
    }

    /// The nearest hit with `0 < t < t_max`, or `None`.
    ///
    /// # Performance
    /// `O(log n)` box tests per ray on typical scenes; all arithmetic in f64.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        self.traverse(ray, t_max, |prim, limit| {
            let h = self.intersect_primitive(prim, ray, limit)?;
            best = Some(h);
            Some(h.t)
        });
        best
    }

    /// Whether anything lies on the ray with `0 < t < t_max` (shadow rays; stops at the first hit).
    pub fn occluded(&self, ray: &Ray, t_max: f64) -> bool {
        let mut hit = false;
        self.traverse(ray, t_max, |prim, limit| {
            self.intersect_primitive(prim, ray, limit)?;
            hit = true;
            Some(-1.0)
        });
        hit
    }

    /// The nearest hit by testing every primitive (no BVH): a reference for tests and benchmarks.
    pub fn intersect_brute_force(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for prim in 0..self.prims.len() as u32 {
            let limit = best.map_or(t_max, |h| h.t);
            if let Some(h) = self.intersect_primitive(prim, ray, limit) {
                best = Some(h);
            }
        }
        best
    }
}

/// The traversal stack: a fixed array on the call stack, spilling to the heap only for trees
/// deeper than it (so a ray costs no allocation).
struct NodeStack {
    inline: [u32; 96],
    len: usize,
    spill: Vec<u32>,
}

impl NodeStack {
    fn new() -> Self {
        Self { inline: [0; 96], len: 0, spill: Vec::new() }
    }

    #[inline]
    fn push(&mut self, node: u32) {
        if self.len < self.inline.len() {
            self.inline[self.len] = node;
            self.len += 1;
        } else {
            self.spill.push(node);
        }
    }

    #[inline]
    fn pop(&mut self) -> Option<u32> {
        if let Some(node) = self.spill.pop() {
            return Some(node);
        }
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        Some(self.inline[self.len])
    }
}
