//! Property tests: for random directions, normals, wavelengths and uniforms (including the edge
//! uniforms 0 and 1 - 2^-53) every material returns finite weights and unit directions on the
//! right side of the surface.

use glam::DVec3;
use proptest::prelude::*;
use spectrace_materials::spectrum::Reflectance;
use spectrace_materials::{
    Dielectric, Diffuse, Incoming, Ior, Material, Mirror, ScatterKind, Transport,
};
use spectrace_sampling::ONE_MINUS_EPSILON;

use crate::{sin_to, sphere};

fn uniform01() -> impl Strategy<Value = f64> {
    prop_oneof![1 => Just(0.0), 1 => Just(ONE_MINUS_EPSILON), 6 => 0.0..1.0]
}

fn unit() -> impl Strategy<Value = DVec3> {
    (uniform01(), uniform01()).prop_map(|(u, v)| sphere(u, v))
}

fn wavelength() -> impl Strategy<Value = f64> {
    prop_oneof![4 => 360.0..830.0, 1 => 100.0..3000.0, 1 => Just(360.0), 1 => Just(830.0)]
}

fn materials() -> Vec<(Box<dyn Material>, Option<Ior>)> {
    let tinted = Reflectance::from_table(&[400.0, 700.0], &[0.0, 1.0]).unwrap();
    let iors = [
        Ior::constant(1.5).unwrap(),
        Ior::constant(1.0).unwrap(),
        Ior::glass("BK7").unwrap(),
        Ior::glass("SF11").unwrap(),
        Ior::glass("FusedSilica").unwrap(),
        Ior::cauchy(1.3, 1e4, 1e9).unwrap(),
        Ior::table(&[400.0, 700.0], &[2.4, 2.3]).unwrap(),
    ];
    let mut all: Vec<(Box<dyn Material>, Option<Ior>)> = vec![
        (Box::new(Diffuse::new(Reflectance::constant(1.0).unwrap())), None),
        (Box::new(Diffuse::new(tinted.clone())), None),
        (Box::new(Mirror::new(tinted.clone())), None),
    ];
    for ior in iors {
        all.push((Box::new(Dielectric::new(ior.clone(), None)), Some(ior.clone())));
        all.push((Box::new(Dielectric::new(ior.clone(), Some(tinted.clone().into()))), Some(ior)));
    }
    all
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    #[test]
    fn scatter_is_finite_unit_and_on_the_right_side(
        direction in unit(),
        normal in unit(),
        lambda in wavelength(),
        u in [uniform01(), uniform01(), uniform01()],
        radiance in any::<bool>(),
    ) {
        let incoming = Incoming { direction, normal, lambda };
        let transport = if radiance { Transport::Radiance } else { Transport::Importance };
        for (material, ior) in materials() {
            let Some(s) = material.scatter_with(&incoming, u, transport) else { continue };
            prop_assert!(s.direction.is_finite(), "{material:?}: {s:?}");
            prop_assert!((s.direction.length() - 1.0).abs() < 1e-12, "{material:?}: {s:?}");
            prop_assert!(s.weight.is_finite() && s.weight > 0.0, "{material:?}: {s:?}");
            prop_assert!(s.pdf.is_finite() && s.pdf >= 0.0, "{material:?}: {s:?}");
            let d_n = direction.dot(normal);
            let o_n = s.direction.dot(normal);
            match s.kind {
                ScatterKind::Diffuse => {
                    prop_assert!(s.pdf > 0.0);
                    // Two-sided: back to the side the beam came from.
                    prop_assert!(o_n * d_n <= 0.0, "{material:?}: {s:?}");
                    prop_assert!(o_n != 0.0);
                }
                ScatterKind::Specular => {
                    prop_assert_eq!(s.pdf, 0.0);
                    if o_n * d_n > 0.0 {
                        // Refracted: Snell's law with the material's index.
                        let n = ior.as_ref().unwrap().n(lambda);
                        prop_assert!(n.is_finite() && n >= 1.0);
                        let (ni, nt) = if d_n < 0.0 { (1.0, n) } else { (n, 1.0) };
                        let lhs = ni * sin_to(direction, normal);
                        let rhs = nt * sin_to(s.direction, normal);
                        prop_assert!((lhs - rhs).abs() < 1e-12, "{material:?}: {lhs} vs {rhs}");
                    } else {
                        // Reflected: the mirror image.
                        prop_assert!((o_n + d_n).abs() < 1e-12, "{material:?}: {s:?}");
                    }
                }
            }
            let f = material.eval(-direction, s.direction, normal, lambda);
            let p = material.pdf(-direction, s.direction, normal, lambda);
            prop_assert!(f.is_finite() && f >= 0.0 && p.is_finite() && p >= 0.0);
        }
    }

    #[test]
    fn ior_is_finite_and_at_least_one_for_any_wavelength(lambda in -1e4..1e5f64) {
        for (_, ior) in materials() {
            if let Some(ior) = ior {
                let n = ior.n(lambda);
                prop_assert!(n.is_finite() && n >= 1.0, "{ior:?} at {lambda}: {n}");
            }
        }
    }
}
