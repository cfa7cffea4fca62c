//! ns per `sample_lambda` and per `value` for every SPD type: `cargo bench -p spectrace-spectrum`.
//!
//! Each iteration evaluates `BATCH` uniforms (or wavelengths) drawn beforehand from a fixed seed,
//! so the time per item is the cost of one call; `Uniform` is the peer to compare against, and the
//! 471-point `Tabulated` the peer for the tabulated inverse CDFs (blackbody, Gaussian, mixture).
#![allow(clippy::unwrap_used)]

use divan::{Bencher, black_box, counter::ItemsCount};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use spectrace_spectrum::*;

fn main() {
    divan::main();
}

const BATCH: usize = 1000;

/// The SPDs measured, by name.
const NAMES: [&str; 12] = [
    "Uniform",
    "Tabulated (471 points)",
    "Binned (47 bins)",
    "Gaussian",
    "Gaussian 1e-6 nm",
    "Monochromatic",
    "Blackbody 2856 K",
    "Blackbody 6500 K",
    "Mixture (blackbody + line)",
    "Mixture (blackbody + Gaussian)",
    "CIE D65",
    "CIE F11",
];

fn build(name: &str) -> Box<dyn SpectralPowerDistribution> {
    match name {
        "Uniform" => Box::new(Uniform::equal_energy()),
        "Tabulated (471 points)" => {
            let v: Vec<f64> = (0..471).map(|i| 1.0 + (i as f64 * 0.05).sin().abs()).collect();
            Box::new(Tabulated::regular(360.0, 1.0, &v).unwrap())
        }
        "Binned (47 bins)" => {
            let v: Vec<f64> = (0..47).map(|i| 1.0 + (i as f64 * 0.3).cos().abs()).collect();
            Box::new(Binned::uniform(360.0, 10.0, &v).unwrap())
        }
        "Gaussian" => Box::new(Gaussian::new(550.0, 40.0).unwrap()),
        "Gaussian 1e-6 nm" => Box::new(Gaussian::new(632.8, 1e-6).unwrap()),
        "Monochromatic" => Box::new(Monochromatic::new(589.0).unwrap()),
        "Blackbody 2856 K" => Box::new(Blackbody::new(2856.0).unwrap()),
        "Blackbody 6500 K" => Box::new(Blackbody::new(6500.0).unwrap()),
        "Mixture (blackbody + Gaussian)" => Box::new(
            Mixture::new(vec![
                Component {
                    weight: 0.8,
                    spd: std::sync::Arc::new(Blackbody::new(3000.0).unwrap()),
                },
                Component {
                    weight: 0.2,
                    spd: std::sync::Arc::new(Gaussian::new(450.0, 20.0).unwrap()),
                },
            ])
            .unwrap(),
        ),
        "Mixture (blackbody + line)" => Box::new(
            Mixture::new(vec![
                Component {
                    weight: 0.8,
                    spd: std::sync::Arc::new(Blackbody::new(3000.0).unwrap()),
                },
                Component {
                    weight: 0.2,
                    spd: std::sync::Arc::new(Monochromatic::new(546.1).unwrap()),
                },
            ])
            .unwrap(),
        ),
        "CIE D65" => Box::new(CieIlluminant::new("D65").unwrap()),
        _ => Box::new(CieIlluminant::new("F11").unwrap()),
    }
}

fn uniforms() -> Vec<f64> {
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    (0..BATCH).map(|_| rng.random::<f64>()).collect()
}

#[divan::bench(args = NAMES)]
fn sample_lambda(bencher: Bencher<'_, '_>, name: &str) {
    let spd = build(name);
    let us = uniforms();
    bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
        for &u in &us {
            black_box(spd.sample_lambda(black_box(u)));
        }
    });
}

#[divan::bench(args = NAMES)]
fn value(bencher: Bencher<'_, '_>, name: &str) {
    let spd = build(name);
    let lambdas: Vec<f64> = uniforms().into_iter().map(|u| 360.0 + 470.0 * u).collect();
    bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
        for &l in &lambdas {
            black_box(spd.value(black_box(l)));
        }
    });
}

/// One CIE 1931 lookup (what the film pays per splat).
#[divan::bench]
fn cmf_lookup(bencher: Bencher<'_, '_>) {
    let lambdas: Vec<f64> = uniforms().into_iter().map(|u| 360.0 + 470.0 * u).collect();
    bencher.counter(ItemsCount::new(BATCH)).bench_local(|| {
        for &l in &lambdas {
            black_box(cmf(black_box(l)));
        }
    });
}
