//! A small, strict reader of IES LM-63 photometric files (the 1991, 1995, 2002 and 2019
//! variants, and the 1986 form without a first line): the candela table of a measured luminaire.
//!
//! The layout, after the format's documents (ANSI/IES LM-63-02 and LM-63-19):
//!
//! ```text
//! IESNA:LM-63-2002                     first line: the version (absent in LM-63-1986)
//! [TEST] ...                           keyword lines, [KEYWORD] text
//! TILT=NONE | TILT=INCLUDE | TILT=<file>
//! (TILT=INCLUDE only) <lamp-to-luminaire geometry> <n tilt angles> <angles...> <factors...>
//! <lamps> <lumens per lamp> <candela multiplier> <n vertical> <n horizontal>
//!     <photometric type> <units type> <width> <length> <height>
//! <ballast factor> <future use / ballast-lamp factor> <input watts>
//! <n vertical angles>  <n horizontal angles>
//! <candela: n vertical values for each horizontal angle>
//! ```
//!
//! Numbers after the `TILT` line may be split over lines at will and separated by blanks or
//! commas. Lumens per lamp of `-1` mean *absolute photometry* (the candela values are the
//! luminaire's own, no lamp rating). Photometry types C (1) and B (2, floodlights: see
//! [`IesFile::type_b_planes`]) and A (3, automotive and signal lights: see
//! [`IesFile::type_a_planes`]) are read. A `TILT=<file>` naming another file is refused (the
//! reader opens nothing); `TILT=INCLUDE` is read and kept.
//!
//! Checks, each an error naming the file, the line and the cause: a `TILT` line is required;
//! counts are whole numbers from 1 to [`MAX_ANGLES`] (vertical) and [`MAX_ANGLES`]
//! (horizontal); every number is finite; candela values and the multiplier are `>= 0`; type C
//! vertical angles lie in `[0, 180]` and horizontal ones in `[0, 360]`, both strictly
//! increasing; the horizontal angles start at 0 (or 90 for the quadrant form 90..270 some
//! files use) and end where the symmetry the format defines allows (0: axial symmetry, 90:
//! quadrant, 180: bilateral, 360: none); nothing follows the last candela value but blanks and
//! one `END` (some 1986-form files close with it). The `TILT` keyword is read in any case
//! (`tilt=none`), and the text as [`super::decode_text`] gives it (UTF-8 or Windows-1252, any
//! line ends, a trailing ^Z dropped).

use super::{CandelaPlanes, PhotometryError};
use crate::glare::LuminousOpening;

/// Most angles along either axis of a candela table.
pub const MAX_ANGLES: usize = 4096;

/// The version an IES file declares on its first line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IesVersion {
    /// LM-63-1986: no version line.
    Lm63_1986,
    /// `IESNA91`.
    Lm63_1991,
    /// `IESNA:LM-63-1995`.
    Lm63_1995,
    /// `IESNA:LM-63-2002`.
    Lm63_2002,
    /// `IES:LM-63-2019`.
    Lm63_2019,
}

/// The lamp tilt data of `TILT=INCLUDE`: how the lamp output varies with the luminaire's tilt.
#[derive(Debug, Clone, PartialEq)]
pub struct Tilt {
    /// Lamp-to-luminaire geometry code (1, 2 or 3).
    pub geometry: u32,
    /// Tilt angles (degrees).
    pub angles: Vec<f64>,
    /// Multiplying factors, one per angle.
    pub factors: Vec<f64>,
}

/// The photometry type of a file (its goniometer's axes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Photometry {
    /// Type C (1): a vertical polar axis through the luminaire; vertical angles from nadir,
    /// horizontal angles the C planes about it (building luminaires).
    C,
    /// Type B (2): a horizontal polar axis across the luminaire; vertical angles turn the
    /// measuring plane about it, horizontal angles are measured within the plane from the
    /// photometric axis (floodlights).
    B,
    /// Type A (3): a vertical polar axis, as type C, but vertical angles are elevations from
    /// the horizontal (-90 straight down, 0 the photometric horizontal) and horizontal angles
    /// turn clockwise seen from above (automotive and signal lights; LM-63-2002 section 3).
    A,
}

/// The luminous dimensions' unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    /// Feet (units type 1).
    Feet,
    /// Metres (units type 2).
    Metres,
}

