//! The film's tests: exact sums, splats, writers, merges.

use std::sync::Mutex;

use spectrace_spectrum::Xyz;

use super::exact::*;
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
        one.splat_spectral(x, y, &[l], &[w]);
    }
    let mut parts = [Film::new(8, 5).unwrap(), Film::new(8, 5).unwrap(), Film::new(8, 5).unwrap()];
    for (k, &(x, y, l, w)) in contributions.iter().enumerate() {
        parts[k % 3].splat_spectral(x, y, &[l], &[w]);
    }
    let mut merged = Film::new(8, 5).unwrap();
    for p in parts.iter().rev() {
        merged.merge(p).unwrap();
    }
    assert_eq!(merged, one);
    assert!(Film::new(8, 5).unwrap().merge(&Film::new(5, 8).unwrap()).is_err());
    assert!(Film::new(0, 5).is_err());
}

#[test]
fn buffered_writers_into_a_shared_film_equal_direct_adds_bit_for_bit() {
    // More contributions than a buffer holds, some of them invalid (NaN, infinite, beyond
    // 2^62, outside the film), written by three interleaved writers.
    let contributions: Vec<(u32, u32, Xyz)> = (0..3 * FilmWriter::CAPACITY as u32 + 77)
        .map(|i| {
            let v = 1.0 / (1.0 + f64::from(i)) * 10f64.powi((i % 9) as i32 - 4);
            let xyz = match i % 101 {
                0 => Xyz::new(f64::NAN, v, v),
                1 => Xyz::new(v, f64::INFINITY, v),
                2 => Xyz::new(v, v, 1e19),
                _ => Xyz::new(v, 0.5 * v, -0.25 * v),
            };
            ((i * 7) % 13, (i * 3) % 6, xyz)
        })
        .collect();
    let mut direct = Film::new(12, 5).unwrap();
    let mut direct_answers = Vec::new();
    for &(x, y, xyz) in &contributions {
        direct_answers.push(direct.splat(x, y, xyz));
    }
    let shared = Mutex::new(Film::new(12, 5).unwrap());
    let mut buffered_answers = Vec::new();
    {
        let mut writers =
            [FilmWriter::new(&shared), FilmWriter::new(&shared), FilmWriter::new(&shared)];
        for (k, &(x, y, xyz)) in contributions.iter().enumerate().rev() {
            buffered_answers.push(writers[k % 3].splat(x, y, xyz));
        }
        writers[1].flush();
        // The others flush when dropped.
    }
    buffered_answers.reverse();
    assert_eq!(buffered_answers, direct_answers);
    let shared = shared.into_inner().unwrap();
    assert!(direct.rejected() > 0 && direct.accepted() > 3 * FilmWriter::CAPACITY as u64 / 2);
    assert_eq!(shared, direct);
}

#[test]
fn the_quick_fixed_point_conversion_is_within_rounding_of_the_exact_one() {
    for x in [0.0, 1e-19, 0.25, -0.25, 1.0, -3.5, 123_456.789, -9.87e17, 4.6e18, 5e-20] {
        let fixed = to_fixed(x).unwrap();
        let exact = fixed as f64 / SCALE;
        let quick = fixed_to_f64(fixed);
        assert!((quick - exact).abs() <= 4.0 * f64::EPSILON * exact.abs() + 1e-300, "{x}");
    }
}

#[test]
fn sensor_cells_sum_apart_from_the_pixels_and_merge_exactly() {
    let mut direct = Film::with_sensor_cells(3, 2, 4).unwrap();
    assert_eq!(direct.sensor_cells(), 4);
    assert!(direct.add_sensor(3, [1.5, 2.0, 4.0, 0.75]));
    assert!(!direct.add_sensor(4, [1.0, 1.0, 1.0, 1.0]), "beyond the cells");
    assert!(!direct.add_sensor(0, [0.0, 0.0, 0.0, f64::NAN]));
    assert_eq!(direct.rejected(), 2);
    assert!(direct.add(2, 1, Xyz::new(1.0, 1.0, 1.0)));
    // The image holds only the pixels; the cells come back scaled (squares by scale^2).
    assert_eq!(direct.to_xyz(1.0).len(), 6);
    assert_eq!(direct.sensor_sums(2.0)[3], [3.0, 4.0, 16.0, 1.5]);
    // Through a buffered writer: bit for bit the same.
    let shared = Mutex::new(Film::with_sensor_cells(3, 2, 4).unwrap());
    {
        let mut w = FilmWriter::new(&shared);
        assert!(w.splat_sensor(3, [1.5, 2.0, 4.0, 0.75]));
        assert!(!w.splat_sensor(4, [1.0, 1.0, 1.0, 1.0]));
        assert!(w.splat(2, 1, Xyz::new(1.0, 1.0, 1.0)));
    }
    let shared = shared.into_inner().unwrap();
    assert_eq!(shared.sensor_sums(1.0), direct.sensor_sums(1.0));
    assert_eq!(shared.to_xyz(1.0), direct.to_xyz(1.0));
    // Films with different sensor cells do not merge.
    let mut other = Film::new(3, 2).unwrap();
    assert!(other.merge(&direct).is_err());
    let mut twice = direct.clone();
    twice.merge(&direct).unwrap();
    assert_eq!(twice.sensor_sums(1.0)[3], [3.0, 4.0, 8.0, 1.5]);
}

