//! The IES LM-63 reader: files written after the format documents' structure (every version
//! line, keywords, `TILT=NONE` and `TILT=INCLUDE`, several lamps, absolute photometry, numbers
//! split over lines and commas), and malformed files, each refused with its line and cause.
#![allow(clippy::unwrap_used)]

use proptest::prelude::*;
use spectrace_lights::photometry::{IesFile, IesVersion, Units};

/// A type C file with bilateral symmetry (0-180), 5 vertical and 3 horizontal angles.
const LM63_2002: &str = "IESNA:LM-63-2002
[TEST] ABC1234 ABC Laboratories
[TESTLAB] ABC Laboratories
[ISSUEDATE] 28-FEB-2001
[MANUFAC] Aardvark Lighting Inc.
[LUMCAT] SKYVIEW 123-XYZ-abs-400
[LUMINAIRE] Wide beam flood to be used without tilt
[LAMP] 400W high pressure sodium
TILT=NONE
1 50000 2.0 5 3 1 2 0.5 0.6 0.1
1.0 1.0 495
0 22.5 45 67.5 90
0 90 180
1000 900 700 400 100
1000 850 600 300 50
1000 800 500 200 0
";

#[test]
fn a_2002_file_reads_with_its_keywords_counts_and_multiplied_candela() {
    let f = IesFile::parse(LM63_2002, "flood.ies").unwrap();
    assert_eq!(f.version, IesVersion::Lm63_2002);
    assert_eq!(f.keywords.len(), 7);
    assert_eq!(f.keywords[3], ("MANUFAC".to_owned(), "Aardvark Lighting Inc.".to_owned()));
    assert_eq!((f.lamps, f.lumens_per_lamp, f.multiplier), (1, Some(50000.0), 2.0));
    assert_eq!((f.units, f.dimensions), (Units::Metres, [0.5, 0.6, 0.1]));
    assert_eq!((f.ballast_factor, f.input_watts), (1.0, 495.0));
    assert_eq!(f.vertical, vec![0.0, 22.5, 45.0, 67.5, 90.0]);
    assert_eq!(f.horizontal, vec![0.0, 90.0, 180.0]);
    assert_eq!(f.candela[1], vec![2000.0, 1700.0, 1200.0, 600.0, 100.0]);
    assert!(f.tilt.is_none());
}

#[test]
fn every_version_line_and_the_1986_form_without_one_are_read() {
    let body = LM63_2002.split_once('\n').unwrap().1;
    for (first, version) in [
        ("IESNA91\n", IesVersion::Lm63_1991),
        ("IESNA:LM-63-1995\n", IesVersion::Lm63_1995),
        ("IES:LM-63-2019\n", IesVersion::Lm63_2019),
        ("", IesVersion::Lm63_1986),
    ] {
        let f = IesFile::parse(&format!("{first}{body}"), "x.ies").unwrap();
        assert_eq!(f.version, version);
    }
}

#[test]
fn tilt_data_several_lamps_absolute_photometry_and_free_number_layout_are_read() {
    // TILT=INCLUDE with 3 angles; 2 lamps; lumens -1 (absolute photometry); numbers split
    // over lines and separated by commas; an axially symmetric table (one horizontal angle).
    let text = "IESNA:LM-63-1995
[TEST] tilt
TILT=INCLUDE
1
3
0 45 90
1.0, 0.95, 0.8
2 -1 1
3 1 1 1
-0.2 0 0.05
1.0 1.0
60
0,
45 90
0
500 300
0
";
    let f = IesFile::parse(text, "tilt.ies").unwrap();
    let tilt = f.tilt.unwrap();
    assert_eq!(
        (tilt.geometry, tilt.angles, tilt.factors),
        (1, vec![0.0, 45.0, 90.0], vec![1.0, 0.95, 0.8])
    );
    assert_eq!((f.lamps, f.lumens_per_lamp), (2, None));
    assert_eq!(f.units, Units::Feet);
    assert_eq!(f.dimensions, [-0.2, 0.0, 0.05]);
    assert_eq!(f.candela, vec![vec![500.0, 300.0, 0.0]]);
}

/// The error text of parsing `text` as `bad.ies`.
fn error(text: &str) -> String {
    IesFile::parse(text, "bad.ies").unwrap_err().to_string()
}

