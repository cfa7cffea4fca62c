//! Writing images: linear EXR, sRGB PNG with exposure, and partial films for sharded renders.

use std::path::Path;

use serde::{Deserialize, Serialize};
use spectrace_spectrum::{Xyz, srgb_encode};
use spectrace_tracer::{Effects, RenderOutput, RenderPlan};

use crate::OutputSettings;

/// Linear sRGB (Rec. 709 primaries, D65 white) of every pixel, row-major from the top-left.
pub fn linear_srgb(xyz: &[Xyz]) -> Vec<[f32; 3]> {
    xyz.iter()
        .map(|p| {
            let [r, g, b] = p.to_linear_srgb();
            [r as f32, g as f32, b as f32]
        })
        .collect()
}

/// Writes a linear EXR (32-bit float R, G, B; ZIP compression, scan lines in increasing order,
/// written sequentially so the same image always gives the same bytes).
///
/// # Errors
/// Any error of the `exr` crate, as text.
pub fn write_exr(path: &Path, width: u32, height: u32, rgb: &[[f32; 3]]) -> Result<(), String> {
    use exr::prelude::*;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let p = rgb[y * width as usize + x];
        (p[0], p[1], p[2])
    });
    Image::from_encoded_channels(
        (width as usize, height as usize),
        Encoding::SMALL_LOSSLESS,
        channels,
    )
    .write()
    .non_parallel()
    .to_file(path)
    .map_err(|e| e.to_string())
}

/// Writes an 8-bit sRGB PNG of `linear * 2^exposure` (negative values, from out-of-gamut
/// colours, become 0; values above 1 saturate).
///
/// # Errors
/// Any error of the `image` crate, as text.
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    exposure: f64,
) -> Result<(), String> {
    let gain = 2f64.powf(exposure);
    let bytes: Vec<u8> = rgb
        .iter()
        .flat_map(|p| {
            p.map(|c| {
                (srgb_encode(f64::from(c) * gain) * 255.0 + 0.5).floor().clamp(0.0, 255.0) as u8
            })
        })
        .collect();
    let image =
        image::RgbImage::from_raw(width, height, bytes).ok_or("image buffer has the wrong size")?;
    image.save_with_format(path, image::ImageFormat::Png).map_err(|e| e.to_string())
}

/// A shard's result, written by `spectrace render --shard K/N` and read by `spectrace merge`.
/// Lossless: the film's exact fixed-point sums.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartialFilm {
    /// Format version (1).
    pub version: u32,
    /// Fingerprint of the scene (all parts of one image must share it).
    pub scene_fingerprint: u64,
    /// The scene file, for the final image's metadata.
    pub scene_path: String,
    /// The plan (beams, chunk size, seed) every part must share.
    pub plan: RenderPlan,
    /// Total power of the scene's lights (W), for the image's normalisation.
    pub light_power: f64,
    /// The effects decision the parts were rendered with.
    pub effects: Effects,
    /// Output settings of the scene.
    pub output_settings: OutputSettings,
    /// Base name of the output files.
    pub name: String,
    /// The shard's render.
    pub output: RenderOutput,
}

/// Current [`PartialFilm::version`].
pub const PARTIAL_VERSION: u32 = 1;
