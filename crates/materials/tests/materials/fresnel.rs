//! Fresnel reflectance against closed forms, and Snell's law.

use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_materials::{fresnel_dielectric, fresnel_dielectric_polarised, reflect, refract};

use crate::{random_unit, sin_to, uniform};

#[test]
fn normal_incidence_is_the_textbook_value() {
    for n in [1.0_f64, 1.000_293, 1.33, 1.5, 1.7847, 2.42, 4.0] {
        let expected = ((n - 1.0) / (n + 1.0)).powi(2);
        assert!((fresnel_dielectric(1.0, n) - expected).abs() < 1e-15, "n = {n}");
        // From the inside, at normal incidence, the same fraction.
        assert!((fresnel_dielectric(-1.0, n) - expected).abs() < 1e-15, "n = {n} inside");
        assert!((fresnel_dielectric(1.0, 1.0 / n) - expected).abs() < 1e-15, "n = {n} 1/eta");
    }
    assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-15);
}

#[test]
fn matches_the_angle_forms_of_the_fresnel_equations() {
    // R_s = sin^2(ti - tt) / sin^2(ti + tt), R_p = tan^2(ti - tt) / tan^2(ti + tt).
    for n in [1.33, 1.5, 2.0] {
        for k in 1..89 {
            let ti = (k as f64).to_radians();
            let tt = (ti.sin() / n).asin();
            let rs = ((ti - tt).sin() / (ti + tt).sin()).powi(2);
            let rp = ((ti - tt).tan() / (ti + tt).tan()).powi(2);
            let r = fresnel_dielectric_polarised(ti.cos(), n);
            assert!((r.s - rs).abs() < 1e-12, "n {n} angle {k}: {} vs {rs}", r.s);
            assert!((r.p - rp).abs() < 1e-12, "n {n} angle {k}: {} vs {rp}", r.p);
            assert!((fresnel_dielectric(ti.cos(), n) - 0.5 * (rs + rp)).abs() < 1e-12);
        }
    }
}

#[test]
fn brewster_angle_cancels_p_and_halves_s() {
    for n in [1.33, 1.5, 1.7847] {
        let brewster = f64::atan(n);
        let r = fresnel_dielectric_polarised(brewster.cos(), n);
        assert!(r.p < 1e-30, "R_p at Brewster = {}", r.p);
        // At Brewster ti + tt = 90 degrees, so R_s = sin^2(ti - tt) = cos^2(2 ti).
        let rs = (2.0 * brewster).cos().powi(2);
        assert!((r.s - rs).abs() < 1e-14, "R_s {} vs {rs}", r.s);
        assert!((fresnel_dielectric(brewster.cos(), n) - 0.5 * rs).abs() < 1e-14);
        // From inside, Brewster's angle is atan(1/n), and R_p vanishes there too.
        let inside = f64::atan(1.0 / n);
        assert!(fresnel_dielectric_polarised(-inside.cos(), n).p < 1e-30);
    }
    // Glass n = 1.5: 56.31 degrees, unpolarised R = 0.0740.
    assert!((fresnel_dielectric(f64::atan(1.5).cos(), 1.5) - 0.073_964).abs() < 1e-6);
}

#[test]
fn total_internal_reflection_beyond_the_critical_angle() {
    let n: f64 = 1.5;
    let critical = (1.0 / n).asin();
    for k in 0..=100 {
        let theta = critical + (std::f64::consts::FRAC_PI_2 - critical) * k as f64 / 100.0;
        // Light inside the glass: pbrt convention, cos < 0 means the far side.
        assert_eq!(fresnel_dielectric(-theta.cos(), n), 1.0, "theta {theta}");
        assert_eq!(fresnel_dielectric(theta.cos(), 1.0 / n), 1.0, "theta {theta}");
    }
    // Just inside the critical angle the reflectance is below 1 and approaches it.
    let just_below = fresnel_dielectric(-(critical - 1e-6).cos(), n);
    assert!(just_below < 1.0 && just_below > 0.99, "{just_below}");
    let mut previous = 0.0;
    for k in 0..1000 {
        let theta = critical * k as f64 / 1000.0;
        let f = fresnel_dielectric(-theta.cos(), n);
        assert!(f >= previous - 1e-15, "F not increasing towards the critical angle");
        previous = f;
    }
}

