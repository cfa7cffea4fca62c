//! A small, strict reader of EULUMDAT (`.ldt`) photometric files, the line-oriented format
//! A. W. Stockmar proposed in 1990 (Licht '90, pp. 641-644) that European lighting software
//! exchanges: the candela table of a measured luminaire, in cd/klm of its lamps' flux.
//!
//! Followed documents: the proposal's line table as reproduced by Helios32
//! (<http://www.helios32.com/Eulumdat.htm>) and by Lighting Analysts' Photometric Toolbox
//! (<https://docs.agi32.com/PhotometricToolbox/Content/Open_Tool/eulumdat_file_format.htm>, which
//! adds type indicator 0), and for a negative number of lamps the note "Handling of absolute
//! photometry data in EULUMDAT files" (DIAL and Lighting Analysts, 14 August 2009). One value
//! per line:
//!
//! ```text
//! line  1      company identification / data bank / version
//! line  2      Ityp: type indicator, 0..=3 (0 no symmetry, 1 rotational, 2 linear, 3 other)
//! line  3      Isym: symmetry indicator, 0..=4 (below)
//! line  4      Mc: number of C planes in [0, 360)
//! line  5      Dc: distance between C planes (0: not equidistant)
//! line  6      Ng: number of intensities (gamma angles) in each C plane
//! line  7      Dg: distance between gamma angles (0: not equidistant)
//! lines 8..12  measurement report number, luminaire name, luminaire number, file name, date/user
//! lines 13..15 length (or diameter), width (0: round), height of the luminaire (mm)
//! lines 16..17 length (or diameter), width (0: round) of the luminous area (mm)
//! lines 18..21 height of the luminous area in the planes C0, C90, C180, C270 (mm)
//! line 22      DFF: downward flux fraction (%)
//! line 23      LORL: light output ratio of the luminaire (%)
//! line 24      conversion factor for the luminous intensities
//! line 25      tilt of the luminaire during measurement (degrees)
//! line 26      n: number of standard sets of lamps, 1..=20
//! 6 lines per set: number of lamps, type, total luminous flux (lm), colour temperature,
//!              colour rendering group / index, wattage including ballast (W)
//! 10 lines     direct ratios for the room indices k = 0.6 ... 5
//! Mc lines     the C angles, beginning with 0
//! Ng lines     the gamma angles
//! the rest     intensities (cd/klm) of the stored C planes, gamma fastest
//! ```
//!
//! The stored C planes, as the documents count them: Isym 0 all `Mc` planes; 1 one plane (the
//! distribution is the same in every plane); 2 (symmetric about the plane C0-C180) the
//! `Mc/2 + 1` planes C0..=C180; 3 (symmetric about C90-C270) the `Mc/2 + 1` planes C90..=C270;
//! 4 (symmetric about both) the `Mc/4 + 1` planes C0..=C90. The C-angle lines always list all
//! `Mc` angles.
//!
//! **Numbers.** A number may be written with a decimal point or with a decimal comma (`12,5`,
//! common in German files): a value with exactly one comma and no point reads the comma as the
//! point. Anything else that Rust's `f64` parser refuses, and every non-finite value, is an error.
//! Text lines (names, lamp type, colour temperature, colour rendering) are kept trimmed.
//!
//! **Lamps.** A set's number of lamps is a non-zero whole number. A negative number marks
//! *absolute photometry* (the 2009 note): the set's flux is then the luminaire's own measured
//! flux, the lamps number its absolute value, and [`CandelaPlanes::lamp_lumens`] is `None`. All
//! sets must then be negative (a mix is refused). Several lamp sets are alternatives (the lamps
//! the luminaire may be fitted with), read as DIALux and Relux read them: the absolute candela
//! of the table are the cd/klm values times *one* set's flux / 1000 (set 1 unless the scene's
//! `lamp_set` says otherwise); the conversion factor (line 24) is kept but not applied, as the
//! readers of the documents above do.
//!
//! **Checks**, each an error naming the file, the line and the cause: Ityp 0..=3; Isym 0..=4;
//! Mc and Ng whole numbers from 1 to [`MAX_ANGLES`] (so at most `MAX_ANGLES^2` intensities);
//! Mc even for Isym 2 and a multiple of 4 for Isym 3 and 4; 1 to [`MAX_LAMP_SETS`] lamp sets;
//! lamp flux > 0, wattage >= 0; DFF and LORL in [0, 100]; every number finite; C angles start
//! at 0, lie in [0, 360) and increase strictly, and the stored range ends where the symmetry
//! says (C180 at index `Mc/2` for Isym 2, C90 and C270 at `Mc/4` and `3Mc/4` for Isym 3, C90 at
//! `Mc/4` for Isym 4); gamma angles lie in [0, 180] and increase strictly; intensities >= 0; a
//! file that ends early (the error names the last line and what was expected); anything but
//! blank lines after the last intensity. Dc and Dg are kept, not compared with the angles (the
//! angle lines are what the table uses). Fields the table does not depend on (dimensions, tilt,
//! conversion factor) are only checked to be numbers; a blank direct-ratio line reads as missing.
//! The text is read as [`super::decode_text`] gives it (UTF-8 or Windows-1252, any line ends).

