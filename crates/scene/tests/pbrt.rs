//! pbrt-v4 scenes: the file syntax, pbrt's conventions (handedness, orientation, units of
//! light), located errors, and that Bitterli's scenes load (their renders are judged in
//! `pathlab-reference-tests`).

use glam::DVec3;
use pathlab_render::film::Film;
use std::path::{Path, PathBuf};

mod pbrt_common;
use pbrt_common::{load_text, render_film};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/bitterli")
        .join(name)
}

/// The mean of the left and right halves of an image.
fn halves(film: &Film) -> (DVec3, DVec3) {
    let (w, h) = (film.width(), film.height());
    let mut sums = [DVec3::ZERO; 2];
    for y in 0..h {
        for x in 0..w {
            sums[(2 * x / w) as usize] += film.pixel(x, y).mean();
        }
    }
    let n = (w * h / 2) as f64;
    (sums[0] / n, sums[1] / n)
}

/// A camera looking at a red quad at world x > 0 and a blue one at x < 0, with `camera` the
/// camera's transform directives.
fn two_quads(camera: &str) -> String {
    format!(
        r#"# Two quads either side of x = 0, lit by a uniform sky.
{camera}
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 32 ] "integer yresolution" 16
Sampler "independent" "integer pixelsamples" 4
Integrator "path" "integer maxdepth" [ 1 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
AttributeBegin
  Material "diffuse" "rgb reflectance" [ 0.8 0 0 ]
  Shape "trianglemesh" "point3 P" [ 0 -2 0  3 -2 0  3 2 0  0 2 0 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
AttributeBegin
  Material "diffuse" "rgb reflectance" [ 0 0 0.8 ]
  Translate -3 0 0
  Shape "trianglemesh" "point3 P" [ 0 -2 0  3 -2 0  3 2 0  0 2 0 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
"#
    )
}

#[test]
fn lookat_cameras_see_the_world_as_pbrt_does() {
    // pbrt's camera space is left-handed: looking down +z from z = -5 with y up, +x is on the
    // image's right, so the red quad (x > 0) is on the right.
    let desc = load_text(
        "lookat",
        &[("a.pbrt", &two_quads("LookAt 0 0 -5  0 0 0  0 1 0"))],
    )
    .unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let (left, right) = halves(&render_film(&desc, 4, 1));
    assert!(
        // The sky fills what the quads leave: compare red and blue within each half.
        right.x > right.z + 0.2 && left.z > left.x + 0.2,
        "{left} {right}"
    );
    // Blender's exports put a mirror in front of LookAt: the quads swap sides.
    let desc = load_text(
        "mirrored",
        &[(
            "a.pbrt",
            &two_quads("Scale -1 1 1\nLookAt 0 0 -5  0 0 0  0 1 0"),
        )],
    )
    .unwrap();
    let (left, right) = halves(&render_film(&desc, 4, 1));
    assert!(
        left.x > left.z + 0.2 && right.z > right.x + 0.2,
        "{left} {right}"
    );
}

/// A one-sided emitting quad in the plane z = 0 whose winding faces +z, seen from `eye`.
fn one_sided_light(eye: &str, extra: &str) -> String {
    format!(
        r#"LookAt {eye}  0 0 0  0 1 0
Camera "perspective" "float fov" 10
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
WorldBegin
AttributeBegin
  {extra}
  AreaLightSource "diffuse" "rgb L" [ 2 2 2 ]
  Shape "trianglemesh" "point3 P" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0 ] "integer indices" [ 0 1 2 0 2 3 ]
AttributeEnd
"#
    )
}

#[test]
fn one_sided_area_lights_emit_on_pbrts_side() {
    let seen = |eye: &str, extra: &str| {
        let desc = load_text("side", &[("a.pbrt", &one_sided_light(eye, extra))]).unwrap();
        render_film(&desc, 1, 0).image_mean().x
    };
    // The winding (0, 1, 2) faces +z: seen from +z it shines, from -z it is black.
    assert!((seen("0 0 5", "") - 2.0).abs() < 1e-3);
    assert_eq!(seen("0 0 -5", ""), 0.0);
    // ReverseOrientation turns the side; a two-sided light shines both ways.
    assert_eq!(seen("0 0 5", "ReverseOrientation"), 0.0);
    assert!((seen("0 0 -5", "ReverseOrientation") - 2.0).abs() < 1e-3);
    // A mirror in z leaves the quad where it is but turns its normal (pbrt carries the
    // object's normal through the transform as a normal): it now shines towards -z.
    assert_eq!(seen("0 0 5", "Scale 1 1 -1"), 0.0);
    assert!((seen("0 0 -5", "Scale 1 1 -1") - 2.0).abs() < 1e-3);
    let two =
        one_sided_light("0 0 -5", "").replace("[ 2 2 2 ]", "[ 2 2 2 ] \"bool twosided\" true");
    let desc = load_text("two", &[("a.pbrt", &two)]).unwrap();
    assert!((render_film(&desc, 1, 0).image_mean().x - 2.0).abs() < 1e-3);
}

#[test]
fn the_file_syntax_includes_objects_and_named_things() {
    let main = r#"
LookAt 0 0 10  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
Sampler "sobol" "integer pixelsamples" [ 8 ]
Integrator "volpath" "integer maxdepth" [ 3 ]
WorldBegin
Include "materials.pbrt"
Texture "checks" "spectrum" "constant" "rgb value" [ 0.2 0.4 0.6 ]
MakeNamedMaterial "tex" "string type" "diffuse" "texture reflectance" "checks"
ObjectBegin "ball"
  NamedMaterial "gold"
  Shape "sphere" "float radius" 0.5
ObjectEnd
AttributeBegin Translate -2 0 0 ObjectInstance "ball" AttributeEnd
AttributeBegin Translate 2 0 0 ObjectInstance "ball" AttributeEnd
Attribute "shape" "float radius" [ 0.25 ]
NamedMaterial "tex"
Shape "sphere"
LightSource "point" "point3 from" [ 0 5 5 ] "blackbody I" [ 5500 ] "float power" [ 100 ]
"#;
    let materials = r#"# Materials, included.
MakeNamedMaterial "gold" "string type" [ "conductor" ]
  "spectrum eta" "metal-Au-eta" "spectrum k" "metal-Au-k" "float roughness" 0.01
"#;
    let desc = load_text(
        "syntax",
        &[("main.pbrt", main), ("materials.pbrt", materials)],
    )
    .unwrap();
    assert_eq!(desc.spheres.len(), 3);
    let xs: Vec<f32> = desc.spheres.iter().map(|s| s.center.x).collect();
    assert!(xs.iter().any(|x| (x.abs() - 2.0).abs() < 1e-5), "{xs:?}");
    assert!(
        desc.spheres.iter().any(|s| (s.radius - 0.25).abs() < 1e-6),
        "Attribute default radius"
    );
    assert_eq!(desc.hints.spp, Some(8));
    assert_eq!(desc.hints.max_depth, Some(3));
    assert_eq!(desc.resolution, [16, 16]);
    // No PixelFilter: pbrt-v4's default Gaussian, σ = 0.5 cut at 1.5 pixels.
    assert_eq!(
        desc.filter,
        pathlab_render::desc::PixelFilter::Gaussian {
            stddev: 0.5,
            radius: 1.5
        }
    );
    // A blackbody light has luminance 1 before its power: 100 W over 4π sr.
    let i = desc.point_lights[0].intensity;
    let y = 0.2126 * i.x + 0.7152 * i.y + 0.0722 * i.z;
    assert!(
        (y - 100.0 / (4.0 * std::f32::consts::PI)).abs() < 1e-3 * y,
        "{i}"
    );
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    render_film(&desc, 1, 0);
}

#[test]
fn bad_files_are_one_line_errors_with_file_and_line() {
    let cases = [
        ("WorldBegin\nAttributeBegin\nShape \"sphere\"\n", "never closed", 2),
        ("WorldBegin\nAttributeEnd\n", "without a matching begin", 2),
        ("WorldBegin\nFrobnicate 1 2\n", "unknown directive 'Frobnicate'", 2),
        ("WorldBegin\nShape \"sphere\" \"float radius\" [ \"big\" ]\n", "the values do not fit", 2),
        ("WorldBegin\nShape \"sphere\" \"real radius\" 1\n", "unknown parameter type 'real'", 2),
        ("WorldBegin\nShape \"sphere\" \"float radius\" [ 1\n", "ends inside its [ ]", 2),
        ("WorldBegin\nShape \"sphere\n", "runs past the end of its line", 2),
        ("Translate 1 2\nWorldBegin\n", "expected 3 numbers, found 2", 1),
        ("WorldBegin\nShape \"sphere\" \"float radius\" [ 1 2 ]\n", "\"float radius\" (line 2): expected one number, found 2", 2),
        ("WorldBegin\nShape \"plymesh\" \"string filename\" [ \"a.ply\" \"b.ply\" ]\n", "expected one string", 2),
        ("WorldBegin\nMaterial \"conductor\" \"bool remaproughness\" [ true false ]\nShape \"sphere\"\n", "expected one true or false", 0),
        ("WorldBegin\nLightSource \"point\" \"blackbody I\" [ 3000 4000 ]\n", "expected one temperature, found 2 numbers", 0),
        ("WorldBegin\nMaterial \"diffuse\" \"texture reflectance\" [ \"a\" \"b\" ]\nShape \"sphere\"\n", "expected one texture name", 0),
        ("WorldBegin\nMaterial \"conductor\" \"float roughness\" -0.25\nShape \"sphere\"\n", "\"float roughness\" (line 2): roughness must be a number >= 0, got -0.25", 0),
        ("WorldBegin\nMaterial \"dielectric\" \"float uroughness\" 0.1 \"float vroughness\" -1\nShape \"sphere\"\n", "\"float vroughness\" (line 2): roughness must be a number >= 0", 0),
        ("WorldBegin\nTexture \"c\" \"float\" \"checkerboard\"\nMaterial \"conductor\" \"texture uroughness\" \"c\" \"float vroughness\" -2\nShape \"sphere\"\n", "\"float vroughness\" (line 3): roughness must be a number >= 0, got -2", 0),
        ("WorldBegin\nLightSource \"point\" \"rgb I\" [ 1 -1 1 ]\n", "\"rgb I\" (line 2): a light's emission must be >= 0 in every channel", 0),
        ("WorldBegin\nLightSource \"spot\" \"float scale\" -2\n", "\"float scale\" (line 2): a light's scale must be a number >= 0, got -2", 0),
        ("WorldBegin\nLightSource \"infinite\" \"string filename\" \"sky.exr\" \"float scale\" -1\n", "a light's scale must be a number >= 0", 0),
        ("WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"blackbody L\" 6500 \"float scale\" -1\nShape \"sphere\"\nAttributeEnd\n", "\"float scale\" (line 3): a light's scale must be a number >= 0", 0),
        ("WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"spectrum L\" [ 400 1 700 -1 ]\nShape \"sphere\"\nAttributeEnd\n", "\"spectrum L\" (line 3): a light's emission must be >= 0", 0),
        ("WorldBegin\nNamedMaterial \"nothing\"\n", "no material of that name", 2),
        ("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 5 ]\n", "out of range", 2),
        ("Camera \"perspective\"\n", "no WorldBegin", 0),
        ("WorldBegin\nInclude \"missing.pbrt\"\n", "missing.pbrt", 0),
        ("WorldBegin\nShape \"plymesh\" \"string filename\" \"no.ply\"\n", "no.ply", 0),
        ("WorldBegin\nShape \"plymesh\" \"string filename\" \"no.ply.gz\"\n", "no.ply.gz", 0),
    ];
    for (i, (text, expected, line)) in cases.iter().enumerate() {
        let result = load_text(&format!("bad{i}"), &[("bad.pbrt", text)]);
        let Err(e) = result else {
            // A missing file (a PLY mesh, an include) is a warning naming it; the scene
            // still loads.
            let desc = result.unwrap();
            assert!(
                desc.warnings.iter().any(|w| w.contains(expected)),
                "case {i}: {:?}",
                desc.warnings
            );
            continue;
        };
        let msg = e.to_string();
        assert!(
            msg.contains(expected),
            "case {i}: expected '{expected}' in: {msg}"
        );
        assert_eq!(msg.lines().count(), 1, "{msg}");
        if *line > 0 {
            assert!(
                msg.contains(&format!("bad.pbrt:{line}:")),
                "case {i}: {msg}"
            );
        }
    }
}

#[test]
fn gzip_scenes_and_meshes_load() {
    use flate2::write::GzEncoder;
    use std::io::Write;
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("pbrt-gz");
    std::fs::create_dir_all(&dir).unwrap();
    let gz = |name: &str, bytes: &[u8]| {
        let mut e = GzEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(bytes).unwrap();
        std::fs::write(dir.join(name), e.finish().unwrap()).unwrap();
    };
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
    gz("quad.ply.gz", ply.as_bytes());
    gz(
        "scene.pbrt.gz",
        b"WorldBegin\nShape \"plymesh\" \"string filename\" \"quad.ply.gz\"\n",
    );
    let desc = pathlab_scene::load(dir.join("scene.pbrt.gz").to_str().unwrap()).unwrap();
    assert_eq!(desc.meshes.len(), 1);
    assert_eq!(desc.meshes[0].indices.len(), 6, "the quad split in two");
    std::fs::write(dir.join("broken.pbrt.gz"), b"\x1f\x8b\x08\x00garbage").unwrap();
    let e = pathlab_scene::load(dir.join("broken.pbrt.gz").to_str().unwrap()).unwrap_err();
    assert!(e.to_string().contains("not a valid gzip file"), "{e}");
}

#[test]
fn bitterli_scenes_load_with_only_documented_warnings() {
    for scene in ["cornell-box", "veach-mis", "veach-bidir"] {
        let path = data(scene).join("scene-v4.pbrt");
        let desc = pathlab_scene::load(path.to_str().unwrap()).unwrap();
        for w in &desc.warnings {
            assert!(w.contains("rendered by the path tracer"), "{scene}: {w}");
        }
        // "bdpt" is rendered by the bidirectional path tracer, without a note.
        let bdpt = desc.hints.integrator == Some(pathlab_render::desc::IntegratorHint::Bdpt);
        assert_eq!(bdpt, scene == "veach-bidir", "{scene}");
        assert!(Path::new(&path).exists());
    }
}

#[test]
fn image_infinite_lights_map_equal_area_squares_and_normalise_illuminance() {
    // A square map bright over its inner diamond (|u| + |v| <= 1 about the centre), which
    // pbrt-v4's equal-area mapping sends to the upper hemisphere of the light's frame (z > 0),
    // and black outside. Rotated so that the light's z is the world's y, it lights a white
    // floor from above; "illuminance" π makes the floor's radiance ρ E / π = 1.
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("pbrt-envmap");
    std::fs::create_dir_all(&dir).unwrap();
    let n = 64;
    let texels: Vec<glam::Vec3> = (0..n * n)
        .map(|k| {
            let (i, j) = (k % n, k / n);
            let u = 2.0 * (i as f32 + 0.5) / n as f32 - 1.0;
            let v = 2.0 * (j as f32 + 0.5) / n as f32 - 1.0;
            glam::Vec3::splat(if u.abs() + v.abs() <= 1.0 { 1.0 } else { 0.0 })
        })
        .collect();
    pathlab_render::image_io::write_exr(&dir.join("sky.exr"), n as u32, n as u32, &texels, &[])
        .unwrap();
    let scene = |rotate: &str| {
        format!(
            r#"LookAt 0 3 0.001  0 0 0  0 1 0
Camera "perspective" "float fov" 10
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
Integrator "path" "integer maxdepth" 1
WorldBegin
AttributeBegin
  {rotate}
  LightSource "infinite" "string filename" "sky.exr" "float illuminance" [ 3.14159265 ]
AttributeEnd
Material "diffuse" "rgb reflectance" [ 1 1 1 ]
Shape "trianglemesh" "point3 P" [ -5 0 -5  5 0 -5  5 0 5  -5 0 5 ] "integer indices" [ 0 2 1 0 3 2 ]
"#
        )
    };
    std::fs::write(dir.join("up.pbrt"), scene("Rotate -90 1 0 0")).unwrap();
    let desc = pathlab_scene::load(dir.join("up.pbrt").to_str().unwrap()).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let l = render_film(&desc, 256, 3).image_mean();
    assert!((l.x - 1.0).abs() < 0.02, "floor radiance {l}");
    // Unrotated, the bright hemisphere is the light's z, which lies along the floor: it lights
    // the floor from one side only, with half the cosine-weighted irradiance (by symmetry).
    std::fs::write(dir.join("side.pbrt"), scene("")).unwrap();
    let desc = pathlab_scene::load(dir.join("side.pbrt").to_str().unwrap()).unwrap();
    let l = render_film(&desc, 256, 3).image_mean();
    assert!((l.x - 0.5).abs() < 0.02, "floor radiance {l}");
}

#[test]
fn a_scene_missing_some_of_its_files_warns_once_for_each_and_renders() {
    // As Bitterli's scenes are found in some mirrors: textures, meshes (one used twice) and an
    // included file left out.
    let scene = r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective"
Film "rgb" "integer xresolution" 16 "integer yresolution" 16
WorldBegin
LightSource "infinite" "string filename" "textures/sky.exr"
LightSource "infinite" "rgb L" [ 1 1 1 ]
Texture "wood" "spectrum" "imagemap" "string filename" "textures/wood.png"
Material "diffuse" "texture reflectance" "wood"
Shape "plymesh" "string filename" "models/mesh1.ply"
Shape "plymesh" "string filename" "models/mesh1.ply"
Shape "plymesh" "string filename" "models/mesh2.ply.gz"
Include "geometry.pbrt"
Shape "sphere"
"#;
    let desc = load_text("missing-files", &[("scene.pbrt", scene)]).unwrap();
    let missing = [
        "sky.exr",
        "wood.png",
        "mesh1.ply",
        "mesh2.ply.gz",
        "geometry.pbrt",
    ];
    assert_eq!(desc.warnings.len(), missing.len(), "{:?}", desc.warnings);
    for (w, name) in desc.warnings.iter().zip(missing) {
        assert!(w.contains(name), "{w} should name {name}");
    }
    let film = render_film(&desc, 4, 1);
    assert!(film.image_mean().min_element() > 0.0 && film.image_mean().is_finite());
}

#[test]
fn samplers_pathlab_lacks_are_rendered_by_sobol_with_a_note() {
    use pathlab_mc::sampler::SamplerKind;
    let scene = |sampler: &str| {
        two_quads("LookAt 0 0 -5  0 0 0  0 1 0")
            .replace("Sampler \"independent\"", &format!("Sampler \"{sampler}\""))
    };
    for (name, kind, note) in [
        ("independent", SamplerKind::Independent, None),
        ("stratified", SamplerKind::Stratified, None),
        ("sobol", SamplerKind::Sobol, None),
        (
            "zsobol",
            SamplerKind::Sobol,
            Some("rendered with the Sobol sampler"),
        ),
        (
            "halton",
            SamplerKind::Sobol,
            Some("rendered with the Sobol sampler"),
        ),
        (
            "pmj02bn",
            SamplerKind::Sobol,
            Some("rendered with the Sobol sampler"),
        ),
        (
            "lowdiscrepancy",
            SamplerKind::Sobol,
            Some("not a pbrt-v4 sampler"),
        ),
    ] {
        let desc = load_text(name, &[("a.pbrt", &scene(name))]).unwrap();
        assert_eq!(desc.hints.sampler, Some(kind), "{name}");
        assert_eq!(desc.hints.spp, Some(4), "{name}");
        let notes: Vec<&String> = desc
            .warnings
            .iter()
            .filter(|w| w.contains("Sampler"))
            .collect();
        match note {
            None => assert!(notes.is_empty(), "{name}: {notes:?}"),
            Some(text) => {
                assert_eq!(notes.len(), 1, "{name}: {notes:?}");
                assert!(notes[0].contains(text), "{name}: {}", notes[0]);
                assert!(
                    notes[0].contains("a.pbrt:5:"),
                    "the file and line: {}",
                    notes[0]
                );
            }
        }
    }
}
