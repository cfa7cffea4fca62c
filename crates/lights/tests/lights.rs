//! Tests of `spectrace-lights` through its public API: beam invariants, direction and origin
//! distributions against closed forms (chi-square at fixed seeds), power bookkeeping, counting
//! under threads, determinism, serialisation round trips and the experiment hooks (bad input:
//! `bad_input.rs`).
#![allow(clippy::unwrap_used)]

use std::f64::consts::PI;
use std::sync::Arc;

use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_lights::spectrum::{
    Blackbody, CieIlluminant, Gaussian, Monochromatic, SpectralPowerDistribution,
};
use spectrace_lights::*;
use spectrace_sampling::stats::{chi_square, histogram};

/// Significance level of every statistical test here: a correct light fails one at a random seed
/// with probability 1e-3 (seeds are fixed, so the outcome is reproducible).
const ALPHA: f64 = 1e-3;
const N: usize = 200_000;

fn d65() -> Arc<dyn SpectralPowerDistribution> {
    Arc::new(CieIlluminant::new("D65").unwrap())
}

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// One of every light type (both wavelength-sampling modes across them).
fn zoo() -> Vec<(&'static str, Box<dyn LightSource>)> {
    use WavelengthSampling::{EqualWavelengths as Eq, Importance as Imp};
    vec![
        (
            "Laser",
            Box::new(
                Laser::new(
                    v(0.0, 1.0, 0.0),
                    v(1.0, 0.0, 0.0),
                    0.005,
                    Arc::new(Gaussian::new(632.8, 0.01).unwrap()),
                    0.0,
                    Imp,
                )
                .unwrap(),
            ),
        ),
        (
            "Laser wide",
            Box::new(Laser::new(v(0.0, 1.0, 0.0), v(1.0, 1.0, 0.0), 1.0, d65(), 0.01, Eq).unwrap()),
        ),
        (
            "Sky",
            Box::new(
                Sky::new(
                    v(-1.0, 2.0, -1.0),
                    v(2.0, 0.0, 0.0),
                    v(0.0, 0.0, 2.0),
                    v(0.2, -1.0, 0.1),
                    10.0,
                    d65(),
                    Imp,
                )
                .unwrap(),
            ),
        ),
        (
            "UniformSpotLight",
            Box::new(
                UniformSpotLight::new(
                    v(0.0, 2.0, 0.0),
                    v(0.0, -1.0, 0.0),
                    30.0,
                    100.0,
                    Arc::new(Blackbody::new(3200.0).unwrap()),
                    Eq,
                )
                .unwrap(),
            ),
        ),
        (
            "FadingSpotLight",
            Box::new(
                FadingSpotLight::new(
                    v(0.0, 2.0, 0.0),
                    v(0.3, -1.0, 0.0),
                    40.0,
                    0.05,
                    100.0,
                    Arc::new(Blackbody::new(3200.0).unwrap()),
                    Imp,
                )
                .unwrap(),
            ),
        ),
        (
            "PointLight",
            Box::new(
                PointLight::new(
                    v(0.0, 2.0, 0.0),
                    60.0,
                    Arc::new(Monochromatic::new(589.0).unwrap()),
                    Imp,
                )
                .unwrap(),
            ),
        ),
        (
            "RectangleLight",
            Box::new(
                RectangleLight::new(
                    v(-0.25, 1.99, -0.25),
                    v(0.5, 0.0, 0.0),
                    v(0.0, 0.0, 0.5),
                    50.0,
                    d65(),
                    false,
                    Imp,
                )
                .unwrap(),
            ),
        ),
        (
            "DiskLight two-sided",
            Box::new(
                DiskLight::new(v(0.0, 2.0, 0.0), v(0.0, -1.0, 0.0), 0.2, 20.0, d65(), true, Eq)
                    .unwrap(),
            ),
        ),
    ]
}

#[test]
fn every_beam_is_well_formed() {
    for (name, light) in zoo() {
        let (lo, hi) = light.spd().range();
        let mut rng = Pcg64::seed_from_u64(1);
        for _ in 0..20_000 {
            let b = light.next_beam(&mut rng);
            assert!(
                (b.direction.length() - 1.0).abs() < 1e-12,
                "{name}: |direction| = {}",
                b.direction.length()
            );
            assert!(b.origin.is_finite(), "{name}: origin {:?}", b.origin);
            assert!(
                b.lambda >= lo && b.lambda <= hi,
                "{name}: lambda {} outside [{lo}, {hi}]",
                b.lambda
            );
            assert!(b.scale.is_finite() && b.scale >= 0.0, "{name}: scale {}", b.scale);
            assert_eq!(b.level, 0, "{name}");
            assert_eq!(b.parent, LightId(0), "{name}");
        }
        assert_eq!(light.number_of_beams(), 20_000, "{name}");
    }
}

/// Every built-in light draws its wavelength first: `next_beam(rng)` is `next_beam_at(u, rng)`
/// with `u` its first draw, bit for bit; and with importance or observer sampling the beam's
/// wavelength is the one `sample_wavelength(u)` gives (the map a light tracer's companions use).
#[test]
fn next_beam_is_next_beam_at_its_first_draw_and_shares_the_companions_map() {
    use rand::RngExt;
    for (name, mut light) in zoo() {
        for sampling in [WavelengthSampling::Importance, WavelengthSampling::Observer] {
            light.set_wavelength_sampling(sampling).unwrap();
            let mut a = Pcg64::seed_from_u64(7);
            for _ in 0..200 {
                let mut b = a.clone();
                let u = spectrace_lights::uniform(&mut b);
                let (x, y) = (light.next_beam(&mut a), light.next_beam_at(u, &mut b));
                assert_eq!(x, y, "{name} {sampling:?}");
                assert_eq!(a.random::<u64>(), b.random::<u64>(), "{name}: same draws after");
                if light.spd().range().1 > light.spd().range().0 {
                    assert_eq!(y.lambda, light.sample_wavelength(u).0, "{name} {sampling:?}");
                }
            }
        }
    }
    // A light that implements only `next_beam` ignores `u_lambda` and stays a beam source.
    let seed_only = SeedOnlyLight { power: 1.0 };
    let mut rng = Pcg64::seed_from_u64(3);
    assert_eq!(seed_only.next_beam_at(0.25, &mut rng), seed_only.next_beam(&mut rng));
}

