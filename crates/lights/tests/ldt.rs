//! The EULUMDAT reader: a complete file in the format's line structure (two lamp sets, decimal
//! commas), every symmetry indicator and the planes it stores, absolute scaling, absolute
//! photometry, malformed files each refused with their line and cause, and a property test; and
//! the uniform view [`CandelaPlanes`] of an IES file.
#![allow(clippy::unwrap_used)]

use proptest::prelude::*;
use spectrace_lights::photometry::{CandelaPlanes, IesFile, LdtFile, LdtSymmetry};

/// A complete file: Isym 4 (both planes), Mc 4, Ng 3, two lamp sets, decimal commas in some
/// fields. Line numbers are given in the comments of the tests that use them.
const DOWNLIGHT: &str = "ACME Leuchten GmbH / DB 7 / EULUMDAT
1
4
4
90
3
45
LR-2024-117
Downlight Rund 2x18W
DL-218
DL218.LDT
12.03.2024 / Pruefer
220
0
95,5
180
0
20
21
22
23
100
67,5
1,000
0
2
1
TC-D 18W
1200
3000 K
1B
21,5
1
TC-D 18W/840
1100,5
4000 K
Ra 80
20
0,45
0,52
0,58
0,63
0,67
0,72
0,76
0,79
0,83
0,86
0
90
180
270
0
45
90
300
250,5
100
310
240
90
";

#[test]
fn a_complete_file_reads_back_every_field() {
    let f = LdtFile::parse(DOWNLIGHT, "dl.ldt").unwrap();
    assert_eq!(f.company, "ACME Leuchten GmbH / DB 7 / EULUMDAT");
    assert_eq!((f.type_indicator, f.symmetry), (1, LdtSymmetry::Quadrants));
    assert_eq!(
        (f.c_plane_count, f.c_plane_distance, f.gamma_count, f.gamma_distance),
        (4, 90.0, 3, 45.0)
    );
    assert_eq!(f.report_number, "LR-2024-117");
    assert_eq!(f.luminaire_name, "Downlight Rund 2x18W");
    assert_eq!(f.luminaire_number, "DL-218");
    assert_eq!(f.file_name, "DL218.LDT");
    assert_eq!(f.date_user, "12.03.2024 / Pruefer");
    assert_eq!(f.luminaire_size_mm, [220.0, 0.0, 95.5]);
    assert_eq!(f.luminous_area_mm, [180.0, 0.0]);
    assert_eq!(f.luminous_heights_mm, [20.0, 21.0, 22.0, 23.0]);
    assert_eq!((f.downward_flux_fraction, f.light_output_ratio), (100.0, 67.5));
    assert_eq!((f.conversion_factor, f.tilt), (1.0, 0.0));
    assert_eq!(f.lamp_sets.len(), 2);
    let (a, b) = (&f.lamp_sets[0], &f.lamp_sets[1]);
    assert_eq!((a.lamps, a.kind.as_str(), a.flux), (1, "TC-D 18W", 1200.0));
    assert_eq!(
        (a.colour_temperature.as_str(), a.colour_rendering.as_str(), a.watts),
        ("3000 K", "1B", 21.5)
    );
    assert_eq!((b.lamps, b.kind.as_str(), b.flux), (1, "TC-D 18W/840", 1100.5));
    assert_eq!(
        (b.colour_temperature.as_str(), b.colour_rendering.as_str(), b.watts),
        ("4000 K", "Ra 80", 20.0)
    );
    assert_eq!(
        f.direct_ratios,
        [0.45, 0.52, 0.58, 0.63, 0.67, 0.72, 0.76, 0.79, 0.83, 0.86].map(Some)
    );
    assert_eq!(f.c_angles, vec![0.0, 90.0, 180.0, 270.0]);
    assert_eq!(f.gamma_angles, vec![0.0, 45.0, 90.0]);
    assert_eq!(f.intensities, vec![vec![300.0, 250.5, 100.0], vec![310.0, 240.0, 90.0]]);
    assert!(!f.is_absolute());
    assert_eq!((f.set_flux(0), f.set_flux(1), f.set_flux(2)), (Some(1200.0), Some(1100.5), None));
}

