//! [`ErrorMeasure`]: what "relative error" means, for the error a render estimates and stops on
//! and for the true error against a reference ([`relative_error`]).
//!
//! Three measures of an image `I` against the converged image `R`:
//! - **`relmse`** (the default): `sqrt(mean over pixels p and linear-sRGB channels c of
//!   (I_pc - R_pc)^2 / (R_pc^2 + eps^2))`, with `eps` 1% of the mean of `R` over the pixels and
//!   channels, so that black pixels do not dominate: the rendering literature's relative MSE,
//!   which asks every part of the picture to be about that noisy.
//! - **`energy`**: `sqrt(sum over pixels and X, Y, Z of (I - R)^2 / sum R^2)`: dominated by the
//!   brightest pixels (a luminaire seen directly can hide a noisy room).
//! - **`mean`**: `sqrt(mean over p, c of (I_pc - R_pc)^2) / mean of R` over linear-sRGB
//!   channels: the RMSE relative to the image's mean level.
//!
//! A render estimates each measure from its own batches ([`crate::Moments::estimate`]). Near
//! the errors users ask for (10%) the `relmse` estimate was within 20% of the truth against a
//! converged reference on four of five shipped scenes measured, and half of it on the fifth,
//! whose dark pixels are lit by rare paths
//! (`cargo test -p spectrace-tests a_render_to_10_percent -- --nocapture`).

use serde::{Deserialize, Serialize};
use spectrace_spectrum::Xyz;

/// `eps` of [`ErrorMeasure::RelMse`] relative to the mean of the reference.
pub const RELMSE_EPSILON: f64 = 0.01;

/// Which relative error a render reports and stops on (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ErrorMeasure {
    /// Per-pixel relative MSE over linear-sRGB channels (the default).
    #[default]
    #[serde(rename = "relmse")]
    RelMse,
    /// Relative RMSE over all pixels and X, Y, Z, weighted by energy.
    #[serde(rename = "energy")]
    Energy,
    /// RMSE over linear-sRGB channels relative to the image's mean.
    #[serde(rename = "mean")]
    Mean,
}

impl ErrorMeasure {
    /// Every measure, in the order of [`ByMeasure`].
    pub const ALL: [ErrorMeasure; 3] = [Self::RelMse, Self::Energy, Self::Mean];

    /// Its name in scene files, on the command line and in the sidecar.
    pub fn name(self) -> &'static str {
        match self {
            Self::RelMse => "relmse",
            Self::Energy => "energy",
            Self::Mean => "mean",
        }
    }

    /// The measure of a name (`"relmse"`, `"energy"`, `"mean"`).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// A value per measure: relmse, energy and mean.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ByMeasure {
    /// [`ErrorMeasure::RelMse`].
    pub relmse: Option<f64>,
    /// [`ErrorMeasure::Energy`].
    pub energy: Option<f64>,
    /// [`ErrorMeasure::Mean`].
    pub mean: Option<f64>,
}

impl ByMeasure {
    /// The value of `measure`.
    pub fn get(&self, measure: ErrorMeasure) -> Option<f64> {
        match measure {
            ErrorMeasure::RelMse => self.relmse,
            ErrorMeasure::Energy => self.energy,
            ErrorMeasure::Mean => self.mean,
        }
    }
}

