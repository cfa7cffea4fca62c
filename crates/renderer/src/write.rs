//! The files of a render: which it will write (checked before any work), the image, the EXR,
//! PNG and error image, and the JSON sidecar.

use std::path::{Path, PathBuf};

use spectrace_tracer::RenderOutput;

use crate::{
    ErrorImage, Normalisation, OutputSettings, RenderError, RenderReport, check_no_input_replaced,
    check_output_name, encode_image, prepare_out_dir, write_atomically, write_exr, write_png,
};

/// The files a render will write, checked before any work starts: a valid base name, an output
/// folder that is a folder, and no output that would replace an input.
pub(crate) fn planned_outputs(
    out_dir: &Path,
    name: &str,
    settings: &OutputSettings,
    shard: Option<(u64, u64)>,
    inputs: &[PathBuf],
    sensor_outputs: Vec<PathBuf>,
) -> Result<(), RenderError> {
    check_output_name(name).map_err(|e| RenderError::Options(format!("output name: {e}")))?;
    prepare_out_dir(out_dir).map_err(RenderError::Options)?;
    let outputs = match shard {
        Some(shard) => vec![part_path(out_dir, name, shard)],
        None => {
            let mut v = Vec::new();
            if settings.exr {
                v.push(out_dir.join(format!("{name}.exr")));
            }
            if settings.png {
                v.push(out_dir.join(format!("{name}.png")));
            }
            if settings.error_image.wanted() {
                v.push(out_dir.join(format!("{name}.error.exr")));
            }
            if settings.error_image == ErrorImage::Relative && settings.png {
                v.push(out_dir.join(format!("{name}.error.png")));
            }
            v.push(out_dir.join(format!("{name}.json")));
            v.extend(sensor_outputs);
            v
        }
    };
    check_no_input_replaced(&outputs, inputs).map_err(RenderError::Options)
}

/// The part file of shard `k` of `n`: `NAME.part-K-of-N.bin`.
pub(crate) fn part_path(out_dir: &Path, name: &str, (k, n): (u64, u64)) -> PathBuf {
    out_dir.join(format!("{name}.part-{k}-of-{n}.bin"))
}

/// What [`write_outputs`] wrote.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Written {
    /// The files.
    pub files: Vec<String>,
    /// The EXR's scale exponent (see [`encode_image`]).
    pub exr_scale_log2: i32,
    /// Values beyond the range of 32-bit floats without that scale.
    pub out_of_range_values: u64,
    /// Warnings for the user.
    pub warnings: Vec<String>,
}

/// The final image of a render: XYZ per pixel in film units ([`Normalisation::image`]).
pub fn image(output: &RenderOutput, norm: Normalisation) -> Vec<spectrace_spectrum::Xyz> {
    norm.image(output)
}

/// Writes the EXR and PNG of a finished render (each to a temporary name, then renamed into
/// place); returns what was written.
///
/// # Errors
/// [`RenderError::File`] if a file cannot be written.
pub fn write_outputs(
    dir: &Path,
    name: &str,
    settings: &OutputSettings,
    numerator: Normalisation,
    output: &RenderOutput,
) -> Result<Written, RenderError> {
    let (w, h) = (output.film.width(), output.film.height());
    let image = encode_image(output, numerator);
    let mut written = Written {
        exr_scale_log2: image.scale_log2,
        out_of_range_values: image.out_of_range_values,
        ..Written::default()
    };
    if image.scale_log2 != 0 {
        written.warnings.push(format!(
            "the image lies beyond the range of 32-bit floats ({} values would be infinite or \
             zero): the EXR holds it multiplied by 2^{} (header attribute spectraceScaleLog2, \
             sidecar exr_scale_log2)",
            image.out_of_range_values, image.scale_log2
        ));
    }
    written.warnings.extend(crate::warnings::unsampled_warning(output, numerator));
    let file_error = |path: &Path| {
        let path = path.to_owned();
        move |message| RenderError::File { path, message }
    };
    if settings.exr {
        let path = dir.join(format!("{name}.exr"));
        write_atomically(&path, |p| write_exr(p, w, h, &image.rgb, image.scale_log2))
            .map_err(file_error(&path))?;
        written.files.push(path.display().to_string());
    }
    if settings.png {
        let path = dir.join(format!("{name}.png"));
        write_atomically(&path, |p| {
            write_png(p, w, h, &image.rgb, settings.exposure, image.scale_log2)
        })
        .map_err(file_error(&path))?;
        written.files.push(path.display().to_string());
    }
    if settings.error_image.wanted() {
        match &output.moments {
            Some(moments) => {
                let path = dir.join(format!("{name}.error.exr"));
                // In the image's units and with the image's EXR scale, so the two compare
                // pixel by pixel.
                let factor = numerator.scale(output.beams) * 2f64.powi(image.scale_log2);
                let se = moments.standard_error_rgb(factor);
                let (rgb, scale_log2) = match settings.error_image {
                    ErrorImage::Relative => (relative_error_image(&se, &image.rgb), 0),
                    _ => (to_f32_values(&se), image.scale_log2),
                };
                write_atomically(&path, |p| write_exr(p, w, h, &rgb, scale_log2))
                    .map_err(file_error(&path))?;
                written.files.push(path.display().to_string());
                if settings.error_image == ErrorImage::Relative && settings.png {
                    let path = dir.join(format!("{name}.error.png"));
                    write_atomically(&path, |p| write_error_png(p, w, h, &rgb))
                        .map_err(file_error(&path))?;
                    written.files.push(path.display().to_string());
                }
            }
            None => written.warnings.push(
                "output.error_image: no error image, the render kept no error estimate".to_owned(),
            ),
        }
    }
    Ok(written)
}

