//! Tests of the lights' methods for path tracing and bidirectional methods: `sample_emission`
//! against `next_beam` (two-sample chi-square at fixed seeds), `pdf_emission` against the sampled
//! densities, `pdf_towards` against `sample_towards`, `emitted_radiance` against the power,
//! `surface`, and the light set's sampler against its `pmf`.
#![allow(clippy::unwrap_used)]

use std::f64::consts::PI;
use std::sync::Arc;

use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_lights::spectrum::{
    Blackbody, CieIlluminant, Monochromatic, SpectralPowerDistribution,
};
use spectrace_lights::*;
use spectrace_sampling::stats::{chi_square, chi_square_sf, histogram};

/// Significance level of every statistical test here (seeds are fixed, so outcomes reproduce).
const ALPHA: f64 = 1e-3;
const N: usize = 100_000;

fn d65() -> Arc<dyn SpectralPowerDistribution> {
    Arc::new(CieIlluminant::new("D65").unwrap())
}

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) || a == b
}

/// One light of every type, with one- and two-sided area lights, a wide and a point laser.
fn zoo() -> Vec<(&'static str, Box<dyn LightSource>)> {
    use WavelengthSampling::Importance as Imp;
    vec![
        (
            "Laser",
            Box::new(Laser::new(v(0.0, 1.0, 0.0), v(1.0, 0.0, 0.0), 0.5, d65(), 0.0, Imp).unwrap()),
        ),
        (
            "Laser wide",
            Box::new(Laser::new(v(0.0, 1.0, 0.0), v(1.0, 1.0, 0.3), 1.0, d65(), 0.2, Imp).unwrap()),
        ),
        (
            "Sky",
            Box::new(
                Sky::new(
                    v(-1.0, 2.0, -1.0),
                    v(2.0, 0.0, 0.5),
                    v(0.0, 0.3, 2.0),
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
                UniformSpotLight::new(v(0.0, 2.0, 0.0), v(0.2, -1.0, 0.4), 30.0, 100.0, d65(), Imp)
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
                    v(0.5, 0.0, 0.1),
                    v(0.0, -0.2, 0.5),
                    50.0,
                    d65(),
                    false,
                    Imp,
                )
                .unwrap(),
            ),
        ),
        (
            "RectangleLight two-sided",
            Box::new(
                RectangleLight::new(
                    v(1.0, 0.0, 0.0),
                    v(0.0, 0.0, 2.0),
                    v(0.0, 1.0, 0.0),
                    5.0,
                    d65(),
                    true,
                    Imp,
                )
                .unwrap(),
            ),
        ),
        (
            "DiskLight",
            Box::new(
                DiskLight::new(v(0.0, 2.0, 0.0), v(0.3, -1.0, 0.2), 0.4, 20.0, d65(), false, Imp)
                    .unwrap(),
            ),
        ),
        (
            "DiskLight two-sided",
            Box::new(
                DiskLight::new(v(0.0, 2.0, 0.0), v(0.0, -1.0, 0.0), 0.2, 20.0, d65(), true, Imp)
                    .unwrap(),
            ),
        ),
    ]
}

fn area_lights() -> Vec<(&'static str, Box<dyn LightSource>)> {
    zoo()
        .into_iter()
        .filter(|(name, _)| name.contains("Rectangle") || name.contains("Disk"))
        .collect()
}

fn uniforms(rng: &mut Pcg64) -> [f64; 4] {
    [uniform(rng), uniform(rng), uniform(rng), uniform(rng)]
}