/// The lamp sets are alternatives (as DIALux and Relux read them): the table is scaled by the
/// chosen set's flux alone, never by their sum.
#[test]
fn candela_planes_are_absolute_cd_per_klm_times_one_lamp_sets_flux() {
    let f = LdtFile::parse(DOWNLIGHT, "dl.ldt").unwrap();
    for (set, flux) in [(0, 1200.0), (1, 1100.5)] {
        let p = f.candela_planes(set).unwrap();
        assert_eq!(p.horizontal, vec![0.0, 90.0]);
        assert_eq!(p.vertical, vec![0.0, 45.0, 90.0]);
        assert_eq!(p.lamp_lumens, Some(flux));
        let expected = [[300.0, 250.5, 100.0], [310.0, 240.0, 90.0]];
        for (row, want) in p.candela.iter().zip(expected) {
            for (&cd, klm) in row.iter().zip(want) {
                let scaled = klm * flux / 1000.0;
                assert!((cd - scaled).abs() < 1e-9 * cd.max(1.0), "{cd} vs {klm} cd/klm");
            }
        }
    }
    assert!(f.candela_planes(2).is_none());
}

#[test]
fn crlf_line_ends_and_trailing_blank_lines_are_accepted() {
    let text = format!("{}\r\n\r\n  \r\n", DOWNLIGHT.replace('\n', "\r\n"));
    let f = LdtFile::parse(&text, "dl.ldt").unwrap();
    assert_eq!(f, LdtFile::parse(DOWNLIGHT, "dl.ldt").unwrap());
}

/// A file with the given symmetry, C and gamma angles, lamp sets `(lamps, flux)` and stored
/// rows; numbers written with a decimal comma when `comma`.
fn ldt(
    isym: u8,
    c: &[f64],
    g: &[f64],
    sets: &[(i32, f64)],
    rows: &[Vec<f64>],
    comma: bool,
) -> String {
    let n = |v: f64| {
        let s = format!("{v}");
        if comma { s.replace('.', ",") } else { s }
    };
    let mut lines = vec![
        "Test".to_owned(),
        "3".to_owned(),
        isym.to_string(),
        c.len().to_string(),
        "0".to_owned(),
        g.len().to_string(),
        "0".to_owned(),
    ];
    lines.extend(["r", "name", "number", "f.ldt", "date"].map(str::to_owned));
    lines.extend(std::iter::repeat_n(n(10.5), 9));
    lines.extend([n(80.5), n(72.5), "1".to_owned(), "0".to_owned(), sets.len().to_string()]);
    for &(lamps, flux) in sets {
        lines.extend([
            lamps.to_string(),
            "LED".to_owned(),
            n(flux),
            "3000".to_owned(),
            "80".to_owned(),
            n(12.5),
        ]);
    }
    lines.extend(std::iter::repeat_n(n(0.5), 10));
    lines.extend(c.iter().map(|&v| n(v)));
    lines.extend(g.iter().map(|&v| n(v)));
    lines.extend(rows.iter().flatten().map(|&v| n(v)));
    lines.join("\n") + "\n"
}

/// `count` rows of distinct values for `gammas` gamma angles.
fn rows(count: usize, gammas: usize) -> Vec<Vec<f64>> {
    (0..count)
        .map(|p| (0..gammas).map(|g| 100.0 * p as f64 + 10.0 * g as f64 + 0.5).collect())
        .collect()
}