use super::{CandelaPlanes, MAX_ANGLES, PhotometryError};
use crate::glare::LuminousOpening;

/// Most lamp sets a file may declare (line 26).
pub const MAX_LAMP_SETS: usize = 20;

/// The symmetry indicator Isym (line 3) and so which C planes the file stores.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LdtSymmetry {
    /// Isym 0: no symmetry, all `Mc` planes stored.
    None,
    /// Isym 1: symmetric about the vertical axis, one plane stored.
    Rotational,
    /// Isym 2: symmetric about the plane C0-C180, planes C0..=C180 stored.
    AboutC0C180,
    /// Isym 3: symmetric about the plane C90-C270, planes C90..=C270 stored.
    AboutC90C270,
    /// Isym 4: symmetric about both planes, planes C0..=C90 stored.
    Quadrants,
}

impl LdtSymmetry {
    /// The indicator as written in the file (0..=4).
    pub fn indicator(self) -> u8 {
        match self {
            Self::None => 0,
            Self::Rotational => 1,
            Self::AboutC0C180 => 2,
            Self::AboutC90C270 => 3,
            Self::Quadrants => 4,
        }
    }

    /// The first stored C plane's index among the `mc` C angles and the number of stored planes.
    pub fn stored_planes(self, mc: usize) -> (usize, usize) {
        match self {
            Self::None => (0, mc),
            Self::Rotational => (0, 1),
            Self::AboutC0C180 => (0, mc / 2 + 1),
            Self::AboutC90C270 => (mc / 4, mc / 2 + 1),
            Self::Quadrants => (0, mc / 4 + 1),
        }
    }
}

/// One standard set of lamps (6 lines after line 26).
#[derive(Debug, Clone, PartialEq)]
pub struct LampSet {
    /// Number of lamps as written: negative marks absolute photometry (see the module docs).
    pub lamps: i32,
    /// Type of the lamps (text).
    pub kind: String,
    /// Total luminous flux of the set's lamps (lm); the luminaire's flux for absolute photometry.
    pub flux: f64,
    /// Colour appearance / colour temperature (text, as written).
    pub colour_temperature: String,
    /// Colour rendering group / index (text, as written).
    pub colour_rendering: String,
    /// Wattage including ballast (W).
    pub watts: f64,
}

