//! The camera against its closed forms: projection, importance, lens sampling and densities.
use super::*;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_sampling::uniform;

fn camera(fov_axis: FovAxis) -> PinholeCamera {
    PinholeCamera::new(CameraRepr {
        position: DVec3::new(0.0, 1.0, 4.0),
        look_at: DVec3::new(0.0, 1.0, 0.0),
        up: DVec3::Y,
        fov: 40.0,
        fov_axis,
        width: 64,
        height: 48,
        aperture_radius: 0.0,
        focus_distance: None,
    })
    .unwrap()
}

#[test]
fn rays_and_projections_are_inverse() {
    let cam = camera(FovAxis::Vertical);
    for (px, py) in [(0.5, 0.5), (32.0, 24.0), (63.9, 47.9), (10.25, 40.75)] {
        let d = cam.direction(px, py);
        let p = cam.position() + d * 3.7;
        let proj = cam.project(p).unwrap();
        assert_eq!((proj.x, proj.y), (px as u32, py as u32));
        assert!((proj.to_camera + d).length() < 1e-12);
    }
    // The image centre looks at look_at; up is up and right is +x.
    assert!((cam.direction(32.0, 24.0) - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12);
    assert!(cam.direction(32.0, 0.0).y > 0.0 && cam.direction(63.0, 24.0).x > 0.0);
    assert!(cam.project(DVec3::new(0.0, 1.0, 5.0)).is_none(), "behind the camera");
}

#[test]
fn fov_axes_span_the_named_axis() {
    let h = camera(FovAxis::Horizontal);
    let edge = h.direction(0.0, 24.0);
    assert!((edge.dot(DVec3::new(0.0, 0.0, -1.0)).acos().to_degrees() - 20.0).abs() < 1e-9);
    let v = camera(FovAxis::Vertical);
    let edge = v.direction(32.0, 0.0);
    assert!((edge.dot(DVec3::new(0.0, 0.0, -1.0)).acos().to_degrees() - 20.0).abs() < 1e-9);
    let d = camera(FovAxis::Diagonal);
    let corner = d.direction(0.0, 0.0);
    assert!((corner.dot(DVec3::new(0.0, 0.0, -1.0)).acos().to_degrees() - 20.0).abs() < 1e-9);
}

#[test]
fn importance_integrates_to_the_pixel_measurement() {
    // A point of unit radiance filling the view at distance r, facing the camera: the sum of
    // importance * cos_x * dA over the plane behind one pixel equals 1 (mean radiance 1).
    let cam = camera(FovAxis::Vertical);
    let z = -2.0; // the plane z = -2, 6 m in front of the pinhole
    let (mut sum, n) = (0.0, 400);
    // Integrate over the plane patch seen by pixel (40, 10) with the midpoint rule.
    let corners = [cam.direction(40.0, 10.0), cam.direction(41.0, 11.0)];
    let hit = |d: DVec3| cam.position() + d * ((z - cam.position().z) / d.z);
    let (a, b) = (hit(corners[0]), hit(corners[1]));
    let (dx, dy) = ((b.x - a.x) / n as f64, (b.y - a.y) / n as f64);
    for i in 0..n {
        for j in 0..n {
            let p = DVec3::new(a.x + dx * (i as f64 + 0.5), a.y + dy * (j as f64 + 0.5), z);
            let proj = cam.project(p).unwrap();
            let cos_x = proj.to_camera.z.abs();
            sum += proj.importance * cos_x * (dx * dy).abs();
        }
    }
    assert!((sum - 1.0).abs() < 1e-3, "{sum}");
}

#[test]
fn invalid_cameras_name_the_field() {
    let mut r = camera(FovAxis::Vertical).repr;
    r.fov = 180.0;
    assert!(PinholeCamera::new(r.clone()).unwrap_err().to_string().starts_with("camera.fov"));
    r.fov = 40.0;
    r.up = DVec3::new(0.0, 0.0, 1.0);
    assert!(PinholeCamera::new(r.clone()).unwrap_err().to_string().starts_with("camera.up"));
    r.up = DVec3::Y;
    r.look_at = r.position;
    assert!(PinholeCamera::new(r.clone()).unwrap_err().to_string().starts_with("camera.look_at"));
    let e = serde_json::from_str::<PinholeCamera>(
        r#"{"position": [0,0,0], "look_at": [0,0,-1], "fov": 40, "width": 0, "height": 4}"#,
    )
    .unwrap_err();
    assert!(e.to_string().contains("camera.width"), "{e}");
}

fn camera_error(position: [f64; 3], look_at: [f64; 3], up: [f64; 3]) -> String {
    let mut r = camera(FovAxis::Vertical).repr;
    r.position = DVec3::from_array(position);
    r.look_at = DVec3::from_array(look_at);
    r.up = DVec3::from_array(up);
    PinholeCamera::new(r).map_or_else(|e| e.to_string(), |_| String::new())
}

#[test]
fn huge_or_tiny_vectors_are_judged_on_direction_and_overflow_blames_the_points() {
    // A far but finite pinhole is a valid camera; the old check blamed `up`.
    assert_eq!(camera_error([0.0, 0.0, 1e300], [0.0; 3], [0.0, 1.0, 0.0]), "");
    assert_eq!(camera_error([0.0, 0.0, 1e-320], [0.0; 3], [0.0, 1e300, 0.0]), "");
    assert_eq!(camera_error([0.0, 0.0, 1.0], [0.0; 3], [0.0, 1e-320, 0.0]), "");
    let e = camera_error([0.0, 0.0, 1.7e308], [0.0, 0.0, -1.7e308], [0.0, 1.0, 0.0]);
    assert!(e.starts_with("camera.position") && e.contains("too far apart"), "{e}");
    let e = camera_error([0.0, 0.0, 1.0e308], [0.0, 0.0, -1.7e308], [0.0, 1.0, 0.0]);
    assert!(e.starts_with("camera.look_at") && e.contains("too far apart"), "{e}");
    let e = camera_error([0.0, 0.0, 1e300], [0.0; 3], [0.0, 0.0, 1e300]);
    assert!(e.starts_with("camera.up") && e.contains("parallel"), "{e}");
    let e = camera_error([0.0, 0.0, 1.0], [0.0; 3], [0.0, -0.0, 0.0]);
    assert!(e.starts_with("camera.up") && e.contains("non-zero"), "{e}");
    let e = camera_error([0.0, 0.0, f64::INFINITY], [0.0; 3], [0.0, 1.0, 0.0]);
    assert!(e.starts_with("camera.position") && e.contains("finite"), "{e}");
    let e = camera_error([0.0, 0.0, 1.0], [0.0, f64::NAN, 0.0], [0.0, 1.0, 0.0]);
    assert!(e.starts_with("camera.look_at") && e.contains("finite"), "{e}");
}

fn lens_camera(aperture_radius: f64, focus_distance: f64) -> PinholeCamera {
    let mut r = camera(FovAxis::Vertical).repr;
    r.aperture_radius = aperture_radius;
    r.focus_distance = Some(focus_distance);
    PinholeCamera::new(r).unwrap()
}

fn u2(rng: &mut Pcg64) -> [f64; 2] {
    [uniform(rng), uniform(rng)]
}

/// A random pixel and an offset in [0.05, 0.95)^2 within it (away from the pixel's edges,
/// where rounding may move a point to the neighbour).
fn pixel_and_offset(cam: &PinholeCamera, rng: &mut Pcg64) -> (u32, u32, [f64; 2]) {
    let x = ((uniform(rng) * f64::from(cam.width())) as u32).min(cam.width() - 1);
    let y = ((uniform(rng) * f64::from(cam.height())) as u32).min(cam.height() - 1);
    (x, y, [0.05 + 0.9 * uniform(rng), 0.05 + 0.9 * uniform(rng)])
}

#[test]
fn pinhole_generate_ray_is_direction_from_the_pinhole() {
    let mut rng = Pcg64::seed_from_u64(1);
    for cam in [camera(FovAxis::Horizontal), camera(FovAxis::Diagonal)] {
        assert!(cam.is_pinhole());
        for _ in 0..1000 {
            let (x, y) = ((uniform(&mut rng) * 64.0) as u32, (uniform(&mut rng) * 48.0) as u32);
            let (u, u_lens) = (u2(&mut rng), u2(&mut rng));
            let ray = cam.generate_ray(x, y, u, u_lens);
            assert_eq!(ray.origin, cam.position());
            assert_eq!(ray.direction, cam.direction(f64::from(x) + u[0], f64::from(y) + u[1]));
        }
    }
}

#[test]
fn sample_wi_round_trips_through_generate_ray() {
    let mut rng = Pcg64::seed_from_u64(2);
    for cam in [camera(FovAxis::Vertical), lens_camera(0.05, 3.0), lens_camera(0.3, 7.0)] {
        for _ in 0..2000 {
            // A point in view: on a camera ray, 0.5 to 10 m from the lens.
            let (x, y, u_film) = pixel_and_offset(&cam, &mut rng);
            let u_lens = u2(&mut rng);
            let ray = cam.generate_ray(x, y, u_film, u_lens);
            assert!((ray.direction.length() - 1.0).abs() < 1e-12);
            let t = 0.5 + 9.5 * uniform(&mut rng);
            let point = ray.origin + ray.direction * t;
            // Seen from the point through the same lens point: the same pixel and lens point.
            let s = cam.sample_wi(point, u_lens).unwrap();
            assert_eq!((s.x, s.y), (x, y), "{cam:?}");
            assert!((s.position - ray.origin).length() < 1e-12);
            assert!((s.to_camera + ray.direction).length() < 1e-9);
            assert!((s.distance - t).abs() < 1e-9 * t);
            // And back: the film offset that sample_wi found regenerates the ray to the point.
            let l = PinholeCamera::lens_disk(u_lens);
            let l = if cam.is_pinhole() { [0.0, 0.0] } else { l };
            let (px, py, _) = cam.raster(l, -s.to_camera).unwrap();
            assert_eq!((px as u32, py as u32), (s.x, s.y));
            let offset = [px - f64::from(s.x), py - f64::from(s.y)];
            assert!((offset[0] - u_film[0]).abs() < 1e-6 && (offset[1] - u_film[1]).abs() < 1e-6);
            let back = cam.generate_ray(s.x, s.y, offset, u_lens);
            assert_eq!(back.origin, s.position);
            assert!((back.direction + s.to_camera).length() < 1e-9);
        }
    }
}

#[test]
fn sample_wi_rejects_points_behind_on_or_outside_the_camera() {
    for cam in [camera(FovAxis::Vertical), lens_camera(0.1, 3.0)] {
        let u = [0.3, 0.7];
        assert!(cam.sample_wi(DVec3::new(0.0, 1.0, 5.0), u).is_none(), "behind");
        assert!(cam.sample_wi(cam.lens_point(PinholeCamera::lens_disk(u)), u).is_none());
        assert!(cam.sample_wi(DVec3::new(0.0, 1.0, 4.0), [0.5, 0.5]).is_none(), "lens centre");
        assert!(cam.sample_wi(DVec3::new(10.0, 1.0, 3.0), u).is_none(), "outside the image");
        assert!(cam.sample_wi(DVec3::new(0.0, 1.0, 1.0), u).is_some());
    }
}

#[test]
fn pinhole_sample_wi_is_project() {
    let cam = camera(FovAxis::Vertical);
    let mut rng = Pcg64::seed_from_u64(3);
    for _ in 0..1000 {
        let (x, y, u) = pixel_and_offset(&cam, &mut rng);
        let d = cam.direction(f64::from(x) + u[0], f64::from(y) + u[1]);
        let point = cam.position() + d * (0.1 + 20.0 * uniform(&mut rng));
        let p = cam.project(point).unwrap();
        let s = cam.sample_wi(point, u2(&mut rng)).unwrap();
        assert_eq!((s.x, s.y, s.position), (p.x, p.y, cam.position()));
        assert_eq!((s.to_camera, s.distance), (p.to_camera, p.distance));
        assert_eq!(s.importance, p.importance);
        assert_eq!(s.pdf, 1.0);
    }
}

/// Monte Carlo estimate of the integral of `pdf_we`'s direction density over all directions
/// from `origin`, by uniform directions in a cone about the view that covers the image; returns
/// (mean, standard error).
fn integrate_pdf_we(cam: &PinholeCamera, origin: DVec3, seed: u64) -> (f64, f64) {
    let corner = cam.half_width.hypot(cam.half_height).atan() * 1.05;
    let one_minus_cos = spectrace_sampling::one_minus_cos(corner);
    let frame = spectrace_sampling::Frame::from_normal(cam.forward);
    let mut rng = Pcg64::seed_from_u64(seed);
    let n = 200_000;
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let local = spectrace_sampling::sample_uniform_cone(u2(&mut rng), one_minus_cos);
        let ray = CameraRay { origin, direction: frame.to_world(local) };
        let v = cam.pdf_we(&ray).1 / spectrace_sampling::pdf_uniform_cone(one_minus_cos);
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / f64::from(n);
    (mean, ((sum2 / f64::from(n) - mean * mean) / f64::from(n)).sqrt())
}

#[test]
fn pdf_we_direction_integrates_to_one_over_the_image() {
    let cam = camera(FovAxis::Diagonal);
    assert_eq!(cam.pdf_we(&cam.generate_ray(3, 4, [0.5, 0.5], [0.0; 2])).0, 1.0);
    let (mean, sigma) = integrate_pdf_we(&cam, cam.position(), 4);
    assert!((mean - 1.0).abs() < 3.0 * sigma, "pinhole: {mean} +- {sigma}");
    // From any point of a lens, the image spans the same solid-angle measure.
    let cam = lens_camera(0.2, 2.5);
    let ray = cam.generate_ray(3, 4, [0.5, 0.5], [0.9, 0.2]);
    assert!((cam.pdf_we(&ray).0 * PI * 0.2 * 0.2 - 1.0).abs() < 1e-12);
    let (mean, sigma) = integrate_pdf_we(&cam, ray.origin, 5);
    assert!((mean - 1.0).abs() < 3.0 * sigma, "lens: {mean} +- {sigma}");
    // Backwards and outside the image: 0.
    let back = CameraRay { origin: cam.position(), direction: -cam.forward };
    assert_eq!(cam.pdf_we(&back).1, 0.0);
    let side = CameraRay { origin: cam.position(), direction: cam.right };
    assert_eq!(cam.pdf_we(&side).1, 0.0);
    assert!((cam.image_area() - 4.0 * cam.half_width * cam.half_height).abs() < 1e-12);
}

#[test]
fn pdf_we_matches_the_image_area_density_of_generated_rays() {
    // pdf_direction * image_area * cos^3 = 1 inside the image, for pinhole and lens rays.
    let mut rng = Pcg64::seed_from_u64(6);
    for cam in [camera(FovAxis::Horizontal), lens_camera(0.1, 2.0)] {
        for _ in 0..200 {
            let (x, y, u) = pixel_and_offset(&cam, &mut rng);
            let ray = cam.generate_ray(x, y, u, u2(&mut rng));
            let cos = ray.direction.dot(cam.forward);
            let (_, pdf) = cam.pdf_we(&ray);
            assert!((pdf * cam.image_area() * cos.powi(3) - 1.0).abs() < 1e-9, "{pdf}");
        }
    }
}

#[test]
fn thin_lens_focus_plane_is_sharp() {
    let cam = lens_camera(0.1, 3.0);
    assert!(!cam.is_pinhole());
    let mut rng = Pcg64::seed_from_u64(7);
    for _ in 0..200 {
        let (x, y, u) = pixel_and_offset(&cam, &mut rng);
        let d = cam.direction(f64::from(x) + u[0], f64::from(y) + u[1]);
        let point = cam.position() + d * (3.0 / d.dot(cam.forward));
        let p = cam.project(point).unwrap();
        assert_eq!((p.x, p.y), (x, y));
        for _ in 0..64 {
            let s = cam.sample_wi(point, u2(&mut rng)).unwrap();
            assert_eq!((s.x, s.y), (x, y));
        }
    }
    // Off the focus plane the lens blurs: some lens points see a neighbouring pixel.
    let d = cam.direction(40.5, 10.5);
    let near = cam.position() + d * (1.0 / d.dot(cam.forward));
    let pixels: std::collections::HashSet<(u32, u32)> =
        (0..64).filter_map(|_| cam.sample_wi(near, u2(&mut rng))).map(|s| (s.x, s.y)).collect();
    assert!(pixels.len() > 1, "{pixels:?}");
}

#[test]
fn thin_lens_importance_of_an_in_focus_patch_equals_the_pinhole_answer() {
    // A Lambertian patch of unit radiance on the focus plane covering pixel (40, 10) exactly:
    // the pixel's value is 1 for a pinhole and for a lens focused on it. Midpoint rule over the
    // patch, one random lens point per quadrature point.
    let pinhole = camera(FovAxis::Vertical);
    let lens = lens_camera(0.2, 3.0);
    let z = 1.0; // the focus plane, 3 m in front of the lens
    let hit = |d: DVec3| pinhole.position() + d * ((z - pinhole.position().z) / d.z);
    let (a, b) = (hit(pinhole.direction(40.0, 10.0)), hit(pinhole.direction(41.0, 11.0)));
    let n = 200;
    let (dx, dy) = ((b.x - a.x) / f64::from(n), (b.y - a.y) / f64::from(n));
    let mut rng = Pcg64::seed_from_u64(8);
    let (mut with_pinhole, mut with_lens) = (0.0, 0.0);
    for i in 0..n {
        for j in 0..n {
            let p = DVec3::new(a.x + dx * (f64::from(i) + 0.5), a.y + dy * (f64::from(j) + 0.5), z);
            let area = (dx * dy).abs();
            let pr = pinhole.project(p).unwrap();
            if (pr.x, pr.y) == (40, 10) {
                with_pinhole += pr.importance * pr.to_camera.z.abs() * area;
            }
            let s = lens.sample_wi(p, u2(&mut rng)).unwrap();
            if (s.x, s.y) == (40, 10) {
                with_lens += s.importance * s.to_camera.z.abs() * area;
            }
        }
    }
    assert!((with_pinhole - 1.0).abs() < 1e-3, "{with_pinhole}");
    assert!((with_lens - with_pinhole).abs() < 1e-3, "{with_lens} vs {with_pinhole}");
}

#[test]
fn thin_lens_light_tracing_estimate_matches_camera_rays_out_of_focus() {
    // A square Lambertian patch of unit radiance facing the camera, 5 m away while the lens
    // focuses at 3 m: the blurred value of a pixel at its edge, once from camera rays (the
    // fraction of rays that hit the patch) and once from points on the patch connected by
    // sample_wi (importance * cos_x * area). Agreement within 4 combined standard errors,
    // which are checked to be under 0.4% of the value (so a 2% error in the importance fails).
    let cam = lens_camera(0.3, 3.0);
    let (depth, z) = (5.0, -1.0);
    let (half, centre) = (0.2, DVec3::new(0.0, 1.0, z));
    let (px, py) = (34, 22);
    let n = 4_000_000_u32;
    let mut rng = Pcg64::seed_from_u64(9);
    let mut hits = 0_u32;
    for _ in 0..n {
        let ray = cam.generate_ray(px, py, u2(&mut rng), u2(&mut rng));
        let t = (z - ray.origin.z) / ray.direction.z;
        let q = ray.origin + ray.direction * t;
        if (q.x - centre.x).abs() < half && (q.y - centre.y).abs() < half {
            hits += 1;
        }
    }
    let camera_rays = f64::from(hits) / f64::from(n);
    let sigma_rays = (camera_rays * (1.0 - camera_rays) / f64::from(n)).sqrt();
    // Seen through lens point l (unit disk), a point at depth D whose pinhole image is s0
    // lands at s0 + r (1/f - 1/D) l on the image plane: only the patch points whose pinhole
    // image lies within that blur radius of the pixel can reach it, so sample those alone.
    let blur = 0.3 * (1.0 / 3.0 - 1.0 / depth) * 1.001;
    let to_plane = |raster_x: f64, raster_y: f64| {
        let sx = (2.0 * raster_x / 64.0 - 1.0) * cam.half_width;
        let sy = (1.0 - 2.0 * raster_y / 48.0) * cam.half_height;
        (sx, sy)
    };
    let (s_left, s_top) = to_plane(f64::from(px), f64::from(py));
    let (s_right, s_bottom) = to_plane(f64::from(px + 1), f64::from(py + 1));
    let x_range = (
        (depth * (s_left - blur)).max(centre.x - half),
        (depth * (s_right + blur)).min(centre.x + half),
    );
    let y_range = (
        (1.0 + depth * (s_bottom - blur)).max(centre.y - half),
        (1.0 + depth * (s_top + blur)).min(centre.y + half),
    );
    let area = (x_range.1 - x_range.0) * (y_range.1 - y_range.0);
    assert!(area > 0.0 && area < 0.6 * 4.0 * half * half, "{x_range:?} {y_range:?}");
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let [a, b] = u2(&mut rng);
        let p = DVec3::new(
            x_range.0 + a * (x_range.1 - x_range.0),
            y_range.0 + b * (y_range.1 - y_range.0),
            z,
        );
        if let Some(s) = cam.sample_wi(p, u2(&mut rng))
            && (s.x, s.y) == (px, py)
        {
            let v = s.importance * s.to_camera.z * area;
            sum += v;
            sum2 += v * v;
        }
    }
    let light = sum / f64::from(n);
    let sigma_light = ((sum2 / f64::from(n) - light * light) / f64::from(n)).sqrt();
    assert!(camera_rays > 0.1 && camera_rays < 0.9, "not at the blurred edge: {camera_rays}");
    let sigma = sigma_rays.hypot(sigma_light);
    assert!((light - camera_rays).abs() < 4.0 * sigma, "{light} vs {camera_rays} (sigma {sigma})");
    assert!(sigma < 0.004 * camera_rays, "too noisy to detect a 2% error: {sigma}");
}

