//! Bundles: `scatter_bundle` and `eval_bundle` overrides give exactly (bit for bit) what the
//! general per-wavelength way gives, for every material, both transports, dead and absorbed
//! wavelengths included.

use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_materials::spectrum::{Reflectance, Transmittance};
use spectrace_materials::{
    ComplexIor, Conductor, Dielectric, Diffuse, Ior, Material, Mirror, RoughConductor, Transport,
    scatter_each,
};

use crate::{random_unit, uniform};

/// Materials whose albedo or transmittance is 0 over part of the range, so that some
/// wavelengths of a bundle are absorbed while others go on.
fn materials() -> Vec<Box<dyn Material>> {
    let ramp = Reflectance::from_table(&[400.0, 550.0, 700.0], &[0.0, 0.0, 0.9]).unwrap();
    let t = Transmittance::from_table(&[400.0, 550.0, 700.0], &[0.0, 0.5, 1.0]).unwrap();
    vec![
        Box::new(Diffuse::new(ramp.clone())),
        Box::new(Diffuse::new(Reflectance::constant(0.7).unwrap())),
        Box::new(Mirror::new(ramp.clone())),
        Box::new(Dielectric::new(Ior::constant(1.5).unwrap(), None)),
        Box::new(Dielectric::new(Ior::constant(1.7).unwrap(), Some(t.clone()))),
        // Dispersive: falls back to the general way, companions dropped on refraction.
        Box::new(Dielectric::new(Ior::glass("SF11").unwrap(), Some(t))),
        Box::new(Conductor::metal("Au").unwrap()),
        Box::new(Conductor::new(ComplexIor::metal("Cu").unwrap(), Some(ramp.clone()))),
        Box::new(RoughConductor::metal("Ag", 0.0).unwrap()),
        Box::new(RoughConductor::metal("Au", 0.3).unwrap()),
        Box::new(
            RoughConductor::isotropic(ComplexIor::metal("Cr").unwrap(), 0.8, Some(ramp.clone()))
                .unwrap(),
        ),
        Box::new(
            RoughConductor::new(ComplexIor::metal("Ti").unwrap(), 0.05, 0.5, Some(ramp.clone()))
                .unwrap(),
        ),
    ]
}

#[test]
fn scatter_bundle_matches_scattering_each_wavelength() {
    let mut rng = Pcg64::seed_from_u64(41);
    let mut scattered = 0;
    for m in materials() {
        for trial in 0..4000 {
            let direction = random_unit(&mut rng);
            let normal = random_unit(&mut rng);
            let lambdas: Vec<f64> = (0..4).map(|_| 380.0 + 400.0 * uniform(&mut rng)).collect();
            // Some wavelengths already dead (weight 0) on arrival.
            let weights: Vec<f64> =
                (0..4).map(|j| if (trial + j) % 5 == 0 { 0.0 } else { 0.25 }).collect();
            let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
            for transport in [Transport::Importance, Transport::Radiance] {
                let (mut a, mut b) = (weights.clone(), weights.clone());
                let fast = m.scatter_bundle(direction, normal, &lambdas, &mut a, u, transport);
                let each =
                    scatter_each(m.as_ref(), direction, normal, &lambdas, &mut b, u, transport);
                assert_eq!(fast, each, "{m:?} {direction} {normal} {lambdas:?} {u:?}");
                assert_eq!(a, b, "{m:?} weights");
                scattered += usize::from(fast.is_some());
            }
        }
    }
    // The comparison is not vacuous: most bundles scatter.
    assert!(scattered > 12 * 2 * 4000 / 2, "{scattered}");
}

#[test]
fn eval_bundle_matches_evaluating_each_wavelength() {
    let mut rng = Pcg64::seed_from_u64(43);
    for m in materials() {
        for _ in 0..2000 {
            let (wi, wo, n) = (random_unit(&mut rng), random_unit(&mut rng), random_unit(&mut rng));
            let lambdas: Vec<f64> = (0..4).map(|_| 380.0 + 400.0 * uniform(&mut rng)).collect();
            for transport in [Transport::Importance, Transport::Radiance] {
                let mut out = [f64::NAN; 4];
                m.eval_bundle(wi, wo, n, &lambdas, transport, &mut out);
                let each: Vec<f64> =
                    lambdas.iter().map(|&l| m.eval_with(wi, wo, n, l, transport)).collect();
                assert_eq!(out.to_vec(), each, "{m:?}");
            }
        }
    }
}

#[test]
fn a_bundle_with_no_live_wavelength_does_not_scatter() {
    for m in materials() {
        let mut w = [0.0; 4];
        let out = m.scatter_bundle(
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::Y,
            &[450.0, 500.0, 600.0, 650.0],
            &mut w,
            [0.5; 3],
            Transport::Importance,
        );
        assert!(out.is_none(), "{m:?}");
        assert_eq!(w, [0.0; 4]);
    }
}
