//! The output files of an illuminance sensor: a CSV of every cell, a two-channel EXR and a
//! false-colour PNG with a lux legend, plus the summary figures lighting standards use.
//!
//! A sensor is the rectangle `corner + s edge_u + t edge_v` (`s`, `t` in `[0, 1]`) divided into
//! `nu x nv` equal cells; cell `(iu, iv)` is stored at index `iv * nu + iu` and its centre is
//! `corner + (iu + 0.5)/nu edge_u + (iv + 0.5)/nv edge_v`, so `iu` counts along `edge_u` from the
//! corner and `iv` along `edge_v`.
//!
//! [`write_sensor_files`] writes, into the output folder, through [`write_atomically`]:
//! - `NAME.csv`: header `iu,iv,x,y,z,irradiance_w_m2,illuminance_lux,melanopic_edi_lux`, one row
//!   per cell (`iv` the outer loop, `iu` the inner), numbers printed so they read back exactly,
//!   `\n` line ends. `melanopic_edi_lux` is the melanopic equivalent daylight illuminance of CIE
//!   S 026 (the melanopic irradiance is it times 1.3262e-3 W/lm).
//! - `NAME.exr`: an image of `nu x nv` pixels, one per cell, with the 32-bit float channels
//!   `illuminance_lux`, `irradiance_w_m2` and `melanopic_edi_lux`. Cell `(iu, iv)` is pixel `(x = iu, y = nv - 1 - iv)`:
//!   image rows run top to bottom, so `+v` (along `edge_v`) is up in image viewers. Written
//!   sequentially (the same grid always gives the same bytes). Values whose magnitude does not fit
//!   a 32-bit float are refused (the CSV has the full f64 values; values below about 1.4e-45 are
//!   stored as 0).
//! - `NAME.png`: the false-colour map ([`SensorGrid::false_colour`]), same orientation as the EXR.
//!
//! Nothing is written if the grid is invalid (bad name, wrong number of values, a non-finite
//! value) or if an output would replace an input.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use glam::DVec3;
use image::{Rgb, RgbImage};
use serde::{Deserialize, Serialize};

use crate::files::{check_no_input_replaced, check_output_name, write_atomically};

/// Most cells a sensor may have (2^20): its CSV stays near 100 MB.
pub const MAX_SENSOR_CELLS: u64 = 1 << 20;

/// The measured grid of one sensor, ready to write.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorGrid {
    /// The sensor's name; its files are `NAME.csv`, `NAME.exr` and `NAME.png`.
    pub name: String,
    /// The corner the cell `(0, 0)` touches.
    pub corner: DVec3,
    /// The whole edge along which `iu` counts.
    pub edge_u: DVec3,
    /// The whole edge along which `iv` counts.
    pub edge_v: DVec3,
    /// Cells along each edge: `[nu, nv]`.
    pub cells: [u32; 2],
    /// Irradiance in W/m^2 of cell `(iu, iv)` at index `iv * nu + iu`.
    pub irradiance: Vec<f64>,
    /// Illuminance in lux (lm/m^2), indexed as `irradiance`.
    pub illuminance: Vec<f64>,
    /// Melanopic equivalent daylight illuminance in lux (CIE S 026), indexed as `irradiance`.
    pub melanopic_edi: Vec<f64>,
}

/// Summary figures (lux) as lighting standards define them (EN 12464-1 / EN 12193: uniformity
/// `U0 = Emin / Eaverage` over the grid's cells).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SensorSummary {
    /// Average illuminance over the cells (lux); cells have equal areas.
    pub average_lux: f64,
    /// Smallest cell illuminance (lux).
    pub minimum_lux: f64,
    /// Largest cell illuminance (lux).
    pub maximum_lux: f64,
    /// `U0 = minimum / average`; 0 when the average is 0.
    pub uniformity: f64,
    /// Average irradiance over the cells (W/m^2).
    pub average_w_m2: f64,
    /// Average melanopic equivalent daylight illuminance over the cells (lux, CIE S 026).
    pub average_melanopic_edi_lux: f64,
    /// Melanopic daylight efficacy ratio of the light on the sensor: average m-EDI over average
    /// illuminance (1 for D65 daylight); 0 when the average illuminance is 0.
    pub melanopic_der: f64,
    /// Number of cells, `nu * nv`.
    pub cells: u64,
    /// Area of the rectangle, `|edge_u x edge_v|` (m^2).
    pub area_m2: f64,
}

impl SensorGrid {
    /// Number of cells, `nu * nv`.
    fn cell_count(&self) -> u64 {
        u64::from(self.cells[0]) * u64::from(self.cells[1])
    }

