//! [`Texture`]: a colour or a number that varies over a surface, looked up by the hit's `uv`.
//!
//! | type | field | default | meaning |
//! |---|---|---|---|
//! | `Bitmap` | `file` | required | PNG, JPEG, TGA (8 or 16 bits, grey or colour, alpha ignored) or OpenEXR (R, G, B channels, linear), relative to the scene file's folder |
//! | | `raw` | `false` | `false`: PNG/JPEG/TGA values are sRGB-encoded and decoded to linear; `true`: taken as linear (a roughness map). EXR is always linear |
//! | | `filter` | `"bilinear"` | `"bilinear"` or `"nearest"` |
//! | | `wrap` | `"repeat"` | `"repeat"`, `"mirror"` or `"clamp"`: what `uv` outside `[0, 1]` reads |
//! | | `to_uv` | identity | `[[a, b, c], [d, e, f]]`: the texture is read at `(a u + b v + c, d u + e v + f)` |
//! | `Checkerboard` | `color0`, `color1` | `0.4`, `0.2` | a number or a linear-sRGB `[r, g, b]`: `color0` where `frac(u) > 1/2` and `frac(v) > 1/2` agree, `color1` elsewhere |
//! | | `to_uv` | identity | as for `Bitmap` |
//!
//! ```json
//! {"type": "Bitmap", "file": "wood.png"}
//! {"type": "Checkerboard", "color0": [0.8, 0.1, 0.1], "color1": 0.9, "to_uv": [[8, 0, 0], [0, 8, 0]]}
//! ```
//!
//! **Image coordinates** follow Mitsuba 3: `(0, 0)` is the image's top-left corner, `u` grows
//! to the right and `v` downwards; texel `(i, j)` is centred on `((i + 1/2) / width,
//! (j + 1/2) / height)`. OBJ files store `v` upwards, so their `vt` are read as `(u, 1 - v)`, as
//! Mitsuba reads them. Bilinear filtering blends the four texels around the point.
//!
//! Files are read through the scene folder's path policy and bounded ([`MAX_TEXTURE_BYTES`],
//! [`MAX_TEXTURE_PIXELS`]); a texel that is not a finite number is refused when the file is read.

use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::{Arc, LazyLock};

use glam::DVec2;
use serde::{Deserialize, Serialize};
use spectrace_sampling::files::read_scene_input_bytes;
use spectrace_spectrum::{srgb_decode, srgb_to_xyz_matrix};

use crate::MaterialError;

/// The largest texture file read (bytes).
pub const MAX_TEXTURE_BYTES: u64 = 1 << 30;
/// The most pixels a texture may have (width times height).
pub const MAX_TEXTURE_PIXELS: u64 = 1 << 27;

/// A colour or number varying over a surface (see the module's table).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", deny_unknown_fields)]
pub enum Texture {
    /// An image file.
    Bitmap(Bitmap),
    /// Two colours in a checkerboard.
    Checkerboard(Checkerboard),
}

/// How a [`Bitmap`] reads between texels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Filter {
    /// Blends the four nearest texels.
    #[default]
    Bilinear,
    /// The texel the point falls in.
    Nearest,
}

/// What a [`Bitmap`] reads outside `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Wrap {
    /// The image tiles the plane.
    #[default]
    Repeat,
    /// The image tiles the plane, every other copy mirrored.
    Mirror,
    /// The edge texels continue outwards.
    Clamp,
}

/// The affine map from a hit's `uv` to the texture's (rows of a 2x3 matrix).
pub type UvTransform = [[f64; 3]; 2];

const IDENTITY: UvTransform = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

fn is_identity(t: &UvTransform) -> bool {
    *t == IDENTITY
}

fn apply(t: &UvTransform, uv: DVec2) -> DVec2 {
    let p = DVec2::new(
        t[0][0] * uv.x + t[0][1] * uv.y + t[0][2],
        t[1][0] * uv.x + t[1][1] * uv.y + t[1][2],
    );
    // A non-finite coordinate (a degenerate hit) reads the origin rather than poisoning the path.
    if p.is_finite() { p } else { DVec2::ZERO }
}

/// A texture read from an image file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "BitmapRepr", into = "BitmapRepr")]
pub struct Bitmap {
    file: PathBuf,
    raw: bool,
    filter: Filter,
    wrap: Wrap,
    to_uv: UvTransform,
    pixels: Arc<Pixels>,
}