#[test]
fn invalid_lenses_name_the_field() {
    let error = |aperture_radius: f64, focus_distance: Option<f64>| {
        let mut r = camera(FovAxis::Vertical).repr;
        r.aperture_radius = aperture_radius;
        r.focus_distance = focus_distance;
        PinholeCamera::new(r).map_or_else(|e| e.to_string(), |_| String::new())
    };
    for bad in [-0.1, f64::NAN, f64::INFINITY, -f64::INFINITY, 1e-200, 1e200] {
        let e = error(bad, Some(2.0));
        assert!(e.starts_with("camera.aperture_radius"), "{bad}: {e}");
    }
    let e = error(0.1, None);
    assert!(e.starts_with("camera.focus_distance") && e.contains("required"), "{e}");
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = error(0.1, Some(bad));
        assert!(e.starts_with("camera.focus_distance"), "{bad}: {e}");
        // Checked even without an aperture, where it has no effect.
        let e = error(0.0, Some(bad));
        assert!(e.starts_with("camera.focus_distance"), "{bad}: {e}");
    }
    let e = error(1e100, Some(1e-300));
    assert!(e.starts_with("camera.focus_distance") && e.contains("overflows"), "{e}");
    assert_eq!(error(0.0, None), "");
    assert_eq!(error(-0.0, None), "");
    assert_eq!(error(0.01, Some(1e6)), "");
    let e = error(1e200, Some(1.0));
    assert!(e.contains("lens area"), "{e}");

    let json = |extra: &str| {
        serde_json::from_str::<PinholeCamera>(&format!(
            r#"{{"position": [0,0,0], "look_at": [0,0,-1], "fov": 40, "width": 4, "height": 4{extra}}}"#
        ))
    };
    let e = json(r#", "aperture_radius": -1"#).unwrap_err().to_string();
    assert!(e.contains("camera.aperture_radius"), "{e}");
    let e = json(r#", "aperture_radius": 0.1"#).unwrap_err().to_string();
    assert!(e.contains("camera.focus_distance"), "{e}");
    let e = json(r#", "aperture_radius": 0.1, "focus_distance": 0"#).unwrap_err().to_string();
    assert!(e.contains("camera.focus_distance"), "{e}");
    let e = json(r#", "aperture": 0.1"#).unwrap_err().to_string();
    assert!(e.contains("unknown field") && e.contains("aperture"), "{e}");
}

#[test]
fn lens_fields_round_trip_and_pinholes_are_written_as_before() {
    let base = r#"{"position":[0.0,0.0,0.0],"look_at":[0.0,0.0,-1.0],"up":[0.0,1.0,0.0],"fov":40.0,"fov_axis":"horizontal","width":4,"height":4"#;
    let pinhole: PinholeCamera = serde_json::from_str(&format!("{base}}}")).unwrap();
    assert_eq!(serde_json::to_string(&pinhole).unwrap(), format!("{base}}}"));
    let text = format!(r#"{base},"aperture_radius":0.05,"focus_distance":2.5}}"#);
    let lens: PinholeCamera = serde_json::from_str(&text).unwrap();
    assert!(!lens.is_pinhole());
    assert_eq!(serde_json::to_string(&lens).unwrap(), text);
}