    /// The summary figures of the grid (non-finite values, which [`write_sensor_files`] refuses,
    /// make the figures non-finite too; an empty grid gives zeros).
    pub fn summary(&self) -> SensorSummary {
        let mean =
            |v: &[f64]| if v.is_empty() { 0.0 } else { v.iter().sum::<f64>() / v.len() as f64 };
        let average_lux = mean(&self.illuminance);
        let (minimum_lux, maximum_lux) = if self.illuminance.is_empty() {
            (0.0, 0.0)
        } else {
            self.illuminance
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| (lo.min(x), hi.max(x)))
        };
        let uniformity = if average_lux > 0.0 { minimum_lux / average_lux } else { 0.0 };
        SensorSummary {
            average_lux,
            minimum_lux,
            maximum_lux,
            uniformity,
            average_w_m2: mean(&self.irradiance),
            average_melanopic_edi_lux: mean(&self.melanopic_edi),
            melanopic_der: if average_lux > 0.0 {
                mean(&self.melanopic_edi) / average_lux
            } else {
                0.0
            },
            cells: self.cell_count(),
            area_m2: self.edge_u.cross(self.edge_v).length(),
        }
    }

    /// The centre of cell `(iu, iv)`: `corner + (iu + 0.5)/nu edge_u + (iv + 0.5)/nv edge_v`.
    pub fn cell_centre(&self, iu: u32, iv: u32) -> DVec3 {
        let [nu, nv] = self.cells.map(|n| f64::from(n.max(1)));
        self.corner
            + (f64::from(iu) + 0.5) / nu * self.edge_u
            + (f64::from(iv) + 0.5) / nv * self.edge_v
    }

    /// The CSV: header `iu,iv,x,y,z,irradiance_w_m2,illuminance_lux,melanopic_edi_lux`, then one
    /// row per cell,
    /// `iv` the outer loop and `iu` the inner, numbers that read back exactly, `\n` line ends. A
    /// value missing from a too-short vector is written as `NaN`, and rows stop after the longer
    /// vector's last value ([`write_sensor_files`] refuses such grids).
    pub fn csv(&self) -> String {
        let [nu, nv] = self.cells;
        let longest =
            self.irradiance.len().max(self.illuminance.len()).max(self.melanopic_edi.len());
        let rows = self.cell_count().min(longest as u64);
        let mut out = String::with_capacity(48 + rows as usize * 96);
        out.push_str("iu,iv,x,y,z,irradiance_w_m2,illuminance_lux,melanopic_edi_lux\n");
        for iv in 0..nv {
            for iu in 0..nu {
                let i = iv as usize * nu as usize + iu as usize;
                if i as u64 >= rows {
                    return out;
                }
                let c = self.cell_centre(iu, iv);
                let e = self.irradiance.get(i).copied().unwrap_or(f64::NAN);
                let l = self.illuminance.get(i).copied().unwrap_or(f64::NAN);
                let m = self.melanopic_edi.get(i).copied().unwrap_or(f64::NAN);
                // Writing to a String cannot fail.
                let _ = writeln!(out, "{iu},{iv},{},{},{},{e},{l},{m}", c.x, c.y, c.z);
            }
        }
        out
    }

    /// The false-colour PNG image: each cell a block of `k x k` pixels (`k` chosen so the map is
    /// 400 to 800 pixels on its long side; one pixel per cell for grids of more than 800 cells on
    /// a side, and for more than 2048 cells on a side the cell at each pixel's centre), `+v` up
    /// as in the EXR, coloured by [`sensor_colour`] of `illuminance / top` where `top` is the
    /// legend's top value. Beside it the colour bar from 0 to `top` lux with 5 to 8 labelled
    /// ticks in 1-2-5 steps (0 to 1 lx for a grid of zeros) under the unit "lx"; under it the
    /// average, minimum, maximum and `U0`. Non-finite or missing values (refused by
    /// [`write_sensor_files`]) are drawn grey.
    pub fn false_colour(&self) -> RgbImage {
        let [nu, nv] = self.cells.map(|n| n.max(1));
        let long = nu.max(nv);
        let (map_w, map_h) = if long <= MAP_TARGET_PX {
            let k = MAP_TARGET_PX / long;
            (nu * k, nv * k)
        } else if long <= MAP_MAX_PX {
            (nu, nv)
        } else {
            let shrink = |n: u32| {
                ((u64::from(n) * u64::from(MAP_MAX_PX)).div_ceil(u64::from(long)) as u32).max(1)
            };
            (shrink(nu), shrink(nv))
        };
        let finite_max =
            self.illuminance.iter().copied().filter(|x| x.is_finite()).fold(0.0f64, f64::max);
        let legend = Legend::for_maximum(finite_max);

        // Layout, in pixels.
        let top_y = MARGIN + GLYPH + 8;
        let bar_h = map_h.max(MIN_BAR_PX);
        let bar_x = MARGIN + map_w + 24;
        let label_x = bar_x + BAR_W + TICK_W + 4;
        let labels: Vec<String> = (0..=legend.intervals).map(|i| legend.label(i)).collect();
        let label_w = labels.iter().map(|l| text_width(l)).max().unwrap_or(0);
        let summary = self.summary();
        let lines = [
            format!("average {} lx", format_value(summary.average_lux)),
            format!("minimum {} lx", format_value(summary.minimum_lux)),
            format!("maximum {} lx", format_value(summary.maximum_lux)),
            format!("U0 = min/avg {:.2}", summary.uniformity),
        ];
        let text_y = top_y + bar_h + 16;
        let width = (label_x + label_w + MARGIN)
            .max(MARGIN + lines.iter().map(|l| text_width(l)).max().unwrap_or(0) + MARGIN);
        let height = text_y + lines.len() as u32 * LINE_H + MARGIN;
        let mut img = RgbImage::from_pixel(width, height, Rgb(WHITE));

        // The map.
        for py in 0..map_h {
            // Image rows run downwards; iv upwards.
            let iv = nv - 1 - scale_index(py, map_h, nv);
            for px in 0..map_w {
                let iu = scale_index(px, map_w, nu);
                let i = iv as usize * nu as usize + iu as usize;
                let colour = match self.illuminance.get(i) {
                    Some(&x) if x.is_finite() => sensor_colour(x / legend.top()),
                    _ => GREY,
                };
                img.put_pixel(MARGIN + px, top_y + py, Rgb(colour));
            }
        }

        // The colour bar: its top row is `top`, its bottom row 0.
        for y in 0..bar_h {
            let t = 1.0 - f64::from(y) / f64::from(bar_h - 1);
            for x in 0..BAR_W {
                img.put_pixel(bar_x + x, top_y + y, Rgb(sensor_colour(t)));
            }
        }
        for (i, label) in labels.iter().enumerate() {
            let t = i as f64 / f64::from(legend.intervals);
            let y = top_y + ((1.0 - t) * f64::from(bar_h - 1)).round() as u32;
            for x in 0..TICK_W {
                img.put_pixel(bar_x + BAR_W + x, y, Rgb(BLACK));
            }
            draw_text(&mut img, label_x, y.saturating_sub(GLYPH / 2), label);
        }
        draw_text(&mut img, bar_x, MARGIN, "lx");

        for (n, line) in lines.iter().enumerate() {
            draw_text(&mut img, MARGIN, text_y + n as u32 * LINE_H, line);
        }
        img
    }

    /// Checks everything [`write_sensor_files`] needs: a valid name, at least one cell and at
    /// most [`MAX_SENSOR_CELLS`], one value per cell, finite values that fit a 32-bit float.
    fn check(&self) -> Result<(), String> {
        check_output_name(&self.name).map_err(|e| format!("sensor name {e}"))?;
        let name = &self.name;
        let [nu, nv] = self.cells;
        if nu == 0 || nv == 0 {
            return Err(format!("sensor {name:?}: cells [{nu}, {nv}] must both be at least 1"));
        }
        let n = self.cell_count();
        if n > MAX_SENSOR_CELLS {
            return Err(format!(
                "sensor {name:?}: cells [{nu}, {nv}] make {n} cells, more than {MAX_SENSOR_CELLS}"
            ));
        }
        for (what, v) in [("corner", self.corner), ("edge_u", self.edge_u), ("edge_v", self.edge_v)]
        {
            if !v.is_finite() {
                return Err(format!("sensor {name:?}: {what} {v} is not finite"));
            }
        }
        for (what, unit, values) in [
            ("irradiance", "W/m^2", &self.irradiance),
            ("illuminance", "lx", &self.illuminance),
            ("melanopic_edi", "lx", &self.melanopic_edi),
        ] {
            if values.len() as u64 != n {
                return Err(format!(
                    "sensor {name:?}: {what} has {} values for {nu} x {nv} = {n} cells",
                    values.len()
                ));
            }
            for (i, &x) in values.iter().enumerate() {
                let (iu, iv) = (i % nu as usize, i / nu as usize);
                if !x.is_finite() {
                    return Err(format!(
                        "sensor {name:?}: {what} of cell ({iu}, {iv}) is {x}, not a finite number"
                    ));
                }
                if !(x as f32).is_finite() {
                    return Err(format!(
                        "sensor {name:?}: {what} of cell ({iu}, {iv}) is {x:e} {unit}, beyond \
                         the range of the EXR's 32-bit floats (about 3.4e38)"
                    ));
                }
            }
        }
        Ok(())
    }

    /// Writes the EXR (see the module docs) to `path`.
    fn write_exr(&self, path: &Path) -> Result<(), String> {
        use exr::prelude::*;
        let [nu, nv] = self.cells.map(|n| n as usize);
        let at = |v: &[f64], x: usize, y: usize| {
            v.get((nv - 1 - y) * nu + x).map_or(f32::NAN, |&s| s as f32)
        };
        let channels = SpecificChannels::build()
            .with_channel("illuminance_lux")
            .with_channel("irradiance_w_m2")
            .with_channel("melanopic_edi_lux")
            .with_pixel_fn(|Vec2(x, y): Vec2<usize>| {
                (
                    at(&self.illuminance, x, y),
                    at(&self.irradiance, x, y),
                    at(&self.melanopic_edi, x, y),
                )
            });
        let image = Image::from_encoded_channels((nu, nv), Encoding::SMALL_LOSSLESS, channels);
        image.write().non_parallel().to_file(path).map_err(|e| e.to_string())
    }
}

