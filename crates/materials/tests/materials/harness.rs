//! A reusable checker for any [`Material`] with a density, in the spirit of Mitsuba 3's `chi2`
//! harness: sampled directions against `pdf` (Pearson's chi-square over a grid of the sphere),
//! `pdf` integrated over the sphere (the probability of the non-delta lobes), the single-scattering
//! albedo (white furnace), and reciprocity of `eval`.
//!
//! The sphere is parametrised around the normal by `cos theta` in `[-1, 1]` and `phi` in
//! `[0, 2 pi)`, both in equal steps, so every bin has the same solid angle; the expected count
//! of a bin is `n` times its integral of `pdf`, by a midpoint rule on a finer sub-grid.

use std::f64::consts::PI;

use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_materials::{Incoming, Material, ScatterKind, Transport};
use spectrace_sampling::Frame;
use spectrace_sampling::stats::chi_square;

use crate::uniform;

/// Grid of the sphere used by [`chi2_directions`] and [`pdf_integral`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Grid {
    /// Bins in `cos theta`.
    pub(crate) cos_bins: usize,
    /// Bins in `phi`.
    pub(crate) phi_bins: usize,
    /// Sub-samples per bin and axis for the integral of `pdf`.
    pub(crate) sub: usize,
}

impl Default for Grid {
    fn default() -> Self {
        Self { cos_bins: 40, phi_bins: 80, sub: 8 }
    }
}

impl Grid {
    fn bin(&self, frame: &Frame, d: DVec3) -> usize {
        let l = frame.to_local(d);
        let c = ((l.z.clamp(-1.0, 1.0) + 1.0) * 0.5 * self.cos_bins as f64) as usize;
        let mut phi = l.y.atan2(l.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let p = (phi / (2.0 * PI) * self.phi_bins as f64) as usize;
        c.min(self.cos_bins - 1) * self.phi_bins + p.min(self.phi_bins - 1)
    }

    /// The integral of `f` over each bin (midpoint rule on the sub-grid).
    fn integrate(&self, frame: &Frame, f: impl Fn(DVec3) -> f64) -> Vec<f64> {
        let (nc, np, s) = (self.cos_bins, self.phi_bins, self.sub);
        let d_cos = 2.0 / (nc * s) as f64;
        let d_phi = 2.0 * PI / (np * s) as f64;
        let mut out = vec![0.0; nc * np];
        for ic in 0..nc * s {
            let cos = -1.0 + (ic as f64 + 0.5) * d_cos;
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            for ip in 0..np * s {
                let phi = (ip as f64 + 0.5) * d_phi;
                let d = frame.to_world(DVec3::new(sin * phi.cos(), sin * phi.sin(), cos));
                out[(ic / s) * np + ip / s] += f(d) * d_cos * d_phi;
            }
        }
        out
    }
}

/// What [`chi2_directions`] found.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Chi2Result {
    /// Pearson's p-value of the sampled non-delta directions against `pdf`.
    pub(crate) p_value: f64,
    /// Fraction of the samples that came from a delta lobe (not binned).
    pub(crate) delta_fraction: f64,
    /// Integral of `pdf` over the sphere.
    pub(crate) pdf_integral: f64,
}

/// Samples `n` directions from `material` for a beam arriving from `wi` (pointing away from
/// the surface) and tests the non-delta ones against `pdf(wi, ., normal, lambda)` integrated
/// over the bins of `grid`. The expected counts are `n * integral(pdf)`, so a `pdf` that does
/// not integrate to the non-delta lobes' probability fails too.
pub(crate) fn chi2_directions(
    material: &dyn Material,
    wi: DVec3,
    normal: DVec3,
    lambda: f64,
    n: u64,
    seed: u64,
    grid: Grid,
) -> Chi2Result {
    chi2_directions_around(material, wi, normal, normal, lambda, n, seed, grid)
}

/// [`chi2_directions`] with the grid's pole along `axis` instead of the normal. A sharp lobe
/// should lie on the grid's equator (pass an axis perpendicular to the lobe's centre, e.g.
/// [`axis_across`]), where the bins are as fine in `theta` as in `cos theta`; near a pole the
/// equal-area bins are wide in angle and a lobe narrower than one sub-cell is integrated wrongly.
#[allow(clippy::too_many_arguments)]
pub(crate) fn chi2_directions_around(
    material: &dyn Material,
    wi: DVec3,
    normal: DVec3,
    axis: DVec3,
    lambda: f64,
    n: u64,
    seed: u64,
    grid: Grid,
) -> Chi2Result {
    let frame = Frame::from_normal(axis);
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut observed = vec![0u64; grid.cos_bins * grid.phi_bins];
    let mut deltas = 0u64;
    let incoming = Incoming { direction: -wi, normal, lambda };
    for _ in 0..n {
        let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
        match material.scatter(&incoming, u) {
            Some(s) if s.kind == ScatterKind::Specular => deltas += 1,
            Some(s) => observed[grid.bin(&frame, s.direction)] += 1,
            None => {} // absorbed: counted by neither (the pdf is of the direction only)
        }
    }
    let expected: Vec<f64> = grid
        .integrate(&frame, |d| material.pdf(wi, d, normal, lambda))
        .into_iter()
        .map(|p| p * n as f64)
        .collect();
    let pdf_integral = expected.iter().sum::<f64>() / n as f64;
    let chi = chi_square(&observed, &expected, 5.0);
    Chi2Result { p_value: chi.p_value, delta_fraction: deltas as f64 / n as f64, pdf_integral }
}

