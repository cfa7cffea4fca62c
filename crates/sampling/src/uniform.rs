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

/// SplitMix64's increment, the golden-ratio gamma `2^64 / phi`.
pub const GOLDEN_GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64's finaliser (Steele, Lea and Flood 2014): a bijective mix of 64 bits, the one copy
/// that Spectrace's hashes of seeds, streams and bits use.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// SplitMix64's output for the state `x`: [`mix64`] of `x` plus [`GOLDEN_GAMMA`].
#[inline]
pub fn split_mix64(x: u64) -> u64 {
    mix64(x.wrapping_add(GOLDEN_GAMMA))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_mix64_is_the_reference_generator() {
        // SplitMix64 (Steele et al. 2014) from state 0: its published first two outputs.
        assert_eq!(split_mix64(0), 0xE220_A839_7B1D_CDAF);
        assert_eq!(split_mix64(GOLDEN_GAMMA), 0x6E78_9E6A_A1B9_65F4);
        assert_eq!(mix64(0), 0);
    }

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