#[test]
fn the_pass_layer_sums_apart_from_the_pixels_and_merges_exactly() {
    let mut direct = Film::with_pass_layer(3, 2, 1).unwrap();
    assert!(direct.has_pass_layer() && !Film::new(3, 2).unwrap().has_pass_layer());
    assert!(direct.add(1, 0, Xyz::new(1.0, 2.0, 3.0)));
    assert!(direct.add_pass(1, 0, Xyz::new(0.5, 0.25, 0.125)));
    assert!(direct.add_pass(2, 1, Xyz::new(4.0, 4.0, 4.0)));
    assert!(!direct.add_pass(3, 0, Xyz::new(1.0, 1.0, 1.0)), "outside the film");
    assert!(!direct.add_pass(0, 0, Xyz::new(f64::INFINITY, 1.0, 1.0)));
    assert!(direct.add_sensor(0, [7.0, 7.0, 49.0, 3.0]));
    assert_eq!((direct.rejected(), direct.accepted()), (2, 5));
    // Whole passes: both layers together, exactly; the sensor cell stays apart.
    let image = direct.to_xyz(2.0);
    assert_eq!(image[1], Xyz::new(3.0, 4.5, 6.25));
    assert_eq!(image[5], Xyz::new(8.0, 8.0, 8.0));
    assert_eq!(direct.sensor_sums(1.0)[0], [7.0, 7.0, 49.0, 3.0]);
    // Each layer normalised on its own.
    let layers = direct.to_xyz_layers(|i| if i == 1 { 10.0 } else { 0.0 }, 100.0);
    assert_eq!(layers[1], Xyz::new(60.0, 45.0, 42.5));
    assert_eq!(layers[5], Xyz::new(400.0, 400.0, 400.0));
    assert_eq!(layers[0], Xyz::default());
    // A film without the layer adds per-pass contributions to the pixel: the same image.
    let mut plain = Film::with_sensor_cells(3, 2, 1).unwrap();
    assert!(plain.add(1, 0, Xyz::new(1.0, 2.0, 3.0)));
    assert!(plain.add_pass(1, 0, Xyz::new(0.5, 0.25, 0.125)));
    assert!(plain.add_pass(2, 1, Xyz::new(4.0, 4.0, 4.0)));
    assert_eq!(plain.to_xyz(2.0), image);
    // Through a buffered writer with the estimate's tally: bit for bit the same film, and the
    // estimate counts a pass-layer contribution at its pixel.
    let shared = Mutex::new(Film::with_pass_layer(3, 2, 1).unwrap());
    let moments = Mutex::new(Moments::new(3, 2).unwrap());
    {
        let mut w = FilmWriter::with_moments(&shared, &moments).unwrap();
        assert!(w.splat(1, 0, Xyz::new(1.0, 2.0, 3.0)));
        assert!(w.splat_pass(1, 0, Xyz::new(0.5, 0.25, 0.125)));
        assert!(w.splat_pass(2, 1, Xyz::new(4.0, 4.0, 4.0)));
        assert!(!w.splat_pass(3, 0, Xyz::new(1.0, 1.0, 1.0)));
        assert!(!w.splat_pass(0, 0, Xyz::new(f64::INFINITY, 1.0, 1.0)));
        assert!(w.splat_sensor(0, [7.0, 7.0, 49.0, 3.0]));
        w.end_chunk(0, 6);
    }
    let shared = shared.into_inner().unwrap();
    assert_eq!(shared, direct);
    let mut expected = Moments::new(3, 2).unwrap();
    expected.add_chunk(0, [(1, [1.5, 2.25, 3.125]), (5, [4.0, 4.0, 4.0])], 6);
    assert_eq!(moments.into_inner().unwrap(), expected);
    // Merging needs the same layers; the same film twice doubles both.
    assert!(matches!(plain.merge(&direct), Err(FilmError::LayerMismatch(..))));
    let mut twice = direct.clone();
    twice.merge(&direct).unwrap();
    assert_eq!(twice.to_xyz(1.0)[5], Xyz::new(8.0, 8.0, 8.0));
    assert_eq!(twice.check_sums(), Ok(()));
    // A forged negative pass-layer sum is found.
    let mut forged = direct.clone();
    forged.pass_sums[4][1] = ExactSum(-1);
    assert!(forged.check_sums().unwrap_err().contains("pass-layer sum 4"));
    forged.pass_sums.pop();
    assert!(forged.check_sums().unwrap_err().contains("pass layer holds 5 sums for 6 pixels"));
}

#[test]
fn film_bytes_are_48_per_pixel() {
    let b = Film::bytes_for(8192, 4096);
    assert!((48 << 25..(48 << 25) + 1024).contains(&b), "{b}");
    let layered = Film::bytes_with_pass_layer(8192, 4096);
    assert!((96 << 25..(96 << 25) + 1024).contains(&layered), "{layered}");
    assert_eq!(Film::bytes_for(u32::MAX, u32::MAX), u64::MAX);
}

#[test]
fn fixed_point_rounding_is_the_library_round() {
    // Halves, both signs, every binade from 2^-80 to 2^62, and the fast path's edges.
    let mut values = vec![0.0, -0.0, 0.5, -0.5, 1.5, 2.5, -2.5, 4503599627370495.5];
    for e in -80..=62 {
        let p = 2f64.powi(e);
        for m in [1.0, 1.1, 1.5, 1.75, 1.999_999_999] {
            values.extend([p * m, -p * m, (p * m).next_up(), (p * m).next_down()]);
        }
    }
    for x in values {
        if let Some(fixed) = to_fixed(x) {
            assert_eq!(fixed, (x * SCALE).round() as i128, "{x:e}");
        }
    }
}
