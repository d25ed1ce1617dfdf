//! A render's plan: what the request leaves open the scene's hints, then the defaults, fill.

use pathlab_lab::render::ProgressiveStop;
use pathlab_lab::render::{Plan, RenderRequest, SceneEdits, PROGRESSIVE_CAP};
use pathlab_mc::sampler::SamplerKind;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

fn plan(req: &RenderRequest) -> (Plan, Vec<String>) {
    let mut warnings = Vec::new();
    let plan = Plan::new(
        req,
        &mut |w| warnings.push(w.to_string()),
        &AtomicBool::new(false),
    )
    .expect("the plan");
    (plan, warnings)
}

/// A pbrt-v4 file of a 100 x 50 image that asks for 8 samples and a crop window.
fn cropped_scene() -> String {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("plan-tests");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("crop.pbrt");
    std::fs::write(
        &path,
        r#"Film "rgb" "integer xresolution" 100 "integer yresolution" 50 "float cropwindow" [ 0.1 0.5 0 0.5 ]
Sampler "independent" "integer pixelsamples" 8
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective"
WorldBegin
Shape "sphere"
"#,
    )
    .unwrap();
    path.to_string_lossy().into_owned()
}

#[test]
fn the_scene_fills_what_the_request_leaves_open() {
    let req = RenderRequest {
        scene: cropped_scene(),
        ..Default::default()
    };
    let (p, warnings) = plan(&req);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!((p.spp, p.settings.sampler), (8, SamplerKind::Independent));
    assert_eq!(p.resolution, [100, 50]);
    assert_eq!(p.settings.crop, Some([10, 0, 50, 25]));
    assert_eq!(p.total_samples(), 40 * 25 * 8);

    // Twice the size: the same part of the image.
    let req = RenderRequest {
        edits: SceneEdits {
            resolution: Some([200, 100]),
            ..Default::default()
        },
        ..req
    };
    assert_eq!(plan(&req).0.settings.crop, Some([20, 0, 100, 50]));
    // The caller's window and samples win.
    let req = RenderRequest {
        crop: Some([0, 0, 4, 4]),
        spp: Some(3),
        sampler: Some(SamplerKind::Sobol),
        ..req
    };
    let p = plan(&req).0;
    assert_eq!(p.settings.crop, Some([0, 0, 4, 4]));
    assert_eq!((p.spp, p.settings.sampler), (3, SamplerKind::Sobol));
}

#[test]
fn defaults_fill_what_neither_says() {
    let req = RenderRequest {
        scene: "cornell-box".into(),
        ..Default::default()
    };
    let p = plan(&req).0;
    assert_eq!((p.spp, p.settings.sampler), (64, SamplerKind::Sobol));
    assert_eq!((p.settings.crop, p.max_depth), (None, u32::MAX));
    // Progressive renders take independent samples, up to the cap.
    let req = RenderRequest {
        progressive: Some(ProgressiveStop {
            time: Some(1.0),
            ..Default::default()
        }),
        ..req
    };
    let p = plan(&req).0;
    assert_eq!(
        (p.stop_cap, p.settings.sampler),
        (PROGRESSIVE_CAP, SamplerKind::Independent)
    );
}

#[test]
fn bdpt_says_when_it_traces_no_light_to_the_lens() {
    use pathlab_render::integrator::{IntegratorChoice, IntegratorName};
    use pathlab_render::render::Adaptive;
    let req = RenderRequest {
        scene: "cornell-box".into(),
        integrator: IntegratorChoice {
            name: Some(IntegratorName::Bdpt),
            ..Default::default()
        },
        ..Default::default()
    };
    assert!(plan(&req).1.is_empty(), "{:?}", plan(&req).1);
    let req = RenderRequest {
        adaptive: Some(Adaptive::DEFAULT),
        ..req
    };
    let warnings = plan(&req).1;
    assert!(
        warnings.len() == 1 && warnings[0].contains("no light tracing"),
        "{warnings:?}"
    );
}

#[test]
fn contradictions_are_refused_before_the_scene_is_loaded() {
    use pathlab_lab::render::Shard;
    use pathlab_render::integrator::IntegratorChoice;
    use pathlab_render::render::{Adaptive, AdaptiveRule};
    // A scene that does not exist: each error must come before loading it.
    let base = RenderRequest {
        scene: "no-such-scene.xml".into(),
        ..Default::default()
    };
    let error = |req: RenderRequest| {
        let e = req.check().expect_err("a contradiction");
        let by_plan = Plan::new(&req, &mut |_| {}, &AtomicBool::new(false));
        assert_eq!(by_plan.err().map(|e| e.to_string()), Some(e.to_string()));
        e.to_string()
    };
    let time = Some(ProgressiveStop {
        time: Some(1.0),
        ..Default::default()
    });
    let cases = [
        (
            RenderRequest {
                integrator: IntegratorChoice {
                    max_depth: Some(2),
                    only_bounce: Some(3),
                    ..Default::default()
                },
                ..base.clone()
            },
            "--only-bounce 3 is beyond --max-depth 2",
        ),
        (
            RenderRequest {
                crop: Some([4, 0, 4, 8]),
                ..base.clone()
            },
            "--crop 4 0 4 8: need x0 < x1",
        ),
        (
            RenderRequest {
                adaptive: Some(Adaptive::DEFAULT),
                progressive: time,
                ..base.clone()
            },
            "choose one",
        ),
        (
            RenderRequest {
                shard: Some(Shard { index: 0, count: 2 }),
                progressive: time,
                ..base.clone()
            },
            "--shard splits a render of fixed samples",
        ),
        (
            RenderRequest {
                adaptive: Some(Adaptive {
                    rule: AdaptiveRule::Course,
                    ..Adaptive::DEFAULT
                }),
                checkpoints: true,
                ..base.clone()
            },
            "use the default two-stage rule",
        ),
        (
            RenderRequest {
                edits: SceneEdits {
                    fov: Some(200.0),
                    ..Default::default()
                },
                ..base.clone()
            },
            "--fov 200: must be",
        ),
        (
            RenderRequest {
                progressive: Some(ProgressiveStop {
                    target_error: Some(-1.0),
                    ..Default::default()
                }),
                ..base.clone()
            },
            "--target-error -1: must be",
        ),
    ];
    for (req, expected) in cases {
        let e = error(req);
        assert!(e.contains(expected), "{e}");
    }
    // The two-stage rule keeps its checkpoints; what is consistent passes.
    let req = RenderRequest {
        adaptive: Some(Adaptive::DEFAULT),
        checkpoints: true,
        ..base
    };
    assert!(req.check().is_ok());
}

#[test]
fn shards_read_as_i_of_n() {
    use pathlab_lab::render::Shard;
    let s: Shard = " 2 / 5".parse().expect("a shard");
    assert_eq!((s.index, s.count), (2, 5));
    for bad in ["2", "a/5", "2/", "-1/4"] {
        let e = bad.parse::<Shard>().expect_err(bad).to_string();
        assert!(e.contains("expected I/N"), "{bad}: {e}");
    }
}
