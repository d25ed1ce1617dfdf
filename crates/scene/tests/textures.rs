//! Image textures from OBJ (`map_Kd`), Mitsuba (`bitmap`) and COLLADA (`<texture>`): the file is
//! found, 8-bit colour is decoded from sRGB, and the texel under a hit point is the albedo
//! there.

use glam::{Vec2, Vec3};
use pathlab_render::desc::{MaterialDesc, TextureDesc};
use pathlab_render::geometry::Ray;
use pathlab_render::image_io::{srgb_decode, write_rgb8};
use pathlab_render::scene::Scene;
use std::path::{Path, PathBuf};

/// A fresh directory with a 2 x 2 texture: top row red, green; bottom row blue, grey 128.
fn fixture(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("textures")
        .join(name);
    std::fs::create_dir_all(&dir).unwrap();
    #[rustfmt::skip]
    let bytes = [255, 0, 0, 0, 255, 0,
                 0, 0, 255, 128, 128, 128];
    write_rgb8(&dir.join("tex.png"), 2, 2, &bytes).unwrap();
    dir
}

/// The albedo (f · π) seen by a ray from `origin` straight down -z.
fn albedo_at(scene: &Scene, origin: Vec3) -> Vec3 {
    let ray = Ray::new(origin, Vec3::NEG_Z);
    let si = scene
        .intersect(&ray)
        .0
        .expect("the ray hits the textured quad");
    let bsdf = scene.bsdf(&si, Vec3::Z);
    bsdf.f(Vec3::Z, Vec3::Z) * std::f32::consts::PI
}

fn assert_close(a: Vec3, b: Vec3) {
    assert!((a - b).abs().max_element() < 1e-4, "{a} vs {b}");
}