#[test]
fn malformed_files_are_refused_with_their_line_and_cause() {
    // Truncated: the last candela row is missing.
    let truncated = LM63_2002.rsplit_once("1000 800").unwrap().0;
    let e = error(truncated);
    assert!(e.starts_with("bad.ies:") && e.contains("ends before candela[2][0]"), "{e}");
    // Wrong counts: one vertical angle too many declared, so the first horizontal angle is read
    // as the sixth vertical one...
    let e = error(&LM63_2002.replace("1 50000 2.0 5 3", "1 50000 2.0 6 3"));
    assert!(
        e.starts_with("bad.ies:13:") && e.contains("must increase strictly: 0 after 90"),
        "{e}"
    );
    // ... or one value too many at the end.
    let e = error(&format!("{LM63_2002}7\n"));
    assert!(e.starts_with("bad.ies:17:") && e.contains("counts do not match"), "{e}");
    // Non-monotone angles, with the line of the offending value.
    let e = error(&LM63_2002.replace("0 22.5 45 67.5 90", "0 22.5 45 40 90"));
    assert!(
        e.starts_with("bad.ies:12:")
            && e.contains("vertical angles must increase strictly: 40 after 45"),
        "{e}"
    );
    // A type C table read as type B or A has angles out of their range, named with their line.
    let e = error(&LM63_2002.replace("5 3 1 2", "5 3 2 2"));
    assert!(
        e.starts_with("bad.ies:13:") && e.contains("type B horizontal angles end at 90"),
        "{e}"
    );
    let e = error(&LM63_2002.replace("5 3 1 2", "5 3 3 2"));
    assert!(e.contains("type A horizontal angles end at 90"), "{e}");
    let e = error(&LM63_2002.replace("5 3 1 2", "5 3 4 2"));
    assert!(e.contains("photometric type = 4"), "{e}");
    // Tilt data in another file: nothing is opened.
    let e = error(&LM63_2002.replace("TILT=NONE", "TILT=/etc/passwd"));
    assert!(e.starts_with("bad.ies:9:") && e.contains("another file is not read"), "{e}");
    // No TILT line at all.
    let e = error("IESNA:LM-63-2002\n[TEST] nothing\n");
    assert!(e.contains("no TILT= line"), "{e}");
    // An unknown version line.
    let e = error(&LM63_2002.replace("IESNA:LM-63-2002", "IESNA:LM-63-2077"));
    assert!(e.starts_with("bad.ies:1:") && e.contains("unknown IES version"), "{e}");
    // Negative candela, NaN, a count that is not whole, zero lumens, a bad last angle.
    let e = error(&LM63_2002.replace("1000 850 600", "1000 -850 600"));
    assert!(e.starts_with("bad.ies:15:") && e.contains("candela value -850"), "{e}");
    let e = error(&LM63_2002.replace("1000 850 600", "1000 nan 600"));
    assert!(e.starts_with("bad.ies:15:") && e.contains("expected a number, found `nan`"), "{e}");
    let e = error(&LM63_2002.replace("2.0 5 3", "2.0 5.5 3"));
    assert!(e.contains("number of vertical angles = 5.5"), "{e}");
    let e = error(&LM63_2002.replace("1 50000", "1 0"));
    assert!(e.contains("lumens per lamp = 0"), "{e}");
    let e = error(&LM63_2002.replace("0 90 180\n", "0 90 120\n"));
    assert!(e.starts_with("bad.ies:13:") && e.contains("last horizontal angle 120"), "{e}");
    let e = error(&LM63_2002.replace("0 22.5 45 67.5 90", "0 22.5 45 67.5 190"));
    assert!(e.contains("vertical angle 190"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Any text, and any corruption of a valid file, gives a file or an error: never a panic.
    #[test]
    fn any_text_gives_a_file_or_an_error(text in "(?s).{0,400}") {
        let _ = IesFile::parse(&text, "fuzz.ies");
    }

    #[test]
    fn a_corrupted_file_gives_a_file_or_an_error_naming_a_line(cut in 0usize..500, insert in "[0-9 .,eE+-]{0,8}") {
        let mut text = LM63_2002.to_owned();
        let at = cut.min(text.len());
        let at = (0..=at).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
        text.insert_str(at, &insert);
        if let Err(e) = IesFile::parse(&text, "fuzz.ies") {
            prop_assert!(e.line >= 1 && e.line <= text.lines().count().max(1));
        }
    }
}