#[test]
fn beam_powers_sum_to_the_light_power() {
    for (name, light) in zoo() {
        let mut rng = Pcg64::seed_from_u64(2);
        let beams: Vec<Beam> = (0..10_000).map(|_| light.next_beam(&mut rng)).collect();
        let n = light.number_of_beams();
        let total: f64 = beams.iter().map(|b| b.power(light.power(), n)).sum();
        let scales: f64 = beams.iter().map(|b| b.scale).sum::<f64>() / beams.len() as f64;
        if beams.iter().all(|b| b.scale == 1.0) {
            // Importance sampling: exactly the light's power, by construction.
            assert!(
                (total / light.power() - 1.0).abs() < 1e-12,
                "{name}: {total} vs {}",
                light.power()
            );
        } else {
            // Equal wavelengths with weights: the mean scale is 1 in expectation. Its standard
            // error at 10^4 beams is below 0.01 for these spectra; 5 standard errors.
            assert!((scales - 1.0).abs() < 0.05, "{name}: mean scale {scales}");
        }
    }
}

#[test]
fn both_wavelength_modes_conserve_power_in_expectation() {
    // The equal-wavelength mode's mean scale converges to 1; measured with its own standard error.
    let spd: Arc<dyn SpectralPowerDistribution> = Arc::new(CieIlluminant::new("F11").unwrap());
    let light =
        PointLight::new(DVec3::ZERO, 1.0, spd, WavelengthSampling::EqualWavelengths).unwrap();
    let mut rng = Pcg64::seed_from_u64(3);
    let scales: Vec<f64> = (0..N).map(|_| light.next_beam(&mut rng).scale).collect();
    let mean = scales.iter().sum::<f64>() / N as f64;
    let var = scales.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (N - 1) as f64;
    let se = (var / N as f64).sqrt();
    assert!((mean - 1.0).abs() < 5.0 * se, "mean scale {mean}, standard error {se}");
    assert!(se < 0.01);
}

fn chi2_uniform(
    values: impl IntoIterator<Item = f64>,
    lo: f64,
    hi: f64,
    bins: usize,
    n: usize,
) -> f64 {
    let counts = histogram(values, lo, hi, bins);
    let expected = vec![n as f64 / bins as f64; bins];
    chi_square(&counts, &expected, 5.0).p_value
}

#[test]
fn uniform_spot_cosines_are_uniform_in_the_cone() {
    let spot = UniformSpotLight::new(
        v(1.0, 2.0, 3.0),
        v(0.0, -1.0, 0.5),
        25.0,
        1.0,
        d65(),
        WavelengthSampling::Importance,
    )
    .unwrap();
    let axis = v(0.0, -1.0, 0.5).normalize();
    let cos_cone = 25f64.to_radians().cos();
    let mut rng = Pcg64::seed_from_u64(10);
    let beams: Vec<Beam> = (0..N).map(|_| spot.next_beam(&mut rng)).collect();
    let cosines: Vec<f64> = beams.iter().map(|b| b.direction.dot(axis)).collect();
    assert!(cosines.iter().all(|&c| c >= cos_cone - 1e-12));
    let p = chi2_uniform(cosines.iter().copied(), cos_cone, 1.0 + 1e-12, 50, N);
    assert!(p > ALPHA, "cos(theta) not uniform: p = {p}");
    // Azimuth uniform too.
    let frame_x = axis.any_orthonormal_vector();
    let frame_y = axis.cross(frame_x);
    let phis = beams.iter().map(|b| b.direction.dot(frame_y).atan2(b.direction.dot(frame_x)));
    let p = chi2_uniform(phis, -PI, PI + 1e-12, 36, N);
    assert!(p > ALPHA, "azimuth not uniform: p = {p}");
}

#[test]
fn a_very_narrow_uniform_spot_still_fills_its_cone() {
    // cos(1e-7 degrees) rounds to 1; the shared cone warp works from 1 - cos, so the beams spread
    // over the whole cone instead of collapsing onto the axis: (theta / theta_max)^2, which is
    // (1 - cos theta) / (1 - cos theta_max) to 1e-15 here, is uniform on [0, 1].
    let cone = 1e-7_f64;
    let spot =
        UniformSpotLight::new(DVec3::ZERO, v(0.0, 0.0, 1.0), cone, 1.0, d65(), Default::default())
            .unwrap();
    let theta_max = cone.to_radians();
    let mut rng = Pcg64::seed_from_u64(12);
    let ratios: Vec<f64> = (0..N)
        .map(|_| {
            let d = spot.next_beam(&mut rng).direction;
            (d.x.hypot(d.y).atan2(d.z) / theta_max).powi(2)
        })
        .collect();
    assert!(ratios.iter().all(|&r| r <= 1.0 + 1e-9), "a beam outside the cone");
    let p = chi2_uniform(ratios.iter().copied(), 0.0, 1.0 + 1e-9, 50, N);
    assert!(p > ALPHA, "(theta / theta_max)^2 not uniform: p = {p}");
}

