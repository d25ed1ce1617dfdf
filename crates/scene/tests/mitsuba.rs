//! Mitsuba 3 XML: the reference Cornell box's own scene.xml gives the built-in Cornell box's
//! image (statistically), and malformed files give located errors.

use glam::DVec3;
use pathlab_mc::sampler::SamplerKind;
use pathlab_mc::stats::z_test_two_sample;
use pathlab_render::desc::SceneDesc;
use pathlab_render::film::Film;
use pathlab_render::integrator::{IntegratorKind, PathIntegrator};
use pathlab_render::render::{render, RenderSettings};
use pathlab_render::scene::Scene;
use pathlab_scene::{builtin, info, mitsuba, Error};
use std::path::{Path, PathBuf};

fn scene_xml() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/cornell-box/scene.xml")
}

fn run(desc: &SceneDesc, seed: u64) -> Film {
    let scene = Scene::build(desc).unwrap();
    let integrator = IntegratorKind::Path(PathIntegrator::default());
    render(
        &scene,
        &integrator,
        &RenderSettings::new(64, seed, SamplerKind::Independent),
        &|_| {},
        &Default::default(),
    )
    .0
}

#[test]
fn scene_xml_reads_the_cornell_box() {
    let xml = mitsuba::load(&scene_xml()).unwrap();
    let built = builtin::cornell_box().unwrap();
    let (a, b) = (info::summarize(&xml), info::summarize(&built));
    assert_eq!(a.triangles, 36);
    assert_eq!(a.bounds, b.bounds);
    assert_eq!(xml.resolution, [256, 256]);
    assert_eq!(xml.hints.spp, Some(256));
    assert_eq!(xml.hints.max_depth, Some(u32::MAX)); // Mitsuba's -1
    assert_eq!(xml.camera.origin, built.camera.origin);
    assert!(xml.warnings.is_empty(), "{:?}", xml.warnings);
}

#[test]
fn scene_xml_renders_the_built_in_image() {
    let xml = run(&mitsuba::load(&scene_xml()).unwrap(), 1);
    let built = run(&builtin::cornell_box().unwrap(), 2);
    // 8 x 8 blocks (each mean averages 64 pixels' samples) and the image mean, two-sample z.
    let w = 256usize;
    let mut outliers = 0;
    for by in 0..32 {
        for bx in 0..32 {
            let (mut d, mut v) = (DVec3::ZERO, DVec3::ZERO);
            for y in by * 8..by * 8 + 8 {
                for x in bx * 8..bx * 8 + 8 {
                    let (p, q) = (&xml.pixels()[y * w + x], &built.pixels()[y * w + x]);
                    d += p.mean() - q.mean();
                    v += p.variance_of_mean() + q.variance_of_mean();
                }
            }
            for c in 0..3 {
                outliers += (d[c].abs() > 4.0 * v[c].sqrt()) as usize;
            }
        }
    }
    assert!(
        outliers <= 3,
        "{outliers} block channels beyond 4 sigma of 3072"
    );
    pathlab_testkit::render::assert_same_mean("the XML box against the built-in box", &xml, &built);
}

