//! Tests of the shared frame, warps and uniform helpers: each warp's samples against its own pdf
//! (chi-square at a fixed seed), the frame's orthonormality for every unit normal (property test,
//! with named awkward normals), the inverses, and the edges of `[0, 1)`.
#![allow(clippy::unwrap_used)]

use std::f64::consts::{PI, TAU};

use glam::DVec3;
use proptest::prelude::*;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_sampling::stats::chi_square;
use spectrace_sampling::*;

/// Significance level of every statistical test in this file (fixed seeds: reproducible).
const ALPHA: f64 = 1e-3;
/// Samples per chi-square test.
const N: usize = 200_000;

/// A uniform pair from the shared helper.
fn pair(rng: &mut Pcg64) -> [f64; 2] {
    [uniform(rng), uniform(rng)]
}

/// Chi-square of `n` directions from `sample` against `pdf` (a density per steradian that depends
/// on `cos theta` only, linear in it on each bin), binned by `(cos theta, phi)` over
/// `[cos_lo, cos_hi] x [0, 2 pi)`. The expected count of a bin is `n pdf(midpoint) dcos dphi`,
/// exact for a density linear in `cos theta`, so the test checks the pdf function as well.
fn direction_p_value(
    seed: u64,
    cos_lo: f64,
    cos_hi: f64,
    sample: impl Fn([f64; 2]) -> DVec3,
    pdf: impl Fn(f64) -> f64,
) -> f64 {
    const NC: usize = 20;
    const NP: usize = 16;
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut counts = vec![0u64; NC * NP];
    let dc = (cos_hi - cos_lo) / NC as f64;
    for _ in 0..N {
        let w = sample(pair(&mut rng));
        assert!((w.length() - 1.0).abs() < 1e-14, "{w} is not unit");
        let c = ((w.z - cos_lo) / dc).floor();
        assert!(c >= -1.0 && c <= NC as f64, "cos theta {} outside [{cos_lo}, {cos_hi}]", w.z);
        let c = (c.max(0.0) as usize).min(NC - 1);
        let phi = w.y.atan2(w.x).rem_euclid(TAU);
        let p = ((phi / TAU * NP as f64) as usize).min(NP - 1);
        counts[c * NP + p] += 1;
    }
    let expected: Vec<f64> = (0..NC * NP)
        .map(|k| {
            let mid = cos_lo + ((k / NP) as f64 + 0.5) * dc;
            N as f64 * pdf(mid) * dc * TAU / NP as f64
        })
        .collect();
    let total: f64 = expected.iter().sum();
    assert!((total - N as f64).abs() < 1e-6 * N as f64, "pdf integrates to {}", total / N as f64);
    chi_square(&counts, &expected, 5.0).p_value
}

#[test]
fn cosine_hemisphere_matches_its_pdf() {
    let p = direction_p_value(1, 0.0, 1.0, sample_cosine_hemisphere, pdf_cosine_hemisphere);
    assert!(p > ALPHA, "p = {p}");
}

#[test]
fn concentric_cosine_hemisphere_matches_its_pdf() {
    let p =
        direction_p_value(2, 0.0, 1.0, sample_cosine_hemisphere_concentric, pdf_cosine_hemisphere);
    assert!(p > ALPHA, "p = {p}");
}

#[test]
fn uniform_hemisphere_matches_its_pdf() {
    let p = direction_p_value(3, 0.0, 1.0, sample_uniform_hemisphere, |_| pdf_uniform_hemisphere());
    assert!(p > ALPHA, "p = {p}");
}

#[test]
fn uniform_sphere_matches_its_pdf() {
    let p = direction_p_value(4, -1.0, 1.0, sample_uniform_sphere, |_| pdf_uniform_sphere());
    assert!(p > ALPHA, "p = {p}");
}

