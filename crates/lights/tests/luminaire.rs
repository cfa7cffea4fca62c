//! Measured luminaires as lights: the unfolding of the formats' symmetries, the handedness of the
//! C-planes, the sampled directions against the candela table (chi-square), the flux carried by
//! the beams against the table's, and scene-file errors naming the file and line.
#![allow(clippy::unwrap_used)]

use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};

use rand::SeedableRng;
use spectrace_lights::LightSource;
use spectrace_lights::glam::DVec3;
use spectrace_lights::photometry::{CandelaDistribution, IesLight};
use spectrace_lights::sampling::files::with_scene_folder;
use spectrace_lights::sampling::stats::chi_square;
use spectrace_lights::spectrum::SpectralPowerDistribution;
use spectrace_lights::spectrum::{lumens_per_watt, luminous_efficacy};

/// An LM-63-2002 type C file with the given angles and `candela[h][v]` (multiplier 1,
/// relative photometry with 1000 lm lamps).
fn ies_text(vertical: &[f64], horizontal: &[f64], candela: &[Vec<f64>]) -> String {
    let join = |v: &[f64]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ");
    let mut s = format!(
        "IESNA:LM-63-2002\n[TEST] spectrace test\nTILT=NONE\n1 1000 1 {} {} 1 2 0.1 0.1 0\n1 1 10\n{}\n{}\n",
        vertical.len(),
        horizontal.len(),
        join(vertical),
        join(horizontal)
    );
    for row in candela {
        s += &join(row);
        s += "\n";
    }
    s
}

/// A folder of its own for a test's files.
fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("spectrace-luminaire-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// An `IesLight` read from a scene-file fragment with the file `lum.ies` in `dir`.
fn load(dir: &Path, json: &str) -> Result<Box<dyn LightSource>, String> {
    with_scene_folder(dir, false, || serde_json::from_str::<Box<dyn LightSource>>(json))
        .0
        .map_err(|e| e.to_string())
}

/// An asymmetric table over the whole circle: bright towards C = 90, dim towards C = 270,
/// fading with the vertical angle (0..90 only).
fn asymmetric() -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
    let vertical = vec![0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0];
    let horizontal: Vec<f64> = (0..=12).map(|k| k as f64 * 30.0).collect();
    let candela = horizontal
        .iter()
        .map(|&c: &f64| {
            vertical
                .iter()
                .map(|&g: &f64| {
                    let toward_90 = 1.0 + 0.9 * c.to_radians().sin();
                    (500.0 * toward_90 * (1.0 - g / 100.0)).round()
                })
                .collect()
        })
        .collect();
    (vertical, horizontal, candela)
}

/// The exact flux of a table under bilinear interpolation in `(C, cos gamma)`: trapezoids in
/// both coordinates, written here from the definition (independently of the sampler).
fn flux_of(horizontal_rad: &[f64], cos_vertical: &[f64], candela: &[Vec<f64>]) -> f64 {
    let mut total = 0.0;
    for h in 0..horizontal_rad.len() - 1 {
        for v in 0..cos_vertical.len() - 1 {
            let mean =
                (candela[h][v] + candela[h][v + 1] + candela[h + 1][v] + candela[h + 1][v + 1])
                    / 4.0;
            total += mean
                * (horizontal_rad[h + 1] - horizontal_rad[h])
                * (cos_vertical[v] - cos_vertical[v + 1]).abs();
        }
    }
    total
}

#[test]
fn the_table_reads_back_at_every_measured_angle_and_the_flux_is_its_integral() {
    let (vertical, horizontal, candela) = asymmetric();
    let d = CandelaDistribution::new(&horizontal, &vertical, &candela).unwrap();
    for (h, &c) in horizontal.iter().enumerate() {
        for (v, &g) in vertical.iter().enumerate() {
            let got = d.candela(c.to_radians(), g.to_radians().cos());
            assert!((got - candela[h][v]).abs() < 1e-9 * candela[h][v].max(1.0), "C{c} g{g}");
        }
    }
    // Nothing above the horizon (the table stops at 90 degrees).
    assert_eq!(d.candela(1.0, -0.2), 0.0);
    let h: Vec<f64> = horizontal.iter().map(|c| c.to_radians()).collect();
    let v: Vec<f64> = vertical.iter().map(|g| g.to_radians().cos()).collect();
    let expected = flux_of(&h, &v, &candela);
    assert!((d.lumens() - expected).abs() < 1e-9 * expected, "{} vs {expected}", d.lumens());
    // An isotropic 100 cd table over the whole sphere has 400 pi lm.
    let iso = CandelaDistribution::new(&[0.0], &[0.0, 90.0, 180.0], &[vec![100.0; 3]]).unwrap();
    assert!((iso.lumens() - 400.0 * PI).abs() < 1e-9);
}

