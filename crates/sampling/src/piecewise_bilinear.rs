//! [`PiecewiseBilinear`]: a 2-D density that is bilinear in every cell of a rectilinear grid,
//! sampled exactly by inverting its marginal and conditional CDFs.
//!
//! # Why bilinear densities invert exactly
//! With node values `f[i][j]` at `(xs[i], ys[j])` and bilinear interpolation in each cell, the
//! marginal density of `x`, `M(x) = integral of f(x, y) dy`, is *linear* in `x` on every column of
//! cells (integrating a bilinear function over `y` leaves a linear one), with node values
//! `M_i = sum_j (f[i][j] + f[i][j+1]) / 2 (ys[j+1] - ys[j])`: a [`PiecewiseLinear`] distribution,
//! sampled exactly. Given `x` at fraction `t` of column `i`, the conditional density of `y` is the
//! blend `(1 - t) f[i][.] + t f[i+1][.]`, piecewise linear in `y`; its segment masses are the same
//! blend of the two rows' trapezoid masses, so the segment is found by bisection on the blended
//! prefix sums (no table built per sample) and the position inside it by the cancellation-free
//! linear inversion of [`PiecewiseLinear`]. Both steps are monotone in their uniforms.
//!
//! Lights use it for measured luminaires, whose candela tables are densities over
//! `(C-plane angle, cos gamma)` (see `spectrace-lights`).

use crate::piecewise_linear::invert_linear_segment;
use crate::table::{validate_grid, validate_nonnegative};
use crate::{GuideTable, PiecewiseLinear, SamplingError, clamp_uniform};

/// A density on `[xs[0], xs[n-1]] x [ys[0], ys[m-1]]`, bilinear in each grid cell, with exact
/// inverse-CDF sampling ([`sample`](Self::sample)) and its density ([`pdf`](Self::pdf)).
///
/// # Example
/// ```
/// use spectrace_sampling::PiecewiseBilinear;
/// // Density proportional to x on [0, 1] x [0, 2].
/// let d = PiecewiseBilinear::new(&[0.0, 1.0], &[0.0, 2.0], &[0.0, 0.0, 1.0, 1.0]).unwrap();
/// assert_eq!(d.integral(), 1.0);
/// assert_eq!(d.pdf(0.5, 1.0), 0.5);
/// let (x, y) = d.sample([0.25, 0.5]);
/// assert!((x - 0.5).abs() < 1e-15 && (y - 1.0).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseBilinear {
    xs: Vec<f64>,
    ys: Vec<f64>,
    /// Node values, `values[i * m + j]` at `(xs[i], ys[j])`.
    values: Vec<f64>,
    /// Prefix sums of each row's segment masses along `y`: `prefix[i * m + j]` is the mass of
    /// `x = xs[i]`'s density over `[ys[0], ys[j]]`.
    prefix: Vec<f64>,
    /// The marginal of `x`.
    marginal: PiecewiseLinear,
    /// Integral of the whole table.
    integral: f64,
    /// Guides to the cell along `x` and along `y` (candela grids are uneven in `y`).
    guides: [GuideTable; 2],
}

impl PiecewiseBilinear {
    /// A density with the values `values[i * ys.len() + j]` at `(xs[i], ys[j])` (rows of `x`).
    ///
    /// # Errors
    /// [`SamplingError`] naming `"xs"`, `"ys"` or `"values"`: a grid of fewer than 2 points, not
    /// strictly increasing or not finite; values of the wrong count, negative, NaN or infinite;
    /// a table of zero or overflowing total mass.
    pub fn new(xs: &[f64], ys: &[f64], values: &[f64]) -> Result<Self, SamplingError> {
        for (array, grid) in [("xs", xs), ("ys", ys)] {
            if grid.len() < 2 {
                return Err(SamplingError::TooFewPoints { array, len: grid.len() });
            }
            validate_grid(array, grid)?;
        }
        let (n, m) = (xs.len(), ys.len());
        if values.len() != n.saturating_mul(m) {
            return Err(SamplingError::LengthMismatch {
                first: "values",
                first_len: values.len(),
                second: "xs",
                second_len: n,
                expected: "xs.len() * ys.len() values",
            });
        }
        validate_nonnegative("values", values)?;
        let mut prefix = vec![0.0; n * m];
        let mut rows = Vec::with_capacity(n);
        for i in 0..n {
            let row = &values[i * m..(i + 1) * m];
            let mut sum = 0.0;
            for j in 0..m - 1 {
                sum += 0.5 * (row[j] + row[j + 1]) * (ys[j + 1] - ys[j]);
                prefix[i * m + j + 1] = sum;
            }
            if !sum.is_finite() {
                return Err(SamplingError::TotalOverflow { array: "values" });
            }
            rows.push(sum);
        }
        let marginal = PiecewiseLinear::new(xs, &rows).map_err(|e| match e {
            SamplingError::ZeroTotal { .. } => SamplingError::ZeroTotal { array: "values" },
            SamplingError::TotalOverflow { .. } => SamplingError::TotalOverflow { array: "values" },
            SamplingError::DensityOverflow { index, .. } => {
                SamplingError::DensityOverflow { array: "values", index }
            }
            other => other,
        })?;
        let integral = marginal.integral();
        Ok(Self {
            xs: xs.to_vec(),
            ys: ys.to_vec(),
            values: values.to_vec(),
            prefix,
            marginal,
            integral,
            guides: [GuideTable::new(xs), GuideTable::new(ys)],
        })
    }