/// A parsed IES LM-63 file (photometry type C).
#[derive(Debug, Clone, PartialEq)]
pub struct IesFile {
    /// The declared version.
    pub version: IesVersion,
    /// Keyword lines (`[TEST]`, `[MANUFAC]`, ...), in order, without brackets.
    pub keywords: Vec<(String, String)>,
    /// `TILT=INCLUDE` data; `None` for `TILT=NONE`.
    pub tilt: Option<Tilt>,
    /// Number of lamps.
    pub lamps: u32,
    /// Rated lumens per lamp; `None` for absolute photometry (`-1` in the file).
    pub lumens_per_lamp: Option<f64>,
    /// Multiplier applied to every candela value.
    pub multiplier: f64,
    /// Unit of the luminous dimensions.
    pub units: Units,
    /// Width, length and height of the luminous opening (in `units`; negative values describe
    /// round shapes, as the format defines).
    pub dimensions: [f64; 3],
    /// Ballast factor.
    pub ballast_factor: f64,
    /// Input power (W).
    pub input_watts: f64,
    /// The photometry type: C (building luminaires) or B (floodlights).
    pub photometry: Photometry,
    /// Vertical angles (degrees), strictly increasing: from nadir for type C; for type B the
    /// rotation of the measuring plane about the horizontal polar axis.
    pub vertical: Vec<f64>,
    /// Horizontal angles (degrees, the C-planes), strictly increasing.
    pub horizontal: Vec<f64>,
    /// Candela values, `candela[h][v]` for `horizontal[h]` and `vertical[v]`, multiplier
    /// applied.
    pub candela: Vec<Vec<f64>>,
}

/// Numbers after the `TILT` line, with the line each starts on.
struct Tokens<'a> {
    file: &'a str,
    items: Vec<(usize, &'a str)>,
    next: usize,
    last_line: usize,
}

impl<'a> Tokens<'a> {
    fn error(&self, line: usize, message: impl Into<String>) -> PhotometryError {
        PhotometryError { file: self.file.to_owned(), line, message: message.into() }
    }

    /// The next number, named `what` in errors.
    fn number(&mut self, what: &str) -> Result<(f64, usize), PhotometryError> {
        let Some(&(line, text)) = self.items.get(self.next) else {
            return Err(
                self.error(self.last_line, format!("the file ends before {what} (truncated?)"))
            );
        };
        self.next += 1;
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok((v, line)),
            _ => Err(self.error(line, format!("{what}: expected a number, found `{text}`"))),
        }
    }

    /// The next number as a count in `1..=max`.
    fn count(&mut self, what: &str, max: usize) -> Result<usize, PhotometryError> {
        let (v, line) = self.number(what)?;
        if v.fract() != 0.0 || v < 1.0 || v > max as f64 {
            return Err(
                self.error(line, format!("{what} = {v}: must be a whole number from 1 to {max}"))
            );
        }
        Ok(v as usize)
    }

    /// `n` numbers named `what[i]`.
    fn numbers(&mut self, what: &str, n: usize) -> Result<Vec<(f64, usize)>, PhotometryError> {
        (0..n).map(|i| self.number(&format!("{what}[{i}]"))).collect()
    }
}

