//! End-to-end tests: run the `pathlab` binary as a user would.

use serde_json::Value;
use std::path::PathBuf;
use std::process::{Command, Output};

fn pathlab(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pathlab"))
        .args(args)
        .output()
        .expect("the pathlab binary runs")
}

fn pathlab_with_threads(args: &[&str], threads: usize) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pathlab"))
        .args(args)
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .expect("the pathlab binary runs")
}

fn json_of(out: &Output) -> Value {
    assert!(
        out.status.success(),
        "pathlab failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("--json prints valid JSON")
}

/// Asserts a failed run with exactly one line on stderr, an error and no panic.
fn assert_one_line_error(out: &Output, expected: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "expected a failure, got success");
    assert_eq!(stderr.trim_end().lines().count(), 1, "stderr: {stderr}");
    assert!(stderr.starts_with("error: "), "stderr: {stderr}");
    assert!(
        stderr.contains(expected),
        "stderr lacks '{expected}': {stderr}"
    );
    assert!(!stderr.contains("panicked"), "stderr: {stderr}");
}

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-tests");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

#[test]
fn exponential_mean_is_one_over_lambda() {
    let v = json_of(&pathlab(&[
        "sample",
        "exponential",
        "--lambda",
        "1",
        "-n",
        "1000000",
        "--json",
    ]));
    let c = &v["components"][0];
    let (mean, se) = (
        c["mean"].as_f64().unwrap(),
        c["std_error"].as_f64().unwrap(),
    );
    assert!(
        se > 0.0 && (mean - 1.0).abs() <= 4.0 * se,
        "mean {mean} ± {se}"
    );
    assert_eq!(v["samples"], 1_000_000);
}

#[test]
fn every_distribution_fits_its_pdf() {
    // One goodness-of-fit test per distribution, Bonferroni-corrected over them.
    let names = [
        "exponential",
        "uniform-hemisphere",
        "cosine-hemisphere",
        "uniform-sphere",
        "uniform-cone",
        "concentric-disk",
        "uniform-triangle",
        "piecewise",
        "piecewise2d",
        "alias",
    ];
    let alpha = 0.01 / names.len() as f64;
    for name in names {
        let v = json_of(&pathlab(&[
            "sample", name, "-n", "200000", "--seed", "3", "--json",
        ]));
        let p = v["chi_square"]["p_value"].as_f64().unwrap();
        assert!(p >= alpha, "{name}: p = {p}");
        for c in v["components"].as_array().unwrap() {
            let z = c["z"].as_f64().unwrap();
            assert!(z.abs() <= 4.5, "{name} {}: z = {z}", c["name"]);
        }
    }
}

#[test]
fn bad_sample_input_is_one_line_error() {
    assert_one_line_error(
        &pathlab(&["sample", "exponential", "--lambda", "-1"]),
        "lambda",
    );
    assert_one_line_error(
        &pathlab(&["sample", "exponential", "--lambda", "nan"]),
        "lambda",
    );
    assert_one_line_error(&pathlab(&["sample", "exponential", "-n", "0"]), "-n");
    assert_one_line_error(
        &pathlab(&["sample", "alias", "--weights", "1,x"]),
        "'x' is not a number",
    );
    assert_one_line_error(
        &pathlab(&["sample", "alias", "--weights", "0,0"]),
        "positive sum",
    );
    assert_one_line_error(
        &pathlab(&["sample", "piecewise", "--weights", "1,-2"]),
        "not a finite non-negative",
    );
    assert_one_line_error(
        &pathlab(&["sample", "piecewise", "--range", "1,0"]),
        "--range",
    );
    // All-zero weights have no density (the library's uniform fallback is for tables with
    // empty rows, not for a density asked for by name).
    assert_one_line_error(
        &pathlab(&["sample", "piecewise", "--weights", "0,0,0"]),
        "positive sum",
    );
    assert_one_line_error(
        &pathlab(&["sample", "piecewise2d", "--weights", "0,0;0,0"]),
        "positive sum",
    );
    assert_one_line_error(
        &pathlab(&["sample", "piecewise2d", "--weights", "1,2;3"]),
        "every row",
    );
    assert_one_line_error(
        &pathlab(&["sample", "uniform-cone", "--cos-theta-max", "1"]),
        "cos-theta-max",
    );
    assert_one_line_error(
        &pathlab(&["sample", "exponential", "--plot", "out.jpg"]),
        ".png or .svg",
    );
}

