//! Indices of refraction: the catalog against published values, the laws, dispersion in
//! refraction, and validation.

use glam::DVec3;
use spectrace_materials::{
    Dielectric, FRAUNHOFER_C_NM, FRAUNHOFER_D_NM, FRAUNHOFER_F_NM, GLASSES, Incoming, Ior,
    Material, MaterialError, find_glass,
};

use crate::{at_angle, sin_to};

#[test]
fn catalog_glasses_reproduce_their_published_n_d_and_abbe_number() {
    for glass in GLASSES {
        let ior = Ior::glass(glass.name).unwrap();
        let n_d = ior.n(FRAUNHOFER_D_NM);
        let abbe = ior.abbe_number().unwrap();
        println!(
            "{:12} n_d = {n_d:.5} (published {}), V_d = {abbe:.2} (published {})",
            glass.name, glass.n_d, glass.abbe_d
        );
        assert!((n_d - glass.n_d).abs() < 1e-4, "{}: n_d {n_d} vs {}", glass.name, glass.n_d);
        assert!(
            (abbe - glass.abbe_d).abs() < 0.1,
            "{}: V_d {abbe} vs {}",
            glass.name,
            glass.abbe_d
        );
    }
    let published = [("N-BK7", 1.5168), ("FusedSilica", 1.4585), ("F2", 1.6200), ("SF11", 1.7847)];
    for (name, n_d) in published {
        assert!((Ior::glass(name).unwrap().n(587.56) - n_d).abs() < 1e-4, "{name}");
    }
}

#[test]
fn bk7_and_fused_silica_at_the_f_and_c_lines() {
    let bk7 = Ior::glass("BK7").unwrap();
    assert!((bk7.n(486.13) - 1.52238).abs() < 2e-5, "{}", bk7.n(486.13));
    assert!((bk7.n(656.27) - 1.51432).abs() < 2e-5, "{}", bk7.n(656.27));
    let silica = Ior::glass("fused silica").unwrap();
    assert!((silica.n(486.13) - 1.46313).abs() < 2e-5, "{}", silica.n(486.13));
    assert!((silica.n(656.27) - 1.45637).abs() < 2e-5, "{}", silica.n(656.27));
    // Blue and red ends, for the record: BK7 at 450 and 650 nm (refractiveindex.info: 1.5253,
    // 1.5145).
    assert!((bk7.n(450.0) - 1.5253).abs() < 1e-4, "{}", bk7.n(450.0));
    assert!((bk7.n(650.0) - 1.5145).abs() < 1e-4, "{}", bk7.n(650.0));
    // The Fraunhofer constants are the lines' wavelengths.
    assert!((FRAUNHOFER_F_NM - 486.13).abs() < 0.01 && (FRAUNHOFER_C_NM - 656.27).abs() < 0.01);
}

#[test]
fn glasses_have_normal_dispersion_over_the_visible() {
    for glass in GLASSES {
        let ior = Ior::glass(glass.name).unwrap();
        assert!(ior.is_dispersive());
        let mut previous = f64::INFINITY;
        for k in 0..=470 {
            let n = ior.n(360.0 + k as f64);
            assert!(n < previous && n > 1.0, "{} at {} nm", glass.name, 360 + k);
            previous = n;
        }
    }
    assert!(find_glass("n-bk7").is_some() && find_glass("sio2").is_some());
}

#[test]
fn cauchy_and_table_laws() {
    // A Cauchy fit of BK7 (A = 1.5046, B = 4200 nm^2): close to the Sellmeier law near n_d.
    let cauchy = Ior::cauchy(1.5046, 4200.0, 0.0).unwrap();
    assert!((cauchy.n(587.56) - 1.5168).abs() < 1e-3);
    assert_eq!(cauchy.n(500.0), 1.5046 + 4200.0 / 250_000.0);
    let with_c = Ior::cauchy(1.5, 0.0, 1e9).unwrap();
    assert!((with_c.n(500.0) - (1.5 + 1e9 / 6.25e10)).abs() < 1e-15);
    assert!(!Ior::cauchy(1.5, 0.0, 0.0).unwrap().is_dispersive());
    let table = Ior::table(&[400.0, 500.0, 700.0], &[1.53, 1.52, 1.51]).unwrap();
    assert!((table.n(450.0) - 1.525).abs() < 1e-15);
    assert!((table.n(600.0) - 1.515).abs() < 1e-15);
    assert!(table.is_dispersive());
    let abbe = table.abbe_number().unwrap();
    assert!(abbe.is_finite() && abbe > 0.0);
    assert_eq!(Ior::constant(1.5).unwrap().abbe_number(), None);
}

