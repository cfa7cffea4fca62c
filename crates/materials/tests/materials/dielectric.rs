//! The dielectric: Fresnel branch frequencies, energy, geometry of both sides, total internal
//! reflection, transmittance and radiance scaling.

use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_materials::spectrum::Transmittance;
use spectrace_materials::{
    Dielectric, Incoming, Ior, Material, ScatterKind, Transport, fresnel_dielectric,
};
use spectrace_sampling::stats::chi_square;

use crate::{ALPHA, at_angle, beam, sin_to, uniform};

fn glass(n: f64) -> Dielectric {
    Dielectric::new(Ior::constant(n).unwrap(), None)
}

#[test]
fn reflection_is_chosen_with_probability_f_and_r_plus_t_is_one() {
    let material = glass(1.5);
    let mut rng = Pcg64::seed_from_u64(31);
    for (degrees, entering) in
        [(0.0, true), (45.0, true), (80.0, true), (89.0, true), (30.0, false), (41.0, false)]
    {
        let theta = f64::to_radians(degrees);
        let normal = DVec3::new(0.2, 1.0, 0.1).normalize();
        let tangent = normal.cross(DVec3::Z).normalize();
        let d = at_angle(theta, normal, tangent);
        let d = if entering { d } else { d - 2.0 * d.dot(normal) * normal };
        let incoming = beam(d, normal, 550.0);
        let f = material.reflectance(incoming.direction, normal, 550.0);
        let expected_f = if entering {
            fresnel_dielectric(theta.cos(), 1.5)
        } else {
            fresnel_dielectric(theta.cos(), 1.0 / 1.5)
        };
        assert!((f - expected_f).abs() < 1e-12);
        const N: u64 = 200_000;
        let (mut reflected, mut weight) = (0u64, 0.0);
        for _ in 0..N {
            let s = material.scatter(&incoming, [uniform(&mut rng), 0.5, 0.5]).unwrap();
            weight += s.weight;
            assert_eq!(s.kind, ScatterKind::Specular);
            assert_eq!(s.pdf, 0.0);
            if s.direction.dot(normal) * d.dot(normal) < 0.0 {
                reflected += 1;
            }
        }
        // Each branch carries weight 1: R + T = F + (1 - F) = 1 in expectation, exactly.
        assert_eq!(weight, N as f64, "{degrees} deg");
        let expected = [f * N as f64, (1.0 - f) * N as f64];
        let chi = chi_square(&[reflected, N - reflected], &expected, 5.0);
        assert!(
            chi.p_value > ALPHA,
            "{degrees} deg entering {entering}: F {f}, {reflected}/{N}: {chi:?}"
        );
    }
}

#[test]
fn branch_is_decided_by_u0_against_f() {
    let material = glass(1.5);
    let d = at_angle(0.7, DVec3::Y, DVec3::X);
    let incoming = beam(d, DVec3::Y, 550.0);
    let f = fresnel_dielectric(0.7f64.cos(), 1.5);
    let below = material.scatter(&incoming, [f * 0.999_999, 0.0, 0.0]).unwrap();
    assert!(below.direction.y > 0.0, "u < F reflects");
    assert!((below.direction - DVec3::new(d.x, -d.y, d.z)).length() < 1e-15);
    let above = material.scatter(&incoming, [f, 0.0, 0.0]).unwrap();
    assert!(above.direction.y < 0.0, "u >= F refracts");
}

#[test]
fn refraction_crosses_the_surface_with_snells_law_from_both_sides() {
    let n = 1.5;
    let material = glass(n);
    for k in 0..90 {
        let theta = f64::to_radians(k as f64);
        // Entering: from outside (normal side) into the glass.
        let d = at_angle(theta, DVec3::Y, DVec3::X);
        let s = material.scatter(&beam(d, DVec3::Y, 500.0), [0.999_999, 0.0, 0.0]).unwrap();
        assert!(s.direction.y < 0.0, "entering {k}: crosses to the inside");
        assert!((sin_to(d, DVec3::Y) - n * sin_to(s.direction, DVec3::Y)).abs() < 1e-12);
        // Leaving: from inside (against the normal) out.
        let critical = (1.0 / n).asin();
        let inside = DVec3::new(d.x, -d.y, d.z);
        let s = material.scatter(&beam(inside, DVec3::Y, 500.0), [0.999_999, 0.0, 0.0]).unwrap();
        if theta < critical - 1e-9 {
            assert!(s.direction.y > 0.0, "leaving {k}: crosses to the outside");
            assert!((n * sin_to(inside, DVec3::Y) - sin_to(s.direction, DVec3::Y)).abs() < 1e-12);
        } else if theta > critical {
            // Total internal reflection: reflected back inside with weight 1 for every u.
            for u in [0.0, 0.5, 1.0 - f64::EPSILON / 2.0] {
                let s = material.scatter(&beam(inside, DVec3::Y, 500.0), [u, 0.0, 0.0]).unwrap();
                assert!(s.direction.y < 0.0, "TIR at {k} deg");
                assert_eq!(s.weight, 1.0);
                assert!((s.direction - DVec3::new(inside.x, -inside.y, inside.z)).length() < 1e-15);
            }
        }
    }
}

