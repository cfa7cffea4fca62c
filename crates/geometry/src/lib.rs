//! Rays, shapes and the BVH of Spectrace: where does a beam next meet a surface?
//!
//! The tracer asks one question of geometry, millions of times: given a [`Ray`], what is the
//! nearest [`Hit`] in a [`World`] (and, for shadow rays, is anything in the way)? A hit carries
//! the point, the geometric normal (on the shape's outward side), a shading normal, surface
//! coordinates `uv`, the index of the shape it belongs to, and a conservative bound on the
//! floating-point error of its point. Shapes come from scene files as tagged JSON (see
//! [`Shape`]): [`Sphere`], [`Rectangle`], [`Disk`], open [`Cylinder`], [`Torus`], triangle
//! [`Mesh`]es (inline or OBJ through `tobj`) and the glass [`Prism`], each with an optional
//! [`Transform`] written row-major or as scale/rotate/translate.
//!
//! The key design decision is robustness by error bounds rather than epsilons. All ray and shape
//! arithmetic is f64; each intersection routine is written to avoid cancellation (the vector form
//! of the ray/sphere discriminant, Woop's watertight triangle test, root isolation instead of a
//! closed-form quartic for the torus) and re-projects its hit onto the surface, so the error of
//! the point is small and known. [`Hit::spawn_ray`] then offsets the next ray's origin just past
//! that error along the normal, so a bounce never re-hits its own surface at `t ~ 0`, at the
//! origin or `1e5` m away, without a scene-dependent epsilon. The BVH is built by `obvhs` from f32
//! boxes rounded outwards from the exact f64 bounds, then collapsed into 8-wide nodes whose boxes
//! are tested together in SIMD lanes with a conservative f32 slab test (the origin's f32 rounding
//! widens the interval), so the BVH can only cost time, never a hit; a leaf's triangles are
//! filtered four at a time by the watertight test's first half in SIMD (the scalar test's own
//! arithmetic per lane), and the full [`Hit`] is built once, for the nearest.
//!
//! For emitting objects, [`Shape::area`] and [`Shape::sample_area`] draw a [`SurfacePoint`]
//! uniformly by area on any shape (the torus by inverting its tube-angle CDF, meshes by a
//! cumulative-area table built with the mesh).
//!
//! Layering: of Spectrace's crates this one depends only on `spectrace-sampling` (shading frames,
//! bounded file reading).

pub mod bench_scenes;
mod bounds;
mod bvh;
mod cylinder;
mod disk;
mod error;
mod float;
mod leaves;
mod mesh;
mod ply;
mod prism;
mod ray;
mod rectangle;
mod serialized;
mod shape;
mod sphere;
mod torus;
mod transform;
mod world;

pub use bounds::Bounds;
pub use cylinder::Cylinder;
pub use disk::Disk;
pub use error::GeometryError;
pub use mesh::{
    CUBE_TRIANGLES, MAX_MESH_TRIANGLES, MAX_MESH_VERTICES, MAX_OBJ_BYTES, Mesh, VertexNormals,
};
pub use prism::Prism;
pub use ray::{Hit, Ray};
pub use rectangle::Rectangle;
pub use serialized::{SerializedMesh, write_serialized};
pub use shape::{Shape, SurfacePoint};
/// Bounded file reading, shared with every crate that reads input files (it lives in the lowest
/// one, `spectrace-sampling`).
pub use spectrace_sampling::files::{human_bytes, read_bounded};
pub use sphere::Sphere;
pub use torus::Torus;
pub use transform::Transform;
pub use world::World;

/// Vectors and matrices (`DVec3`, `DMat4`), re-exported so callers use the same `glam`.
pub use glam;
