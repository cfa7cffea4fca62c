//! What an eye sees of a measured luminaire (CIE 117's luminance and solid angle, from the
//! luminous opening of its IES or EULUMDAT file), and the luminaire's flux against its lamps'
//! (table lumens, lamp lumens, light output ratio).
#![allow(clippy::unwrap_used)]

use std::f64::consts::{FRAC_1_SQRT_2, PI};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use spectrace_lights::glam::DVec3;
use spectrace_lights::photometry::{IesFile, LdtFile};
use spectrace_lights::sampling::files::with_scene_folder;
use spectrace_lights::spectrum::{CieIlluminant, SpectralPowerDistribution};
use spectrace_lights::{
    EulumdatLight, GlareView, IesLight, LightSource, LuminousOpening, PointLight,
    WavelengthSampling,
};

/// Where the test luminaires hang (default orientation: nadir -y, C0 +x, so C90 is -z).
const POS: DVec3 = DVec3::new(0.0, 3.0, 0.0);

fn spd() -> Arc<dyn SpectralPowerDistribution> {
    Arc::new(CieIlluminant::new("A").unwrap())
}

/// An IES file: `version` line, `lamps` (`<lamps> <lumens per lamp> <candela multiplier>`),
/// photometric type `kind`, `dims` (`<units> <width> <length> <height>`), ballast factor, angles
/// and `rows[h][v]`.
#[allow(clippy::too_many_arguments)]
fn ies_with(
    version: &str,
    lamps: &str,
    kind: u32,
    dims: &str,
    ballast: f64,
    vertical: &[f64],
    horizontal: &[f64],
    rows: &[Vec<f64>],
) -> IesFile {
    let join = |v: &[f64]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ");
    let mut t = format!(
        "{version}\n[TEST] glare\nTILT=NONE\n{lamps} {} {} {kind} {dims}\n{ballast} 1 40\n{}\n{}\n",
        vertical.len(),
        horizontal.len(),
        join(vertical),
        join(horizontal)
    );
    for row in rows {
        t += &join(row);
        t += "\n";
    }
    IesFile::parse(&t, "test.ies").unwrap()
}

/// An LM-63-2002 type C file of one rotationally symmetric plane, 1 lamp of 1000 lm.
fn ies(dims: &str, vertical: &[f64], candela: &[f64]) -> IesFile {
    ies_with("IESNA:LM-63-2002", "1 1000 1", 1, dims, 1.0, vertical, &[0.0], &[candela.to_vec()])
}

/// A downlight's table: 1000 cd straight down, falling to 100 cd at the horizontal.
const DOWN_V: [f64; 4] = [0.0, 30.0, 60.0, 90.0];
const DOWN_CD: [f64; 4] = [1000.0, 900.0, 600.0, 100.0];

fn light(file: IesFile) -> IesLight {
    IesLight::new(file, POS, DVec3::NEG_Y, DVec3::X, spd(), 1.0, WavelengthSampling::Importance)
        .unwrap()
}

/// The unit direction of `(C, gamma)` (degrees) in the default orientation.
fn towards(c: f64, gamma: f64) -> DVec3 {
    let (c, g) = (c.to_radians(), gamma.to_radians());
    DVec3::NEG_Y * g.cos() + (DVec3::X * c.cos() + DVec3::NEG_Z * c.sin()) * g.sin()
}