impl IesFile {
    /// Parses the text of an IES file; `file` names it in errors.
    ///
    /// # Errors
    /// [`PhotometryError`] with the line and cause for anything the module documentation lists.
    pub fn parse(text: &str, file: &str) -> Result<Self, PhotometryError> {
        let err =
            |line: usize, message: String| PhotometryError { file: file.to_owned(), line, message };
        let lines: Vec<&str> = text.lines().collect();
        let mut i = 0;
        let first = lines.first().map_or("", |l| l.trim());
        let version = match first.to_ascii_uppercase().as_str() {
            "IESNA:LM-63-1995" => Some(IesVersion::Lm63_1995),
            "IESNA:LM-63-2002" => Some(IesVersion::Lm63_2002),
            "IES:LM-63-2019" => Some(IesVersion::Lm63_2019),
            "IESNA91" => Some(IesVersion::Lm63_1991),
            _ => None,
        };
        let version = match version {
            Some(v) => {
                i = 1;
                v
            }
            None if first.to_ascii_uppercase().starts_with("IES") => {
                return Err(err(
                    1,
                    format!(
                        "unknown IES version line `{first}` (known: IESNA91, IESNA:LM-63-1995, IESNA:LM-63-2002, IES:LM-63-2019)"
                    ),
                ));
            }
            None => IesVersion::Lm63_1986,
        };
        let mut keywords = Vec::new();
        let tilt_line;
        loop {
            let Some(line) = lines.get(i) else {
                return Err(err(
                    lines.len().max(1),
                    "no TILT= line: the file ends in its header (is it an IES file?)".to_owned(),
                ));
            };
            let trimmed = line.trim();
            // `TILT=`, in any case, with blanks before the `=` allowed.
            let tilt = trimmed
                .get(..4)
                .filter(|t| t.eq_ignore_ascii_case("TILT"))
                .and_then(|_| trimmed[4..].trim_start().strip_prefix('='));
            if let Some(rest) = tilt {
                tilt_line = (i + 1, rest.trim().to_owned());
                i += 1;
                break;
            }
            if let Some((key, value)) = trimmed.strip_prefix('[').and_then(|b| b.split_once(']')) {
                keywords.push((key.to_owned(), value.trim().to_owned()));
            }
            i += 1;
        }
        let mut tokens = Tokens { file, items: Vec::new(), next: 0, last_line: lines.len().max(1) };
        for (k, line) in lines.iter().enumerate().skip(i) {
            for t in line.split(|c: char| c.is_whitespace() || c == ',').filter(|t| !t.is_empty()) {
                tokens.items.push((k + 1, t));
            }
        }
        let tilt = match tilt_line.1.to_ascii_uppercase().as_str() {
            "NONE" => None,
            "INCLUDE" => {
                let (g, line) = tokens.number("the tilt's lamp-to-luminaire geometry")?;
                if !(g == 1.0 || g == 2.0 || g == 3.0) {
                    return Err(err(
                        line,
                        format!("lamp-to-luminaire geometry = {g}: must be 1, 2 or 3"),
                    ));
                }
                let n = tokens.count("the number of tilt angles", MAX_ANGLES)?;
                let angles = tokens.numbers("tilt angle", n)?;
                let factors = tokens.numbers("tilt factor", n)?;
                increasing(&angles, "tilt angles", &err)?;
                for &(f, line) in &factors {
                    if f < 0.0 {
                        return Err(err(line, format!("tilt factor {f}: must be >= 0")));
                    }
                }
                Some(Tilt {
                    geometry: g as u32,
                    angles: angles.iter().map(|a| a.0).collect(),
                    factors: factors.iter().map(|a| a.0).collect(),
                })
            }
            other => {
                return Err(err(
                    tilt_line.0,
                    format!(
                        "TILT={other}: tilt data in another file is not read (use TILT=NONE or TILT=INCLUDE)"
                    ),
                ));
            }
        };
        let lamps = tokens.count("the number of lamps", 1_000_000)? as u32;
        let (lumens, lumens_line) = tokens.number("the lumens per lamp")?;
        let lumens_per_lamp = if lumens == -1.0 {
            None
        } else if lumens > 0.0 {
            Some(lumens)
        } else {
            return Err(err(
                lumens_line,
                format!("lumens per lamp = {lumens}: must be > 0, or -1 for absolute photometry"),
            ));
        };
        let (multiplier, line) = tokens.number("the candela multiplier")?;
        if multiplier < 0.0 {
            return Err(err(line, format!("candela multiplier = {multiplier}: must be >= 0")));
        }
        let n_vertical = tokens.count("the number of vertical angles", MAX_ANGLES)?;
        let n_horizontal = tokens.count("the number of horizontal angles", MAX_ANGLES)?;
        let (kind, line) = tokens.number("the photometric type")?;
        let photometry = match kind {
            1.0 => Photometry::C,
            2.0 => Photometry::B,
            3.0 => Photometry::A,
            _ => {
                return Err(err(
                    line,
                    format!("photometric type = {kind}: must be 1 (C), 2 (B) or 3 (A)"),
                ));
            }
        };
        let (u, line) = tokens.number("the units type")?;
        let units = match u {
            1.0 => Units::Feet,
            2.0 => Units::Metres,
            _ => {
                return Err(err(line, format!("units type = {u}: must be 1 (feet) or 2 (metres)")));
            }
        };
        let width = tokens.number("the width")?.0;
        let length = tokens.number("the length")?.0;
        let height = tokens.number("the height")?.0;
        let (ballast_factor, line) = tokens.number("the ballast factor")?;
        if ballast_factor < 0.0 {
            return Err(err(line, format!("ballast factor = {ballast_factor}: must be >= 0")));
        }
        tokens.number("the ballast-lamp photometric factor (future use)")?;
        let input_watts = tokens.number("the input watts")?.0;
        let vertical = tokens.numbers("vertical angle", n_vertical)?;
        let horizontal = tokens.numbers("horizontal angle", n_horizontal)?;
        increasing(&vertical, "vertical angles", &err)?;
        increasing(&horizontal, "horizontal angles", &err)?;
        match photometry {
            Photometry::C => check_type_c(&vertical, &horizontal, &err)?,
            Photometry::B => check_types_a_b("B", &vertical, &horizontal, &err)?,
            Photometry::A => check_types_a_b("A", &vertical, &horizontal, &err)?,
        }
        let mut candela = Vec::with_capacity(n_horizontal);
        for (h, &(angle, _)) in horizontal.iter().enumerate() {
            let row = tokens.numbers(&format!("candela[{h}]"), n_vertical)?;
            let mut values = Vec::with_capacity(n_vertical);
            for (v, line) in row {
                if v < 0.0 {
                    return Err(err(
                        line,
                        format!("candela value {v} (horizontal angle {angle}): must be >= 0"),
                    ));
                }
                values.push(v * multiplier);
            }
            candela.push(values);
        }
        // Some 1986-form files close with an `END` line after the table.
        let rest = &tokens.items[tokens.next.min(tokens.items.len())..];
        if let [(_, end)] = rest
            && end.eq_ignore_ascii_case("END")
        {
            tokens.next += 1;
        }
        if let Some(&(line, t)) = tokens.items.get(tokens.next) {
            return Err(err(
                line,
                format!("`{t}` after the last candela value: the counts do not match the table"),
            ));
        }
        Ok(Self {
            version,
            keywords,
            tilt,
            lamps,
            lumens_per_lamp,
            multiplier,
            units,
            dimensions: [width, length, height],
            ballast_factor,
            input_watts,
            photometry,
            vertical: vertical.iter().map(|v| v.0).collect(),
            horizontal: horizontal.iter().map(|v| v.0).collect(),
            candela,
        })
    }
}