#[test]
fn bad_integrate_input_is_one_line_error() {
    assert_one_line_error(
        &pathlab(&["integrate", "x +* 2", "--domain", "0,1"]),
        "cannot parse",
    );
    assert_one_line_error(&pathlab(&["integrate", "x", "--domain", "1,1"]), "empty");
    assert_one_line_error(&pathlab(&["integrate", "x", "--domain", "2,1"]), "empty");
    assert_one_line_error(&pathlab(&["integrate", "x", "--domain", "0"]), "two bounds");
    assert_one_line_error(
        &pathlab(&["integrate", "x", "--domain", "0,b"]),
        "not a number",
    );
    assert_one_line_error(
        &pathlab(&["integrate", "x + q", "--domain", "0,1"]),
        "unknown variable 'q'",
    );
    assert_one_line_error(
        &pathlab(&["integrate", "y", "--domain", "0,1"]),
        "unknown variable 'y'",
    );
    assert_one_line_error(
        &pathlab(&["integrate", "sqrt(x-2)", "--domain", "0,1", "-n", "16"]),
        "not finite",
    );
    assert_one_line_error(
        &pathlab(&["integrate", "exp(-x^2)", "--domain", "0,1"]),
        "ambiguous",
    );
    assert_one_line_error(
        &pathlab(&[
            "integrate",
            "-x",
            "--domain",
            "0,1",
            "--sampler",
            "sobol",
            "-n",
            "4",
        ]),
        "--reps",
    );
    assert_one_line_error(
        &pathlab(&["integrate", "x", "--domain", "0,1", "--importance", "x-1"]),
        "finite and >= 0",
    );
    assert_one_line_error(
        &pathlab(&[
            "integrate",
            "x",
            "-d",
            "0,1",
            "-d",
            "0,1",
            "-d",
            "0,1",
            "--importance",
            "1",
        ]),
        "1 or 2 dimensions",
    );
}

#[test]
fn integrate_gaussian_within_four_standard_errors() {
    // ∫∫ exp(-(x² + y²)/2) over [-2, 2]² = 2π erf(√2)².
    let exact = 2.0 * std::f64::consts::PI * 0.954_499_736_103_641_6f64.powi(2);
    for sampler in ["independent", "stratified", "sobol"] {
        let v = json_of(&pathlab(&[
            "integrate",
            "exp(-(x^2+y^2)/2)",
            "--domain",
            "-2,2",
            "--domain",
            "-2,2",
            "-n",
            "200000",
            "--sampler",
            sampler,
            "--json",
        ]));
        let (est, se) = (
            v["estimate"].as_f64().unwrap(),
            v["std_error"].as_f64().unwrap(),
        );
        assert!(
            se > 0.0 && (est - exact).abs() <= 4.0 * se,
            "{sampler}: {est} ± {se} vs {exact}"
        );
        let ci = v["ci95"].as_array().unwrap();
        assert!(ci[0].as_f64().unwrap() < est && est < ci[1].as_f64().unwrap());
    }
}

#[test]
fn importance_sampling_is_unbiased_and_reduces_variance() {
    let args = |importance: Option<&str>| {
        let mut a = vec![
            "integrate",
            "exp(-(x^2))",
            "--domain",
            "-3,3",
            "-n",
            "100000",
            "--json",
        ];
        if let Some(g) = importance {
            a.extend(["--importance", g]);
        }
        json_of(&pathlab(&a))
    };
    let exact = std::f64::consts::PI.sqrt() * 0.999_977_909_503_001_4; // √π erf(3)
    let uniform = args(None);
    let is = args(Some("exp(-(x^2))"));
    for v in [&uniform, &is] {
        let (est, se) = (
            v["estimate"].as_f64().unwrap(),
            v["std_error"].as_f64().unwrap(),
        );
        assert!((est - exact).abs() <= 4.0 * se, "{est} ± {se} vs {exact}");
    }
    let var = |v: &Value| v["variance_per_sample"].as_f64().unwrap();
    assert!(
        var(&is) < var(&uniform) / 100.0,
        "{} vs {}",
        var(&is),
        var(&uniform)
    );
}

