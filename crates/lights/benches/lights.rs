//! Beams per second for every light type with 1 and 2 threads emitting from the same light, and
//! the beam counter against a single shared atomic: `cargo bench -p spectrace-lights`.
//!
//! Each iteration emits `BATCH` beams on each thread (divan runs the closure on every thread at
//! once), with a per-thread generator; the time per item is ns per beam on one thread, so
//! aggregate beams/s = threads / (time per item).
#![allow(clippy::unwrap_used)]

use std::cell::RefCell;
use std::hint::black_box;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use divan::{Bencher, counter::ItemsCount};
use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use spectrace_lights::spectrum::{Blackbody, CieIlluminant, Gaussian, SpectralPowerDistribution};
use spectrace_lights::*;

fn main() {
    divan::main();
}

const BATCH: usize = 1000;
/// Increments per iteration in the counter benchmarks: long enough (~0.3 ms) that the threads'
/// loops overlap, so contention shows.
const COUNT_BATCH: usize = 100_000;
const THREADS: [usize; 2] = [1, 2];

thread_local! {
    static RNG: RefCell<Pcg64Mcg> = RefCell::new(Pcg64Mcg::seed_from_u64(7));
}

/// The lights measured, by name.
const LIGHTS: [&str; 9] = [
    "Laser",
    "Sky",
    "UniformSpotLight",
    "FadingSpotLight",
    "PointLight",
    "PointLight (blackbody)",
    "RectangleLight",
    "DiskLight",
    "LightSet (4 lights)",
];

fn table() -> Arc<dyn SpectralPowerDistribution> {
    Arc::new(CieIlluminant::new("D65").unwrap())
}

fn build(name: &str) -> Box<dyn LightSource> {
    use WavelengthSampling::Importance as I;
    let (o, y, z) = (DVec3::ZERO, DVec3::Y, DVec3::Z);
    match name {
        "Laser" => Box::new(
            Laser::new(o, z, 1.0, Arc::new(Gaussian::new(632.8, 0.01).unwrap()), 0.0, I).unwrap(),
        ),
        "Sky" => Box::new(Sky::new(o, DVec3::X, z, -y, 1.0, table(), I).unwrap()),
        "UniformSpotLight" => {
            Box::new(UniformSpotLight::new(o, -y, 30.0, 1.0, table(), I).unwrap())
        }
        "FadingSpotLight" => {
            Box::new(FadingSpotLight::new(o, -y, 30.0, 0.1, 1.0, table(), I).unwrap())
        }
        "PointLight" => Box::new(PointLight::new(o, 1.0, table(), I).unwrap()),
        "PointLight (blackbody)" => {
            Box::new(PointLight::new(o, 1.0, Arc::new(Blackbody::new(3000.0).unwrap()), I).unwrap())
        }
        "RectangleLight" => {
            Box::new(RectangleLight::new(o, DVec3::X, z, 1.0, table(), false, I).unwrap())
        }
        "DiskLight" => Box::new(DiskLight::new(o, y, 0.5, 1.0, table(), true, I).unwrap()),
        _ => Box::new(
            LightSet::new(vec![
                build("Laser"),
                build("UniformSpotLight"),
                build("PointLight"),
                build("RectangleLight"),
            ])
            .unwrap(),
        ),
    }
}

#[divan::bench(args = LIGHTS, threads = THREADS)]
fn next_beam(bencher: Bencher<'_, '_>, name: &str) {
    let light = build(name);
    bencher.counter(ItemsCount::new(BATCH)).bench(|| {
        RNG.with(|r| {
            let mut rng = r.borrow_mut();
            for _ in 0..BATCH {
                black_box(light.next_beam(&mut *rng));
            }
        })
    });
}

/// The beam counter lights use (per-thread slots, summed on demand).
#[divan::bench(threads = THREADS)]
fn count_sharded(bencher: Bencher<'_, '_>) {
    let counter = BeamCounter::new();
    bencher.counter(ItemsCount::new(COUNT_BATCH)).bench(|| {
        for _ in 0..COUNT_BATCH {
            counter.increment();
        }
    });
}

/// The design the counter avoids: one atomic shared by every thread.
#[divan::bench(threads = THREADS)]
fn count_one_shared_atomic(bencher: Bencher<'_, '_>) {
    let counter = AtomicU64::new(0);
    bencher.counter(ItemsCount::new(COUNT_BATCH)).bench(|| {
        for _ in 0..COUNT_BATCH {
            counter.fetch_add(1, Ordering::Relaxed);
        }
    });
}
