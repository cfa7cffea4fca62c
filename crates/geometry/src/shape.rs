//! [`Shape`]: the scene-file union of all shapes, and the per-primitive interface the BVH uses.

use std::path::Path;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::{
    Bounds, Cylinder, Disk, GeometryError, Hit, Mesh, Prism, Ray, Rectangle, Sphere, Torus,
    Transform,
};

/// What the world needs of a shape: its primitives (one for analytic shapes, one per triangle
/// for meshes), their bounds, and exact f64 intersection of one of them.
pub(crate) trait Primitives {
    /// How many primitives.
    fn count(&self) -> usize;
    /// Bounds of primitive `index`.
    fn bounds(&self, index: u32) -> Bounds;
    /// The hit with primitive `index` in `(0, t_max)`, with `primitive = 0` (the world fills it).
    fn intersect(&self, index: u32, ray: &Ray, t_max: f64) -> Option<Hit>;
    /// Only the `t` that [`Primitives::intersect`] would report (same arithmetic, bit for bit),
    /// without building the [`Hit`]: the BVH's per-candidate test.
    fn hit_t(&self, index: u32, ray: &Ray, t_max: f64) -> Option<f64> {
        self.intersect(index, ray, t_max).map(|h| h.t)
    }
}

/// The uniform scale of `t` if it is a similarity, else an error naming `shape.transform`.
pub(crate) fn similarity(shape: &'static str, t: &Transform) -> Result<f64, GeometryError> {
    t.similarity_scale().ok_or_else(|| {
        GeometryError::parameter(
            shape,
            "transform",
            t.to_rows(),
            "must be a similarity (rotation, uniform scale, translation); use a Mesh otherwise",
        )
    })
}

/// A point on a shape's surface, as [`Shape::sample_area`] draws it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// The point (m, world space).
    pub point: DVec3,
    /// Unit outward geometric normal: the one [`Shape::intersect`] reports there as
    /// [`Hit::geometric_normal`] (the front face of rectangles and disks).
    pub normal: DVec3,
}

/// Any shape, as scene files name it: `{"type": "Sphere", ...}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type")]
#[non_exhaustive]
pub enum Shape {
    /// A sphere.
    Sphere(Sphere),
    /// A parallelogram.
    Rectangle(Rectangle),
    /// A disk.
    Disk(Disk),
    /// An open cylinder.
    Cylinder(Cylinder),
    /// A ring torus.
    Torus(Torus),
    /// A triangle mesh.
    Mesh(Mesh),
    /// A triangular prism.
    Prism(Prism),
}

macro_rules! from_shape {
    ($($t:ident),*) => {$(
        impl From<$t> for Shape {
            fn from(s: $t) -> Self {
                Shape::$t(s)
            }
        }
    )*};
}
from_shape!(Sphere, Rectangle, Disk, Cylinder, Torus, Mesh, Prism);

impl Shape {
    /// The shape's primitives (the one place that dispatches on the variant).
    pub(crate) fn primitives(&self) -> &dyn Primitives {
        match self {
            Shape::Sphere(s) => s,
            Shape::Rectangle(s) => s,
            Shape::Disk(s) => s,
            Shape::Cylinder(s) => s,
            Shape::Torus(s) => s,
            Shape::Mesh(s) => s,
            Shape::Prism(s) => s.mesh(),
        }
    }

    /// [`Primitives::hit_t`] of primitive `index`, dispatched by an enum match (no vtable).
    #[inline]
    pub(crate) fn hit_t(&self, index: u32, ray: &Ray, t_max: f64) -> Option<f64> {
        match self {
            Shape::Sphere(s) => s.hit_t(index, ray, t_max),
            Shape::Rectangle(s) => s.hit_t(index, ray, t_max),
            Shape::Disk(s) => s.hit_t(index, ray, t_max),
            Shape::Cylinder(s) => s.hit_t(index, ray, t_max),
            Shape::Torus(s) => s.hit_t(index, ray, t_max),
            Shape::Mesh(s) => s.hit_t(index, ray, t_max),
            Shape::Prism(s) => s.mesh().hit_t(index, ray, t_max),
        }
    }