#[test]
fn symmetric_tables_unfold_by_the_mirrors_the_formats_define() {
    let vertical = [0.0, 45.0, 90.0];
    let row = |k: f64| vec![100.0 + k, 50.0 + k, k];
    // Quadrant (0..90): C 120 is C 60 mirrored about C 90, C 240 is C 60 turned by 180,
    // C 300 is C 60 mirrored about C 0.
    let q =
        CandelaDistribution::new(&[0.0, 60.0, 90.0], &vertical, &[row(0.0), row(7.0), row(20.0)])
            .unwrap();
    for c in [60.0_f64, 120.0, 240.0, 300.0] {
        assert!((q.candela(c.to_radians(), 1.0) - 107.0).abs() < 1e-9, "quadrant C{c}");
    }
    assert!((q.candela(270.0_f64.to_radians(), 1.0) - 120.0).abs() < 1e-9);
    // Bilateral about C0-C180 (0..180): C 300 is C 60.
    let b =
        CandelaDistribution::new(&[0.0, 60.0, 180.0], &vertical, &[row(0.0), row(7.0), row(20.0)])
            .unwrap();
    assert!((b.candela(300.0_f64.to_radians(), 1.0) - 107.0).abs() < 1e-9);
    assert!((b.candela(60.0_f64.to_radians(), 1.0) - 107.0).abs() < 1e-9);
    // Bilateral about C90-C270 (90..270): C 30 is C 150, C 330 is C 210.
    let c = CandelaDistribution::new(
        &[90.0, 150.0, 210.0, 270.0],
        &vertical,
        &[row(0.0), row(7.0), row(20.0), row(30.0)],
    )
    .unwrap();
    assert!((c.candela(30.0_f64.to_radians(), 1.0) - 107.0).abs() < 1e-9);
    assert!((c.candela(330.0_f64.to_radians(), 1.0) - 120.0).abs() < 1e-9);
    // No symmetry, ending before 360: wraps from the last plane to C 0.
    let n = CandelaDistribution::new(
        &[0.0, 120.0, 240.0],
        &vertical,
        &[row(0.0), row(30.0), row(60.0)],
    )
    .unwrap();
    assert!((n.candela(300.0_f64.to_radians(), 1.0) - 130.0).abs() < 1e-9);
    // A range that declares no symmetry is refused.
    let e = CandelaDistribution::new(&[0.0, 45.0], &vertical, &[row(0.0), row(1.0)]).unwrap_err();
    assert!(e.contains("declare no symmetry"), "{e}");
}

#[test]
fn a_rotationally_symmetric_table_gives_one_intensity_all_round_the_nadir() {
    let vertical = [0.0, 30.0, 60.0, 90.0, 180.0];
    let round = CandelaDistribution::new(&[0.0], &vertical, &[vec![500.0, 410.0, 230.0, 7.0, 0.0]])
        .unwrap();
    assert!(!round.depends_on_c());
    for gamma in [0.0_f64, 12.5, 30.0, 44.0, 89.0, 120.0] {
        let cos_gamma = gamma.to_radians().cos();
        let at_c0 = round.candela(0.0, cos_gamma);
        assert!(at_c0 > 0.0 || gamma > 90.0, "gamma {gamma}");
        // Exactly, not to rounding: the intensity is the one column's, whatever C is.
        for c in [0.3_f64, 1.0, PI, 4.0, 6.2, TAU, -1.0, 20.0] {
            assert_eq!(round.candela(c, cos_gamma), at_c0, "gamma {gamma}, C {c}");
        }
    }
    let (vertical, horizontal, candela) = asymmetric();
    assert!(CandelaDistribution::new(&horizontal, &vertical, &candela).unwrap().depends_on_c());
}

