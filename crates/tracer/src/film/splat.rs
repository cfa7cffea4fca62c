//! [`Splat`]: where estimators put their contributions, and [`spectral_xyz`], the one place
//! spectral samples become the film's CIE XYZ.

use std::sync::LazyLock;

use spectrace_spectrum::{CIE_Y_INTEGRAL, Xyz, cmf};

#[cfg(doc)]
use super::{Film, FilmWriter};

/// Where contributions go: a [`Film`] directly, or a [`FilmWriter`] that buffers them for a
/// film shared between threads. The light tracer ([`crate::trace_chunk`]) writes through it.
pub trait Splat {
    /// Adds an XYZ contribution to pixel `(x, y)` (0-based, from the top-left); returns `false`
    /// if the pixel is outside the film or a component is NaN, infinite or larger than 2^62
    /// (films and writers then count a rejection and add nothing).
    fn splat(&mut self, x: u32, y: u32, xyz: Xyz) -> bool;

    /// Adds an XYZ contribution normalised per *pass* rather than per pixel sample to pixel
    /// `(x, y)`: a light path splatted to the camera, or a point light seen directly, whose
    /// estimates count the passes, not the samples of the pixel they land in. A [`Film`] with a
    /// pass layer keeps them apart (so that a pass cut short keeps the image exact); everything
    /// else, by default, adds them as [`splat`](Self::splat) does.
    #[inline]
    fn splat_pass(&mut self, x: u32, y: u32, xyz: Xyz) -> bool {
        self.splat(x, y, xyz)
    }

    /// Adds `[radiant, luminous, luminous^2]` to sensor cell `cell` (numbered over all the
    /// scene's sensors, see [`crate::SensorSet`]); same rejections as `splat`. The default, for
    /// targets without sensors, rejects.
    fn splat_sensor(&mut self, cell: u32, sums: crate::SensorSums) -> bool {
        let _ = (cell, sums);
        false
    }

    /// Adds spectral samples to pixel `(x, y)`: `values[j]` at wavelength `lambdas[j]` (nm),
    /// turned into the film's XYZ by [`spectral_xyz`]. Nothing is added (and `false` returned)
    /// when every value is zero; otherwise as [`splat`](Self::splat).
    #[inline]
    fn splat_spectral(&mut self, x: u32, y: u32, lambdas: &[f64], values: &[f64]) -> bool {
        let xyz = spectral_xyz(lambdas, values);
        if xyz.x == 0.0 && xyz.y == 0.0 && xyz.z == 0.0 {
            return false;
        }
        self.splat(x, y, xyz)
    }
}

/// The film's XYZ of spectral samples, the one place colour is made: `sum_j cmf(lambda_j)
/// values[j]` over the integral of `ybar`, so that a spectral radiance of 1 W m^-2 sr^-1 nm^-1
/// at every wavelength gives `Y = 1`. Zero values are skipped (a wavelength outside the
/// matching functions' table contributes nothing).
#[inline]
pub fn spectral_xyz(lambdas: &[f64], values: &[f64]) -> Xyz {
    let inv_y = *INV_Y_INTEGRAL;
    let mut xyz = Xyz::default();
    for (&lambda, &v) in lambdas.iter().zip(values) {
        if v != 0.0 {
            xyz += cmf(lambda) * (v * inv_y);
        }
    }
    xyz
}

/// One over the integral of `ybar` (nm^-1), computed once.
static INV_Y_INTEGRAL: LazyLock<f64> = LazyLock::new(|| 1.0 / *CIE_Y_INTEGRAL);
