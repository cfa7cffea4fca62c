//! [`RgbTable`]: Jakob and Hanika's coefficient table, for the many colours of a texture.
//!
//! [`SigmoidSpectrum::fit`] solves one colour exactly; a bitmap texture has up to millions of
//! texel colours, filtered between texels at every hit, so textures look their spectra up in a
//! table instead, as Mitsuba 3 and pbrt-v4 do. The table is generated here by the project's own
//! solver as a process needs it, never shipped as data: each column of entries along `z` is
//! fitted the first time a lookup touches it (about a millisecond), so a scene pays for the
//! colours it has (all 12,288 columns take about 5 s on one core).
//!
//! # Layout
//! A colour `(r, g, b)` with largest component `c[i]` is placed by `i` (which of three tables),
//! `z = c[i]` and the two other components over it, `x = c[i+1] / z`, `y = c[i+2] / z` (indices
//! mod 3). `x` and `y` are sampled evenly on `[0, 1]` at [`RgbTable::RESOLUTION`] points; `z` at
//! `smoothstep(smoothstep(k / (n - 1)))`, dense near black and white where the coefficients change
//! fastest. A lookup interpolates the three coefficients trilinearly.
//!
//! # Generation
//! For each `(i, x, y)` the solver fits the entry at `k = n / 5` from mid grey (the continuation
//! of [`SigmoidSpectrum::fit`]), then walks up and down `z`, each entry starting from its
//! neighbour's coefficients. Entries on the gamut's faces (`z = 0`, a component 0) need infinite
//! coefficients and keep the solver's best finite ones; their colours are still within 1e-3.

use std::sync::{LazyLock, OnceLock};

use crate::rgb::{COARSE, FINE, SigmoidSpectrum, newton_steps};

/// Jakob and Hanika's table of sigmoid coefficients over the sRGB cube (see the module's essay).
#[derive(Debug)]
pub struct RgbTable {
    /// The `z` sample positions, increasing from 0 to 1.
    scale: Vec<f64>,
    /// Coefficients along `z` for each `(i, y, x)`, indexed `[i][y][x]` flattened: each column
    /// fitted the first time a lookup needs it.
    columns: Vec<OnceLock<Box<[[f64; 3]]>>>,
}

/// `a`, fitted on the coarse quadrature, refined on the fine one (one or two Newton steps away).
fn polish(mut a: [f64; 3], target: [f64; 3]) -> [f64; 3] {
    newton_steps(&mut a, target, &FINE, 8);
    a
}

/// `3 t^2 - 2 t^3`.
fn smoothstep(t: f64) -> f64 {
    t * t * (3.0 - 2.0 * t)
}

impl RgbTable {
    /// Points per axis.
    pub const RESOLUTION: usize = 64;

