//! pbrt-v4's materials, textures, spectra and quadrics, each checked against pbrt-v4's
//! definition: values at points, closed forms, and furnaces (shapes as lights, the screen
//! window and the film are `pbrt_film_shapes.rs`'s; the coated and mixed materials
//! `pbrt_layered.rs`'s).

use glam::DVec3;
use pathlab_testkit::render::assert_mean;
use std::path::PathBuf;

mod pbrt_common;
use pbrt_common::{load_text, render_film, FURNACE};

/// The world block `world` under a small camera, loaded from a folder of its own (`tag`) that
/// also holds `two.exr`, a 2 x 1 image: 0.2 on its left half, 0.6 on its right; no warnings.
fn load_with_two_texels(tag: &str, world: &str) -> pathlab_render::desc::SceneDesc {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(tag);
    std::fs::create_dir_all(&dir).unwrap();
    let texels = [glam::Vec3::splat(0.2), glam::Vec3::splat(0.6)];
    pathlab_render::image_io::write_exr(&dir.join("two.exr"), 2, 1, &texels, &[]).unwrap();
    let scene = format!(
        "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\n\
         Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\nWorldBegin\n{world}"
    );
    std::fs::write(dir.join("scene.pbrt"), scene).unwrap();
    let desc = pathlab_scene::load(dir.join("scene.pbrt").to_str().unwrap()).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    desc
}

/// The reflectance texture of a textured diffuse material.
fn reflectance_texture(m: &pathlab_render::desc::MaterialDesc) -> pathlab_render::texture::Tex {
    match m {
        pathlab_render::desc::MaterialDesc::TexturedDiffuse { texture, .. } => {
            pathlab_render::texture::Tex::from_desc(texture)
        }
        other => panic!("not a textured diffuse material: {other:?}"),
    }
}

/// Texture `t` at (u, v).
fn tex_at(t: &pathlab_render::texture::Tex, u: f32, v: f32) -> glam::Vec3 {
    t.eval(&pathlab_render::texture::TexPoint::uv(glam::Vec2::new(
        u, v,
    )))
}