#[test]
fn uniform_cones_match_their_pdf() {
    for (seed, degrees) in [(5, 30.0_f64), (6, 120.0), (7, 1e-3)] {
        let omc = one_minus_cos(degrees.to_radians());
        let p = direction_p_value(
            seed,
            1.0 - omc,
            1.0,
            |u| sample_uniform_cone(u, omc),
            |_| pdf_uniform_cone(omc),
        );
        assert!(p > ALPHA, "{degrees} degrees: p = {p}");
    }
}

#[test]
fn narrow_cones_keep_their_width() {
    // cos(1e-7 degrees) rounds to 1; 1 - cos does not, and the samples spread inside the cone.
    let theta = 1e-7_f64.to_radians();
    assert_eq!(theta.cos(), 1.0);
    let omc = one_minus_cos(theta);
    assert!((omc / (theta * theta / 2.0) - 1.0).abs() < 1e-12);
    let w = sample_uniform_cone([ONE_MINUS_EPSILON, 0.25], omc);
    let angle = w.x.hypot(w.y).atan2(w.z);
    assert!((angle / theta - 1.0).abs() < 1e-6, "edge sample at {angle}, cone {theta}");
    assert!(pdf_uniform_cone(omc).is_finite());
}

#[test]
fn concentric_disk_matches_its_pdf() {
    // Bins by (r^2, phi): equal areas of pi / (NR NP) each; the expectation uses the pdf.
    const NR: usize = 20;
    const NP: usize = 16;
    let mut rng = Pcg64::seed_from_u64(8);
    let mut counts = vec![0u64; NR * NP];
    for _ in 0..N {
        let p = sample_uniform_disk_concentric(pair(&mut rng));
        let r2 = p[0] * p[0] + p[1] * p[1];
        assert!(r2 <= 1.0 + 1e-15, "{p:?} outside the disk");
        assert!(pdf_uniform_disk_concentric([p[0] * 0.999_999, p[1] * 0.999_999]) > 0.0);
        let i = ((r2 * NR as f64) as usize).min(NR - 1);
        let phi = p[1].atan2(p[0]).rem_euclid(TAU);
        let j = ((phi / TAU * NP as f64) as usize).min(NP - 1);
        counts[i * NP + j] += 1;
    }
    let area = PI / (NR * NP) as f64;
    let expected = vec![N as f64 * pdf_uniform_disk_concentric([0.0, 0.0]) * area; NR * NP];
    let p = chi_square(&counts, &expected, 5.0).p_value;
    assert!(p > ALPHA, "p = {p}");
    assert_eq!(pdf_uniform_disk_concentric([0.8, 0.7]), 0.0);
}

/// Uniform pairs probing the edges of `[0, 1)` and a grid.
fn probe_pairs() -> Vec<[f64; 2]> {
    let edges = [0.0, 1e-300, 1e-17, 1e-9, 0.125, 0.25, 0.5, 0.75, 1.0 - 1e-9, ONE_MINUS_EPSILON];
    let mut us: Vec<[f64; 2]> = edges.iter().flat_map(|&a| edges.map(|b| [a, b])).collect();
    us.extend((0..40).flat_map(|i| (0..40).map(move |j| [i as f64 / 40.0, j as f64 / 40.0])));
    us
}

/// Distance between two uniforms on the circle `[0, 1)` (the azimuth wraps around).
fn circular(a: f64, b: f64) -> f64 {
    let d = (a - b).abs();
    d.min(1.0 - d)
}