/// The true relative error of `image` against `reference` (XYZ per pixel, the same layout) in
/// `measure` (see the module docs).
///
/// # Errors
/// A message when the sizes differ, or the reference is black (or, for `relmse` and `mean`,
/// its mean level in linear sRGB is not positive).
pub fn relative_error(
    measure: ErrorMeasure,
    image: &[Xyz],
    reference: &[Xyz],
) -> Result<f64, String> {
    if image.len() != reference.len() {
        return Err(format!(
            "image of {} pixels against a reference of {}",
            image.len(),
            reference.len()
        ));
    }
    if measure == ErrorMeasure::Energy {
        let (mut diff, mut norm) = (0.0, 0.0);
        for (a, r) in image.iter().zip(reference) {
            diff += (a.x - r.x).powi(2) + (a.y - r.y).powi(2) + (a.z - r.z).powi(2);
            norm += r.x * r.x + r.y * r.y + r.z * r.z;
        }
        return if norm > 0.0 {
            Ok((diff / norm).sqrt())
        } else {
            Err("the reference image is black".to_owned())
        };
    }
    let values = 3.0 * reference.len() as f64;
    let level = reference.iter().flat_map(|r| r.to_linear_srgb()).sum::<f64>() / values;
    if !(level > 0.0 && level.is_finite()) {
        return Err(format!("the reference's mean level in linear sRGB is {level}, not positive"));
    }
    let eps2 = (RELMSE_EPSILON * level).powi(2);
    let mut sum = 0.0;
    for (a, r) in image.iter().zip(reference) {
        for (i, r) in a.to_linear_srgb().into_iter().zip(r.to_linear_srgb()) {
            let d2 = (i - r).powi(2);
            sum += if measure == ErrorMeasure::RelMse { d2 / (r * r + eps2) } else { d2 };
        }
    }
    Ok(match measure {
        ErrorMeasure::RelMse => (sum / values).sqrt(),
        _ => (sum / values).sqrt() / level,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    /// The XYZ whose linear sRGB is `(v, v, v)`: the sRGB matrix inverted by Cramer's rule.
    fn grey(v: f64) -> Xyz {
        let cols = [Xyz::new(1.0, 0.0, 0.0), Xyz::new(0.0, 1.0, 0.0), Xyz::new(0.0, 0.0, 1.0)]
            .map(Xyz::to_linear_srgb);
        let det = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
            a[0] * (b[1] * c[2] - b[2] * c[1]) - b[0] * (a[1] * c[2] - a[2] * c[1])
                + c[0] * (a[1] * b[2] - a[2] * b[1])
        };
        let d = det(cols[0], cols[1], cols[2]);
        let rhs = [v, v, v];
        Xyz::new(
            det(rhs, cols[1], cols[2]) / d,
            det(cols[0], rhs, cols[2]) / d,
            det(cols[0], cols[1], rhs) / d,
        )
    }

    #[test]
    fn each_measure_weighs_the_error_as_its_definition_says() {
        // A grey pixel of level 1 and a bright one of level 100, in linear sRGB.
        let reference = [grey(1.0), grey(100.0)];
        // 10% too bright on the dim pixel only.
        let image = [grey(1.1), grey(100.0)];
        let eps = RELMSE_EPSILON * 50.5;
        let relmse = relative_error(ErrorMeasure::RelMse, &image, &reference).unwrap();
        let want = (0.01 / (1.0 + eps * eps) / 2.0).sqrt();
        assert!((relmse - want).abs() < 1e-9 * want, "{relmse} vs {want}");
        assert!(grey(2.0).to_linear_srgb().iter().all(|c| (c - 2.0).abs() < 1e-12));
        // The energy measure hardly sees it.
        let energy = relative_error(ErrorMeasure::Energy, &image, &reference).unwrap();
        assert!(energy < 0.002, "{energy}");
        let mean = relative_error(ErrorMeasure::Mean, &image, &reference).unwrap();
        let want = (0.01 / 2.0f64).sqrt() / 50.5;
        assert!((mean - want).abs() < 1e-9 * want, "{mean} vs {want}");
        // A perfect image has no error; a black or mismatched reference is refused.
        for m in ErrorMeasure::ALL {
            assert!(relative_error(m, &reference, &reference).unwrap() < 1e-12);
            assert!(relative_error(m, &image, &[grey(0.0), grey(0.0)]).is_err());
            assert!(relative_error(m, &image[..1], &reference).is_err());
            assert_eq!(ErrorMeasure::from_name(m.name()), Some(m));
        }
        assert_eq!(ErrorMeasure::from_name("rmse"), None);
        assert_eq!(ErrorMeasure::default(), ErrorMeasure::RelMse);
    }
}
