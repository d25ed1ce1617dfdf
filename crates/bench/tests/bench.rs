//! The benchmark harness run as bench/run.sh runs it: ray files checked hit by hit, and the OBJ
//! export of a scene's triangles.

use std::path::PathBuf;
use std::process::{Command, Output};

fn bench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pathlab-bench"))
        .args(args)
        .output()
        .expect("the pathlab-bench binary runs")
}

use pathlab_testkit::process::{assert_one_line_error, json_of};

fn scratch(name: &str) -> PathBuf {
    pathlab_testkit::process::scratch(env!("CARGO_TARGET_TMPDIR"), "bench-tests", name)
}

#[test]
fn bench_rays_checks_hits_against_the_ray_file() {
    // A unit quad at z = 0 and four rays in the file format embree_bench writes: two hit it
    // at t = 2 (one starting at t_near 1), one misses, one has a wrong distance on purpose.
    let obj = scratch("bench_quad.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let write_rays = |name: &str, wrong: bool| {
        let mut bytes = b"PLRAYS1\0".to_vec();
        bytes.extend(2u64.to_le_bytes());
        bytes.extend(2u64.to_le_bytes());
        let rays: [[f32; 8]; 4] = [
            [0.5, 0.5, 2.0, 0.0, 0.0, -1.0, 0.0, 2.0],
            [0.2, 0.7, 2.0, 0.0, 0.0, -1.0, 1.0, 2.0],
            [5.0, 5.0, 2.0, 0.0, 0.0, -1.0, 0.0, f32::INFINITY],
            [
                0.5,
                0.5,
                2.0,
                0.0,
                0.0,
                -1.0,
                0.0,
                if wrong { 3.0 } else { 2.0 },
            ],
        ];
        for r in rays {
            for v in r {
                bytes.extend(v.to_le_bytes());
            }
        }
        let path = scratch(name);
        std::fs::write(&path, bytes).unwrap();
        path
    };
    let good = write_rays("good.rays", false);
    let v = json_of(&bench(&[
        "rays",
        obj.to_str().unwrap(),
        good.to_str().unwrap(),
        "--repeat",
        "1",
        "--json",
    ]));
    assert_eq!(v["triangles"], 2);
    for set in v["sets"].as_array().unwrap() {
        assert_eq!(set["agreement"].as_f64().unwrap(), 1.0, "{set}");
    }
    // The text report: the scene, both ray sets, the baselines.
    let out = bench(&[
        "rays",
        obj.to_str().unwrap(),
        good.to_str().unwrap(),
        "--repeat",
        "1",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(text.contains(": 2 triangles, BVH build"), "{text}");
    for line in ["  primary ", "  bounce ", "  baseline, 1 thread"] {
        assert!(text.contains(line), "{line}: {text}");
    }
    // A disagreeing hit distance fails the run.
    let bad = write_rays("bad.rays", true);
    let out = bench(&[
        "rays",
        obj.to_str().unwrap(),
        bad.to_str().unwrap(),
        "--repeat",
        "1",
    ]);
    assert_one_line_error(&out, "agree");
    // A file that is not a ray file is a one-line error naming it.
    let junk = scratch("junk.rays");
    std::fs::write(&junk, b"not rays at all, really not").unwrap();
    assert_one_line_error(
        &bench(&["rays", obj.to_str().unwrap(), junk.to_str().unwrap()]),
        "junk.rays",
    );
    // OBJ export round-trips the triangles.
    let exported = scratch("exported.obj");
    assert!(bench(&["obj", "cornell-box", exported.to_str().unwrap()])
        .status
        .success());
    let text = std::fs::read_to_string(&exported).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 36);
}
