//! A time budget that runs out inside a camera pass: the pass stops, its pixels keep their own
//! sample counts, and the image is still the exact mean per pixel. The same for a `--beams`
//! budget that is not a whole number of passes: the last pass is cut where the budget ends.
//!
//! The renders here cut passes deterministically: a chunk given a deadline that has already
//! passed stops at the first look at the clock, after its first 64 items (two rows of a 32-pixel
//! image, from the pass's scrambled start). A render of a few whole passes and many such cut
//! ones gives pixels from 1 to about 10 samples, in rows that differ from pass to pass but not
//! from seed to seed, so a wrong normalisation is a bias that more seeds do not average out.
//! Each estimator's image must then agree with the closed form, or with whole-pass renders of
//! the same work, as the matrix of `integrators.rs` asks: every 8x8 block within
//! [`Z_BLOCK`] standard errors, the image mean within [`Z_CLOSED_FORM`] (closed form) or
//! the row's `mean_z` (between renders). And the check must have power: the image normalised
//! as if every pass were whole (the film over the average count) must fail it.

use std::time::Instant;

use spectrace_renderer::{decide_effects, with_integrator};
use spectrace_spectrum::Xyz;
use spectrace_tracer::{ChunkWork, Film, IntegratorChoice, RenderOutput, TraceStats};

use crate::integrators::{
    Row, Z_BLOCK, Z_CLOSED_FORM, blocks, five_lights, lit_plane, region_stats,
};
use crate::rendering::render_with;

/// Items a cut chunk does: the render loop's look at the clock comes every 64 items.
const CUT_ITEMS: u64 = 64;

/// What [`cut_render`] makes of one seed: the image as the renderer normalises it (each pixel
/// over its own sample count) and as if every pass were whole (the film over the mean count).
struct CutImages {
    exact: Vec<Xyz>,
    naive: Vec<Xyz>,
}

/// Renders `whole` whole passes and `cuts` passes cut after [`CUT_ITEMS`] items of `row`'s scene
/// with `choice` into a film with a pass layer, as the render loop does under a time budget.
fn cut_render(row: &Row, choice: IntegratorChoice, whole: u64, cuts: u64, seed: u64) -> CutImages {
    let scene = &row.scene;
    let effects = decide_effects(scene, None);
    let images = with_integrator(scene, choice, effects, |tracer| {
        let (w, h) = tracer.resolution();
        let items = u64::from(w) * u64::from(h);
        let mut film = Film::with_pass_layer(w, h, 0).unwrap();
        let mut stats = TraceStats::default();
        let mut cut = Vec::new();
        for chunk in 0..whole {
            let s = tracer.render_chunk(
                ChunkWork { seed, chunk, items, deadline: None, ends_pass: true },
                &mut film,
            );
            assert_eq!(s.beams, items, "{}: a pass without a deadline is whole", row.name);
            stats.merge(&s);
        }
        let passed = Instant::now();
        for chunk in whole..whole + cuts {
            let work = ChunkWork { seed, chunk, items, deadline: Some(passed), ends_pass: true };
            let s = tracer.render_chunk(work, &mut film);
            assert_eq!(s.beams, CUT_ITEMS, "{}: a pass past its deadline stops", row.name);
            stats.merge(&s);
            cut.push((chunk, s.beams));
        }
        let out = RenderOutput {
            film,
            beams: stats.beams,
            stats,
            chunks: (0..whole + cuts).collect(),
            seconds: 0.0,
            moments: None,
            cut,
        };
        CutImages {
            exact: tracer.image(&out),
            naive: out.film.to_xyz(tracer.image_scale(out.beams)),
        }
    });
    spectrace_lights::LightSource::reset_count(&scene.lights);
    images
}

/// The largest deviation of an 8x8 block of `images` from `reference` (mean and standard error
/// per block mask), in standard errors; asserts each within [`Z_BLOCK`] when `assert` is set.
fn worst_block(
    row: &Row,
    images: &[Vec<Xyz>],
    reference: &dyn Fn(&[bool]) -> (f64, f64),
    assert: bool,
) -> f64 {
    let (w, h) = (row.scene.camera.width() as usize, row.scene.camera.height() as usize);
    let mut worst = 0.0f64;
    for ((bx, by), mask) in blocks(w, h, &vec![true; w * h]) {
        let (mean, se) = region_stats(images, &mask).unwrap();
        let (want, want_se) = reference(&mask);
        let z = (mean - want).abs() / se.hypot(want_se);
        assert!(
            !assert || z <= Z_BLOCK,
            "{}: block ({bx}, {by}): {mean} vs {want} ({z:.1} standard errors)",
            row.name
        );
        worst = worst.max(z);
    }
    worst
}

