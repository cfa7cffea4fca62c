//! Uniform variates: drawing one from a generator, clamping one into `[0, 1)`, and shifting one
//! by a fraction of the unit interval.

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

/// `(u + j / k) mod 1` for `u` clamped into `[0, 1)` ([`clamp_uniform`]) and `j < k`: the `j`-th
/// of `k` uniforms stratified together from one (each uniform on its own, one in each `1 / k`
/// of the interval up to the rounding of `u + j / k` at a stratum's edge). Exact wrap: `x - 1`
/// is exact for `x` in `[1, 2)`, so the result is in `[0, 1)`.
#[inline]
pub fn shifted_uniform(u: f64, j: usize, k: usize) -> f64 {
    let shifted = clamp_uniform(u) + j as f64 / k as f64;
    if shifted >= 1.0 { shifted - 1.0 } else { shifted }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifted_uniforms_wrap_into_the_unit_interval_one_per_stratum() {
        for u in [0.0, 0.1, 0.25, 0.5, 0.999, ONE_MINUS_EPSILON, 1.0, -3.0, f64::NAN] {
            let mut strata: Vec<usize> = (0..4)
                .map(|j| {
                    let v = shifted_uniform(u, j, 4);
                    assert!((0.0..1.0).contains(&v), "{u} {j}: {v}");
                    (v * 4.0) as usize
                })
                .collect();
            strata.sort_unstable();
            // Within an ulp of 1, `u + 1/4` rounds to 1.25: that one lands on its stratum's edge.
            if !(u >= 0.9999) {
                assert_eq!(strata, [0, 1, 2, 3], "{u}");
            }
        }
        assert_eq!(shifted_uniform(0.3, 1, 4), 0.55);
        assert_eq!(shifted_uniform(0.8, 2, 4), 0.8 + 0.5 - 1.0);
    }
}
