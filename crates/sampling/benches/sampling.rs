//! ns per sample of every generator beside `rand_distr`'s weighted samplers on the same weights,
//! same random number generator, same run: `cargo bench -p spectrace-sampling`.
//!
//! Each benchmark draws `BATCH` samples per iteration through `rand::distr::Distribution`
//! (`rng.sample(&d)`), so divan's "items/s" is samples per second and the time per item is ns per
//! sample, random number generation included (the same for every generator).
#![allow(clippy::unwrap_used)]

use divan::{Bencher, black_box, counter::ItemsCount};
use rand::{RngExt, SeedableRng, distr::Distribution};
use rand_distr::weighted::{WeightedAliasIndex, WeightedIndex};
use rand_pcg::Pcg64Mcg;
use spectrace_sampling::{AliasTable, Discrete, GuideTable, PiecewiseConstant, PiecewiseLinear};

fn main() {
    divan::main();
}

/// Table sizes: a small table, 1 nm from 360 to 830 nm, and a large table.
const SIZES: [usize; 3] = [16, 471, 100_000];
/// Samples per timed iteration.
const BATCH: usize = 1000;

/// The same smooth-but-bumpy positive weights for every generator.
fn weights(n: usize) -> Vec<f64> {
    let mut rng = Pcg64Mcg::seed_from_u64(42);
    (0..n).map(|i| 0.1 + (i as f64 * 0.37).sin().abs() + rng.random::<f64>()).collect()
}

fn grid(n: usize) -> Vec<f64> {
    (0..n).map(|i| 360.0 + i as f64 * 470.0 / (n - 1) as f64).collect()
}

fn run<T, D: Distribution<T>>(bencher: Bencher<'_, '_>, d: &D) {
    let mut rng = Pcg64Mcg::seed_from_u64(7);
    bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
        for _ in 0..BATCH {
            black_box(rng.sample(d));
        }
    });
}

#[divan::bench(args = SIZES)]
fn discrete(bencher: Bencher<'_, '_>, n: usize) {
    run(bencher, &Discrete::new(&weights(n)).unwrap());
}

#[divan::bench(args = SIZES)]
fn alias_table(bencher: Bencher<'_, '_>, n: usize) {
    run(bencher, &AliasTable::new(&weights(n)).unwrap());
}

#[divan::bench(args = SIZES)]
fn piecewise_linear(bencher: Bencher<'_, '_>, n: usize) {
    run(bencher, &PiecewiseLinear::new(&grid(n), &weights(n)).unwrap());
}

#[divan::bench(args = SIZES)]
fn piecewise_constant(bencher: Bencher<'_, '_>, n: usize) {
    run(bencher, &PiecewiseConstant::new(&grid(n + 1), &weights(n)).unwrap());
}

#[divan::bench(args = SIZES)]
fn rand_distr_weighted_index(bencher: Bencher<'_, '_>, n: usize) {
    run(bencher, &WeightedIndex::new(weights(n)).unwrap());
}

#[divan::bench(args = SIZES)]
fn rand_distr_weighted_alias_index(bencher: Bencher<'_, '_>, n: usize) {
    run(bencher, &WeightedAliasIndex::new(weights(n)).unwrap());
}

/// Building the tables (not a per-sample cost, but what a scene load pays).
#[divan::bench(args = SIZES)]
fn build_piecewise_linear(bencher: Bencher<'_, '_>, n: usize) {
    let (xs, ys) = (grid(n), weights(n));
    bencher.bench_local(|| PiecewiseLinear::new(black_box(&xs), black_box(&ys)).unwrap());
}

/// Vertical-angle counts of candela tables: every 5 degrees, and every degree, 0 to 180.
const ANGLES: [usize; 2] = [37, 181];

/// `-cos(gamma)` at evenly spaced angles: a candela table's vertical grid, whose steps shrink
/// towards the poles (what [`GuideTable`] is for).
fn cosine_grid(n: usize) -> Vec<f64> {
    (0..n).map(|k| -(std::f64::consts::PI * k as f64 / (n - 1) as f64).cos()).collect()
}

/// Points spread over `[-1, 1]` in a fixed random order (the branch predictor cannot learn it).
fn probes() -> Vec<f64> {
    let mut rng = Pcg64Mcg::seed_from_u64(9);
    (0..BATCH).map(|_| rng.random::<f64>() * 2.0 - 1.0).collect()
}

/// The cell of each probe on a cosine grid through [`GuideTable`] (ns per lookup).
#[divan::bench(args = ANGLES)]
fn cosine_grid_guide_table(bencher: Bencher<'_, '_>, n: usize) {
    let (ys, probes) = (cosine_grid(n), probes());
    let guide = GuideTable::new(&ys);
    bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
        for &y in &probes {
            black_box(guide.last_at_or_below(black_box(&ys), y));
        }
    });
}

/// The same lookups by binary search (`partition_point`), the peer of the guide.
#[divan::bench(args = ANGLES)]
fn cosine_grid_binary_search(bencher: Bencher<'_, '_>, n: usize) {
    let (ys, probes) = (cosine_grid(n), probes());
    bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
        for &y in &probes {
            black_box(black_box(&ys).partition_point(|&v| v <= y).max(1) - 1);
        }
    });
}