/// Metres per foot (units type 1).
const METRES_PER_FOOT: f64 = 0.3048;

impl IesFile {
    /// The luminous opening the file's width, length and height describe, in metres; `None`
    /// for a point source (`0 0 0`), for a combination of signs the file's version does not
    /// define, or for a dimension that is not finite.
    ///
    /// **Axes.** LM-63 measures type C horizontal angles from the *photometric horizontal*,
    /// "a horizontal direction from photometric center that is coincident with horizontal
    /// angle 0 and vertical angle 90" (LM-63-2002, section 3); the *length* lies along it (the
    /// 0-180 degree plane: the shape LM-63-2002 calls "horizontal cylinder along photometric
    /// horizontal" takes its axis from the length; the 0 degree axis "is oriented parallel to
    /// the length of the luminaire", as Autodesk's IES documentation puts it; Radiance's
    /// ies2rad lays the length along its `x` axis, horizontal angle 0), the *width* across it
    /// (along the 90-270 degree plane) and the *height* vertically. For type B files
    /// (floodlights) the same frame is taken about the photometric axis (horizontal and
    /// vertical angle 0, the opening's normal) and the photometric horizontal (horizontal
    /// angle 0, vertical angle 90), the width lying along the polar axis: a reading of ours,
    /// the standard naming no axes for them.
    ///
    /// **Shapes** (`w`, `l`, `h` the signed width, length and height; `W`, `L`, `H` their
    /// magnitudes; feet converted at 0.3048 m). LM-63-2002 and LM-63-2019 (Table 1, "luminous
    /// opening shapes"):
    ///
    /// | `w l h` | shape | [`LuminousOpening`] |
    /// |---|---|---|
    /// | `0 0 0` | point | `None` |
    /// | `+ + 0` | rectangular | `Box` of heights 0 |
    /// | `+ + +` | rectangular with luminous sides | `Box`, every side `H` |
    /// | `- - 0` | circular (`w = l`) or ellipse | `Cylinder` of heights 0 |
    /// | `- - +` | vertical cylinder or vertical ellipsoidal cylinder | `Cylinder`, heights `H` |
    /// | `- - -` | sphere or ellipsoidal spheroid | `Ellipsoid` |
    /// | `- + -` | horizontal (ellipsoidal) cylinder along photometric horizontal | `CylinderAlongC0` |
    /// | `+ - -` | horizontal (ellipsoidal) cylinder perpendicular to photometric horizontal | `CylinderAlongC90` |
    /// | `- 0 -` | vertical circle or ellipse facing photometric horizontal | `VerticalEllipse` |
    ///
    /// Also read, as Radiance's ies2rad does: `0 + +` and `+ 0 +`, vertical rectangles (`Box`
    /// with a zero length or width). The earlier versions (LM-63-1986, -1991 and -1995) wrote
    /// round shapes with a zero length; they are read as ies2rad reads LM-63-1995: `- 0 0` a
    /// disk and `- 0 +` a vertical cylinder of diameter `W`, `- 0 -` a sphere of diameter `W`,
    /// `0 + -` a horizontal cylinder along the photometric horizontal (length `L`, diameter
    /// `H`), `+ 0 -` one perpendicular to it (length `W`, diameter `H`), `+ - +` and `- + +`
    /// vertical elliptic cylinders, `+ - -` and `- + -` ellipsoids, and `- + 0` an ellipse.
    /// Signs one table leaves unused are read as the other defines them (files in the wild
    /// write `- 0 0` disks under a 2002 version line); where the tables disagree (`- 0 -`,
    /// `+ - -`, `- + -`) the file's version line decides.
    pub fn luminous_opening(&self) -> Option<LuminousOpening> {
        let scale = match self.units {
            Units::Feet => METRES_PER_FOOT,
            Units::Metres => 1.0,
        };
        let [w, l, h] = self.dimensions.map(|d| d * scale);
        if ![w, l, h].iter().all(|d| d.is_finite()) {
            return None;
        }
        let (width, length, height) = (w.abs(), l.abs(), h.abs());
        let sign = |d: f64| -> i8 {
            if d > 0.0 {
                1
            } else if d < 0.0 {
                -1
            } else {
                0
            }
        };
        let modern = matches!(self.version, IesVersion::Lm63_2002 | IesVersion::Lm63_2019);
        let opening = match (sign(w), sign(l), sign(h)) {
            (0, 0, 0) => return None,
            (0..=1, 0..=1, 0..=1) => LuminousOpening::Box { length, width, heights: [height; 4] },
            (-1, -1, 0..=1) => LuminousOpening::Cylinder { length, width, heights: [height; 4] },
            (-1, -1, -1) => LuminousOpening::Ellipsoid { length, width, height },
            (-1, 0, 0..=1) => {
                LuminousOpening::Cylinder { length: width, width, heights: [height; 4] }
            }
            (-1, 1, -1) if modern => LuminousOpening::CylinderAlongC0 { length, width, height },
            (1, -1, -1) if modern => LuminousOpening::CylinderAlongC90 { length, width, height },
            (-1, 0, -1) if modern => LuminousOpening::VerticalEllipse { width, height },
            // LM-63-1986, -1991 and -1995, as Radiance's ies2rad reads them.
            (-1, 0, -1) => LuminousOpening::Ellipsoid { length: width, width, height: width },
            (0, 1, -1) => LuminousOpening::CylinderAlongC0 { length, width: height, height },
            (1, 0, -1) => LuminousOpening::CylinderAlongC90 { length: height, width, height },
            (1, -1, 1) | (-1, 1, 1) => {
                LuminousOpening::Cylinder { length, width, heights: [height; 4] }
            }
            (1, -1, -1) | (-1, 1, -1) => LuminousOpening::Ellipsoid { length, width, height },
            (-1, 1, 0) => LuminousOpening::Cylinder { length, width, heights: [0.0; 4] },
            _ => return None,
        };
        Some(opening).filter(LuminousOpening::is_valid)
    }