/// Writes `NAME.csv`, `NAME.exr` and `NAME.png` (see the module docs) into `dir` via
/// [`write_atomically`], refusing to replace any path in `inputs`; returns the paths written.
///
/// # Errors
/// What is wrong with the grid (its name, cell counts, value counts, a non-finite value or one
/// beyond 32-bit floats), naming the sensor; an output that would replace an input; a failed
/// write, naming the file. Nothing is written for an invalid grid or a replaced input.
pub fn write_sensor_files(
    dir: &Path,
    grid: &SensorGrid,
    inputs: &[PathBuf],
) -> Result<Vec<PathBuf>, String> {
    grid.check()?;
    let paths: Vec<PathBuf> =
        ["csv", "exr", "png"].iter().map(|ext| dir.join(format!("{}.{ext}", grid.name))).collect();
    check_no_input_replaced(&paths, inputs)?;
    let with_path =
        |p: &Path, r: Result<(), String>| r.map_err(|e| format!("{}: {e}", p.display()));
    let csv = grid.csv();
    with_path(
        &paths[0],
        write_atomically(&paths[0], |p| std::fs::write(p, &csv).map_err(|e| e.to_string())),
    )?;
    with_path(&paths[1], write_atomically(&paths[1], |p| grid.write_exr(p)))?;
    let png = grid.false_colour();
    with_path(
        &paths[2],
        write_atomically(&paths[2], |p| {
            png.save_with_format(p, image::ImageFormat::Png).map_err(|e| e.to_string())
        }),
    )?;
    Ok(paths)
}

