//! Corrupted scene files: truncated, bit-flipped and number-mangled variants of the course's
//! scenes must load or fail with an error, never panic, and stay within a memory bound; what
//! loads must build and render.

use pathlab_mc::sampler::SamplerKind;
use pathlab_render::integrator::{IntegratorKind, PathIntegrator};
use pathlab_render::render::{render, RenderSettings};
use pathlab_render::scene::Scene;
use pathlab_scene::collada;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Counts the bytes this test binary holds, and the most it held, so that a loader that
/// trusted a huge declared count would be caught even if the allocation happened to succeed.
struct Counting;

static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every method forwards to the system allocator with the caller's arguments unchanged,
// so `Counting` upholds exactly the guarantees `System` does; the counters are plain atomics and
// never affect what is returned.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: same contract as the caller's, forwarded unchanged.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = CURRENT.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` was allocated by `alloc` above with this layout.
        unsafe { System.dealloc(ptr, layout) };
        CURRENT.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Most memory the whole test binary may hold at once while loading corrupted files: the
/// inputs are a few tens of kilobytes, so anything near this means a declared size was trusted.
const MEMORY_BOUND: usize = 512 << 20;

fn assert_memory_bound() {
    let peak = PEAK.load(Ordering::Relaxed);
    assert!(
        peak < MEMORY_BOUND,
        "peak allocation {peak} bytes exceeds {MEMORY_BOUND}"
    );
}

#[test]
fn the_allocator_counts() {
    let before = CURRENT.load(Ordering::Relaxed);
    let v = vec![0u8; 1 << 20];
    assert!(
        CURRENT.load(Ordering::Relaxed) >= before + (1 << 20)
            || PEAK.load(Ordering::Relaxed) >= 1 << 20
    );
    drop(v);
    assert_memory_bound();
}

fn sample(name: &str) -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/cs184")
        .join(name);
    std::fs::read_to_string(path).unwrap()
}

const SAMPLES: [&str; 3] = ["cube.dae", "CBspheres.dae", "plane.dae"];

/// Loads corrupted text; whatever loads must also build and render a tiny image.
fn exercise(text: &str) {
    if let Ok(desc) = collada::parse(text, Path::new("corrupt.dae")) {
        render_tiny(desc);
    }
    assert_memory_bound();
}

/// Builds and renders a 4 x 3 image of a scene that loaded; it must be finite.
fn render_tiny(mut desc: pathlab_render::desc::SceneDesc) {
    assert_memory_bound();
    desc.resolution = [4, 3];
    if let Ok(scene) = Scene::build(&desc) {
        let settings = RenderSettings::new(1, 0, SamplerKind::Independent);
        let integrator = IntegratorKind::Path(PathIntegrator::default());
        let (film, _) = render(&scene, &integrator, &settings, &|_| {}, &Default::default());
        assert!(film.pixels().iter().all(|p| p.mean().is_finite()));
    }
}

/// Writes corrupted bytes to a file named `name` and loads it by extension.
fn exercise_file(name: &str, bytes: &[u8]) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("corruption");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    if let Ok(desc) = pathlab_scene::load(path.to_str().unwrap()) {
        render_tiny(desc);
    }
    assert_memory_bound();
    let _ = std::fs::remove_file(path);
}

/// Truncates `bytes` at `cut` (as a fraction) after flipping the given bits.
fn corrupt(mut bytes: Vec<u8>, cut: f64, flips: &[(f64, u8)]) -> Vec<u8> {
    for &(pos, bit) in flips {
        let i = ((pos * bytes.len() as f64) as usize).min(bytes.len() - 1);
        bytes[i] ^= 1 << bit;
    }
    let keep = ((cut * 1.2).min(1.0) * bytes.len() as f64) as usize;
    bytes.truncate(keep);
    bytes
}

/// Byte offsets of number tokens in `text`.
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() {
            let start = i;
            while i < b.len()
                && (b[i].is_ascii_digit() || b[i] == b'.' || b[i] == b'e' || b[i] == b'-')
            {
                i += 1;
            }
            spans.push((start, i));
        } else {
            i += 1;
        }
    }
    spans
}

const MANGLED: [&str; 10] = [
    "NaN",
    "-1",
    "1e39",
    "99999999999999",
    "",
    "-0",
    "1e-45",
    "inf",
    "4294967295",
    "0.5.5",
];