/// Two-sample chi-square test that `a` and `b` (equal sizes) come from one distribution: both
/// are binned on 40 equal bins of their common range, sparse adjacent bins pooled until each
/// pooled bin holds at least 10 values of both samples together; the statistic
/// `sum (a_i - b_i)^2 / (a_i + b_i)` is chi-square with (bins - 1) degrees of freedom. Returns
/// the p-value (1 when both samples are one and the same constant).
fn two_sample_p(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let lo = a.iter().chain(b).copied().fold(f64::INFINITY, f64::min);
    let hi = a.iter().chain(b).copied().fold(f64::NEG_INFINITY, f64::max);
    if lo == hi {
        return 1.0;
    }
    let hi = hi + (hi - lo) * 1e-9;
    let (ha, hb) =
        (histogram(a.iter().copied(), lo, hi, 40), histogram(b.iter().copied(), lo, hi, 40));
    assert_eq!(ha.iter().sum::<u64>() as usize, a.len());
    assert_eq!(hb.iter().sum::<u64>() as usize, b.len());
    let (mut statistic, mut bins) = (0.0, 0usize);
    let (mut x, mut y) = (0.0_f64, 0.0_f64);
    for (&ca, &cb) in ha.iter().zip(&hb) {
        x += ca as f64;
        y += cb as f64;
        if x + y >= 10.0 {
            statistic += (x - y) * (x - y) / (x + y);
            bins += 1;
            x = 0.0;
            y = 0.0;
        }
    }
    if x + y > 0.0 {
        statistic += (x - y) * (x - y) / (x + y);
        bins += 1;
    }
    chi_square_sf(statistic, bins.saturating_sub(1).max(1) as f64)
}

/// A number computed from fixed axes, an origin and a direction.
type Feature = fn(&[DVec3; 3], DVec3, DVec3) -> f64;

#[test]
fn sample_emission_draws_the_beams_distribution() {
    // Projections of origin and direction on fixed generic axes, and a mixed one, so that
    // position, direction and their pairing are all compared.
    let axes = [v(0.3, 0.8, -0.5).normalize(), v(-0.7, 0.2, 0.6).normalize(), v(0.1, -0.4, 0.9)];
    let features: [(&str, Feature); 6] = [
        ("origin . a", |a, o, _| o.dot(a[0])),
        ("origin . b", |a, o, _| o.dot(a[1])),
        ("direction . a", |a, _, d| d.dot(a[0])),
        ("direction . b", |a, _, d| d.dot(a[1])),
        ("direction . c", |a, _, d| d.dot(a[2])),
        ("origin . a + direction . c", |a, o, d| o.dot(a[0]) + 0.3 * d.dot(a[2])),
    ];
    for (k, (name, light)) in zoo().into_iter().enumerate() {
        let mut rng = Pcg64::seed_from_u64(100 + k as u64);
        let beams: Vec<(DVec3, DVec3)> = (0..N)
            .map(|_| {
                let b = light.next_beam(&mut rng);
                (b.origin, b.direction)
            })
            .collect();
        let mut rng = Pcg64::seed_from_u64(200 + k as u64);
        let samples: Vec<(DVec3, DVec3)> = (0..N)
            .map(|_| {
                let s = light.sample_emission(uniforms(&mut rng)).unwrap();
                (s.position, s.direction)
            })
            .collect();
        for (feature, f) in &features {
            let a: Vec<f64> = beams.iter().map(|&(o, d)| f(&axes, o, d)).collect();
            let b: Vec<f64> = samples.iter().map(|&(o, d)| f(&axes, o, d)).collect();
            let p = two_sample_p(&a, &b);
            assert!(
                p > ALPHA,
                "{name}: {feature} differs between next_beam and sample_emission: p = {p}"
            );
        }
    }
}

