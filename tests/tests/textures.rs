//! Textures through the whole pipeline: a Mitsuba `checkerboard` and `bitmap` imported as a
//! `Textured` material, rendered, and compared pixel by pixel with untextured renders.

use spectrace_renderer::{RenderOptions, Scene, convert, import_mitsuba, render_in_memory};

use crate::rendering::temp_dir;

const SENSOR: &str = r#"<sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/></film></sensor>
    <integrator type="direct"/>"#;

/// A plane (a rectangle three units wide) with `reflectance`, lit by a point light.
fn plane(reflectance: &str) -> String {
    format!(
        r#"<scene version="3.0.0">{SENSOR}
        <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform>
          <bsdf type="twosided"><bsdf type="diffuse">{reflectance}</bsdf></bsdf></shape>
        <emitter type="point"><point name="position" value="0,0,3"/><spectrum name="intensity" value="5"/></emitter>
        </scene>"#
    )
}

fn render(test: &str, xml: &str) -> Vec<f64> {
    let dir = temp_dir(test);
    let path = dir.join("scene.xml");
    std::fs::write(&path, xml).unwrap();
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let options = RenderOptions { spp: Some(4), threads: Some(2), ..RenderOptions::default() };
    let r = render_in_memory(&scene, &options).unwrap();
    assert!(r.image.iter().all(|p| p.is_finite()));
    r.image.iter().map(|p| p.y).collect()
}

