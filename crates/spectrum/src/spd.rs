//! The [`SpectralPowerDistribution`] trait and the quadrature it uses by default.

use std::fmt::Debug;

/// A spectral power distribution (seed 2.1.1): how a light's power is spread over wavelength,
/// normalised to integral 1 over [`range`](Self::range), and sampled by its own shape.
///
/// Wavelengths are in nm; [`value`](Self::value) is in nm^-1, so a light of power `P` watts emits
/// `P * value(lambda)` W/nm. Samplers take an explicit uniform `u` in `[0, 1)`, so stratified and
/// low-discrepancy sequences can drive them and results are reproducible.
///
/// The trait is typetag-serialisable: a scene file names any SPD by its type,
/// `{"type": "Blackbody", "kelvin": 6500}`, and a third-party crate can add its own SPD type by
/// implementing the trait with `#[typetag::serde]`.
///
/// Delta lines (see [`crate::Monochromatic`]) have no density: their `value` is 0 everywhere and
/// they contribute through [`integrate`](Self::integrate) and [`is_delta`](Self::is_delta).
#[typetag::serde(tag = "type")]
pub trait SpectralPowerDistribution: Send + Sync + Debug {
    /// Draws a wavelength (nm) with probability density [`value`](Self::value), from a uniform `u`
    /// in `[0, 1)`. The result lies in [`range`](Self::range).
    fn sample_lambda(&self, u: f64) -> f64;

    /// The normalised spectral density at `lambda` (nm^-1); 0 outside the range. Finite for every
    /// input (NaN gives 0).
    fn value(&self, lambda: f64) -> f64;

    /// The wavelength interval `(min, max)` in nm outside which the SPD is zero.
    fn range(&self) -> (f64, f64);

    /// `integral of value(lambda) * f(lambda) d lambda`, delta lines included. The default uses
    /// 4-point Gauss-Legendre quadrature on panels split at every integer nm (where tabulated CIE
    /// data has its kinks) and at [`breakpoints`](Self::breakpoints).
    fn integrate(&self, f: &dyn Fn(f64) -> f64) -> f64 {
        let (min, max) = self.range();
        integrate_panels(&|l| self.value(l) * f(l), min, max, &self.breakpoints())
    }

    /// Wavelengths where the SPD has kinks or narrow features, for quadrature (default: none).
    fn breakpoints(&self) -> Vec<f64> {
        Vec::new()
    }

    /// `true` if the SPD consists only of delta lines (no density anywhere).
    fn is_delta(&self) -> bool {
        false
    }

    /// Experiment hook (the accuracy report's "piecewise constant SPD" knob): the same table as
    /// bins of constant value, each bin centred on one of the table's nodes with that node's
    /// value (the seed's "choppy" generator instead of linear interpolation). `None`, the
    /// default, when the SPD has no table to re-bin (formulas, lines, bins already), so SPD
    /// types from other crates need not implement it.
    fn piecewise_constant(&self) -> Option<Box<dyn SpectralPowerDistribution>> {
        None
    }
}

/// Nodes and weights of 4-point Gauss-Legendre quadrature on `[-1, 1]` (exact to degree 7).
const GL4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_85),
    (-0.339_981_043_584_856_26, 0.652_145_154_862_546_2),
    (0.339_981_043_584_856_26, 0.652_145_154_862_546_2),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_85),
];

/// Integrates `f` over `[a, b]` with 4-point Gauss-Legendre.
pub(crate) fn gauss_legendre(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let (mid, half) = ((a + b) / 2.0, (b - a) / 2.0);
    half * GL4.iter().map(|&(x, w)| w * f(mid + half * x)).sum::<f64>()
}

/// Most panels of one nm [`integrate_panels`] makes; a wider range is split into this many equal
/// panels instead (8 MiB of points), so that a spectrum over 1e300 nm costs bounded memory and
/// time instead of one panel per nm.
pub const MAX_NM_PANELS: usize = 1 << 20;

/// Integrates `f` over `[min, max]` on panels split at every integer nm (or, over more than
/// [`MAX_NM_PANELS`] nm, at that many equal steps) and at `extra` points.
pub fn integrate_panels(f: &dyn Fn(f64) -> f64, min: f64, max: f64, extra: &[f64]) -> f64 {
    if !(min < max) {
        return 0.0;
    }
    let mut points: Vec<f64> = extra.iter().copied().filter(|&x| x > min && x < max).collect();
    let first = min.floor() + 1.0;
    let span = (max.ceil() - first).max(0.0);
    if span <= MAX_NM_PANELS as f64 {
        let count = span as usize;
        points.extend((0..count).map(|k| first + k as f64).filter(|&x| x > min && x < max));
    } else {
        // Steps of max/n - min/n, which stay finite where max - min would overflow.
        let n = MAX_NM_PANELS as f64;
        let step = max / n - min / n;
        points.extend(
            (1..MAX_NM_PANELS).map(|k| min + k as f64 * step).filter(|&x| x > min && x < max),
        );
    }
    points.push(min);
    points.push(max);
    points.sort_by(f64::total_cmp);
    points.dedup();
    // Sum panel by panel with compensation: hundreds of panels of very different magnitude.
    let (mut sum, mut c) = (0.0_f64, 0.0_f64);
    for p in points.windows(2) {
        let v = gauss_legendre(f, p[0], p[1]);
        let t = sum + v;
        c += if sum.abs() >= v.abs() { (sum - t) + v } else { (v - t) + sum };
        sum = t;
    }
    sum + c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_is_exact_for_degree_seven() {
        let v = gauss_legendre(&|x: f64| x.powi(7) + 3.0 * x.powi(6) - x, 0.0, 2.0);
        let exact = 2f64.powi(8) / 8.0 + 3.0 * 2f64.powi(7) / 7.0 - 2.0;
        assert!((v - exact).abs() < 1e-12, "{v} vs {exact}");
    }

    #[test]
    fn a_huge_range_is_integrated_in_bounded_panels() {
        // One panel per nm would be 1e300 panels: bounded instead, and still right for a
        // constant and for a function that lives in the first nanometres.
        let v = integrate_panels(&|_| 1.0, 490.0, 1e300, &[]);
        assert!((v / 1e300 - 1.0).abs() < 1e-12, "{v}");
        let w = integrate_panels(&|_| 2.0, -1e300, 1e300, &[]);
        assert!((w / 4e300 - 1.0).abs() < 1e-12, "{w}");
        let narrow = integrate_panels(&|x| if x < 500.0 { 1.0 } else { 0.0 }, 490.0, 1e9, &[500.0]);
        assert!((narrow - 10.0).abs() < 1e-9, "{narrow}");
    }

    #[test]
    fn panels_cover_the_range_exactly_once() {
        let v = integrate_panels(&|_| 1.0, 360.5, 829.25, &[400.0, 400.0, 500.1, 10.0]);
        assert!((v - (829.25 - 360.5)).abs() < 1e-10);
    }
}