impl PartialEq for Bitmap {
    fn eq(&self, other: &Self) -> bool {
        self.file == other.file
            && self.raw == other.raw
            && self.filter == other.filter
            && self.wrap == other.wrap
            && self.to_uv == other.to_uv
    }
}

/// Scene-file form of [`Bitmap`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BitmapRepr {
    file: PathBuf,
    #[serde(default)]
    raw: bool,
    #[serde(default)]
    filter: Filter,
    #[serde(default)]
    wrap: Wrap,
    #[serde(default = "identity", skip_serializing_if = "is_identity")]
    to_uv: UvTransform,
}

fn identity() -> UvTransform {
    IDENTITY
}

impl TryFrom<BitmapRepr> for Bitmap {
    type Error = MaterialError;
    fn try_from(r: BitmapRepr) -> Result<Self, MaterialError> {
        check_transform(&r.to_uv)?;
        let (path, bytes) = read_scene_input_bytes(&r.file, MAX_TEXTURE_BYTES, "texture")
            .map_err(|e| texture_error("file", e))?;
        let pixels = Pixels::decode(&path, &bytes, r.raw)?;
        Ok(Self {
            file: r.file,
            raw: r.raw,
            filter: r.filter,
            wrap: r.wrap,
            to_uv: r.to_uv,
            pixels: Arc::new(pixels),
        })
    }
}

impl From<Bitmap> for BitmapRepr {
    fn from(b: Bitmap) -> Self {
        Self { file: b.file, raw: b.raw, filter: b.filter, wrap: b.wrap, to_uv: b.to_uv }
    }
}

fn texture_error(field: &'static str, reason: String) -> MaterialError {
    MaterialError::Texture { field, reason }
}

fn check_transform(t: &UvTransform) -> Result<(), MaterialError> {
    if t.iter().flatten().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(texture_error("to_uv", format!("{t:?}: every entry must be a finite number")))
    }
}

/// Decoded texels, linear, row 0 at the top.
#[derive(Debug)]
struct Pixels {
    width: usize,
    height: usize,
    data: Vec<[f32; 3]>,
}