    /// The triangle mesh behind a `Mesh` or `Prism` (its triangles are BVH primitives).
    pub(crate) fn triangle_mesh(&self) -> Option<&Mesh> {
        match self {
            Shape::Mesh(m) => Some(m),
            Shape::Prism(p) => Some(p.mesh()),
            _ => None,
        }
    }

    /// The type name as in scene files.
    pub fn type_name(&self) -> &'static str {
        match self {
            Shape::Sphere(_) => "Sphere",
            Shape::Rectangle(_) => "Rectangle",
            Shape::Disk(_) => "Disk",
            Shape::Cylinder(_) => "Cylinder",
            Shape::Torus(_) => "Torus",
            Shape::Mesh(_) => "Mesh",
            Shape::Prism(_) => "Prism",
        }
    }

    /// Loads an OBJ mesh relative to `base_dir` (no-op for other shapes).
    ///
    /// # Errors
    /// [`GeometryError::Obj`] if the file cannot be read.
    pub fn load(&mut self, base_dir: &Path) -> Result<(), GeometryError> {
        match self {
            Shape::Mesh(m) => m.load(base_dir),
            _ => Ok(()),
        }
    }

    /// How many BVH primitives the shape contributes (triangles for meshes, else 1).
    pub fn primitive_count(&self) -> usize {
        self.primitives().count()
    }

    /// World-space bounds (empty for an unloaded mesh).
    pub fn bounds(&self) -> Bounds {
        let p = self.primitives();
        (0..p.count() as u32).fold(Bounds::EMPTY, |b, i| b.union(p.bounds(i)))
    }

    /// Total surface area (m^2), after the shape's transform; `> 0` for every valid shape.
    ///
    /// Closed forms: sphere `4 pi r^2`, rectangle `|edge_u x edge_v|`, disk `pi r^2`, open
    /// cylinder `2 pi r h` (side only), torus `4 pi^2 R r`, mesh and prism the sum of their
    /// triangles' areas. Two edge cases a caller that emits from the shape must refuse: a mesh
    /// whose triangles are all degenerate (or an OBJ mesh not yet loaded) has area 0, and an
    /// area beyond `f64::MAX` is `+inf`.
    pub fn area(&self) -> f64 {
        match self {
            Shape::Sphere(s) => s.area(),
            Shape::Rectangle(s) => s.area(),
            Shape::Disk(s) => s.area(),
            Shape::Cylinder(s) => s.area(),
            Shape::Torus(s) => s.area(),
            Shape::Mesh(s) => s.area(),
            Shape::Prism(s) => s.mesh().area(),
        }
    }

    /// A point drawn uniformly by area from three uniforms in `[0, 1)` (each clamped into
    /// `[0, 1)` first, NaN to 0, so any input is accepted and nothing panics).
    ///
    /// The density is `1 / area()` per m^2. Meshes pick a triangle by area from a cumulative
    /// table built when the mesh is built or loaded (`u[0]`), then a point on it by the
    /// square-root warp (`u[1]`, `u[2]`). A mesh of zero or overflowing total area is sampled
    /// uniformly by triangle instead; an OBJ mesh not yet loaded returns the origin.
    pub fn sample_area(&self, u: [f64; 3]) -> SurfacePoint {
        let u = u.map(crate::float::unit_uniform);
        match self {
            Shape::Sphere(s) => s.sample_area(u),
            Shape::Rectangle(s) => s.sample_area(u),
            Shape::Disk(s) => s.sample_area(u),
            Shape::Cylinder(s) => s.sample_area(u),
            Shape::Torus(s) => s.sample_area(u),
            Shape::Mesh(s) => s.sample_area(u),
            Shape::Prism(s) => s.mesh().sample_area(u),
        }
    }

    /// The nearest hit in `(0, t_max)` by testing every primitive (no BVH), `primitive = 0`.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let p = self.primitives();
        let mut best: Option<Hit> = None;
        for i in 0..p.count() as u32 {
            let limit = best.map_or(t_max, |h| h.t);
            if let Some(h) = p.intersect(i, ray, limit) {
                best = Some(h);
            }
        }
        best
    }
}
