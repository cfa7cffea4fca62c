//! Tests of the per-pixel moments and their error estimates.

use super::*;
use rand::{RngExt, SeedableRng};

/// A synthetic render: `pixels` pixels whose chunk sums are the sum of `items` draws of
/// `value * (1 + noise * u)`, u uniform in [-1, 1].
fn synthetic(chunks: u64, items: u64, seed: u64) -> (Moments, Vec<[f64; 3]>) {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let (w, h) = (16, 8);
    let mut m = Moments::new(w, h).unwrap();
    let mut total = vec![[0.0; 3]; (w * h) as usize];
    for c in 0..chunks {
        let mut chunk = vec![[0.0; 3]; (w * h) as usize];
        for _ in 0..items {
            let p = rng.random_range(0..(w * h) as usize);
            let u: f64 = rng.random_range(-1.0..1.0);
            let v = 1.0 + (p % 7) as f64 * 0.1;
            chunk[p][0] += v * (1.0 + 0.5 * u);
            chunk[p][1] += v;
            chunk[p][2] += 0.5 * v * (1.0 - 0.5 * u);
        }
        for (t, c) in total.iter_mut().zip(&chunk) {
            for k in 0..3 {
                t[k] += c[k];
            }
        }
        m.add_chunk(c, chunk.into_iter().enumerate(), items);
    }
    (m, total)
}

#[test]
fn estimate_matches_the_spread_of_independent_renders() {
    // The true relative RMSE of a render, measured from 40 independent renders against
    // their mean (the converged image), against the estimate of each render alone. With
    // 32 chunks per render the estimate's own noise is a few percent; 15% bounds it.
    let (renders, chunks, items) = (40u64, 32, 2000);
    let runs: Vec<(Moments, Vec<[f64; 3]>)> =
        (0..renders).map(|r| synthetic(chunks, items, 100 + r)).collect();
    let n = (chunks * items) as f64;
    let mut mean = vec![[0.0; 3]; runs[0].1.len()];
    for (_, img) in &runs {
        for (a, b) in mean.iter_mut().zip(img) {
            for k in 0..3 {
                a[k] += b[k] / n / renders as f64;
            }
        }
    }
    let xyz = |img: &[[f64; 3]], scale: f64| -> Vec<Xyz> {
        img.iter().map(|p| Xyz::new(p[0] * scale, p[1] * scale, p[2] * scale)).collect()
    };
    let converged = xyz(&mean, 1.0);
    for measure in ErrorMeasure::ALL {
        // The true error: the RMS over renders of each render's error in the measure.
        let truth = (runs
            .iter()
            .map(|(_, img)| {
                crate::relative_error(measure, &xyz(img, 1.0 / n), &converged).unwrap().powi(2)
            })
            .sum::<f64>()
            / renders as f64)
            .sqrt();
        let estimated: f64 =
            runs.iter().map(|(m, _)| m.estimate(measure).relative_error.unwrap()).sum::<f64>()
                / renders as f64;
        assert!(
            (estimated / truth - 1.0).abs() < 0.15,
            "{}: estimate {estimated}, truth {truth}",
            measure.name()
        );
        let e = runs[0].0.estimate(measure);
        assert!(e.is_trusted() && e.batches == chunks && e.items == chunks * items);
        assert!(e.degrees_of_freedom > 100.0, "{}", e.degrees_of_freedom);
        assert_eq!(e.relative_error, e.by_measure.get(measure));
        let (lo, hi) = e.interval().unwrap();
        assert!(lo < e.relative_error.unwrap() && e.relative_error.unwrap() < hi);
    }
    // The running totals give the same energy estimate to rounding.
    let e = runs[0].0.estimate(ErrorMeasure::Energy);
    let quick = runs[0].0.quick_estimate().relative_error.unwrap();
    assert!((quick / e.relative_error.unwrap() - 1.0).abs() < 1e-9, "{quick} vs {e:?}");
    assert!(e.degrees_of_freedom > 100.0, "{}", e.degrees_of_freedom);
}

