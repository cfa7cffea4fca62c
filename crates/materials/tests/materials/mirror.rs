//! The mirror: exact reflection, spectral weight, two-sidedness, delta lobe.

use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_materials::spectrum::Reflectance;
use spectrace_materials::{Material, Mirror, ScatterKind};

use crate::{beam, random_unit, uniform};

#[test]
fn reflects_exactly_with_the_reflectance_as_weight() {
    let gold =
        Mirror::new(Reflectance::from_table(&[450.0, 550.0, 650.0], &[0.38, 0.75, 0.95]).unwrap());
    let mut rng = Pcg64::seed_from_u64(21);
    for _ in 0..10_000 {
        let n = random_unit(&mut rng);
        let d = random_unit(&mut rng);
        let lambda = 400.0 + 300.0 * uniform(&mut rng);
        let s = gold.scatter(&beam(d, n, lambda), [uniform(&mut rng); 3]).unwrap();
        assert_eq!(s.kind, ScatterKind::Specular);
        assert_eq!(s.pdf, 0.0);
        assert_eq!(
            s.weight,
            Reflectance::from_table(&[450.0, 550.0, 650.0], &[0.38, 0.75, 0.95])
                .unwrap()
                .value(lambda)
        );
        // Angle of reflection equals angle of incidence, on the beam's own side (two-sided).
        assert!((s.direction.dot(n) + d.dot(n)).abs() < 1e-14);
        assert!((s.direction - (d - 2.0 * d.dot(n) * n)).length() < 1e-14);
        assert!((s.direction.length() - 1.0).abs() < 1e-15);
        assert_eq!(gold.eval(-d, s.direction, n, lambda), 0.0);
        assert_eq!(gold.pdf(-d, s.direction, n, lambda), 0.0);
    }
    assert!(gold.is_specular() && !gold.is_dispersive());
}

#[test]
fn back_side_reflects_on_the_beam_side_and_black_absorbs() {
    let mirror = Mirror::new(Reflectance::constant(1.0).unwrap());
    let from_behind = beam(DVec3::new(1.0, 1.0, 0.0), DVec3::Y, 550.0);
    let s = mirror.scatter(&from_behind, [0.0; 3]).unwrap();
    assert!((s.direction - DVec3::new(1.0, -1.0, 0.0).normalize()).length() < 1e-15);
    assert_eq!(s.weight, 1.0);
    let normal = mirror.scatter(&beam(DVec3::NEG_Y, DVec3::Y, 550.0), [0.0; 3]).unwrap();
    assert_eq!(normal.direction, DVec3::Y);
    let grazing = mirror.scatter(&beam(DVec3::X, DVec3::Y, 550.0), [0.0; 3]).unwrap();
    assert_eq!(grazing.direction, DVec3::X);
    let black = Mirror::new(Reflectance::constant(0.0).unwrap());
    assert_eq!(black.scatter(&from_behind, [0.0; 3]), None);
}