#[test]
fn fading_spot_follows_its_profile_per_solid_angle() {
    let (cone, fade) = (40.0_f64, 0.05_f64); // full intensity to 20 degrees, zero at 40
    let spot = FadingSpotLight::new(
        DVec3::ZERO,
        v(0.0, 0.0, 1.0),
        cone,
        fade,
        1.0,
        d65(),
        WavelengthSampling::Importance,
    )
    .unwrap();
    let mut rng = Pcg64::seed_from_u64(11);
    let thetas: Vec<f64> = (0..N)
        .map(|_| spot.next_beam(&mut rng).direction.z.clamp(-1.0, 1.0).acos().to_degrees())
        .collect();
    // Expected: density in theta proportional to I(theta) sin(theta), from the stated profile
    // (independent of the tabulation: integrated here by Simpson's rule on each bin).
    let profile = |t: f64| if t <= 20.0 { 1.0 } else { ((cone - t) * fade).max(0.0) };
    let f = |t: f64| profile(t) * t.to_radians().sin();
    let bins = 80;
    let width = cone / bins as f64;
    let simpson = |a: f64, b: f64| {
        let m = 64;
        let h = (b - a) / m as f64;
        let mut s = f(a) + f(b);
        for i in 1..m {
            s += f(a + h * i as f64) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        s * h / 3.0
    };
    let masses: Vec<f64> =
        (0..bins).map(|i| simpson(width * i as f64, width * (i + 1) as f64)).collect();
    let total: f64 = masses.iter().sum();
    let expected: Vec<f64> = masses.iter().map(|m| m / total * N as f64).collect();
    let counts = histogram(thetas.iter().copied(), 0.0, cone + 1e-9, bins);
    let chi = chi_square(&counts, &expected, 5.0);
    assert!(chi.p_value > ALPHA, "fading profile: {chi:?}");
    // The seed's mistake (no sin(theta) Jacobian) is clearly rejected by the same test.
    let wrong: Vec<f64> = (0..bins).map(|i| profile(width * (i as f64 + 0.5))).collect();
    let wrong_total: f64 = wrong.iter().sum();
    let wrong_expected: Vec<f64> = wrong.iter().map(|m| m / wrong_total * N as f64).collect();
    assert!(chi_square(&counts, &wrong_expected, 5.0).p_value < 1e-100);
}

#[test]
fn fading_spot_tabulation_matches_the_stated_intensity() {
    // The tabulated polar density (normalised) against the stated profile * sin, normalised with
    // the light's closed-form peak intensity: they differ by less than 1e-6 of the peak density.
    let spot = FadingSpotLight::new(
        DVec3::ZERO,
        DVec3::Z,
        60.0,
        0.04,
        3.0,
        d65(),
        WavelengthSampling::Importance,
    )
    .unwrap();
    let sampler = spot.polar_sampler();
    let stated = |t_deg: f64| {
        2.0 * PI * spot.peak_intensity() * spot.profile(t_deg) * t_deg.to_radians().sin()
            / spot.power()
    };
    let peak = (0..=6000).map(|k| stated(60.0 * k as f64 / 6000.0)).fold(0.0, f64::max);
    for k in 0..=6000 {
        let t_deg = 60.0 * k as f64 / 6000.0;
        let error = (sampler.pdf(t_deg.to_radians()) - stated(t_deg)).abs();
        assert!(error < 1e-6 * peak, "theta {t_deg}: error {error} vs peak {peak}");
    }
    for k in 1..600 {
        let t_deg = 60.0 * k as f64 / 600.0;
        let t = t_deg.to_radians();
        let stated =
            2.0 * PI * spot.peak_intensity() * spot.profile(t_deg) * t.sin() / spot.power();
        let tabulated = sampler.pdf(t);
        if t_deg < 55.0 {
            // Away from the zero at the cone's edge the agreement is also relative.
            assert!(
                (tabulated / stated - 1.0).abs() < 1e-5,
                "theta {t_deg}: {tabulated} vs {stated}"
            );
        }
    }
}

#[test]
fn fading_spot_power_normalisation_matches_the_closed_form_and_survives_narrow_fades() {
    // Wide fade: the quadrature agrees with the closed form (1 - cos tf) + k (sin tf - sin tc +
    // (tc - tf) cos tf), k = 1 / (tc - tf).
    let spot = FadingSpotLight::new(
        DVec3::ZERO,
        DVec3::Z,
        50.0,
        0.05,
        2.0,
        d65(),
        WavelengthSampling::Importance,
    )
    .unwrap();
    let (tc, tf) = (50f64.to_radians(), 30f64.to_radians());
    let z = (1.0 - tf.cos()) + (tf.sin() - tc.sin() + (tc - tf) * tf.cos()) / (tc - tf);
    assert!((spot.peak_intensity() / (2.0 / (2.0 * PI * z)) - 1.0).abs() < 1e-12);
    // A fade of 1e-6 degrees on a 1e-4 degree cone: still finite, positive, and equal to a
    // uniform spot of the same cone to first order.
    let narrow = FadingSpotLight::new(
        DVec3::ZERO,
        DVec3::Z,
        1e-4,
        1e6,
        1.0,
        d65(),
        WavelengthSampling::Importance,
    )
    .unwrap();
    let uniform = UniformSpotLight::new(
        DVec3::ZERO,
        DVec3::Z,
        1e-4,
        1.0,
        d65(),
        WavelengthSampling::Importance,
    )
    .unwrap();
    assert!(narrow.peak_intensity().is_finite() && narrow.peak_intensity() > 0.0);
    assert!(
        (narrow.peak_intensity() / uniform.intensity() - 1.0).abs() < 0.03,
        "{} vs {}",
        narrow.peak_intensity(),
        uniform.intensity()
    );
}

#[test]
fn point_light_is_uniform_on_the_sphere() {
    let light = PointLight::new(DVec3::ZERO, 1.0, d65(), WavelengthSampling::Importance).unwrap();
    let mut rng = Pcg64::seed_from_u64(12);
    let dirs: Vec<DVec3> = (0..N).map(|_| light.next_beam(&mut rng).direction).collect();
    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
        let p = chi2_uniform(dirs.iter().map(|d| d.dot(axis)), -1.0, 1.0 + 1e-12, 50, N);
        assert!(p > ALPHA, "cos to {axis:?} not uniform: p = {p}");
    }
    let p = chi2_uniform(dirs.iter().map(|d| d.y.atan2(d.x)), -PI, PI + 1e-12, 36, N);
    assert!(p > ALPHA, "azimuth: p = {p}");
}