#[test]
fn the_live_estimate_is_redone_as_the_chunks_grow_or_when_a_target_may_be_reached() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
    let mut m = Moments::new(4, 1).unwrap();
    let mut chunk = |m: &mut Moments| {
        let v: f64 = rng.random_range(0.5..1.5);
        m.add_chunk(m.chunks(), (0..4).map(|p| (p, [v, v * (1.0 + p as f64), v])), 4);
    };
    // A 2-pixel film in chunks of 4 items: redone every 8 x 2 / 4 = 4 chunks at first.
    for measure in [ErrorMeasure::RelMse, ErrorMeasure::Energy] {
        let mut live = LiveEstimate::new(measure, 2, 4);
        let mut fresh = Vec::new();
        let mut m = Moments::new(4, 1).unwrap();
        for _ in 0..10 {
            chunk(&mut m);
            let (e, is_fresh) = live.update(&m, None);
            assert_eq!(e.measure, measure);
            fresh.push(is_fresh);
        }
        let want = [true, false, false, false, true, false, false, false, true, false];
        assert_eq!(fresh, want, "{}", measure.name());
        // A fresh estimate is the full one.
        let (e, _) = live.update(&m, None);
        assert!(e.batches <= m.chunks());
    }
    // Later, once a quarter of the chunks is more than 4, after a quarter more: the chunks of
    // the fresh estimates of 100 grow by max(4, last / 4).
    let mut live = LiveEstimate::new(ErrorMeasure::RelMse, 2, 4);
    let mut grown = Moments::new(4, 1).unwrap();
    let mut fresh_at = Vec::new();
    for _ in 0..100 {
        chunk(&mut grown);
        if live.update(&grown, None).1 {
            fresh_at.push(grown.chunks());
        }
    }
    assert_eq!(fresh_at, [1, 5, 9, 13, 17, 21, 26, 32, 40, 50, 62, 77, 96]);
    // With a target the energy estimate has reached, every chunk is checked at once.
    let mut live = LiveEstimate::new(ErrorMeasure::Energy, 2, 4);
    for _ in 0..3 {
        chunk(&mut m);
    }
    assert!(live.update(&m, Some(0.99)).1);
    chunk(&mut m);
    assert!(live.update(&m, Some(0.99)).1, "the quick estimate says 0.99 is reached");
    chunk(&mut m);
    assert!(!live.update(&m, Some(1e-9)).1, "not due, and the target is far");
    // The re-judgement of a chunk that ended after the target was reached: computed now, over
    // every chunk, and kept as the latest.
    let stale = live.update(&m, Some(1e-9)).0;
    let now = live.fresh(&m);
    assert_eq!(now.batches, m.chunks());
    assert!(stale.batches < now.batches, "{} then {}", stale.batches, now.batches);
    assert_eq!(live.update(&m, Some(1e-9)), (now, false));
}

#[test]
fn noiseless_images_estimate_zero_and_one_chunk_estimates_nothing() {
    let mut m = Moments::new(2, 1).unwrap();
    m.add_chunk(0, [(0, [2.0, 2.0, 2.0])], 4);
    for measure in ErrorMeasure::ALL {
        assert_eq!(m.estimate(measure).relative_error, None);
    }
    assert_eq!(m.standard_error_rgb(1.0), vec![[0.0; 3]; 2]);
    m.add_chunk(1, [(0, [2.0, 2.0, 2.0])], 4);
    // A black image has no relative error.
    let mut black = Moments::new(2, 1).unwrap();
    black.add_chunk(0, [], 4);
    black.add_chunk(1, [], 4);
    for measure in ErrorMeasure::ALL {
        assert_eq!(m.estimate(measure).relative_error, Some(0.0), "{}", measure.name());
        assert_eq!(black.estimate(measure).relative_error, None, "{}", measure.name());
        // No noise: the 0 is exact, but two batches are too few to trust.
        assert_eq!(m.estimate(measure).relative_uncertainty(), 0.0);
        assert!(!m.estimate(measure).is_trusted());
    }
}

