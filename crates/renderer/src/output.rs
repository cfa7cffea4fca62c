//! Writing images: linear EXR and sRGB PNG with exposure, never a silent infinity.
//!
//! The EXR holds 32-bit floats, whose range (about 1.2e-38 to 3.4e38) is far narrower than the
//! film's. [`encode_image`] therefore checks the image's range first: an image that fits is
//! written as it is, bit for bit the film's values; one that does not (a light of 1e43 W, or of
//! 1e-45 W) is written multiplied by a power of two, `2^exr_scale_log2`, chosen so its largest
//! value is near 1. The exponent is recorded in the EXR header (`spectraceScaleLog2`) and in the
//! sidecar, a warning says so, and the sidecar counts the values that would have overflowed to
//! infinity or underflowed to zero without it. The PNG always shows the true values.

use std::path::Path;

use spectrace_spectrum::srgb_encode;
use spectrace_tracer::RenderOutput;

use crate::Normalisation;

/// Writes a linear EXR (32-bit float R, G, B; ZIP compression, scan lines in increasing order,
/// written sequentially so the same image always gives the same bytes) of values stored
/// multiplied by `2^scale_log2` (0 for an image that fits f32, see [`encode_image`]); a non-zero
/// exponent is recorded in the header attribute `spectraceScaleLog2`.
///
/// # Errors
/// Any error of the `exr` crate, as text.
pub fn write_exr(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    scale_log2: i32,
) -> Result<(), String> {
    use exr::prelude::*;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let p = rgb[y * width as usize + x];
        (p[0], p[1], p[2])
    });
    let mut image = Image::from_encoded_channels(
        (width as usize, height as usize),
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    if scale_log2 != 0 {
        image
            .layer_data
            .attributes
            .other
            .insert(Text::from("spectraceScaleLog2"), AttributeValue::I32(scale_log2));
    }
    image.write().non_parallel().to_file(path).map_err(|e| e.to_string())
}

/// Writes an 8-bit sRGB PNG of the true values times `2^exposure` for values stored multiplied by
/// `2^scale_log2` (as [`write_exr`]); negative values, from out-of-gamut colours, become 0;
/// values above 1 saturate.
///
/// # Errors
/// Any error of the `image` crate, as text.
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    exposure: f64,
    scale_log2: i32,
) -> Result<(), String> {
    let gain = 2f64.powf(exposure);
    let shift = exposure - f64::from(scale_log2);
    let display = |c: f32| -> f64 {
        let c = f64::from(c);
        if scale_log2 == 0 {
            c * gain
        } else if c > 0.0 {
            // The true value may lie beyond f64: work in log2; anything that large saturates.
            (c.log2() + shift).min(1000.0).exp2()
        } else {
            0.0
        }
    };
    let bytes: Vec<u8> = rgb
        .iter()
        .flat_map(|p| {
            p.map(|c| (srgb_encode(display(c)) * 255.0 + 0.5).floor().clamp(0.0, 255.0) as u8)
        })
        .collect();
    let image =
        image::RgbImage::from_raw(width, height, bytes).ok_or("image buffer has the wrong size")?;
    image.save_with_format(path, image::ImageFormat::Png).map_err(|e| e.to_string())
}

/// An image ready for the EXR: linear sRGB in 32-bit floats, possibly scaled to fit their range.
#[derive(Debug, Clone, PartialEq)]
pub struct EncodedImage {
    /// Linear sRGB per pixel, row-major, multiplied by `2^scale_log2`.
    pub rgb: Vec<[f32; 3]>,
    /// The exponent of the power of two the values were multiplied by (0 when the image fits).
    pub scale_log2: i32,
    /// Channel values that would have overflowed to infinity, or underflowed from a non-zero
    /// value to zero, in 32-bit floats without the scale.
    pub out_of_range_values: u64,
}

/// Bytes per pixel that writing an image needs beside the film: linear sRGB in f64 (made in place
/// of the XYZ) and its f32 copy for the EXR.
pub const OUTPUT_BYTES_PER_PIXEL: u64 = 24 + 12;