impl Pixels {
    /// Decodes `bytes` (read from `path`): EXR by its magic number, anything else by `image`.
    fn decode(path: &Path, bytes: &[u8], raw: bool) -> Result<Self, MaterialError> {
        let at = |e: String| texture_error("file", format!("{}: {e}", path.display()));
        let pixels = if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
            Self::exr(bytes).map_err(at)?
        } else {
            Self::image(bytes, raw).map_err(at)?
        };
        if let Some(i) = pixels.data.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            let (x, y) = (i % pixels.width, i / pixels.width);
            return Err(at(format!("texel ({x}, {y}) is {:?}, not finite", pixels.data[i])));
        }
        Ok(pixels)
    }

    fn check_size(width: usize, height: usize) -> Result<(), String> {
        let n = width as u64 * height as u64;
        if n == 0 {
            return Err("the image has no pixels".to_owned());
        }
        if n > MAX_TEXTURE_PIXELS {
            return Err(format!(
                "{width} x {height} pixels is more than the {MAX_TEXTURE_PIXELS} a texture may have"
            ));
        }
        Ok(())
    }

    fn image(bytes: &[u8], raw: bool) -> Result<Self, String> {
        let mut reader = image::ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| e.to_string())?;
        let mut limits = image::Limits::default();
        limits.max_alloc = Some(MAX_TEXTURE_PIXELS * 16);
        reader.limits(limits);
        let (width, height) = reader.into_dimensions().map_err(|e| e.to_string())?;
        Self::check_size(width as usize, height as usize)?;
        let mut reader = image::ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| e.to_string())?;
        reader.limits(limits_for(width, height));
        let decoded = reader.decode().map_err(|e| e.to_string())?.into_rgb32f();
        let decode = |v: f32| if raw { v } else { srgb_decode(f64::from(v)) as f32 };
        let data = decoded.pixels().map(|p| p.0.map(decode)).collect();
        Ok(Self { width: width as usize, height: height as usize, data })
    }

    fn exr(bytes: &[u8]) -> Result<Self, String> {
        use exr::prelude::*;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .rgba_channels(
                |res, _| {
                    let ok = Self::check_size(res.width(), res.height()).is_ok();
                    let n = if ok { res.width() * res.height() } else { 0 };
                    (res.width(), vec![[0f32; 3]; n])
                },
                |(w, px): &mut (usize, Vec<[f32; 3]>), pos, (r, g, b, _): (f32, f32, f32, f32)| {
                    if let Some(p) = px.get_mut(pos.y() * *w + pos.x()) {
                        *p = [r, g, b];
                    }
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(Cursor::new(bytes))
            .map_err(|e| e.to_string())?;
        let size = image.layer_data.size;
        Self::check_size(size.width(), size.height())?;
        let (_, data) = image.layer_data.channel_data.pixels;
        Ok(Self { width: size.width(), height: size.height(), data })
    }

    fn texel(&self, x: i64, y: i64, wrap: Wrap) -> [f32; 3] {
        let (x, y) = (wrapped(x, self.width, wrap), wrapped(y, self.height, wrap));
        self.data[y * self.width + x]
    }
}

/// Decoder limits for an image of the given size (room for 16-bit RGBA and the float copy).
fn limits_for(width: u32, height: u32) -> image::Limits {
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(width);
    limits.max_image_height = Some(height);
    limits.max_alloc = Some(u64::from(width) * u64::from(height) * 32);
    limits
}

/// Texel index `i` of a row or column of `n`, under `wrap`.
fn wrapped(i: i64, n: usize, wrap: Wrap) -> usize {
    let n = n as i64;
    let k = match wrap {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Mirror => {
            let k = i.rem_euclid(2 * n);
            if k >= n { 2 * n - 1 - k } else { k }
        }
    };
    k as usize
}

impl Bitmap {
    /// The image's width and height in texels.
    pub fn size(&self) -> (usize, usize) {
        (self.pixels.width, self.pixels.height)
    }

    /// The linear colour of texel `(x, y)` (row 0 at the top), or black outside the image.
    pub fn texel(&self, x: usize, y: usize) -> [f64; 3] {
        let px = &self.pixels;
        if x < px.width && y < px.height {
            px.data[y * px.width + x].map(f64::from)
        } else {
            [0.0; 3]
        }
    }

    /// The linear colour at `uv`.
    pub fn rgb(&self, uv: DVec2) -> [f64; 3] {
        let p = apply(&self.to_uv, uv);
        let px = &self.pixels;
        let (w, h) = (px.width as f64, px.height as f64);
        // Far outside the image every wrap mode reads a texel within one period.
        let clampi = |v: f64| v.clamp(-1e15, 1e15);
        match self.filter {
            Filter::Nearest => {
                let (x, y) = (clampi((p.x * w).floor()) as i64, clampi((p.y * h).floor()) as i64);
                px.texel(x, y, self.wrap).map(f64::from)
            }
            Filter::Bilinear => {
                let (fx, fy) = (clampi(p.x * w - 0.5), clampi(p.y * h - 0.5));
                let (x0, y0) = (fx.floor(), fy.floor());
                let (tx, ty) = (fx - x0, fy - y0);
                let (x0, y0) = (x0 as i64, y0 as i64);
                let mut out = [0.0; 3];
                for (dy, wy) in [(0, 1.0 - ty), (1, ty)] {
                    for (dx, wx) in [(0, 1.0 - tx), (1, tx)] {
                        let t = px.texel(x0 + dx, y0 + dy, self.wrap);
                        for c in 0..3 {
                            out[c] += wx * wy * f64::from(t[c]);
                        }
                    }
                }
                out
            }
        }
    }

    /// The smallest and largest component of any texel (every filtered value lies between).
    fn range(&self) -> (f64, f64) {
        self.pixels
            .data
            .iter()
            .flatten()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(f64::from(v)), hi.max(f64::from(v)))
            })
    }
}

/// A colour of a [`Checkerboard`]: a number (grey) or a linear-sRGB `[r, g, b]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Colour {
    /// The same value in every channel.
    Grey(f64),
    /// Linear sRGB.
    Rgb([f64; 3]),
}

impl Colour {
    /// The colour's three channels.
    pub fn rgb(self) -> [f64; 3] {
        match self {
            Colour::Grey(v) => [v; 3],
            Colour::Rgb(c) => c,
        }
    }
}

/// Two colours in a checkerboard of period 1 in `uv` (after `to_uv`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, try_from = "CheckerboardRepr")]
pub struct Checkerboard {
    /// Where `frac(u) > 1/2` and `frac(v) > 1/2` agree.
    #[serde(default = "default_color0")]
    pub color0: Colour,
    /// Elsewhere.
    #[serde(default = "default_color1")]
    pub color1: Colour,
    /// The map from the hit's `uv` to the board's.
    #[serde(default = "identity", skip_serializing_if = "is_identity")]
    pub to_uv: UvTransform,
}