#[test]
fn area_lights_are_cosine_weighted_and_uniform_over_their_surface() {
    let rect = RectangleLight::new(
        v(1.0, 0.0, 0.0),
        v(2.0, 0.0, 0.0),
        v(0.0, 1.0, 0.0),
        1.0,
        d65(),
        false,
        WavelengthSampling::Importance,
    )
    .unwrap();
    assert!((rect.normal() - DVec3::Z).length() < 1e-15);
    let mut rng = Pcg64::seed_from_u64(13);
    let beams: Vec<Beam> = (0..N).map(|_| rect.next_beam(&mut rng)).collect();
    // Cosine-weighted: P(cos <= c) = c^2, so cos^2 is uniform on [0, 1].
    assert!(beams.iter().all(|b| b.direction.z >= 0.0));
    let p =
        chi2_uniform(beams.iter().map(|b| b.direction.z * b.direction.z), 0.0, 1.0 + 1e-12, 50, N);
    assert!(p > ALPHA, "rectangle cos^2: p = {p}");
    let p = chi2_uniform(beams.iter().map(|b| b.origin.x), 1.0, 3.0 + 1e-12, 40, N);
    assert!(p > ALPHA, "rectangle origin x: p = {p}");
    let p = chi2_uniform(beams.iter().map(|b| b.origin.y), 0.0, 1.0 + 1e-12, 40, N);
    assert!(p > ALPHA, "rectangle origin y: p = {p}");

    let disk = DiskLight::new(
        v(0.0, 0.0, 1.0),
        v(0.0, 0.0, -1.0),
        2.0,
        1.0,
        d65(),
        true,
        WavelengthSampling::Importance,
    )
    .unwrap();
    let beams: Vec<Beam> = (0..N).map(|_| disk.next_beam(&mut rng)).collect();
    let p =
        chi2_uniform(beams.iter().map(|b| b.direction.z * b.direction.z), 0.0, 1.0 + 1e-12, 50, N);
    assert!(p > ALPHA, "disk cos^2: p = {p}");
    // Two-sided: half the beams on each side.
    let up = beams.iter().filter(|b| b.direction.z > 0.0).count() as f64;
    assert!((up / N as f64 - 0.5).abs() < 5.0 * (0.25 / N as f64).sqrt(), "two-sided split {up}");
    // Uniform over the disk: r^2 / R^2 uniform, azimuth uniform.
    let p = chi2_uniform(
        beams.iter().map(|b| (b.origin.x.powi(2) + b.origin.y.powi(2)) / 4.0),
        0.0,
        1.0 + 1e-12,
        50,
        N,
    );
    assert!(p > ALPHA, "disk radius: p = {p}");
    assert!(beams.iter().all(|b| (b.origin.z - 1.0).abs() < 1e-12));
}

#[test]
fn sky_origins_are_uniform_over_the_rectangle() {
    let (corner, eu, ev) = (v(-1.0, 5.0, -2.0), v(2.0, 0.0, 1.0), v(0.0, 0.5, 0.0));
    let sky =
        Sky::new(corner, eu, ev, v(0.0, -1.0, 0.2), 1.0, d65(), WavelengthSampling::Importance)
            .unwrap();
    let mut rng = Pcg64::seed_from_u64(14);
    let beams: Vec<Beam> = (0..N).map(|_| sky.next_beam(&mut rng)).collect();
    // Recover (s, t) from origin = corner + s eu + t ev (eu and ev are orthogonal here).
    let st: Vec<(f64, f64)> = beams
        .iter()
        .map(|b| {
            let d = b.origin - corner;
            (d.dot(eu) / eu.length_squared(), d.dot(ev) / ev.length_squared())
        })
        .collect();
    // A 10 x 10 grid over the unit square.
    let mut counts = vec![0u64; 100];
    for &(s, t) in &st {
        assert!((-1e-12..=1.0 + 1e-12).contains(&s) && (-1e-12..=1.0 + 1e-12).contains(&t));
        counts[((s * 10.0) as usize).min(9) * 10 + ((t * 10.0) as usize).min(9)] += 1;
    }
    let p = chi_square(&counts, &[N as f64 / 100.0; 100], 5.0).p_value;
    assert!(p > ALPHA, "sky origins: p = {p}");
    let dir = v(0.0, -1.0, 0.2).normalize();
    assert!(beams.iter().all(|b| (b.direction - dir).length() < 1e-15));
}