    /// The table as [`CandelaPlanes`]: the angles and candela as stored (multiplier applied),
    /// `lamp_lumens` the lamps times their rated lumens (`None` for absolute photometry).
    ///
    /// A type B table is given as the type C table of the same distribution about its own
    /// polar axis (see [`Self::type_b_planes`]); the light places that axis where a type C
    /// file's nadir goes.
    pub fn candela_planes(&self) -> CandelaPlanes {
        let lamp_lumens = self.lumens_per_lamp.map(|l| l * f64::from(self.lamps));
        match self.photometry {
            Photometry::C => CandelaPlanes {
                horizontal: self.horizontal.clone(),
                vertical: self.vertical.clone(),
                candela: self.candela.clone(),
                lamp_lumens,
            },
            Photometry::B => {
                let (horizontal, vertical, candela) = self.type_b_planes();
                CandelaPlanes { horizontal, vertical, candela, lamp_lumens }
            }
            Photometry::A => {
                let (horizontal, vertical, candela) = self.type_a_planes();
                CandelaPlanes { horizontal, vertical, candela, lamp_lumens }
            }
        }
    }

    /// A type B table as type C planes about the polar axis: a direction of type B angles
    /// `(H, V)` (`H` within the measuring plane from the photometric axis, `V` the plane's turn
    /// about the polar axis) lies at `gamma' = 90 - H` from the axis, in the plane `C' = V` (`V`
    /// below 0 as `360 + V`), the photometric axis being `C' = 0, gamma' = 90`. A table given
    /// from 0 only is mirrored first. The unmeasured back half (`C'` from 90 to 270) is dark:
    /// planes of zero just inside it (1e-6 degrees). The intensity stays bilinear in
    /// `(C', cos gamma') = (V, sin H)`, the grid the measurement was made on, so the flux is
    /// the file's exact zonal sum.
    pub fn type_b_planes(&self) -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let value = |v: usize, h: usize| self.candela[h][v];
        polar_planes(&self.vertical, &self.horizontal, value)
    }

    /// A type A table as type C planes about its polar axis pointing *up*: a direction of type
    /// A angles `(H, V)` (`H` the vertical plane's turn, clockwise seen from above, from the
    /// photometric horizontal; `V` the elevation within it) lies at `gamma' = 90 - V` from the
    /// zenith, in the plane `C' = H` (`H` below 0 as `360 + H`), which turns clockwise seen
    /// from above when the light's `nadir` is the zenith. It is [`Self::type_b_planes`] with
    /// the two angles' roles exchanged: type A's planes share the vertical axis, type B's a
    /// horizontal one. A table given from 0 only is mirrored; the unmeasured back half is
    /// dark; the intensity is bilinear in `(H, sin V)`, so the flux is the file's zonal sum.
    pub fn type_a_planes(&self) -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let value = |h: usize, v: usize| self.candela[h][v];
        polar_planes(&self.horizontal, &self.vertical, value)
    }
}