#[test]
fn merged_moments_estimate_what_one_render_of_all_chunks_does() {
    let (a, _) = synthetic(10, 500, 1);
    let (b, _) = synthetic(12, 500, 2);
    let mut merged = a.clone();
    merged.merge(&b).unwrap();
    assert_eq!((merged.chunks(), merged.items()), (22, 11_000));
    let e = merged.estimate(ErrorMeasure::Energy).relative_error.unwrap();
    let quick = merged.quick_estimate().relative_error.unwrap();
    assert!((quick / e - 1.0).abs() < 1e-9, "{quick} vs {e}");
    let ea = a.estimate(ErrorMeasure::Energy).relative_error.unwrap();
    // More chunks of the same kind: the error falls by about sqrt(22 / 10).
    assert!((ea / e / (22.0f64 / 10.0).sqrt() - 1.0).abs() < 0.25, "{ea} {e}");
    assert!(merged.merge(&Moments::new(3, 3).unwrap()).is_err());
}

#[test]
fn the_rgb_error_of_a_luminance_only_noise_follows_the_matrix() {
    // Noise in Y alone (X and Z constant): the sRGB errors are |row_Y| times Y's error.
    let mut m = Moments::new(1, 1).unwrap();
    for (c, y) in [1.0, 3.0, 1.0, 3.0].into_iter().enumerate() {
        m.add_chunk(c as u64, [(0, [1.0, y, 1.0])], 1);
    }
    // Y's chunk values 1, 3, 1, 3: sample variance 4/3; the image (scale 1/4 per item
    // over 4 items) has standard error sqrt(4/3 / 4) = 0.577 in Y.
    let se = m.standard_error_rgb(0.25)[0];
    let rows = srgb_rows();
    for r in 0..3 {
        let expected = rows[r][1].abs() * (4.0f64 / 3.0 / 4.0).sqrt();
        assert!((se[r] - expected).abs() < 1e-12, "{r}: {} vs {expected}", se[r]);
    }
}

#[test]
fn every_shard_has_chunks_in_both_halves() {
    for n in 1..=16u64 {
        for k in 0..n {
            let first = (0..64).filter(|i| Moments::in_first_half(k + i * n)).count();
            assert!((16..=48).contains(&first), "shard {k} of {n}: {first} of 64 first");
        }
    }
}

#[test]
fn a_firefly_counts_against_the_other_halfs_value() {
    // One grey pixel: 32 chunks of value 1, and one of them a firefly of 101. The image
    // is 4.1 where the firefly-free value is 1: a relative error of about 3, which the
    // split estimate sees (about 3.1); the same chunks' own square would say about 1.1.
    let mut m = Moments::new(1, 1).unwrap();
    let firefly = (0..).find(|&c| Moments::in_first_half(c)).unwrap();
    for c in 0..32 {
        let v = if c == firefly { 101.0 } else { 1.0 };
        m.add_chunk(c, [(0, [v, v, v])], 1);
    }
    let e = m.estimate(ErrorMeasure::RelMse).relative_error.unwrap();
    assert!(e > 2.5, "{e}");
}

/// Moments of `chunks` chunks over `pixels` grey pixels of true value 1 whose chunk
/// values are `E² / 2` (`E` exponential): skewed, relative deviation `sqrt(5)`.
fn skewed(pixels: u32, chunks: u64, seed: u64) -> Moments {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut m = Moments::new(pixels, 1).unwrap();
    for c in 0..chunks {
        let values: Vec<(usize, [f64; 3])> = (0..pixels as usize)
            .map(|p| {
                let e = -(1.0 - rng.random::<f64>()).ln();
                (p, [0.5 * e * e; 3])
            })
            .collect();
        m.add_chunk(c, values, 1);
    }
    m
}

#[test]
fn skewed_pixels_with_few_chunks_do_not_explode_the_estimate() {
    // 8 chunks of relative variance 5: the truth is sqrt(5 / 8) = 0.79 per pixel. Without
    // `SPLIT_FLOOR` the estimate is 3.96 (a half whose value is small and whose spread is
    // small too passes the spread test), with it 1.14: a factor 1.6 either way bounds it.
    let e = skewed(4000, 8, 7).estimate(ErrorMeasure::RelMse).relative_error.unwrap();
    let truth = (5.0f64 / 8.0).sqrt();
    assert!((truth / 1.6..truth * 1.6).contains(&e), "{e} against {truth}");
}