fn write(name: &str, text: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("mitsuba-tests");
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn defaults_includes_and_shapes() {
    write(
        "inc.xml",
        r#"<scene version="3.0.0"><bsdf type="twosided" id="w"><bsdf type="diffuse"><rgb name="reflectance" value="0.2 0.4 0.6"/></bsdf></bsdf></scene>"#,
    );
    let main = write(
        "main.xml",
        r#"<scene version="3.0.0">
  <default name="res" value="32"/>
  <include filename="inc.xml"/>
  <sensor type="thinlens"><float name="fov" value="45"/><float name="aperture_radius" value="0.1"/>
    <float name="focus_distance" value="4"/>
    <transform name="to_world"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="$res"/></film>
  </sensor>
  <shape type="cube"><transform name="to_world"><scale value="0.5"/><translate x="1"/></transform><ref id="w"/></shape>
  <shape type="sphere"><float name="radius" value="0.25"/><bsdf type="diffuse"/></shape>
  <shape type="disk"><emitter type="area"><rgb name="radiance" value="3"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.1"/></emitter>
  <emitter type="point"><point name="position" x="0" y="3" z="0"/><rgb name="intensity" value="5"/></emitter>
</scene>"#,
    );
    let desc = mitsuba::load(&main).unwrap();
    assert_eq!(desc.resolution, [32, 32]);
    assert!((desc.camera.lens_radius - 0.1).abs() < 1e-6);
    let s = info::summarize(&desc);
    // The disk is a fan of 256 triangles.
    assert_eq!((s.triangles, s.spheres), (12 + 256, 1));
    let (lo, hi) = s.bounds.unwrap();
    assert!((hi.x - 1.5).abs() < 1e-5 && (lo.x + 1.0).abs() < 1e-5);
    assert_eq!(desc.point_lights.len(), 1);
    assert!(desc.environment.is_some());
    let film = run(&desc, 3);
    assert!(film.image_mean().max_element() > 1e-3 && film.image_mean().is_finite());
}

#[test]
fn malformed_xml_gives_located_errors() {
    let cases = [
        (
            r#"<scene><shape type="rectangle"><ref id="nope"/></shape></scene>"#,
            "no object has id 'nope'",
        ),
        (
            r#"<scene><sensor type="perspective"><film type="hdrfilm"><integer name="width" value="$w"/></film></sensor></scene>"#,
            "'$w' has no <default>",
        ),
        (
            r#"<scene><shape type="rectangle"><transform name="to_world"><translate x="NaN"/></transform></shape></scene>"#,
            "is not a number",
        ),
        (
            r#"<scene><shape type="rectangle"><transform name="to_world"><matrix value="1 2 3"/></transform></shape></scene>"#,
            "16 numbers",
        ),
        (
            r#"<scene><shape type="rectangle"><bsdf type="roughconductor"><float name="alpha" value="-0.5"/></bsdf></shape></scene>"#,
            "alpha must be a number >= 0, got -0.5",
        ),
        (
            r#"<scene><shape type="rectangle"><bsdf type="roughdielectric"><float name="alpha_u" value="0.1"/><float name="alpha_v" value="-1"/></bsdf></shape></scene>"#,
            "alpha_v must be a number >= 0, got -1",
        ),
        (
            r#"<scene><shape type="rectangle"><bsdf type="roughplastic"><float name="alpha" value="-0.1"/></bsdf></shape></scene>"#,
            "alpha must be a number >= 0, got -0.1",
        ),
        (
            r#"<scene><shape type="sphere"><bsdf type="principled"><float name="roughness" value="-3"/></bsdf></shape></scene>"#,
            "<bsdf type=\"principled\">: roughness must be a number >= 0, got -3",
        ),
        // A negative emission has no meaning; rendered, its samples would carry no light
        // and the image would come out black without a word.
        (
            r#"<scene><emitter type="point"><rgb name="intensity" value="-1"/></emitter></scene>"#,
            "<emitter type=\"point\">: 'intensity' is an emission and must be >= 0 in every channel",
        ),
        (
            r#"<scene><shape type="rectangle"><emitter type="area"><rgb name="radiance" value="1, -1, 1"/></emitter></shape></scene>"#,
            "'radiance' is an emission and must be >= 0",
        ),
        (
            r#"<scene><emitter type="constant"><spectrum name="radiance" value="-2"/></emitter></scene>"#,
            "'radiance' is an emission and must be >= 0",
        ),
        (
            r#"<scene><emitter type="constant"><spectrum name="radiance" value="400:1, 700:-1"/></emitter></scene>"#,
            "'radiance' is an emission and must be >= 0",
        ),
        (
            r#"<scene><emitter type="directional"><float name="irradiance" value="NaN"/></emitter></scene>"#,
            "is not a number",
        ),
        (
            r#"<scene><emitter type="projector"><float name="scale" value="-3"/></emitter></scene>"#,
            "'scale' must be a number >= 0, got -3",
        ),
        (r#"<scene><shape type="rectangle">"#, "malformed XML"),
        (r#"<notscene/>"#, "expected a <scene>"),
        (
            r#"<scene><include filename="missing.xml"/></scene>"#,
            "missing.xml",
        ),
        (
            r#"<scene><include filename="loop.xml"/></scene>"#,
            "nest too deeply",
        ),
    ];
    for (i, (text, expected)) in cases.into_iter().enumerate() {
        let path = if expected == "nest too deeply" {
            write("loop.xml", text)
        } else {
            write(&format!("bad{i}.xml"), text)
        };
        let e = mitsuba::load(&path).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains(expected), "expected '{expected}' in: {msg}");
        if let Error::Parse { line, .. } = e {
            assert!(line >= 1);
        }
    }
    assert!(matches!(
        mitsuba::load(Path::new("/no/scene.xml")),
        Err(Error::Io { .. })
    ));
}

#[test]
fn conductor_table_matches_mitsubas_spectral_files() {
    use pathlab_scene::mitsuba::ior::{named_conductor, CONDUCTORS};
    use pathlab_scene::spectrum::{parse_spd, sampled_to_rgb, SpectrumKind};
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/mitsuba-suite/ior");
    let rgb = |file: &str| {
        let text = std::fs::read_to_string(dir.join(file)).unwrap();
        sampled_to_rgb(&parse_spd(&text).unwrap(), SpectrumKind::Unbounded)
    };
    let mut files = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if let Some(material) = name.strip_suffix(".eta.spd") {
            files += 1;
            let (eta, k) = named_conductor(material)
                .unwrap_or_else(|| panic!("{material} is missing from the table"));
            let (e, kk) = (rgb(&name), rgb(&format!("{material}.k.spd")));
            for c in 0..3 {
                let close = |a: f32, b: f64| (a as f64 - b).abs() <= 1e-5 * b.abs().max(1.0);
                assert!(
                    close(eta[c], e[c]),
                    "{material} eta[{c}]: {} vs {}",
                    eta[c],
                    e[c]
                );
                assert!(
                    close(k[c], kk[c]),
                    "{material} k[{c}]: {} vs {}",
                    k[c],
                    kk[c]
                );
            }
        }
    }
    assert_eq!(files, CONDUCTORS.len());
    // Mitsuba 3's RGB silver (its ior_from_file("Ag")).
    let (eta, k) = named_conductor("Ag").unwrap();
    assert!((eta[0] - 0.155_276).abs() < 1e-5 && (k[2] - 2.146_90).abs() < 1e-4);
    assert_eq!(named_conductor("none"), Some(([0.0; 3], [1.0; 3])));
}

#[test]
fn thin_dielectric_and_plastic_specular_are_read() {
    let main = write(
        "thin.xml",
        r#"<scene version="3.0.0">
  <shape type="sphere"><bsdf type="thindielectric"><float name="int_ior" value="1.33"/>
    <float name="ext_ior" value="1"/><rgb name="specular_transmittance" value="0.5"/></bsdf></shape>
  <shape type="rectangle"><bsdf type="plastic"><rgb name="specular_reflectance" value="0.25"/>
    <rgb name="diffuse_reflectance" value="0.1 0.2 0.3"/></bsdf></shape>
</scene>"#,
    );
    let desc = mitsuba::load(&main).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    use pathlab_render::desc::MaterialDesc;
    assert!(desc.materials.iter().any(|m| matches!(m,
        MaterialDesc::ThinGlass { ior, transmittance, .. }
            if (*ior - 1.33).abs() < 1e-6 && *transmittance == glam::Vec3::splat(0.5))));
    assert!(desc.materials.iter().any(|m| matches!(m,
        MaterialDesc::Plastic { specular, .. } if *specular == glam::Vec3::splat(0.25))));
}

#[test]
fn an_sdf_grid_of_a_plane_renders_as_the_plane_and_a_torus_grid_renders() {
    // A linear distance is its own trilinear interpolant: the grid's surface is exactly the
    // plane's square inside the grid's cube, so the image must match a quad's.
    let n = 9u32;
    let sample = |f: &dyn Fn(glam::Vec3) -> f32| {
        let mut v = Vec::new();
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    v.push(f(
                        glam::Vec3::new(x as f32, y as f32, z as f32) / (n - 1) as f32
                    ));
                }
            }
        }
        mitsuba::volume::write(&v, [n; 3])
    };
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("mitsuba-tests");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("plane.vol"), sample(&|p| p.y - 0.45)).unwrap();
    let main = write(
        "sdf_plane.xml",
        r#"<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="0.3, 2.5, 2.8" target="0, -0.1, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <emitter type="point"><point name="position" x="0.5" y="1.5" z="0.3"/><rgb name="intensity" value="2"/></emitter>
  <shape type="sdfgrid"><string name="filename" value="plane.vol"/><string name="normals" value="analytic"/>
    <transform name="to_world"><scale value="2"/><translate x="-1" y="-1" z="-1"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.6 0.4 0.2"/></bsdf></shape>
</scene>"#,
    );
    let grid = mitsuba::load(&main).unwrap();
    assert!(grid.warnings.is_empty(), "{:?}", grid.warnings);
    assert_eq!(grid.sdf_grids.len(), 1);
    let mut quad = grid.clone();
    let material = quad.sdf_grids.remove(0).material;
    quad.meshes.push(pathlab_render::desc::MeshDesc {
        name: "quad".into(),
        positions: vec![
            glam::Vec3::new(-1.0, -0.1, -1.0),
            glam::Vec3::new(1.0, -0.1, -1.0),
            glam::Vec3::new(1.0, -0.1, 1.0),
            glam::Vec3::new(-1.0, -0.1, 1.0),
        ],
        indices: vec![0, 2, 1, 0, 3, 2],
        material,
        ..Default::default()
    });
    let (a, b) = (run(&grid, 1), run(&quad, 2));
    let mut outliers = 0;
    for (p, q) in a.pixels().iter().zip(b.pixels()) {
        let (d, v) = (
            p.mean() - q.mean(),
            p.variance_of_mean() + q.variance_of_mean(),
        );
        for c in 0..3 {
            outliers += (d[c].abs() > 4.0 * v[c].sqrt() + 1e-6) as usize;
        }
    }
    assert!(outliers <= 2, "{outliers} pixel channels beyond 4 sigma");
    let (ma, mb) = (a.image_mean(), b.image_mean());
    let (sa, sb) = (a.image_mean_std_error(), b.image_mean_std_error());
    for c in 0..3 {
        let z = z_test_two_sample(ma[c], sa[c], mb[c], sb[c]);
        assert!(
            z.within(3.5),
            "channel {c}: {} vs {} (z {})",
            ma[c],
            mb[c],
            z.z
        );
    }
    // A torus with smooth normals, rotated by its transform, renders finite and lit.
    std::fs::write(
        dir.join("torus.vol"),
        sample(&|p| {
            let q = p - 0.5;
            (glam::Vec2::new(glam::Vec2::new(q.x, q.z).length() - 0.3, q.y)).length() - 0.12
        }),
    )
    .unwrap();
    let torus = std::fs::read_to_string(&main)
        .unwrap()
        .replace("plane.vol", "torus.vol")
        .replace(r#"<string name="normals" value="analytic"/>"#, "")
        .replace(
            r#"<translate x="-1" y="-1" z="-1"/>"#,
            r#"<translate x="-1" y="-1" z="-1"/><rotate x="1" angle="30"/>"#,
        );
    let desc = mitsuba::load(&write("sdf_torus.xml", &torus)).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let film = run(&desc, 3);
    assert!(film.pixels().iter().all(|p| p.mean().is_finite()));
    // The torus covers some pixels and not others: the image is neither uniform nor black.
    let lum: Vec<f64> = film.pixels().iter().map(|p| p.mean().y).collect();
    let (lo, hi) = lum
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &l| (a.min(l), b.max(l)));
    assert!(hi > 0.0 && hi - lo > 0.1, "luminance range {lo}..{hi}");
}