/// The type C planes of a table measured in planes through a polar axis (types A and B):
/// `planes` the angles turning the measuring plane about the axis, `within` the angles within
/// a plane from the photometric axis towards the `+90` end of the polar axis, `value(p, w)`
/// the candela at `planes[p]`, `within[w]`. A direction at `(p, w)` lies at `gamma' = 90 - w`
/// from the polar axis's `+90` end, in the plane `C' = p` (negative `p` as `360 + p`), the
/// photometric axis being `C' = 0, gamma' = 90`. Either angle list starting at 0 is a half
/// table, mirrored first; the unmeasured back half (`C'` from 90 to 270) is dark: planes of zero
/// just inside it (1e-6 degrees).
fn polar_planes(
    planes: &[f64],
    within: &[f64],
    value: impl Fn(usize, usize) -> f64,
) -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
    // Mirror a half table.
    let mirror = |angles: &[f64]| -> Vec<f64> {
        if angles[0] == 0.0 {
            angles.iter().rev().map(|a| -a).chain(angles[1..].iter().copied()).collect()
        } else {
            angles.to_vec()
        }
    };
    let source = |angles: &[f64], i: usize| -> usize {
        if angles[0] == 0.0 { i.abs_diff(angles.len() - 1) } else { i }
    };
    let hs = mirror(within);
    let vs = mirror(planes);
    let value = |h: usize, v: usize| value(source(planes, v), source(within, h));
    // gamma' increasing: H from 90 down to -90.
    let gammas: Vec<f64> = hs.iter().rev().map(|h| 90.0 - h).collect();
    let column = |v: usize| -> Vec<f64> { (0..hs.len()).rev().map(|h| value(h, v)).collect() };
    // The plane at V = 0, interpolated where the file has none.
    let zero = vs.partition_point(|&v| v < 0.0);
    let mut planes: Vec<(f64, Vec<f64>)> = Vec::new();
    if vs[zero] != 0.0 {
        let (a, b) = (zero - 1, zero);
        let t = -vs[a] / (vs[b] - vs[a]);
        let (ca, cb) = (column(a), column(b));
        planes.push((0.0, ca.iter().zip(&cb).map(|(x, y)| x + t * (y - x)).collect()));
    }
    planes.extend((zero..vs.len()).map(|v| (vs[v], column(v))));
    const EDGE: f64 = 1e-6;
    planes.push((90.0 + EDGE, vec![0.0; gammas.len()]));
    planes.push((270.0 - EDGE, vec![0.0; gammas.len()]));
    planes.extend((0..zero).map(|v| (360.0 + vs[v], column(v))));
    let (horizontal, candela) = planes.into_iter().unzip();
    (horizontal, gammas, candela)
}

