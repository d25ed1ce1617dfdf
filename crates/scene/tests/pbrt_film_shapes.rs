//! pbrt-v4's shapes as lights and surfaces, its camera's screen window and its film: area
//! lights' power per shape, subdivision surfaces, pixel filters, crop windows and clamps, each
//! checked against pbrt-v4's definition.

use glam::DVec3;
use pathlab_testkit::render::assert_mean;

mod pbrt_common;
use pbrt_common::{load_text, render_film};

#[test]
fn area_light_power_is_per_pbrt_shape_as_in_pbrt_v4() {
    // pbrt-v4 makes one light of each triangle of a mesh, a sphere or a disk, and scales each
    // to emit `power` watts: radiance Φ / (π A × sides) for white L.
    use std::f64::consts::PI;
    let scene = r#"LookAt 0 0 10  0 0 0  0 1 0
Camera "perspective" "float fov" 30
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "float power" [ 6 ]
  # Two triangles of areas 2 and 1.
  Shape "trianglemesh" "point3 P" [ 0 0 0  2 0 0  0 2 0   5 0 0  6 0 0  5 2 0 ] "integer indices" [ 0 1 2  3 4 5 ]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "float power" [ 8 ] "bool twosided" true "rgb L" [ 1 0.5 0.25 ]
  # A unit square: two triangles of area 1/2, each its own light.
  Shape "bilinearmesh" "point3 P" [ 0 0 3  1 0 3  0 1 3  1 1 3 ] "integer indices" [ 0 1 2 3 ]
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "float power" [ 100 ]
  Shape "sphere" "float radius" 2
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "float power" [ 10 ] "float scale" 2
  Translate 0 0 -3
  Shape "disk" "float radius" 1
AttributeEnd
"#;
    let desc = load_text("power", &[("power.pbrt", scene)]).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let radiance = |i: usize| desc.meshes[i].emission.unwrap().radiance.as_dvec3();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-5 * b;
    // The triangle mesh: two lights, one per triangle (smaller area first).
    assert_eq!(
        desc.meshes.len(),
        4,
        "{:?}",
        desc.meshes.iter().map(|m| &m.name).collect::<Vec<_>>()
    );
    assert_eq!(desc.meshes[0].indices.len(), 3);
    assert_eq!(desc.meshes[0].positions.len(), 3);
    assert!(close(radiance(0).x, 6.0 / (PI * 1.0)), "{}", radiance(0));
    assert!(close(radiance(1).x, 6.0 / (PI * 2.0)), "{}", radiance(1));
    // The patch: one light of area 1, two-sided, its colour kept.
    let l = radiance(2);
    assert!(close(l.x, 8.0 / (PI * 1.0 * 2.0)), "{l}");
    assert!(close(l.y, 0.5 * l.x) && close(l.z, 0.25 * l.x), "{l}");
    // The disk: one light over its whole (tessellated) area, times scale.
    let disk = &desc.meshes[3];
    let area: f64 = disk
        .indices
        .chunks_exact(3)
        .map(|t| {
            let p = |k: usize| disk.positions[t[k] as usize].as_dvec3();
            0.5 * (p(1) - p(0)).cross(p(2) - p(0)).length()
        })
        .sum();
    assert!((area - PI).abs() < 1e-3 * PI);
    assert!(
        close(radiance(3).x, 2.0 * 10.0 / (PI * area)),
        "{}",
        radiance(3)
    );
    // The sphere: 4π r².
    let s = desc.spheres[0].emission.unwrap().radiance.x as f64;
    assert!(close(s, 100.0 / (PI * 4.0 * PI * 4.0)), "{s}");
}

#[test]
fn loop_subdivision_surfaces_are_subdivided_at_load() {
    let scene = |levels: &str| {
        format!(
            r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" 30
WorldBegin
Shape "loopsubdiv" {levels} "integer indices" [ 0 1 2  0 2 3  0 3 1  1 3 2 ]
  "point3 P" [ 0 0 1  0.943 0 -0.333  -0.471 0.816 -0.333  -0.471 -0.816 -0.333 ]
"#
        )
    };
    let desc = load_text("loop", &[("loop.pbrt", &scene("\"integer levels\" 2"))]).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let m = &desc.meshes[0];
    assert_eq!(m.indices.len(), 4 * 16 * 3);
    assert_eq!(m.normals.len(), m.positions.len());
    // The limit surface shrinks inside the control tetrahedron (circumradius 1).
    assert!(m.positions.iter().all(|p| p.length() < 0.9));
    // pbrt-v4's default is 3 levels.
    let desc = load_text("loop3", &[("loop.pbrt", &scene(""))]).unwrap();
    assert_eq!(desc.meshes[0].indices.len(), 4 * 64 * 3);
    let err = load_text(
        "loop-huge",
        &[("loop.pbrt", &scene("\"integer levels\" 40"))],
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("loop.pbrt") && err.contains("levels"), "{err}");
}