/// A parsed EULUMDAT file: every header field, the lamp sets and the stored intensities.
#[derive(Debug, Clone, PartialEq)]
pub struct LdtFile {
    /// Line 1: company identification / data bank / version.
    pub company: String,
    /// Line 2: type indicator Ityp (0..=3).
    pub type_indicator: u8,
    /// Line 3: symmetry indicator Isym.
    pub symmetry: LdtSymmetry,
    /// Line 4: Mc, the number of C planes in [0, 360).
    pub c_plane_count: usize,
    /// Line 5: Dc, the distance between C planes (degrees; 0 when not equidistant).
    pub c_plane_distance: f64,
    /// Line 6: Ng, the number of gamma angles per C plane.
    pub gamma_count: usize,
    /// Line 7: Dg, the distance between gamma angles (degrees; 0 when not equidistant).
    pub gamma_distance: f64,
    /// Line 8: measurement report number.
    pub report_number: String,
    /// Line 9: luminaire name.
    pub luminaire_name: String,
    /// Line 10: luminaire number.
    pub luminaire_number: String,
    /// Line 11: file name.
    pub file_name: String,
    /// Line 12: date / user.
    pub date_user: String,
    /// Lines 13-15: length (or diameter), width (0: round) and height of the luminaire (mm).
    pub luminaire_size_mm: [f64; 3],
    /// Lines 16-17: length (or diameter) and width (0: round) of the luminous area (mm).
    pub luminous_area_mm: [f64; 2],
    /// Lines 18-21: height of the luminous area in the planes C0, C90, C180, C270 (mm).
    pub luminous_heights_mm: [f64; 4],
    /// Line 22: DFF, downward flux fraction (%).
    pub downward_flux_fraction: f64,
    /// Line 23: LORL, light output ratio of the luminaire (%).
    pub light_output_ratio: f64,
    /// Line 24: conversion factor for the luminous intensities (kept, not applied).
    pub conversion_factor: f64,
    /// Line 25: tilt of the luminaire during measurement (degrees).
    pub tilt: f64,
    /// The standard sets of lamps (line 26 counts them).
    pub lamp_sets: Vec<LampSet>,
    /// Direct ratios for the room indices k = 0.6, 0.8, 1, 1.25, 1.5, 2, 2.5, 3, 4, 5 (`None`
    /// where the line is blank).
    pub direct_ratios: [Option<f64>; 10],
    /// All `Mc` C angles (degrees), strictly increasing from 0.
    pub c_angles: Vec<f64>,
    /// The `Ng` gamma angles (degrees from nadir), strictly increasing within [0, 180].
    pub gamma_angles: Vec<f64>,
    /// Intensities in cd/klm of the stored C planes (see [`LdtSymmetry::stored_planes`]),
    /// `intensities[plane][gamma]`.
    pub intensities: Vec<Vec<f64>>,
}

/// The file's lines, read one value each, in order.
struct Lines<'a> {
    file: &'a str,
    lines: Vec<&'a str>,
    next: usize,
}

impl<'a> Lines<'a> {
    fn error(&self, line: usize, message: impl Into<String>) -> PhotometryError {
        PhotometryError { file: self.file.to_owned(), line, message: message.into() }
    }

    /// The next line, trimmed, and its number; `what` names it if the file has ended.
    fn text(&mut self, what: &str) -> Result<(&'a str, usize), PhotometryError> {
        let Some(line) = self.lines.get(self.next) else {
            return Err(self.error(
                self.lines.len().max(1),
                format!("the file ends before line {} ({what}) (truncated?)", self.next + 1),
            ));
        };
        self.next += 1;
        Ok((line.trim(), self.next))
    }

    /// The next line as a finite number.
    fn number(&mut self, what: &str) -> Result<(f64, usize), PhotometryError> {
        let (text, line) = self.text(what)?;
        match parse_number(text) {
            Some(v) => Ok((v, line)),
            None if text.is_empty() => {
                Err(self.error(line, format!("{what}: expected a number, found an empty line")))
            }
            None => Err(self.error(line, format!("{what}: expected a number, found `{text}`"))),
        }
    }

    /// The next line as a whole number in `min..=max`.
    fn whole(&mut self, what: &str, min: i64, max: i64) -> Result<(i64, usize), PhotometryError> {
        let (v, line) = self.number(what)?;
        if v.fract() != 0.0 || v < min as f64 || v > max as f64 {
            return Err(self
                .error(line, format!("{what} = {v}: must be a whole number from {min} to {max}")));
        }
        Ok((v as i64, line))
    }

    /// `n` numbers named `what[i]`.
    fn numbers(&mut self, what: &str, n: usize) -> Result<Vec<(f64, usize)>, PhotometryError> {
        (0..n).map(|i| self.number(&format!("{what}[{i}]"))).collect()
    }
}

/// A finite number with a decimal point or a single decimal comma.
fn parse_number(text: &str) -> Option<f64> {
    let v: f64 = if !text.contains('.') && text.matches(',').count() == 1 {
        text.replacen(',', ".", 1).parse().ok()?
    } else {
        text.parse().ok()?
    };
    v.is_finite().then_some(v)
}