/// Each camera sample draws the same random numbers whatever the albedo, so a checkerboard of
/// greys 0.8 and 0.2 renders every pixel wholly inside a square exactly (to rounding) as the
/// uniform plane of that grey does; pixels straddling an edge lie between. Both squares must
/// cover at least a fifth of the image, and at least 80% of the pixels must match one plane.
#[test]
fn a_checkerboard_renders_each_square_as_its_uniform_grey() {
    let board = r#"<texture type="checkerboard" name="reflectance">
        <float name="color0" value="0.8"/><float name="color1" value="0.2"/></texture>"#;
    let textured = render("texture-board", &plane(board));
    let light = render("texture-light", &plane(r#"<float name="reflectance" value="0.8"/>"#));
    let dark = render("texture-dark", &plane(r#"<float name="reflectance" value="0.2"/>"#));
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()) + 1e-300;
    let (mut n_light, mut n_dark) = (0, 0);
    for i in 0..textured.len() {
        let t = textured[i];
        if same(t, light[i]) && light[i] != dark[i] {
            n_light += 1;
        } else if same(t, dark[i]) && light[i] != dark[i] {
            n_dark += 1;
        } else {
            let (lo, hi) = (dark[i].min(light[i]), dark[i].max(light[i]));
            assert!(
                t >= lo * (1.0 - 1e-12) && t <= hi * (1.0 + 1e-12),
                "pixel {i}: {t} not in [{lo}, {hi}]"
            );
        }
    }
    let n = textured.len();
    assert!(n_light * 5 >= n && n_dark * 5 >= n, "{n_light} light, {n_dark} dark of {n}");
    assert!((n_light + n_dark) * 5 >= 4 * n, "{n_light} + {n_dark} of {n}");
}

/// A bitmap imports as a `Textured` diffuse whose file `convert` rewrites relative to the
/// output; the render reads the PNG (sRGB-decoded) and a uniform image renders as the uniform
/// plane of its decoded grey, pixel for pixel.
#[test]
fn a_bitmap_imports_converts_and_renders_as_its_decoded_colour() {
    let dir = temp_dir("texture-bitmap");
    let grey = 200u8;
    let img = image_png(4, 4, [grey; 3]);
    std::fs::write(dir.join("grey.png"), img).unwrap();
    let xml = plane(
        r#"<texture type="bitmap" name="reflectance"><string name="filename" value="grey.png"/></texture>"#,
    );
    let path = dir.join("scene.xml");
    std::fs::write(&path, &xml).unwrap();
    let imported = import_mitsuba(&path, &[]).unwrap();
    let m = &imported.scene["objects"][0]["material"];
    assert_eq!(m["type"], "Textured", "{m}");
    assert_eq!(m["reflectance"]["type"], "Bitmap");
    // convert: the texture's file relative to the output's folder.
    let out = dir.join("out/scene.json");
    convert(&path, &out, &[]).unwrap();
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(written["objects"][0]["material"]["reflectance"]["file"], "../grey.png");
    Scene::load(&out).unwrap_or_else(|e| panic!("{e}"));
    // The render: the decoded grey, exactly as a uniform plane of it.
    let textured = render(
        "texture-bitmap-render",
        &std::fs::read_to_string(&path)
            .unwrap()
            .replace("grey.png", dir.join("grey.png").to_str().unwrap()),
    );
    let decoded = spectrace_spectrum::srgb_decode(f64::from(grey) / 255.0) as f32;
    let uniform = render(
        "texture-bitmap-uniform",
        &plane(&format!(r#"<float name="reflectance" value="{}"/>"#, f64::from(decoded))),
    );
    for (i, (t, u)) in textured.iter().zip(&uniform).enumerate() {
        assert!((t - u).abs() <= 1e-12 * u.abs() + 1e-300, "pixel {i}: {t} vs {u}");
    }
    assert!(uniform.iter().sum::<f64>() > 0.0);
}

/// What textures the importer cannot read is refused with the file and line.
#[test]
fn unsupported_textures_are_refused_with_file_and_line() {
    let dir = temp_dir("texture-refused");
    for (body, cause) in [
        (r#"<texture type="wireframe" name="reflectance"/>"#, "texture type \"wireframe\""),
        (
            r#"<texture type="bitmap" name="reflectance"><string name="filename" value="missing.png"/></texture>"#,
            "missing.png",
        ),
        (
            r#"<texture type="bitmap" name="reflectance"><string name="filename" value="x.png"/><string name="wrap_mode" value="spiral"/></texture>"#,
            "wrap_mode",
        ),
    ] {
        std::fs::write(dir.join("x.png"), image_png(1, 1, [0; 3])).unwrap();
        let path = dir.join("scene.xml");
        std::fs::write(&path, plane(body)).unwrap();
        let e = Scene::load(&path).err().unwrap_or_else(|| panic!("{body} was accepted"));
        let e = e.to_string();
        assert!(e.contains(cause), "{e}");
        assert!(e.contains("scene.xml:"), "no file:line in {e}");
    }
}

/// A `width` x `height` PNG of one colour.
fn image_png(width: u32, height: u32, rgb: [u8; 3]) -> Vec<u8> {
    let mut bytes = Vec::new();
    let img = image::RgbImage::from_pixel(width, height, image::Rgb(rgb));
    img.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).unwrap();
    bytes
}

/// A Mitsuba sphere keeps Mitsuba's `uv` (pole on its local `+z`, azimuth from `+x` towards
/// `+y`), and a checkerboard read as a roughness has its values swapped as Mitsuba 3 reads them.
#[test]
fn spheres_keep_mitsubas_uv_and_a_roughness_board_is_read_as_mitsuba_reads_it() {
    use glam::DVec3;
    use spectrace_geometry::{Ray, Shape};
    let dir = temp_dir("texture-sphere");
    let xml = format!(
        r#"<scene version="3.0.0">{SENSOR}
        <shape type="sphere"><point name="center" value="1,2,3"/><float name="radius" value="0.5"/>
          <transform name="to_world"><rotate y="1" angle="90"/></transform>
          <bsdf type="roughconductor"><string name="material" value="Au"/>
            <texture type="checkerboard" name="alpha"><float name="color0" value="0.1"/><float name="color1" value="0.3"/></texture></bsdf></shape>
        <emitter type="point"><point name="position" value="0,0,3"/><spectrum name="intensity" value="5"/></emitter>
        </scene>"#
    );
    let path = dir.join("scene.xml");
    std::fs::write(&path, xml).unwrap();
    let imported = import_mitsuba(&path, &[]).unwrap();
    let object = &imported.scene["objects"][0];
    assert_eq!(object["material"]["roughness"]["color0"], 0.3);
    assert_eq!(object["material"]["roughness"]["color1"], 0.1);
    let shape: Shape = serde_json::from_value(object["shape"].clone()).unwrap();
    // to_world turns the sphere's local axes: +z to +x, +x to -z, +y stays.
    let m = glam::DMat4::from_rotation_y(std::f64::consts::FRAC_PI_2);
    let centre = m.transform_point3(DVec3::new(1.0, 2.0, 3.0));
    for (local, uv) in [
        (DVec3::Z, None),              // the pole: v = 0
        (DVec3::X, Some((0.0, 0.5))),  // azimuth 0 on the equator
        (DVec3::Y, Some((0.25, 0.5))), // a quarter turn
        (DVec3::new(-1.0, 0.0, 0.0), Some((0.5, 0.5))),
    ] {
        let towards = m.transform_vector3(local);
        let ray = Ray { origin: centre + towards * 5.0, direction: -towards };
        let hit = shape.intersect(&ray, f64::INFINITY).unwrap();
        match uv {
            None => assert!(hit.uv.y < 1e-6, "pole: {}", hit.uv),
            Some((u, v)) => {
                let du = (hit.uv.x - u).abs().min((hit.uv.x - u - 1.0).abs());
                assert!(
                    du < 1e-6 && (hit.uv.y - v).abs() < 1e-6,
                    "{local}: {} not {u}, {v}",
                    hit.uv
                );
            }
        }
    }
}
