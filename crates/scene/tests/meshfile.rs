//! OBJ and PLY meshes written by the tests themselves: counts and bounds round-trip, they render
//! with the default camera and light, and bad files give errors that name them.

use glam::Vec3;
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::integrator::{IntegratorKind, PathIntegrator};
use pathlab_render::render::{render, RenderSettings};
use pathlab_render::scene::Scene;
use pathlab_scene::{info, load, Error};
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    pathlab_testkit::process::scratch(env!("CARGO_TARGET_TMPDIR"), "meshfile-tests", name)
}

/// A box [-1, 2] x [0, 1] x [-3, 0.5] as 8 vertices and 6 quads.
fn box_vertices() -> Vec<[f32; 3]> {
    let (x, y, z) = ([-1.0, 2.0], [0.0, 1.0], [-3.0, 0.5]);
    let mut v = Vec::new();
    for &a in &x {
        for &b in &y {
            for &c in &z {
                v.push([a, b, c]);
            }
        }
    }
    v
}

const QUADS: [[u32; 4]; 6] = [
    [0, 1, 3, 2],
    [4, 6, 7, 5],
    [0, 4, 5, 1],
    [2, 3, 7, 6],
    [0, 2, 6, 4],
    [1, 5, 7, 3],
];

fn check_box(source: &str, emissive: bool) {
    let desc = load(source).unwrap_or_else(|e| panic!("{e}"));
    let s = info::summarize(&desc);
    assert_eq!(s.triangles, 12, "{source}");
    let (lo, hi) = s.bounds.unwrap();
    assert_eq!(
        (lo, hi),
        (Vec3::new(-1.0, 0.0, -3.0), Vec3::new(2.0, 1.0, 0.5)),
        "{source}"
    );
    assert_eq!(desc.meshes.iter().any(|m| m.emission.is_some()), emissive);
    let mut desc = desc;
    desc.resolution = [32, 24];
    let scene = Scene::build(&desc).unwrap();
    let (film, stats) = render(
        &scene,
        &IntegratorKind::Path(PathIntegrator::default()),
        &RenderSettings::new(16, 1, SamplerKind::Independent),
        &|_| {},
        &Default::default(),
    );
    assert_eq!(stats.nonfinite_samples, 0);
    let m = film.image_mean();
    assert!(m.is_finite() && m.max_element() > 1e-3, "{source}: {m:?}");
}