/// Largest magnitude written unscaled: half of `f32::MAX`, so rounding to f32 cannot overflow.
const F32_SAFE_MAX: f64 = 1.7e38;
/// f32's smallest normal number.
const F32_SAFE_MIN: f64 = 1.1754943508222875e-38;
/// An image whose largest value is below this (2^-100) is scaled up.
const DIM_LIMIT: f64 = 7.888609052210118e-31;

/// `x * 2^e`, exact unless the result over- or underflows (`ldexp`).
fn ldexp(mut x: f64, mut e: i64) -> f64 {
    while e > 1000 {
        x *= 2f64.powi(1000);
        e -= 1000;
    }
    while e < -1000 {
        x *= 2f64.powi(-1000);
        e += 1000;
    }
    x * 2f64.powi(e as i32)
}

/// The binary exponent of a positive finite `x` (`x = m 2^e`, `m` in `[1, 2)`), exactly, read
/// from its bits (subnormals included).
fn exponent(x: f64) -> i64 {
    let biased = ((x.to_bits() >> 52) & 0x7ff) as i64;
    if biased == 0 { exponent(x * 2f64.powi(64)) - 64 } else { biased - 1023 }
}

/// The image of a finished render (the film times [`Normalisation::scale`] of the work items
/// done), as the EXR stores it; see the module docs for the scaling of images beyond the range of
/// 32-bit floats.
pub fn encode_image(output: &RenderOutput, norm: Normalisation) -> EncodedImage {
    let light_power = norm.light_power;
    // `into_iter().map().collect()` reuses the XYZ allocation for the RGB (same layout): the
    // conversion needs 24 bytes per pixel, plus 12 for the f32 copy.
    let exact = norm.image(output);
    let rgb: Vec<[f64; 3]> = exact.into_iter().map(|p| p.to_linear_srgb()).collect();
    let largest =
        rgb.iter().flatten().try_fold(0.0f64, |m, &c| c.is_finite().then(|| m.max(c.abs())));
    // An image fits if nothing overflows and it is not so dim that 32-bit floats lose its
    // precision; single dim pixels of a normal image round to f32 as any renderer's would.
    let fits = largest.is_some_and(|m| m <= F32_SAFE_MAX && (m == 0.0 || m >= DIM_LIMIT));
    if fits {
        return EncodedImage { rgb: to_f32(&rgb), scale_log2: 0, out_of_range_values: 0 };
    }
    drop(rgb);
    // Recompute without overflow: with the power's mantissa, then powers of two.
    let power_exp = if light_power > 0.0 { exponent(light_power) } else { 0 };
    let mantissa = Normalisation { light_power: ldexp(light_power, -power_exp), ..norm };
    let rgb: Vec<[f64; 3]> =
        mantissa.image(output).into_iter().map(|p| p.to_linear_srgb()).collect();
    let largest = rgb.iter().flatten().fold(0.0f64, |m, &c| m.max(c.abs()));
    if !(largest > 0.0 && largest.is_finite()) {
        return EncodedImage { rgb: to_f32(&rgb), scale_log2: 0, out_of_range_values: 0 };
    }
    // The true image is `rgb * 2^power_exp`; store it times `2^scale` with the largest value in
    // [1, 2).
    let true_exp = exponent(largest) + power_exp;
    let scale = (-true_exp).clamp(i64::from(i32::MIN / 2), i64::from(i32::MAX / 2));
    let out_of_range_values = rgb
        .iter()
        .flatten()
        .filter(|&&c| {
            let a = c.abs();
            a > 0.0 && {
                let e = a.log2() + power_exp as f64;
                e > F32_SAFE_MAX.log2() || e < F32_SAFE_MIN.log2() - 23.0
            }
        })
        .count() as u64;
    let stored = rgb.iter().map(|p| p.map(|c| ldexp(c, power_exp + scale) as f32)).collect();
    EncodedImage { rgb: stored, scale_log2: scale as i32, out_of_range_values }
}

fn to_f32(rgb: &[[f64; 3]]) -> Vec<[f32; 3]> {
    rgb.iter().map(|p| p.map(|c| c as f32)).collect()
}
