//! The luminaire readers on the files makers ship: the 53 real IES and EULUMDAT files of
//! `../shared/realworld/photometry/files/` (skipped, with a message, when that folder is absent)
//! load, with the flux of an independent integration of their tables, and the variants that
//! lighting software accepts (old Mac line ends, lowercase keywords, DOS trailers, Windows-1252
//! bytes, blank direct ratios) load with the same flux as the file they vary.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use spectrace_lights::LightSource;
use spectrace_lights::photometry::{CandelaPlanes, IesFile, LdtFile, Photometry, decode_text};

use crate::rendering::temp_dir;

/// `../shared/realworld/photometry/files` beside the workspace, if present.
fn realworld_photometry() -> Option<PathBuf> {
    crate::rendering::realworld("photometry/files")
}

/// The flux (lm) of a table, integrated independently of the light: per C plane the exact
/// integral of the intensity linear in `cos gamma` between measured angles, then the planes
/// linear in `C`, unfolded over the circle by the symmetry the horizontal range declares.
fn table_lumens(p: &CandelaPlanes) -> f64 {
    let zone = |row: &[f64]| -> f64 {
        let g: Vec<f64> = p.vertical.iter().map(|v| v.to_radians().cos()).collect();
        (0..g.len() - 1).map(|j| 0.5 * (row[j] + row[j + 1]) * (g[j] - g[j + 1])).sum()
    };
    let zones: Vec<f64> = p.candela.iter().map(|r| zone(r)).collect();
    let h = &p.horizontal;
    if h.len() == 1 {
        return 2.0 * PI * zones[0];
    }
    let mut sum: f64 = (0..h.len() - 1)
        .map(|k| 0.5 * (zones[k] + zones[k + 1]) * (h[k + 1] - h[k]).to_radians())
        .sum();
    let span = h[h.len() - 1] - h[0];
    if span < 360.0 && h[0] == 0.0 && h[h.len() - 1] > 180.0 {
        // No symmetry, the last plane short of 360: wrap back to C0.
        sum += 0.5 * (zones[0] + zones[h.len() - 1]) * (360.0 - h[h.len() - 1]).to_radians();
        return sum;
    }
    sum * 360.0 / span.max(f64::MIN_POSITIVE)
}

/// The flux (lm) of a full type B (or A) table from the file's own grid, as floodlight
/// photometry computes it: each cell's mean of its four corners times its solid angle
/// `dV (sin H_b - sin H_a)` (`H` within the measuring plane, `V` the plane's turn; for type A
/// the roles are exchanged).
fn polar_zonal_lumens(f: &IesFile) -> f64 {
    let (hs, vs) = (&f.horizontal, &f.vertical);
    assert!(hs[0] == -90.0 && vs[0] == -90.0, "a full table");
    let mut sum = 0.0;
    for i in 0..hs.len() - 1 {
        for j in 0..vs.len() - 1 {
            let c = &f.candela;
            let mean = (c[i][j] + c[i + 1][j] + c[i][j + 1] + c[i + 1][j + 1]) / 4.0;
            // Type B: V turns the plane, H lies within it; type A the other way round.
            let (plane, within) = match f.photometry {
                Photometry::A => ((hs[i + 1] - hs[i]), (vs[j], vs[j + 1])),
                _ => ((vs[j + 1] - vs[j]), (hs[i], hs[i + 1])),
            };
            sum += mean
                * plane.to_radians()
                * (within.1.to_radians().sin() - within.0.to_radians().sin());
        }
    }
    sum
}

/// A luminaire light read from `file` by the scene-file form.
fn light(kind: &str, file: &Path, extra: &str) -> Result<Box<dyn LightSource>, String> {
    let json = format!(r#"{{"type": "{kind}", "file": {file:?}, "position": [0, 3, 0]{extra}}}"#);
    serde_json::from_str(&json).map_err(|e| e.to_string())
}

/// The lumens a light reports (its power times its spectrum's efficacy).
fn lumens(light: &dyn LightSource) -> f64 {
    light.power() * spectrace_spectrum::luminous_efficacy(light.spd().as_ref())
}

/// Every real file loads, the floodlight in type B photometry too; each light's flux is the
/// independent integration of its table within 0.5% (the floodlight's: its own grid's zonal
/// sum; set 1 for the two EULUMDAT files with several lamp sets, which also say so in a note);
/// and a file with a Windows-1252 byte says it was read so.
#[test]
fn every_real_luminaire_file_loads_with_the_flux_of_its_table() {
    let Some(dir) = realworld_photometry() else { return };
    let mut files: Vec<PathBuf> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    assert_eq!(files.len(), 53, "the real-file set changed");
    let mut refused = Vec::new();
    let mut several_sets = Vec::new();
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let ies = name.ends_with(".ies");
        let loaded = light(if ies { "IesLight" } else { "EulumdatLight" }, path, "");
        let light = match loaded {
            Ok(l) => l,
            Err(e) => {
                refused.push((name, e));
                continue;
            }
        };
        let (text, _) = decode_text(&std::fs::read(path).unwrap());
        let want = if ies {
            let f = IesFile::parse(&text, &name).unwrap();
            let table = match f.photometry {
                Photometry::C => table_lumens(&f.candela_planes()),
                Photometry::B | Photometry::A => polar_zonal_lumens(&f),
            };
            table * f.ballast_factor
        } else {
            let f = LdtFile::parse(&text, &name).unwrap();
            if f.lamp_sets.len() > 1 {
                several_sets.push(name.clone());
                assert!(
                    light.notes().iter().any(|n| n.contains("set 1 used")),
                    "{name}: {:?}",
                    light.notes()
                );
            }
            table_lumens(&f.candela_planes(0).unwrap())
        };
        let got = lumens(light.as_ref());
        assert!(
            (got / want - 1.0).abs() < 5e-3,
            "{name}: {got} lm, the table integrates to {want} lm"
        );
        if name == "rp_vee_erco.ies" || name == "zumtobel_crossign_d31267aa.ldt" {
            assert!(
                light.notes().iter().any(|n| n.contains("Windows-1252")),
                "{name}: {:?}",
                light.notes()
            );
        }
    }
    assert!(refused.is_empty(), "refused: {refused:?}");
    assert_eq!(several_sets.len(), 2, "{several_sets:?}");
}