/// The colour map of the false-colour PNG: viridis, perceptually ordered from dark purple (`t =
/// 0`, low) to yellow (`t = 1`, high), as 8-bit sRGB; `t` is clamped to `[0, 1]` and NaN maps to
/// 0.
///
/// The anchors are matplotlib's viridis (van der Walt and Smith, 2015, released CC0) at `t = 0,
/// 1/8, ..., 1` (#440154, #472D7B, #3B528B, #2C728E, #21918C, #28AE80, #5EC962, #ADDC30,
/// #FDE725), interpolated linearly in between.
pub fn sensor_colour(t: f64) -> [u8; 3] {
    const ANCHORS: [[u8; 3]; 9] = [
        [0x44, 0x01, 0x54],
        [0x47, 0x2D, 0x7B],
        [0x3B, 0x52, 0x8B],
        [0x2C, 0x72, 0x8E],
        [0x21, 0x91, 0x8C],
        [0x28, 0xAE, 0x80],
        [0x5E, 0xC9, 0x62],
        [0xAD, 0xDC, 0x30],
        [0xFD, 0xE7, 0x25],
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let x = t * (ANCHORS.len() - 1) as f64;
    let i = (x.floor() as usize).min(ANCHORS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (ANCHORS[i], ANCHORS[i + 1]);
    [0, 1, 2].map(|c| {
        (f64::from(a[c]) + (f64::from(b[c]) - f64::from(a[c])) * f).round().clamp(0.0, 255.0) as u8
    })
}

/// The map's long side when cells are drawn as blocks (between 400 and 800 pixels).
const MAP_TARGET_PX: u32 = 800;
/// The map's long side beyond which cells are sampled rather than drawn.
const MAP_MAX_PX: u32 = 2048;
/// The colour bar's least height, for flat maps.
const MIN_BAR_PX: u32 = 256;
/// The colour bar's width.
const BAR_W: u32 = 24;
/// The tick marks' length.
const TICK_W: u32 = 6;
/// Blank border around everything.
const MARGIN: u32 = 16;
/// Pixels per font pixel.
const FONT_SCALE: u32 = 2;
/// A glyph's side in pixels (the font is 8 x 8).
const GLYPH: u32 = 8 * FONT_SCALE;
/// Height of a line of summary text.
const LINE_H: u32 = GLYPH + 6;
const WHITE: [u8; 3] = [255, 255, 255];
const BLACK: [u8; 3] = [0, 0, 0];
const GREY: [u8; 3] = [128, 128, 128];

/// The cell shown at pixel `p` of `pixels` along a side of `cells` cells (the cell under the
/// pixel's centre).
fn scale_index(p: u32, pixels: u32, cells: u32) -> u32 {
    let i = (2 * u64::from(p) + 1) * u64::from(cells) / (2 * u64::from(pixels));
    (i as u32).min(cells - 1)
}

/// The legend: ticks at `0, step, ..., intervals * step` with `step = mantissa * 10^exponent`,
/// `mantissa` 1, 2 or 5.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Legend {
    mantissa: u64,
    exponent: i32,
    intervals: u32,
}

impl Legend {
    /// The tightest legend from 0 to at least `max` with 5 to 8 ticks (4 to 7 intervals) in
    /// 1-2-5 steps; a `max` that is not positive and finite gives 0 to 1. A `max` beyond 1e300
    /// (never written: the EXR refuses it) is treated as 1e300.
    fn for_maximum(max: f64) -> Self {
        let max = if max > 0.0 && max.is_finite() { max.min(1e300) } else { 1.0 };
        let mut exponent = max.log10().floor() as i32 - 1;
        loop {
            for mantissa in [1, 2, 5] {
                let step = mantissa as f64 * 10f64.powi(exponent);
                let n = (max / step).ceil();
                if n <= 7.0 {
                    return Legend { mantissa, exponent, intervals: (n as u32).max(4) };
                }
            }
            exponent += 1;
        }
    }

    /// The value of the top tick.
    fn top(&self) -> f64 {
        self.value(self.intervals)
    }

    /// The value of tick `i`.
    fn value(&self, i: u32) -> f64 {
        (u64::from(i) * self.mantissa) as f64 * 10f64.powi(self.exponent)
    }

    /// The label of tick `i`, exact: `k 10^exponent` with `k = i * mantissa`, as a plain number
    /// from 0.0001 up to 999999 and in scientific notation beyond.
    fn label(&self, i: u32) -> String {
        format_decimal(u64::from(i) * self.mantissa, self.exponent)
    }
}

/// `k 10^e` written exactly: plain decimal for `e` in `-4..` while below 10^6, else `d.ddde±N`.
fn format_decimal(k: u64, e: i32) -> String {
    if k == 0 {
        return "0".to_owned();
    }
    let digits = k.to_string();
    let magnitude = digits.len() as i32 - 1 + e; // floor(log10(k 10^e))
    if (0..6).contains(&magnitude) && e >= 0 {
        format!("{digits}{}", "0".repeat(e as usize))
    } else if (-4..0).contains(&e) && magnitude < 6 {
        let frac = (-e) as usize;
        let padded = format!("{digits:0>width$}", width = frac + 1);
        let (int, dec) = padded.split_at(padded.len() - frac);
        let dec = dec.trim_end_matches('0');
        if dec.is_empty() { int.to_owned() } else { format!("{int}.{dec}") }
    } else {
        let (first, rest) = digits.split_at(1);
        let rest = rest.trim_end_matches('0');
        if rest.is_empty() {
            format!("{first}e{magnitude}")
        } else {
            format!("{first}.{rest}e{magnitude}")
        }
    }
}

/// A summary figure with about three significant digits.
pub(crate) fn format_value(x: f64) -> String {
    if x == 0.0 {
        return "0".to_owned();
    }
    let a = x.abs();
    if (1e-3..1e6).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).clamp(0, 5) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.2e}")
    }
}

