//! [`Film`]: per-pixel CIE XYZ accumulated in exact fixed-point sums.
//!
//! Floating-point addition is not associative, so a film summed in a different order (more
//! threads, another chunk order, several machines) would differ in the last bits. Spectrace
//! instead rounds every contribution once to a fixed-point integer with 64 fractional bits and
//! adds integers, which is exact and associative: any split of the work gives a bit-identical
//! image. The cost is a resolution of 2^-64 (5.4e-20) per contribution and a range of 2^62
//! (4.6e18) per pixel sum, both in the film's unscaled units (before the factor `power / beams`);
//! contributions outside the range, NaN and infinities are rejected and counted, never added.

use serde::{Deserialize, Serialize};
use spectrace_spectrum::{Xyz, cmf};

/// Fractional bits of the fixed-point sums.
const FRAC_BITS: i32 = 64;
/// `2^FRAC_BITS`.
const SCALE: f64 = (1u128 << FRAC_BITS) as f64;
/// Largest magnitude of one contribution: `2^62`; sums beyond `2^63` are refused as overflow.
const MAX_CONTRIBUTION: f64 = 4_611_686_018_427_387_904.0; // 2^62

/// An exact, order-independent sum of `f64` contributions (fixed point, 64 fractional bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ExactSum(i128);

impl ExactSum {
    /// Adds `x`; returns `false` (and adds nothing) if `x` is NaN, infinite or larger in magnitude
    /// than 2^62, or if the sum would overflow.
    #[inline]
    pub fn add(&mut self, x: f64) -> bool {
        if !(x.abs() <= MAX_CONTRIBUTION) {
            return false;
        }
        let fixed = (x * SCALE).round() as i128;
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

/// Why a film operation failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FilmError {
    /// Two films of different sizes cannot be merged.
    #[error("film sizes differ: {0}x{1} vs {2}x{3}")]
    SizeMismatch(u32, u32, u32, u32),
    /// A width or height of zero, or a pixel count that does not fit in memory.
    #[error(
        "film size {0}x{1} is invalid: both must be at least 1 and their product at most 2^25 (33.5 million pixels)"
    )]
    InvalidSize(u32, u32),
}

/// A film of `width x height` pixels, each accumulating X, Y, Z exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Film {
    width: u32,
    height: u32,
    /// `[X, Y, Z]` per pixel, row-major from the top-left pixel.
    sums: Vec<[ExactSum; 3]>,
    /// Contributions that were not finite or out of range (never added).
    rejected: u64,
    /// Contributions added.
    accepted: u64,
}