#[test]
fn disk_and_hemisphere_inverses_return_the_uniforms() {
    for u in probe_pairs() {
        let p = sample_uniform_disk_concentric(u);
        let v = invert_uniform_disk_concentric(p);
        // At the centre every u maps to (0, 0); elsewhere the map is one-to-one.
        if p != [0.0, 0.0] {
            assert!((v[0] - u[0]).abs() < 1e-12 && (v[1] - u[1]).abs() < 1e-12, "{u:?} -> {v:?}");
        }
        let v = invert_cosine_hemisphere_concentric(sample_cosine_hemisphere_concentric(u));
        if p != [0.0, 0.0] {
            assert!((v[0] - u[0]).abs() < 1e-12 && (v[1] - u[1]).abs() < 1e-12, "{u:?} -> {v:?}");
        }
        // The polar maps lose the azimuth at the pole (u[0] = 0 or a zero sin theta).
        let w = sample_cosine_hemisphere(u);
        let v = invert_cosine_hemisphere(w);
        assert!((v[0] - u[0]).abs() < 1e-12, "cosine {u:?} -> {v:?}");
        if u[0] > 1e-9 {
            assert!(circular(v[1], u[1]) < 1e-12, "cosine {u:?} -> {v:?}");
        }
        let w = sample_uniform_hemisphere(u);
        let v = invert_uniform_hemisphere(w);
        assert!((v[0] - u[0]).abs() < 1e-12, "hemisphere {u:?} -> {v:?}");
        if u[0] < 1.0 - 1e-9 {
            assert!(circular(v[1], u[1]) < 1e-12, "hemisphere {u:?} -> {v:?}");
        }
        let v = invert_uniform_sphere(sample_uniform_sphere(u));
        assert!((v[0] - u[0]).abs() < 1e-12, "sphere {u:?} -> {v:?}");
        if u[0] > 1e-9 && u[0] < 1.0 - 1e-9 {
            assert!(circular(v[1], u[1]) < 1e-12, "sphere {u:?} -> {v:?}");
        }
        let omc = one_minus_cos(0.5);
        let v = invert_uniform_cone(sample_uniform_cone(u, omc), omc);
        assert!((v[0] - u[0]).abs() < 1e-12, "cone {u:?} -> {v:?}");
        for v in [v, invert_uniform_disk_concentric(p)] {
            assert!(v.iter().all(|x| (0.0..1.0).contains(x)), "{v:?} outside [0, 1)");
        }
    }
}

#[test]
fn cosine_directions_are_never_tangent_and_pdfs_never_zero() {
    for u in probe_pairs() {
        let w = sample_cosine_hemisphere(u);
        assert!(w.z > 0.0 && pdf_cosine_hemisphere(w.z) > 0.0, "{u:?} -> {w}");
        assert!((w.length() - 1.0).abs() < 1e-15, "{u:?} -> {w}");
    }
    assert_eq!(sample_cosine_hemisphere([0.0, 0.0]), DVec3::Z);
    assert_eq!(pdf_cosine_hemisphere(-0.5), 0.0);
}

#[test]
fn out_of_range_uniforms_are_clamped_not_panics() {
    assert_eq!(clamp_uniform(f64::NAN), 0.0);
    assert_eq!(clamp_uniform(-1.0), 0.0);
    assert_eq!(clamp_uniform(1.0), ONE_MINUS_EPSILON);
    assert_eq!(clamp_uniform(f64::INFINITY), ONE_MINUS_EPSILON);
    assert_eq!(clamp_uniform(0.3).to_bits(), 0.3_f64.to_bits());
    for bad in [[f64::NAN, 2.0], [-1.0, f64::INFINITY], [1.0, 1.0]] {
        let p = sample_uniform_disk_concentric(bad);
        assert!(p.iter().all(|x| x.is_finite()), "{bad:?} -> {p:?}");
        for w in [
            sample_cosine_hemisphere(bad),
            sample_cosine_hemisphere_concentric(bad),
            sample_uniform_hemisphere(bad),
            sample_uniform_sphere(bad),
            sample_uniform_cone(bad, 0.5),
        ] {
            assert!(w.is_finite() && (w.length() - 1.0).abs() < 1e-14, "{bad:?} -> {w}");
        }
    }
    let mut rng = Pcg64::seed_from_u64(9);
    for _ in 0..1000 {
        let u = uniform(&mut rng);
        assert!((0.0..1.0).contains(&u) && (u * (1u64 << 53) as f64).fract() == 0.0);
    }
}

