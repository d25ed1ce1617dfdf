//! End-to-end tests of the experiments: `pathlab sample`, `integrate`, `compare` and
//! `converge`.

mod common;

use common::*;
use serde_json::Value;
use std::path::PathBuf;

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
fn compare_ranks_the_strategies() {
    let out = scratch("compare.png");
    let reference = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/cornell-box/mean-maxdepth-2.exr");
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
        .join("../../tests/data/cornell-box/mean-maxdepth-2.exr");
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
fn compare_warns_when_the_reference_is_of_another_depth() {
    let data = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/cornell-box");
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
fn compare_and_converge_take_scene_parameters_and_say_what_the_loader_warns() {
    // A Mitsuba scene whose film width is a parameter: `-D` sets it, and a parameter the
    // scene does not use is the loader's warning, printed.
    let scene = scratch("param_sphere.xml");
    std::fs::write(
        &scene,
        r#"<scene version="3.0.0">
  <default name="w" value="8"/>
  <sensor type="perspective">
    <float name="fov" value="30"/>
    <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="$w"/><integer name="height" value="4"/></film>
  </sensor>
  <shape type="sphere"><bsdf type="diffuse"/></shape>
  <emitter type="constant"/>
</scene>
"#,
    )
    .unwrap();
    let scene = scene.to_str().unwrap();
    let out = scratch("param_compare.png");
    let o = pathlab(&[
        "compare",
        scene,
        "-D",
        "w=6",
        "-D",
        "unused=1",
        "-s",
        "2",
        "--strategies",
        "cosine",
        "-o",
        out.to_str().unwrap(),
    ]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(o.status.success(), "{stderr}");
    assert!(stdout.contains("at 6x4"), "{stdout}");
    assert!(
        stderr.contains("warning:") && stderr.contains("'unused'"),
        "{stderr}"
    );
    assert_one_line_error(&pathlab(&["compare", scene, "-D", "novalue"]), "-D novalue");
    // converge reads its reference at the size -D gives the scene.
    let reference = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/cornell-box/mean-maxdepth-2.exr");
    assert_one_line_error(
        &pathlab(&[
            "converge",
            scene,
            "-D",
            "w=6",
            "--ref",
            reference.to_str().unwrap(),
        ]),
        "6x4",
    );
}