/// A unit axis perpendicular to both `normal` and `centre` (any tangent if they are parallel):
/// the pole for a grid that puts a lobe around `centre` on its equator.
pub(crate) fn axis_across(normal: DVec3, centre: DVec3) -> DVec3 {
    let c = normal.cross(centre);
    if c.length_squared() > 1e-12 { c.normalize() } else { Frame::from_normal(normal).t() }
}

/// The integral of `f` over the sphere on `grid` with its pole along `axis`.
pub(crate) fn integrate_sphere(axis: DVec3, grid: Grid, f: impl Fn(DVec3) -> f64) -> f64 {
    grid.integrate(&Frame::from_normal(axis), f).iter().sum()
}

/// Integral of `pdf(wi, ., normal, lambda)` over the sphere.
pub(crate) fn pdf_integral(
    material: &dyn Material,
    wi: DVec3,
    normal: DVec3,
    lambda: f64,
    grid: Grid,
) -> f64 {
    let frame = Frame::from_normal(normal);
    grid.integrate(&frame, |d| material.pdf(wi, d, normal, lambda)).iter().sum()
}

/// The single-scattering albedo for a beam arriving from `wi`: the mean of the sampled
/// weights over `n` samples (absorbed samples count 0), with its standard error.
pub(crate) fn albedo(
    material: &dyn Material,
    wi: DVec3,
    normal: DVec3,
    lambda: f64,
    transport: Transport,
    n: u64,
    seed: u64,
) -> (f64, f64) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let incoming = Incoming { direction: -wi, normal, lambda };
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
        let w = material.scatter_with(&incoming, u, transport).map_or(0.0, |s| s.weight);
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

/// The albedo by quadrature of the non-delta part, `integral f(wi, wo) |cos wo| dwo`, as a
/// check of `eval` independent of `scatter`.
pub(crate) fn albedo_from_eval(
    material: &dyn Material,
    wi: DVec3,
    normal: DVec3,
    lambda: f64,
    grid: Grid,
) -> f64 {
    let frame = Frame::from_normal(normal);
    grid.integrate(&frame, |wo| material.eval(wi, wo, normal, lambda) * wo.dot(normal).abs())
        .iter()
        .sum()
}

/// Largest relative difference `|f(a, b) - f(b, a)| / max(f)` over `n` random direction
/// pairs (pairs where both values are below `floor` are skipped).
pub(crate) fn reciprocity_error(
    material: &dyn Material,
    normal: DVec3,
    lambda: f64,
    transport: Transport,
    n: usize,
    seed: u64,
) -> f64 {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut worst: f64 = 0.0;
    for _ in 0..n {
        let a = crate::random_unit(&mut rng);
        let b = crate::random_unit(&mut rng);
        let fab = material.eval_with(a, b, normal, lambda, transport);
        let fba = material.eval_with(b, a, normal, lambda, transport);
        let m = fab.max(fba);
        if m > 1e-9 {
            worst = worst.max((fab - fba).abs() / m);
        }
    }
    worst
}

/// The harness itself: it accepts the Lambertian lobe and rejects a density that is wrong.
#[test]
fn harness_accepts_lambert_and_rejects_a_wrong_density() {
    use spectrace_materials::Diffuse;
    use spectrace_materials::spectrum::Reflectance;

    /// A Lambertian whose `pdf` claims a uniform hemisphere: its samples must fail.
    #[derive(Debug, serde::Serialize, serde::Deserialize)]
    struct Liar(Diffuse);
    #[typetag::serde]
    impl Material for Liar {
        fn scatter(&self, i: &Incoming, u: [f64; 3]) -> Option<spectrace_materials::Scattered> {
            self.0.scatter(i, u)
        }
        fn eval(&self, wi: DVec3, wo: DVec3, n: DVec3, l: f64) -> f64 {
            self.0.eval(wi, wo, n, l)
        }
        fn pdf(&self, wi: DVec3, wo: DVec3, n: DVec3, _l: f64) -> f64 {
            if wi.dot(n) * wo.dot(n) > 0.0 { 0.5 / PI } else { 0.0 }
        }
        fn is_specular(&self) -> bool {
            false
        }
        fn is_dispersive(&self) -> bool {
            false
        }
    }

    let d = Diffuse::new(Reflectance::constant(0.7).unwrap());
    let n = DVec3::new(0.3, -0.2, 0.9).normalize();
    let wi = (n + DVec3::new(0.5, 0.1, 0.0)).normalize();
    let good = chi2_directions(&d, wi, n, 550.0, 200_000, 1, Grid::default());
    assert!(good.p_value > crate::ALPHA, "{good:?}");
    assert!((good.pdf_integral - 1.0).abs() < 1e-3 && good.delta_fraction == 0.0, "{good:?}");
    assert!((pdf_integral(&d, wi, n, 550.0, Grid::default()) - 1.0).abs() < 1e-3);
    let (a, se) = albedo(&d, wi, n, 550.0, Transport::Importance, 1000, 2);
    assert!((a - 0.7).abs() <= 1e-12 && se < 1e-9, "{a} {se}");
    assert!((albedo_from_eval(&d, wi, n, 550.0, Grid::default()) - 0.7).abs() < 1e-3);
    assert!(reciprocity_error(&d, n, 550.0, Transport::Radiance, 1000, 3) < 1e-12);
    let bad = Liar(Diffuse::new(Reflectance::constant(0.7).unwrap()));
    let r = chi2_directions(&bad, wi, n, 550.0, 200_000, 1, Grid::default());
    assert!(r.p_value < 1e-6, "{r:?}");
}