#[test]
fn obj_map_kd_is_the_albedo_under_each_point() {
    let dir = fixture("obj");
    std::fs::write(
        dir.join("quad.mtl"),
        "newmtl tex\nKd 1 1 1\nmap_Kd tex.png\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl tex\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    let desc = pathlab_scene::load(dir.join("quad.obj").to_str().unwrap()).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let scene = Scene::build(&desc).unwrap();
    // v grows upwards: (¼, ¼) is the bottom-left texel.
    assert_close(albedo_at(&scene, Vec3::new(0.25, 0.25, 1.0)), Vec3::Z);
    assert_close(albedo_at(&scene, Vec3::new(0.75, 0.75, 1.0)), Vec3::Y);
    assert_close(
        albedo_at(&scene, Vec3::new(0.75, 0.25, 1.0)),
        Vec3::splat(srgb_decode(128.0 / 255.0)),
    );
    // Halfway between two texel centres: the average of the linear values.
    assert_close(
        albedo_at(&scene, Vec3::new(0.25, 0.5, 1.0)),
        Vec3::new(0.5, 0.0, 0.5),
    );
}

#[test]
fn mitsuba_bitmap_on_a_rectangle() {
    let dir = fixture("mitsuba");
    std::fs::write(
        dir.join("scene.xml"),
        r#"<scene version="3.0.0">
  <shape type="rectangle">
    <bsdf type="diffuse">
      <texture type="bitmap" name="reflectance"><string name="filename" value="tex.png"/></texture>
    </bsdf>
  </shape>
  <emitter type="constant"/>
</scene>"#,
    )
    .unwrap();
    let desc = pathlab_scene::load(dir.join("scene.xml").to_str().unwrap()).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let scene = Scene::build(&desc).unwrap();
    // The rectangle spans [-1, 1]² with Mitsuba's (u, v) = ((x + 1)/2, (y + 1)/2), and
    // Mitsuba's v = 0 is the image's top row: y = -1 shows the top of the image.
    assert_close(albedo_at(&scene, Vec3::new(-0.5, -0.5, 1.0)), Vec3::X);
    assert_close(albedo_at(&scene, Vec3::new(-0.5, 0.5, 1.0)), Vec3::Z);
    assert_close(albedo_at(&scene, Vec3::new(0.5, -0.5, 1.0)), Vec3::Y);
}

#[test]
fn collada_texture_resolves_sampler_surface_and_image() {
    let dir = fixture("collada");
    let plane = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/cs184/plane.dae");
    let text = std::fs::read_to_string(plane).unwrap();
    // The plane with an image, a surface and a sampler, its diffuse colour replaced by the
    // texture, and every corner's texture coordinate at the top-left texel's centre.
    let text = text
        .replace(
            "<library_images/>",
            r#"<library_images><image id="tex_png" name="tex_png"><init_from>tex.png</init_from></image></library_images>"#,
        )
        .replace(
            r#"<technique sid="common">"#,
            r#"<newparam sid="tex_png-surface"><surface type="2D"><init_from>tex_png</init_from></surface></newparam>
               <newparam sid="tex_png-sampler"><sampler2D><source>tex_png-surface</source></sampler2D></newparam>
               <technique sid="common">"#,
        )
        .replace(
            r#"<color sid="diffuse">0.6 0.6 0.6 1</color>"#,
            r#"<texture texture="tex_png-sampler" texcoord="UVMap"/>"#,
        )
        .replace(
            "0 1 0 1 0 1 0 1 0 1 0 1",
            "0.25 0.75 0.25 0.75 0.25 0.75 0.25 0.75 0.25 0.75 0.25 0.75",
        );
    std::fs::write(dir.join("plane.dae"), text).unwrap();
    let desc = pathlab_scene::load(dir.join("plane.dae").to_str().unwrap()).unwrap();
    assert!(
        desc.warnings.iter().all(|w| !w.contains("texture")),
        "{:?}",
        desc.warnings
    );
    let textured: Vec<_> = desc
        .materials
        .iter()
        .filter_map(|m| match m {
            MaterialDesc::TexturedDiffuse {
                texture: TextureDesc::Image { image, .. },
                ..
            } => Some(image.clone()),
            _ => None,
        })
        .collect();
    assert_eq!(textured.len(), 1);
    assert_close(textured[0].eval(Vec2::new(0.25, 0.75)), Vec3::X);
    let scene = Scene::build(&desc).unwrap();
    assert!(scene.stats().triangles >= 2);
}

#[test]
fn a_missing_texture_is_a_warning_not_a_failure() {
    let dir = fixture("missing");
    std::fs::write(
        dir.join("quad.mtl"),
        "newmtl tex\nKd 0.5 0.5 0.5\nmap_Kd nowhere.png\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl tex\nf 1 2 3\n",
    )
    .unwrap();
    let desc = pathlab_scene::load(dir.join("quad.obj").to_str().unwrap()).unwrap();
    assert!(
        desc.warnings.iter().any(|w| w.contains("nowhere.png")),
        "{:?}",
        desc.warnings
    );
    assert!(matches!(desc.materials[0], MaterialDesc::Diffuse { .. }));
}

#[test]
fn gltf_base_colour_texture_times_factor() {
    let dir = fixture("gltf");
    let mut bin = Vec::new();
    for p in [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ] {
        for c in p {
            bin.extend(c.to_le_bytes());
        }
    }
    // glTF's v runs down the image: the corner at y = 1 shows the top row.
    for t in [[0.0f32, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]] {
        for c in t {
            bin.extend(c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend(i.to_le_bytes());
    }
    std::fs::write(dir.join("quad.bin"), &bin).unwrap();
    let json = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "images": [{{"uri": "tex.png"}}],
  "textures": [{{"source": 0}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.5, 0.5, 0.5, 1], "baseColorTexture": {{"index": 0}}, "metallicFactor": 0}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2, "material": 0}}]}}],
  "buffers": [{{"uri": "quad.bin", "byteLength": {len}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 80, "byteLength": 12}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
        len = bin.len()
    );
    std::fs::write(dir.join("quad.gltf"), json).unwrap();
    let desc = pathlab_scene::load(dir.join("quad.gltf").to_str().unwrap()).unwrap();
    assert!(
        desc.warnings.iter().all(|w| !w.contains("image")),
        "{:?}",
        desc.warnings
    );
    let scene = Scene::build(&desc).unwrap();
    assert_close(
        albedo_at(&scene, Vec3::new(0.25, 0.25, 1.0)),
        Vec3::new(0.0, 0.0, 0.5),
    );
    assert_close(
        albedo_at(&scene, Vec3::new(0.25, 0.75, 1.0)),
        Vec3::new(0.5, 0.0, 0.0),
    );
}