#[test]
fn beam_wavelengths_follow_the_spd() {
    let spd = Arc::new(Blackbody::new(2700.0).unwrap());
    let light =
        PointLight::new(DVec3::ZERO, 1.0, spd.clone(), WavelengthSampling::Importance).unwrap();
    let mut rng = Pcg64::seed_from_u64(15);
    let lambdas: Vec<f64> = (0..N).map(|_| light.next_beam(&mut rng).lambda).collect();
    let bins = 47;
    let counts = histogram(lambdas, 360.0, 830.0 + 1e-9, bins);
    let expected: Vec<f64> = (0..bins)
        .map(|i| {
            let (a, b) = (360.0 + 10.0 * i as f64, 370.0 + 10.0 * i as f64);
            spectrace_lights::spectrum::integrate_panels(&|l| spd.value(l), a, b, &[]) * N as f64
        })
        .collect();
    let chi = chi_square(&counts, &expected, 5.0);
    assert!(chi.p_value > ALPHA, "{chi:?}");
}

#[test]
fn light_set_picks_lights_by_power_and_marks_the_parent() {
    let lights: Vec<Box<dyn LightSource>> = vec![
        Box::new(PointLight::new(DVec3::ZERO, 1.0, d65(), WavelengthSampling::Importance).unwrap()),
        Box::new(PointLight::new(DVec3::X, 0.0, d65(), WavelengthSampling::Importance).unwrap()),
        Box::new(
            Laser::new(
                DVec3::Y,
                DVec3::X,
                3.0,
                Arc::new(Monochromatic::new(532.0).unwrap()),
                0.0,
                WavelengthSampling::Importance,
            )
            .unwrap(),
        ),
        Box::new(
            UniformSpotLight::new(
                DVec3::Z,
                DVec3::Z,
                10.0,
                6.0,
                d65(),
                WavelengthSampling::Importance,
            )
            .unwrap(),
        ),
    ];
    let set = LightSet::new(lights).unwrap();
    assert_eq!(set.power(), 10.0);
    let mut rng = Pcg64::seed_from_u64(16);
    let mut counts = vec![0u64; 4];
    for _ in 0..N {
        let b = set.next_beam(&mut rng);
        counts[b.parent.0 as usize] += 1;
        // The beam is the parent's kind of beam.
        if b.parent == LightId(2) {
            assert_eq!((b.origin, b.direction, b.lambda), (DVec3::Y, DVec3::X, 532.0));
        }
    }
    assert_eq!(counts[1], 0, "a zero-power light emitted");
    let expected: Vec<f64> = [1.0, 0.0, 3.0, 6.0].iter().map(|p| p / 10.0 * N as f64).collect();
    let chi = chi_square(&counts, &expected, 5.0);
    assert!(chi.p_value > ALPHA, "{chi:?}");
    assert_eq!(set.number_of_beams(), N as u64);
    let per_light: u64 = set.lights().iter().map(|l| l.number_of_beams()).sum();
    assert_eq!(per_light, N as u64);
    // Each light's share of the power converges to its fraction: beam powers per parent.
    for (i, l) in set.lights().iter().enumerate() {
        assert_eq!(l.number_of_beams(), counts[i]);
    }
    // The set's SPD is the power-weighted mixture: the laser line holds 30% of it.
    let line_share = set.spd().integrate(&|l| if (l - 532.0).abs() < 1e-9 { 1.0 } else { 0.0 });
    assert!((line_share - 0.3).abs() < 1e-12, "{line_share}");
    set.reset_count();
    assert_eq!(set.number_of_beams(), 0);
    assert_eq!(set.lights()[0].number_of_beams(), 0);
}

#[test]
fn counting_is_exact_across_threads() {
    let light =
        Arc::new(PointLight::new(DVec3::ZERO, 1.0, d65(), WavelengthSampling::Importance).unwrap());
    std::thread::scope(|scope| {
        for t in 0..4u64 {
            let light = light.clone();
            scope.spawn(move || {
                let mut rng = Pcg64::seed_from_u64(100 + t);
                for _ in 0..25_000 {
                    light.next_beam(&mut rng);
                }
            });
        }
    });
    assert_eq!(light.number_of_beams(), 100_000);
}

#[test]
fn same_seed_same_beams() {
    for (name, light) in zoo() {
        let (mut a, mut b) = (Pcg64::seed_from_u64(7), Pcg64::seed_from_u64(7));
        for _ in 0..1000 {
            assert_eq!(light.next_beam(&mut a), light.next_beam(&mut b), "{name}");
        }
    }
}

fn beams(light: &dyn LightSource, seed: u64) -> Vec<Beam> {
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..500).map(|_| light.next_beam(&mut rng)).collect()
}

#[test]
fn lights_round_trip_through_json_and_bincode() {
    let config = bincode::config::standard();
    let mut all = zoo();
    let set_members: Vec<Box<dyn LightSource>> = zoo().into_iter().map(|(_, l)| l).collect();
    all.push(("LightSet", Box::new(LightSet::new(set_members).unwrap())));
    for (name, light) in all {
        let json = serde_json::to_string(&light).unwrap();
        let from_json: Box<dyn LightSource> =
            serde_json::from_str(&json).unwrap_or_else(|e| panic!("{name}: {e}\n{json}"));
        assert_eq!(
            serde_json::to_string(&from_json).unwrap(),
            json,
            "{name}: JSON changed on the trip"
        );
        let bytes = bincode::serde::encode_to_vec(&light, config).unwrap();
        let (from_bincode, _): (Box<dyn LightSource>, usize) =
            bincode::serde::decode_from_slice(&bytes, config)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(
            serde_json::to_string(&from_bincode).unwrap(),
            json,
            "{name}: bincode trip changed the light"
        );
        let original = beams(light.as_ref(), 5);
        assert_eq!(beams(from_json.as_ref(), 5), original, "{name}: JSON trip changed the beams");
        assert_eq!(
            beams(from_bincode.as_ref(), 5),
            original,
            "{name}: bincode trip changed the beams"
        );
        assert_eq!(
            from_json.number_of_beams(),
            500,
            "{name}: a deserialised light counts from zero"
        );
    }
}