#[test]
fn pdf_emission_returns_the_sampled_densities() {
    for (name, light) in zoo() {
        let flags = light.flags().unwrap();
        let mut rng = Pcg64::seed_from_u64(3);
        for _ in 0..20_000 {
            let s = light.sample_emission(uniforms(&mut rng)).unwrap();
            assert!(s.position.is_finite(), "{name}: {s:?}");
            assert!((s.direction.length() - 1.0).abs() < 1e-12, "{name}: {s:?}");
            assert!(s.pdf_position > 0.0 && s.pdf_position.is_finite(), "{name}: {s:?}");
            assert!(s.pdf_direction > 0.0 && s.pdf_direction.is_finite(), "{name}: {s:?}");
            let (pp, pd) = light.pdf_emission(s.position, s.direction).unwrap();
            assert!(close(pp, s.pdf_position, 1e-12), "{name}: pdf_position {pp} vs {s:?}");
            assert!(close(pd, s.pdf_direction, 1e-12), "{name}: pdf_direction {pd} vs {s:?}");
            if flags.delta_position {
                assert_eq!(s.pdf_position, 1.0, "{name}");
                assert_eq!(s.normal, DVec3::ZERO, "{name}");
            } else {
                // The ray leaves the side its normal is on.
                assert!((s.normal.length() - 1.0).abs() < 1e-12, "{name}: {s:?}");
                assert!(s.normal.dot(s.direction) > 0.0, "{name}: {s:?}");
            }
            if flags.delta_direction {
                assert_eq!(s.pdf_direction, 1.0, "{name}");
            } else {
                // The direction's density is the one the light tracer uses for the same beam.
                let density = light.emission_density(s.position, s.direction);
                assert!(close(density, s.pdf_direction, 1e-12), "{name}: {density} vs {s:?}");
            }
        }
    }
}

#[test]
fn area_emission_samples_carry_the_whole_power() {
    // L |cos| / (pdf_position pdf_direction) = power for every Lambertian sample: each ray
    // carries the light's power, as each beam does.
    for (name, light) in area_lights() {
        let mut rng = Pcg64::seed_from_u64(4);
        let mut sides = [0usize; 2];
        for _ in 0..20_000 {
            let s = light.sample_emission(uniforms(&mut rng)).unwrap();
            let l = light.emitted_radiance(s.position, s.direction);
            let weight = l * s.normal.dot(s.direction).abs() / (s.pdf_position * s.pdf_direction);
            assert!(close(weight, light.power(), 1e-9), "{name}: {weight} vs {}", light.power());
            let front = match light.surface().unwrap() {
                LightSurface::Rectangle { edge_u, edge_v, .. } => edge_u.cross(edge_v).normalize(),
                LightSurface::Disk { normal, .. } => normal,
                _ => unreachable!("a built-in area light has a rectangle or a disk"),
            };
            sides[usize::from(s.normal.dot(front) < 0.0)] += 1;
        }
        if name.contains("two-sided") {
            let p = chi_square(&sides.map(|c| c as u64), &[10_000.0, 10_000.0], 5.0).p_value;
            assert!(p > ALPHA, "{name}: sides {sides:?}, p = {p}");
        } else {
            assert_eq!(sides[1], 0, "{name}: a one-sided light emitted from its back");
        }
    }
}

