//! [`ExactSum`]: the film's fixed-point accumulator (64 fractional bits in an `i128`), exact and
//! associative, so any split of the work sums to a bit-identical image.

use serde::{Deserialize, Serialize};
use spectrace_spectrum::Xyz;

/// Fractional bits of the fixed-point sums.
pub(super) const FRAC_BITS: i32 = 64;
/// `2^FRAC_BITS`.
pub(super) const SCALE: f64 = (1u128 << FRAC_BITS) as f64;
/// Largest magnitude of one contribution: `2^62`; sums beyond `2^63` are refused as overflow.
pub(super) const MAX_CONTRIBUTION: f64 = 4_611_686_018_427_387_904.0; // 2^62

/// Bytes of one pixel: three `i128` sums.
pub(super) const PIXEL_BYTES: u64 = std::mem::size_of::<[ExactSum; 3]>() as u64;

/// `x` rounded once to fixed point, or `None` if it is NaN, infinite or larger in magnitude than
/// 2^62.
#[inline]
pub(super) fn to_fixed(x: f64) -> Option<i128> {
    (x.abs() <= MAX_CONTRIBUTION).then(|| round_to_i128(x * SCALE))
}

/// `y.round() as i128` (to nearest, ties away from zero) for finite `|y| <= 2^126`, through
/// 64-bit integer conversions (single instructions) instead of the library's `round` and
/// 128-bit conversion calls that baseline x86-64 needs.
#[inline]
fn round_to_i128(y: f64) -> i128 {
    const TWO_52: f64 = 4_503_599_627_370_496.0;
    const TWO_63: f64 = 9_223_372_036_854_775_808.0;
    let t = y.abs();
    let magnitude = if t < TWO_52 {
        // Truncate, then round the exact remainder up from one half.
        let i = t as i64;
        let rest = t - i as f64;
        i128::from(i + i64::from(rest >= 0.5))
    } else if t < TWO_63 {
        // Already an integer.
        i128::from(t as i64)
    } else {
        t as i128
    };
    if y < 0.0 { -magnitude } else { magnitude }
}

/// A fixed-point value as `f64`, to within a few units in the last place (for the error
/// estimate, which needs no exactness): two 64-bit conversions instead of the slow 128-bit one.
#[inline]
pub(super) fn fixed_to_f64(v: i128) -> f64 {
    let hi = (v >> 64) as i64 as f64;
    let lo = v as u64 as f64;
    hi + lo * (1.0 / SCALE)
}

/// The three components of `xyz` in fixed point, or `None` if any of them is out of range.
#[inline]
pub(super) fn xyz_to_fixed(xyz: Xyz) -> Option<[i128; 3]> {
    Some([to_fixed(xyz.x)?, to_fixed(xyz.y)?, to_fixed(xyz.z)?])
}

/// An exact, order-independent sum of `f64` contributions (fixed point, 64 fractional bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ExactSum(pub(super) i128);

impl ExactSum {
    /// Adds `x`; returns `false` (and adds nothing) if `x` is NaN, infinite or larger in magnitude
    /// than 2^62, or if the sum would overflow.
    #[inline]
    pub fn add(&mut self, x: f64) -> bool {
        let Some(fixed) = to_fixed(x) else { return false };
        match self.0.checked_add(fixed) {
            Some(s) => {
                self.0 = s;
                true
            }
            None => false,
        }
    }

    /// Adds another exact sum; returns `false` on overflow (and leaves `self` unchanged).
    #[inline]
    pub fn merge(&mut self, other: ExactSum) -> bool {
        match self.0.checked_add(other.0) {
            Some(s) => {
                self.0 = s;
                true
            }
            None => false,
        }
    }

    /// The sum as the nearest `f64`.
    pub fn value(self) -> f64 {
        // i128 -> f64 rounds once; the division by a power of two is exact.
        self.0 as f64 / SCALE
    }

    /// The raw fixed-point integer (sum times 2^64).
    pub fn raw(self) -> i128 {
        self.0
    }
}