#[test]
fn each_symmetry_stores_its_planes_and_maps_them_to_the_ies_ranges() {
    let c8: Vec<f64> = (0..8).map(|i| 45.0 * i as f64).collect();
    let g = [0.0, 30.0, 60.0, 90.0, 180.0];
    let cases: [(u8, &[f64], LdtSymmetry, Vec<f64>); 6] = [
        (0, &c8, LdtSymmetry::None, c8.clone()),
        (1, &[0.0], LdtSymmetry::Rotational, vec![0.0]),
        (1, &c8, LdtSymmetry::Rotational, vec![0.0]),
        (2, &c8, LdtSymmetry::AboutC0C180, vec![0.0, 45.0, 90.0, 135.0, 180.0]),
        (3, &c8, LdtSymmetry::AboutC90C270, vec![90.0, 135.0, 180.0, 225.0, 270.0]),
        (4, &c8, LdtSymmetry::Quadrants, vec![0.0, 45.0, 90.0]),
    ];
    for (isym, c, symmetry, horizontal) in cases {
        let stored = rows(horizontal.len(), g.len());
        for comma in [false, true] {
            let text = ldt(isym, c, &g, &[(2, 1500.0), (1, 500.0)], &stored, comma);
            let f = LdtFile::parse(&text, "sym.ldt").unwrap_or_else(|e| panic!("Isym {isym}: {e}"));
            assert_eq!(f.symmetry, symmetry);
            assert_eq!(f.symmetry.indicator(), isym);
            assert_eq!(f.intensities, stored, "Isym {isym}");
            assert_eq!(f.light_output_ratio, 72.5);
            let p = f.candela_planes(0).unwrap();
            assert_eq!(p.horizontal, horizontal, "Isym {isym}");
            assert_eq!(p.vertical, g.to_vec());
            assert_eq!(p.lamp_lumens, Some(1500.0));
            // Set 1's 1500 lm: 1.5 times the cd/klm values.
            let doubled: Vec<Vec<f64>> =
                stored.iter().map(|r| r.iter().map(|v| 1.5 * v).collect()).collect();
            assert_eq!(p.candela, doubled, "Isym {isym}");
        }
        // One plane too few stored: the file ends early.
        let short = ldt(isym, c, &g, &[(1, 1000.0)], &rows(horizontal.len() - 1, g.len()), false);
        let e = LdtFile::parse(&short, "sym.ldt").unwrap_err();
        assert!(e.message.contains("ends before"), "Isym {isym}: {e}");
        // One plane too many: values left over.
        let long = ldt(isym, c, &g, &[(1, 1000.0)], &rows(horizontal.len() + 1, g.len()), false);
        let e = LdtFile::parse(&long, "sym.ldt").unwrap_err();
        assert!(e.message.contains("after the last intensity"), "Isym {isym}: {e}");
        assert_eq!(e.line, long.lines().count() - g.len() + 1, "Isym {isym}: {e}");
    }
}

#[test]
fn negative_lamp_counts_mean_absolute_photometry() {
    let text = ldt(1, &[0.0], &[0.0, 90.0], &[(-1, 3500.0)], &[vec![200.0, 50.0]], false);
    let f = LdtFile::parse(&text, "abs.ldt").unwrap();
    assert!(f.is_absolute());
    assert_eq!(f.lamp_sets[0].lamps, -1);
    let p = f.candela_planes(0).unwrap();
    assert_eq!(p.lamp_lumens, None);
    assert_eq!(p.candela, vec![vec![700.0, 175.0]]);
    // Mixing absolute and relative sets is refused at the second set's count (line 33).
    let mixed =
        ldt(1, &[0.0], &[0.0, 90.0], &[(-1, 3500.0), (1, 100.0)], &[vec![200.0, 50.0]], false);
    let e = LdtFile::parse(&mixed, "abs.ldt").unwrap_err();
    assert_eq!(e.line, 33, "{e}");
    assert!(e.message.contains("every set or none"), "{e}");
}

/// The error of parsing `text` as `bad.ldt`: its line and message.
fn error(text: &str) -> (usize, String) {
    let e = LdtFile::parse(text, "bad.ldt").unwrap_err();
    assert!(e.to_string().starts_with(&format!("bad.ldt:{}: ", e.line)), "{e}");
    (e.line, e.message)
}

/// `DOWNLIGHT` with line `n` (1-based) replaced by `with`.
fn with_line(n: usize, with: &str) -> String {
    let mut lines: Vec<&str> = DOWNLIGHT.lines().collect();
    lines[n - 1] = with;
    lines.join("\n") + "\n"
}

/// The first `n` lines of `DOWNLIGHT`.
fn first_lines(n: usize) -> String {
    DOWNLIGHT.lines().take(n).collect::<Vec<_>>().join("\n") + "\n"
}

