//! [`SobolSampler`]: Owen-scrambled Sobol points served as a random generator, so that code that
//! draws its uniforms one `next_u64` at a time (lights, materials, cameras) gets low-discrepancy
//! points without knowing it.

use std::convert::Infallible;
use std::sync::OnceLock;

use rand::{Rng, TryRng};
use sobol_burley::parts;

use crate::split_mix64;

/// Dimensions of a path served from the Sobol table (the Joe-Kuo direction numbers of the
/// `sobol_burley` crate); later draws of a path come from the fallback generator.
pub const SOBOL_DIMENSIONS: u32 = sobol_burley::NUM_DIMENSIONS;

/// Points of one scrambled sequence: `sobol_burley` serves indices below `2^16`; a path index
/// beyond starts another, independently scrambled, block of `2^16` points.
pub const SOBOL_BLOCK: u64 = 1 << 16;

/// Bits of a draw that come from the Sobol point (the precision of `sobol_burley`'s output); the
/// 41 low bits come from the fallback generator.
const SOBOL_BITS: u32 = 23;

/// An Owen-scrambled Sobol sampler (Burley 2020, hash-based nested uniform scrambling) exposed as
/// a [`rand::Rng`].
///
/// Each path calls [`start_path`](Self::start_path)`(stream, index)`; after it, the `k`-th
/// `next_u64` (or `next_u32`) returns dimension `k` of point `index` of the sequence scrambled
/// for `(seed, stream)`: its top 23 bits are the scrambled Sobol coordinate and the low 41 bits
/// come from the fallback generator, so each draw is exactly uniform over the 64-bit integers
/// and [`crate::uniform`] keeps its 53 bits. Draws beyond [`SOBOL_DIMENSIONS`] in one path, and
/// draws before the first `start_path`, come from the fallback generator alone. Index `i` uses
/// point `i mod 2^16` of a sequence whose scramble also depends on `i / 2^16` (see
/// [`SOBOL_BLOCK`]). `fill_bytes` always uses the fallback.
///
/// Every coordinate is uniform on `[0, 1)` for any scramble, so estimators stay unbiased; the
/// gain is stratification: the first `2^m` points of every dimension of one block have one point
/// in each interval of length `2^-m`, and those of dimensions 0 and 1 (a (0, 2)-sequence) one
/// point in each elementary interval of area `2^-m`. Stratification holds per dimension, so code that draws a variable number
/// of uniforms (rejection loops) shifts the later dimensions of its path: still unbiased, but
/// the shifted draws lose their stratification.
#[derive(Debug, Clone)]
pub struct SobolSampler<R> {
    fallback: R,
    /// The seed, mixed (the part of every path's scramble that depends on it alone).
    seed_key: u64,
    /// Scramble of the current path's sequence (from seed, stream and block).
    scramble: u32,
    /// The current point's index within the block, bit-reversed and shuffled by the scramble
    /// (`sobol_burley`'s first step, done once per path instead of once per draw).
    shuffled: u32,
    /// The scramble's part of every dimension's Owen-scrambling key (`scramble * 0x9c8f2d3b`).
    key: u32,
    /// Next dimension to serve; [`SOBOL_DIMENSIONS`] or more: fallback only.
    dimension: u32,
    /// The Sobol integers' byte tables, fetched once (not through the lazy static per draw).
    tables: Tables,
}

/// The process's [`ByteTables`], as a slice (one entry per dimension); its `Debug` names
/// their count rather than printing 2 MiB of integers.
#[derive(Clone, Copy)]
struct Tables(&'static [[[u32; 256]; 2]]);

impl std::fmt::Debug for Tables {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Tables({} dimensions)", self.0.len())
    }
}

