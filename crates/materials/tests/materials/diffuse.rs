//! The Lambertian lobe: weights, the cosine distribution, eval/pdf consistency, two-sidedness.

use std::f64::consts::{PI, TAU};

use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_materials::spectrum::Reflectance;
use spectrace_materials::{Diffuse, Material, ScatterKind};
use spectrace_sampling::stats::{chi_square, histogram, kolmogorov_smirnov};

use crate::{ALPHA, beam, random_unit, uniform};

fn white() -> Diffuse {
    Diffuse::new(Reflectance::constant(1.0).unwrap())
}

/// Polar coordinates `(cos^2 theta, phi / 2 pi)` of `d` in a frame around `n`: both uniform on
/// `[0, 1)` for a cosine-distributed direction.
fn cosine_coordinates(d: DVec3, n: DVec3) -> (f64, f64) {
    let helper = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let t = n.cross(helper).normalize();
    let b = n.cross(t);
    let cos = d.dot(n);
    let phi = d.dot(b).atan2(d.dot(t)).rem_euclid(TAU) / TAU;
    (cos * cos, phi)
}

#[test]
fn white_lambertian_conserves_energy_and_is_cosine_distributed() {
    let material = white();
    let mut rng = Pcg64::seed_from_u64(11);
    // Beams from the front and from the back of a tilted surface (two-sided).
    let normal = DVec3::new(0.3, 0.8, -0.5).normalize();
    for (label, direction, facing) in [
        ("front", DVec3::new(0.1, -1.0, 0.2), normal),
        ("back", DVec3::new(-0.4, 1.0, 0.1), -normal),
    ] {
        let incoming = beam(direction, normal, 550.0);
        const N: usize = 200_000;
        const BINS: usize = 20;
        let mut cells = vec![0u64; BINS * BINS];
        let mut cos2 = Vec::with_capacity(N);
        let mut weight_sum = 0.0;
        for _ in 0..N {
            let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
            let s = material.scatter(&incoming, u).unwrap();
            assert_eq!(s.kind, ScatterKind::Diffuse);
            assert!(s.direction.dot(facing) > 0.0, "{label}: scattered to the beam's side");
            weight_sum += s.weight;
            let (c2, phi) = cosine_coordinates(s.direction, facing);
            let i = ((c2 * BINS as f64) as usize).min(BINS - 1);
            let j = ((phi * BINS as f64) as usize).min(BINS - 1);
            cells[i * BINS + j] += 1;
            cos2.push(c2);
        }
        assert_eq!(weight_sum / N as f64, 1.0, "{label}: white Lambertian weight");
        let expected = vec![N as f64 / (BINS * BINS) as f64; BINS * BINS];
        let chi = chi_square(&cells, &expected, 5.0);
        assert!(chi.p_value > ALPHA, "{label}: chi-square {chi:?}");
        let ks = kolmogorov_smirnov(cos2.clone(), |x| x.clamp(0.0, 1.0));
        assert!(ks.p_value > ALPHA, "{label}: KS {ks:?}");
        // The same with the harness's 1-D histogram of cos^2 theta.
        let counts = histogram(cos2, 0.0, 1.0, 50);
        let chi = chi_square(&counts, &[N as f64 / 50.0; 50], 5.0);
        assert!(chi.p_value > ALPHA, "{label}: cos^2 histogram {chi:?}");
    }
}