#[track_caller]
fn assert_error(text: &str, line: usize, word: &str) {
    let (l, m) = error(text);
    assert_eq!(l, line, "{m}");
    assert!(m.contains(word), "`{word}` not in: {m}");
}

#[test]
fn truncated_files_name_their_last_line_and_what_is_missing() {
    assert_error("", 1, "the file ends before line 1 (the company identification)");
    assert_error(&first_lines(5), 5, "ends before line 6 (Ng");
    assert_error(&first_lines(25), 25, "ends before line 26 (the number of lamp sets)");
    assert_error(&first_lines(30), 30, "lamp set 1: the colour rendering index");
    assert_error(&first_lines(40), 40, "direct ratio[2]");
    assert_error(&first_lines(50), 50, "C angle[2]");
    assert_error(&first_lines(54), 54, "gamma angle[2]");
    assert_error(&first_lines(60), 60, "intensity[1][2]");
}

#[test]
fn malformed_files_are_refused_with_their_line_and_cause() {
    // Header indicators and counts.
    assert_error(&with_line(2, "4"), 2, "Ityp (the type indicator) = 4");
    assert_error(&with_line(3, "5"), 3, "Isym (the symmetry indicator) = 5");
    assert_error(&with_line(4, "0"), 4, "Mc (the number of C planes) = 0");
    assert_error(&with_line(4, "4097"), 4, "from 1 to 4096");
    assert_error(&with_line(4, "6"), 4, "multiple of 4");
    assert_error(&with_line(6, "2,5"), 6, "Ng (the number of gamma angles) = 2.5");
    assert_error(&with_line(26, "21"), 26, "number of lamp sets = 21");
    assert_error(&with_line(26, "0"), 26, "number of lamp sets = 0");
    // Numbers: not numbers, non-finite, thousands separators, empty lines.
    assert_error(
        &with_line(5, "ninety"),
        5,
        "Dc (the distance between C planes): expected a number, found `ninety`",
    );
    assert_error(
        &with_line(29, "nan"),
        29,
        "lamp set 1: the total luminous flux: expected a number",
    );
    assert_error(&with_line(35, "1.100,5"), 35, "found `1.100,5`");
    assert_error(&with_line(13, ""), 13, "found an empty line");
    assert_error(&with_line(57, "inf"), 57, "intensity[0][1]");
    // Ranges of the fields the table depends on.
    assert_error(&with_line(22, "120"), 22, "DFF (the downward flux fraction) = 120");
    assert_error(&with_line(23, "-1"), 23, "LORL");
    assert_error(&with_line(27, "0"), 27, "lamp set 1: the number of lamps = 0");
    assert_error(&with_line(35, "0"), 35, "lamp set 2: the total luminous flux = 0");
    assert_error(&with_line(38, "-20"), 38, "lamp set 2: the wattage = -20");
    // Angles.
    assert_error(&with_line(51, "80"), 51, "C angles must increase strictly: 80 after 90");
    assert_error(&with_line(49, "10"), 49, "C angle[0] = 10: the C angles begin with 0");
    assert_error(&with_line(52, "360"), 52, "C angle[3] = 360: C angles lie in [0, 360)");
    assert_error(&with_line(50, "80"), 50, "stored planes end at C90");
    assert_error(&with_line(55, "40"), 55, "gamma angles must increase strictly: 40 after 45");
    assert_error(&with_line(55, "190"), 55, "gamma angle[2] = 190");
    // One gamma angle too many declared: the first intensity is read as a gamma angle.
    assert_error(&with_line(6, "4"), 56, "gamma angle[3] = 300");
    // Intensities.
    assert_error(
        &with_line(57, "-250,5"),
        57,
        "intensity[0][1] (C0, gamma 45) = -250.5: must be >= 0",
    );
    // Trailing garbage, after blank lines.
    assert_error(&format!("{DOWNLIGHT}\n \n42\n"), 64, "`42` after the last intensity");
}