impl LdtFile {
    /// Parses the text of a EULUMDAT file; `file` names it in errors.
    ///
    /// # Errors
    /// [`PhotometryError`] with the line and cause for anything the module documentation lists.
    pub fn parse(text: &str, file: &str) -> Result<Self, PhotometryError> {
        let mut r = Lines { file, lines: text.lines().collect(), next: 0 };
        let company = r.text("the company identification")?.0.to_owned();
        let type_indicator = r.whole("Ityp (the type indicator)", 0, 3)?.0 as u8;
        let symmetry = match r.whole("Isym (the symmetry indicator)", 0, 4)?.0 {
            0 => LdtSymmetry::None,
            1 => LdtSymmetry::Rotational,
            2 => LdtSymmetry::AboutC0C180,
            3 => LdtSymmetry::AboutC90C270,
            _ => LdtSymmetry::Quadrants,
        };
        let max = MAX_ANGLES as i64;
        let (mc, mc_line) = r.whole("Mc (the number of C planes)", 1, max)?;
        let mc = mc as usize;
        let (needed, planes) = match symmetry {
            LdtSymmetry::AboutC0C180 => (2, "end at C180"),
            LdtSymmetry::AboutC90C270 => (4, "run from C90 to C270"),
            LdtSymmetry::Quadrants => (4, "end at C90"),
            LdtSymmetry::None | LdtSymmetry::Rotational => (1, ""),
        };
        if !mc.is_multiple_of(needed) {
            return Err(r.error(
                mc_line,
                format!(
                    "Mc = {mc} with Isym {}: must be a multiple of {needed} (the stored planes {planes})",
                    symmetry.indicator()
                ),
            ));
        }
        let c_plane_distance = r.number("Dc (the distance between C planes)")?.0;
        let ng = r.whole("Ng (the number of gamma angles)", 1, max)?.0 as usize;
        let gamma_distance = r.number("Dg (the distance between gamma angles)")?.0;
        let report_number = r.text("the measurement report number")?.0.to_owned();
        let luminaire_name = r.text("the luminaire name")?.0.to_owned();
        let luminaire_number = r.text("the luminaire number")?.0.to_owned();
        let file_name = r.text("the file name")?.0.to_owned();
        let date_user = r.text("the date/user")?.0.to_owned();
        let luminaire_size_mm = [
            r.number("the luminaire length")?.0,
            r.number("the luminaire width")?.0,
            r.number("the luminaire height")?.0,
        ];
        let luminous_area_mm =
            [r.number("the luminous area length")?.0, r.number("the luminous area width")?.0];
        let luminous_heights_mm = [
            r.number("the luminous area height C0")?.0,
            r.number("the luminous area height C90")?.0,
            r.number("the luminous area height C180")?.0,
            r.number("the luminous area height C270")?.0,
        ];
        let percent = |r: &mut Lines<'_>, what: &str| {
            let (v, line) = r.number(what)?;
            if !(0.0..=100.0).contains(&v) {
                return Err(
                    r.error(line, format!("{what} = {v}: must be a percentage in [0, 100]"))
                );
            }
            Ok(v)
        };
        let downward_flux_fraction = percent(&mut r, "DFF (the downward flux fraction)")?;
        let light_output_ratio = percent(&mut r, "LORL (the light output ratio)")?;
        let conversion_factor = r.number("the conversion factor")?.0;
        let tilt = r.number("the tilt during measurement")?.0;
        let sets = r.whole("the number of lamp sets", 1, MAX_LAMP_SETS as i64)?.0 as usize;
        let mut lamp_sets = Vec::with_capacity(sets);
        for s in 0..sets {
            let what = |field: &str| format!("lamp set {}: {field}", s + 1);
            let (lamps, lamps_line) =
                r.whole(&what("the number of lamps"), -1_000_000, 1_000_000)?;
            if lamps == 0 {
                return Err(r.error(
                    lamps_line,
                    format!(
                        "{} = 0: must be non-zero (negative for absolute photometry)",
                        what("the number of lamps")
                    ),
                ));
            }
            if let Some(first) = lamp_sets.first().map(|f: &LampSet| f.lamps)
                && (first < 0) != (lamps < 0)
            {
                return Err(r.error(
                    lamps_line,
                    format!(
                        "{} = {lamps}, but lamp set 1 has {first}: a negative number (absolute photometry) must be used by every set or none",
                        what("the number of lamps")
                    ),
                ));
            }
            let kind = r.text(&what("the lamp type"))?.0.to_owned();
            let (flux, line) = r.number(&what("the total luminous flux"))?;
            if flux <= 0.0 {
                return Err(r.error(
                    line,
                    format!("{} = {flux}: must be > 0 lm", what("the total luminous flux")),
                ));
            }
            let colour_temperature = r.text(&what("the colour temperature"))?.0.to_owned();
            let colour_rendering = r.text(&what("the colour rendering index"))?.0.to_owned();
            let (watts, line) = r.number(&what("the wattage"))?;
            if watts < 0.0 {
                return Err(
                    r.error(line, format!("{} = {watts}: must be >= 0 W", what("the wattage")))
                );
            }
            lamp_sets.push(LampSet {
                lamps: lamps as i32,
                kind,
                flux,
                colour_temperature,
                colour_rendering,
                watts,
            });
        }
        // Direct ratios serve room-index tables, not the candela table: blank lines (as some
        // makers ship them) are read as missing.
        let mut direct_ratios = [None; 10];
        for (i, d) in direct_ratios.iter_mut().enumerate() {
            let what = format!("direct ratio[{i}]");
            let (text, line) = r.text(&what)?;
            *d = match parse_number(text) {
                Some(v) => Some(v),
                None if text.is_empty() => None,
                None => {
                    return Err(r.error(line, format!("{what}: expected a number, found `{text}`")));
                }
            };
        }
        let c_angles = r.numbers("C angle", mc)?;
        increasing(&r, &c_angles, "C angles")?;
        let (c0, c0_line) = c_angles[0];
        if c0 != 0.0 {
            return Err(r.error(c0_line, format!("C angle[0] = {c0}: the C angles begin with 0")));
        }
        for (i, &(c, line)) in c_angles.iter().enumerate() {
            if !(0.0..360.0).contains(&c) {
                return Err(r.error(line, format!("C angle[{i}] = {c}: C angles lie in [0, 360)")));
            }
        }
        let (first, count) = symmetry.stored_planes(mc);
        let ends: &[(usize, f64)] = match symmetry {
            LdtSymmetry::None | LdtSymmetry::Rotational => &[],
            LdtSymmetry::AboutC0C180 => &[(mc / 2, 180.0)],
            LdtSymmetry::AboutC90C270 => &[(mc / 4, 90.0), (3 * mc / 4, 270.0)],
            LdtSymmetry::Quadrants => &[(mc / 4, 90.0)],
        };
        for &(i, want) in ends {
            if let Some(&(c, line)) = c_angles.get(i)
                && c != want
            {
                return Err(r.error(
                    line,
                    format!(
                        "C angle[{i}] = {c}: with Isym {} and Mc = {mc} the stored planes {planes}, so angle {i} must be C{want}",
                        symmetry.indicator()
                    ),
                ));
            }
        }
        let gamma_angles = r.numbers("gamma angle", ng)?;
        increasing(&r, &gamma_angles, "gamma angles")?;
        for (i, &(g, line)) in gamma_angles.iter().enumerate() {
            if !(0.0..=180.0).contains(&g) {
                return Err(
                    r.error(line, format!("gamma angle[{i}] = {g}: gamma angles lie in [0, 180]"))
                );
            }
        }
        let mut intensities = Vec::with_capacity(count);
        for p in 0..count {
            let angle = c_angles.get(first + p).map_or(0.0, |c| c.0);
            let mut row = Vec::with_capacity(ng);
            for (g, &(gamma, _)) in gamma_angles.iter().enumerate() {
                let what = format!("intensity[{p}][{g}] (C{angle}, gamma {gamma})");
                let (v, line) = r.number(&what)?;
                if v < 0.0 {
                    return Err(r.error(line, format!("{what} = {v}: must be >= 0 cd/klm")));
                }
                row.push(v);
            }
            intensities.push(row);
        }
        let rest = r.lines.iter().enumerate().skip(r.next).find(|(_, l)| !l.trim().is_empty());
        if let Some((k, l)) = rest {
            return Err(r.error(
                k + 1,
                format!(
                    "`{}` after the last intensity: the counts do not match the table",
                    l.trim()
                ),
            ));
        }
        Ok(Self {
            company,
            type_indicator,
            symmetry,
            c_plane_count: mc,
            c_plane_distance,
            gamma_count: ng,
            gamma_distance,
            report_number,
            luminaire_name,
            luminaire_number,
            file_name,
            date_user,
            luminaire_size_mm,
            luminous_area_mm,
            luminous_heights_mm,
            downward_flux_fraction,
            light_output_ratio,
            conversion_factor,
            tilt,
            lamp_sets,
            direct_ratios,
            c_angles: c_angles.iter().map(|c| c.0).collect(),
            gamma_angles: gamma_angles.iter().map(|g| g.0).collect(),
            intensities,
        })
    }

    /// Whether the file holds absolute photometry (its lamp counts are negative).
    pub fn is_absolute(&self) -> bool {
        self.lamp_sets.iter().any(|s| s.lamps < 0)
    }

    /// The flux of lamp set `set` (0-based; lm), the flux the cd/klm values are relative to
    /// when that set is fitted; `None` past the last set.
    pub fn set_flux(&self, set: usize) -> Option<f64> {
        self.lamp_sets.get(set).map(|s| s.flux)
    }

    /// The luminous area (lines 16-21), in metres: `None` when every dimension is 0 (a point)
    /// or one is negative. Its *length* (line 16) lies along the C0-C180 plane and its *width*
    /// (line 17) along C90-C270; a width of 0 makes it round, of diameter the length (a
    /// [`LuminousOpening::Cylinder`]), else it is a rectangle (a [`LuminousOpening::Box`]). The
    /// heights of lines 18-21 are those of its luminous sides seen in the planes C0, C90, C180
    /// and C270 (for a round area, of the quarters of its rim centred on them).
    pub fn luminous_opening(&self) -> Option<LuminousOpening> {
        let [length, width] = self.luminous_area_mm.map(|d| d / 1000.0);
        let heights = self.luminous_heights_mm.map(|d| d / 1000.0);
        let opening = if width == 0.0 {
            LuminousOpening::Cylinder { length, width: length, heights }
        } else {
            LuminousOpening::Box { length, width, heights }
        };
        Some(opening).filter(LuminousOpening::is_valid)
    }

    /// The stored C angles (degrees): the planes `intensities` holds, in the IES ranges
    /// (`[0]` for Isym 1).
    pub fn stored_c_angles(&self) -> Vec<f64> {
        if self.symmetry == LdtSymmetry::Rotational {
            return vec![0.0];
        }
        let (first, count) = self.symmetry.stored_planes(self.c_plane_count);
        self.c_angles.iter().skip(first).take(count).copied().collect()
    }

    /// The table as [`CandelaPlanes`] with lamp set `set` (0-based) fitted: the stored planes in
    /// absolute candela (cd/klm times the set's flux / 1000), `lamp_lumens` that flux (`None`
    /// for absolute photometry). A file's lamp sets are alternatives (the lamps the luminaire
    /// may be fitted with), as DIALux and Relux read them, so one set is used, never their sum.
    /// `None` past the last set.
    pub fn candela_planes(&self, set: usize) -> Option<CandelaPlanes> {
        let flux = self.set_flux(set)?;
        let scale = flux / 1000.0;
        Some(CandelaPlanes {
            horizontal: self.stored_c_angles(),
            vertical: self.gamma_angles.clone(),
            candela: self
                .intensities
                .iter()
                .map(|row| row.iter().map(|v| v * scale).collect())
                .collect(),
            lamp_lumens: (!self.is_absolute()).then_some(flux),
        })
    }
}

/// Checks that `values` strictly increase, naming the first that does not.
fn increasing(r: &Lines<'_>, values: &[(f64, usize)], what: &str) -> Result<(), PhotometryError> {
    for w in values.windows(2) {
        if !(w[1].0 > w[0].0) {
            return Err(r.error(
                w[1].1,
                format!("{what} must increase strictly: {} after {}", w[1].0, w[0].0),
            ));
        }
    }
    Ok(())
}