#[test]
fn documented_json_forms_parse() {
    let docs = [
        r#"{"type": "Laser", "position": [0, 1, 0], "direction": [1, 0, 0], "power": 0.005, "spd": {"type": "Gaussian", "center_nm": 632.8, "fwhm_nm": 0.002}, "beam_radius": 0.0005}"#,
        r#"{"type": "Sky", "corner": [-1, 2, -1], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2], "direction": [0, -1, 0], "power": 10, "spd": {"type": "CieIlluminant", "name": "D65"}}"#,
        r#"{"type": "UniformSpotLight", "position": [0, 2, 0], "direction": [0, -1, 0], "cone_angle": 30, "power": 100, "spd": {"type": "Blackbody", "kelvin": 3200}}"#,
        r#"{"type": "FadingSpotLight", "position": [0, 2, 0], "direction": [0, -1, 0], "cone_angle": 30, "fade_per_angle": 0.1, "power": 100, "spd": {"type": "Blackbody", "kelvin": 3200}}"#,
        r#"{"type": "PointLight", "position": [0, 2, 0], "power": 60, "spd": {"type": "CieIlluminant", "name": "A"}}"#,
        r#"{"type": "RectangleLight", "corner": [-0.25, 1.99, -0.25], "edge_u": [0.5, 0, 0], "edge_v": [0, 0, 0.5], "power": 50, "spd": {"type": "Blackbody", "kelvin": 4000}}"#,
        r#"{"type": "DiskLight", "center": [0, 2, 0], "normal": [0, -1, 0], "radius": 0.2, "power": 20, "spd": {"type": "CieIlluminant", "name": "F11"}, "two_sided": true}"#,
        r#"{"type": "PointLight", "position": [0, 0, 0], "power": 1, "spd": {"type": "Blackbody", "kelvin": 5000}, "wavelength_sampling": "equal_wavelengths"}"#,
        r#"{"type": "LightSet", "lights": [{"type": "PointLight", "position": [0, 2, 0], "power": 60, "spd": {"type": "Blackbody", "kelvin": 2700}}, {"type": "Laser", "position": [0, 1, 0], "direction": [1, 0, 0], "power": 0.005, "spd": {"type": "Monochromatic", "lambda_nm": 532}}]}"#,
    ];
    for d in docs {
        let light: Box<dyn LightSource> =
            serde_json::from_str(d).unwrap_or_else(|e| panic!("{d}: {e}"));
        assert!(light.power() > 0.0);
    }
}

#[test]
fn emission_densities_integrate_to_one() {
    // Over the sphere of directions, each light's emission density integrates to 1 (midpoint rule
    // on a fine grid in cos(theta) and phi around +z); the direction tests above check that the
    // beams follow the same shapes.
    let lights: Vec<(&str, Box<dyn LightSource>)> = vec![
        (
            "point",
            Box::new(
                PointLight::new(DVec3::ZERO, 1.0, d65(), WavelengthSampling::Importance).unwrap(),
            ),
        ),
        (
            "uniform spot",
            Box::new(
                UniformSpotLight::new(
                    DVec3::ZERO,
                    DVec3::Z,
                    35.0,
                    1.0,
                    d65(),
                    WavelengthSampling::Importance,
                )
                .unwrap(),
            ),
        ),
        (
            "fading spot",
            Box::new(
                FadingSpotLight::new(
                    DVec3::ZERO,
                    DVec3::Z,
                    35.0,
                    0.1,
                    1.0,
                    d65(),
                    WavelengthSampling::Importance,
                )
                .unwrap(),
            ),
        ),
        (
            "rectangle",
            Box::new(
                RectangleLight::new(
                    DVec3::ZERO,
                    DVec3::X,
                    DVec3::Y,
                    1.0,
                    d65(),
                    false,
                    WavelengthSampling::Importance,
                )
                .unwrap(),
            ),
        ),
        (
            "disk two-sided",
            Box::new(
                DiskLight::new(
                    DVec3::ZERO,
                    DVec3::Z,
                    1.0,
                    1.0,
                    d65(),
                    true,
                    WavelengthSampling::Importance,
                )
                .unwrap(),
            ),
        ),
    ];
    let (nc, np) = (2000, 64);
    for (name, light) in &lights {
        let mut total = 0.0;
        for i in 0..nc {
            let c = -1.0 + 2.0 * (i as f64 + 0.5) / nc as f64;
            let s = (1.0 - c * c).sqrt();
            for j in 0..np {
                let phi = 2.0 * PI * (j as f64 + 0.5) / np as f64;
                total += light.emission_density(DVec3::ZERO, v(s * phi.cos(), s * phi.sin(), c));
            }
        }
        total *= (2.0 / nc as f64) * (2.0 * PI / np as f64);
        assert!((total - 1.0).abs() < 2e-3, "{name}: density integrates to {total}");
    }
    let laser =
        Laser::new(DVec3::ZERO, DVec3::X, 1.0, d65(), 0.0, WavelengthSampling::Importance).unwrap();
    assert_eq!(laser.emission_density(DVec3::ZERO, DVec3::X), 0.0);
}

