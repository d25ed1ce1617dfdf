//! End-to-end tests of renders that survive and scale: shards and `pathlab merge`, signals,
//! checkpoints and resuming.

mod common;

use common::*;
use serde_json::Value;
use std::path::PathBuf;

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
    // `-o`, as `render` takes it, names the output; every file is then a part.
    let with_o = scratch("merged-o.plf");
    let o = pathlab(&[
        "merge",
        p(0),
        p(1),
        "-o",
        with_o.to_str().unwrap(),
        p(2),
        p(3),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read(&with_o).unwrap(),
        std::fs::read(&single).unwrap()
    );
    // An output that is one of the parts would destroy it: refused, the part untouched.
    let before = std::fs::read(&parts[0]).unwrap();
    assert_one_line_error(
        &pathlab(&["merge", "-o", p(0), p(0), p(1), p(2), p(3)]),
        "is also one of the parts",
    );
    assert_one_line_error(&pathlab(&["merge", "m.exr"]), "at least one part");
    assert_eq!(std::fs::read(&parts[0]).unwrap(), before);
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

#[test]
#[cfg(unix)]
fn a_stopped_render_writes_whole_passes_and_exits_with_the_signals_status() {
    // Stopped at a moment the test does not choose precisely: every pixel holds whole passes
    // (or one pass more), the image is an unbiased estimate, the exit status 130.
    let reference = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/cornell-box/mean-maxdepth-2.exr");
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