#[test]
fn the_relmse_uncertainty_is_how_far_a_skewed_renders_estimate_strays() {
    // 40 renders of 200 skewed grey pixels in 64 chunks: how far their relmse estimates
    // scatter (measured 5.2%) is what each one's uncertainty claims (5.6%); counting every
    // channel of every pixel as an independent normal term claims far less. Within a
    // factor 1.4 either way.
    let (mut estimates, mut claimed) = (Vec::new(), Vec::new());
    for seed in 0..40 {
        let e = skewed(200, 64, 1000 + seed).estimate(ErrorMeasure::RelMse);
        estimates.push(e.relative_error.unwrap());
        claimed.push(e.relative_uncertainty());
    }
    let k = estimates.len() as f64;
    let mean = estimates.iter().sum::<f64>() / k;
    let var = estimates.iter().map(|r| (r - mean) * (r - mean)).sum::<f64>() / (k - 1.0);
    let found = var.sqrt() / mean;
    let claim = claimed.iter().sum::<f64>() / k;
    assert!((claim / 1.4..claim * 1.4).contains(&found), "claimed {claim}, found {found}");
}

#[test]
fn a_tally_lists_each_pixel_once_even_when_its_sum_returns_to_zero() {
    let moments = Mutex::new(Moments::new(4, 1).unwrap());
    let mut t = ChunkTally::new(&moments).unwrap();
    t.add(1, [1.0, 0.0, 0.0]);
    t.add(1, [-1.0, 0.0, 0.0]);
    t.add(1, [2.0, 0.0, 0.0]);
    t.add(3, [0.0, 0.0, 0.0]);
    t.end_chunk(0, 2);
    t.add(1, [4.0, 0.0, 0.0]);
    t.end_chunk(1, 2);
    let m = moments.into_inner().unwrap();
    assert_eq!(m.sums[1][0], 6.0);
    // Second moments: 2^2 / 2 + 4^2 / 2.
    assert_eq!(m.sums[1][3], 10.0);
    // A pixel that received only zeros adds zeros.
    assert_eq!(m.sums[3], [0.0; 9]);
    assert_eq!((m.chunks(), m.items(), m.first_half_chunks()), (2, 4, [1, 2]));
    // The first half's chunk alone (chunk 0): 2 in X, and its linear-sRGB squares over
    // its 2 items.
    assert_eq!(m.first[1][..3], [2.0, 0.0, 0.0]);
    for (q, row) in m.first[1][3..].iter().zip(srgb_rows()) {
        assert!((q - (2.0 * row[0]).powi(2) / 2.0).abs() < 1e-12);
    }
}

#[test]
fn channels_within_their_noise_of_zero_do_not_explode_the_estimate() {
    // 2000 pixels whose three linear-sRGB channels (a saturated colour's, which single-
    // wavelength paths scatter on both sides of 0) have normal chunk values of deviation 1
    // about a mean 2.5 standard errors of the image from 0: the truth is 1 / 2.5 = 0.4.
    // Denominators that fall to `I² / 2` near 0 estimated 1.69 (4.2 times the truth); with
    // `VARIANCE_FLOOR`, 0.61: bounded, and above the truth by what the floor is simulated to
    // give at most on such channels (2.5 in squares, 1.6 in the relmse).
    let (pixels, chunks, k) = (2000u32, 128u64, 2.5);
    let to_xyz = glam::DMat3::from_cols_array_2d(&srgb_rows()).transpose().inverse();
    let mean = k / (chunks as f64).sqrt();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(17);
    let mut normal = || {
        let (u, v): (f64, f64) = (1.0 - rng.random::<f64>(), rng.random());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    let mut m = Moments::new(pixels, 1).unwrap();
    for c in 0..chunks {
        let values: Vec<(usize, [f64; 3])> = (0..pixels as usize)
            .map(|p| {
                let rgb = glam::DVec3::new(mean + normal(), mean + normal(), mean + normal());
                (p, (to_xyz * rgb).to_array())
            })
            .collect();
        m.add_chunk(c, values, 1);
    }
    let e = m.estimate(ErrorMeasure::RelMse).relative_error.unwrap();
    let truth = 1.0 / k;
    eprintln!("estimated {e}, true {truth}");
    assert!((truth / 1.25..truth * 1.6).contains(&e), "{e} against {truth}");
}