#[test]
fn sample_towards_gives_the_closed_form_irradiance() {
    // E = I cos / r^2 for point lights; for an area light, the mean of intensity cos / r^2 over
    // its samples converges to the closed form of a disk seen on-axis: E = L pi R^2 / (R^2 + h^2).
    let point =
        PointLight::new(DVec3::ZERO, 4.0 * PI, d65(), WavelengthSampling::Importance).unwrap();
    let s = point.sample_towards(v(0.0, 0.0, 2.0), [0.5, 0.5]).unwrap();
    assert_eq!((s.intensity, s.distance, s.delta), (1.0, 2.0, true));
    let spot = UniformSpotLight::new(
        DVec3::ZERO,
        DVec3::Z,
        10.0,
        1.0,
        d65(),
        WavelengthSampling::Importance,
    )
    .unwrap();
    assert_eq!(spot.sample_towards(v(1.0, 0.0, 1.0), [0.0, 0.0]).unwrap().intensity, 0.0);
    assert!(
        (spot.sample_towards(v(0.0, 0.0, 1.0), [0.0, 0.0]).unwrap().intensity - spot.intensity())
            .abs()
            < 1e-12
    );
    let (r, h) = (0.5_f64, 2.0_f64);
    let disk =
        DiskLight::new(DVec3::ZERO, DVec3::Z, r, 1.0, d65(), false, WavelengthSampling::Importance)
            .unwrap();
    let receiver = v(0.0, 0.0, h);
    let n = 200_000;
    let mut rng = Pcg64::seed_from_u64(17);
    let estimates: Vec<f64> = (0..n)
        .map(|_| {
            let u = [uniform(&mut rng), uniform(&mut rng)];
            let s = disk.sample_towards(receiver, u).unwrap();
            let cos_receiver = s.direction.dot(-DVec3::Z).abs();
            s.intensity * cos_receiver / (s.distance * s.distance)
        })
        .collect();
    let mean = estimates.iter().sum::<f64>() / n as f64;
    let sd = (estimates.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    let exact = disk.radiance() * PI * r * r / (r * r + h * h);
    assert!((mean - exact).abs() < 5.0 * sd / (n as f64).sqrt(), "{mean} vs {exact}");
}

/// The irradiance the beams of `light` give the square of half-width `h` around `centre` on the
/// plane `y = centre.y` (normal +y), counted from `n` beams: `(hits, irradiance estimate)`.
fn beam_irradiance(light: &dyn LightSource, centre: DVec3, h: f64, n: usize) -> (usize, f64) {
    let mut rng = Pcg64::seed_from_u64(29);
    let hits = (0..n)
        .filter(|_| {
            let b = light.next_beam(&mut rng);
            let t = (centre.y - b.origin.y) / b.direction.y;
            let p = b.origin + b.direction * t;
            t > 0.0 && (p.x - centre.x).abs() < h && (p.z - centre.z).abs() < h
        })
        .count();
    (hits, hits as f64 * light.power() / n as f64 / (4.0 * h * h))
}

/// Next-event estimation of a parallel light (`sample_towards`) gives a receiver the
/// irradiance its beams give on average: the closed form, checked against beams counted
/// through a small square (binomial count, 4 standard deviations), `None` beside the beams and
/// upstream of them, and nothing for a laser of zero width.
#[test]
fn parallel_lights_are_sampled_towards_a_receiver_as_their_beams_light_it() {
    let direction = v(0.3, -1.0, 0.2).normalize();
    let sky = Sky::new(
        v(-1.0, 2.0, -1.0),
        v(2.0, 0.0, 0.0),
        v(0.5, 0.0, 2.0),
        direction,
        7.0,
        d65(),
        WavelengthSampling::Importance,
    )
    .unwrap();
    let laser =
        Laser::new(v(0.0, 2.0, 0.0), direction, 3.0, d65(), 0.4, WavelengthSampling::Importance)
            .unwrap();
    // Where the laser's axis meets the plane y = 0, well inside the sky's beams too.
    let receiver = v(0.0, 2.0, 0.0) + direction * (2.0 / direction.dot(-DVec3::Y));
    for (name, light) in [("sky", &sky as &dyn LightSource), ("laser", &laser)] {
        let s = light.sample_towards(receiver, [0.3, 0.8]).unwrap();
        assert!(s.delta && s.pdf == 1.0, "{name}");
        assert!((s.position + s.direction * s.distance - receiver).length() < 1e-12, "{name}");
        let irradiance = s.intensity * s.direction.dot(DVec3::Y).abs() / (s.distance * s.distance);
        let (hits, counted) = beam_irradiance(light, receiver, 0.1, 1_000_000);
        let sd = counted / (hits as f64).sqrt();
        assert!(hits > 5000, "{name}: {hits} hits");
        assert!((counted - irradiance).abs() < 4.0 * sd, "{name}: {counted} vs {irradiance}");
        // Upstream of the light, and far beside its beams: no beam passes.
        assert!(light.sample_towards(receiver - direction * 10.0, [0.5; 2]).is_none(), "{name}");
        assert!(light.sample_towards(v(50.0, 0.0, 0.0), [0.5; 2]).is_none(), "{name}");
    }
    let expected = 7.0 / (sky.area() * direction.dot(-DVec3::Y));
    assert!((sky.irradiance() - expected).abs() < 1e-12 * expected);
    assert!((laser.irradiance() - 3.0 / (PI * 0.16)).abs() < 1e-12);
    let thin =
        Laser::new(v(0.0, 2.0, 0.0), direction, 3.0, d65(), 0.0, WavelengthSampling::Importance)
            .unwrap();
    let on_axis = v(0.0, 2.0, 0.0) + direction * 2.0;
    assert!(thin.sample_towards(on_axis, [0.5; 2]).is_none());
    assert!(sky.sample_towards(v(0.0, 1e300, 0.0) * -1.0, [0.5; 2]).is_none());
}

#[test]
fn nested_light_sets_are_flattened() {
    let point = || -> Box<dyn LightSource> {
        Box::new(PointLight::new(DVec3::ZERO, 1.0, d65(), WavelengthSampling::Importance).unwrap())
    };
    let inner = LightSet::new(vec![point(), point()]).unwrap();
    assert!(!inner.uniform_spectrum());
    let outer = LightSet::new(vec![point(), Box::new(inner), point()]).unwrap();
    assert_eq!(outer.lights().len(), 4);
    assert_eq!(outer.power(), 4.0);
    assert!(outer.lights().iter().all(|l| l.uniform_spectrum()));
    let mut rng = Pcg64::seed_from_u64(3);
    for _ in 0..1000 {
        assert!(outer.next_beam(&mut rng).parent.0 < 4);
    }
    // The flattened set serialises as one level: no nested set is left inside it.
    let json = serde_json::to_string(&outer).unwrap();
    assert_eq!(json.matches("LightSet").count(), 0, "{json}");
}

#[test]
fn the_experiment_hooks_retune_lights_in_place_and_keep_the_set_consistent() {
    let table: Arc<dyn SpectralPowerDistribution> = Arc::new(
        spectrum::Tabulated::new(&[400.0, 500.0, 600.0, 700.0], &[0.2, 1.0, 0.6, 0.3]).unwrap(),
    );
    // A Gaussian with a spectral line: delta lines have no density to weight by.
    let line: Arc<dyn SpectralPowerDistribution> = Arc::new(
        spectrum::Mixture::new(vec![
            spectrum::Component { weight: 1.0, spd: Arc::new(Gaussian::new(500.0, 40.0).unwrap()) },
            spectrum::Component { weight: 1.0, spd: Arc::new(Monochromatic::new(550.0).unwrap()) },
        ])
        .unwrap(),
    );
    let lights: Vec<Box<dyn LightSource>> = vec![
        Box::new(PointLight::new(DVec3::ZERO, 3.0, table, WavelengthSampling::Importance).unwrap()),
        Box::new(PointLight::new(DVec3::ONE, 1.0, line, WavelengthSampling::Importance).unwrap()),
    ];
    let mut set = LightSet::new(lights).unwrap();
    let sampling = |set: &LightSet, i: usize| {
        serde_json::to_value(&set.lights()[i]).unwrap()["wavelength_sampling"].clone()
    };

    // Equal wavelengths: allowed for the table, refused (naming the field) for the line.
    let mut outcomes = Vec::new();
    set.modify_lights(&mut |id, light| {
        outcomes.push((id, light.set_wavelength_sampling(WavelengthSampling::EqualWavelengths)));
    })
    .unwrap();
    assert!(outcomes[0].1.is_ok());
    let refused = outcomes[1].1.as_ref().unwrap_err().to_string();
    assert!(refused.contains("wavelength_sampling"), "{refused}");
    assert_eq!(sampling(&set, 0), "equal_wavelengths");
    assert_eq!(sampling(&set, 1), "importance");
    // Power and order unchanged: light 0 still has 3/4 of the power.
    assert_eq!(set.power(), 4.0);
    assert!((set.pmf(LightId(0)) - 0.75).abs() < 1e-12);

    // Piecewise-constant SPD for the table; the line has none and stays.
    let mut replaced = Vec::new();
    set.modify_lights(&mut |_, light| {
        replaced.push(
            light
                .map_spd(&|spd: &dyn SpectralPowerDistribution| {
                    spd.piecewise_constant().map(Arc::from)
                })
                .unwrap(),
        );
    })
    .unwrap();
    assert_eq!(replaced, [true, false]);
    let spd = serde_json::to_value(set.lights()[0].spd().as_ref()).unwrap();
    assert_eq!(spd["type"], "Binned");
    assert_eq!(sampling(&set, 0), "equal_wavelengths");
    // The set's own spectrum is rebuilt from the lights as they are now.
    let rebinned = set.lights()[0].spd();
    assert_eq!(rebinned.value(451.0), rebinned.value(549.0));
    let expected = 0.75 * rebinned.value(451.0) + 0.25 * set.lights()[1].spd().value(451.0);
    assert!((set.spd().value(451.0) - expected).abs() < 1e-12);
}

/// A light from another crate that implements only the seed's four methods.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
struct SeedOnlyLight {
    power: f64,
}

#[typetag::serde]
impl LightSource for SeedOnlyLight {
    fn next_beam(&self, _rng: &mut dyn rand::Rng) -> Beam {
        Beam::new(DVec3::ZERO, DVec3::Z, 550.0, 1.0)
    }
    fn number_of_beams(&self) -> u64 {
        0
    }
    fn power(&self) -> f64 {
        self.power
    }
    fn spd(&self) -> Arc<dyn SpectralPowerDistribution> {
        Arc::new(Monochromatic::new(550.0).unwrap())
    }
}

#[test]
fn a_light_without_the_hooks_says_so_by_field() {
    let mut light = SeedOnlyLight { power: 1.0 };
    let e = light.set_wavelength_sampling(WavelengthSampling::Observer).unwrap_err();
    assert_eq!(e, LightError::Unsupported { field: "wavelength_sampling" });
    assert!(e.to_string().starts_with("wavelength_sampling: "), "{e}");
    let e = light
        .map_spd(&|spd: &dyn SpectralPowerDistribution| spd.piecewise_constant().map(Arc::from));
    assert_eq!(e, Err(LightError::Unsupported { field: "spd" }));
}