/// The type C angle ranges: vertical in [0, 180], horizontal in [0, 360], starting at 0 (or 90
/// for the range 90-270) and ending where a symmetry allows.
fn check_type_c(
    vertical: &[(f64, usize)],
    horizontal: &[(f64, usize)],
    err: &impl Fn(usize, String) -> PhotometryError,
) -> Result<(), PhotometryError> {
    let n_horizontal = horizontal.len();
    for &(v, line) in vertical {
        if !(0.0..=180.0).contains(&v) {
            return Err(err(
                line,
                format!("vertical angle {v}: type C vertical angles lie in [0, 180]"),
            ));
        }
    }
    for &(h, line) in horizontal {
        if !(0.0..=360.0).contains(&h) {
            return Err(err(
                line,
                format!("horizontal angle {h}: type C horizontal angles lie in [0, 360]"),
            ));
        }
    }
    let (h0, h0_line) = horizontal[0];
    let (hn, hn_line) = horizontal[n_horizontal - 1];
    if !(h0 == 0.0 || (h0 == 90.0 && hn == 270.0)) {
        return Err(err(
            h0_line,
            format!("first horizontal angle {h0}: must be 0 (or 90 for the range 90-270)"),
        ));
    }
    if h0 == 0.0 && ![0.0, 90.0, 180.0, 360.0].contains(&hn) {
        return Err(err(
            hn_line,
            format!(
                "last horizontal angle {hn}: must be 0 (axial symmetry), 90 (quadrants), 180 (bilateral) or 360 (none)"
            ),
        ));
    }
    Ok(())
}

/// The type A and B angle ranges (LM-63-2002 section 5.13): both within [-90, 90], each
/// starting at -90 (or at 0 for a table symmetric about its plane 0) and ending at 90.
fn check_types_a_b(
    kind: &str,
    vertical: &[(f64, usize)],
    horizontal: &[(f64, usize)],
    err: &impl Fn(usize, String) -> PhotometryError,
) -> Result<(), PhotometryError> {
    for (values, what) in [(vertical, "vertical"), (horizontal, "horizontal")] {
        let (first, line) = values[0];
        let (last, last_line) = values[values.len() - 1];
        if !(first == -90.0 || first == 0.0) {
            return Err(err(
                line,
                format!(
                    "first {what} angle {first}: type {kind} {what} angles start at -90 (or 0 for a symmetric table)"
                ),
            ));
        }
        if last != 90.0 {
            return Err(err(
                last_line,
                format!("last {what} angle {last}: type {kind} {what} angles end at 90"),
            ));
        }
    }
    Ok(())
}

/// Checks that `values` strictly increase, naming the first that does not.
fn increasing(
    values: &[(f64, usize)],
    what: &str,
    err: &impl Fn(usize, String) -> PhotometryError,
) -> Result<(), PhotometryError> {
    for w in values.windows(2) {
        if !(w[1].0 > w[0].0) {
            return Err(err(
                w[1].1,
                format!("{what} must increase strictly: {} after {}", w[1].0, w[0].0),
            ));
        }
    }
    Ok(())
}