#[test]
fn a_films_crop_window_is_the_part_of_the_image_to_render() {
    use pathlab_render::desc::CropHint;
    let film = |crop: &str| {
        format!(
            r#"<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm">
<integer name="width" value="64"/><integer name="height" value="32"/>{crop}</film></sensor></scene>"#
        )
    };
    let path = write(
        "crop.xml",
        &film(
            r#"<integer name="crop_offset_x" value="8"/><integer name="crop_width" value="16"/><integer name="crop_height" value="4"/>"#,
        ),
    );
    let desc = mitsuba::load(&path).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    assert_eq!(
        desc.hints.crop,
        Some(CropHint {
            window: [8, 0, 24, 4],
            of: [64, 32]
        })
    );
    let path = write("no-crop.xml", &film(""));
    assert_eq!(mitsuba::load(&path).unwrap().hints.crop, None);
    // As Mitsuba: a window that leaves the film is an error.
    let path = write(
        "bad-crop.xml",
        &film(
            r#"<integer name="crop_offset_y" value="30"/><integer name="crop_height" value="4"/>"#,
        ),
    );
    let e = mitsuba::load(&path).unwrap_err().to_string();
    assert!(e.contains("does not lie inside the 64 x 32 film"), "{e}");
}

#[test]
fn a_rough_dielectric_with_two_roughnesses_or_a_textured_one_is_read_as_such() {
    use pathlab_render::desc::MaterialDesc;
    let main = write(
        "anisotropic-glass.xml",
        r#"<scene version="3.0.0">
  <shape type="sphere"><bsdf type="roughdielectric"><float name="alpha_u" value="0.05"/>
    <float name="alpha_v" value="0.3"/><rgb name="specular_transmittance" value="0.5"/></bsdf></shape>
  <shape type="rectangle"><bsdf type="roughdielectric"><float name="alpha" value="0.2"/></bsdf></shape>
  <shape type="cube"><bsdf type="roughdielectric"><texture type="checkerboard" name="alpha">
    <float name="color0" value="0.1"/><float name="color1" value="0.3"/></texture></bsdf></shape>
</scene>"#,
    );
    let desc = mitsuba::load(&main).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    let constant = |t: &pathlab_render::desc::TextureDesc| t.as_constant().map(|c| c.x);
    assert!(desc.materials.iter().any(|m| matches!(m,
        MaterialDesc::RoughGlass { alpha_u, alpha_v, transmittance, .. }
            if constant(alpha_u) == Some(0.05) && constant(alpha_v) == Some(0.3)
                && *transmittance == glam::Vec3::splat(0.5))));
    assert!(desc.materials.iter().any(|m| matches!(m,
        MaterialDesc::Glass { roughness, .. } if *roughness == 0.2)));
    // A textured α: the textured rough glass, the same texture along u and v.
    assert!(desc.materials.iter().any(|m| matches!(m,
        MaterialDesc::RoughGlass { alpha_u, alpha_v, .. }
            if constant(alpha_u).is_none() && alpha_u == alpha_v)));
}