proptest! {
    // Fixed seeds: the suite tests the same cases on every run (a new seed explores others;
    // set it here to look further).
    #![proptest_config(ProptestConfig { cases: 200, failure_persistence: None, rng_seed: RngSeed::Fixed(0x5eed_0001), ..ProptestConfig::default() })]

    #[test]
    fn truncated(which in 0usize..3, cut in 0.0f64..1.0) {
        let text = sample(SAMPLES[which]);
        let mut at = (cut * text.len() as f64) as usize;
        while !text.is_char_boundary(at) {
            at -= 1;
        }
        exercise(&text[..at]);
    }

    #[test]
    fn bit_flipped(which in 0usize..3, flips in prop::collection::vec((0.0f64..1.0, 0u8..8), 1..8)) {
        let mut bytes = sample(SAMPLES[which]).into_bytes();
        for (pos, bit) in flips {
            let i = ((pos * bytes.len() as f64) as usize).min(bytes.len() - 1);
            bytes[i] ^= 1 << bit;
        }
        exercise(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn numbers_mangled(which in 0usize..3, edits in prop::collection::vec((0.0f64..1.0, 0usize..MANGLED.len()), 1..6)) {
        let mut text = sample(SAMPLES[which]);
        for (pos, k) in edits {
            let spans = number_spans(&text);
            let (s, e) = spans[((pos * spans.len() as f64) as usize).min(spans.len() - 1)];
            text.replace_range(s..e, MANGLED[k]);
        }
        exercise(&text);
    }
}

/// A small binary PLY (a square) to corrupt.
fn ply_square() -> Vec<u8> {
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
    for c in [0.0f32, 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.] {
        b.extend(c.to_le_bytes());
    }
    b.push(4);
    for i in [0i32, 1, 2, 3] {
        b.extend(i.to_le_bytes());
    }
    b
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 100, failure_persistence: None, rng_seed: RngSeed::Fixed(0x5eed_0002), ..ProptestConfig::default() })]

    #[test]
    fn ply_truncated_or_flipped(cut in 0.0f64..1.0, flips in prop::collection::vec((0.0f64..1.0, 0u8..8), 0..6)) {
        exercise_file("case.ply", &corrupt(ply_square(), cut, &flips));
    }

    #[test]
    fn obj_truncated_or_flipped(cut in 0.0f64..1.0, flips in prop::collection::vec((0.0f64..1.0, 0u8..8), 0..6)) {
        let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n".to_vec();
        exercise_file("case.obj", &corrupt(obj, cut, &flips));
    }

    #[test]
    fn mitsuba_xml_truncated_or_flipped(cut in 0.0f64..1.0, flips in prop::collection::vec((0.0f64..1.0, 0u8..8), 0..6)) {
        let xml = std::fs::read(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/cornell-box/scene.xml")).unwrap();
        exercise_file("case.xml", &corrupt(xml, cut, &flips));
    }
}

/// A Mitsuba scene around one shape of type `plugin` read from `file` next to it.
fn scene_around(plugin: &str, file: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    </sensor>
    <emitter type="constant"/>
    <shape type="{plugin}"><string name="filename" value="{file}"/></shape>
</scene>"#
    )
}

/// Mitsuba's `.serialized` rectangle from its test suite.
fn serialized_rectangle() -> Vec<u8> {
    std::fs::read(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(
            "../../tests/data/mitsuba-suite/tests/serialized/rectangle_normals_uv.serialized",
        ),
    )
    .unwrap()
}

/// Loads a scene whose `plugin` shape reads `bytes` from `file`, in a folder of its own for
/// each test (`tag`): tests run in parallel. What fails to load must name the file.
fn exercise_shape_file(tag: &str, plugin: &str, file: &str, bytes: &[u8]) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("corruption-{tag}"));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(file), bytes).unwrap();
    let scene = dir.join("scene.xml");
    std::fs::write(&scene, scene_around(plugin, file)).unwrap();
    match pathlab_scene::load(scene.to_str().unwrap()) {
        Ok(desc) => render_tiny(desc),
        Err(e) => {
            let message = e.to_string();
            assert!(
                message.contains(file),
                "the error does not name {file}: {message}"
            );
        }
    }
    assert_memory_bound();
}

fn exercise_serialized(tag: &str, mesh: &[u8]) {
    exercise_shape_file(tag, "serialized", "case.serialized", mesh);
}

/// The uncompressed body of a one-shape `.serialized` file (after its 4-byte header).
fn inflate(bytes: &[u8]) -> Vec<u8> {
    let mut body = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::ZlibDecoder::new(&bytes[4..]), &mut body)
        .unwrap();
    body
}