#[test]
fn obj_with_mtl_round_trips_and_renders() {
    let obj = scratch("box.obj");
    let mut text = String::from("mtllib box.mtl\no box\nusemtl red\n");
    for v in box_vertices() {
        text += &format!("v {} {} {}\n", v[0], v[1], v[2]);
    }
    for q in QUADS {
        text += &format!("f {} {} {} {}\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    }
    std::fs::write(&obj, text).unwrap();
    std::fs::write(scratch("box.mtl"), "newmtl red\nKd 0.8 0.1 0.1\nNs 10\n").unwrap();
    check_box(obj.to_str().unwrap(), false);
    let desc = load(obj.to_str().unwrap()).unwrap();
    assert!(desc.materials.iter().any(|m| matches!(m,
        pathlab_render::desc::MaterialDesc::Diffuse { reflectance, .. } if (*reflectance - Vec3::new(0.8, 0.1, 0.1)).length() < 1e-6)));
    // An emissive material (Ke) makes the mesh a light; no default lights are added then.
    std::fs::write(scratch("box.mtl"), "newmtl red\nKd 0.8 0.1 0.1\nKe 2 2 2\n").unwrap();
    check_box(obj.to_str().unwrap(), true);
    // A negative emission is refused, naming the material.
    std::fs::write(
        scratch("box.mtl"),
        "newmtl red\nKd 0.8 0.1 0.1\nKe 2 -2 2\n",
    )
    .unwrap();
    let msg = load(obj.to_str().unwrap()).unwrap_err().to_string();
    assert!(
        msg.contains("box.obj")
            && msg.contains("material 'red'")
            && msg.contains("Ke is an emission and must be >= 0"),
        "{msg}"
    );
    std::fs::write(scratch("box.mtl"), "newmtl red\nKd 0.8 0.1 0.1\nKe 2 2 2\n").unwrap();
    // Without its MTL file, the mesh is grey, with a warning naming the file.
    let mtl = scratch("box.mtl"); // (`scratch` removes the file)
    assert!(!mtl.exists());
    let desc = load(obj.to_str().unwrap()).unwrap();
    assert!(
        desc.warnings
            .iter()
            .any(|w| w.contains("box.mtl not found") && w.contains("grey diffuse")),
        "{:?}",
        desc.warnings
    );
}

fn ply_header(format: &str, vertices: usize, faces: usize) -> String {
    format!(
        "ply\nformat {format} 1.0\nelement vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    )
}

#[test]
fn ascii_and_binary_ply_round_trip_and_render() {
    let ascii = scratch("box_ascii.ply");
    let mut text = ply_header("ascii", 8, 6);
    for v in box_vertices() {
        text += &format!("{} {} {}\n", v[0], v[1], v[2]);
    }
    for q in QUADS {
        text += &format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    std::fs::write(&ascii, text).unwrap();
    check_box(ascii.to_str().unwrap(), false);

    let binary = scratch("box_binary.ply");
    std::fs::write(&binary, binary_box(6)).unwrap();
    check_box(binary.to_str().unwrap(), false);
}

fn binary_box(declared_faces: usize) -> Vec<u8> {
    let mut bytes = ply_header("binary_little_endian", 8, declared_faces).into_bytes();
    for v in box_vertices() {
        for c in v {
            bytes.extend(c.to_le_bytes());
        }
    }
    for q in QUADS {
        bytes.push(4);
        for i in q {
            bytes.extend((i as i32).to_le_bytes());
        }
    }
    bytes
}

#[test]
fn bad_mesh_files_are_errors_naming_the_file() {
    let check = |name: &str, bytes: Vec<u8>, expected: &str| {
        let path = scratch(name);
        std::fs::write(&path, bytes).unwrap();
        let e = load(path.to_str().unwrap()).expect_err(name);
        let msg = e.to_string();
        assert!(msg.contains(name), "{msg}");
        assert!(
            msg.to_lowercase().contains(expected),
            "expected '{expected}' in: {msg}"
        );
    };
    // Truncated binary PLY, and one whose header declares far more faces than it holds.
    let full = binary_box(6);
    check("truncated.ply", full[..full.len() - 7].to_vec(), "ply");
    check("huge.ply", binary_box(4_000_000_000), "ply");
    let mut nan = ply_header("binary_little_endian", 3, 1).into_bytes();
    for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, f32::NAN, 0.0, 1.0, 0.0] {
        nan.extend(c.to_le_bytes());
    }
    nan.push(3);
    for i in [0i32, 1, 2] {
        nan.extend(i.to_le_bytes());
    }
    check("nan.ply", nan, "finite");
    let mut text_nan = ply_header("ascii", 3, 1);
    text_nan += "0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n";
    check(
        "text_nan.ply",
        text_nan.into_bytes(),
        "text_nan.ply:11: not a valid ply file",
    );
    let mut range = ply_header("ascii", 3, 1);
    range += "0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n";
    check("range.ply", range.into_bytes(), "out of range");
    check(
        "range.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n".to_vec(),
        "obj",
    );
    check("empty.obj", b"# nothing\n".to_vec(), "no geometry");
    let missing = load("/no/such/mesh.ply").unwrap_err();
    assert!(matches!(missing, Error::Io { .. }), "{missing}");
    let unknown = load("scene.fbx").unwrap_err();
    assert!(unknown.to_string().contains("unknown scene format"));
}

/// A glTF with the test box as an indexed mesh under a translated node, a camera and a point
/// light; its buffer in a separate .bin file.
fn write_gltf(name: &str, translate_x: f32, bad_index: bool) -> PathBuf {
    let mut bin = Vec::new();
    for v in box_vertices() {
        for c in v {
            bin.extend(c.to_le_bytes());
        }
    }
    let mut tris: Vec<u16> = Vec::new();
    for q in QUADS {
        tris.extend([
            q[0] as u16,
            q[1] as u16,
            q[2] as u16,
            q[0] as u16,
            q[2] as u16,
            q[3] as u16,
        ]);
    }
    if bad_index {
        tris[5] = 40;
    }
    for i in &tris {
        bin.extend(i.to_le_bytes());
    }
    let bin_name = format!("{name}.bin");
    std::fs::write(scratch(&bin_name), &bin).unwrap();
    let json = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {{"KHR_lights_punctual": {{"lights": [{{"type": "point", "color": [1, 1, 1], "intensity": 20}}]}}}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 1, 2]}}],
  "nodes": [
    {{"mesh": 0, "translation": [{translate_x}, 0, 0]}},
    {{"camera": 0, "translation": [0, 0.5, 8]}},
    {{"translation": [0, 4, 2], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}}
  ],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.8, "aspectRatio": 1.5, "znear": 0.1}}}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.2, 0.7, 0.3, 1], "metallicFactor": 0}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}}],
  "buffers": [{{"uri": "{bin_name}", "byteLength": {len}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 96}},
    {{"buffer": 0, "byteOffset": 96, "byteLength": 72}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [-1, 0, -3], "max": [2, 1, 0.5]}},
    {{"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}}
  ]
}}"#,
        len = bin.len()
    );
    let path = scratch(&format!("{name}.gltf"));
    std::fs::write(&path, json).unwrap();
    path
}

