//! Uniform variates: drawing one from a generator, and clamping one into `[0, 1)`.

use rand::Rng;

use crate::ONE_MINUS_EPSILON;

/// Draws a uniform in `[0, 1)` from any generator: the top 53 bits of one `u64`, scaled by
/// `2^-53`, so every value is a multiple of `2^-53` and `1` is never returned.
#[inline]
pub fn uniform<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Clamps a uniform variate into `[0, 1)`, tolerantly: NaN and negative values become `0`, values
/// `>= 1` become `1 - 2^-53` ([`ONE_MINUS_EPSILON`]); values already in `[0, 1)` are returned
/// unchanged, bit for bit. Never panics.
#[inline]
pub fn clamp_uniform(u: f64) -> f64 {
    if u >= 0.0 { u.min(ONE_MINUS_EPSILON) } else { 0.0 }
}