impl<R> SobolSampler<R> {
    /// A sampler whose scrambles derive from `seed`, with `fallback` for the low bits and the
    /// dimensions beyond the table. Until [`start_path`](Self::start_path) it is the fallback.
    pub fn new(seed: u64, fallback: R) -> Self {
        Self {
            fallback,
            seed_key: split_mix64(seed),
            scramble: 0,
            shuffled: 0,
            key: 0,
            dimension: SOBOL_DIMENSIONS,
            tables: Tables(byte_tables()),
        }
    }

    /// `SobolSampler::new(seed, fallback)` of this sampler's seed, without mixing the seed
    /// again: for code that makes a sampler per path (no path started yet).
    #[inline]
    pub fn with_fallback<S>(&self, fallback: S) -> SobolSampler<S> {
        SobolSampler::<S> {
            fallback,
            seed_key: self.seed_key,
            scramble: 0,
            shuffled: 0,
            key: 0,
            dimension: SOBOL_DIMENSIONS,
            tables: self.tables,
        }
    }
}

impl<R: Rng> SobolSampler<R> {
    /// Starts a path: point `index` of the sequence scrambled for `stream` (and the sampler's
    /// seed); the next draw is its dimension 0.
    pub fn start_path(&mut self, stream: u64, index: u64) {
        let block = index / SOBOL_BLOCK;
        let key = split_mix64(
            split_mix64(self.seed_key ^ stream) ^ block.wrapping_mul(0xD6E8_FEB8_6659_FD93),
        );
        self.scramble = (key ^ (key >> 32)) as u32;
        let index = (index % SOBOL_BLOCK) as u32;
        self.shuffled =
            parts::owen_scramble_rev(index.reverse_bits(), parts::hash(self.scramble ^ INDEX_KEY));
        self.key = self.scramble.wrapping_mul(SEED_FACTOR);
        self.dimension = 0;
    }

    /// The dimension the next draw will serve (`>= SOBOL_DIMENSIONS`: the fallback alone).
    pub fn dimension(&self) -> u32 {
        self.dimension
    }

    /// The fallback generator.
    pub fn fallback_mut(&mut self) -> &mut R {
        &mut self.fallback
    }

    /// The top [`SOBOL_BITS`] bits of dimension `dimension` of the current point:
    /// `sobol_burley::sample(index, dimension, scramble)` times `2^23` (an integer, exactly),
    /// the crate's steps with the unscrambled Sobol integer read from `t`, the dimension's
    /// [`ByteTables`] entry.
    #[inline]
    fn coordinate(&self, t: &[[u32; 256]; 2], dimension: u32) -> u32 {
        let sobol =
            t[0][(self.shuffled >> 24) as usize] ^ t[1][((self.shuffled >> 16) & 0xff) as usize];
        let key = (dimension >> 2) ^ self.key ^ LANE_KEYS[(dimension & 3) as usize];
        // `u32_to_f32_norm(n)` is `(n >> 9) * 2^-23` exactly: its top 23 bits.
        parts::owen_scramble_rev(sobol, parts::hash(key)).reverse_bits() >> (32 - SOBOL_BITS)
    }
}

/// `sobol_burley`'s key for shuffling the point index (see `sobol_burley::sample`).
const INDEX_KEY: u32 = 0x79c6_8e4a;
/// `sobol_burley`'s factor on the seed in every dimension's scrambling key.
const SEED_FACTOR: u32 = 0x9c8f_2d3b;
/// `sobol_burley`'s per-lane constants of the scrambling key (dimension mod 4).
const LANE_KEYS: [u32; 4] = [0x912f_69ba, 0x174f_18ab, 0x691e_72ca, 0xb40c_c1b8];

/// Per dimension (all [`SOBOL_DIMENSIONS`], 2 KiB each), the (bit-reversed) Sobol integer of every value of the shuffled index's top
/// byte (`[0]`) and of its second byte (`[1]`). The Sobol integer of an index is the XOR of the
/// direction vectors of its set bits (`sobol_burley` reads the top 16 bits), so it is the XOR of
/// the two bytes' entries: two loads instead of a loop over up to 16 bits.
type ByteTables = Vec<[[u32; 256]; 2]>;