    /// The process's table. Its columns are fitted as lookups need them (a column of 64
    /// entries in about a millisecond), so a scene pays only for the colours it has.
    pub fn get() -> &'static RgbTable {
        static TABLE: LazyLock<RgbTable> = LazyLock::new(RgbTable::new);
        &TABLE
    }

    fn new() -> Self {
        let n = Self::RESOLUTION;
        let scale = (0..n).map(|k| smoothstep(smoothstep(k as f64 / (n - 1) as f64))).collect();
        Self { scale, columns: (0..3 * n * n).map(|_| OnceLock::new()).collect() }
    }

    /// The colour of entry `(i, z, y, x)`.
    fn colour(&self, i: usize, z: usize, y: usize, x: usize) -> [f64; 3] {
        let step = 1.0 / (Self::RESOLUTION - 1) as f64;
        let zv = self.scale[z];
        let mut rgb = [0.0; 3];
        rgb[i] = zv;
        rgb[(i + 1) % 3] = x as f64 * step * zv;
        rgb[(i + 2) % 3] = y as f64 * step * zv;
        rgb
    }

    /// The coefficients of column `(i, y, x)` along `z`, fitted on first use.
    fn column(&self, i: usize, y: usize, x: usize) -> &[[f64; 3]] {
        let n = Self::RESOLUTION;
        self.columns[(i * n + y) * n + x].get_or_init(|| self.walk(i, y, x))
    }

    /// Fits entries `(i, *, y, x)` along `z`, from `n / 5` outwards, each from its neighbour.
    fn walk(&self, i: usize, y: usize, x: usize) -> Box<[[f64; 3]]> {
        let n = Self::RESOLUTION;
        let mut out = vec![[0.0; 3]; n];
        let start = n / 5;
        let first = SigmoidSpectrum::continuation(self.colour(i, start, y, x), &COARSE, 8);
        let face = x == 0 || y == 0;
        let target = self.colour(i, start, y, x);
        out[start] = if face { polish(first, target) } else { first };
        for range in [(start + 1..n).collect::<Vec<_>>(), (0..start).rev().collect()] {
            let mut a = first;
            for z in range {
                let target = self.colour(i, z, y, x);
                newton_steps(&mut a, target, &COARSE, 8);
                let face = x == 0 || y == 0 || z == 0;
                out[z] = if face { polish(a, target) } else { a };
            }
        }
        out.into_boxed_slice()
    }

    /// The smooth reflectance of the linear-sRGB colour `rgb` (components clamped to `[0, 1]`,
    /// NaN read as 0), by trilinear interpolation of the coefficients.
    pub fn spectrum(&self, rgb: [f64; 3]) -> SigmoidSpectrum {
        let rgb = rgb.map(|v| if v >= 0.0 { v.min(1.0) } else { 0.0 });
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            return SigmoidSpectrum::constant(rgb[0]);
        }
        let i = if rgb[0] >= rgb[1] && rgb[0] >= rgb[2] {
            0
        } else if rgb[1] >= rgb[2] {
            1
        } else {
            2
        };
        let z = rgb[i];
        let n = Self::RESOLUTION;
        let cell = |v: f64| {
            let p = v * (n - 1) as f64;
            let k = spectrace_sampling::cell_index(p, n - 2);
            (k, p - k as f64)
        };
        let (x0, fx) = cell(rgb[(i + 1) % 3] / z);
        let (y0, fy) = cell(rgb[(i + 2) % 3] / z);
        let z0 = self.scale.partition_point(|&s| s <= z).saturating_sub(1).min(n - 2);
        let fz = ((z - self.scale[z0]) / (self.scale[z0 + 1] - self.scale[z0])).clamp(0.0, 1.0);
        let mut c = [0.0; 3];
        for (dy, wy) in [(0, 1.0 - fy), (1, fy)] {
            for (dx, wx) in [(0, 1.0 - fx), (1, fx)] {
                let column = self.column(i, y0 + dy, x0 + dx);
                for (dz, wz) in [(0, 1.0 - fz), (1, fz)] {
                    let (e, w) = (column[z0 + dz], wz * wy * wx);
                    for k in 0..3 {
                        c[k] += w * e[k];
                    }
                }
            }
        }
        SigmoidSpectrum::from_coefficients(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rgb::srgb_under_d65;

    /// The criterion for textures: RGB -> spectrum -> RGB under D65 within 1e-3 over the
    /// sRGB gamut, here for colours between the table's points (an 11^3 grid off the table's
    /// lattice, corners and faces included).
    #[test]
    fn table_round_trip_over_the_gamut_is_within_1e_3() {
        let table = RgbTable::get();
        let mut worst = (0.0f64, [0.0; 3]);
        for r in 0..=10 {
            for g in 0..=10 {
                for b in 0..=10 {
                    let rgb = [r, g, b].map(|v| f64::from(v) / 10.0);
                    let s = table.spectrum(rgb);
                    let back = srgb_under_d65(&|l| s.value(l));
                    let e = (0..3).map(|c| (back[c] - rgb[c]).abs()).fold(0.0, f64::max);
                    if e > worst.0 {
                        worst = (e, rgb);
                    }
                }
            }
        }
        assert!(worst.0 < 1e-3, "worst round trip {worst:?}");
    }

    #[test]
    fn table_spectra_are_reflectances_and_bad_input_is_clamped() {
        let table = RgbTable::get();
        for rgb in [[0.9, 0.1, 0.0], [0.0, 0.0, 1e-9], [2.0, f64::NAN, -1.0], [0.3, 0.6, 0.2]] {
            let s = table.spectrum(rgb);
            for l in [300.0, 360.0, 550.0, 830.0, 900.0] {
                let v = s.value(l);
                assert!((0.0..=1.0).contains(&v), "{rgb:?} at {l}: {v}");
            }
        }
        assert_eq!(table.spectrum([2.0, 2.0, 2.0]).value(500.0), 1.0);
    }
}