/// Scene-file form of [`Checkerboard`], checked on the way in.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CheckerboardRepr {
    #[serde(default = "default_color0")]
    color0: Colour,
    #[serde(default = "default_color1")]
    color1: Colour,
    #[serde(default = "identity")]
    to_uv: UvTransform,
}

impl TryFrom<CheckerboardRepr> for Checkerboard {
    type Error = MaterialError;
    fn try_from(r: CheckerboardRepr) -> Result<Self, MaterialError> {
        check_transform(&r.to_uv)?;
        Ok(Self { color0: r.color0, color1: r.color1, to_uv: r.to_uv })
    }
}

fn default_color0() -> Colour {
    Colour::Grey(0.4)
}

fn default_color1() -> Colour {
    Colour::Grey(0.2)
}

impl Checkerboard {
    /// The colour at `uv`.
    pub fn rgb(&self, uv: DVec2) -> [f64; 3] {
        let p = apply(&self.to_uv, uv);
        let upper = |v: f64| v - v.floor() > 0.5;
        if upper(p.x) == upper(p.y) { self.color0.rgb() } else { self.color1.rgb() }
    }
}

impl Texture {
    /// The linear colour at `uv`.
    pub fn rgb(&self, uv: DVec2) -> [f64; 3] {
        match self {
            Texture::Bitmap(b) => b.rgb(uv),
            Texture::Checkerboard(c) => c.rgb(uv),
        }
    }

    /// The number at `uv`: the colour's luminance (Rec. 709 weights; a grey's own value).
    pub fn value(&self, uv: DVec2) -> f64 {
        luminance(self.rgb(uv))
    }

    /// The smallest and largest channel value the texture can return.
    pub fn range(&self) -> (f64, f64) {
        match self {
            Texture::Bitmap(b) => b.range(),
            Texture::Checkerboard(c) => {
                let all = c.color0.rgb().into_iter().chain(c.color1.rgb());
                all.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
            }
        }
    }
}