#[test]
fn ten_dimensional_integral() {
    let v = json_of(&pathlab(&[
        "integrate",
        "x1*x2*x3*x4*x5*x6*x7*x8*x9*x10",
        "-d",
        "0,2",
        "-d",
        "0,2",
        "-d",
        "0,2",
        "-d",
        "0,2",
        "-d",
        "0,2",
        "-d",
        "0,2",
        "-d",
        "0,2",
        "-d",
        "0,2",
        "-d",
        "0,2",
        "-d",
        "0,2",
        "-n",
        "400000",
        "--json",
    ]));
    // ∏ ∫0^2 x dx = 2^10.
    let (est, se) = (
        v["estimate"].as_f64().unwrap(),
        v["std_error"].as_f64().unwrap(),
    );
    assert!((est - 1024.0).abs() <= 4.0 * se, "{est} ± {se}");
}

#[test]
fn same_seed_same_answer_for_any_thread_count() {
    let args = [
        "integrate",
        "sin(x)*cos(y)",
        "-d",
        "0,pi",
        "-d",
        "0,1",
        "-n",
        "300000",
        "--seed",
        "7",
        "--json",
    ];
    let est = |threads| json_of(&pathlab_with_threads(&args, threads))["estimate"].clone();
    assert_eq!(est(1), est(2));
    assert_eq!(est(1), est(3));
    let other = json_of(&pathlab(&[
        "integrate",
        "sin(x)*cos(y)",
        "-d",
        "0,pi",
        "-d",
        "0,1",
        "-n",
        "300000",
        "--seed",
        "8",
        "--json",
    ]));
    assert_ne!(est(1), other["estimate"]);
}

fn assert_image(path: &PathBuf, png: bool) {
    assert_image_at_least(path, png, 10_000);
}

fn assert_image_at_least(path: &PathBuf, png: bool, min_bytes: usize) {
    let bytes = std::fs::read(path).expect("image written");
    if png {
        assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
        assert!(bytes.len() > min_bytes, "suspiciously small PNG");
    } else {
        let text = String::from_utf8(bytes).unwrap();
        assert!(
            text.contains("<svg") && text.contains("<text"),
            "not an SVG with text"
        );
    }
}