/// The relative error PNG's top of scale: pixels with a relative standard error of this or
/// more are yellow.
const ERROR_PNG_TOP: f64 = 0.2;

/// Writes `NAME.error.png`: each pixel's relative standard error (the root mean square over its
/// linear-sRGB channels of `relative`) in false colour, from 0 (dark purple) to
/// [`ERROR_PNG_TOP`] or more (yellow), on the sensor maps' viridis scale.
fn write_error_png(path: &Path, w: u32, h: u32, relative: &[[f32; 3]]) -> Result<(), String> {
    let bytes: Vec<u8> = relative
        .iter()
        .flat_map(|p| {
            let mean_square = p.iter().map(|&c| f64::from(c).powi(2)).sum::<f64>() / 3.0;
            crate::sensor_output::sensor_colour(mean_square.sqrt() / ERROR_PNG_TOP)
        })
        .collect();
    let image = image::RgbImage::from_raw(w, h, bytes).ok_or("image buffer has the wrong size")?;
    image.save_with_format(path, image::ImageFormat::Png).map_err(|e| e.to_string())
}

/// Standard errors as the EXR's 32-bit floats (saturating at the largest).
fn to_f32_values(se: &[[f64; 3]]) -> Vec<[f32; 3]> {
    se.iter().map(|p| p.map(|v| v.min(f64::from(f32::MAX)) as f32)).collect()
}

/// Each pixel's standard error over its value (`rgb`, in the same units), per channel:
/// `se / max(|value|, eps)` with `eps` 1% of the image's mean level over pixels and channels
/// ([`spectrace_tracer::RELMSE_EPSILON`]), so that black pixels do not divide by zero.
fn relative_error_image(se: &[[f64; 3]], rgb: &[[f32; 3]]) -> Vec<[f32; 3]> {
    let values = 3.0 * rgb.len().max(1) as f64;
    let level = rgb.iter().flatten().map(|&v| f64::from(v)).sum::<f64>() / values;
    let eps = (spectrace_tracer::RELMSE_EPSILON * level).max(f64::MIN_POSITIVE);
    se.iter()
        .zip(rgb)
        .map(|(s, v)| std::array::from_fn(|c| (s[c] / f64::from(v[c]).abs().max(eps)) as f32))
        .collect()
}

pub(crate) fn write_sidecar(
    dir: &Path,
    name: &str,
    report: &RenderReport,
) -> Result<(), RenderError> {
    let path = dir.join(format!("{name}.json"));
    let text = serde_json::to_string_pretty(report)
        .map_err(|e| RenderError::File { path: path.clone(), message: e.to_string() })?;
    write_atomically(&path, |p| std::fs::write(p, &text).map_err(|e| e.to_string()))
        .map_err(|message| RenderError::File { path, message })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    #[test]
    fn the_error_png_maps_the_rms_relative_error_onto_the_colour_scale() {
        let dir = std::env::temp_dir().join(format!("spectrace-error-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("e.png");
        // 0, the top of the scale (RMS of 0.2 over the channels), half of it, and beyond.
        let top = ERROR_PNG_TOP as f32;
        let rel = [[0.0; 3], [top; 3], [top / 2.0, top / 2.0, top / 2.0], [0.0, 0.0, 9.0]];
        write_error_png(&path, 4, 1, &rel).unwrap();
        let png = image::open(&path).unwrap().to_rgb8();
        let colour = crate::sensor_output::sensor_colour;
        let want = [colour(0.0), colour(1.0), colour(0.5), colour(1.0)];
        for (x, w) in want.iter().enumerate() {
            assert_eq!(png.get_pixel(x as u32, 0).0, *w, "pixel {x}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