#[test]
fn area_lights_radiance_integrates_to_their_power() {
    // Power = integral over the surface and the sphere of L |cos|: estimated with points uniform on
    // the surface and directions uniform on the sphere, independently of the lights' samplers.
    let n = 200_000;
    for (name, light) in area_lights() {
        let (area, front) = match light.surface().unwrap() {
            LightSurface::Rectangle { edge_u, edge_v, .. } => {
                let c = edge_u.cross(edge_v);
                (c.length(), c.normalize())
            }
            LightSurface::Disk { normal, radius, .. } => (PI * radius * radius, normal),
            _ => unreachable!("a built-in area light has a rectangle or a disk"),
        };
        let mut rng = Pcg64::seed_from_u64(5);
        let estimates: Vec<f64> = (0..n)
            .map(|_| {
                let position = light.sample_emission(uniforms(&mut rng)).unwrap().position;
                let z = 1.0 - 2.0 * uniform(&mut rng);
                let phi = 2.0 * PI * uniform(&mut rng);
                let r = (1.0 - z * z).sqrt();
                let w = v(r * phi.cos(), r * phi.sin(), z);
                light.emitted_radiance(position, w) * w.dot(front).abs() * area * 4.0 * PI
            })
            .collect();
        let mean = estimates.iter().sum::<f64>() / n as f64;
        let sd =
            (estimates.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
        let sigma = sd / (n as f64).sqrt();
        assert!(sigma < 0.01 * light.power(), "{name}: too noisy to judge");
        assert!((mean - light.power()).abs() < 3.0 * sigma, "{name}: {mean} vs {}", light.power());
        // Back and edge-on.
        let back = light.emitted_radiance(DVec3::ZERO, -front);
        if name.contains("two-sided") {
            assert_eq!(back, light.emitted_radiance(DVec3::ZERO, front), "{name}");
        } else {
            assert_eq!(back, 0.0, "{name}");
        }
        assert!(light.emitted_radiance(DVec3::ZERO, front) > 0.0, "{name}");
    }
}

#[test]
fn pdf_towards_matches_sample_towards_for_area_lights() {
    let receivers = [v(0.3, 0.5, 0.2), v(0.1, 3.5, -0.4), v(2.5, 1.0, 1.0), v(-3.0, 2.0, 0.5)];
    for (name, light) in area_lights() {
        let mut rng = Pcg64::seed_from_u64(6);
        let mut hits = 0;
        for receiver in receivers {
            for _ in 0..2_000 {
                let u = [uniform(&mut rng), uniform(&mut rng)];
                let s = light.sample_towards(receiver, u).unwrap();
                let pdf = light.pdf_towards(receiver, s.position);
                assert!(close(pdf, s.pdf, 1e-12), "{name}: pdf_towards {pdf} vs {s:?}");
                hits += usize::from(pdf > 0.0);
            }
        }
        assert!(hits > 0, "{name}: no receiver sees the light");
    }
    // The density is per solid angle: its reciprocal's mean over the samples is the solid angle
    // the light subtends, for a disk seen on its axis 2 pi (1 - h / sqrt(h^2 + R^2)).
    let (r, h) = (0.5_f64, 2.0_f64);
    let disk =
        DiskLight::new(DVec3::ZERO, DVec3::Z, r, 1.0, d65(), false, WavelengthSampling::Importance)
            .unwrap();
    let receiver = v(0.0, 0.0, h);
    let n = 100_000;
    let mut rng = Pcg64::seed_from_u64(7);
    let inv: Vec<f64> = (0..n)
        .map(|_| {
            let s = disk.sample_towards(receiver, [uniform(&mut rng), uniform(&mut rng)]).unwrap();
            1.0 / disk.pdf_towards(receiver, s.position)
        })
        .collect();
    let mean = inv.iter().sum::<f64>() / n as f64;
    let sd = (inv.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    let exact = 2.0 * PI * (1.0 - h / (h * h + r * r).sqrt());
    assert!((mean - exact).abs() < 3.0 * sd / (n as f64).sqrt(), "{mean} vs {exact}");
    // Behind a one-sided light, on it, and edge-on: 0.
    assert_eq!(disk.pdf_towards(v(0.0, 0.0, -1.0), DVec3::ZERO), 0.0);
    assert_eq!(disk.pdf_towards(DVec3::ZERO, DVec3::ZERO), 0.0);
    assert_eq!(disk.pdf_towards(v(1.0, 0.0, 0.0), DVec3::ZERO), 0.0);
}

#[test]
fn lights_without_a_surface_are_never_hit() {
    for (name, light) in zoo() {
        let is_area = name.contains("Rectangle") || name.contains("Disk");
        assert_eq!(light.surface().is_some(), is_area, "{name}");
        if is_area {
            continue;
        }
        let mut rng = Pcg64::seed_from_u64(8);
        for _ in 0..100 {
            let s = light.sample_emission(uniforms(&mut rng)).unwrap();
            let receiver = s.position + s.direction;
            assert_eq!(light.pdf_towards(receiver, s.position), 0.0, "{name}");
            assert_eq!(light.emitted_radiance(s.position, s.direction), 0.0, "{name}");
            assert_eq!(light.emitted_radiance(s.position, -s.direction), 0.0, "{name}");
        }
    }
}

#[test]
fn point_and_spot_emission_records() {
    let position = v(1.0, 2.0, 3.0);
    let point = PointLight::new(position, 2.0, d65(), WavelengthSampling::Importance).unwrap();
    let s = point.sample_emission([0.3, 0.6, 0.1, 0.9]).unwrap();
    assert_eq!((s.position, s.normal, s.pdf_position), (position, DVec3::ZERO, 1.0));
    assert!(close(s.pdf_direction, 1.0 / (4.0 * PI), 1e-15));
    let spot =
        UniformSpotLight::new(position, DVec3::Z, 20.0, 1.0, d65(), WavelengthSampling::Importance)
            .unwrap();
    let (pp, pd) = spot.pdf_emission(position, DVec3::Z).unwrap();
    assert_eq!(pp, 1.0);
    assert!(close(pd, 1.0 / (2.0 * PI * (1.0 - spot.cos_cone())), 1e-12), "{pd}");
    assert_eq!(spot.pdf_emission(position, -DVec3::Z), Some((1.0, 0.0)));
    // A fading spot of zero power still has a direction density (it is per beam, not per watt).
    let dark = FadingSpotLight::new(
        position,
        DVec3::Z,
        30.0,
        0.1,
        0.0,
        d65(),
        WavelengthSampling::Importance,
    )
    .unwrap();
    let s = dark.sample_emission([0.0, 0.5, 0.5, 0.5]).unwrap();
    assert!(s.pdf_direction > 0.0);
    assert_eq!(dark.pdf_emission(position, -DVec3::Z), Some((1.0, 0.0)));
}

#[test]
fn laser_and_sky_emission_records() {
    let imp = WavelengthSampling::Importance;
    let laser = Laser::new(v(0.0, 1.0, 0.0), v(0.0, 0.0, 2.0), 1.0, d65(), 0.0, imp).unwrap();
    let s = laser.sample_emission([0.1, 0.2, 0.3, 0.4]).unwrap();
    assert_eq!(
        (s.position, s.normal, s.direction, s.pdf_position, s.pdf_direction),
        (v(0.0, 1.0, 0.0), DVec3::ZERO, DVec3::Z, 1.0, 1.0)
    );
    assert_eq!(laser.pdf_emission(s.position, DVec3::Z), Some((1.0, 1.0)));
    assert_eq!(laser.pdf_emission(s.position, v(0.0, 0.6, 0.8)), Some((1.0, 0.0)));
    assert_eq!(laser.pdf_towards(v(0.0, 1.0, 5.0), s.position), 0.0);

    let r = 0.25;
    let wide = Laser::new(v(0.0, 1.0, 0.0), v(0.0, 0.0, 2.0), 1.0, d65(), r, imp).unwrap();
    let s = wide.sample_emission([0.9, 0.2, 0.3, 0.4]).unwrap();
    assert!(close(s.pdf_position, 1.0 / (PI * r * r), 1e-15));
    assert_eq!((s.normal, s.direction, s.pdf_direction), (DVec3::Z, DVec3::Z, 1.0));
    assert!((s.position - v(0.0, 1.0, 0.0)).length() <= r * (1.0 + 1e-12));
    assert!(s.position.z.abs() < 1e-15);

    let (eu, ev) = (v(2.0, 0.0, 0.0), v(0.0, 0.0, 3.0));
    let sky = Sky::new(v(-1.0, 2.0, -1.0), eu, ev, v(0.0, -1.0, 0.5), 1.0, d65(), imp).unwrap();
    assert!(close(sky.area(), 6.0, 1e-15));
    let s = sky.sample_emission([0.5, 0.5, 0.0, 0.0]).unwrap();
    assert_eq!(s.position, v(0.0, 2.0, 0.5));
    assert_eq!((s.normal, s.pdf_direction), (-DVec3::Y, 1.0));
    assert!(close(s.pdf_position, 1.0 / 6.0, 1e-15));
    assert_eq!(sky.pdf_emission(s.position, s.direction), Some((s.pdf_position, 1.0)));
    assert_eq!(sky.pdf_emission(s.position, -s.direction), Some((s.pdf_position, 0.0)));
    assert_eq!(sky.pdf_towards(v(0.0, 0.0, 0.0), s.position), 0.0);
}

#[test]
fn surfaces_hold_the_emission_points() {
    let imp = WavelengthSampling::Importance;
    let (corner, eu, ev) = (v(1.0, 2.0, 3.0), v(0.5, 0.0, 0.0), v(0.0, 0.25, 0.25));
    let rect = RectangleLight::new(corner, eu, ev, 1.0, d65(), false, imp).unwrap();
    assert_eq!(rect.surface(), Some(LightSurface::Rectangle { corner, edge_u: eu, edge_v: ev }));
    assert!(close(rect.area(), 0.5 * 0.25 * 2f64.sqrt(), 1e-15));
    let disk = DiskLight::new(corner, v(0.0, 3.0, 4.0), 0.5, 1.0, d65(), true, imp).unwrap();
    assert_eq!(
        disk.surface(),
        Some(LightSurface::Disk { center: corner, normal: v(0.0, 0.6, 0.8), radius: 0.5 })
    );
    let mut rng = Pcg64::seed_from_u64(9);
    for _ in 0..10_000 {
        let p = rect.sample_emission(uniforms(&mut rng)).unwrap().position - corner;
        // p = s eu + t ev with eu, ev orthogonal.
        let (s, t) = (p.dot(eu) / eu.length_squared(), p.dot(ev) / ev.length_squared());
        assert!((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t), "{s} {t}");
        assert!((p - eu * s - ev * t).length() < 1e-12);
        let p = disk.sample_emission(uniforms(&mut rng)).unwrap().position - corner;
        assert!(p.dot(v(0.0, 0.6, 0.8)).abs() < 1e-12 && p.length() <= 0.5 * (1.0 + 1e-12));
    }
}

#[test]
fn bad_uniforms_never_panic() {
    let bad = [f64::NAN, -1.0, 1.0, 2.0, f64::INFINITY, f64::NEG_INFINITY, -0.0];
    for (name, light) in zoo() {
        for &x in &bad {
            for k in 0..4 {
                let mut u = [0.5; 4];
                u[k] = x;
                if let Some(s) = light.sample_emission(u) {
                    assert!(
                        s.position.is_finite() && s.direction.is_finite(),
                        "{name} {u:?}: {s:?}"
                    );
                    assert!(s.pdf_position > 0.0 && s.pdf_direction > 0.0, "{name} {u:?}: {s:?}");
                }
            }
            let _ = light.sample_towards(v(0.1, 0.2, 0.3), [x, x]);
        }
    }
    let set = LightSet::new(zoo().into_iter().map(|(_, l)| l).collect()).unwrap();
    for &x in &bad {
        let (id, pmf, remapped) = set.sample_light(x);
        assert!(set.light(id).is_some() && pmf > 0.0 && (0.0..1.0).contains(&remapped), "{x}");
        let _ = set.sample_towards(v(0.1, 0.2, 0.3), [x, x]);
    }
}

#[test]
fn light_set_sample_light_follows_its_pmf() {
    let imp = WavelengthSampling::Importance;
    let lights: Vec<Box<dyn LightSource>> = vec![
        Box::new(PointLight::new(DVec3::ZERO, 1.0, d65(), imp).unwrap()),
        Box::new(PointLight::new(DVec3::ZERO, 0.0, d65(), imp).unwrap()),
        Box::new(Laser::new(DVec3::ZERO, DVec3::X, 2.0, d65(), 0.0, imp).unwrap()),
        Box::new(DiskLight::new(DVec3::ZERO, DVec3::Z, 1.0, 7.0, d65(), false, imp).unwrap()),
    ];
    let set = LightSet::new(lights).unwrap();
    let pmf: Vec<f64> = (0..4).map(|i| set.pmf(LightId(i))).collect();
    for (p, exact) in pmf.iter().zip([0.1, 0.0, 0.2, 0.7]) {
        assert!(close(*p, exact, 1e-15), "{pmf:?}");
    }
    assert_eq!(set.pmf(LightId(9)), 0.0);
    let mut rng = Pcg64::seed_from_u64(10);
    let mut counts = [0u64; 4];
    let mut remapped = Vec::with_capacity(N);
    for _ in 0..N {
        let (id, p, r) = set.sample_light(uniform(&mut rng));
        assert_eq!(p, pmf[id.0 as usize]);
        counts[id.0 as usize] += 1;
        remapped.push(r);
    }
    let expected: Vec<f64> = pmf.iter().map(|p| p * N as f64).collect();
    let p = chi_square(&counts, &expected, 5.0).p_value;
    assert!(p > ALPHA, "light choice {counts:?} vs {expected:?}: p = {p}");
    // The remapped uniform is a fresh uniform.
    let p = chi_square(&histogram(remapped, 0.0, 1.0, 50), &[N as f64 / 50.0; 50], 5.0).p_value;
    assert!(p > ALPHA, "remapped uniform: p = {p}");
    // The set itself keeps the defaults: ask the chosen light.
    assert!(set.sample_emission([0.5; 4]).is_none());
    assert!(set.pdf_emission(DVec3::ZERO, DVec3::Z).is_none());
    assert!(set.surface().is_none());
    assert_eq!(set.pdf_towards(v(0.0, 0.0, 1.0), DVec3::ZERO), 0.0);
    assert_eq!(set.emitted_radiance(DVec3::ZERO, DVec3::Z), 0.0);
    assert!(set.light(LightId(3)).unwrap().surface().is_some());
}

/// Every light of the zoo with a [`spectrace_lights::LightBounds`] bounds what it emits: its
/// emission points lie in the box, and wherever it sends light (a positive `sample_towards`)
/// the bound's importance is positive, so that a light tree never misses light it could find.
/// Unbounded lights (lasers, skies) say so.
#[test]
fn light_bounds_hold_what_the_light_emits() {
    let mut rng = Pcg64::seed_from_u64(21);
    for (name, light) in zoo() {
        let Some(bounds) = light.light_bounds() else {
            assert!(name.contains("Laser") || name.contains("Sky"), "{name} has no bounds");
            continue;
        };
        assert!(bounds.is_valid(), "{name}: {bounds:?}");
        let slack = 1e-9 * (1.0 + bounds.max.abs().max_element());
        for _ in 0..2000 {
            if let Some(e) = light.sample_emission(uniforms(&mut rng)) {
                let p = e.position;
                assert!(
                    p.cmpge(bounds.min - slack).all() && p.cmple(bounds.max + slack).all(),
                    "{name}: {p} outside {bounds:?}"
                );
            }
            // Receivers anywhere within 3 m.
            let u = uniforms(&mut rng);
            let receiver = v(6.0 * u[0] - 3.0, 6.0 * u[1] - 3.0, 6.0 * u[2] - 3.0);
            let Some(s) = light.sample_towards(receiver, [u[3], u[0]]) else { continue };
            if s.intensity > 0.0 {
                assert!(bounds.importance(receiver) > 0.0, "{name}: {receiver} is lit");
                // On a surface through the receiver, lit unless the light lies in its plane.
                let normal = v(u[1] - 0.5, u[2] - 0.5, u[0] - 0.5).normalize();
                if s.direction.dot(normal).abs() > 1e-9 {
                    let prepared = bounds.prepare();
                    assert!(
                        prepared.importance_at(receiver, normal) > 0.0,
                        "{name}: {receiver} {normal}"
                    );
                }
            }
        }
    }
}