/// What an eye `r` metres from the light towards `(C, gamma)` sees.
fn seen(light: &dyn LightSource, c: f64, gamma: f64, r: f64) -> Option<GlareView> {
    light.glare_view(POS + towards(c, gamma) * r)
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

#[track_caller]
fn assert_view(v: Option<GlareView>, area: f64, r: f64, intensity: f64) {
    let v = v.unwrap();
    assert!(close(v.projected_area, area, 1e-9), "area {} vs {area}", v.projected_area);
    assert!(close(v.solid_angle, area / (r * r), 1e-9), "solid angle {}", v.solid_angle);
    assert!(close(v.intensity, intensity, 1e-9), "intensity {} vs {intensity}", v.intensity);
    assert!(close(v.luminance, intensity / area, 1e-9), "luminance {}", v.luminance);
    assert_eq!(v.centre, POS);
}

#[test]
fn a_flat_opening_seen_from_below_and_obliquely() {
    let l = light(ies("2 0.6 0.6 0", &DOWN_V, &DOWN_CD));
    assert_eq!(
        l.luminous_opening(),
        Some(LuminousOpening::Box { length: 0.6, width: 0.6, heights: [0.0; 4] })
    );
    // Straight below at 2 m: 0.36 m^2, 0.09 sr, L = I(nadir) / 0.36.
    let v = seen(&l, 0.0, 0.0, 2.0).unwrap();
    assert!(close(v.projected_area, 0.36, 1e-12), "{}", v.projected_area);
    assert!(close(v.solid_angle, 0.09, 1e-12), "{}", v.solid_angle);
    assert!(close(v.luminance, 1000.0 / 0.36, 1e-9), "{}", v.luminance);
    assert_view(Some(v), 0.36, 2.0, 1000.0);
    // 60 degrees from nadir, in any plane: half the area, the table's 600 cd.
    for c in [0.0, 37.0, 90.0, 200.0] {
        assert_view(seen(&l, c, 60.0, 2.0), 0.18, 2.0, 600.0);
    }
    assert_view(seen(&l, 0.0, 60.0, 5.0), 0.18, 5.0, 600.0);
    // The intensity is the light's: every multiplier applied.
    let bright = IesLight::new(
        ies("2 0.6 0.6 0", &DOWN_V, &DOWN_CD),
        POS,
        DVec3::NEG_Y,
        DVec3::X,
        spd(),
        2.5,
        WavelengthSampling::Importance,
    )
    .unwrap();
    assert_view(seen(&bright, 0.0, 0.0, 2.0), 0.36, 2.0, 2500.0);
    let dir = towards(10.0, 20.0);
    let v = bright.glare_view(POS + dir * 3.0).unwrap();
    assert_eq!(v.intensity, bright.candela_towards(dir));
}

#[test]
fn no_view_without_a_visible_opening() {
    let l = light(ies("2 0.6 0.6 0", &DOWN_V, &DOWN_CD));
    // From above a flat downlight, edge-on, at the light itself, or from nowhere.
    assert!(seen(&l, 0.0, 180.0, 2.0).is_none());
    assert!(seen(&l, 45.0, 120.0, 2.0).is_none());
    assert!(seen(&l, 0.0, 90.0, 2.0).is_none());
    assert!(l.glare_view(POS).is_none());
    assert!(l.glare_view(DVec3::new(f64::NAN, 0.0, 0.0)).is_none());
    assert!(l.glare_view(DVec3::new(0.0, f64::INFINITY, 0.0)).is_none());
    // A point source (0 0 0) has no luminance.
    let point = light(ies("2 0 0 0", &DOWN_V, &DOWN_CD));
    assert_eq!(point.luminous_opening(), None);
    assert!(seen(&point, 0.0, 0.0, 2.0).is_none());
    // Lights that do not say: the default.
    let p = PointLight::new(POS, 10.0, spd(), WavelengthSampling::Importance).unwrap();
    assert!(p.glare_view(DVec3::ZERO).is_none());
    assert!(p.photometric_summary().is_none());
}

#[test]
fn a_box_shows_its_sides() {
    // Width 0.3 (along C90-C270), length 0.6 (along C0-C180), height 0.1.
    let vertical = [0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0];
    let candela = [1000.0, 900.0, 600.0, 400.0, 0.0, 0.0, 0.0];
    let l = light(ies("2 0.3 0.6 0.1", &vertical, &candela));
    assert_eq!(
        l.luminous_opening(),
        Some(LuminousOpening::Box { length: 0.6, width: 0.3, heights: [0.1; 4] })
    );
    // From the side: towards C0 the 0.3 x 0.1 end, towards C90 (-z) the 0.6 x 0.1 side.
    for c in [0.0, 180.0] {
        assert_view(seen(&l, c, 90.0, 2.0), 0.03, 2.0, 400.0);
    }
    for c in [90.0, 270.0] {
        assert_view(seen(&l, c, 90.0, 2.0), 0.06, 2.0, 400.0);
    }
    let s60 = 60f64.to_radians().sin();
    assert_view(seen(&l, 0.0, 60.0, 2.0), 0.18 * 0.5 + 0.03 * s60, 2.0, 600.0);
    let side = s60 * (0.03 * FRAC_1_SQRT_2 + 0.06 * FRAC_1_SQRT_2);
    assert_view(seen(&l, 45.0, 60.0, 2.0), 0.18 * 0.5 + side, 2.0, 600.0);
    // From above: the sides only (the table sends nothing up, so the top is dark), at the
    // intensity the table has there.
    let v = seen(&l, 0.0, 100.0, 2.0).unwrap();
    assert!(close(v.projected_area, 0.03 * 100f64.to_radians().sin(), 1e-9));
    assert!(seen(&l, 0.0, 180.0, 2.0).is_none());
    // The frame turns with c0: C0 along +z now, so the end faces +z.
    let turned = IesLight::new(
        ies("2 0.3 0.6 0.1", &vertical, &candela),
        POS,
        DVec3::NEG_Y,
        DVec3::Z,
        spd(),
        1.0,
        WavelengthSampling::Importance,
    )
    .unwrap();
    let v = turned.glare_view(POS + DVec3::Z * 2.0).unwrap();
    assert!(close(v.projected_area, 0.03, 1e-9), "{}", v.projected_area);
    let v = turned.glare_view(POS + DVec3::X * 2.0).unwrap();
    assert!(close(v.projected_area, 0.06, 1e-9), "{}", v.projected_area);
}

#[test]
fn an_uplight_opening_is_seen_from_above() {
    let l = light(ies("2 0.6 0.6 0", &[0.0, 90.0, 180.0], &[0.0, 0.0, 800.0]));
    assert_view(seen(&l, 0.0, 180.0, 2.0), 0.36, 2.0, 800.0);
    assert!(seen(&l, 0.0, 0.0, 2.0).is_none());
}

#[test]
fn round_openings_disks_and_cylinders() {
    let disk_area = PI * 0.3 * 0.3 / 4.0;
    let l = light(ies("2 -0.3 -0.3 0", &DOWN_V, &DOWN_CD));
    assert_eq!(
        l.luminous_opening(),
        Some(LuminousOpening::Cylinder { length: 0.3, width: 0.3, heights: [0.0; 4] })
    );
    assert_view(seen(&l, 0.0, 0.0, 2.0), disk_area, 2.0, 1000.0);
    assert_view(seen(&l, 123.0, 60.0, 2.0), disk_area * 0.5, 2.0, 600.0);
    assert!(seen(&l, 0.0, 90.0, 2.0).is_none());
    // A vertical cylinder 0.2 high: d h from the side, whatever the plane.
    // (A table reaching 180 degrees: a 0-90 one ends at -cos(90 deg) = -6e-17, just short of
    // an exactly horizontal direction.)
    let cyl = light(ies(
        "2 -0.3 -0.3 0.2",
        &[0.0, 30.0, 60.0, 90.0, 180.0],
        &[1000.0, 900.0, 600.0, 100.0, 0.0],
    ));
    for c in [0.0, 30.0, 90.0, 250.0] {
        assert_view(seen(&cyl, c, 90.0, 2.0), 0.06, 2.0, 100.0);
    }
    let v = seen(&cyl, 10.0, 45.0, 2.0).unwrap();
    let want = disk_area * FRAC_1_SQRT_2 + 0.06 * FRAC_1_SQRT_2;
    assert!(close(v.projected_area, want, 1e-9), "{} vs {want}", v.projected_area);
    // A sphere, the same from everywhere.
    let sphere = light(ies("2 -0.3 -0.3 -0.3", &[0.0, 90.0, 180.0], &[100.0, 100.0, 100.0]));
    for (c, g) in [(0.0, 0.0), (40.0, 70.0), (0.0, 180.0), (300.0, 100.0)] {
        assert_view(seen(&sphere, c, g, 2.0), disk_area, 2.0, 100.0);
    }
}

#[test]
fn the_dimensions_read_as_their_version_and_unit_define() {
    let opening = |version: &str, dims: &str| {
        ies_with(version, "1 1000 1", 1, dims, 1.0, &DOWN_V, &[0.0], &[DOWN_CD.to_vec()])
            .luminous_opening()
    };
    const V02: &str = "IESNA:LM-63-2002";
    const V95: &str = "IESNA:LM-63-1995";
    // Feet: 2 ft = 0.6096 m.
    let Some(LuminousOpening::Box { length, width, .. }) = opening(V02, "1 2 2 0") else {
        panic!("not a box")
    };
    assert!(close(length, 0.6096, 1e-12) && close(width, 0.6096, 1e-12));
    // An ellipse and a horizontal cylinder along the photometric horizontal (a tube).
    assert_eq!(
        opening(V02, "2 -0.2 -0.4 0"),
        Some(LuminousOpening::Cylinder { length: 0.4, width: 0.2, heights: [0.0; 4] })
    );
    assert_eq!(
        opening(V02, "2 -0.1 1.2 -0.1"),
        Some(LuminousOpening::CylinderAlongC0 { length: 1.2, width: 0.1, height: 0.1 })
    );
    assert_eq!(
        opening(V02, "2 1.2 -0.1 -0.1"),
        Some(LuminousOpening::CylinderAlongC90 { length: 0.1, width: 1.2, height: 0.1 })
    );
    assert_eq!(
        opening(V02, "2 -0.2 0 -0.3"),
        Some(LuminousOpening::VerticalEllipse { width: 0.2, height: 0.3 })
    );
    // LM-63-1995 writes a disk with a zero length, and a sphere as `- 0 -`; a 2002 file's
    // unused `- 0 0` reads as the disk too.
    let disk = Some(LuminousOpening::Cylinder { length: 0.15, width: 0.15, heights: [0.0; 4] });
    assert_eq!(opening(V95, "2 -0.15 0 0"), disk);
    assert_eq!(opening(V02, "2 -0.15 0 0"), disk);
    assert_eq!(
        opening(V95, "2 -0.2 0 -0.2"),
        Some(LuminousOpening::Ellipsoid { length: 0.2, width: 0.2, height: 0.2 })
    );
    assert_eq!(
        opening(V95, "2 0 1.2 -0.05"),
        Some(LuminousOpening::CylinderAlongC0 { length: 1.2, width: 0.05, height: 0.05 })
    );
    // Signs no table defines, and the point.
    assert_eq!(opening(V02, "2 0.3 -0.3 0"), None);
    assert_eq!(opening(V02, "2 0 0 0"), None);
}

#[test]
fn a_tube_is_seen_along_and_across() {
    // A horizontal cylinder 1.2 m long along C0, 0.1 m across, lit all round.
    let vertical = [0.0, 90.0, 180.0];
    let l = light(ies("2 -0.1 1.2 -0.1", &vertical, &[500.0, 500.0, 500.0]));
    let end = PI * 0.05 * 0.05;
    assert_view(seen(&l, 0.0, 0.0, 3.0), 0.12, 3.0, 500.0);
    assert_view(seen(&l, 0.0, 180.0, 3.0), 0.12, 3.0, 500.0);
    assert_view(seen(&l, 90.0, 90.0, 3.0), 0.12, 3.0, 500.0);
    assert_view(seen(&l, 0.0, 90.0, 3.0), end, 3.0, 500.0);
}

#[test]
fn a_type_b_opening_faces_its_photometric_axis() {
    let (hs, vs) = ([-90.0, 0.0, 90.0], [-90.0, 0.0, 90.0]);
    let rows = vec![vec![100.0; 3]; 3];
    let file = ies_with("IESNA:LM-63-2002", "1 -1 1", 2, "2 0.4 0.2 0", 1.0, &vs, &hs, &rows);
    // Aimed along +x, its polar axis vertical: the photometric horizontal is +z.
    let l =
        IesLight::new(file, POS, DVec3::X, DVec3::Y, spd(), 1.0, WavelengthSampling::Importance)
            .unwrap();
    let v = l.glare_view(POS + DVec3::X * 2.0).unwrap();
    assert!(close(v.projected_area, 0.08, 1e-9) && close(v.intensity, 100.0, 1e-9), "{v:?}");
    let oblique = DVec3::new(0.5, 0.0, 0.75f64.sqrt());
    let v = l.glare_view(POS + oblique * 2.0).unwrap();
    assert!(close(v.projected_area, 0.04, 1e-9), "{v:?}");
    assert!(l.glare_view(POS - DVec3::X * 2.0).is_none());
    assert!(l.glare_view(POS + DVec3::Z * 2.0).is_none());
}

/// A EULUMDAT file of one plane (Isym 1): luminous `area` (length, width; mm), `heights`
/// (mm), `lorl` (%), lamp `sets` (count, flux), and `cd_per_klm` at `gammas`.
fn ldt_text(
    area: [f64; 2],
    heights: [f64; 4],
    lorl: f64,
    sets: &[(i32, f64)],
    gammas: &[f64],
    cd_per_klm: &[f64],
) -> String {
    let mut lines: Vec<String> = vec![
        "Spectrace glare tests".into(),
        "1".into(),
        "1".into(),
        "4".into(),
        "90".into(),
        gammas.len().to_string(),
        "0".into(),
        "report".into(),
        "luminaire".into(),
        "L-1".into(),
        "l.ldt".into(),
        "2026".into(),
        "620".into(),
        "620".into(),
        "80".into(),
    ];
    lines.extend(area.iter().chain(&heights).map(|v| v.to_string()));
    lines.extend(["100".into(), lorl.to_string(), "1".into(), "0".into()]);
    lines.push(sets.len().to_string());
    for (lamps, flux) in sets {
        lines.extend([
            lamps.to_string(),
            "LED".into(),
            flux.to_string(),
            "4000".into(),
            "80".into(),
            "30".into(),
        ]);
    }
    lines.extend((0..10).map(|k| format!("0.{}", k + 1)));
    lines.extend(["0", "90", "180", "270"].map(String::from));
    lines.extend(gammas.iter().map(|g| g.to_string()));
    lines.extend(cd_per_klm.iter().map(|v| v.to_string()));
    lines.join("\n") + "\n"
}

fn eulumdat(text: &str) -> EulumdatLight {
    let ldt = LdtFile::parse(text, "t.ldt").unwrap();
    EulumdatLight::new(ldt, POS, DVec3::NEG_Y, DVec3::X, spd(), 1.0, WavelengthSampling::Importance)
        .unwrap()
}

#[test]
fn eulumdat_areas_rectangles_with_side_heights_and_round() {
    // 600 x 300 mm (length along C0-C180), sides 10, 20, 30, 40 mm high in C0, C90, C180, C270;
    // 500 cd/klm x 1 klm everywhere below the horizontal.
    let gammas = [0.0, 90.0, 180.0];
    let text = ldt_text(
        [600.0, 300.0],
        [10.0, 20.0, 30.0, 40.0],
        80.0,
        &[(1, 1000.0)],
        &gammas,
        &[500.0, 500.0, 0.0],
    );
    let l = eulumdat(&text);
    assert_eq!(
        l.luminous_opening(),
        Some(LuminousOpening::Box { length: 0.6, width: 0.3, heights: [0.01, 0.02, 0.03, 0.04] })
    );
    assert_view(seen(&l, 0.0, 0.0, 2.0), 0.18, 2.0, 500.0);
    // Each side at its own height: C0 and C180 ends span the width, C90 and C270 the length.
    assert_view(seen(&l, 0.0, 90.0, 2.0), 0.3 * 0.01, 2.0, 500.0);
    assert_view(seen(&l, 90.0, 90.0, 2.0), 0.6 * 0.02, 2.0, 500.0);
    assert_view(seen(&l, 180.0, 90.0, 2.0), 0.3 * 0.03, 2.0, 500.0);
    assert_view(seen(&l, 270.0, 90.0, 2.0), 0.6 * 0.04, 2.0, 500.0);
    // Round (width 0): a disk of 300 mm with a side 50 mm high all round.
    let round =
        ldt_text([300.0, 0.0], [50.0; 4], 80.0, &[(1, 1000.0)], &gammas, &[500.0, 500.0, 0.0]);
    let l = eulumdat(&round);
    let disk = PI * 0.3 * 0.3 / 4.0;
    assert_view(seen(&l, 0.0, 0.0, 2.0), disk, 2.0, 500.0);
    for c in [0.0, 45.0, 160.0] {
        assert_view(seen(&l, c, 90.0, 2.0), 0.3 * 0.05, 2.0, 500.0);
    }
    // No area at all: a point.
    let point = ldt_text([0.0, 0.0], [0.0; 4], 80.0, &[(1, 1000.0)], &gammas, &[1.0, 1.0, 0.0]);
    assert!(seen(&eulumdat(&point), 0.0, 0.0, 2.0).is_none());
}

#[test]
fn ies_lumens_summary_two_lamps_of_1500_lm() {
    // 745 cd at nadir falling linearly in cos(gamma) to 0 at the horizontal: 745 pi lm.
    let file = |lamps: &str, ballast: f64| {
        ies_with(
            "IESNA:LM-63-2002",
            lamps,
            1,
            "2 0.6 0.6 0",
            ballast,
            &[0.0, 90.0],
            &[0.0],
            &[vec![745.0, 0.0]],
        )
    };
    let table = 745.0 * PI;
    let l = light(file("2 1500 1", 0.9));
    let s = l.lumens_summary();
    assert!(close(s.file_lumens, table, 1e-12), "{}", s.file_lumens);
    assert!(close(s.table_lumens, table * 0.9, 1e-12), "{}", s.table_lumens);
    assert_eq!(s.table_lumens, l.lumens());
    assert_eq!((s.lamp_count, s.lamp_lumens), (2, Some(3000.0)));
    assert!(close(s.light_output_ratio.unwrap(), table / 3000.0, 1e-12));
    assert_eq!(s.stated_light_output_ratio, None);
    assert_eq!(s.to_string(), "table 2106.4 lm, lamps 2 x 1500 lm = 3000 lm, LOR 0.780");
    // Through `dyn LightSource`, the same numbers.
    let boxed: Box<dyn LightSource> = Box::new(l.clone());
    assert_eq!(boxed.photometric_summary(), Some(s));
    // The file's candela multiplier scales the file's table; the scene's multiplier only the
    // light's.
    let l2 = IesLight::new(
        file("2 1500 2", 1.0),
        POS,
        DVec3::NEG_Y,
        DVec3::X,
        spd(),
        3.0,
        WavelengthSampling::Importance,
    )
    .unwrap();
    let s2 = l2.lumens_summary();
    assert!(close(s2.file_lumens, 2.0 * table, 1e-12));
    assert!(close(s2.table_lumens, 6.0 * table, 1e-12));
    assert!(close(s2.light_output_ratio.unwrap(), 2.0 * table / 3000.0, 1e-12));
    // Absolute photometry: no lamp rating, no ratio.
    let s3 = light(file("1 -1 1", 1.0)).lumens_summary();
    assert_eq!((s3.lamp_lumens, s3.light_output_ratio), (None, None));
    assert!(s3.to_string().contains("absolute photometry"), "{s3}");
}

/// A folder of its own for a test's files.
fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("spectrace-glare-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn load(dir: &Path, json: &str) -> Box<dyn LightSource> {
    with_scene_folder(dir, false, || serde_json::from_str::<Box<dyn LightSource>>(json)).0.unwrap()
}

#[test]
fn scene_lumens_rescale_the_table_but_not_the_ratio() {
    let dir = folder("ies");
    let text = "IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n2 1500 1 2 1 1 2 0.6 0.6 0\n1 1 40\n0 90\n0\n745 0\n";
    std::fs::write(dir.join("l.ies"), text).unwrap();
    let l = load(
        &dir,
        r#"{"type": "IesLight", "file": "l.ies", "position": [0, 3, 0], "lumens": 5000}"#,
    );
    let s = l.photometric_summary().unwrap();
    assert!(close(s.table_lumens, 5000.0, 1e-12), "{}", s.table_lumens);
    assert!(close(s.light_output_ratio.unwrap(), 745.0 * PI / 3000.0, 1e-12));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn eulumdat_lumens_summary_against_the_stated_lorl() {
    // 248.3 cd/klm at nadir falling linearly in cos(gamma) to 0 at the horizontal:
    // 248.3 pi lm per klm = LOR 0.78005; the file states 78 %.
    let text = ldt_text(
        [600.0, 600.0],
        [0.0; 4],
        78.0,
        &[(2, 2000.0), (1, 1200.0)],
        &[0.0, 90.0],
        &[248.3, 0.0],
    );
    let per_klm = 248.3 * PI;
    let l = eulumdat(&text);
    let s = l.lumens_summary();
    assert_eq!((l.lamp_set(), s.lamp_count, s.lamp_lumens), (0, 2, Some(2000.0)));
    assert!(close(s.file_lumens, 2.0 * per_klm, 1e-12), "{}", s.file_lumens);
    assert_eq!(s.table_lumens, l.lumens());
    let lor = s.light_output_ratio.unwrap();
    assert!(close(lor, per_klm / 1000.0, 1e-12), "{lor}");
    assert_eq!(s.stated_light_output_ratio, Some(0.78));
    assert!((lor - 0.78).abs() < 1e-3, "{lor}");
    assert_eq!(
        s.to_string(),
        "table 1560.1 lm, lamps 2 x 1000 lm = 2000 lm, LOR 0.780 (file states 0.780)"
    );
    // The second set fitted: its lamps, the same ratio (a property of the luminaire).
    let dir = folder("ldt");
    std::fs::write(dir.join("l.ldt"), &text).unwrap();
    let l2 = load(
        &dir,
        r#"{"type": "EulumdatLight", "file": "l.ldt", "position": [0, 3, 0], "lamp_set": 2}"#,
    );
    let s2 = l2.photometric_summary().unwrap();
    assert_eq!((s2.lamp_count, s2.lamp_lumens), (1, Some(1200.0)));
    assert!(close(s2.table_lumens, 1.2 * per_klm, 1e-12), "{}", s2.table_lumens);
    assert!(close(s2.light_output_ratio.unwrap(), lor, 1e-12));
    std::fs::remove_dir_all(&dir).unwrap();
    // Absolute photometry (negative lamp counts): no lamp rating, the stated LORL kept.
    let absolute =
        ldt_text([600.0, 600.0], [0.0; 4], 100.0, &[(-1, 1560.0)], &[0.0, 90.0], &[248.3, 0.0]);
    let s3 = eulumdat(&absolute).lumens_summary();
    assert_eq!((s3.lamp_count, s3.lamp_lumens, s3.light_output_ratio), (1, None, None));
    assert_eq!(s3.stated_light_output_ratio, Some(1.0));
}