#[test]
fn reflectance_is_the_same_from_both_sides() {
    // F(theta_1 in medium 1) == F(theta_2 in medium 2) when theta_2 is the refraction angle.
    for n in [1.2, 1.5, 2.4] {
        // Up to 89 degrees: at exactly 90 the inside angle is the critical angle, where F has
        // a square-root singularity and any rounding of the angle is amplified (both are 1 there).
        assert_eq!(fresnel_dielectric(0.0, n), 1.0);
        assert!(fresnel_dielectric(-(1.0 - 1.0 / (n * n)).sqrt(), n) > 1.0 - 1e-6);
        for k in 0..90 {
            let t1 = (k as f64).to_radians();
            let t2 = (t1.sin() / n).asin();
            let outside = fresnel_dielectric(t1.cos(), n);
            let inside = fresnel_dielectric(-t2.cos(), n);
            assert!((outside - inside).abs() < 1e-12, "n {n}, {k} deg: {outside} vs {inside}");
            assert_eq!(fresnel_dielectric(-t1.cos(), n), fresnel_dielectric(t1.cos(), 1.0 / n));
        }
    }
}

#[test]
fn grazing_and_normal_incidence_are_finite() {
    for n in [1.0, 1.5, 4.0] {
        assert_eq!(fresnel_dielectric(0.0, n), 1.0);
        assert_eq!(fresnel_dielectric(-0.0, n), 1.0);
        for c in [1e-300, 1e-30, 1e-12, 1e-6, 1.0 - 1e-16, 1.0] {
            for cos in [c, -c] {
                let f = fresnel_dielectric(cos, n);
                assert!((0.0..=1.0).contains(&f), "F({cos}, {n}) = {f}");
            }
        }
    }
    // eta = 1 is no interface at all, except exactly at grazing.
    assert!(fresnel_dielectric(0.3, 1.0) < 1e-30);
}

#[test]
fn snell_holds_to_1e_12_and_refracted_directions_cross_the_surface() {
    let mut rng = Pcg64::seed_from_u64(7);
    let mut refracted = 0;
    for _ in 0..100_000 {
        let n = random_unit(&mut rng);
        let d = random_unit(&mut rng);
        let eta = 1.0 + 2.0 * uniform(&mut rng); // n_t / n_i in [1, 3)
        let eta = if uniform(&mut rng) < 0.5 { eta } else { 1.0 / eta };
        let Some(t) = refract(d, n, eta) else {
            // Total internal reflection only from the denser side, beyond the critical angle.
            assert!(eta < 1.0 && sin_to(d, n) * 1.0 >= eta - 1e-12);
            continue;
        };
        refracted += 1;
        assert!((t.length() - 1.0).abs() < 1e-14);
        // The same side of the surface as the beam travels to: d.n and t.n share a sign.
        assert!(t.dot(n) * d.dot(n) > 0.0 || d.dot(n) == 0.0);
        let lhs = sin_to(d, n);
        let rhs = eta * sin_to(t, n);
        assert!((lhs - rhs).abs() < 1e-12, "n_i sin_i {lhs} vs n_t sin_t {rhs}");
        // The refracted direction lies in the plane of incidence.
        assert!(t.dot(d.cross(n)).abs() < 1e-12);
    }
    assert!(refracted > 55_000, "{refracted}");
}

#[test]
fn reflection_keeps_the_angle_and_the_plane() {
    let mut rng = Pcg64::seed_from_u64(8);
    for _ in 0..10_000 {
        let n = random_unit(&mut rng);
        let d = random_unit(&mut rng);
        let r = reflect(d, n);
        assert!((r.length() - 1.0).abs() < 1e-14);
        assert!((r.dot(n) + d.dot(n)).abs() < 1e-14);
        assert!((r - d).cross(n).length() < 1e-14);
    }
    assert_eq!(reflect(DVec3::new(0.0, -1.0, 0.0), DVec3::Y), DVec3::Y);
}
