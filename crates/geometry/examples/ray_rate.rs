//! Rays per second of [`World::intersect`] (closest hit) and [`World::occluded`] (shadow rays,
//! `t_max` = [`SHADOW_T_MAX`]) on the geometry benchmark's mesh ([`bumpy_sphere`]`(160)`, 102,400
//! triangles) and rays ([`rays`]), on the calling thread only, printed as one JSON line.
//!
//! ```text
//! cargo run --release -p spectrace-geometry --example ray_rate -- [--rays N] [--reps K] [--dump DIR]
//! ```
//!
//! `--rays` (default 100,000) rays are traced `--reps` times (default 5) per query; the JSON gives
//! the best repetition's rate (the one least disturbed by other work on the machine) and the
//! median's. The vertices and the rays are rounded to f32 first, so that an f32 engine (Embree, in
//! `cargo xtask peer --geometry`) can be given bit for bit the same scene; Spectrace still
//! computes in f64. With `--dump DIR` the example also writes that scene and its own answers to
//! raw little-endian files in `DIR` (see [`dump`]), which `xtask/peer/geometry.py` reads.

use std::error::Error;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Instant;

use spectrace_geometry::bench_scenes::{
    BENCH_SPHERE_N, SHADOW_T_MAX, bumpy_sphere_triangles, rays,
};
use spectrace_geometry::{Mesh, Ray, World};

/// The command line: rays per repetition, repetitions, and the folder to dump the scene into.
struct Options {
    rays: usize,
    reps: usize,
    dump: Option<PathBuf>,
}

/// Reads `--rays N`, `--reps K` and `--dump DIR`.
fn options() -> Result<Options, Box<dyn Error>> {
    let mut options = Options { rays: 100_000, reps: 5, dump: None };
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        let value = args.next().ok_or_else(|| format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--rays" => options.rays = value.parse()?,
            "--reps" => options.reps = value.parse()?,
            "--dump" => options.dump = Some(value.into()),
            _ => {
                return Err(
                    format!("unknown option {flag}: use --rays N --reps K --dump DIR").into()
                );
            }
        }
    }
    if options.rays == 0 || options.reps == 0 {
        return Err("--rays and --reps must be at least 1".into());
    }
    Ok(options)
}

/// `v` rounded to f32 and back, so that f32 and f64 engines see the same number.
fn round_f32(v: glam::DVec3) -> glam::DVec3 {
    v.as_vec3().as_dvec3()
}

/// The best and the median of `reps` timings of `trace` (seconds), and its last result.
fn time(reps: usize, mut trace: impl FnMut() -> usize) -> (f64, f64, usize) {
    let mut seconds = Vec::with_capacity(reps);
    let mut result = 0;
    for _ in 0..reps {
        let start = Instant::now();
        result = black_box(trace());
        seconds.push(start.elapsed().as_secs_f64());
    }
    seconds.sort_by(f64::total_cmp);
    (seconds[0], seconds[reps / 2], result)
}

fn main() -> Result<(), Box<dyn Error>> {
    let options = options()?;
    let (positions, triangles) = bumpy_sphere_triangles(BENCH_SPHERE_N);
    let positions: Vec<_> = positions.into_iter().map(round_f32).collect();
    let rays: Vec<Ray> = rays(options.rays)
        .iter()
        .map(|r| Ray { origin: round_f32(r.origin), direction: round_f32(r.direction) })
        .collect();
    let mesh = Mesh::from_triangles(positions.clone(), triangles.clone())?;
    let start = Instant::now();
    let world = World::new(vec![mesh.into()])?;
    let build = start.elapsed().as_secs_f64();
    let reps = options.reps;
    let (closest_best, closest_median, closest_hits) = time(reps, || {
        black_box(&rays).iter().filter(|r| world.intersect(r, f64::INFINITY).is_some()).count()
    });
    let (shadow_best, shadow_median, shadow_hits) =
        time(reps, || black_box(&rays).iter().filter(|r| world.occluded(r, SHADOW_T_MAX)).count());
    if let Some(dir) = &options.dump {
        dump(dir, &positions, &triangles, &rays, &world)?;
    }
    let n = rays.len() as f64;
    let report = serde_json::json!({
        "engine": "spectrace",
        "threads": 1,
        "vertices": positions.len(),
        "triangles": triangles.len(),
        "rays": rays.len(),
        "reps": reps,
        "build_seconds": build,
        "closest_rays_per_second": n / closest_best,
        "closest_rays_per_second_median": n / closest_median,
        "closest_hits": closest_hits,
        "shadow_t_max": SHADOW_T_MAX,
        "shadow_rays_per_second": n / shadow_best,
        "shadow_rays_per_second_median": n / shadow_median,
        "shadow_hits": shadow_hits,
    });
    println!("{report}");
    Ok(())
}

/// Writes the scene and Spectrace's answers into `dir` (created if missing), all little-endian:
/// `vertices.f32` (x, y, z per vertex), `triangles.u32` (three vertex indices per triangle),
/// `origins.f32` and `directions.f32` (x, y, z per ray), `closest_t.f64` (the closest hit's `t`
/// per ray, `inf` for a miss), `closest_triangle.u32` (its triangle, `u32::MAX` for a miss),
/// `occluded.u8` (1 where the shadow ray is blocked) and
/// `scene.json` (the counts and the shadow rays' `t_max`).
fn dump(
    dir: &Path,
    positions: &[glam::DVec3],
    triangles: &[[u32; 3]],
    rays: &[Ray],
    world: &World,
) -> Result<(), Box<dyn Error>> {
    std::fs::create_dir_all(dir)?;
    let xyz = |points: &mut dyn Iterator<Item = glam::DVec3>| -> Vec<u8> {
        points.flat_map(|p| p.as_vec3().to_array()).flat_map(f32::to_le_bytes).collect()
    };
    std::fs::write(dir.join("vertices.f32"), xyz(&mut positions.iter().copied()))?;
    let indices: Vec<u8> = triangles.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
    std::fs::write(dir.join("triangles.u32"), indices)?;
    std::fs::write(dir.join("origins.f32"), xyz(&mut rays.iter().map(|r| r.origin)))?;
    std::fs::write(dir.join("directions.f32"), xyz(&mut rays.iter().map(|r| r.direction)))?;
    let hits: Vec<_> = rays.iter().map(|r| world.intersect(r, f64::INFINITY)).collect();
    let t: Vec<u8> =
        hits.iter().map(|h| h.map_or(f64::INFINITY, |h| h.t)).flat_map(f64::to_le_bytes).collect();
    std::fs::write(dir.join("closest_t.f64"), t)?;
    let index: Vec<u8> = hits
        .iter()
        .map(|h| h.map_or(u32::MAX, |h| h.triangle))
        .flat_map(u32::to_le_bytes)
        .collect();
    std::fs::write(dir.join("closest_triangle.u32"), index)?;
    let occluded: Vec<u8> =
        rays.iter().map(|r| u8::from(world.occluded(r, SHADOW_T_MAX))).collect();
    std::fs::write(dir.join("occluded.u8"), occluded)?;
    let scene = serde_json::json!({
        "vertices": positions.len(),
        "triangles": triangles.len(),
        "rays": rays.len(),
        "shadow_t_max": SHADOW_T_MAX,
    });
    std::fs::write(dir.join("scene.json"), format!("{scene}\n"))?;
    Ok(())
}