fn deflate(header: &[u8], body: &[u8]) -> Vec<u8> {
    let mut enc = flate2::write::ZlibEncoder::new(header.to_vec(), flate2::Compression::default());
    std::io::Write::write_all(&mut enc, body).unwrap();
    enc.finish().unwrap()
}

#[test]
fn the_serialized_rectangle_loads_and_renders() {
    let bytes = serialized_rectangle();
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("corruption-serialized-ok");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("case.serialized"), &bytes).unwrap();
    std::fs::write(
        dir.join("scene.xml"),
        scene_around("serialized", "case.serialized"),
    )
    .unwrap();
    let desc = pathlab_scene::load(dir.join("scene.xml").to_str().unwrap()).unwrap();
    assert_eq!(desc.meshes.len(), 1);
    assert_eq!(desc.meshes[0].indices.len(), 6);
    // Inflating and deflating again keeps the mesh: the body-corruption cases start from it.
    let again = deflate(&bytes[..4], &inflate(&bytes));
    std::fs::write(dir.join("case.serialized"), &again).unwrap();
    let desc2 = pathlab_scene::load(dir.join("scene.xml").to_str().unwrap()).unwrap();
    assert_eq!(desc2.meshes[0].positions, desc.meshes[0].positions);
}

#[test]
fn serialized_counts_are_not_trusted() {
    // Version 4 body: flags (u32), the shape's name ending in a zero byte, then the vertex and
    // triangle counts (u64 each).
    let bytes = serialized_rectangle();
    let body = inflate(&bytes);
    let name_end = 4 + body[4..].iter().position(|&b| b == 0).unwrap();
    let counts = name_end + 1;
    for field in [0, 8] {
        for count in [0u64, 5, 1 << 20, 1 << 26, 1 << 28, 1 << 40, u64::MAX] {
            let mut b = body.clone();
            b[counts + field..counts + field + 8].copy_from_slice(&count.to_le_bytes());
            exercise_serialized("serialized-counts", &deflate(&bytes[..4], &b));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 100, failure_persistence: None, rng_seed: RngSeed::Fixed(0x5eed_0003), ..ProptestConfig::default() })]

    /// The file as stored, truncated or bit-flipped (mostly caught by zlib's checksum).
    #[test]
    fn serialized_truncated_or_flipped(cut in 0.0f64..1.0, flips in prop::collection::vec((0.0f64..1.0, 0u8..8), 0..6)) {
        exercise_serialized("serialized-file", &corrupt(serialized_rectangle(), cut, &flips));
    }

    /// The mesh data itself corrupted (counts, flags, indices, numbers) and compressed again,
    /// so that the reader, not zlib, meets the damage.
    #[test]
    fn serialized_body_corrupted(cut in 0.0f64..1.0, flips in prop::collection::vec((0.0f64..1.0, 0u8..8), 1..8)) {
        let bytes = serialized_rectangle();
        let body = corrupt(inflate(&bytes), cut, &flips);
        exercise_serialized("serialized-body", &deflate(&bytes[..4], &body));
    }
}

/// A small signed distance grid (a sphere, 6³ samples) as a `.vol` file.
fn sphere_grid() -> Vec<u8> {
    let n = 6u32;
    let mut values = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let p = glam::Vec3::new(x as f32, y as f32, z as f32) / (n - 1) as f32;
                values.push((p - 0.5).length() - 0.3);
            }
        }
    }
    pathlab_scene::mitsuba::volume::write(&values, [n; 3])
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 100, failure_persistence: None, rng_seed: RngSeed::Fixed(0x5eed_0004), ..ProptestConfig::default() })]

    /// SDF grids truncated or bit-flipped (header counts, samples made NaN or huge).
    #[test]
    fn sdf_grid_truncated_or_flipped(cut in 0.0f64..1.0, flips in prop::collection::vec((0.0f64..1.0, 0u8..8), 0..6)) {
        exercise_shape_file("sdfgrid", "sdfgrid", "case.vol", &corrupt(sphere_grid(), cut, &flips));
    }
}

/// Standard base64 of `bytes`, for a glTF buffer's data URI.
fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                out.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// The buffer of [`gltf_triangle`]: three positions and the indices (padded to 44 bytes).
fn triangle_buffer() -> Vec<u8> {
    let mut buffer = Vec::new();
    for c in [0.0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        buffer.extend(c.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0] {
        buffer.extend(i.to_le_bytes());
    }
    buffer
}

/// A glTF 2.0 file of one triangle (positions and indices in an embedded buffer), a camera
/// and an emissive material.
fn gltf_triangle() -> String {
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64(&triangle_buffer())
    );
    gltf_triangle_with_buffer(&uri)
}