/// The tables, built once per process from `sobol_burley::parts::sobol_rev` (about 2 million
/// instructions, under a millisecond).
fn byte_tables() -> &'static ByteTables {
    static TABLES: OnceLock<ByteTables> = OnceLock::new();
    TABLES.get_or_init(|| {
        (0..SOBOL_DIMENSIONS)
            .map(|d| {
                let byte =
                    |shift: u32| std::array::from_fn(|b| parts::sobol_rev((b as u32) << shift, d));
                [byte(24), byte(16)]
            })
            .collect()
    })
}

impl<R: Rng> TryRng for SobolSampler<R> {
    type Error = Infallible;

    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        self.try_next_u64().map(|x| (x >> 32) as u32)
    }

    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        let low = self.fallback.next_u64();
        // Every dimension below SOBOL_DIMENSIONS has its table; beyond, the fallback alone.
        let Some(t) = self.tables.0.get(self.dimension as usize) else { return Ok(low) };
        let high = u64::from(self.coordinate(t, self.dimension));
        self.dimension += 1;
        Ok((high << (64 - SOBOL_BITS)) | (low >> SOBOL_BITS))
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        self.fallback.fill_bytes(dst);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use rand::SeedableRng;
    use rand_pcg::Pcg64;

    use super::*;
    use crate::uniform;

    fn sampler(seed: u64) -> SobolSampler<Pcg64> {
        SobolSampler::new(seed, Pcg64::seed_from_u64(seed))
    }

    /// The first `dims` uniforms of points `0..n` of stream `stream`.
    fn points(s: &mut SobolSampler<Pcg64>, stream: u64, n: u64, dims: usize) -> Vec<Vec<f64>> {
        (0..n)
            .map(|i| {
                s.start_path(stream, i);
                (0..dims).map(|_| uniform(s)).collect()
            })
            .collect()
    }

    #[test]
    fn a_sampler_made_with_another_fallback_is_the_one_new_makes() {
        let template = SobolSampler::new(11, ());
        for (stream, index) in [(0, 0), (3, 7), (1 << 40, SOBOL_BLOCK + 5)] {
            let mut a = template.with_fallback(Pcg64::seed_from_u64(4));
            let mut b = SobolSampler::new(11, Pcg64::seed_from_u64(4));
            a.start_path(stream, index);
            b.start_path(stream, index);
            let (xa, xb): (Vec<u64>, Vec<u64>) =
                (0..8).map(|_| (a.next_u64(), b.next_u64())).unzip();
            assert_eq!(xa, xb, "stream {stream}, index {index}");
        }
    }

    #[test]
    fn every_one_dimensional_projection_is_stratified() {
        let mut s = sampler(5);
        for m in [4u32, 8, 12] {
            let n = 1u64 << m;
            let p = points(&mut s, 3, n, 40);
            for d in 0..40 {
                let mut cells = vec![0u32; n as usize];
                for x in &p {
                    cells[(x[d] * n as f64) as usize] += 1;
                }
                assert!(cells.iter().all(|&c| c == 1), "m = {m}, dimension {d}");
            }
        }
    }

    #[test]
    fn pairs_of_dimensions_have_one_point_per_elementary_interval() {
        let mut s = sampler(9);
        let m = 10u32;
        let n = 1u64 << m;
        for stream in [0u64, 77] {
            let p = points(&mut s, stream, n, 2);
            // Every elementary interval [a 2^-i, (a+1) 2^-i) x [b 2^-(m-i), (b+1) 2^-(m-i)).
            for i in 0..=m {
                let (nx, ny) = (1u64 << i, 1u64 << (m - i));
                let mut cells = vec![0u32; n as usize];
                for x in &p {
                    let cx = (x[0] * nx as f64) as u64;
                    let cy = (x[1] * ny as f64) as u64;
                    cells[(cx * ny + cy) as usize] += 1;
                }
                assert!(cells.iter().all(|&c| c == 1), "stream {stream}, split {i}");
            }
        }
    }

    #[test]
    fn streams_and_blocks_are_scrambled_differently_and_reproducibly() {
        let mut a = sampler(1);
        let mut b = sampler(1);
        a.start_path(0, 5);
        b.start_path(0, 5);
        assert_eq!(a.next_u64() >> 41, b.next_u64() >> 41);
        let first = |s: &mut SobolSampler<Pcg64>, stream, index| {
            s.start_path(stream, index);
            s.next_u64() >> 41
        };
        let base: Vec<u64> = (0..16).map(|i| first(&mut a, 0, i)).collect();
        let other_stream: Vec<u64> = (0..16).map(|i| first(&mut a, 1, i)).collect();
        let other_block: Vec<u64> = (0..16).map(|i| first(&mut a, 0, SOBOL_BLOCK + i)).collect();
        let other_seed: Vec<u64> = (0..16).map(|i| first(&mut sampler(2), 0, i)).collect();
        assert_ne!(base, other_stream);
        assert_ne!(base, other_block);
        assert_ne!(base, other_seed);
    }

    #[test]
    fn dimensions_beyond_the_table_and_draws_before_a_path_use_the_fallback() {
        let mut s = sampler(4);
        let mut f = Pcg64::seed_from_u64(4);
        // Before any path: the fallback alone.
        assert_eq!(s.next_u64(), f.next_u64());
        s.start_path(0, 3);
        for _ in 0..SOBOL_DIMENSIONS {
            let _ = s.next_u64();
            let _ = f.next_u64();
        }
        assert_eq!(s.dimension(), SOBOL_DIMENSIONS);
        assert_eq!(s.next_u64(), f.next_u64());
    }

    #[test]
    fn draws_are_the_crates_points_dimension_by_dimension() {
        // Every draw is `sample(index, dimension, scramble)` of the crate: the top 23 bits equal
        // the one-dimension function's value, in every dimension, for indices whose shuffled
        // bits cover both table bytes.
        let mut s = sampler(21);
        for (stream, index) in
            [(5, 0u64), (5, 1), (6, 7), (7, 4095), (8, 65535), (5, SOBOL_BLOCK + 3)]
                .into_iter()
                .chain((0..64).map(|k| (k, k * 1031 % SOBOL_BLOCK)))
        {
            s.start_path(stream, index);
            let scramble = s.scramble;
            for d in 0..SOBOL_DIMENSIONS {
                let x = sobol_burley::sample((index % SOBOL_BLOCK) as u32, d, scramble);
                let expected = (f64::from(x) * f64::from(1u32 << SOBOL_BITS)) as u64;
                assert_eq!(s.next_u64() >> 41, expected, "index {index}, dimension {d}");
            }
        }
    }

    #[test]
    fn draws_are_uniform_with_random_low_bits() {
        // Mean and variance of 4096 points x 8 dimensions match U(0, 1) closely (stratified:
        // much closer than 1/sqrt(n)); the low bits vary between two seeds of the fallback.
        let mut s = sampler(12);
        let p = points(&mut s, 0, 4096, 8);
        let n = (p.len() * 8) as f64;
        let mean: f64 = p.iter().flatten().sum::<f64>() / n;
        let var: f64 = p.iter().flatten().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
        assert!((mean - 0.5).abs() < 1e-3, "{mean}");
        assert!((var - 1.0 / 12.0).abs() < 1e-3, "{var}");
        let mut t = SobolSampler::new(12, Pcg64::seed_from_u64(13));
        s.start_path(0, 0);
        t.start_path(0, 0);
        let (a, b) = (s.next_u64(), t.next_u64());
        assert_eq!(a >> 41, b >> 41);
        assert_ne!(a & ((1 << 41) - 1), b & ((1 << 41) - 1));
    }
}