/// Width in pixels of `text` drawn by [`draw_text`].
fn text_width(text: &str) -> u32 {
    text.chars().count() as u32 * GLYPH
}

/// Draws `text` in black with its top-left corner at `(x, y)`, clipped to the image; characters
/// beyond ASCII are drawn as `?`.
fn draw_text(img: &mut RgbImage, x: u32, y: u32, text: &str) {
    for (n, ch) in text.chars().enumerate() {
        let code = if ch.is_ascii() { ch as usize } else { '?' as usize };
        let glyph = font8x8::legacy::BASIC_LEGACY[code];
        let gx = x + n as u32 * GLYPH;
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8u32 {
                // Bit 0 is the leftmost pixel of a row.
                if bits >> col & 1 == 0 {
                    continue;
                }
                for dy in 0..FONT_SCALE {
                    for dx in 0..FONT_SCALE {
                        let (px, py) =
                            (gx + col * FONT_SCALE + dx, y + row as u32 * FONT_SCALE + dy);
                        if px < img.width() && py < img.height() {
                            img.put_pixel(px, py, Rgb(BLACK));
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("spectrace-sensor-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A 3 x 2 grid on a tilted rectangle, with distinct values per cell.
    fn grid() -> SensorGrid {
        let illuminance = vec![100.0, 200.0, 300.0, 400.0, 500.0, 600.0];
        SensorGrid {
            name: "desk".to_owned(),
            corner: DVec3::new(1.0, 2.0, 3.0),
            edge_u: DVec3::new(3.0, 0.0, 0.0),
            edge_v: DVec3::new(0.0, 2.0, 1.0),
            cells: [3, 2],
            irradiance: illuminance.iter().map(|l| l / 683.0).collect(),
            melanopic_edi: illuminance.iter().map(|l| l * 0.5).collect(),
            illuminance,
        }
    }

    #[test]
    fn sensor_csv_header_and_rows_read_back() {
        let g = grid();
        let csv = g.csv();
        let lines: Vec<&str> = csv.split('\n').collect();
        assert_eq!(lines[0], "iu,iv,x,y,z,irradiance_w_m2,illuminance_lux,melanopic_edi_lux");
        assert_eq!(lines.len(), 1 + 6 + 1, "one row per cell and a final newline");
        assert_eq!(*lines.last().unwrap(), "");
        assert!(!csv.contains('\r'));
        // Row 5 (iv = 1, iu = 1): iv is the outer loop.
        let f: Vec<f64> = lines[5].split(',').map(|s| s.parse().unwrap()).collect();
        assert_eq!(&f[..2], &[1.0, 1.0]);
        // corner + 1.5/3 edge_u + 1.5/2 edge_v.
        let expected = DVec3::new(1.0 + 1.5, 2.0 + 1.5, 3.0 + 0.75);
        assert!((DVec3::new(f[2], f[3], f[4]) - expected).length() < 1e-12, "{f:?}");
        assert_eq!(f[5], 500.0 / 683.0, "irradiance round-trips exactly");
        assert_eq!(f[6], 500.0);
        assert_eq!((f.len(), f[7]), (8, 250.0), "melanopic EDI last");
        // iu counts along edge_u from the corner.
        let first: Vec<f64> = lines[1].split(',').map(|s| s.parse().unwrap()).collect();
        let second: Vec<f64> = lines[2].split(',').map(|s| s.parse().unwrap()).collect();
        assert_eq!(&first[..2], &[0.0, 0.0]);
        assert_eq!(&second[..2], &[1.0, 0.0]);
        assert_eq!(first[2], 1.5);
        assert_eq!(second[2] - first[2], 1.0);
        assert_eq!(second[3], first[3]);
    }

    #[test]
    fn sensor_cell_centre_formula() {
        let g = grid();
        assert_eq!(g.cell_centre(0, 0), DVec3::new(1.5, 2.5, 3.25));
        assert_eq!(g.cell_centre(2, 1), DVec3::new(3.5, 3.5, 3.75));
    }

    #[test]
    fn sensor_summary_of_a_hand_made_grid() {
        let s = grid().summary();
        assert_eq!(s.average_lux, 350.0);
        assert_eq!(s.minimum_lux, 100.0);
        assert_eq!(s.maximum_lux, 600.0);
        assert_eq!(s.uniformity, 100.0 / 350.0);
        assert!((s.average_w_m2 - 350.0 / 683.0).abs() < 1e-15);
        assert_eq!((s.average_melanopic_edi_lux, s.melanopic_der), (175.0, 0.5));
        assert_eq!(s.cells, 6);
        // |(3,0,0) x (0,2,1)| = |(0,-3,6)| = sqrt(45).
        assert!((s.area_m2 - 45f64.sqrt()).abs() < 1e-12);
        let mut dark = grid();
        dark.illuminance = vec![0.0; 6];
        let d = dark.summary();
        assert_eq!((d.average_lux, d.uniformity), (0.0, 0.0));
    }

    #[test]
    fn sensor_colour_map_runs_from_dark_to_bright() {
        assert_eq!(sensor_colour(0.0), [0x44, 0x01, 0x54]);
        assert_eq!(sensor_colour(1.0), [0xFD, 0xE7, 0x25]);
        assert_eq!(sensor_colour(0.5), [0x21, 0x91, 0x8C]);
        assert_eq!(sensor_colour(-3.0), sensor_colour(0.0));
        assert_eq!(sensor_colour(7.0), sensor_colour(1.0));
        assert_eq!(sensor_colour(f64::NAN), sensor_colour(0.0));
        // Perceptually ordered: the luma (Rec. 709 weights) rises monotonically.
        let luma = |c: [u8; 3]| {
            0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
        };
        let mut last = -1.0;
        for i in 0..=100 {
            let l = luma(sensor_colour(f64::from(i) / 100.0));
            assert!(l > last, "luma falls at t = {}", f64::from(i) / 100.0);
            last = l;
        }
    }

    #[test]
    fn sensor_png_high_and_low_cells_match_the_ends_of_the_colour_bar() {
        let mut g = grid();
        // The maximum 600 lx gives the legend 0..600 (intervals of 100): 600 is its top.
        let img = g.false_colour();
        let legend = Legend::for_maximum(600.0);
        assert_eq!(legend.top(), 600.0);
        // The map is 3 x 2 cells of k = 266 px, at (MARGIN, top_y).
        let k = MAP_TARGET_PX / 3;
        let top_y = MARGIN + GLYPH + 8;
        let cell = |iu: u32, iv: u32| {
            *img.get_pixel(MARGIN + iu * k + k / 2, top_y + (1 - iv) * k + k / 2)
        };
        let high = cell(2, 1); // 600 lx, drawn top right (+v up)
        let low = cell(0, 0); // 100 lx, bottom left
        assert_ne!(high, low);
        let bar_x = MARGIN + 3 * k + 24 + BAR_W / 2;
        let bar_h = (2 * k).max(MIN_BAR_PX);
        assert_eq!(high.0, img.get_pixel(bar_x, top_y).0, "the top of the bar is the maximum");
        assert_eq!(high.0, sensor_colour(1.0));
        assert_eq!(low.0, sensor_colour(100.0 / 600.0));
        // 100 lx sits a sixth of the way up the bar.
        let y100 = top_y + ((1.0 - 1.0 / 6.0) * f64::from(bar_h - 1)).round() as u32;
        assert_eq!(low.0, img.get_pixel(bar_x, y100).0);
        assert_eq!(img.get_pixel(bar_x, top_y + bar_h - 1).0, sensor_colour(0.0));
        // The image's long side holds the map and the legend; text is drawn somewhere below.
        assert!(img.width() > 3 * k && img.height() > 2 * k);
        let below = (top_y + bar_h..img.height())
            .any(|y| (0..img.width()).any(|x| img.get_pixel(x, y).0 == BLACK));
        assert!(below, "no summary text under the map");
        // A non-finite value is drawn grey, not a panic.
        g.illuminance[0] = f64::NAN;
        let img = g.false_colour();
        assert_eq!(img.get_pixel(MARGIN + k / 2, top_y + k + k / 2).0, GREY);
    }

    #[test]
    fn sensor_png_of_zeros_single_cells_and_long_grids() {
        let mut g = grid();
        g.illuminance = vec![0.0; 6];
        assert_eq!(Legend::for_maximum(0.0).top(), 1.0);
        let img = g.false_colour();
        assert_eq!(img.get_pixel(MARGIN + 1, MARGIN + GLYPH + 9).0, sensor_colour(0.0));
        let one = SensorGrid {
            name: "one".to_owned(),
            corner: DVec3::ZERO,
            edge_u: DVec3::X,
            edge_v: DVec3::Y,
            cells: [1, 1],
            irradiance: vec![1.0],
            illuminance: vec![683.0],
            melanopic_edi: vec![300.0],
        };
        let img = one.false_colour();
        assert!(img.width() >= 800 && img.height() >= 800);
        // A strip of 5000 x 1 cells is sampled down, not drawn 5000 px wide.
        let strip = SensorGrid {
            cells: [5000, 1],
            irradiance: vec![1.0; 5000],
            illuminance: (0..5000).map(f64::from).collect(),
            melanopic_edi: vec![1.0; 5000],
            ..one
        };
        let img = strip.false_colour();
        assert!(img.width() < MAP_MAX_PX + 400, "{}", img.width());
    }

    #[test]
    fn sensor_legend_has_5_to_8_round_ticks() {
        let mut max = 1e-7;
        while max < 1e9 {
            let l = Legend::for_maximum(max);
            assert!((4..=7).contains(&l.intervals), "{max}: {l:?}");
            assert!([1, 2, 5].contains(&l.mantissa));
            assert!(l.top() >= max * (1.0 - 1e-12), "{max}: top {}", l.top());
            assert!(l.top() <= 1.5 * max, "{max}: top {} too loose", l.top());
            max *= 1.037;
        }
        let l = Legend::for_maximum(14.5);
        let labels: Vec<String> = (0..=l.intervals).map(|i| l.label(i)).collect();
        assert_eq!(labels, ["0", "5", "10", "15", "20"]);
        let l = Legend::for_maximum(0.7);
        let labels: Vec<String> = (0..=l.intervals).map(|i| l.label(i)).collect();
        assert_eq!(labels, ["0", "0.1", "0.2", "0.3", "0.4", "0.5", "0.6", "0.7"]);
        assert_eq!(format_decimal(5, -5), "5e-5");
        assert_eq!(format_decimal(15, 6), "1.5e7");
        assert_eq!(format_decimal(20, 4), "200000");
        assert_eq!(format_decimal(10, 5), "1e6");
        assert_eq!(format_decimal(25, -2), "0.25");
    }

    #[test]
    fn sensor_exr_round_trips() {
        let d = temp("exr");
        let mut g = grid();
        g.illuminance[4] = 1e-30; // within f32 range, kept
        let written = write_sensor_files(&d, &g, &[]).unwrap();
        assert_eq!(written, ["desk.csv", "desk.exr", "desk.png"].map(|n| d.join(n)));
        use exr::prelude::*;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .specific_channels()
            .required("illuminance_lux")
            .required("irradiance_w_m2")
            .required("melanopic_edi_lux")
            .collect_pixels(
                |res, _| vec![vec![(0f32, 0f32, 0f32); res.width()]; res.height()],
                |rows, pos, (l, e, m): (f32, f32, f32)| rows[pos.y()][pos.x()] = (l, e, m),
            )
            .first_valid_layer()
            .all_attributes()
            .from_file(&written[1])
            .unwrap();
        let rows = &image.layer_data.channel_data.pixels;
        assert_eq!((rows.len(), rows[0].len()), (2, 3));
        for (i, (l, e)) in g.illuminance.iter().zip(&g.irradiance).enumerate() {
            let (iu, iv) = (i % 3, i / 3);
            let m = g.melanopic_edi[i] as f32;
            assert_eq!(rows[1 - iv][iu], (*l as f32, *e as f32, m), "cell ({iu}, {iv})");
        }
        // Deterministic bytes, and the CSV is the grid's.
        let bytes = std::fs::read(&written[1]).unwrap();
        write_sensor_files(&d, &g, &[]).unwrap();
        assert_eq!(bytes, std::fs::read(&written[1]).unwrap());
        assert_eq!(std::fs::read_to_string(&written[0]).unwrap(), g.csv());
        let png = image::open(&written[2]).unwrap().to_rgb8();
        assert_eq!(png, g.false_colour());
    }

    #[test]
    fn sensor_files_refuse_bad_names_inputs_and_values() {
        let d = temp("refuse");
        let mut g = grid();
        for bad in ["../x", "", "a/b", ".."] {
            g.name = bad.to_owned();
            let e = write_sensor_files(&d, &g, &[]).unwrap_err();
            assert!(e.starts_with("sensor name"), "{e}");
        }
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0);
        // An input named like an output is never replaced, and nothing is written.
        g.name = "scene".to_owned();
        let input = d.join("scene.csv");
        std::fs::write(&input, "keep").unwrap();
        let e = write_sensor_files(&d, &g, std::slice::from_ref(&input)).unwrap_err();
        assert!(e.contains("would replace the input"), "{e}");
        assert_eq!(std::fs::read_to_string(&input).unwrap(), "keep");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        // Bad values: errors name the sensor, the quantity and the cell; nothing is written.
        let mut nan = grid();
        nan.illuminance[4] = f64::INFINITY;
        let e = write_sensor_files(&d, &nan, &[]).unwrap_err();
        assert!(e.contains("\"desk\"") && e.contains("illuminance of cell (1, 1) is inf"), "{e}");
        let mut huge = grid();
        huge.irradiance[2] = 1e39;
        let e = write_sensor_files(&d, &huge, &[]).unwrap_err();
        assert!(e.contains("irradiance of cell (2, 0)") && e.contains("32-bit"), "{e}");
        let mut short = grid();
        short.irradiance.pop();
        let e = write_sensor_files(&d, &short, &[]).unwrap_err();
        assert!(e.contains("irradiance has 5 values for 3 x 2 = 6 cells"), "{e}");
        let mut empty = grid();
        empty.cells = [0, 2];
        let e = write_sensor_files(&d, &empty, &[]).unwrap_err();
        assert!(e.contains("at least 1"), "{e}");
        let mut many = grid();
        many.cells = [1 << 16, 1 << 16];
        assert!(write_sensor_files(&d, &many, &[]).unwrap_err().contains("more than"));
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        // A missing folder is an error naming the file, not a panic.
        let e = write_sensor_files(&d.join("missing"), &grid(), &[]).unwrap_err();
        assert!(e.contains("desk.csv"), "{e}");
    }
}