/// [`gltf_triangle`] with its buffer at `uri`.
fn gltf_triangle_with_buffer(uri: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],
"nodes":[{{"mesh":0}},{{"camera":0,"translation":[0.3,0.3,2]}}],
"cameras":[{{"type":"perspective","perspective":{{"yfov":0.8,"znear":0.01}}}}],
"materials":[{{"pbrMetallicRoughness":{{"baseColorFactor":[0.8,0.5,0.2,1]}},"emissiveFactor":[1,1,1]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"material":0}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
"buffers":[{{"byteLength":44,"uri":"{uri}"}}]}}"#
    )
}

#[test]
fn the_gltf_triangle_loads() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("corruption-gltf-ok");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("tri.gltf");
    std::fs::write(&path, gltf_triangle()).unwrap();
    let desc = pathlab_scene::load(path.to_str().unwrap()).unwrap();
    assert_eq!(desc.meshes.len(), 1);
    assert_eq!(desc.meshes[0].indices, vec![0, 1, 2]);
}

#[test]
fn a_gltf_buffer_file_is_read_beside_it_and_named_when_missing() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("corruption-gltf-external");
    std::fs::create_dir_all(&dir).unwrap();
    // The triangle's buffer in a file of its own, its name percent-escaped in the URI.
    let external = gltf_triangle_with_buffer("tri%20data.bin");
    let path = dir.join("tri.gltf");
    std::fs::write(&path, &external).unwrap();
    let _ = std::fs::remove_file(dir.join("tri data.bin"));
    let err = pathlab_scene::load(path.to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("tri.gltf") && err.contains("buffers[0]") && err.contains("tri%20data.bin"),
        "{err}"
    );
    std::fs::write(dir.join("tri data.bin"), triangle_buffer()).unwrap();
    let desc = pathlab_scene::load(path.to_str().unwrap()).unwrap();
    assert_eq!(desc.meshes[0].indices, vec![0, 1, 2]);
    // An escape that decodes to no UTF-8 (the gltf crate's own decoding panics on it) is an
    // error naming the URI.
    std::fs::write(&path, gltf_triangle_with_buffer("%FF%FE.bin")).unwrap();
    let err = pathlab_scene::load(path.to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(err.contains("%FF%FE.bin"), "{err}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 150, failure_persistence: None, rng_seed: RngSeed::Fixed(0x5eed_0005), ..ProptestConfig::default() })]

    /// glTF truncated or bit-flipped.
    #[test]
    fn gltf_truncated_or_flipped(cut in 0.0f64..1.0, flips in prop::collection::vec((0.0f64..1.0, 0u8..8), 0..6)) {
        exercise_file("case.gltf", &corrupt(gltf_triangle().into_bytes(), cut, &flips));
    }

    /// glTF whose numbers (indices, counts, offsets, sizes) are mangled.
    #[test]
    fn gltf_numbers_mangled(edits in prop::collection::vec((0.0f64..1.0, 0usize..MANGLED.len()), 1..6)) {
        let mut text = gltf_triangle();
        for (pos, k) in edits {
            let spans = number_spans(&text);
            let (s, e) = spans[((pos * spans.len() as f64) as usize).min(spans.len() - 1)];
            text.replace_range(s..e, MANGLED[k]);
        }
        exercise_file("case-n.gltf", text.as_bytes());
    }
}

/// A small pbrt-v4 scene using most of the syntax.
fn pbrt_scene() -> String {
    r#"LookAt 0 1 5  0 1 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 6 ]
Sampler "sobol" "integer pixelsamples" 4
Integrator "path" "integer maxdepth" [ 3 ]
WorldBegin
LightSource "infinite" "rgb L" [ 0.1 0.1 0.1 ]
MakeNamedMaterial "metal" "string type" "conductor" "spectrum eta" "metal-Cu-eta" "spectrum k" "metal-Cu-k" "float roughness" 0.1
Texture "t" "spectrum" "constant" "rgb value" [ 0.5 0.2 0.1 ]
AttributeBegin
  AreaLightSource "diffuse" "blackbody L" [ 4000 ] "float scale" 3
  Translate 0 2 0
  Shape "sphere" "float radius" 0.2
AttributeEnd
ObjectBegin "o"
  NamedMaterial "metal"
  Shape "trianglemesh" "point3 P" [ -1 0 -1 1 0 -1 1 0 1 -1 0 1 ] "integer indices" [ 0 1 2 0 2 3 ] "normal N" [ 0 1 0 0 1 0 0 1 0 0 1 0 ] "point2 uv" [ 0 0 1 0 1 1 0 1 ]
ObjectEnd
AttributeBegin Rotate 10 0 1 0 ObjectInstance "o" AttributeEnd
Material "diffuse" "texture reflectance" "t"
Shape "disk" "float radius" 0.5 "float height" 0.1
Shape "bilinearmesh" "point3 P" [ 0 0 0 1 0 0 0 1 0 1 1 0 ]
"#
    .to_string()
}

#[test]
fn the_pbrt_scene_loads() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("corruption");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("sample.pbrt");
    std::fs::write(&path, pbrt_scene()).unwrap();
    let desc = pathlab_scene::load(path.to_str().unwrap()).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    assert_eq!((desc.meshes.len(), desc.spheres.len()), (3, 1));
    render_tiny(desc);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, failure_persistence: None, rng_seed: RngSeed::Fixed(0x5eed_0006), ..ProptestConfig::default() })]

    /// pbrt-v4 files truncated or bit-flipped (plain and gzip-compressed).
    #[test]
    fn pbrt_truncated_or_flipped(cut in 0.0f64..1.0, flips in prop::collection::vec((0.0f64..1.0, 0u8..8), 0..6), gz in any::<bool>()) {
        let bytes = corrupt(pbrt_scene().into_bytes(), cut, &flips);
        if gz {
            use std::io::Write;
            let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
            e.write_all(&bytes).unwrap();
            exercise_file("case.pbrt.gz", &corrupt(e.finish().unwrap(), 1.0, &flips[..flips.len().min(1)]));
        } else {
            exercise_file("case.pbrt", &bytes);
        }
    }

    /// pbrt-v4 files whose numbers are mangled (sizes, indices, radii, counts).
    #[test]
    fn pbrt_numbers_mangled(edits in prop::collection::vec((0.0f64..1.0, 0usize..MANGLED.len()), 1..6)) {
        let mut text = pbrt_scene();
        for (pos, k) in edits {
            let spans = number_spans(&text);
            let (s, e) = spans[((pos * spans.len() as f64) as usize).min(spans.len() - 1)];
            text.replace_range(s..e, MANGLED[k]);
        }
        exercise_file("case-n.pbrt", text.as_bytes());
    }
}