/// Whether two colours agree to 1e-5.
fn close(a: glam::Vec3, b: glam::Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

#[test]
fn textures_scale_mix_invert_and_checker_as_pbrt_defines_them() {
    use glam::Vec3;
    use pathlab_render::desc::{MaterialDesc, TextureDesc};
    use pathlab_render::texture::Tex;
    let desc = load_with_two_texels(
        "pbrt-textures",
        r#"Texture "img" "spectrum" "imagemap" "string filename" "two.exr" "string filter" "point" "string encoding" "linear"
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
"#,
    );
    let (texture, at) = (reflectance_texture, tex_at);
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
fn bilerp_textures_and_black_wrapping_as_pbrt_defines_them() {
    use glam::Vec3;
    let desc = load_with_two_texels(
        "pbrt-bilerp",
        r#"Texture "corners" "spectrum" "bilerp" "rgb v00" [ 1 0 0 ] "rgb v10" [ 0 1 0 ] "rgb v01" [ 0 0 1 ] "rgb v11" [ 1 1 1 ]
Texture "ramp" "float" "bilerp"
Texture "wide" "float" "bilerp" "float v10" 1 "float v11" 0 "float v01" 0 "float uscale" 2
Texture "black" "spectrum" "imagemap" "string filename" "two.exr" "string encoding" "linear" "string wrap" "black"
Texture "clamped" "spectrum" "imagemap" "string filename" "two.exr" "string encoding" "linear" "string wrap" "clamp"
MakeNamedMaterial "m0" "string type" "diffuse" "texture reflectance" "corners"
MakeNamedMaterial "m1" "string type" "diffuse" "texture reflectance" "black"
MakeNamedMaterial "m2" "string type" "diffuse" "texture reflectance" "clamped"
Texture "by-ramp" "spectrum" "mix" "rgb tex1" [ 0 0 0 ] "rgb tex2" [ 1 1 1 ] "texture amount" "ramp"
Texture "by-wide" "spectrum" "mix" "rgb tex1" [ 0 0 0 ] "rgb tex2" [ 1 1 1 ] "texture amount" "wide"
MakeNamedMaterial "m3" "string type" "diffuse" "texture reflectance" "by-ramp"
MakeNamedMaterial "m4" "string type" "diffuse" "texture reflectance" "by-wide"
NamedMaterial "m0"
Shape "sphere"
"#,
    );
    let (texture, at) = (reflectance_texture, tex_at);
    let m = &desc.materials;
    // The corners at the corners, their mean at the centre, linear along the edges.
    let t = texture(&m[0]);
    assert!(close(at(&t, 0.0, 0.0), Vec3::X));
    assert!(close(at(&t, 1.0, 0.0), Vec3::Y));
    assert!(close(at(&t, 0.0, 1.0), Vec3::Z));
    assert!(close(at(&t, 1.0, 1.0), Vec3::ONE));
    assert!(close(at(&t, 0.5, 0.5), Vec3::splat(0.5)));
    assert!(close(at(&t, 0.25, 0.0), Vec3::new(0.75, 0.25, 0.0)));
    // Black wrapping: a bilinear read at the image's left edge is half its first texel and
    // half the black beyond; clamped, it is the first texel.
    let t = texture(&m[1]);
    assert!(close(at(&t, 0.25, 0.5), Vec3::splat(0.2)));
    assert!(close(at(&t, 0.0, 0.5), Vec3::splat(0.1)));
    assert!(close(at(&t, 1.0, 0.5), Vec3::splat(0.3)));
    assert!(close(at(&t, 1.5, 0.5), Vec3::ZERO));
    let t = texture(&m[2]);
    assert!(close(at(&t, 0.0, 0.5), Vec3::splat(0.2)));
    // Float bilerps (as mix amounts between black and white): the defaults give t; a scaled
    // mapping extrapolates, s (1 - t) at s = 1.5.
    let t = texture(&m[3]);
    assert!(close(at(&t, 0.3, 0.7), Vec3::splat(0.7)));
    let t = texture(&m[4]);
    assert!(close(at(&t, 0.75, 0.0), Vec3::splat(1.5)));
    assert!(close(at(&t, 0.25, 0.5), Vec3::splat(0.25)));
}

#[test]
fn conductors_take_textured_roughness_remapped_as_pbrt_remaps_it() {
    use glam::{Vec2, Vec3};
    use pathlab_render::desc::MaterialDesc;
    use pathlab_render::texture::{Tex, TexPoint};
    let desc = load_text(
        "textured-roughness",
        &[(
            "r.pbrt",
            r#"WorldBegin
Texture "ramp" "float" "bilerp"
Texture "flat" "float" "constant" "float value" 0.09
MakeNamedMaterial "remapped" "string type" "conductor" "texture roughness" "ramp"
MakeNamedMaterial "raw" "string type" "conductor" "texture uroughness" "ramp" "float vroughness" 0.2 "bool remaproughness" false
MakeNamedMaterial "constant" "string type" "conductor" "texture roughness" "flat"
NamedMaterial "remapped"
Shape "sphere"
"#,
        )],
    )
    .unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    // Two-sided conductors: the material inside.
    let inner = |m: &MaterialDesc| -> MaterialDesc {
        match m {
            MaterialDesc::TwoSided { front, .. } => (**front).clone(),
            other => other.clone(),
        }
    };
    let alphas = |m: &MaterialDesc| match inner(m) {
        MaterialDesc::RoughConductor {
            alpha_u, alpha_v, ..
        } => (Tex::from_desc(&alpha_u), Tex::from_desc(&alpha_v)),
        other => panic!("not a textured conductor: {other:?}"),
    };
    let at = |t: &Tex, v: f32| t.eval(&TexPoint::uv(Vec2::new(0.3, v)));
    let close = |a: Vec3, b: f32| (a - Vec3::splat(b)).abs().max_element() < 1e-6;
    // α = √roughness, the roughness being t along the bilerp's v.
    let (u, v) = alphas(&desc.materials[0]);
    assert!(close(at(&u, 0.25), 0.5) && close(at(&v, 0.64), 0.8));
    // Not remapped, and v given as a number.
    let (u, v) = alphas(&desc.materials[1]);
    assert!(close(at(&u, 0.25), 0.25) && close(at(&v, 0.7), 0.2));
    // A constant texture is a number: the plain conductor, α = √0.09.
    match inner(&desc.materials[2]) {
        MaterialDesc::Conductor { alpha, .. } => assert!((alpha - 0.3).abs() < 1e-6),
        other => panic!("{other:?}"),
    }
}

#[test]
fn spectra_read_from_files_as_pbrt_reads_them() {
    use pathlab_render::desc::MaterialDesc;
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("pbrt-spd");
    std::fs::create_dir_all(dir.join("spds")).unwrap();
    // The same reddish reflectance inline and in a file with comments and commas; a file of
    // an odd count of numbers; no file at all.
    std::fs::write(
        dir.join("spds/red.spd"),
        "# a reddish reflectance\n400 0.1\n550, 0.1 # green\n600 0.9\n700 0.9\n",
    )
    .unwrap();
    std::fs::write(dir.join("odd.spd"), "400 0.5 500\n").unwrap();
    let scene = r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 4 "integer yresolution" 4
WorldBegin
MakeNamedMaterial "inline" "string type" "diffuse" "spectrum reflectance" [ 400 0.1 550 0.1 600 0.9 700 0.9 ]
MakeNamedMaterial "file" "string type" "diffuse" "spectrum reflectance" "spds/red.spd"
MakeNamedMaterial "odd" "string type" "diffuse" "spectrum reflectance" "odd.spd"
MakeNamedMaterial "missing" "string type" "diffuse" "spectrum reflectance" "spds/none.spd"
NamedMaterial "inline"
Shape "sphere"
"#;
    std::fs::write(dir.join("spd.pbrt"), scene).unwrap();
    let desc = pathlab_scene::load(dir.join("spd.pbrt").to_str().unwrap()).unwrap();
    let reflectance = |m: &MaterialDesc| match m {
        MaterialDesc::Diffuse { reflectance, .. } => *reflectance,
        other => panic!("not a diffuse material: {other:?}"),
    };
    let m = &desc.materials;
    let (inline, file) = (reflectance(&m[0]), reflectance(&m[1]));
    assert_eq!(inline, file);
    assert!(inline.x > 2.0 * inline.y, "reddish: {inline}");
    // The unreadable files: one warning each, naming the file and why, and grey.
    assert_eq!(desc.warnings.len(), 2, "{:?}", desc.warnings);
    assert!(
        desc.warnings[0].contains("odd.spd") && desc.warnings[0].contains("3 numbers"),
        "{}",
        desc.warnings[0]
    );
    assert!(
        desc.warnings[1].contains("none.spd"),
        "{}",
        desc.warnings[1]
    );
    assert_eq!(reflectance(&m[2]), glam::Vec3::splat(0.5));
    assert_eq!(reflectance(&m[3]), glam::Vec3::splat(0.5));
    // A name that is no file and no spectrum pathlab knows stays an error.
    let bad = load_text(
        "spd-unknown",
        &[(
            "s.pbrt",
            "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"glass-XYZ\"\nShape \"sphere\"\n",
        )],
    );
    let e = bad.expect_err("an unknown spectrum name").to_string();
    assert!(e.contains("glass-XYZ") && e.contains("s.pbrt:2"), "{e}");
}

#[test]
fn a_sphere_that_reflects_and_transmits_everything_vanishes_in_a_furnace() {
    // Under a uniform sky of radiance 1, a closed sphere whose diffuse reflectance and
    // transmittance add up to one returns all the light it receives, on both its sides: the
    // expected radiance of every pixel is 1 (light sampling and MIS leave some noise).
    let scene = FURNACE.to_string()
        + r#"Material "diffusetransmission" "rgb reflectance" [ 0.3 0.3 0.3 ] "rgb transmittance" [ 0.7 0.7 0.7 ]
Shape "sphere" "float radius" 1
"#;
    let desc = load_text("furnace", &[("furnace.pbrt", &scene)]).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let film = render_film(&desc, 64, 5);
    assert!(film.image_mean_std_error().x < 0.01);
    assert_mean("diffuse transmission furnace", &film, DVec3::ONE);
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
fn partial_spheres_are_the_part_pbrt_defines_and_vanish_in_a_furnace() {
    use std::f64::consts::PI;
    // The upper half (z from 0.5 up) of a sphere of radius 2 over three quarters of a turn,
    // centred at (1, 0, 0), emitting 9 W.
    let scene = r#"LookAt 0 0 10  0 0 0  0 1 0
Camera "perspective" "float fov" 30
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "float power" [ 9 ]
  Translate 1 0 0
  Shape "sphere" "float radius" 2 "float zmin" 0.5 "float zmax" 5 "float phimax" 270
AttributeEnd
"#;
    let desc = load_text("partial", &[("partial.pbrt", scene)]).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    assert!(desc.spheres.is_empty());
    assert_eq!(desc.meshes.len(), 1);
    let mesh = &desc.meshes[0];
    // The loader may mirror the world in x (pbrt's camera space is left-handed): the centre
    // is at x = 1 or -1. Every vertex is on the sphere, at z >= 0.5.
    let on_sphere = |c: &DVec3| ((mesh.positions[0].as_dvec3() - *c).length() - 2.0).abs() < 1e-5;
    let centre = [DVec3::X, -DVec3::X]
        .into_iter()
        .find(on_sphere)
        .expect("a vertex on the sphere");
    let mut area = 0.0;
    for t in mesh.indices.chunks_exact(3) {
        let p = [0, 1, 2].map(|k| mesh.positions[t[k] as usize].as_dvec3());
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        if cross == DVec3::ZERO {
            // Collapsed at the pole: no area, and dropped when the scene is built.
            continue;
        }
        area += 0.5 * cross.length();
        let outward = (p[0] + p[1] + p[2]) / 3.0 - centre;
        assert!(cross.dot(outward) > 0.0, "a triangle faces inwards");
    }
    for p in &mesh.positions {
        let d = p.as_dvec3() - centre;
        assert!((d.length() - 2.0).abs() < 1e-5, "{p}");
        assert!(d.z >= 0.5 - 1e-5, "{p}");
    }
    // A zone of height h on a sphere of radius r, over φmax: φmax r h.
    let exact = 1.5 * PI * 2.0 * 1.5;
    assert!(
        (area - exact).abs() < 1e-3 * exact,
        "area {area} vs {exact}"
    );
    let l = mesh.emission.unwrap().radiance.x as f64;
    assert!((l - 9.0 / (PI * area)).abs() < 1e-5 * l, "{l}");

    // A white diffuse hemisphere in a furnace reflects every bit of its sky, inside and out.
    let furnace = FURNACE.to_string()
        + r#"Material "diffuse" "rgb reflectance" [ 1 1 1 ]
Shape "sphere" "float radius" 1 "float zmin" 0
"#;
    let desc = load_text("partial-furnace", &[("furnace.pbrt", &furnace)]).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let film = render_film(&desc, 64, 5);
    assert!(film.image_mean_std_error().x < 0.01);
    assert_mean("partial sphere furnace", &film, DVec3::ONE);
}

#[test]
fn dielectrics_take_textured_and_anisotropic_roughness() {
    use glam::{Vec2, Vec3};
    use pathlab_render::desc::MaterialDesc;
    use pathlab_render::texture::{Tex, TexPoint};
    let desc = load_text(
        "dielectric-roughness",
        &[(
            "r.pbrt",
            r#"WorldBegin
Texture "ramp" "float" "bilerp"
MakeNamedMaterial "textured" "string type" "dielectric" "texture roughness" "ramp" "float eta" 1.33
MakeNamedMaterial "anisotropic" "string type" "dielectric" "float uroughness" 0.04 "float vroughness" 0.25
MakeNamedMaterial "plain" "string type" "dielectric" "float roughness" 0.04
NamedMaterial "textured"
Shape "sphere"
"#,
        )],
    )
    .unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let at = |t: &TextureDesc, v: f32| Tex::from_desc(t).eval(&TexPoint::uv(Vec2::new(0.3, v)));
    let close = |a: Vec3, b: f32| (a - Vec3::splat(b)).abs().max_element() < 1e-6;
    use pathlab_render::desc::TextureDesc;
    // α = √roughness along the bilerp's v, on both axes; the index as given.
    match &desc.materials[0] {
        MaterialDesc::RoughGlass {
            alpha_u,
            alpha_v,
            ior,
            ..
        } => {
            assert!(close(at(alpha_u, 0.25), 0.5) && close(at(alpha_v, 0.64), 0.8));
            assert_eq!(*ior, 1.33);
        }
        other => panic!("not textured glass: {other:?}"),
    }
    // Different roughness along u and v: α = (0.2, 0.5).
    match &desc.materials[1] {
        MaterialDesc::RoughGlass {
            alpha_u, alpha_v, ..
        } => assert!(close(at(alpha_u, 0.5), 0.2) && close(at(alpha_v, 0.5), 0.5)),
        other => panic!("not anisotropic glass: {other:?}"),
    }
    // One number: the plain rough glass.
    match &desc.materials[2] {
        MaterialDesc::Glass { roughness, .. } => assert!((roughness - 0.2).abs() < 1e-6),
        other => panic!("{other:?}"),
    }
}

#[test]
fn glass_of_textured_roughness_renders_as_glass_of_that_roughness() {
    // A bilerp texture of one value is a texture that the loader cannot fold to a number, so
    // the sphere takes the textured model; it must render what the number renders.
    let scene = |roughness: &str| {
        FURNACE.replace("LightSource \"infinite\" \"rgb L\" [ 1 1 1 ]", "LightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\nLightSource \"distant\" \"point3 from\" [ 1 2 3 ] \"rgb L\" [ 3 3 3 ]")
            + &format!(
                r#"Texture "flat" "float" "bilerp" "float v00" 0.09 "float v01" 0.09 "float v10" 0.09 "float v11" 0.09
Material "dielectric" {roughness}
Shape "sphere"
Material "diffuse" "rgb reflectance" [ 0.5 0.5 0.5 ]
Translate 0 0 -3
Shape "bilinearmesh" "point3 P" [ -4 -4 0  4 -4 0  -4 4 0  4 4 0 ] "integer indices" [ 0 1 2 3 ]
"#
            )
    };
    let textured = load_text(
        "glass-textured",
        &[("s.pbrt", &scene(r#""texture roughness" "flat""#))],
    )
    .unwrap();
    assert!(matches!(
        textured.materials[0],
        pathlab_render::desc::MaterialDesc::RoughGlass { .. }
    ));
    let plain = load_text(
        "glass-plain",
        &[("s.pbrt", &scene(r#""float roughness" 0.09"#))],
    )
    .unwrap();
    let (a, b) = (render_film(&textured, 256, 1), render_film(&plain, 256, 2));
    pathlab_testkit::render::assert_same_image("textured against plain roughness", &a, &b);
}