/// Cuts passes in renders of `row` by `choice` and checks the images against the closed form
/// or, without one, against whole-pass renders of the same number of samples; with `power`,
/// that the image normalised as if every pass were whole fails the check.
fn check_cut(row: &Row, choice: IntegratorChoice, power: bool) {
    let (w, h) = (row.scene.camera.width() as usize, row.scene.camera.height() as usize);
    let items = (w * h) as u64;
    let (whole, cuts) = (1, 4 * items / CUT_ITEMS);
    let renders: Vec<CutImages> =
        (0..row.seeds).map(|k| cut_render(row, choice, whole, cuts, 500 + k)).collect();
    let exact: Vec<Vec<Xyz>> = renders.iter().map(|r| r.exact.clone()).collect();
    let naive: Vec<Vec<Xyz>> = renders.iter().map(|r| r.naive.clone()).collect();
    let all = vec![true; w * h];
    let name = row.name;
    let (mean, se) = region_stats(&exact, &all).unwrap();
    let (z_mean, worst_naive) = match &row.closed_form {
        Some((pixel, allowance)) => {
            let expected: Vec<f64> = (0..w * h).map(|p| pixel(&row.scene, p % w, p / w)).collect();
            // The closed form's quadrature allowance, as a standard error (it is at most 0.2%).
            let reference = |mask: &[bool]| {
                let n = mask.iter().filter(|k| **k).count() as f64;
                let v = expected.iter().zip(mask).filter(|(_, k)| **k).map(|(v, _)| v).sum::<f64>();
                (v / n, allowance * v / n)
            };
            worst_block(row, &exact, &reference, true);
            let (want, _) = reference(&all);
            ((mean - want).abs() / se, worst_block(row, &naive, &reference, false))
        }
        None => {
            let effort = (whole + 4) * items;
            let first = 900;
            let whole_passes: Vec<Vec<Xyz>> = (0..row.seeds)
                .map(|k| render_with(&row.scene, choice, effort, first + k).image)
                .collect();
            let reference = |mask: &[bool]| region_stats(&whole_passes, mask).unwrap();
            worst_block(row, &exact, &reference, true);
            let (want, want_se) = reference(&all);
            ((mean - want).abs() / se.hypot(want_se), worst_block(row, &naive, &reference, false))
        }
    };
    eprintln!(
        "{name}, {}: cut passes {z_mean:.2} standard errors from the reference; normalised as \
         whole passes, a block {worst_naive:.1}",
        choice.name()
    );
    let z_allowed = if row.closed_form.is_some() { Z_CLOSED_FORM } else { row.mean_z };
    assert!(z_mean <= z_allowed, "{name}: image mean {mean} is {z_mean:.1} standard errors off");
    assert!(se < row.sharp * mean, "{name}: the test must be sharp: standard error {se} of {mean}");
    assert!(
        !power || worst_naive > Z_BLOCK,
        "{name}: the test has no power: normalised as whole passes, no block is off by more \
         than {worst_naive:.1} standard errors"
    );
}

/// BDPT's light paths splatted to the camera count passes, its camera strategies pixel
/// samples: on the lit plane, both parts stay exact when passes are cut.
#[test]
fn bdpt_cut_inside_its_passes_keeps_the_closed_form() {
    check_cut(&lit_plane(), IntegratorChoice::Bdpt, true);
}

/// The path tracer's pixels each over their own count, on the lit plane.
#[test]
fn the_path_tracer_cut_inside_its_passes_keeps_the_closed_form() {
    check_cut(&lit_plane(), IntegratorChoice::Path, true);
}

/// Point lights in view: the path tracer splats them once per pass, weighted by the share of
/// the pass done; BDPT joins their light paths to the camera. Both against whole passes. On this
/// scene BDPT's image normalised as whole passes is within noise too (measured: 2.3 standard
/// errors in its worst block), so only the path tracer's check is asked to have power.
#[test]
fn cut_passes_with_point_lights_in_view_agree_with_whole_passes() {
    let row = five_lights();
    check_cut(&row, IntegratorChoice::Path, true);
    check_cut(&row, IntegratorChoice::Bdpt, false);
}