#[test]
fn pdf_integrates_to_one_and_matches_scatter() {
    let material = Diffuse::new(Reflectance::from_table(&[400.0, 700.0], &[0.2, 0.9]).unwrap());
    let normal = DVec3::new(-0.2, 0.5, 0.9).normalize();
    let wi = DVec3::new(0.4, 0.3, 0.8).normalize();
    // Midpoint rule over the whole sphere in (cos theta, phi) about the z axis.
    let (nu, nphi) = (4000, 64);
    let mut integral = 0.0;
    for i in 0..nu {
        let z = -1.0 + 2.0 * (i as f64 + 0.5) / nu as f64;
        let r = (1.0 - z * z).sqrt();
        for j in 0..nphi {
            let phi = TAU * (j as f64 + 0.5) / nphi as f64;
            let wo = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            integral += material.pdf(wi, wo, normal, 500.0);
        }
    }
    integral *= 2.0 / nu as f64 * TAU / nphi as f64;
    assert!((integral - 1.0).abs() < 1e-4, "pdf integrates to {integral}");

    let mut rng = Pcg64::seed_from_u64(12);
    for _ in 0..10_000 {
        let n = random_unit(&mut rng);
        let d = random_unit(&mut rng);
        let lambda = 380.0 + 400.0 * uniform(&mut rng);
        let s = material
            .scatter(&beam(d, n, lambda), [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)])
            .unwrap();
        let wi = -d;
        let wo = s.direction;
        let f = material.eval(wi, wo, n, lambda);
        let pdf = material.pdf(wi, wo, n, lambda);
        assert!((pdf - s.pdf).abs() <= 1e-12 * pdf.max(1.0), "pdf {pdf} vs {}", s.pdf);
        let w = f * wo.dot(n).abs() / pdf;
        assert!((w - s.weight).abs() < 1e-12, "f cos / pdf = {w}, weight {}", s.weight);
        // Reciprocity of the BSDF, and no light through the surface.
        assert_eq!(material.eval(wo, wi, n, lambda), f);
        assert_eq!(material.eval(wi, -wo, n, lambda), 0.0);
        assert_eq!(material.pdf(wi, -wo, n, lambda), 0.0);
    }
}

#[test]
fn eval_is_albedo_over_pi_on_both_sides() {
    let material = Diffuse::new(Reflectance::constant(0.6).unwrap());
    let n = DVec3::Y;
    let a = DVec3::new(0.6, 0.8, 0.0);
    let b = DVec3::new(-0.8, 0.6, 0.0);
    assert!((material.eval(a, b, n, 500.0) - 0.6 / PI).abs() < 1e-16);
    assert!((material.eval(-a, -b, n, 500.0) - 0.6 / PI).abs() < 1e-16);
    assert!((material.pdf(-a, -b, n, 500.0) - 0.6 / PI).abs() < 1e-16);
    assert!(!material.is_specular() && !material.is_dispersive());
}

#[test]
fn colour_depends_on_wavelength_and_black_absorbs() {
    // A red paint: dark in the blue, bright in the red.
    let red = Diffuse::new(
        Reflectance::from_table(&[400.0, 550.0, 600.0, 700.0], &[0.05, 0.05, 0.7, 0.8]).unwrap(),
    );
    let incoming = |lambda| beam(DVec3::new(0.0, -1.0, 0.0), DVec3::Y, lambda);
    assert_eq!(red.scatter(&incoming(450.0), [0.5; 3]).unwrap().weight, 0.05);
    assert!((red.scatter(&incoming(650.0), [0.5; 3]).unwrap().weight - 0.75).abs() < 1e-15);
    let black = Diffuse::new(Reflectance::constant(0.0).unwrap());
    assert_eq!(black.scatter(&incoming(550.0), [0.5; 3]), None);
}

#[test]
fn normal_and_grazing_incidence_and_edge_uniforms() {
    let material = white();
    let n = DVec3::Y;
    for d in [DVec3::new(0.0, -1.0, 0.0), DVec3::X, DVec3::new(1.0, -1e-300, 0.0).normalize()] {
        for u in [0.0, 0.5, 1.0 - f64::EPSILON / 2.0, 1.0, f64::NAN, -1.0] {
            let s = material.scatter(&beam(d, n, 550.0), [u, u, u]).unwrap();
            assert!((s.direction.length() - 1.0).abs() < 1e-15);
            assert!(s.pdf > 0.0 && s.pdf.is_finite(), "u {u}: pdf {}", s.pdf);
            assert!(s.direction.dot(n).abs() > 0.0);
        }
    }
}