/// Checks that `f` is orthonormal and right-handed around `n`, to `tol`.
fn assert_orthonormal(n: DVec3, tol: f64) {
    let f = Frame::from_normal(n);
    assert_eq!(f.n(), n);
    for (a, b) in [(f.t(), f.b()), (f.b(), f.n()), (f.t(), f.n())] {
        assert!(a.dot(b).abs() < tol, "{n}: dot {}", a.dot(b));
    }
    for v in [f.t(), f.b()] {
        assert!((v.length() - 1.0).abs() < tol, "{n}: length {}", v.length());
    }
    assert!((f.t().cross(f.b()) - n).length() < tol, "{n}: not right-handed");
    // to_local inverts to_world (an orthonormal matrix's transpose is its inverse).
    let v = DVec3::new(0.3, -1.7, 2.5);
    assert!((f.to_local(f.to_world(v)) - v).length() < 4.0 * tol, "{n}");
    assert_eq!(f.to_world(DVec3::Z), n);
}

#[test]
fn frames_are_orthonormal_for_awkward_normals() {
    for n in [
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        DVec3::NEG_X,
        DVec3::NEG_Y,
        DVec3::NEG_Z,
        DVec3::new(0.0, 0.0, -0.0) + DVec3::NEG_Z,
        DVec3::new(-0.0, -0.0, -1.0),
        DVec3::new(1e-300, 0.0, 1.0),
        DVec3::new(0.0, -1.0, 1e-17),
        DVec3::new(0.0, -1.0, -1e-17),
        DVec3::new(f64::from_bits(1), 0.0, -1.0),
        DVec3::new(1e-9, -1e-9, -1.0).normalize(),
        DVec3::new(0.6, 0.0, 0.8),
        DVec3::new(1.0, -2.0, 0.5).normalize(),
    ] {
        assert_orthonormal(n, 1e-15);
    }
}

#[test]
fn a_frame_with_a_tangent_follows_it_and_falls_back_when_it_is_parallel() {
    let n = DVec3::new(1.0, -2.0, 0.5).normalize();
    let tangent = DVec3::new(0.3, 0.9, -0.2);
    let f = Frame::from_normal_and_tangent(n, tangent);
    let projected = (tangent - n * tangent.dot(n)).normalize();
    assert!((f.t() - projected).length() < 1e-15, "the first tangent follows the tangent");
    assert!((f.t().cross(f.b()) - n).length() < 1e-15, "right-handed around n");
    assert!(f.t().dot(f.b()).abs() < 1e-15 && (f.b().length() - 1.0).abs() < 1e-15);
    assert_eq!(f.n(), n);
    // A tangent along the normal (or not finite) gives the frame around the normal alone.
    for bad in [n * 3.0, DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 0.0)] {
        assert_eq!(Frame::from_normal_and_tangent(n, bad), Frame::from_normal(n), "{bad}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(10_000))]

    #[test]
    fn frames_are_orthonormal_for_every_unit_normal(
        x in -1.0..1.0_f64,
        y in -1.0..1.0_f64,
        z in -1.0..1.0_f64,
        scale in -300..300_i32,
    ) {
        // Components spanning many magnitudes, so near-axis normals are common.
        let v = DVec3::new(x * 10f64.powi(scale % 20), y, z * 10f64.powi(scale / 20));
        prop_assume!(v.length() > 1e-150 && v.is_finite());
        assert_orthonormal(v.normalize(), 1e-14);
    }
}

#[test]
fn the_harness_rejects_a_warp_against_the_wrong_pdf() {
    // Uniform hemisphere directions are not cosine-distributed: the test above would notice.
    let p = direction_p_value(10, 0.0, 1.0, sample_uniform_hemisphere, pdf_cosine_hemisphere);
    assert!(p < ALPHA, "p = {p}");
}