/// Set 2 of the two-set Philips file is chosen by `lamp_set`; a set the file lacks, or the key
/// on an IES file, is refused naming it.
#[test]
fn lamp_set_chooses_among_a_files_alternatives() {
    let Some(dir) = realworld_photometry() else { return };
    let file = dir.join("philips_townguide_2lampsets.ldt");
    let (text, _) = decode_text(&std::fs::read(&file).unwrap());
    let f = LdtFile::parse(&text, "townguide").unwrap();
    let second = light("EulumdatLight", &file, r#", "lamp_set": 2"#).unwrap();
    let want = table_lumens(&f.candela_planes(1).unwrap());
    assert!((lumens(second.as_ref()) / want - 1.0).abs() < 5e-3);
    let e = light("EulumdatLight", &file, r#", "lamp_set": 3"#).err().unwrap();
    assert!(e.contains("lamp_set"), "{e}");
    let ies = dir.join("rab_1.ies");
    let e = light("IesLight", &ies, r#", "lamp_set": 1"#).err().unwrap();
    assert!(e.contains("lamp_set"), "{e}");
}

/// Variants of the shipped luminaires that lighting software reads: each loads with exactly the
/// flux of the original, and says what its reading took where that is worth telling.
#[test]
fn variants_makers_ship_load_with_the_same_flux() {
    let dir = temp_dir("luminaire-variants");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/luminaires");
    let ies = std::fs::read_to_string(root.join("downlight.ies")).unwrap();
    let ldt = std::fs::read_to_string(root.join("linear.ldt")).unwrap();
    let flux = |kind: &str, name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let l = light(kind, &path, "").unwrap_or_else(|e| panic!("{name}: {e}"));
        (lumens(l.as_ref()), l.notes())
    };
    let (base_ies, _) = flux("IesLight", "base.ies", ies.as_bytes());
    let (base_ldt, _) = flux("EulumdatLight", "base.ldt", ldt.as_bytes());
    let mut latin1 = ies.replacen("TILT", "[OTHER] 10\u{b0} tilt\nTILT", 1).into_bytes();
    let degree = latin1.windows(2).position(|w| w == [0xc2, 0xb0]).unwrap();
    latin1.splice(degree..degree + 2, [0xb0]);
    let ies_variants: Vec<(&str, Vec<u8>, Option<&str>)> = vec![
        ("cr.ies", ies.replace("\r\n", "\n").replace('\n', "\r").into_bytes(), Some("lone CR")),
        ("crlf.ies", ies.replace('\n', "\r\n").into_bytes(), None),
        ("lower.ies", ies.replace("TILT=NONE", "tilt = none").into_bytes(), None),
        ("end.ies", format!("{}\nEND\n\u{1a}", ies.trim_end()).into_bytes(), Some("^Z")),
        ("latin1.ies", latin1, Some("Windows-1252")),
        ("bom.ies", [b"\xEF\xBB\xBF".as_slice(), ies.as_bytes()].concat(), None),
    ];
    for (name, bytes, note) in ies_variants {
        let (got, notes) = flux("IesLight", name, &bytes);
        assert_eq!(got, base_ies, "{name}");
        match note {
            Some(n) => assert!(notes.iter().any(|x| x.contains(n)), "{name}: {notes:?}"),
            None => assert!(notes.is_empty(), "{name}: {notes:?}"),
        }
    }
    // Blank direct ratios (lines 27 + 6 sets .. + 10) and a Windows-1252 name.
    let lines: Vec<&str> = ldt.lines().collect();
    let sets: usize = lines[25].trim().parse().unwrap();
    let first_ratio = 26 + 6 * sets;
    let blank: Vec<String> = lines
        .iter()
        .enumerate()
        .map(|(i, l)| {
            if (first_ratio..first_ratio + 10).contains(&i) {
                String::new()
            } else {
                (*l).to_owned()
            }
        })
        .collect();
    let (got, _) = flux("EulumdatLight", "blank.ldt", blank.join("\n").as_bytes());
    assert_eq!(got, base_ldt);
    let mut named = ldt.clone().into_bytes();
    let end_of_first = named.iter().position(|&b| b == b'\n' || b == b'\r').unwrap();
    named.splice(end_of_first..end_of_first, [b' ', 0xa7]);
    let (got, notes) = flux("EulumdatLight", "section.ldt", &named);
    assert_eq!(got, base_ldt);
    assert!(notes.iter().any(|n| n.contains("Windows-1252")), "{notes:?}");
    let cr = ldt.replace("\r\n", "\n").replace('\n', "\r");
    let (got, _) = flux("EulumdatLight", "cr.ldt", cr.as_bytes());
    assert_eq!(got, base_ldt);
}