impl Film {
    /// An empty film.
    ///
    /// # Errors
    /// [`FilmError::InvalidSize`] for a zero dimension or more than 2^25 pixels (each pixel takes
    /// 48 bytes, and every render thread keeps a film).
    pub fn new(width: u32, height: u32) -> Result<Self, FilmError> {
        let n = u64::from(width) * u64::from(height);
        if width == 0 || height == 0 || n > 1 << 25 {
            return Err(FilmError::InvalidSize(width, height));
        }
        Ok(Self {
            width,
            height,
            sums: vec![[ExactSum::default(); 3]; n as usize],
            rejected: 0,
            accepted: 0,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Adds an XYZ contribution to pixel `(x, y)` (0-based, from the top-left). Returns `false`
    /// and counts a rejection if the pixel is outside the film or any component is not finite or
    /// out of range; nothing is then added.
    #[inline]
    pub fn add(&mut self, x: u32, y: u32, xyz: Xyz) -> bool {
        if x >= self.width || y >= self.height {
            self.rejected += 1;
            return false;
        }
        let limit = |v: f64| v.abs() <= MAX_CONTRIBUTION;
        if !(limit(xyz.x) && limit(xyz.y) && limit(xyz.z)) {
            self.rejected += 1;
            return false;
        }
        let pixel = &mut self.sums[(y * self.width + x) as usize];
        let mut trial = *pixel;
        if trial[0].add(xyz.x) && trial[1].add(xyz.y) && trial[2].add(xyz.z) {
            *pixel = trial;
            self.accepted += 1;
            true
        } else {
            self.rejected += 1;
            false
        }
    }

    /// Adds a spectral contribution: `weight` at wavelength `lambda` (nm), weighted by the CIE
    /// 1931 matching functions.
    #[inline]
    pub fn add_spectral(&mut self, x: u32, y: u32, lambda: f64, weight: f64) -> bool {
        self.add(x, y, cmf(lambda) * weight)
    }

    /// Adds every pixel of `other` (same size) to this film, exactly.
    ///
    /// # Errors
    /// [`FilmError::SizeMismatch`] if the sizes differ.
    pub fn merge(&mut self, other: &Film) -> Result<(), FilmError> {
        if (self.width, self.height) != (other.width, other.height) {
            return Err(FilmError::SizeMismatch(
                self.width,
                self.height,
                other.width,
                other.height,
            ));
        }
        for (a, b) in self.sums.iter_mut().zip(&other.sums) {
            for c in 0..3 {
                if !a[c].merge(b[c]) {
                    self.rejected += 1;
                }
            }
        }
        self.rejected += other.rejected;
        self.accepted += other.accepted;
        Ok(())
    }

    /// The accumulated XYZ of every pixel, row-major, multiplied by `scale` (the estimator's
    /// normalisation, e.g. `1 / beams`).
    pub fn to_xyz(&self, scale: f64) -> Vec<Xyz> {
        self.sums
            .iter()
            .map(|p| Xyz::new(p[0].value() * scale, p[1].value() * scale, p[2].value() * scale))
            .collect()
    }

    /// Contributions rejected (non-finite, out of range, or outside the film).
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// Contributions added.
    pub fn accepted(&self) -> u64 {
        self.accepted
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_are_order_independent() {
        let values: Vec<f64> =
            (0..10_000).map(|i| ((i as f64) * 0.7).sin() * 10f64.powi(i % 13 - 6)).collect();
        let mut forward = ExactSum::default();
        let mut backward = ExactSum::default();
        for &v in &values {
            assert!(forward.add(v));
        }
        for &v in values.iter().rev() {
            assert!(backward.add(v));
        }
        assert_eq!(forward, backward);
        // Plain f64 sums in the two orders differ; the exact sum is within 1e-12 of both.
        let f: f64 = values.iter().sum();
        assert!((forward.value() - f).abs() < 1e-9 * f.abs().max(1.0));
    }

    #[test]
    fn non_finite_and_huge_contributions_are_rejected() {
        let mut s = ExactSum::default();
        assert!(!s.add(f64::NAN));
        assert!(!s.add(f64::INFINITY));
        assert!(!s.add(1e19));
        assert!(s.add(4e18));
        assert_eq!(s.value(), 4e18);
        assert!(!s.add(4e18) || !s.add(4e18), "2^63 overflows");
        let mut film = Film::new(2, 2).unwrap();
        assert!(!film.add(0, 0, Xyz::new(1.0, f64::NAN, 0.0)));
        assert!(!film.add(2, 0, Xyz::new(1.0, 1.0, 1.0)));
        assert!(film.add(1, 1, Xyz::new(1.0, 2.0, 3.0)));
        assert_eq!(film.rejected(), 2);
        assert_eq!(film.to_xyz(0.5)[3], Xyz::new(0.5, 1.0, 1.5));
        assert_eq!(film.to_xyz(1.0)[0], Xyz::default());
    }

    #[test]
    fn merged_films_equal_one_film_bit_for_bit() {
        let contributions: Vec<(u32, u32, f64, f64)> = (0..5000)
            .map(|i| ((i * 7) % 8, (i * 3) % 5, 380.0 + (i % 400) as f64, 1.0 / (1.0 + i as f64)))
            .collect();
        let mut one = Film::new(8, 5).unwrap();
        for &(x, y, l, w) in &contributions {
            one.add_spectral(x, y, l, w);
        }
        let mut parts =
            [Film::new(8, 5).unwrap(), Film::new(8, 5).unwrap(), Film::new(8, 5).unwrap()];
        for (k, &(x, y, l, w)) in contributions.iter().enumerate() {
            parts[k % 3].add_spectral(x, y, l, w);
        }
        let mut merged = Film::new(8, 5).unwrap();
        for p in parts.iter().rev() {
            merged.merge(p).unwrap();
        }
        assert_eq!(merged, one);
        assert!(Film::new(8, 5).unwrap().merge(&Film::new(5, 8).unwrap()).is_err());
        assert!(Film::new(0, 5).is_err());
    }
}