#[test]
fn c_plane_90_lies_counter_clockwise_from_c0_seen_from_above() {
    // Light only around C 90 (asymmetric, no symmetry): with nadir -y and c0 +x, C 90 is
    // c0 x nadir = -z; turning the luminaire's c0 to +z moves it to +x.
    let vertical = [0.0, 30.0, 60.0, 90.0];
    let horizontal: Vec<f64> = (0..=8).map(|k| k as f64 * 45.0).collect();
    let candela: Vec<Vec<f64>> = horizontal
        .iter()
        .map(|&c| {
            let k = if c == 90.0 { 1000.0 } else { 0.0 };
            vec![0.0, k, k, 0.0]
        })
        .collect();
    let dir = folder("handedness");
    std::fs::write(dir.join("lum.ies"), ies_text(&vertical, &horizontal, &candela)).unwrap();
    for (c0, towards) in [([1.0, 0.0, 0.0], DVec3::NEG_Z), ([0.0, 0.0, 1.0], DVec3::X)] {
        let json = format!(
            r#"{{"type": "IesLight", "file": "lum.ies", "position": [0, 3, 0],
               "nadir": [0, -1, 0], "c0": {c0:?}, "cct": 3000}}"#
        );
        let light = load(&dir, &json).unwrap();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
        let mut mean = DVec3::ZERO;
        for _ in 0..2000 {
            let b = light.next_beam(&mut rng);
            assert!(b.direction.y < 0.0, "below the luminaire only");
            mean += b.direction;
        }
        let horizontal_mean = (mean - DVec3::Y * mean.y).normalize();
        assert!(horizontal_mean.dot(towards) > 0.99, "{c0:?}: {horizontal_mean}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn emitted_directions_follow_the_candela_table() {
    let (vertical, horizontal, candela) = asymmetric();
    let dir = folder("chi2");
    std::fs::write(dir.join("lum.ies"), ies_text(&vertical, &horizontal, &candela)).unwrap();
    // A tilted luminaire, so the test also covers the frame.
    let nadir = DVec3::new(0.3, -1.0, 0.2).normalize();
    let json = r#"{"type": "IesLight", "file": "lum.ies", "position": [1, 2, 3],
                   "nadir": [0.3, -1, 0.2], "c0": [1, 0, 0.5], "cct": 4000}"#;
    let light = load(&dir, json).unwrap();
    let c0 = {
        let c = DVec3::new(1.0, 0.0, 0.5).normalize();
        (c - nadir * c.dot(nadir)).normalize()
    };
    let c90 = c0.cross(nadir);
    // Bins in (C, cos gamma): 24 x 10 over C in [0, 2 pi), cos gamma in [0, 1].
    let (nc, nm) = (24usize, 10usize);
    let n = 300_000u64;
    let mut counts = vec![0u64; nc * nm];
    let mut rng = rand_pcg::Pcg64::seed_from_u64(2);
    for _ in 0..n {
        let b = light.next_beam(&mut rng);
        assert_eq!(b.origin, DVec3::new(1.0, 2.0, 3.0));
        let cos_g = b.direction.dot(nadir);
        assert!(cos_g >= -1e-12, "a beam above the horizon: {cos_g}");
        let c = b.direction.dot(c90).atan2(b.direction.dot(c0)).rem_euclid(TAU);
        let i = ((c / TAU * nc as f64) as usize).min(nc - 1);
        let j = ((cos_g.max(0.0) * nm as f64) as usize).min(nm - 1);
        counts[i * nm + j] += 1;
    }
    // Expected: the candela table interpolated from its definition (linear in C between planes,
    // linear in cos gamma between vertical angles), integrated over each bin by 8x8 midpoints,
    // over the flux.
    let h: Vec<f64> = horizontal.iter().map(|c| c.to_radians()).collect();
    let v: Vec<f64> = vertical.iter().map(|g| g.to_radians().cos()).collect();
    let interpolate = |c: f64, mu: f64| {
        let a = (h.partition_point(|&x| x <= c).max(1) - 1).min(h.len() - 2);
        let t = (c - h[a]) / (h[a + 1] - h[a]);
        // v decreases with the index.
        let b = (v.partition_point(|&x| x >= mu).max(1) - 1).min(v.len() - 2);
        let s = (mu - v[b]) / (v[b + 1] - v[b]);
        let row = |k: usize| candela[k][b] * (1.0 - s) + candela[k][b + 1] * s;
        row(a) * (1.0 - t) + row(a + 1) * t
    };
    let flux = flux_of(&h, &v, &candela);
    let k = 8;
    let expected: Vec<f64> = (0..nc * nm)
        .map(|cell| {
            let (i, j) = (cell / nm, cell % nm);
            let (dc, dm) = (TAU / nc as f64, 1.0 / nm as f64);
            let mut sum = 0.0;
            for p in 0..k {
                for q in 0..k {
                    let c = (i as f64 + (p as f64 + 0.5) / k as f64) * dc;
                    let mu = (j as f64 + (q as f64 + 0.5) / k as f64) * dm;
                    sum += interpolate(c, mu);
                }
            }
            sum / (k * k) as f64 * dc * dm / flux * n as f64
        })
        .collect();
    let result = chi_square(&counts, &expected, 5.0);
    assert!(result.p_value > 1e-3, "{result:?}");
    // The density the light reports is the same table's.
    let d = (nadir * 0.8 + c90 * 0.6).normalize();
    let pdf = light.emission_density(DVec3::ZERO, d);
    let (c, mu) = (d.dot(c90).atan2(d.dot(c0)).rem_euclid(TAU), d.dot(nadir));
    assert!((pdf - interpolate(c, mu) / flux).abs() < 1e-9 * pdf, "{pdf}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_beams_carry_the_tables_lumens() {
    let (vertical, horizontal, candela) = asymmetric();
    let dir = folder("lumens");
    std::fs::write(dir.join("lum.ies"), ies_text(&vertical, &horizontal, &candela)).unwrap();
    let json = r#"{"type": "IesLight", "file": "lum.ies", "position": [0, 3, 0], "multiplier": 2,
                   "spd": {"type": "CieIlluminant", "name": "D65"}}"#;
    let light = load(&dir, json).unwrap();
    let h: Vec<f64> = horizontal.iter().map(|c| c.to_radians()).collect();
    let v: Vec<f64> = vertical.iter().map(|g| g.to_radians().cos()).collect();
    let expected = 2.0 * flux_of(&h, &v, &candela);
    // The power is the flux over the spectrum's efficacy.
    let k = luminous_efficacy(light.spd().as_ref());
    assert!((light.power() * k - expected).abs() < 1e-9 * expected);
    // Sum the beams' luminous power: P / N * scale * 683 ybar(lambda).
    let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
    let n = 200_000;
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let b = light.next_beam(&mut rng);
        let lm = b.scale * lumens_per_watt(b.lambda);
        sum += lm;
        sum2 += lm * lm;
    }
    let mean = sum / n as f64;
    let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
    let lumens = light.power() * mean;
    // Four standard errors (the wavelength draw is the only randomness).
    assert!(
        (lumens - expected).abs() < 4.0 * light.power() * se,
        "{lumens} vs {expected} (se {})",
        light.power() * se
    );
    assert!(light.power() * se < 0.005 * expected, "the check is sharp to 0.5%");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn next_event_samples_give_the_intensity_towards_the_receiver() {
    let (vertical, horizontal, candela) = asymmetric();
    let dir = folder("towards");
    std::fs::write(dir.join("lum.ies"), ies_text(&vertical, &horizontal, &candela)).unwrap();
    let json = r#"{"type": "IesLight", "file": "lum.ies", "position": [0, 3, 0], "cct": 5000}"#;
    let light = load(&dir, json).unwrap();
    let ies = IesLight::new(
        spectrace_lights::photometry::IesFile::parse(
            &ies_text(&vertical, &horizontal, &candela),
            "lum.ies",
        )
        .unwrap(),
        DVec3::new(0.0, 3.0, 0.0),
        DVec3::NEG_Y,
        DVec3::X,
        light.spd(),
        1.0,
        Default::default(),
    )
    .unwrap();
    // Straight below, and 45 degrees towards C 90 (= -z): the file's values, in W/sr.
    let k = luminous_efficacy(light.spd().as_ref());
    let below = light.sample_towards(DVec3::ZERO, [0.5, 0.5]).unwrap();
    assert!(below.delta && (below.distance - 3.0).abs() < 1e-12);
    assert!((below.intensity * k - candela[0][0]).abs() < 1e-6 * candela[0][0]);
    let s = light.sample_towards(DVec3::new(0.0, 0.0, -3.0), [0.5, 0.5]).unwrap();
    assert!((s.intensity * k - candela[3][3]).abs() < 1e-6 * candela[3][3], "{}", s.intensity * k);
    assert!((ies.candela_towards(s.direction) - candela[3][3]).abs() < 1e-9);
    let e = light.sample_emission([0.3, 0.6, 0.5, 0.5]).unwrap();
    let (pa, pd) = light.pdf_emission(e.position, e.direction).unwrap();
    assert_eq!(pa, 1.0);
    assert!((pd - e.pdf_direction).abs() < 1e-12 * pd);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn scene_file_errors_name_the_file_the_line_and_the_field() {
    let dir = folder("errors");
    let missing = load(&dir, r#"{"type": "IesLight", "file": "none.ies", "position": [0, 1, 0]}"#)
        .unwrap_err();
    assert!(missing.contains("IesLight.file") && missing.contains("none.ies"), "{missing}");
    // Truncated: the candela values stop early.
    let (vertical, horizontal, candela) = asymmetric();
    let text = ies_text(&vertical, &horizontal, &candela);
    let cut: String = text.lines().take(9).collect::<Vec<_>>().join("\n");
    std::fs::write(dir.join("cut.ies"), cut).unwrap();
    let e = load(&dir, r#"{"type": "IesLight", "file": "cut.ies", "position": [0, 1, 0]}"#)
        .unwrap_err();
    assert!(e.contains("cut.ies:9:"), "{e}");
    std::fs::write(dir.join("lum.ies"), &text).unwrap();
    let e = load(
        &dir,
        r#"{"type": "IesLight", "file": "lum.ies", "position": [0, 1, 0], "c0": [0, 2, 0]}"#,
    )
    .unwrap_err();
    assert!(e.contains("IesLight.c0") && e.contains("parallel"), "{e}");
    let e = load(
        &dir,
        r#"{"type": "IesLight", "file": "lum.ies", "position": [0, 1, 0],
            "spd": {"type": "Monochromatic", "lambda_nm": 300}}"#,
    )
    .unwrap_err();
    assert!(e.contains("no visible light"), "{e}");
    let e = load(
        &dir,
        r#"{"type": "IesLight", "file": "lum.ies", "position": [0, 1, 0], "multiplier": -1}"#,
    )
    .unwrap_err();
    assert!(e.contains("IesLight.multiplier"), "{e}");
    let e = load(
        &dir,
        r#"{"type": "IesLight", "file": "lum.ies", "position": [0, 1, 0], "cct": 3000,
            "spd": {"type": "Blackbody", "kelvin": 3000}}"#,
    )
    .unwrap_err();
    assert!(e.contains("either"), "{e}");
    for bad in ["-5", "0"] {
        let json = format!(
            r#"{{"type": "IesLight", "file": "lum.ies", "position": [0, 1, 0], "cct": {bad}}}"#
        );
        let e = load(&dir, &json).unwrap_err();
        assert!(e.contains("IesLight.cct"), "{bad}: {e}");
    }
    // Without `spd` or `cct`: CIE illuminant A.
    let a =
        load(&dir, r#"{"type": "IesLight", "file": "lum.ies", "position": [0, 1, 0]}"#).unwrap();
    let illuminant_a = spectrace_lights::spectrum::CieIlluminant::new("A").unwrap();
    assert_eq!(luminous_efficacy(a.spd().as_ref()), luminous_efficacy(&illuminant_a));
    assert_eq!(a.spd().value(560.0), illuminant_a.value(560.0));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A EULUMDAT file without symmetry (Isym 0): 8 C-planes every 45 degrees, gammas 0..90 every
/// 30, one set of 2 lamps of 1000 lm at "3000 K"; `cd_per_klm[c][g]`.
fn ldt_text(cd_per_klm: &[[f64; 4]; 8]) -> String {
    let mut lines: Vec<String> = [
        "Spectrace tests",
        "1",
        "0",
        "8",
        "45",
        "4",
        "30",
        "report",
        "asymmetric",
        "A-1",
        "a.ldt",
        "2026",
        "600",
        "100",
        "50",
        "600",
        "100",
        "50",
        "50",
        "50",
        "50",
        "100",
        "80",
        "1",
        "0",
        "1",
        "2",
        "LED",
        "2000",
        "3000 K",
        "80",
        "20",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    lines.extend((0..10).map(|k| format!("0.{}", k + 1)));
    lines.extend((0..8).map(|k| (k * 45).to_string()));
    lines.extend((0..4).map(|k| (k * 30).to_string()));
    for plane in cd_per_klm {
        lines.extend(plane.iter().map(|v| v.to_string()));
    }
    lines.join("\n") + "\n"
}

#[test]
fn a_eulumdat_luminaire_is_absolute_oriented_and_lit_by_its_lamps_colour() {
    let mut table = [[0.0; 4]; 8];
    table[2] = [0.0, 400.0, 400.0, 0.0]; // C 90 only
    let dir = folder("ldt");
    std::fs::write(dir.join("a.ldt"), ldt_text(&table)).unwrap();
    let light =
        load(&dir, r#"{"type": "EulumdatLight", "file": "a.ldt", "position": [0, 3, 0]}"#).unwrap();
    // Absolute: cd/klm x 2000 lm / 1000, so 800 cd at (C 90, gamma 30).
    let k = luminous_efficacy(light.spd().as_ref());
    // 60 degrees from nadir towards -z is (C 90, gamma 60): 400 cd/klm x 2.
    let towards = DVec3::new(0.0, -0.5, -(0.75_f64.sqrt()));
    let at = light.sample_towards(DVec3::new(0.0, 3.0, 0.0) + towards * 2.0, [0.5, 0.5]).unwrap();
    assert!((at.intensity * k - 800.0).abs() < 1e-6, "{}", at.intensity * k);
    // C 90 is -z with the default orientation: every beam heads that way.
    let mut rng = rand_pcg::Pcg64::seed_from_u64(4);
    for _ in 0..500 {
        let b = light.next_beam(&mut rng);
        assert!(b.direction.z < 0.0 && b.direction.y < 0.0, "{}", b.direction);
    }
    // The lamps' "3000 K" gives the default spectrum.
    let bb = spectrace_lights::spectrum::Blackbody::new(3000.0).unwrap();
    assert_eq!(light.spd().value(555.0), bb.value(555.0));
    // Beyond the table, and an error names the line.
    let text = ldt_text(&table);
    let cut: String = text.lines().take(30).collect::<Vec<_>>().join("\n");
    std::fs::write(dir.join("cut.ldt"), cut).unwrap();
    let e = load(&dir, r#"{"type": "EulumdatLight", "file": "cut.ldt", "position": [0, 3, 0]}"#)
        .unwrap_err();
    assert!(e.contains("EulumdatLight.file") && e.contains("cut.ldt:"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn lumens_scale_the_table_to_the_luminaires_flux() {
    let (vertical, horizontal, candela) = asymmetric();
    let dir = folder("scale");
    std::fs::write(dir.join("lum.ies"), ies_text(&vertical, &horizontal, &candela)).unwrap();
    let light = load(
        &dir,
        r#"{"type": "IesLight", "file": "lum.ies", "position": [0, 3, 0], "lumens": 5000, "cct": 3000}"#,
    )
    .unwrap();
    let k = luminous_efficacy(light.spd().as_ref());
    assert!((light.power() * k - 5000.0).abs() < 1e-9 * 5000.0, "{}", light.power() * k);
    // The shape is the table's: straight down, 5000 / (the table's flux) times the file's value.
    let h: Vec<f64> = horizontal.iter().map(|c| c.to_radians()).collect();
    let v: Vec<f64> = vertical.iter().map(|g| g.to_radians().cos()).collect();
    let scale = 5000.0 / flux_of(&h, &v, &candela);
    let below = light.sample_towards(DVec3::ZERO, [0.5, 0.5]).unwrap();
    assert!((below.intensity * k - scale * candela[0][0]).abs() < 1e-6 * candela[0][0]);
    for bad in [r#""lumens": 5000, "multiplier": 2"#, r#""lumens": -1"#, r#""lumens": 0"#] {
        let json =
            format!(r#"{{"type": "IesLight", "file": "lum.ies", "position": [0, 3, 0], {bad}}}"#);
        let e = load(&dir, &json).unwrap_err();
        assert!(e.contains("IesLight.lumens"), "{bad}: {e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An IES file of photometric type `kind` (2: B, 3: A) with vertical angles `vs`, horizontal
/// angles `hs` and the candela `at(h, v)`, a 0.1 x 0.2 x 0.05 m opening, absolute photometry.
fn polar_file(kind: u8, hs: &[f64], vs: &[f64], at: &dyn Fn(f64, f64) -> f64) -> String {
    let mut t = format!("IESNA:LM-63-2002\n[TEST] type {kind}\nTILT=NONE\n");
    t += &format!("1 -1 1 {} {} {kind} 2 0.1 0.2 0.05\n1 1 20\n", vs.len(), hs.len());
    let line = |a: &[f64]| a.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ") + "\n";
    t += &line(vs);
    t += &line(hs);
    for &h in hs {
        t += &line(&vs.iter().map(|&v| at(h, v)).collect::<Vec<_>>());
    }
    t
}

/// The light of an IES `text` at the origin, `nadir` -y and `c0` +x, of illuminant A.
fn polar_light(text: &str) -> IesLight {
    let f = spectrace_lights::photometry::IesFile::parse(text, "polar.ies").unwrap();
    let a = spectrace_lights::spectrum::CieIlluminant::new("A").unwrap();
    IesLight::new(
        f,
        DVec3::ZERO,
        DVec3::NEG_Y,
        DVec3::X,
        std::sync::Arc::new(a),
        1.0,
        Default::default(),
    )
    .unwrap()
}

/// The zonal flux of a polar table: each cell's mean of its four corners `at(h, v)` times its
/// solid angle `d(plane) (sin within_b - sin within_a)`, where the planes turn by `H` (type A)
/// or by `V` (type B) and the other angle lies within them.
fn zonal(hs: &[f64], vs: &[f64], at: &dyn Fn(f64, f64) -> f64, planes_turn_by_h: bool) -> f64 {
    let mut sum = 0.0;
    for i in 0..hs.len() - 1 {
        for j in 0..vs.len() - 1 {
            let avg = (at(hs[i], vs[j])
                + at(hs[i + 1], vs[j])
                + at(hs[i], vs[j + 1])
                + at(hs[i + 1], vs[j + 1]))
                / 4.0;
            let (plane, within) = if planes_turn_by_h {
                (hs[i + 1] - hs[i], (vs[j], vs[j + 1]))
            } else {
                (vs[j + 1] - vs[j], (hs[i], hs[i + 1]))
            };
            sum += avg
                * plane.to_radians()
                * (within.1.to_radians().sin() - within.0.to_radians().sin());
        }
    }
    sum
}

/// A type B (floodlight) file of asymmetric made-up intensities. Its table is read about its
/// horizontal polar axis `c0`, the photometric axis along `nadir`: the direction of type B
/// angles `(H, V)` is `sin H c0 + cos H (cos V nadir + sin V (nadir x c0))`, where the light
/// gives the file's value; the flux is the file's zonal sum `sum avg4 dV (sin H_b - sin H_a)`
/// (the bilinear interpolant in `(V, sin H)` integrated exactly); a table given for `H >= 0`
/// only is the mirrored full one; and the back half-space gets no light.
#[test]
fn type_b_tables_turn_about_their_horizontal_axis() {
    let hs = [-90.0, -40.0, 0.0, 30.0, 90.0];
    let vs = [-90.0, -20.0, 0.0, 45.0, 90.0];
    let value = |h: f64, v: f64| 100.0 + 3.0 * (h + 90.0) + 0.5 * (v + 90.0) + 0.01 * h * v;
    // The pole (H = +-90) is one direction whatever V.
    let at = |h: f64, v: f64| value(h, if h.abs() == 90.0 { 0.0 } else { v });
    let (nadir, c0) = (DVec3::NEG_Y, DVec3::X);
    let full = polar_light(&polar_file(2, &hs, &vs, &at));
    let direction = |h: f64, v: f64| {
        let (h, v) = (h.to_radians(), v.to_radians());
        c0 * h.sin() + (nadir * v.cos() + nadir.cross(c0) * v.sin()) * h.cos()
    };
    // The poles (H = +-90) are left out: every plane meets there, the dark back's too, so the
    // intensity exactly at a pole is a discontinuity of no solid angle.
    for &h in hs.iter().filter(|h| h.abs() < 90.0) {
        for &v in &vs {
            let want = value(h, v);
            let got = full.candela_towards(direction(h, v));
            assert!((got - want).abs() < 1e-9 * want, "H {h}, V {v}: {got} vs {want}");
        }
    }
    assert_eq!(full.candela_towards(-nadir), 0.0, "the back of a floodlight is dark");
    let zonal = zonal(&hs, &vs, &at, false);
    assert!((full.lumens() - zonal).abs() < 1e-6 * zonal, "{} vs {zonal}", full.lumens());
    // A symmetric table given from H = 0: the same light as its mirrored full table.
    let half = polar_light(&polar_file(2, &[0.0, 30.0, 90.0], &vs, &at));
    for (h, v) in [(-30.0, 45.0), (30.0, 45.0), (-60.0, -20.0), (60.0, -20.0)] {
        let a = half.candela_towards(direction(h, v));
        let b = half.candela_towards(direction(-h, v));
        assert!((a - b).abs() < 1e-9 * a.max(1.0), "mirror H {h}, V {v}: {a} vs {b}");
        assert!(a > 0.0, "H {h}, V {v} is in front");
    }
}

/// A type A (automotive and signal light) file of asymmetric made-up intensities. Its vertical
/// planes share the vertical axis, as type C's, but its vertical angles are elevations (`V =
/// -90` straight down, along `nadir`) and its horizontal angles turn clockwise seen from above
/// from the photometric horizontal `c0` (LM-63-2002 section 3): the direction of `(H, V)` is
/// `cos V (cos H c0 + sin H (c0 x up)) + sin V up` with `up = -nadir`. The light gives the
/// file's value there; the flux is the zonal sum `sum avg4 dH (sin V_b - sin V_a)`; a table
/// given for `H >= 0` only is the mirrored full one; the back half-space gets no light.
#[test]
fn type_a_tables_turn_about_the_vertical_axis_clockwise() {
    let hs = [-90.0, -40.0, 0.0, 30.0, 90.0];
    let vs = [-90.0, -20.0, 0.0, 45.0, 90.0];
    let value = |h: f64, v: f64| 100.0 + 3.0 * (h + 90.0) + 0.5 * (v + 90.0) + 0.01 * h * v;
    // At the zenith and the nadir (V = +-90) every plane meets: one value whatever H.
    let at = |h: f64, v: f64| value(if v.abs() == 90.0 { 0.0 } else { h }, v);
    let (nadir, c0) = (DVec3::NEG_Y, DVec3::X);
    let full = polar_light(&polar_file(3, &hs, &vs, &at));
    let up = -nadir;
    let direction = |h: f64, v: f64| {
        let (h, v) = (h.to_radians(), v.to_radians());
        (c0 * h.cos() + c0.cross(up) * h.sin()) * v.cos() + up * v.sin()
    };
    // Clockwise from above: H = +90 is +z when c0 is +x and up is +y.
    assert!((direction(90.0, 0.0) - DVec3::Z).length() < 1e-12);
    for &h in hs.iter().filter(|h| h.abs() < 90.0) {
        for &v in vs.iter().filter(|v| v.abs() < 90.0) {
            let want = value(h, v);
            let got = full.candela_towards(direction(h, v));
            assert!((got - want).abs() < 1e-9 * want, "H {h}, V {v}: {got} vs {want}");
        }
    }
    let down = full.candela_towards(nadir);
    assert!((down - value(0.0, -90.0)).abs() < 1e-9 * down, "photometric zero: {down}");
    assert_eq!(full.candela_towards(-c0), 0.0, "behind the photometric horizontal is dark");
    let zonal = zonal(&hs, &vs, &at, true);
    assert!((full.lumens() - zonal).abs() < 1e-6 * zonal, "{} vs {zonal}", full.lumens());
    // A laterally symmetric table given from H = 0: the mirrored full one.
    let half = polar_light(&polar_file(3, &[0.0, 30.0, 90.0], &vs, &at));
    for (h, v) in [(30.0, 45.0), (60.0, -20.0)] {
        let a = half.candela_towards(direction(h, v));
        let b = half.candela_towards(direction(-h, v));
        assert!((a - b).abs() < 1e-9 * a, "mirror H {h}, V {v}: {a} vs {b}");
        assert!(a > 0.0, "H {h}, V {v} is in front");
    }
    // The scene-file form keeps the keys as given.
    let json = serde_json::to_value(&full).unwrap();
    assert_eq!(json["nadir"], serde_json::json!([0.0, -1.0, 0.0]));
    // The opening (width 0.1, length 0.2, height 0.05) faces the photometric horizontal: seen
    // from straight ahead it shows its width x length face, as a lamp's lens.
    let ahead = full.glare_view(c0 * 10.0).unwrap();
    assert!((ahead.projected_area - 0.1 * 0.2).abs() < 1e-12, "{ahead:?}");
    assert!((ahead.intensity - value(0.0, 0.0)).abs() < 1e-9, "{ahead:?}");
}