#[test]
fn symmetry_ends_are_checked_for_isym_2_and_3() {
    let c8: Vec<f64> = (0..8).map(|i| 45.0 * i as f64).collect();
    let mut bent = c8.clone();
    bent[4] = 170.0;
    // Isym 2: angle 4 of 8 must be C180.
    let text = ldt(2, &bent, &[0.0, 90.0], &[(1, 1000.0)], &rows(5, 2), false);
    let (line, m) = error(&text);
    assert_eq!(text.lines().nth(line - 1), Some("170"));
    assert!(m.contains("C angle[4] = 170") && m.contains("C180"), "{m}");
    // Isym 3: angles 2 and 6 of 8 must be C90 and C270.
    let mut bent = c8.clone();
    bent[6] = 260.0;
    let text = ldt(3, &bent, &[0.0, 90.0], &[(1, 1000.0)], &rows(5, 2), false);
    let (line, m) = error(&text);
    assert_eq!(text.lines().nth(line - 1), Some("260"));
    assert!(m.contains("C angle[6] = 260") && m.contains("C270"), "{m}");
    // Isym 2 with an odd Mc.
    let text = ldt(2, &[0.0, 120.0, 240.0], &[0.0], &[(1, 1000.0)], &rows(2, 1), false);
    assert_eq!(
        error(&text),
        (
            4,
            "Mc = 3 with Isym 2: must be a multiple of 2 (the stored planes end at C180)"
                .to_owned()
        )
    );
}

#[test]
fn ies_candela_planes_keep_the_stored_table_and_sum_the_lamp_lumens() {
    let text = "IESNA:LM-63-2002
TILT=NONE
2 1500 2.0 3 3 1 2 0 0 0
1.0 1.0 40
0 45 90
0 90 180
100 80 10
90 70 5
80 60 0
";
    let p = IesFile::parse(text, "x.ies").unwrap().candela_planes();
    assert_eq!(
        p,
        CandelaPlanes {
            horizontal: vec![0.0, 90.0, 180.0],
            vertical: vec![0.0, 45.0, 90.0],
            candela: vec![
                vec![200.0, 160.0, 20.0],
                vec![180.0, 140.0, 10.0],
                vec![160.0, 120.0, 0.0]
            ],
            lamp_lumens: Some(3000.0),
        }
    );
    let absolute = text.replace("2 1500 2.0", "2 -1 2.0");
    assert_eq!(IesFile::parse(&absolute, "x.ies").unwrap().candela_planes().lamp_lumens, None);
    // No symmetry, ending at 360 (a duplicate of 0): kept as stored.
    let full =
        text.replace("3 3 1 2", "3 4 1 2").replace("0 90 180\n", "0 90 180 360\n") + "100 80 10\n";
    assert_eq!(
        IesFile::parse(&full, "x.ies").unwrap().candela_planes().horizontal,
        vec![0.0, 90.0, 180.0, 360.0]
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Any text gives a file or an error: never a panic.
    #[test]
    fn any_text_gives_a_file_or_an_error(text in "(?s).{0,400}") {
        let _ = LdtFile::parse(&text, "fuzz.ldt");
    }

    /// Any text of lines that look like numbers gives a file or an error naming a real line.
    #[test]
    fn number_lines_give_a_file_or_an_error(lines in prop::collection::vec("[0-9 .,eE+-]{0,6}", 0..120)) {
        let text = lines.join("\n");
        if let Err(e) = LdtFile::parse(&text, "fuzz.ldt") {
            prop_assert!(e.line >= 1 && e.line <= text.lines().count().max(1));
        }
    }

    /// A corrupted valid file gives a file or an error naming one of its lines.
    #[test]
    fn a_corrupted_file_gives_a_file_or_an_error_naming_a_line(cut in 0usize..700, insert in "[0-9 .,\n-]{0,8}") {
        let mut text = DOWNLIGHT.to_owned();
        let at = cut.min(text.len());
        let at = (0..=at).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
        text.insert_str(at, &insert);
        if let Err(e) = LdtFile::parse(&text, "fuzz.ldt") {
            prop_assert!(e.line >= 1 && e.line <= text.lines().count().max(1));
        }
    }
}