#[test]
fn a_screen_window_shows_that_part_of_the_screen() {
    use pathlab_render::camera::Camera;
    // The full view at 200 x 100 (screen window [-2, 2, -1, 1]), and its right half alone at
    // 100 x 100 (window [0, 2, -1, 1]): a world point lands 100 pixels further left there.
    // Likewise the top-left quarter at 100 x 50, and an orthographic camera.
    let scene = |projection: &str, window: &str, (w, h): (u32, u32)| {
        format!(
            r#"LookAt 0.3 0.2 5  0 0 0  0 1 0
Camera "{projection}" {window}
Film "rgb" "integer xresolution" {w} "integer yresolution" {h}
WorldBegin
Shape "sphere"
"#
        )
    };
    let points = [
        glam::Vec3::new(0.5, 0.2, 0.1),
        glam::Vec3::new(1.2, -0.4, -0.3),
        glam::Vec3::new(-0.8, 0.6, 0.2),
    ];
    for projection in ["perspective", "orthographic"] {
        let camera = |tag: &str, window: &str, size: (u32, u32)| {
            let text = scene(projection, window, size);
            let desc = load_text(tag, &[("window.pbrt", &text)]).unwrap();
            assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
            Camera::new(&desc.camera, desc.resolution)
        };
        let full = camera("full", "", (200, 100));
        let right = camera("right", "\"float screenwindow\" [ 0 2 -1 1 ]", (100, 100));
        let corner = camera("corner", "\"float screenwindow\" [ -2 0 0 1 ]", (100, 50));
        for p in points {
            let f = full.raster_position(p).unwrap();
            let r = right.raster_position(p).unwrap();
            let c = corner.raster_position(p).unwrap();
            assert!(
                (r - (f - glam::Vec2::new(100.0, 0.0))).length() < 1e-3,
                "{projection}: {f} {r}"
            );
            assert!((c - f).length() < 1e-3, "{projection}: {f} {c}");
        }
    }
    // A window of another shape than the film: warned.
    let text = scene(
        "perspective",
        "\"float screenwindow\" [ -1 1 -1 1 ]",
        (200, 100),
    );
    let desc = load_text("stretched", &[("window.pbrt", &text)]).unwrap();
    assert_eq!(desc.warnings.len(), 1, "{:?}", desc.warnings);
}

#[test]
fn mitchell_and_sinc_filters_are_read_and_render() {
    use pathlab_render::desc::PixelFilter;
    let scene = |filter: &str| {
        format!(
            r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
PixelFilter {filter}
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
"#
        )
    };
    for (filter, expected) in [
        (
            "\"mitchell\"",
            PixelFilter::Mitchell {
                radius: 2.0,
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            },
        ),
        (
            "\"mitchell\" \"float xradius\" 1.5 \"float B\" 0 \"float C\" 0.5",
            PixelFilter::Mitchell {
                radius: 1.5,
                b: 0.0,
                c: 0.5,
            },
        ),
        (
            "\"sinc\"",
            PixelFilter::LanczosSinc {
                radius: 4.0,
                tau: 3.0,
            },
        ),
    ] {
        let desc = load_text("filters", &[("filter.pbrt", &scene(filter))]).unwrap();
        assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
        assert_eq!(desc.filter, expected);
        // Under a sky of radiance 1 every pixel's expected value is 1; the signed weights
        // make noise, whose standard error gives the tolerance.
        let film = render_film(&desc, 256, 1);
        assert!(
            film.image_mean_std_error().x > 0.0,
            "{filter}: no noise from negative lobes?"
        );
        assert_mean(filter, &film, DVec3::ONE);
    }
}

#[test]
fn a_film_clamp_is_warned_about_not_ignored() {
    let scene = r#"Film "rgb" "integer xresolution" 8 "integer yresolution" 8 "float maxcomponentvalue" 10
Camera "perspective"
WorldBegin
"#;
    let desc = load_text("clamp", &[("clamp.pbrt", scene)]).unwrap();
    assert_eq!(desc.warnings.len(), 1, "{:?}", desc.warnings);
    assert!(desc.warnings[0].contains("maxcomponentvalue"));
}

#[test]
fn a_films_crop_window_and_pixel_bounds_are_placed_as_pbrt_places_them() {
    use pathlab_render::desc::CropHint;
    let load = |tag: &str, film: &str| {
        let scene = format!(
            "Film \"rgb\" \"integer xresolution\" 100 \"integer yresolution\" 50 {film}\nCamera \"perspective\"\nWorldBegin\n"
        );
        load_text(tag, &[("crop.pbrt", &scene)]).unwrap()
    };
    let hint = |window| {
        Some(CropHint {
            window,
            of: [100, 50],
        })
    };
    // Fractions x0 x1 y0 y1, in any order, each edge at the first pixel at or past it.
    let desc = load("cropwindow", r#""float cropwindow" [ 0.25 0.101 0.5 1 ]"#);
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    assert_eq!(desc.hints.crop, hint([11, 25, 25, 50]));
    // Pixel bounds x0 x1 y0 y1 win over a crop window, with a warning.
    let desc = load(
        "pixelbounds",
        r#""integer pixelbounds" [ 10 20 5 45 ] "float cropwindow" [ 0 1 0 1 ]"#,
    );
    assert_eq!(desc.hints.crop, hint([10, 5, 20, 45]));
    assert_eq!(desc.warnings.len(), 1, "{:?}", desc.warnings);
    assert!(desc.warnings[0].contains("pixelbounds is used"));
    // Bounds past the image are cut to it; bounds that hold no pixel render the whole image.
    let desc = load("past", r#""integer pixelbounds" [ 90 200 -5 10 ]"#);
    assert_eq!(desc.hints.crop, hint([90, 0, 100, 10]));
    let desc = load("empty", r#""float cropwindow" [ 0.5 0.5 0 1 ]"#);
    assert_eq!(desc.hints.crop, None);
    assert!(
        desc.warnings[0].contains("holds no pixel"),
        "{:?}",
        desc.warnings
    );
    let e = load_text(
        "three",
        &[(
            "crop.pbrt",
            "Film \"rgb\" \"float cropwindow\" [ 0 1 0 ]\nCamera \"perspective\"\nWorldBegin\n",
        )],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("cropwindow takes four numbers"), "{e}");
}