#[test]
fn gltf_round_trips_and_renders() {
    let path = write_gltf("box", 0.0, false);
    check_box(path.to_str().unwrap(), false);
    let desc = load(path.to_str().unwrap()).unwrap();
    assert_eq!(desc.point_lights.len(), 1);
    assert_eq!(desc.camera.origin, Vec3::new(0.0, 0.5, 8.0));
    assert_eq!(desc.resolution, [720, 480]);
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    // Node transforms apply.
    let moved = load(write_gltf("moved", 3.0, false).to_str().unwrap()).unwrap();
    let (lo, _) = info::summarize(&moved).bounds.unwrap();
    assert_eq!(lo.x, 2.0);
    // Bad input names the file.
    let bad = write_gltf("bad", 0.0, true);
    let msg = load(bad.to_str().unwrap()).unwrap_err().to_string();
    assert!(
        msg.contains("bad.gltf") && msg.contains("out of range"),
        "{msg}"
    );
    // A light of negative intensity is refused, naming it.
    let text = std::fs::read_to_string(&path).unwrap();
    let negative = path.with_file_name("negative.gltf");
    std::fs::write(
        &negative,
        text.replace("\"intensity\": 20", "\"intensity\": -20"),
    )
    .unwrap();
    let msg = load(negative.to_str().unwrap()).unwrap_err().to_string();
    assert!(
        msg.contains("negative.gltf") && msg.contains("light 0") && msg.contains("must be >= 0"),
        "{msg}"
    );
    let garbage = scratch("garbage.gltf");
    std::fs::write(&garbage, "{ not json").unwrap();
    let msg = load(garbage.to_str().unwrap()).unwrap_err().to_string();
    assert!(
        msg.contains("garbage.gltf") && msg.contains("glTF"),
        "{msg}"
    );
}

#[test]
fn binary_ply_reads_as_the_general_reader_reads_it() {
    // The same box with normals and texture coordinates, little and big endian, with double
    // positions and ushort indices: the direct binary reader must give what the general reader
    // gives for the ASCII file (and for a file with an extra attribute, which only the general
    // reader takes).
    let verts = box_vertices();
    let props = "property float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n";
    let header = |format: &str, props: &str, index: &str| {
        format!("ply\nformat {format} 1.0\ncomment test\nelement vertex 8\n{props}element face 6\nproperty list uchar {index} vertex_indices\nend_header\n")
    };
    let extra = |i: usize| {
        [
            0.5 * i as f32,
            1.0,
            0.0,
            0.25 * i as f32,
            1.0 - 0.1 * i as f32,
        ]
    };
    let mut ascii = header("ascii", props, "int");
    for (i, v) in verts.iter().enumerate() {
        let e = extra(i);
        ascii += &format!(
            "{} {} {} {} {} {} {} {}\n",
            v[0], v[1], v[2], e[0], e[1], e[2], e[3], e[4]
        );
    }
    for q in QUADS {
        ascii += &format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    let binary = |little: bool| {
        let mut b = header(
            if little {
                "binary_little_endian"
            } else {
                "binary_big_endian"
            },
            &props.replace(
                "float x\nproperty float y\nproperty float z",
                "double x\nproperty double y\nproperty double z",
            ),
            "ushort",
        )
        .into_bytes();
        for (i, v) in verts.iter().enumerate() {
            for c in v {
                b.extend(if little {
                    (*c as f64).to_le_bytes()
                } else {
                    (*c as f64).to_be_bytes()
                });
            }
            for c in extra(i) {
                b.extend(if little {
                    c.to_le_bytes()
                } else {
                    c.to_be_bytes()
                });
            }
        }
        for q in QUADS {
            b.push(4);
            for i in q {
                b.extend(if little {
                    (i as u16).to_le_bytes()
                } else {
                    (i as u16).to_be_bytes()
                });
            }
        }
        b
    };
    let mesh = |name: &str, bytes: Vec<u8>| {
        let path = scratch(name);
        std::fs::write(&path, bytes).unwrap();
        pathlab_scene::meshfile::ply_mesh(&path).unwrap()
    };
    let general = mesh("attrs_ascii.ply", ascii.into_bytes());
    for (name, bytes) in [
        ("attrs_le.ply", binary(true)),
        ("attrs_be.ply", binary(false)),
    ] {
        let direct = mesh(name, bytes);
        assert_eq!(direct.positions, general.positions, "{name}");
        assert_eq!(direct.indices, general.indices, "{name}");
        assert_eq!(direct.normals, general.normals, "{name}");
        assert_eq!(direct.uvs, general.uvs, "{name}");
        assert!(direct.attributes.is_empty() && general.attributes.is_empty());
    }
    // A property pathlab keeps as an attribute goes to the general reader.
    let mut with_attr = ply_header("binary_little_endian", 8, 6)
        .replace(
            "property float z\n",
            "property float z\nproperty float weight\n",
        )
        .into_bytes();
    for v in verts {
        for c in v {
            with_attr.extend(c.to_le_bytes());
        }
        with_attr.extend(2.0f32.to_le_bytes());
    }
    for q in QUADS {
        with_attr.push(4);
        for i in q {
            with_attr.extend((i as i32).to_le_bytes());
        }
    }
    let m = mesh("attr_weight.ply", with_attr);
    assert_eq!(m.attributes.len(), 1);
    assert_eq!(m.attributes[0].name, "vertex_weight");
}