    /// Maps two uniforms in `[0, 1)` to a point: `x` from `u[0]` through the marginal, `y` from
    /// `u[1]` through the conditional. Out-of-range or NaN uniforms are clamped. The point never
    /// lies where [`pdf`](Self::pdf) is 0 (up to rounding of the blend at a cell edge).
    pub fn sample(&self, u: [f64; 2]) -> (f64, f64) {
        let x = self.marginal.sample(clamp_uniform(u[0]));
        let (i, t) = self.column(x);
        let m = self.ys.len();
        let blend =
            |j: usize| (1.0 - t) * self.prefix[i * m + j] + t * self.prefix[(i + 1) * m + j];
        let total = blend(m - 1);
        if !(total > 0.0) {
            // The marginal never lands on a column of zero mass; rounding aside, take the middle.
            return (x, 0.5 * (self.ys[0] + self.ys[m - 1]));
        }
        let target = clamp_uniform(u[1]) * total;
        // The segment j with blend(j) <= target < blend(j + 1): the first j + 1 above target.
        let mut lo = 0;
        let mut hi = m - 1;
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if blend(mid) <= target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let j = lo;
        let (c0, c1) = (blend(j), blend(j + 1));
        let value =
            |jj: usize| (1.0 - t) * self.values[i * m + jj] + t * self.values[(i + 1) * m + jj];
        let (a, b) = (value(j), value(j + 1));
        let peak = a.max(b);
        let s = if c1 > c0 { ((target - c0) / (c1 - c0)).clamp(0.0, 1.0) } else { 0.5 };
        let tau = if peak > 0.0 { invert_linear_segment(a / peak, b / peak, s) } else { s };
        let y = self.ys[j] + tau * (self.ys[j + 1] - self.ys[j]);
        (x, y.clamp(self.ys[j], self.ys[j + 1]))
    }

    /// The column of cells `i` holding `x` and the fraction `t` in `[0, 1]` across it (`x` is
    /// clamped to the grid).
    fn column(&self, x: f64) -> (usize, f64) {
        let n = self.xs.len();
        let i = self.guides[0].last_at_or_below(&self.xs, x).min(n - 2);
        let t = ((x - self.xs[i]) / (self.xs[i + 1] - self.xs[i])).clamp(0.0, 1.0);
        (i, t)
    }

    /// The unnormalised density (the table's bilinear interpolation) at `(x, y)`; 0 outside.
    pub fn value(&self, x: f64, y: f64) -> f64 {
        let (n, m) = (self.xs.len(), self.ys.len());
        if !(x >= self.xs[0] && x <= self.xs[n - 1] && y >= self.ys[0] && y <= self.ys[m - 1]) {
            return 0.0;
        }
        let (i, t) = self.column(x);
        let j = self.guides[1].last_at_or_below(&self.ys, y).min(m - 2);
        let s = ((y - self.ys[j]) / (self.ys[j + 1] - self.ys[j])).clamp(0.0, 1.0);
        let v = |ii: usize, jj: usize| self.values[ii * m + jj];
        (1.0 - t) * ((1.0 - s) * v(i, j) + s * v(i, j + 1))
            + t * ((1.0 - s) * v(i + 1, j) + s * v(i + 1, j + 1))
    }

    /// The normalised density at `(x, y)` (0 outside the grid).
    pub fn pdf(&self, x: f64, y: f64) -> f64 {
        self.value(x, y) / self.integral
    }

    /// The integral of the unnormalised density over the grid.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The marginal distribution of `x`.
    pub fn marginal(&self) -> &PiecewiseLinear {
        &self.marginal
    }

    /// The grid along `x`.
    pub fn xs(&self) -> &[f64] {
        &self.xs
    }