/// The luminance `Y` of a linear-sRGB colour: the `Y` row of the sRGB-to-XYZ matrix (Rec. 709's
/// 0.2126, 0.7152, 0.0722), exactly `v` for a grey `[v, v, v]`.
pub fn luminance(rgb: [f64; 3]) -> f64 {
    static Y: LazyLock<[f64; 3]> = LazyLock::new(|| srgb_to_xyz_matrix()[1]);
    if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
        return rgb[0];
    }
    Y[0] * rgb[0] + Y[1] * rgb[1] + Y[2] * rgb[2]
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn pixels(width: usize, height: usize, data: Vec<[f32; 3]>) -> Bitmap {
        Bitmap {
            file: PathBuf::from("test"),
            raw: true,
            filter: Filter::Bilinear,
            wrap: Wrap::Repeat,
            to_uv: IDENTITY,
            pixels: Arc::new(Pixels { width, height, data }),
        }
    }

    #[test]
    fn bilinear_reads_texel_centres_exactly_and_blends_between() {
        // 2 x 1: left black, right white.
        let b = pixels(2, 1, vec![[0.0; 3], [1.0; 3]]);
        assert_eq!(b.rgb(DVec2::new(0.25, 0.5)), [0.0; 3]);
        assert_eq!(b.rgb(DVec2::new(0.75, 0.5)), [1.0; 3]);
        assert_eq!(b.rgb(DVec2::new(0.5, 0.5)), [0.5; 3]);
        // Repeat: at u = 0 the left texel blends with the right one of the next copy.
        assert_eq!(b.rgb(DVec2::new(0.0, 0.5)), [0.5; 3]);
        let clamp = Bitmap { wrap: Wrap::Clamp, ..b.clone() };
        assert_eq!(clamp.rgb(DVec2::new(0.0, 0.5)), [0.0; 3]);
        assert_eq!(clamp.rgb(DVec2::new(-7.0, 0.5)), [0.0; 3]);
        let nearest = Bitmap { filter: Filter::Nearest, ..b.clone() };
        assert_eq!(nearest.rgb(DVec2::new(0.49, 0.5)), [0.0; 3]);
        assert_eq!(nearest.rgb(DVec2::new(0.51, 0.5)), [1.0; 3]);
        // Non-finite and huge coordinates read a texel, never panic.
        for uv in [DVec2::NAN, DVec2::new(f64::INFINITY, 0.0), DVec2::new(1e300, -1e300)] {
            let c = b.rgb(uv);
            assert!(c.iter().all(|v| (0.0..=1.0).contains(v)), "{uv}: {c:?}");
        }
    }

    #[test]
    fn wrap_modes_index_as_documented() {
        assert_eq!([-1, 0, 3, 4].map(|i| wrapped(i, 4, Wrap::Repeat)), [3, 0, 3, 0]);
        assert_eq!([-1, 0, 3, 4, 8].map(|i| wrapped(i, 4, Wrap::Mirror)), [0, 0, 3, 3, 0]);
        assert_eq!([-1, 0, 3, 4].map(|i| wrapped(i, 4, Wrap::Clamp)), [0, 0, 3, 3]);
    }

    #[test]
    fn checkerboard_squares_follow_mitsuba() {
        let c: Texture = serde_json::from_str(
            r#"{"type": "Checkerboard", "color0": [1, 0, 0], "color1": 0.5, "to_uv": [[2, 0, 0], [0, 2, 0]]}"#,
        )
        .unwrap();
        assert_eq!(c.rgb(DVec2::new(0.1, 0.1)), [1.0, 0.0, 0.0]);
        assert_eq!(c.rgb(DVec2::new(0.3, 0.3)), [1.0, 0.0, 0.0]);
        assert_eq!(c.rgb(DVec2::new(0.3, 0.1)), [0.5; 3]);
        // A red texel's number is the matrix's red luminance, Rec. 709's 0.2126 to 4 decimals.
        let red = c.value(DVec2::new(0.1, 0.1));
        assert!((red - srgb_to_xyz_matrix()[1][0]).abs() < 1e-15, "{red}");
        assert!((red - 0.2126).abs() < 1e-4, "{red}");
        let e = serde_json::from_str::<Texture>(
            r#"{"type": "Checkerboard", "to_uv": [[1e309, 0, 0], [0, 1, 0]]}"#,
        );
        assert!(e.is_err(), "an infinite to_uv is refused");
        let e = serde_json::from_str::<Texture>(r#"{"type": "Checkerboard", "colour0": 1}"#);
        assert!(e.unwrap_err().to_string().contains("unknown field `colour0`"));
    }

    #[test]
    fn bad_files_are_refused_with_the_cause() {
        let e = serde_json::from_str::<Texture>(r#"{"type": "Bitmap", "file": "no/such.png"}"#)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no/such.png"), "{e}");
        let dir = std::env::temp_dir().join(format!("spectrace-texture-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bad = dir.join("bad.png");
        std::fs::write(&bad, b"\x89PNG\r\n\x1a\nnot really").unwrap();
        let json = format!(r#"{{"type": "Bitmap", "file": {:?}}}"#, bad.to_str().unwrap());
        let e = serde_json::from_str::<Texture>(&json).unwrap_err().to_string();
        assert!(e.contains("bad.png"), "{e}");
    }

    #[test]
    fn png_is_srgb_decoded_unless_raw_and_rows_start_at_the_top() {
        let dir = std::env::temp_dir().join(format!("spectrace-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("two.png");
        // 1 x 2: top row 188 (sRGB ~0.5 linear), bottom row 255.
        let img = image::RgbImage::from_fn(1, 2, |_, y| {
            image::Rgb([[188, 188, 188], [255, 0, 0]][y as usize])
        });
        img.save(&file).unwrap();
        let json = |raw: bool| {
            format!(
                r#"{{"type": "Bitmap", "file": {:?}, "filter": "nearest", "raw": {raw}}}"#,
                file.to_str().unwrap()
            )
        };
        let t: Texture = serde_json::from_str(&json(false)).unwrap();
        let top = t.rgb(DVec2::new(0.5, 0.25));
        assert!((top[0] - srgb_decode(188.0 / 255.0)).abs() < 1e-6, "{top:?}");
        assert_eq!(t.rgb(DVec2::new(0.5, 0.75)), [1.0, 0.0, 0.0]);
        let raw: Texture = serde_json::from_str(&json(true)).unwrap();
        assert!((raw.rgb(DVec2::new(0.5, 0.25))[0] - 188.0 / 255.0).abs() < 1e-6);
        assert_eq!(t.range(), (0.0, 1.0));
    }
}