#[test]
fn samplers_pathlab_lacks_are_rendered_by_its_nearest_with_a_note() {
    let text = std::fs::read_to_string(scene_xml()).unwrap();
    assert!(text.contains(r#"<sampler type="independent">"#));
    for (plugin, kind, note) in [
        ("independent", SamplerKind::Independent, None),
        ("stratified", SamplerKind::Stratified, None),
        // What `pathlab export` writes for Sobol: read back without a note.
        ("ldsampler", SamplerKind::Sobol, None),
        (
            "multijitter",
            SamplerKind::Stratified,
            Some("rendered with the stratified sampler"),
        ),
        (
            "orthogonal",
            SamplerKind::Sobol,
            Some("rendered with the Sobol sampler"),
        ),
        (
            "halton",
            SamplerKind::Sobol,
            Some("not a Mitsuba 3 sampler"),
        ),
    ] {
        let file = write(
            &format!("sampler-{plugin}.xml"),
            &text.replace(
                r#"<sampler type="independent">"#,
                &format!(r#"<sampler type="{plugin}">"#),
            ),
        );
        let desc = mitsuba::load(&file).unwrap();
        assert_eq!(desc.hints.sampler, Some(kind), "{plugin}");
        assert_eq!(desc.hints.spp, Some(256), "{plugin}");
        match note {
            None => assert!(desc.warnings.is_empty(), "{plugin}: {:?}", desc.warnings),
            Some(text) => {
                assert_eq!(desc.warnings.len(), 1, "{plugin}: {:?}", desc.warnings);
                let w = &desc.warnings[0];
                assert!(w.contains(text) && w.contains(plugin), "{plugin}: {w}");
                assert!(
                    w.contains(&format!("sampler-{plugin}.xml:")),
                    "the file: {w}"
                );
            }
        }
    }
}

#[test]
fn unknown_and_unused_bsdfs_are_reported_with_their_line() {
    let text = r#"<scene version="3.0.0">
    <bsdf type="nosuch" id="used"/>
    <bsdf type="alsonosuch" id="spare"/>
    <bsdf type="diffuse" id="idle"><texture type="checkerboard" name="reflectance"/></bsdf>
    <texture type="bitmap" id="unreferenced"/>
    <shape type="sphere"><ref id="used"/></shape>
</scene>"#;
    let file = write("unknown-and-unused.xml", text);
    let desc = mitsuba::load(&file).unwrap();
    let line = |n: usize| format!("unknown-and-unused.xml:{n}:");
    let unused = "is not used by anything in the scene; not loaded";
    let expected = [
        (
            2,
            r#"<bsdf type="nosuch"> is not supported by pathlab yet; drawn as grey"#,
        ),
        (
            3,
            &format!(r#"<bsdf type="alsonosuch" id="spare"> {unused}"#),
        ),
        (4, &format!(r#"<bsdf type="diffuse" id="idle"> {unused}"#)),
        (
            5,
            &format!(r#"<texture type="bitmap" id="unreferenced"> {unused}"#),
        ),
    ];
    assert_eq!(desc.warnings.len(), expected.len(), "{:?}", desc.warnings);
    for ((n, text), w) in expected.iter().zip(&desc.warnings) {
        assert!(w.contains(&line(*n)) && w.contains(text), "{w}");
    }
    // The scene itself is what it was: one sphere, of the grey stand-in.
    assert_eq!(desc.materials.len(), 1);
}

#[test]
fn info_counts_spots_and_projectors() {
    let suite = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/mitsuba-suite/tests/scenes");
    let lights = |file: &str| {
        let desc = mitsuba::load(&suite.join(file)).unwrap();
        info::summarize(&desc)
            .lights
            .into_iter()
            .collect::<Vec<_>>()
    };
    let one = |kind: &str| (kind.to_string(), 1);
    assert_eq!(
        lights("spot_light/test_spot_direct.xml"),
        [one("environment"), one("spot")]
    );
    assert_eq!(
        lights("projector/test_projector_textured_direct.xml"),
        [one("projector")]
    );
}
