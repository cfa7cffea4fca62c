//! [`sin_cos_turn`]: the sine and cosine of an angle given as a fraction of a turn, the form in
//! which every azimuth of a warp arrives (`2 pi u` for a uniform `u`).
//!
//! The warps used to compute `(2 pi u).sin_cos()`: a call into the C library, whose argument
//! reduction for angles up to `2 pi` costs more than the polynomial, and whose argument
//! `2 pi u` is already rounded (up to 4.4e-16 off near a full turn). A fraction of a turn
//! reduces exactly instead: `4 u` and its integer part are exact, so the quadrant and the place
//! in it carry no rounding, and the place is folded to an angle of at most `pi / 4` from the
//! nearer end of the quadrant, where two short Taylor polynomials are accurate to about an ulp.
//! In a wall-time profile (`perf record`, 2 threads) the C library's `sincos` was 4-5% of a
//! path-traced Cornell box (its diffuse bounces) and of a light-traced spot (its beams).

use std::f64::consts::FRAC_PI_2;

/// `(sin, cos)` of the angle `2 pi turn`, for `turn` in `[0, 1)` (the warps' uniforms); within
/// 2 ulps of the exact values (tested against the C library on the same reduced angle), and
/// `sin^2 + cos^2` within a few ulps of 1. Negative turns down to `-1/8` and turns from 1 up are
/// still right (the quadrant repeats); NaN gives NaN.
#[inline]
pub fn sin_cos_turn(turn: f64) -> (f64, f64) {
    let x = 4.0 * turn;
    // Truncation is the floor for x >= 0 (a saturating conversion: no libm `floor` call on
    // baseline x86-64); `x - q` is then exact.
    let q = x as u32;
    let g = x - f64::from(q);
    let (s, c) = if g <= 0.5 {
        sin_cos_eighth(g * FRAC_PI_2)
    } else {
        // The far half of the quadrant from its other end: sin(pi/2 - a) = cos(a).
        let (s, c) = sin_cos_eighth((1.0 - g) * FRAC_PI_2);
        (c, s)
    };
    match q & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// `(sin, cos)` of `a` with `|a| <= pi / 4`: Taylor polynomials through `a^17` and `a^16`, whose
/// first omitted terms are below `1e-19` and `3e-18` there, as `a + a z S(z)` and `1 + z C(z)`
/// with `z = a^2` (the leading term added last, exactly).
#[inline(always)]
fn sin_cos_eighth(a: f64) -> (f64, f64) {
    let z = a * a;
    (a + a * (z * horner(z, &SIN_TAIL)), 1.0 + z * horner(z, &COS_TAIL))
}

/// The sine's Taylor coefficients after the first, `(-1)^k / (2k + 1)!` for `k = 1..=8`.
const SIN_TAIL: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5_040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];

/// The cosine's Taylor coefficients after the first, `(-1)^k / (2k)!` for `k = 1..=8`.
const COS_TAIL: [f64; 8] = [
    -0.5,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
];

/// `c[0] + z c[1] + z^2 c[2] + ...` by Horner's rule.
#[inline(always)]
fn horner(z: f64, c: &[f64]) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * z + k)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::TAU;

    use proptest::prelude::*;

    use super::*;

    /// Distance in ulps of `got` from `want` (at `want`'s scale, floored at the ulp of 2^-60 so
    /// values near 0 compare absolutely).
    fn ulps(got: f64, want: f64) -> f64 {
        let scale = want.abs().max(2f64.powi(-60));
        (got - want).abs() / (scale * f64::EPSILON)
    }

    #[test]
    fn the_quadrants_and_their_ends_are_exact() {
        assert_eq!(sin_cos_turn(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_turn(0.25), (1.0, -0.0));
        assert_eq!(sin_cos_turn(0.5), (-0.0, -1.0));
        assert_eq!(sin_cos_turn(0.75), (-1.0, 0.0));
        assert_eq!(sin_cos_turn(1.0), (0.0, 1.0));
        let (s, c) = sin_cos_turn(0.125);
        assert!(ulps(s, 0.5f64.sqrt()) <= 1.0 && ulps(c, 0.5f64.sqrt()) <= 1.0, "{s} {c}");
        let (s, c) = sin_cos_turn(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
    }

    #[test]
    fn tiny_turns_keep_their_relative_precision() {
        for t in [1e-300, 1e-20, 1e-10, 1e-5] {
            let (s, c) = sin_cos_turn(t);
            assert!(ulps(s, (TAU * t).sin()) <= 2.0, "{t}: {s}");
            assert!(ulps(c, (TAU * t).cos()) <= 1.0, "{t}: {c}");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 20_000, ..ProptestConfig::default() })]

        #[test]
        fn within_two_ulps_of_the_c_library_on_the_same_reduced_angle(t in 0.0f64..1.0) {
            // The reference: the C library's sine and cosine of the same folded angle, rotated
            // to the quadrant exactly as `sin_cos_turn` does.
            let x = 4.0 * t;
            let q = x.floor();
            let g = x - q;
            let (a, swap) = if g <= 0.5 { (g * FRAC_PI_2, false) } else { ((1.0 - g) * FRAC_PI_2, true) };
            let (s0, c0) = if swap { (a.cos(), a.sin()) } else { (a.sin(), a.cos()) };
            let want = match q as u32 & 3 { 0 => (s0, c0), 1 => (c0, -s0), 2 => (-s0, -c0), _ => (-c0, s0) };
            let got = sin_cos_turn(t);
            prop_assert!(ulps(got.0, want.0) <= 2.0 && ulps(got.1, want.1) <= 2.0, "{}: {:?} vs {:?}", t, got, want);
            // And the angle itself, against the library's (whose argument 2 pi t is rounded).
            let (s, c) = (TAU * t).sin_cos();
            prop_assert!((got.0 - s).abs() <= 1e-15 && (got.1 - c).abs() <= 1e-15);
            prop_assert!((got.0 * got.0 + got.1 * got.1 - 1.0).abs() <= 4.0 * f64::EPSILON);
        }
    }
}