/// End to end: a BDPT render of 64 x 64 pixels whose budget (1 us) runs out inside its first
/// pass stops after the first 64 items, says how many pixels got no sample, and its two shards
/// merge into the same image, their cut chunks and pass layers validated and added.
#[test]
fn a_budget_that_ends_inside_the_first_pass_cuts_it_and_says_so() {
    use spectrace_renderer::{PartialFilm, RenderOptions, merge_parts, render_scene};
    let json = crate::rendering::POINT_OVER_PLANE
        .replace(r#""width": 32, "height": 32"#, r#""width": 64, "height": 64"#);
    assert!(json.contains(r#""width": 64"#));
    let s = crate::rendering::scene(&json);
    let out = crate::rendering::temp_dir("cut-first-pass");
    let options = |shard| RenderOptions {
        time: Some(1e-6),
        threads: Some(1),
        integrator: Some(IntegratorChoice::Bdpt),
        shard,
        out_dir: out.clone(),
        ..RenderOptions::default()
    };
    let whole = render_scene(&s, &options(None)).unwrap();
    assert_eq!((whole.beams, whole.chunks_cut), (CUT_ITEMS, 1));
    let warning = whole.warnings.iter().find(|w| w.contains("got no camera sample"));
    let expected = format!("{} of 4096 pixels", 4096 - CUT_ITEMS);
    assert!(warning.is_some_and(|w| w.contains(&expected)), "{:?}", whole.warnings);
    let mut parts = Vec::new();
    for k in 0..2 {
        let r = render_scene(&s, &options(Some((k, 2)))).unwrap();
        assert_eq!((r.beams, r.chunks_cut), (CUT_ITEMS, 1));
        let path = out.join(format!("inline.part-{k}-of-2.bin"));
        let part = PartialFilm::read(&path).unwrap();
        assert!(part.output.film.has_pass_layer());
        assert_eq!(part.output.cut, vec![(k, CUT_ITEMS)]);
        parts.push(path);
    }
    let merged = merge_parts(&parts, &out.join("merged")).unwrap();
    assert_eq!((merged.beams, merged.chunks_cut), (2 * CUT_ITEMS, 2));
    let expected = format!("{} of 4096 pixels", 4096 - 2 * CUT_ITEMS);
    assert!(merged.warnings.iter().any(|w| w.contains(&expected)), "{:?}", merged.warnings);
    // A cut that claims more items than its chunk holds is refused, naming the field.
    let mut part = PartialFilm::read(&parts[0]).unwrap();
    part.output.cut = vec![(0, 4096)];
    let err = PartialFilm::decode(&part.encode().unwrap()).unwrap_err();
    assert!(err.contains("output.cut"), "{err}");
    let _ = std::fs::remove_dir_all(&out);
}

/// `--beams N` for a camera estimator: exactly `N` samples, the last pass cut where the budget
/// ends (2.5 passes here: half the pixels get 3 samples, half 2), every pixel over its own
/// count; on the lit plane both camera estimators keep the closed form (normalised as whole
/// passes, half the image would be 20% off: the check has power by construction), and 3 shards
/// merge to the unsharded image, byte for byte.
#[test]
fn a_beams_budget_inside_a_pass_cuts_it_and_keeps_the_closed_form() {
    use spectrace_renderer::{RenderOptions, merge_parts, render_scene};
    let row = lit_plane();
    let (w, h) = (row.scene.camera.width() as usize, row.scene.camera.height() as usize);
    let pixels = (w * h) as u64;
    let budget = 5 * pixels / 2;
    let (pixel, allowance) = row.closed_form.as_ref().unwrap();
    let expected: Vec<f64> = (0..w * h).map(|p| pixel(&row.scene, p % w, p / w)).collect();
    let reference = |mask: &[bool]| {
        let n = mask.iter().filter(|k| **k).count() as f64;
        let v = expected.iter().zip(mask).filter(|(_, k)| **k).map(|(v, _)| v).sum::<f64>();
        (v / n, allowance * v / n)
    };
    for choice in [IntegratorChoice::Path, IntegratorChoice::Bdpt] {
        let renders: Vec<_> =
            (0..row.seeds).map(|k| render_with(&row.scene, choice, budget, 700 + k)).collect();
        for r in &renders {
            assert_eq!(r.output.beams, budget, "exactly the budget");
            assert_eq!(r.output.cut, vec![(2, pixels / 2)], "the third pass, cut at the budget");
        }
        let images: Vec<Vec<Xyz>> = renders.into_iter().map(|r| r.image).collect();
        let worst = worst_block(&row, &images, &reference, true);
        let (mean, se) = region_stats(&images, &vec![true; w * h]).unwrap();
        let (want, _) = reference(&vec![true; w * h]);
        eprintln!(
            "lit plane, {}: worst block {worst:.2}, mean {:.2} standard errors",
            choice.name(),
            (mean - want) / se
        );
        assert!((mean - want).abs() <= Z_CLOSED_FORM * se, "{}: {mean} vs {want}", choice.name());
        assert!(se < row.sharp * mean, "the test must be sharp: {se} of {mean}");
    }
    // Shards: the cut pass lands in one of them; merged, the same bytes as one render.
    let out = crate::rendering::temp_dir("beams-cut");
    let options = |shard, dir: &str| RenderOptions {
        beams: Some(budget),
        threads: Some(2),
        integrator: Some(IntegratorChoice::Bdpt),
        shard,
        out_dir: out.join(dir),
        ..RenderOptions::default()
    };
    let one = render_scene(&row.scene, &options(None, "one")).unwrap();
    assert_eq!((one.beams, one.chunks_cut), (budget, 1));
    let parts: Vec<_> = (0..3)
        .map(|k| {
            render_scene(&row.scene, &options(Some((k, 3)), "parts")).unwrap();
            out.join("parts").join(format!("inline.part-{k}-of-3.bin"))
        })
        .collect();
    let merged = merge_parts(&parts, &out.join("merged")).unwrap();
    assert_eq!((merged.beams, merged.chunks_cut), (budget, 1));
    let bytes = |dir: &str| std::fs::read(out.join(dir).join("inline.exr")).unwrap();
    assert!(bytes("one") == bytes("merged"), "the merged image differs from one render's");
    let _ = std::fs::remove_dir_all(&out);
}