    /// The grid along `y`.
    pub fn ys(&self) -> &[f64] {
        &self.ys
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::stats::chi_square;
    use rand::SeedableRng;

    fn table() -> PiecewiseBilinear {
        // Irregular grid, a zero row, a zero column segment and a peak.
        let xs = [0.0, 0.3, 1.0, 1.2, 2.0];
        let ys = [-1.0, 0.0, 0.5, 2.0];
        #[rustfmt::skip]
        let values = [
            0.0, 1.0, 2.0, 0.0,
            0.0, 0.0, 0.0, 0.0,
            3.0, 0.5, 0.0, 0.0,
            1.0, 1.0, 1.0, 1.0,
            0.2, 5.0, 0.0, 2.0,
        ];
        PiecewiseBilinear::new(&xs, &ys, &values).unwrap()
    }

    #[test]
    fn the_density_integrates_to_one() {
        let d = table();
        // Midpoint rule on a fine grid (the density is continuous, so it converges).
        let (nx, ny) = (800, 600);
        let (dx, dy) = (2.0 / nx as f64, 3.0 / ny as f64);
        let mut sum = 0.0;
        for a in 0..nx {
            for b in 0..ny {
                sum += d.pdf((a as f64 + 0.5) * dx, -1.0 + (b as f64 + 0.5) * dy) * dx * dy;
            }
        }
        assert!((sum - 1.0).abs() < 1e-4, "{sum}");
        assert_eq!(d.pdf(-0.1, 0.0), 0.0);
        assert_eq!(d.pdf(1.0, 2.5), 0.0);
    }

    #[test]
    fn samples_follow_the_density() {
        let d = table();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let (nx, ny) = (20usize, 15usize);
        let (dx, dy) = (2.0 / nx as f64, 3.0 / ny as f64);
        let n = 400_000u64;
        let mut counts = vec![0u64; nx * ny];
        for _ in 0..n {
            let (x, y) = d.sample([crate::uniform(&mut rng), crate::uniform(&mut rng)]);
            assert!(d.pdf(x, y) > 0.0, "sample ({x}, {y}) where the density is 0");
            let a = ((x / dx) as usize).min(nx - 1);
            let b = (((y + 1.0) / dy) as usize).min(ny - 1);
            counts[a * ny + b] += 1;
        }
        // Expected counts by 8x8 midpoint quadrature per bin.
        let k = 8;
        let expected: Vec<f64> = (0..nx * ny)
            .map(|c| {
                let (a, b) = (c / ny, c % ny);
                let mut s = 0.0;
                for p in 0..k {
                    for q in 0..k {
                        let x = (a as f64 + (p as f64 + 0.5) / k as f64) * dx;
                        let y = -1.0 + (b as f64 + (q as f64 + 0.5) / k as f64) * dy;
                        s += d.pdf(x, y);
                    }
                }
                s * dx * dy / (k * k) as f64 * n as f64
            })
            .collect();
        let result = chi_square(&counts, &expected, 5.0);
        // Quadrature error per bin is far below the counts' standard deviation at this n.
        assert!(result.p_value > 1e-3, "{result:?}");
    }

    #[test]
    fn sampling_is_monotone_in_each_uniform_and_exact_on_known_tables() {
        let d = table();
        let mut last = f64::NEG_INFINITY;
        for k in 0..1000 {
            let (x, _) = d.sample([k as f64 / 1000.0, 0.3]);
            assert!(x >= last);
            last = x;
        }
        let mut last = f64::NEG_INFINITY;
        for k in 0..1000 {
            let (_, y) = d.sample([0.77, k as f64 / 1000.0]);
            assert!(y >= last);
            last = y;
        }
        // A constant density: the uniforms map linearly.
        let flat = PiecewiseBilinear::new(&[0.0, 2.0], &[0.0, 1.0, 4.0], &[1.0; 6]).unwrap();
        let (x, y) = flat.sample([0.25, 0.75]);
        assert!((x - 0.5).abs() < 1e-14 && (y - 3.0).abs() < 1e-14, "{x} {y}");
    }

    #[test]
    fn bad_tables_are_refused_naming_the_array() {
        let e = PiecewiseBilinear::new(&[0.0], &[0.0, 1.0], &[1.0, 1.0]).unwrap_err();
        assert!(e.to_string().contains("xs"), "{e}");
        let e = PiecewiseBilinear::new(&[0.0, 1.0], &[0.0, 0.0], &[1.0; 4]).unwrap_err();
        assert!(e.to_string().contains("ys"), "{e}");
        let e = PiecewiseBilinear::new(&[0.0, 1.0], &[0.0, 1.0], &[1.0; 3]).unwrap_err();
        assert!(e.to_string().contains("values"), "{e}");
        let e =
            PiecewiseBilinear::new(&[0.0, 1.0], &[0.0, 1.0], &[1.0, -1.0, 1.0, 1.0]).unwrap_err();
        assert!(e.to_string().contains("values[1]"), "{e}");
        let e = PiecewiseBilinear::new(&[0.0, 1.0], &[0.0, 1.0], &[0.0; 4]).unwrap_err();
        assert!(e.to_string().contains("values"), "{e}");
        let e = PiecewiseBilinear::new(&[0.0, 1.0], &[0.0, 1.0], &[f64::NAN, 0.0, 0.0, 1.0])
            .unwrap_err();
        assert!(e.to_string().contains("values[0]"), "{e}");
    }
}
