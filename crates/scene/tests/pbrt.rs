//! pbrt-v4 scenes: the file syntax, pbrt's conventions (handedness, orientation, units of
//! light), located errors, and Bitterli's scenes against Tungsten's reference renders.

use glam::DVec3;
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::film::Film;
use pathlab_render::integrator::{IntegratorKind, PathIntegrator};
use pathlab_render::render::{render, RenderSettings};
use pathlab_render::scene::Scene;
use pathlab_scene::Error;
use pathlab_testkit::render::assert_mean;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/bitterli")
        .join(name)
}

/// Writes `files` (name, text) to a scratch folder and loads the first.
fn load_text(tag: &str, files: &[(&str, &str)]) -> Result<pathlab_render::desc::SceneDesc, Error> {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("pbrt")
        .join(tag);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    pathlab_scene::load(dir.join(files[0].0).to_str().unwrap())
}

fn render_film(desc: &pathlab_render::desc::SceneDesc, spp: u32, seed: u64) -> Film {
    let scene = Scene::build(desc).unwrap();
    let integrator = IntegratorKind::Path(PathIntegrator {
        max_depth: desc.hints.max_depth.unwrap_or(u32::MAX),
        ..Default::default()
    });
    let settings = RenderSettings::new(spp, seed, SamplerKind::Independent);
    render(&scene, &integrator, &settings, &|_| {}, &Default::default()).0
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
        ("WorldBegin\nNamedMaterial \"nothing\"\n", "no material of that name", 2),
        ("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 5 ]\n", "out of range", 2),
        ("Camera \"perspective\"\n", "no WorldBegin", 0),
        ("WorldBegin\nInclude \"missing.pbrt\"\n", "missing.pbrt", 0),
        ("WorldBegin\nShape \"plymesh\" \"string filename\" \"no.ply\"\n", "", 0),
    ];
    for (i, (text, expected, line)) in cases.iter().enumerate() {
        let result = load_text(&format!("bad{i}"), &[("bad.pbrt", text)]);
        let Err(e) = result else {
            // A missing PLY is a warning, the scene still loads.
            let desc = result.unwrap();
            assert!(
                desc.warnings.iter().any(|w| w.contains("no.ply")),
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
fn textures_scale_mix_invert_and_checker_as_pbrt_defines_them() {
    use glam::{Vec2, Vec3};
    use pathlab_render::desc::{MaterialDesc, TextureDesc};
    use pathlab_render::texture::{Tex, TexPoint};
    // A 2 x 1 image: 0.2 on its left half, 0.6 on its right.
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("pbrt-textures");
    std::fs::create_dir_all(&dir).unwrap();
    let texels = [Vec3::splat(0.2), Vec3::splat(0.6)];
    pathlab_render::image_io::write_exr(&dir.join("two.exr"), 2, 1, &texels, &[]).unwrap();
    let scene = r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 4 "integer yresolution" 4
WorldBegin
Texture "img" "spectrum" "imagemap" "string filename" "two.exr" "string filter" "point" "string encoding" "linear"
Texture "amount" "float" "imagemap" "string filename" "two.exr" "string filter" "point" "string encoding" "linear"
Texture "doubled" "spectrum" "scale" "texture tex" "img" "float scale" 2
Texture "inverted" "spectrum" "imagemap" "string filename" "two.exr" "string filter" "point" "string encoding" "linear" "float scale" 2 "bool invert" true
Texture "mixed" "spectrum" "mix" "rgb tex1" [ 1 0 0 ] "rgb tex2" [ 0 0 1 ] "texture amount" "amount"
Texture "checks" "spectrum" "checkerboard" "float uscale" 4 "float vscale" 4 "rgb tex1" [ 1 0 0 ]
Texture "checked" "spectrum" "checkerboard" "float uscale" 4 "float vscale" 4 "texture tex2" "img"
MakeNamedMaterial "m0" "string type" "diffuse" "texture reflectance" "doubled"
MakeNamedMaterial "m1" "string type" "diffuse" "texture reflectance" "inverted"
MakeNamedMaterial "m2" "string type" "diffuse" "texture reflectance" "mixed"
MakeNamedMaterial "m3" "string type" "diffuse" "texture reflectance" "checks"
MakeNamedMaterial "m4" "string type" "diffuse" "texture reflectance" "checked"
MakeNamedMaterial "m5" "string type" "diffusetransmission" "rgb reflectance" [ 0.8 0.6 0.4 ] "texture transmittance" "img" "float scale" 0.5
NamedMaterial "m5"
Shape "sphere"
"#;
    std::fs::write(dir.join("textures.pbrt"), scene).unwrap();
    let desc = pathlab_scene::load(dir.join("textures.pbrt").to_str().unwrap()).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let texture = |m: &MaterialDesc| match m {
        MaterialDesc::TexturedDiffuse { texture, .. } => Tex::from_desc(texture),
        other => panic!("not a textured diffuse material: {other:?}"),
    };
    let at = |t: &Tex, u: f32, v: f32| t.eval(&TexPoint::uv(Vec2::new(u, v)));
    let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-5;
    let m = &desc.materials;
    // scale: the image times 2.
    let t = texture(&m[0]);
    assert!(close(at(&t, 0.25, 0.5), Vec3::splat(0.4)));
    assert!(close(at(&t, 0.75, 0.5), Vec3::splat(1.2)));
    // An image's scale, then invert, clamped at zero: max(0, 1 - 2 x).
    let t = texture(&m[1]);
    assert!(close(at(&t, 0.25, 0.5), Vec3::splat(0.6)));
    assert!(close(at(&t, 0.75, 0.5), Vec3::ZERO));
    // mix: (1 - a) red + a blue, a read from the image.
    let t = texture(&m[2]);
    assert!(close(at(&t, 0.25, 0.5), Vec3::new(0.8, 0.0, 0.2)));
    assert!(close(at(&t, 0.75, 0.5), Vec3::new(0.4, 0.0, 0.6)));
    // checkerboard: tex1 where ⌊4u⌋ + ⌊4v⌋ is even, tex2 (default 0) elsewhere.
    let t = texture(&m[3]);
    assert!(close(at(&t, 0.1, 0.1), Vec3::X));
    assert!(close(at(&t, 0.3, 0.1), Vec3::ZERO));
    assert!(close(at(&t, 0.3, 0.3), Vec3::X));
    assert!(close(at(&t, 0.6, 0.1), Vec3::X));
    // A textured square: tex2 is the image, read at the point's own (u, v).
    let t = texture(&m[4]);
    assert!(close(at(&t, 0.1, 0.1), Vec3::ONE));
    assert!(close(at(&t, 0.3, 0.1), Vec3::splat(0.2)));
    assert!(close(at(&t, 0.8, 0.1), Vec3::splat(0.6)));
    // diffusetransmission: both albedos times scale.
    let MaterialDesc::DiffuseTransmission {
        reflectance,
        transmittance,
    } = &m[5]
    else {
        panic!("{:?}", m[5]);
    };
    assert!(close(
        reflectance.as_constant().unwrap(),
        Vec3::new(0.4, 0.3, 0.2)
    ));
    assert!(matches!(transmittance, TextureDesc::Product(_)));
    let t = Tex::from_desc(transmittance);
    assert!(close(at(&t, 0.25, 0.5), Vec3::splat(0.1)));
    render_film(&desc, 1, 0);
}

#[test]
fn a_sphere_that_reflects_and_transmits_everything_vanishes_in_a_furnace() {
    // Under a uniform sky of radiance 1, a closed sphere whose diffuse reflectance and
    // transmittance add up to one returns all the light it receives, on both its sides: the
    // expected radiance of every pixel is 1 (light sampling and MIS leave some noise).
    let scene = r#"LookAt 0 0 4  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 16 "integer yresolution" 16
Integrator "path" "integer maxdepth" [ 1000 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
Material "diffusetransmission" "rgb reflectance" [ 0.3 0.3 0.3 ] "rgb transmittance" [ 0.7 0.7 0.7 ]
Shape "sphere" "float radius" 1
"#;
    let desc = load_text("furnace", &[("furnace.pbrt", scene)]).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let film = render_film(&desc, 64, 5);
    assert!(film.image_mean_std_error().x < 0.01);
    assert_mean("diffuse transmission furnace", &film, DVec3::ONE);
}

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
fn coated_materials_read_their_layers_and_a_lossless_coat_vanishes_in_a_furnace() {
    use pathlab_render::desc::{CoatedBase, MaterialDesc};
    let scene = r#"LookAt 0 0 4  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 16 "integer yresolution" 16
Integrator "path" "integer maxdepth" [ 1000 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
MakeNamedMaterial "plastic" "string type" "coateddiffuse" "rgb reflectance" [ 0.2 0.4 0.6 ]
  "float roughness" 0.04 "float thickness" 0.2 "rgb albedo" [ 0.5 0.5 0.5 ] "float g" 0.3
  "integer maxdepth" 20 "integer nsamples" 2 "float eta" 1.4
MakeNamedMaterial "gold" "string type" "coatedconductor" "float interface.roughness" 0.01
  "spectrum conductor.eta" "metal-Au-eta" "spectrum conductor.k" "metal-Au-k"
  "float conductor.uroughness" 0.09 "float conductor.vroughness" 0.16 "bool remaproughness" false
Material "coateddiffuse" "rgb reflectance" [ 1 1 1 ] "integer maxdepth" 1000 "float thickness" 1e-30
Shape "sphere" "float radius" 1
"#;
    let desc = load_text("coated", &[("coated.pbrt", scene)]).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let MaterialDesc::Coated(plastic) = &desc.materials[0] else {
        panic!("{:?}", desc.materials[0]);
    };
    assert_eq!(plastic.coat_alpha, [0.2, 0.2]);
    assert_eq!(
        (plastic.coat_eta, plastic.thickness, plastic.g),
        (1.4, 0.2, 0.3)
    );
    assert_eq!((plastic.max_depth, plastic.samples), (20, 2));
    assert_eq!(plastic.albedo, glam::Vec3::splat(0.5));
    assert!(
        matches!(&plastic.base, CoatedBase::Diffuse(t) if t.as_constant() == Some(glam::Vec3::new(0.2, 0.4, 0.6)))
    );
    let MaterialDesc::Coated(gold) = &desc.materials[1] else {
        panic!("{:?}", desc.materials[1]);
    };
    // remaproughness false: the coat's roughness is its α.
    assert_eq!(gold.coat_alpha, [0.01, 0.01]);
    assert_eq!(
        (gold.coat_eta, gold.thickness, gold.max_depth, gold.samples),
        (1.5, 0.01, 10, 1)
    );
    let CoatedBase::Conductor { eta, alpha, .. } = &gold.base else {
        panic!("{:?}", gold.base);
    };
    assert_eq!(*alpha, [0.09, 0.16]);
    assert!(eta.x < 0.5 && eta.z > 1.0, "gold's η {eta}");
    // A white Lambertian under a smooth coat, with no medium and no thickness to absorb in,
    // returns all the light it receives: under a uniform sky the sphere's radiance is the
    // sky's, 1. (pbrt-v4's default thickness 0.01 absorbs a little at each crossing.)
    let film = render_film(&desc, 64, 5);
    assert!(film.image_mean_std_error().y < 0.01);
    assert_mean("coated furnace", &film, DVec3::ONE);
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
fn area_lights_emit_their_image_and_name_a_missing_one() {
    use glam::Vec3;
    use std::f64::consts::PI;
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("pbrt-area-image");
    std::fs::create_dir_all(&dir).unwrap();
    // Mean luminance 0.5: one black texel, one white.
    pathlab_render::image_io::write_exr(&dir.join("glow.exr"), 2, 1, &[Vec3::ZERO, Vec3::ONE], &[])
        .unwrap();
    let scene = |file: &str, extra: &str| {
        format!(
            r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" 30
WorldBegin
AreaLightSource "diffuse" "string filename" "{file}" "float scale" 2 {extra}
Shape "trianglemesh" "point3 P" [ 0 0 0  1 0 0  1 1 0  0 1 0 ] "integer indices" [ 0 1 2  0 2 3 ]
  "point2 uv" [ 0 0  1 0  1 1  0 1 ]
"#
        )
    };
    std::fs::write(dir.join("image.pbrt"), scene("glow.exr", "")).unwrap();
    let desc = pathlab_scene::load(dir.join("image.pbrt").to_str().unwrap()).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let mesh = &desc.meshes[0];
    assert_eq!(mesh.emission.unwrap().radiance, Vec3::splat(2.0));
    let t = pathlab_render::texture::Tex::from_desc(mesh.emission_texture.as_ref().unwrap());
    let at = |u: f32| {
        t.eval(&pathlab_render::texture::TexPoint::uv(glam::Vec2::new(
            u, 0.5,
        )))
    };
    assert_eq!((at(0.25), at(0.75)), (Vec3::ZERO, Vec3::ONE));
    // With a power, each triangle (area ½) emits it: L = scale Φ / (π A × mean luminance).
    std::fs::write(
        dir.join("power.pbrt"),
        scene("glow.exr", "\"float power\" 3"),
    )
    .unwrap();
    let desc = pathlab_scene::load(dir.join("power.pbrt").to_str().unwrap()).unwrap();
    let l = desc.meshes[0].emission.unwrap().radiance.x as f64;
    let expected = 2.0 * 3.0 / (PI * 0.5 * 0.5);
    assert!((l - expected).abs() < 1e-4 * expected, "{l} vs {expected}");
    // A missing image: one warning naming it, and the light still emits.
    std::fs::write(dir.join("missing.pbrt"), scene("gone.exr", "")).unwrap();
    let desc = pathlab_scene::load(dir.join("missing.pbrt").to_str().unwrap()).unwrap();
    assert_eq!(desc.warnings.len(), 1, "{:?}", desc.warnings);
    assert!(
        desc.warnings[0].contains("gone.exr"),
        "{}",
        desc.warnings[0]
    );
    assert!(desc.meshes[0].emission.is_some());
    // L and an image together are an error, as in pbrt-v4.
    std::fs::write(
        dir.join("both.pbrt"),
        scene("glow.exr", "\"rgb L\" [ 1 1 1 ]"),
    )
    .unwrap();
    let err = pathlab_scene::load(dir.join("both.pbrt").to_str().unwrap()).unwrap_err();
    assert!(err.to_string().contains("both.pbrt"), "{err}");
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