#[test]
fn sample_plots_are_written() {
    for (name, file) in [
        ("exponential", "exp.png"),
        ("cosine-hemisphere", "cos.svg"),
        ("alias", "alias.png"),
        ("piecewise2d", "pw2.png"),
    ] {
        let path = scratch(file);
        let out = pathlab(&[
            "sample",
            name,
            "-n",
            "20000",
            "--plot",
            path.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_image(&path, file.ends_with(".png"));
    }
}

#[test]
fn convergence_plot_and_data() {
    let path = scratch("conv.png");
    let v = json_of(&pathlab(&[
        "integrate",
        "exp(-(x^2+y^2)/2)",
        "-d",
        "-2,2",
        "-d",
        "-2,2",
        "-n",
        "16384",
        "--exact",
        "2*pi*0.9544997361036416^2",
        "--convergence",
        path.to_str().unwrap(),
        "--json",
    ]));
    assert_image(&path, true);
    let series = v["convergence"]["series"].as_array().unwrap();
    assert_eq!(series.len(), 3);
    let slope = |i: usize| series[i]["fitted_slope"].as_f64().unwrap();
    // Independent sampling converges as N^-1/2; Sobol clearly faster on this smooth integrand.
    assert!(
        (slope(0) + 0.5).abs() < 0.2,
        "independent slope {}",
        slope(0)
    );
    assert!(slope(2) < -0.8, "sobol slope {}", slope(2));
}

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
    for view in ["normals", "depth", "bvh"] {
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

fn scratch_exists(name: &str) -> bool {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("cli-tests")
        .join(name)
        .exists()
}

#[test]
fn render_same_seed_same_image_for_any_thread_count() {
    let run = |threads: &str, name: &str| {
        let path = scratch(name);
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
            "-o",
            path.to_str().unwrap(),
            "-q",
        ]);
        assert!(out.status.success());
        pathlab_render::image_io::read_exr_rgb(&path).unwrap().2
    };
    assert_eq!(run("1", "t1.exr"), run("2", "t2.exr"));
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

fn course_scene(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scene/tests/data/cs184")
        .join(name)
        .to_str()
        .unwrap()
        .to_string()
}

#[test]
fn info_and_render_read_scene_files() {
    let bunny = course_scene("CBbunny.dae");
    let v = json_of(&pathlab(&["info", &bunny, "--json"]));
    assert_eq!(v["triangles"], 28_588);
    assert_eq!(v["camera"]["resolution"], serde_json::json!([800, 600]));
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
}

/// Asserts a one-line error that reads as a sentence: no Rust debug text in it.
fn assert_plain_error(out: &Output, expected: &str) {
    assert_one_line_error(out, expected);
    let stderr = String::from_utf8_lossy(&out.stderr);
    for debug in [
        "Os {",
        "Error(",
        "ParseError",
        "{ ",
        "`.\"",
        ":0:0:",
        "wlog",
    ] {
        assert!(!stderr.contains(debug), "debug text '{debug}' in: {stderr}");
    }
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
fn compare_ranks_the_strategies() {
    let out = scratch("compare.png");
    let reference = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scene/tests/data/cornell-box/mean-maxdepth-2.exr");
    let v = json_of(&pathlab(&[
        "compare",
        "-s",
        "8",
        "--ref",
        reference.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_image(&out, true);
    let rows = v["strategies"].as_array().unwrap();
    let get = |name: &str, key: &str| {
        rows.iter().find(|r| r["name"] == name).unwrap()[key]
            .as_f64()
            .unwrap()
    };
    // The course's worksheet, in numbers: cosine beats uniform, light sampling beats both.
    assert!(get("cosine", "mean_pixel_variance") < get("hemisphere", "mean_pixel_variance"));
    assert!(get("light", "mean_pixel_variance") < get("cosine", "mean_pixel_variance"));
    assert!(get("light", "rmse") < get("hemisphere", "rmse"));
    // A course scene works too.
    let out = scratch("compare_dae.png");
    let o = pathlab(&[
        "compare",
        &course_scene("CBspheres_lambertian.dae"),
        "-s",
        "2",
        "-r",
        "40",
        "30",
        "--strategies",
        "cosine,mis,path",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_one_line_error(
        &pathlab(&["compare", "--strategies", "magic"]),
        "unknown direct-lighting strategy",
    );
}

#[test]
fn converge_plots_error_curves() {
    let out = scratch("converge.png");
    let reference = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scene/tests/data/cornell-box/mean-maxdepth-2.exr");
    let v = json_of(&pathlab(&[
        "converge",
        "--ref",
        reference.to_str().unwrap(),
        "--max-spp",
        "32",
        "-o",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_image(&out, true);
    let curves = v["curves"].as_array().unwrap();
    let find = |n: &str| curves.iter().find(|c| c["name"] == n).unwrap();
    let slope = |n: &str| find(n)["fitted_slope"].as_f64().unwrap();
    // Independent sampling converges as N^-1/2; Sobol faster.
    assert!(
        (slope("independent") + 0.5).abs() < 0.15,
        "{}",
        slope("independent")
    );
    assert!(slope("sobol") < slope("independent"));
    // A course scene, against a reference pathlab renders itself.
    let scene = course_scene("CBspheres_lambertian.dae");
    let reference = scratch("cb_ref.exr");
    let o = pathlab(&[
        "render",
        &scene,
        "-r",
        "40",
        "30",
        "-s",
        "256",
        "-m",
        "1",
        "-o",
        reference.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success());
    let out = scratch("converge_dae.svg");
    let o = pathlab(&[
        "converge",
        &scene,
        "-r",
        "40",
        "30",
        "--ref",
        reference.to_str().unwrap(),
        "--max-spp",
        "8",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_image(&out, false);
    assert_one_line_error(
        &pathlab(&[
            "converge",
            &scene,
            "--ref",
            reference.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]),
        "the reference is 40x30",
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
        .join("../scene/tests/data/sky-spheres/sky.exr")
        .display()
        .to_string();
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scene/tests/data/cornell-spheres/scene.xml")
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

const PNG: &[u8] = b"\x89PNG\r\n\x1a\n";
const EXR: &[u8] = &[0x76, 0x2f, 0x31, 0x01];

/// Asserts the file exists and starts with its format's magic number.
fn assert_magic(path: &PathBuf, magic: &[u8]) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(bytes.starts_with(magic), "{}: wrong format", path.display());
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
fn compare_warns_when_the_reference_is_of_another_depth() {
    let data = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scene/tests/data/cornell-box");
    let run = |reference: &str, strategies: &str| {
        let out = scratch("compare_warn.png");
        pathlab(&[
            "compare",
            "-s",
            "4",
            "--strategies",
            strategies,
            "-m",
            "1",
            "--ref",
            data.join(reference).to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
    };
    let o = run("mean-maxdepth-inf.exr", "path");
    assert!(o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("warning:") && stderr.contains("its name suggests -m inf"),
        "{stderr}"
    );
    let o = run("mean-maxdepth-2.exr", "light");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.success() && !stderr.contains("warning"),
        "{stderr}"
    );
}

#[test]
fn sample_says_its_verdict_and_when_n_is_too_small() {
    let o = pathlab(&["sample", "exponential", "-n", "1"]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("too few") && !text.contains("inf"), "{text}");
    let v = json_of(&pathlab(&["sample", "exponential", "-n", "1", "--json"]));
    assert!(v["components"][0]["z"].is_null());
    let o = pathlab(&["sample", "exponential", "-n", "100000"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("consistent with the pdf at α = 0.01"),
        "{text}"
    );
}

#[test]
fn integrate_warns_of_heavy_tails() {
    let o = pathlab(&["integrate", "1/x", "-d", "0,1", "--json"]);
    let v = json_of(&o);
    assert_eq!(v["heavy_tailed"], true);
    assert!(String::from_utf8_lossy(&o.stderr).contains("heavy-tailed"));
    let v = json_of(&pathlab(&["integrate", "x^2", "-d", "0,1", "--json"]));
    assert_eq!(v["heavy_tailed"], false);
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
fn shards_merge_into_the_single_render_to_the_bit_and_bad_sets_are_reported() {
    let single = scratch("single.plf");
    let run = |extra: &[&str], out: &PathBuf| {
        let mut args = vec![
            "render",
            "-s",
            "32",
            "-r",
            "48",
            "32",
            "-q",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = pathlab(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    run(&[], &single);
    let parts: Vec<PathBuf> = (0..4).map(|i| scratch(&format!("part{i}.plf"))).collect();
    for (i, p) in parts.iter().enumerate() {
        run(&["--shard", &format!("{i}/4")], p);
    }
    let merged = scratch("merged.plf");
    let mut args: Vec<&str> = vec!["merge", merged.to_str().unwrap()];
    args.extend(parts.iter().map(|p| p.to_str().unwrap()));
    let o = pathlab(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read(&merged).unwrap(),
        std::fs::read(&single).unwrap()
    );
    // The merged EXR carries the variance and sample-count layers.
    let exr = scratch("merged.exr");
    args[1] = exr.to_str().unwrap();
    assert!(pathlab(&args).status.success());
    assert_magic(&exr, EXR);
    let p = |i: usize| parts[i].to_str().unwrap();
    assert_one_line_error(
        &pathlab(&["merge", "m.exr", p(0), p(1), p(3)]),
        "samples 16..24 are missing",
    );
    assert_one_line_error(
        &pathlab(&["merge", "m.exr", p(0), p(1), p(1), p(2), p(3)]),
        "overlaps",
    );
    let other = scratch("other-seed.plf");
    run(&["--shard", "2/4", "--seed", "9"], &other);
    assert_one_line_error(
        &pathlab(&["merge", "m.exr", p(0), p(1), other.to_str().unwrap(), p(3)]),
        "not a part of the same render",
    );
    assert_one_line_error(
        &pathlab(&["render", "--shard", "1/4", "-o", "x.exr"]),
        "-o PART.plf",
    );
    assert_one_line_error(
        &pathlab(&["render", "--shard", "4/4", "-o", "x.plf"]),
        "need 0 <= I < N",
    );
}

#[cfg(unix)]
fn interrupt(args: &[&str], signal: &str, after: std::time::Duration) -> std::process::Output {
    let child = Command::new(env!("CARGO_BIN_EXE_pathlab"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(after);
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    child.wait_with_output().unwrap()
}

#[test]
#[cfg(unix)]
fn a_stopped_render_writes_whole_passes_and_exits_with_the_signals_status() {
    // Stopped at a moment the test does not choose precisely: every pixel holds whole passes
    // (or one pass more), the image is an unbiased estimate, the exit status 130.
    let reference = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../scene/tests/data/cornell-box/mean-maxdepth-2.exr");
    let out = scratch("stopped.exr");
    let ck = scratch("stopped.plf");
    let o = interrupt(
        &[
            "render",
            "-m",
            "1",
            "-s",
            "100000",
            "--sampler",
            "independent",
            "--aov",
            "variance,samples",
            "--checkpoint",
            ck.to_str().unwrap(),
            "--checkpoint-every",
            "0",
            "-o",
            out.to_str().unwrap(),
            "-q",
            "--json",
        ],
        "-INT",
        std::time::Duration::from_millis(1500),
    );
    assert_eq!(
        o.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["cancelled"], true);
    let lo = v["spp_range"][0].as_f64().unwrap();
    let hi = v["spp_range"][1].as_f64().unwrap();
    assert!(lo >= 1.0 && hi <= 2.0 * lo.max(1.0) + 64.0, "{lo} to {hi}");
    // Unbiased: the image mean within 4 standard errors of the reference's.
    let (w, h, mean) = pathlab_render::image_io::read_exr_rgb(&out).unwrap();
    let (_, _, refm) = pathlab_render::image_io::read_exr_rgb(&reference).unwrap();
    assert_eq!((w, h), (256, 256));
    let avg = |img: &[glam::Vec3]| {
        img.iter().map(|p| p.as_dvec3()).sum::<glam::DVec3>() / img.len() as f64
    };
    let (ours, theirs) = (avg(&mean), avg(&refm));
    let var = read_exr_layer(&out, "variance.G");
    let se = (var.iter().map(|&v| v as f64).sum::<f64>()).sqrt() / var.len() as f64;
    let z = (ours.y - theirs.y) / se.max(1e-12);
    assert!(z.abs() < 4.0, "image mean {ours} vs {theirs}: z {z}");
    // A SIGTERM exits 143.
    let o = interrupt(
        &[
            "render",
            "-s",
            "100000",
            "-r",
            "8",
            "8",
            "-o",
            scratch("term.exr").to_str().unwrap(),
            "-q",
        ],
        "-TERM",
        std::time::Duration::from_millis(800),
    );
    assert_eq!(o.status.code(), Some(143));
}

#[test]
#[cfg(unix)]
fn a_checkpoint_resumes_to_the_same_image_and_another_renders_is_refused() {
    // A checkpoint resumes to the image an uninterrupted render gives, bit for bit.
    let ck2 = scratch("resume.plf");
    let whole = scratch("whole.plf");
    let args = |extra: &[&str]| {
        let mut a = vec!["render", "-s", "2048", "-r", "64", "64", "-q"];
        a.extend_from_slice(extra);
        a.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    let o = interrupt(
        &args(&[
            "--checkpoint",
            ck2.to_str().unwrap(),
            "--checkpoint-every",
            "0",
            "-o",
            scratch("partial.exr").to_str().unwrap(),
        ])
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>(),
        "-INT",
        std::time::Duration::from_millis(700),
    );
    assert_eq!(
        o.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let resumed = scratch("resumed.plf");
    let o = pathlab(
        &args(&[
            "--resume",
            ck2.to_str().unwrap(),
            "-o",
            resumed.to_str().unwrap(),
        ])
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = pathlab(
        &args(&["-o", whole.to_str().unwrap()])
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert!(o.status.success());
    assert_eq!(
        std::fs::read(&resumed).unwrap(),
        std::fs::read(&whole).unwrap()
    );
    // A checkpoint of another render, or a corrupt one, is refused.
    assert_one_line_error(
        &pathlab(&[
            "render",
            "-s",
            "2048",
            "-r",
            "64",
            "64",
            "--seed",
            "4",
            "--resume",
            ck2.to_str().unwrap(),
            "-o",
            "x.exr",
        ]),
        "seed",
    );
    let bad = scratch("bad.plf");
    let mut bytes = std::fs::read(&ck2).unwrap();
    let n = bytes.len();
    bytes[n / 2] ^= 1;
    std::fs::write(&bad, &bytes).unwrap();
    assert_one_line_error(
        &pathlab(&[
            "render",
            "-s",
            "2048",
            "-r",
            "64",
            "64",
            "--resume",
            bad.to_str().unwrap(),
            "-o",
            "x.exr",
        ]),
        "corrupt",
    );
}

/// One channel of an EXR file, by name.
fn read_exr_layer(path: &PathBuf, name: &str) -> Vec<f32> {
    use exr::prelude::*;
    let image = read_all_flat_layers_from_file(path).unwrap();
    let layer = &image.layer_data[0];
    let ch = layer
        .channel_data
        .list
        .iter()
        .find(|c| c.name.to_string() == name)
        .unwrap_or_else(|| panic!("no channel {name}"));
    match &ch.sample_data {
        FlatSamples::F32(v) => v.clone(),
        FlatSamples::F16(v) => v.iter().map(|x| x.to_f32()).collect(),
        FlatSamples::U32(v) => v.iter().map(|&x| x as f32).collect(),
    }
}

#[test]
#[cfg(unix)]
fn progressive_and_adaptive_renders_checkpoint_and_resume_to_the_same_image() {
    // `pathlab render -r SIZE SIZE -q EXTRA...`, which must succeed.
    let render = |size: &str, extra: &[&str]| {
        let mut a = vec!["render", "-r", size, size, "-q"];
        a.extend_from_slice(extra);
        let o = pathlab(&a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        o
    };
    let same = |a: &PathBuf, b: &PathBuf| {
        assert!(
            std::fs::read(a).unwrap() == std::fs::read(b).unwrap(),
            "{a:?} and {b:?} differ"
        );
    };
    let (a, b) = (scratch("resumed-a.plf"), scratch("resumed-b.plf"));
    let (a_s, b_s) = (a.to_str().unwrap(), b.to_str().unwrap());
    // --target-error: a render stopped at one target and resumed to a lower one gives the
    // image of a render to the lower target, bit for bit.
    let ck = scratch("progressive.plf");
    let ck_s = ck.to_str().unwrap();
    render(
        "32",
        &["--target-error", "0.05", "--checkpoint", ck_s, "-o", a_s],
    );
    render(
        "32",
        &["--target-error", "0.03", "--resume", ck_s, "-o", a_s],
    );
    render("32", &["--target-error", "0.03", "-o", b_s]);
    same(&a, &b);
    // --time goes on from a checkpoint too (where it stops depends on the time).
    let o = render(
        "32",
        &["--time", "0.3", "--resume", ck_s, "--json", "-o", a_s],
    );
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["estimated_relative_rmse"].as_f64().unwrap() <= 0.05);
    // Adaptive (two-stage): stopped by SIGINT mid-render and resumed, the same image.
    let ck = scratch("adaptive.plf");
    let ck_s = ck.to_str().unwrap();
    let partial = scratch("adaptive-partial.exr");
    let adaptive = ["-a", "-s", "1024"];
    let o = interrupt(
        &[
            &["render", "-r", "48", "48", "-q"][..],
            &adaptive,
            &["--checkpoint", ck_s, "-o", partial.to_str().unwrap()],
        ]
        .concat(),
        "-INT",
        std::time::Duration::from_millis(500),
    );
    assert_eq!(
        o.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    render(
        "48",
        &[&adaptive[..], &["--resume", ck_s, "-o", a_s]].concat(),
    );
    render("48", &[&adaptive[..], &["-o", b_s]].concat());
    same(&a, &b);
    // The stopping rules decide on samples a film does not keep: refused, saying why.
    assert_one_line_error(
        &pathlab(&[
            "render",
            "-a",
            "--adaptive-rule",
            "course",
            "--checkpoint",
            ck_s,
            "-o",
            "x.exr",
        ]),
        "two-stage",
    );
}

#[test]
fn refused_command_lines_are_one_line_errors_that_name_the_argument() {
    let o = pathlab(&["diff", "a.exr"]);
    assert_one_line_error(&o, "required arguments were not provided: <B>");
    assert_eq!(o.status.code(), Some(2));
    assert_one_line_error(&pathlab(&["render", "--bogus"]), "'--bogus'");
    assert_one_line_error(&pathlab(&["render", "-s", "x"]), "'--spp <SPP>'");
}

/// tev's packets as a listener decodes them: CreateImage (name, size, channels) and
/// UpdateImage (channels, region, planar values); others are only counted.
#[derive(Debug, Default)]
struct TevStream {
    created: Vec<(String, i32, i32, Vec<String>)>,
    updates: Vec<(Vec<String>, [i32; 4], Vec<f32>)>,
    others: usize,
}

fn decode_tev(bytes: &[u8]) -> TevStream {
    struct R<'a>(&'a [u8], usize);
    impl R<'_> {
        fn take(&mut self, n: usize) -> &[u8] {
            let s = &self.0[self.1..self.1 + n];
            self.1 += n;
            s
        }
        fn i32(&mut self) -> i32 {
            i32::from_le_bytes(self.take(4).try_into().unwrap())
        }
        fn i64(&mut self) -> i64 {
            i64::from_le_bytes(self.take(8).try_into().unwrap())
        }
        fn string(&mut self) -> String {
            let end = self.0[self.1..].iter().position(|&b| b == 0).unwrap();
            let s = String::from_utf8(self.take(end).to_vec()).unwrap();
            self.1 += 1;
            s
        }
    }
    let mut out = TevStream::default();
    let mut at = 0;
    while at < bytes.len() {
        let len = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        let mut r = R(&bytes[at..at + len], 4);
        match r.take(1)[0] {
            4 => {
                r.take(1);
                let name = r.string();
                let (w, h, n) = (r.i32(), r.i32(), r.i32());
                let channels = (0..n).map(|_| r.string()).collect();
                out.created.push((name, w, h, channels));
            }
            6 => {
                r.take(1);
                r.string();
                let n = r.i32() as usize;
                let channels: Vec<String> = (0..n).map(|_| r.string()).collect();
                let region = [r.i32(), r.i32(), r.i32(), r.i32()];
                let count = (region[2] * region[3]) as usize;
                let offsets: Vec<i64> = (0..n).map(|_| r.i64()).collect();
                let strides: Vec<i64> = (0..n).map(|_| r.i64()).collect();
                let data: Vec<f32> = r
                    .take(len - r.1)
                    .chunks_exact(4)
                    .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                    .collect();
                // Planar in the channels' order: value c of pixel p at offset_c + p stride_c.
                let mut planar = Vec::with_capacity(n * count);
                for c in 0..n {
                    for p in 0..count {
                        planar.push(data[(offsets[c] + p as i64 * strides[c]) as usize]);
                    }
                }
                out.updates.push((channels, region, planar));
            }
            _ => out.others += 1,
        }
        at += len;
    }
    out
}

#[test]
fn display_streams_the_render_to_tev_and_ends_on_the_image_written() {
    use std::io::Read;
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap().to_string();
    let reader = std::thread::spawn(move || {
        let (mut s, _) = listener.accept().unwrap();
        let mut bytes = Vec::new();
        s.read_to_end(&mut bytes).unwrap();
        bytes
    });
    let exr = scratch("display.exr");
    // Long enough (about a second) for updates while it renders.
    let (w, h) = (64, 40);
    let o = pathlab(&[
        "render",
        "-r",
        "64",
        "40",
        "-s",
        "1024",
        "--aov",
        "variance,samples",
        "--display",
        &addr,
        "-o",
        exr.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let tev = decode_tev(&reader.join().unwrap());
    let channels = [
        "R",
        "G",
        "B",
        "variance.R",
        "variance.G",
        "variance.B",
        "samples.Y",
    ];
    assert_eq!(tev.created.len(), 1);
    let (name, cw, ch, cc) = &tev.created[0];
    assert_eq!((name.as_str(), *cw, *ch), ("cornell-box", w, h));
    assert_eq!(cc, &channels);
    // The last value each update gave each pixel's channels.
    let mut last = vec![vec![f32::NAN; (w * h) as usize]; channels.len()];
    for (uc, [x0, y0, rw, rh], planar) in &tev.updates {
        assert_eq!(uc, &channels);
        let n = (rw * rh) as usize;
        for (c, plane) in last.iter_mut().enumerate() {
            for p in 0..n {
                let (x, y) = (x0 + p as i32 % rw, y0 + p as i32 / rw);
                plane[(y * w + x) as usize] = planar[c * n + p];
            }
        }
    }
    // Besides the first and last whole images, tiles re-sent as passes changed them.
    let tiles = tev.updates.iter().filter(|u| u.1[2] <= 16).count();
    assert!(tiles > 0, "no tile updates during the render");
    for (c, name) in channels.iter().enumerate() {
        let written = read_exr_layer(&exr, name);
        assert!(
            last[c]
                .iter()
                .zip(&written)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{name}: tev's last values differ from the EXR's"
        );
    }
    // Nothing listening: one warning, and the render goes on.
    let free = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = free.local_addr().unwrap().port();
    drop(free);
    let o = pathlab(&[
        "render",
        "-r",
        "8",
        "8",
        "-s",
        "4",
        "--display",
        &format!("127.0.0.1:{port}"),
        "-o",
        scratch("display-alone.exr").to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("warning: --display"), "{stderr}");
}