#[test]
fn a_parallel_slab_returns_the_original_direction() {
    let material = Dielectric::glass("F2").unwrap();
    for k in 0..90 {
        let d =
            at_angle(f64::to_radians(k as f64), DVec3::Y, DVec3::new(1.0, 0.0, 1.0).normalize());
        // Top face (normal +y), then bottom face (normal -y), both transmitting.
        let inside = material.scatter(&beam(d, DVec3::Y, 480.0), [0.999_999, 0.0, 0.0]).unwrap();
        let out = material
            .scatter(
                &Incoming { direction: inside.direction, normal: DVec3::NEG_Y, lambda: 480.0 },
                [0.999_999, 0.0, 0.0],
            )
            .unwrap();
        assert!((out.direction - d).length() < 1e-12, "{k} deg");
    }
}

#[test]
fn transmittance_tints_refraction_only_and_radiance_scales_by_eta_squared() {
    let tint = Transmittance::from_table(&[400.0, 700.0], &[0.5, 1.0]).unwrap();
    let material = Dielectric::new(Ior::constant(1.5).unwrap(), Some(tint));
    let entering = beam(DVec3::NEG_Y, DVec3::Y, 400.0);
    let t = material.scatter(&entering, [0.5, 0.0, 0.0]).unwrap();
    assert_eq!(t.weight, 0.5);
    let r = material.scatter(&entering, [0.0, 0.0, 0.0]).unwrap();
    assert_eq!(r.weight, 1.0);
    let radiance = material.scatter_with(&entering, [0.5, 0.0, 0.0], Transport::Radiance).unwrap();
    assert!((radiance.weight - 0.5 / 2.25).abs() < 1e-15);
    let leaving = beam(DVec3::NEG_Y, DVec3::NEG_Y, 700.0);
    let radiance = material.scatter_with(&leaving, [0.5, 0.0, 0.0], Transport::Radiance).unwrap();
    assert!((radiance.weight - 2.25).abs() < 1e-15);
    assert_eq!(material.scatter_with(&leaving, [0.0; 3], Transport::Radiance).unwrap().weight, 1.0);
    assert_eq!(
        material.scatter_with(&entering, [0.5; 3], Transport::Importance),
        material.scatter(&entering, [0.5; 3])
    );
    let opaque =
        Dielectric::new(Ior::constant(1.5).unwrap(), Some(Transmittance::constant(0.0).unwrap()));
    assert_eq!(opaque.scatter(&entering, [0.5, 0.0, 0.0]), None);
}

#[test]
fn normal_and_grazing_incidence_are_finite() {
    let material = Dielectric::glass("SF11").unwrap();
    for normal in [DVec3::Y, DVec3::NEG_Y] {
        for d in [
            DVec3::NEG_Y,
            DVec3::Y,
            DVec3::X,
            DVec3::new(1.0, -1e-300, 0.0),
            DVec3::new(1.0, 1e-17, 0.0).normalize(),
        ] {
            for u in [0.0, 0.04, 0.5, 1.0 - f64::EPSILON / 2.0] {
                let s = material
                    .scatter(&Incoming { direction: d, normal, lambda: 550.0 }, [u; 3])
                    .unwrap();
                assert!(s.direction.is_finite() && (s.direction.length() - 1.0).abs() < 1e-15);
                assert!(s.weight.is_finite());
            }
        }
    }
    // Exactly at normal incidence the refracted beam goes straight through.
    let s = material.scatter(&beam(DVec3::NEG_Y, DVec3::Y, 550.0), [0.9, 0.0, 0.0]).unwrap();
    assert_eq!(s.direction, DVec3::NEG_Y);
}
