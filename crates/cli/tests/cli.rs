//! End-to-end tests of `pathlab render`, `info`, `image` and scene reading: the binary run
//! as a user would.

mod common;

use common::*;
use std::path::PathBuf;

#[test]
fn render_writes_png_exr_and_aovs_with_statistics() {
    let png = scratch("cornell.png");
    let v = json_of(&pathlab(&[
        "render",
        "-s",
        "2",
        "-r",
        "32",
        "24",
        "-o",
        png.to_str().unwrap(),
        "--aov",
        "variance,samples",
        "--json",
    ]));
    assert_image_at_least(&png, true, 100);
    assert!(scratch_exists("cornell_variance.exr") && scratch_exists("cornell_samples.exr"));
    assert_eq!(v["resolution"], serde_json::json!([32, 24]));
    assert_eq!(v["samples"], 32 * 24 * 2);
    for key in [
        "seconds",
        "samples_per_second",
        "rays",
        "rays_per_second",
        "bvh_build_seconds",
        "bvh_nodes",
        "nonfinite_samples",
    ] {
        assert!(v[key].is_number(), "{key} missing");
    }
    assert_eq!(v["image_mean_rgb"].as_array().unwrap().len(), 3);
    let exr = scratch("cornell.exr");
    let out = pathlab(&[
        "render",
        "-s",
        "1",
        "-r",
        "16",
        "16",
        "-f",
        exr.to_str().unwrap(),
        "--aov",
        "samples",
        "-m",
        "1",
        "-q",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (w, h, px) = pathlab_render::image_io::read_exr_rgb(&exr).unwrap();
    assert_eq!((w, h, px.len()), (16, 16, 256));
    for view in ["normals", "depth", "bvh", "bdpt"] {
        let out = pathlab(&[
            "render",
            "--integrator",
            view,
            "-s",
            "1",
            "-r",
            "8",
            "8",
            "-o",
            scratch(&format!("{view}.png")).to_str().unwrap(),
            "-q",
        ]);
        assert!(
            out.status.success(),
            "{view}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn render_same_seed_same_image_for_any_thread_count() {
    let run = |threads: &str, integrator: &str| {
        let path = scratch(&format!("t{threads}-{integrator}.exr"));
        let out = pathlab(&[
            "render",
            "-s",
            "2",
            "-r",
            "24",
            "24",
            "-t",
            threads,
            "--seed",
            "5",
            "--integrator",
            integrator,
            "-o",
            path.to_str().unwrap(),
            "-q",
        ]);
        assert!(out.status.success());
        pathlab_render::image_io::read_exr_rgb(&path).unwrap().2
    };
    for integrator in ["path", "bdpt"] {
        assert_eq!(run("1", integrator), run("2", integrator), "{integrator}");
    }
}

#[test]
fn bad_render_flags_are_one_line_errors() {
    assert_one_line_error(&pathlab(&["render", "-m", "deep"]), "--max-depth");
    assert_one_line_error(&pathlab(&["render", "-r", "0", "10"]), "--resolution");
    assert_one_line_error(&pathlab(&["render", "-o", "out.jpg"]), ".exr or .png");
    assert_one_line_error(&pathlab(&["render", "-s", "0"]), "--spp");
    assert_one_line_error(
        &pathlab(&["render", "no-such-scene"]),
        "unknown built-in scene",
    );
    assert_one_line_error(
        &pathlab(&["render", "--crop", "10", "10", "5", "20"]),
        "--crop",
    );
    assert_one_line_error(&pathlab(&["render", "-b", "-1"]), "--lens-radius");
    assert_one_line_error(&pathlab(&["render", "-d", "0"]), "--focal-distance");
    assert_one_line_error(
        &pathlab(&["render", "-s", "1", "-o", "/nonexistent-dir/x.png"]),
        "nonexistent-dir",
    );
}

#[test]
fn negative_and_contradictory_flags_are_errors_and_unused_ones_warnings() {
    // Negative numbers reach the option (not the scene argument) and get a range message.
    for (args, expected) in [
        (&["render", "-s", "-1"][..], "--spp"),
        (&["render", "-r", "-256", "256"][..], "--resolution"),
        (&["render", "-l", "-2"][..], "--light-samples"),
        (&["render", "-t", "-1"][..], "--threads"),
        (&["render", "-m", "-3"][..], "--max-depth"),
        (&["render", "--only-bounce", "-1"][..], "--only-bounce"),
        // Contradictions that would write a black or meaningless image.
        (
            &["render", "-m", "1", "--only-bounce", "3"][..],
            "beyond --max-depth",
        ),
        (&["render", "--exposure", "nan"][..], "--exposure"),
        (&["render", "--exposure", "inf"][..], "--exposure"),
    ] {
        assert_one_line_error(&pathlab(args), expected);
    }
    // `-m -1` is Mitsuba's spelling of unbounded, and works.
    let out = scratch("m-minus-one.png");
    let run = pathlab(&[
        "render",
        "-m",
        "-1",
        "-s",
        "1",
        "-r",
        "8",
        "8",
        "-q",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // Flags the chosen integrator does not read: a warning each, and the render goes on.
    for (args, flag) in [
        (&["--direct", "hemisphere"][..], "--direct"),
        (
            &["--integrator", "normals", "--only-bounce", "1"][..],
            "--only-bounce",
        ),
        (
            &["--integrator", "direct", "--lighting", "bsdf"][..],
            "--lighting",
        ),
        (&["--adaptive-rule", "neyman"][..], "--adaptive-rule"),
    ] {
        let out = scratch("unused-flag.png");
        let mut all = vec![
            "render",
            "-s",
            "1",
            "-r",
            "8",
            "8",
            "-o",
            out.to_str().unwrap(),
        ];
        all.extend_from_slice(args);
        let run = pathlab(&all);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(run.status.success(), "{args:?}: {stderr}");
        assert!(
            stderr.contains(&format!("warning: {flag} applies to")),
            "{args:?}: {stderr}"
        );
    }
}

#[test]
fn the_bvh_view_is_a_heat_map_of_its_own_range() {
    // Node counts (one to dozens) written raw would clamp to white in a PNG.
    let png = scratch("bvh-view.png");
    let run = pathlab(&[
        "render",
        &course_scene("CBbunny.dae"),
        "--integrator",
        "bvh",
        "-s",
        "1",
        "-r",
        "80",
        "60",
        "--json",
        "-o",
        png.to_str().unwrap(),
    ]);
    let j = json_of(&run);
    let (lo, hi) = (
        j["debug_range"]["min"].as_f64().unwrap(),
        j["debug_range"]["max"].as_f64().unwrap(),
    );
    assert!(lo >= 1.0 && hi > lo + 2.0, "range {lo}..{hi}");
    let img = image::open(&png).unwrap().to_rgb8();
    let mut colours: Vec<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    colours.sort();
    colours.dedup();
    assert!(colours.len() > 5, "{} distinct colours", colours.len());
    assert!(
        img.pixels().filter(|p| p.0 == [255, 255, 255]).count() == 0,
        "white pixels: counts were clamped"
    );
}

#[test]
fn info_and_render_read_scene_files() {
    let bunny = course_scene("CBbunny.dae");
    let v = json_of(&pathlab(&["info", &bunny, "--json"]));
    assert_eq!(v["triangles"], 28_588);
    assert_eq!(v["camera"]["resolution"], serde_json::json!([800, 600]));
    // What a render at that size holds in memory: 136 bytes a pixel of exact sums (the
    // count, then the low and the high halves of eight 128-bit sums).
    assert_eq!(v["film_bytes"], 800 * 600 * 136);
    assert!(v["lights"]
        .as_object()
        .unwrap()
        .contains_key("area (parallelogram)"));
    let out = scratch("spheres.png");
    let stats = json_of(&pathlab(&[
        "render",
        &course_scene("CBspheres.dae"),
        "-s",
        "2",
        "-r",
        "40",
        "30",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_image_at_least(&out, true, 100);
    let mean = stats["image_mean_rgb"].as_array().unwrap();
    assert!(mean.iter().all(|m| m.as_f64().unwrap() > 0.0));
    let text =
        String::from_utf8(pathlab(&["info", &course_scene("CBspheres.dae")]).stdout).unwrap();
    assert!(
        text.contains("2 spheres") && text.contains("1 mirror") && !text.contains("warning"),
        "{text}"
    );
    // The course's microfacet materials load as conductors, with nothing left to warn about.
    let text = String::from_utf8(
        pathlab(&["info", &course_scene("CBspheres_microfacet_al_ag.dae")]).stdout,
    )
    .unwrap();
    assert!(
        !text.contains("warning") && text.contains("2 conductor"),
        "{text}"
    );
}

#[test]
fn bad_scene_files_are_short_errors() {
    let bad = scratch("broken.dae");
    std::fs::write(
        &bad,
        "<COLLADA><library_geometries><geometry id=\"g\"><mesh>",
    )
    .unwrap();
    let out = pathlab(&["render", bad.to_str().unwrap(), "-s", "1"]);
    assert_one_line_error(&out, "broken.dae:1:");
    assert_one_line_error(
        &pathlab(&["info", "/no/such/file.dae"]),
        "/no/such/file.dae",
    );
    assert_one_line_error(&pathlab(&["info", "model.fbx"]), "unknown scene format");
    // Without a scene, `info` describes the built-in Cornell box, as `render` renders it.
    let built_in = String::from_utf8(pathlab(&["info"]).stdout).unwrap();
    assert!(built_in.starts_with("cornell-box"), "{built_in}");
}

#[test]
fn error_messages_are_plain_sentences_naming_the_file() {
    let write = |name: &str, text: &str| {
        let p = scratch(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let ply = write(
        "bad-element.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n2\nfoo\n",
    );
    assert_plain_error(
        &pathlab(&["info", &ply]),
        "bad-element.ply:8: not a valid PLY file",
    );
    let obj = write("bad-index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    assert_plain_error(
        &pathlab(&["info", &obj]),
        "bad-index.obj:4: not a valid OBJ file",
    );
    let gltf = write(
        "bad-accessor.gltf",
        r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":5}}]}]}"#,
    );
    assert_plain_error(&pathlab(&["info", &gltf]), "accessor 5");
    let txt = write("sky.txt", "not an image");
    assert_plain_error(
        &pathlab(&[
            "render",
            "-s",
            "1",
            "-e",
            &txt,
            "-o",
            scratch("e.png").to_str().unwrap(),
        ]),
        "not an image format pathlab reads",
    );
    let exr = write("broken.exr", "not an exr");
    assert_plain_error(
        &pathlab(&[
            "render",
            "-s",
            "1",
            "-e",
            &exr,
            "-o",
            scratch("e.png").to_str().unwrap(),
        ]),
        "not a valid OpenEXR file",
    );
    assert_plain_error(
        &pathlab(&[
            "sample",
            "exponential",
            "-n",
            "100",
            "--plot",
            "/no/such/dir/p.png",
        ]),
        "cannot write the plot /no/such/dir/p.png",
    );
    assert_plain_error(
        &pathlab(&["integrate", "foo(x)", "-d", "0,1"]),
        "unknown function 'foo'",
    );
}

#[test]
fn target_error_and_time_budget() {
    let v = json_of(&pathlab(&[
        "render",
        "-m",
        "1",
        "--target-error",
        "0.1",
        "-o",
        scratch("te.exr").to_str().unwrap(),
        "--json",
    ]));
    let e = v["estimated_relative_rmse"].as_f64().unwrap();
    assert!(e <= 0.1, "{e}");
    assert_eq!(v["sampler"], "independent");
    let v = json_of(&pathlab(&[
        "render",
        "-m",
        "1",
        "--time",
        "1",
        "-o",
        scratch("tb.exr").to_str().unwrap(),
        "--json",
    ]));
    assert!(v["seconds"].as_f64().unwrap() < 5.0);
    // The samples per pixel reported are those taken, not the -s default.
    let [w, h] = [0, 1].map(|i| v["resolution"][i].as_f64().unwrap());
    let spp = v["spp"].as_f64().unwrap();
    let taken = v["samples"].as_f64().unwrap() / (w * h);
    assert!(
        (spp - taken).abs() < 1e-6 * taken,
        "spp {spp} vs {taken} taken"
    );
    let (lo, hi) = (
        v["spp_range"][0].as_f64().unwrap(),
        v["spp_range"][1].as_f64().unwrap(),
    );
    assert!(lo <= spp && spp <= hi && hi <= 65536.0, "{lo} {spp} {hi}");
    assert_eq!(v["spp_cap"], 65536);
    assert_one_line_error(
        &pathlab(&["render", "--target-error", "-1"]),
        "--target-error",
    );
    assert_one_line_error(&pathlab(&["render", "--time", "1", "-a"]), "choose one");
}

#[test]
fn envmap_lighting_and_fresnel_flags() {
    let sky = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/sky-spheres/sky.exr")
        .display()
        .to_string();
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/cornell-spheres/scene.xml")
        .display()
        .to_string();
    let mean = |extra: &[&str]| -> Vec<f64> {
        let out = scratch("flags.png");
        let mut args = vec![
            "render", &scene, "-s", "4", "-r", "24", "24", "-q", "--json", "-o",
        ];
        let out_s = out.to_str().unwrap().to_string();
        args.push(&out_s);
        args.extend_from_slice(extra);
        let v = json_of(&pathlab(&args));
        v["image_mean_rgb"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m.as_f64().unwrap())
            .collect()
    };
    // Emission seen directly (-m 0): camera rays that pass beside the box see the sky.
    let plain = mean(&["-m", "0"]);
    let lit = mean(&["-m", "0", "-e", &sky, "--envmap-scale", "2"]);
    assert!(
        lit.iter().zip(&plain).all(|(l, p)| l > p),
        "{lit:?} {plain:?}"
    );
    for lighting in ["bsdf", "light", "mis"] {
        assert!(mean(&["--lighting", lighting]).iter().all(|m| *m > 0.0));
    }
    assert!(mean(&["--fresnel", "schlick"]).iter().all(|m| *m > 0.0));
    assert_one_line_error(
        &pathlab(&["render", &scene, "-e", "no-such-sky.exr", "-q"]),
        "no-such-sky.exr",
    );
}

#[test]
fn one_render_writes_several_outputs_and_convert_and_diff_read_them() {
    let (exr, png) = (scratch("multi.exr"), scratch("multi.png"));
    let v = json_of(&pathlab(&[
        "render",
        "-s",
        "4",
        "-r",
        "32",
        "24",
        "-o",
        exr.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "-q",
        "--json",
    ]));
    assert_magic(&exr, EXR);
    assert_magic(&png, PNG);
    assert_eq!(v["outputs"].as_array().unwrap().len(), 2);
    // An output that cannot be written is found before rendering.
    assert_one_line_error(
        &pathlab(&["render", "-s", "100000", "-o", "/no/such/folder/x.png"]),
        "cannot write the output",
    );
    assert_one_line_error(
        &pathlab(&["render", "-o", "a.exr", "-o", "b.tiff"]),
        "must end in .exr or .png",
    );
    // convert and diff write images, not films.
    let film = scratch("converted.plf");
    for args in [
        vec!["convert", exr.to_str().unwrap(), film.to_str().unwrap()],
        vec![
            "diff",
            exr.to_str().unwrap(),
            exr.to_str().unwrap(),
            "-o",
            film.to_str().unwrap(),
        ],
    ] {
        assert_one_line_error(&pathlab(&args), "must end in .png or .exr");
    }
    // convert: EXR to PNG with exposure; PNG back to EXR.
    let converted = scratch("converted.png");
    let out = pathlab(&[
        "convert",
        exr.to_str().unwrap(),
        converted.to_str().unwrap(),
        "--exposure",
        "1",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_magic(&converted, PNG);
    let back = scratch("converted.exr");
    let out = pathlab(&["convert", png.to_str().unwrap(), back.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // diff: an image against itself is zero; against another render it is not.
    let same = json_of(&pathlab(&[
        "diff",
        exr.to_str().unwrap(),
        exr.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(same["rmse"].as_f64(), Some(0.0));
    let other = scratch("other.exr");
    json_of(&pathlab(&[
        "render",
        "-s",
        "4",
        "-r",
        "32",
        "24",
        "--seed",
        "9",
        "-o",
        other.to_str().unwrap(),
        "-q",
        "--json",
    ]));
    let heat = scratch("diff.png");
    let d = json_of(&pathlab(&[
        "diff",
        exr.to_str().unwrap(),
        other.to_str().unwrap(),
        "-o",
        heat.to_str().unwrap(),
        "--json",
    ]));
    let rmse = d["rmse"].as_f64().unwrap();
    assert!(rmse > 0.0 && rmse < 1.0, "{rmse}");
    assert!(d["relative_mse"].as_f64().unwrap() > 0.0);
    assert_magic(&heat, PNG);
    let small = scratch("small.exr");
    json_of(&pathlab(&[
        "render",
        "-s",
        "1",
        "-r",
        "8",
        "8",
        "-o",
        small.to_str().unwrap(),
        "-q",
        "--json",
    ]));
    assert_one_line_error(
        &pathlab(&["diff", exr.to_str().unwrap(), small.to_str().unwrap()]),
        "images of one size are compared",
    );
}

#[test]
fn the_default_adaptive_rule_is_two_stage_with_its_pilot_reported() {
    let out = scratch("adaptive2.png");
    let run = |rule: Option<&str>| {
        let mut args = vec![
            "render",
            "-a",
            "-s",
            "64",
            "-r",
            "16",
            "16",
            "-o",
            out.to_str().unwrap(),
            "--json",
        ];
        if let Some(r) = rule {
            args.extend(["--adaptive-rule", r]);
        }
        json_of(&pathlab(&args))
    };
    let v = run(None);
    assert_eq!(v["pilot_samples"].as_u64(), Some(32 * 256));
    let v = run(Some("course"));
    assert_eq!(v["pilot_samples"].as_u64(), Some(0));
}

#[test]
fn scale_and_fov_resize_and_reframe_any_scene() {
    let out = scratch("scaled.png");
    let v = json_of(&pathlab(&[
        "render",
        &course_scene("CBspheres_lambertian.dae"),
        "--scale",
        "0.05",
        "-s",
        "1",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(v["resolution"], serde_json::json!([40, 30]));
    // The same view at a twentieth of the size: the box fills the same part of the image,
    // where -r 40 30 shows a crop of the middle (the course's pixel scale).
    let scaled = v["image_mean_rgb"][0].as_f64().unwrap();
    let v = json_of(&pathlab(&[
        "render",
        &course_scene("CBspheres_lambertian.dae"),
        "-r",
        "40",
        "30",
        "-s",
        "1",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]));
    let cropped = v["image_mean_rgb"][0].as_f64().unwrap();
    assert!(cropped > 1.5 * scaled, "crop {cropped} vs scaled {scaled}");
    let wide = json_of(&pathlab(&[
        "render",
        "--fov",
        "80",
        "-s",
        "1",
        "-r",
        "32",
        "32",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]));
    let narrow = json_of(&pathlab(&[
        "render",
        "--fov",
        "10",
        "-s",
        "1",
        "-r",
        "32",
        "32",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_ne!(wide["image_mean_rgb"], narrow["image_mean_rgb"]);
    assert_one_line_error(&pathlab(&["render", "--scale", "0"]), "--scale 0");
    assert_one_line_error(&pathlab(&["render", "--fov", "200"]), "--fov 200");
}

#[test]
fn refused_command_lines_are_one_line_errors_that_name_the_argument() {
    let o = pathlab(&["diff", "a.exr"]);
    assert_one_line_error(&o, "required arguments were not provided: <B>");
    assert_eq!(o.status.code(), Some(2));
    assert_one_line_error(&pathlab(&["render", "--bogus"]), "'--bogus'");
    assert_one_line_error(&pathlab(&["render", "-s", "x"]), "'--spp <SPP>'");
}

#[test]
fn view_refuses_bad_scenes_and_addresses_with_one_line_errors() {
    assert_one_line_error(&pathlab(&["view", "missing.xml"]), "missing.xml");
    assert_one_line_error(
        &pathlab(&["view", "--host", "not a host", "--port", "0"]),
        "cannot listen on not a host:0",
    );
    // A port another program holds.
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    assert_one_line_error(
        &pathlab(&["view", "-r", "8", "8", "--port", &port]),
        &format!("cannot listen on 127.0.0.1:{port}"),
    );
    assert_one_line_error(&pathlab(&["view", "-D", "novalue"]), "-D novalue");
}