/// A small film file (the format of checkpoints and shards) to corrupt.
fn film_file_bytes() -> Vec<u8> {
    let mut film = pathlab_render::film::Film::new(5, 3);
    for (i, p) in film.pixels_mut().iter_mut().enumerate() {
        for k in 0..3 {
            p.add(glam::Vec3::new(0.1 * (i + k) as f32, 0.5, 2.0));
        }
    }
    let header = pathlab_render::film_file::FilmHeader {
        resolution: [5, 3],
        key: "0123456789abcdef".into(),
        description: "a test film".into(),
        seed: 1,
        spp: 8,
        range: [0, 8],
        writer: "corruption suite".into(),
    };
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("corruption");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("film.plf");
    pathlab_render::film_file::write(&path, &header, &film).unwrap();
    std::fs::read(path).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, failure_persistence: None, rng_seed: RngSeed::Fixed(0x5eed_0007), ..ProptestConfig::default() })]

    /// Checkpoint and shard files truncated, bit-flipped, or with their sizes mangled: an
    /// error (never a panic, never a huge allocation) unless the file is intact.
    #[test]
    fn film_files_truncated_flipped_or_resized(cut in 0.0f64..1.0, flips in prop::collection::vec((0.0f64..1.0, 0u8..8), 0..4), size in prop::option::of((0usize..3, any::<u64>()))) {
        let original = film_file_bytes();
        let mut bytes = corrupt(original.clone(), cut, &flips);
        if let Some((which, v)) = size {
            // The header length, the pixel count, or a pixel's sample count.
            let at = [8usize, 12 + u32::from_le_bytes(original[8..12].try_into().unwrap()) as usize, original.len() / 2][which];
            if at + 8 <= bytes.len() {
                bytes[at..at + 8].copy_from_slice(&v.to_le_bytes());
            }
        }
        let result = pathlab_render::film_file::parse(&bytes);
        assert_memory_bound();
        if bytes != original {
            prop_assert!(result.is_err());
        } else {
            prop_assert!(result.is_ok());
        }
    }
}