/// Refraction angle inside a dispersive block for a beam entering at 60 degrees.
fn refraction_sine(material: &dyn Material, lambda: f64) -> f64 {
    let incoming = Incoming {
        direction: at_angle(60f64.to_radians(), DVec3::Y, DVec3::X),
        normal: DVec3::Y,
        lambda,
    };
    let out = material.scatter(&incoming, [0.999, 0.0, 0.0]).unwrap();
    assert!(out.direction.y < 0.0, "refracted into the block");
    sin_to(out.direction, DVec3::Y)
}

#[test]
fn dispersion_bends_blue_more_than_red() {
    let flint = Dielectric::glass("SF11").unwrap();
    assert!(flint.is_dispersive() && flint.is_specular());
    let blue = refraction_sine(&flint, 450.0);
    let red = refraction_sine(&flint, 650.0);
    assert!(blue < red, "blue bends more: sin {blue} vs {red}");
    let ior = flint.ior();
    assert!((blue * ior.n(450.0) - 60f64.to_radians().sin()).abs() < 1e-12);
    assert!((red * ior.n(650.0) - 60f64.to_radians().sin()).abs() < 1e-12);
    let plain = Dielectric::new(Ior::constant(1.5).unwrap(), None);
    assert!(!plain.is_dispersive());
    assert_eq!(refraction_sine(&plain, 450.0), refraction_sine(&plain, 650.0));
}

fn field_of(error: &MaterialError) -> String {
    error.field_path()
}

#[test]
fn bad_indices_are_rejected_by_field() {
    let e = Ior::sellmeier(&[1.0, 0.2, 1.0], &[0.006, 0.02, 0.25]).unwrap_err();
    assert_eq!(field_of(&e), "Ior.sellmeier.c[2]");
    assert!(e.to_string().contains("pole at 500.0 nm"), "{e}");
    let e = Ior::sellmeier(&[1.0, f64::NAN], &[0.006, 0.02]).unwrap_err();
    assert_eq!(field_of(&e), "Ior.sellmeier.b[1]");
    let e = Ior::sellmeier(&[1.0, 0.2], &[0.006]).unwrap_err();
    assert_eq!(field_of(&e), "Ior.sellmeier.c");
    // Negative B: n^2 < 1 over the visible.
    let e = Ior::sellmeier(&[-0.5], &[0.01]).unwrap_err();
    assert_eq!(field_of(&e), "Ior.sellmeier");
    assert!(e.to_string().contains(">= 1"), "{e}");
    let e = Ior::cauchy(0.9, 0.0, 0.0).unwrap_err();
    assert_eq!(field_of(&e), "Ior.cauchy");
    let e = Ior::cauchy(1.5, f64::INFINITY, 0.0).unwrap_err();
    assert_eq!(field_of(&e), "Ior.cauchy.b");
    let e = Ior::table(&[400.0, 500.0], &[1.5, 0.99]).unwrap_err();
    assert_eq!(field_of(&e), "Ior.table.n[1]");
    let e = Ior::table(&[400.0, 400.0], &[1.5, 1.5]).unwrap_err();
    assert_eq!(field_of(&e), "Ior.table.nm[1]");
    let e = Ior::table(&[], &[]).unwrap_err();
    assert_eq!(field_of(&e), "Ior.table.nm");
    let e = Ior::constant(0.5).unwrap_err();
    assert_eq!(field_of(&e), "Ior");
    let e = Ior::glass("unobtainium").unwrap_err();
    assert_eq!(field_of(&e), "Ior.glass");
    assert!(e.to_string().contains("N-BK7") && e.to_string().contains("SF11"), "{e}");
    let e = Dielectric::glass("BK-7").unwrap_err();
    assert_eq!(field_of(&e), "Dielectric.ior.glass");
}
