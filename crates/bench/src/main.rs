//! `pathlab-bench`: measurements that are not tests. `pathlab-bench rays MESH RAYS` traces
//! the exact rays of a ray file written by the Embree benchmark (`bench/embree/`), checks
//! every hit distance against Embree's, and reports build time, throughput and memory, so
//! that the two can be compared as ratios in one script.

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use glam::Vec3;
use pathlab_render::geometry::Ray;
use pathlab_render::scene::Scene;
use rayon::prelude::*;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// pathlab-bench: measurements that are not tests (BVH build and ray throughput against
/// Embree's ray files).
#[derive(Parser, Debug)]
#[command(name = "pathlab-bench", version, about, long_about = None)]
struct BenchArgs {
    #[command(subcommand)]
    what: BenchWhat,
}

#[derive(Subcommand, Debug)]
enum BenchWhat {
    /// Trace a ray file (primary and bounce rays with Embree's hit distances) through the BVH of
    /// a mesh: build time, Mrays/s for 1 and all threads, hits checked against Embree's.
    Rays(RaysArgs),
    /// Write a scene's triangles (world space) as an OBJ file, for tools that read only OBJ.
    Obj(ObjArgs),
}

#[derive(Args, Debug)]
struct ObjArgs {
    /// The scene.
    scene: String,
    /// The OBJ file to write.
    output: PathBuf,
}

#[derive(Args, Debug)]
struct RaysArgs {
    /// The mesh (any scene file pathlab reads; OBJ for the Embree comparison).
    mesh: String,
    /// The ray file written by `embree_bench MESH THREADS RAYS`.
    rays: PathBuf,
    /// Threads for the parallel run (0: all cores).
    #[arg(short = 't', long, default_value_t = 0)]
    threads: usize,
    /// Timed repetitions per measurement (the best is reported).
    #[arg(long, default_value_t = 3)]
    repeat: u32,
    /// Print the results as JSON.
    #[arg(long)]
    json: bool,
    /// Only the scene's hit distances on one thread (no parallel run, no surface
    /// interactions, no baselines, no check against Embree's hits): for timing two builds
    /// in turns.
    #[arg(long)]
    quick: bool,
}

/// One ray of the file: origin, unit direction, the start of its extent and Embree's hit
/// distance (infinite for a miss).
#[derive(Clone, Copy, Debug)]
struct FileRay {
    o: Vec3,
    d: Vec3,
    t_near: f32,
    t_hit: f32,
}

/// Reads the ray file: 8-byte magic `PLRAYS1\0`, u64 primary count, u64 bounce count, then
/// records of 8 little-endian f32 (origin, direction, t_near, t_hit).
fn read_rays(path: &Path) -> Result<(Vec<FileRay>, Vec<FileRay>)> {
    let bytes = std::fs::read(path).with_context(|| format!("{}", path.display()))?;
    let bad = |what: &str| anyhow::anyhow!("{}: {what}", path.display());
    if bytes.len() < 24 || &bytes[..8] != b"PLRAYS1\0" {
        return Err(bad("not a ray file (expected the magic PLRAYS1)"));
    }
    let word =
        |i: usize| u64::from_le_bytes(bytes[8 + 8 * i..16 + 8 * i].try_into().unwrap_or([0; 8]));
    let (n_primary, n_bounce) = (word(0) as usize, word(1) as usize);
    let records = n_primary
        .checked_add(n_bounce)
        .filter(|n| n.checked_mul(32).is_some_and(|b| b == bytes.len() - 24))
        .ok_or_else(|| {
            bad(&format!(
                "{} bytes of records do not hold {n_primary} + {n_bounce} rays of 32 bytes",
                bytes.len() - 24
            ))
        })?;
    let rays: Vec<FileRay> = bytes[24..]
        .chunks_exact(32)
        .take(records)
        .map(|r| {
            let f =
                |k: usize| f32::from_le_bytes([r[4 * k], r[4 * k + 1], r[4 * k + 2], r[4 * k + 3]]);
            FileRay {
                o: Vec3::new(f(0), f(1), f(2)),
                d: Vec3::new(f(3), f(4), f(5)),
                t_near: f(6),
                t_hit: f(7),
            }
        })
        .collect();
    let mut primary = rays;
    let bounce = primary.split_off(n_primary);
    Ok((primary, bounce))
}

/// The ray as pathlab traces it.
fn to_ray(r: &FileRay) -> Ray {
    Ray {
        t_min: r.t_near,
        ..Ray::new(r.o, r.d)
    }
}

/// What is asked of the scene for each ray.
#[derive(Clone, Copy, PartialEq)]
enum Query {
    /// The nearest hit's distance, as a ray-tracing kernel (Embree's `rtcIntersect1`) answers.
    Distance,
    /// The whole surface interaction the renderer asks for (point, normals, material, uv).
    Interaction,
    /// Hit distances of eight consecutive rays at a time, walking the BVH together where the
    /// scene allows (`Scene::hit_distances`), as a kernel's packets of eight are.
    Packets,
}

/// Hit distances of every ray (infinite for a miss), measured from the file's origin, written
/// to `hits` (as long as `rays`; written before the clock starts, as the Embree benchmark's
/// copy of its rays is, so that no run pays for first touching its pages).
fn trace_all(
    scene: &Scene,
    rays: &[FileRay],
    pool: Option<&rayon::ThreadPool>,
    query: Query,
    hits: &mut [f32],
) {
    let one = |(r, hit): (&FileRay, &mut f32)| {
        let ray = to_ray(r);
        *hit = match query {
            Query::Distance | Query::Packets => scene.hit_distance(&ray),
            Query::Interaction => scene.intersect(&ray).0.map(|si| si.t),
        }
        .unwrap_or(f32::INFINITY);
    };
    let eight = |(r, hit): (&[FileRay], &mut [f32])| match <&[FileRay; 8]>::try_from(r) {
        Ok(r) => {
            for (h, t) in hit
                .iter_mut()
                .zip(scene.hit_distances(&r.map(|r| to_ray(&r))))
            {
                *h = t.unwrap_or(f32::INFINITY);
            }
        }
        // The last few rays.
        Err(_) => r.iter().zip(hit.iter_mut()).for_each(one),
    };
    match (pool, query) {
        (None, Query::Packets) => rays.chunks(8).zip(hits.chunks_mut(8)).for_each(eight),
        (None, _) => rays.iter().zip(hits.iter_mut()).for_each(one),
        (Some(pool), Query::Packets) => pool.install(|| {
            rays.par_chunks(8)
                .zip(hits.par_chunks_mut(8))
                .with_min_len(512)
                .for_each(eight)
        }),
        (Some(pool), _) => pool.install(|| {
            rays.par_iter()
                .zip(hits.par_iter_mut())
                .with_min_len(4096)
                .for_each(one)
        }),
    }
}

/// Best throughput in Mrays/s over `repeat` runs of `trace`, which traces all `count` rays.
fn timed_into(count: usize, repeat: u32, mut trace: impl FnMut()) -> f64 {
    let mut best = 0.0f64;
    for _ in 0..repeat.max(1) {
        let start = Instant::now();
        trace();
        best = best.max(count as f64 / start.elapsed().as_secs_f64() / 1e6);
    }
    best
}

/// How many hits agree with Embree's: both miss, or distances within 1e-4 relative.
fn agreement(rays: &[FileRay], hits: &[f32]) -> usize {
    rays.iter()
        .zip(hits)
        .filter(|(r, &t)| {
            if r.t_hit.is_infinite() || t.is_infinite() {
                r.t_hit.is_infinite() && t.is_infinite()
            } else {
                (t - r.t_hit).abs() <= 1e-4 * r.t_hit.abs().max(1e-3)
            }
        })
        .count()
}

fn main() -> std::process::ExitCode {
    let args = BenchArgs::parse();
    let result = match &args.what {
        BenchWhat::Rays(a) => rays(a),
        BenchWhat::Obj(a) => export_obj(a),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            let chain: Vec<String> = e.chain().map(|c| c.to_string()).collect();
            eprintln!("error: {}", chain.join(": "));
            std::process::ExitCode::FAILURE
        }
    }
}

fn export_obj(args: &ObjArgs) -> Result<()> {
    use std::io::Write;
    let desc = pathlab_scene::load(&args.scene)?;
    let file = std::fs::File::create(&args.output)
        .with_context(|| format!("cannot create {}", args.output.display()))?;
    let mut out = std::io::BufWriter::new(file);
    let (mut base, mut faces) = (1usize, 0usize);
    for m in &desc.meshes {
        for p in &m.positions {
            writeln!(out, "v {} {} {}", p.x, p.y, p.z)?;
        }
        for t in m.indices.chunks_exact(3) {
            writeln!(
                out,
                "f {} {} {}",
                base + t[0] as usize,
                base + t[1] as usize,
                base + t[2] as usize
            )?;
            faces += 1;
        }
        base += m.positions.len();
    }
    out.flush()
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    if desc.spheres.is_empty() && desc.sdf_grids.is_empty() {
        println!("{}: {faces} triangles", args.output.display());
    } else {
        println!(
            "{}: {faces} triangles ({} spheres and {} SDF grids left out)",
            args.output.display(),
            desc.spheres.len(),
            desc.sdf_grids.len()
        );
    }
    Ok(())
}

fn rays(args: &RaysArgs) -> Result<()> {
    let (primary, bounce) = read_rays(&args.rays)?;
    let mut desc = pathlab_scene::load(&args.mesh)?;
    // Only the geometry matters here.
    desc.environment = None;
    desc.environment_map = None;
    desc.point_lights.clear();
    desc.spot_lights.clear();
    desc.directional_lights.clear();
    for m in &mut desc.meshes {
        m.emission = None;
    }
    let start = Instant::now();
    let scene = Scene::build(&desc).context("cannot build the scene")?;
    let build_total = start.elapsed().as_secs_f64();
    let stats = scene.stats();
    if stats.triangles == 0 {
        bail!("{}: no triangles", args.mesh);
    }
    let threads = if args.threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        args.threads
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start the worker threads")?;
    let mut sets = Vec::new();
    for (name, rays) in [("primary", &primary), ("bounce", &bounce)] {
        let run = |pool, query| {
            let mut hits = vec![0.0f32; rays.len()];
            let rate = timed_into(rays.len(), args.repeat, || {
                trace_all(&scene, rays, pool, query, &mut hits)
            });
            (rate, hits)
        };
        let (one, hits) = run(None, Query::Distance);
        let (packets, packet_hits) = run(None, Query::Packets);
        if args.quick {
            sets.push(
                json!({"rays": name, "count": rays.len(), "mrays_per_s_1_thread": one,
                "mrays_per_s_1_thread_packets": packets}),
            );
            continue;
        }
        let (all, _) = run(Some(&pool), Query::Distance);
        let (with_interaction, full_hits) = run(None, Query::Interaction);
        let agree = agreement(rays, &hits)
            .min(agreement(rays, &full_hits))
            .min(agreement(rays, &packet_hits));
        let visited: u64 = rays
            .iter()
            .map(|r| u64::from(scene.intersect(&to_ray(r)).1))
            .sum();
        sets.push(json!({
            "rays": name,
            "count": rays.len(),
            "mrays_per_s_1_thread": one,
            "mrays_per_s_1_thread_packets": packets,
            "mrays_per_s_all_threads": all,
            "mrays_per_s_1_thread_with_interaction": with_interaction,
            "agreeing_hits": agree,
            "agreement": agree as f64 / rays.len().max(1) as f64,
            "nodes_per_ray": visited as f64 / rays.len().max(1) as f64,
        }));
    }
    if args.quick {
        println!("{}", serde_json::to_string_pretty(&json!({"sets": sets}))?);
        return Ok(());
    }
    let baseline = binary_baseline(&desc, &primary, &bounce, args.repeat);
    let bytes_per_triangle = scene.geometry_bytes() as f64 / stats.triangles as f64;
    let out = json!({
        "mesh": args.mesh,
        "triangles": stats.triangles,
        "bvh_build_seconds": stats.bvh_seconds,
        "scene_build_seconds": build_total,
        "bvh_nodes": stats.bvh_nodes,
        "bytes_per_triangle": bytes_per_triangle,
        "threads": threads,
        "sets": sets,
        "binary_bvh_baseline": baseline,
    });
    if args.json {
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        print_rays_text(&out);
    }
    let worst = sets
        .iter()
        .map(|s| s["agreement"].as_f64().unwrap_or(0.0))
        .fold(1.0, f64::min);
    if worst < 0.9999 {
        bail!(
            "only {:.4}% of hits agree with Embree's (at least 99.99% expected)",
            100.0 * worst
        );
    }
    Ok(())
}

/// The `rays` report as text: the scene, each ray set's rates, the baselines.
fn print_rays_text(out: &serde_json::Value) {
    let f = |v: &serde_json::Value| v.as_f64().unwrap_or(0.0);
    let threads = &out["threads"];
    println!(
        "{}: {} triangles, BVH build {:.3} s ({} nodes), {:.0} bytes/triangle",
        out["mesh"].as_str().unwrap_or(""),
        out["triangles"],
        f(&out["bvh_build_seconds"]),
        out["bvh_nodes"],
        f(&out["bytes_per_triangle"])
    );
    for s in out["sets"].as_array().into_iter().flatten() {
        println!(
            "  {:<8} {:>8} rays: {:>7.2} Mrays/s (1 thread), {:>7.2} in packets of 8, {:>7.2} Mrays/s ({threads} threads), {:.2} Mrays/s (1 thread, with surface interactions), {:.1} nodes/ray, hits agreeing with Embree {:.4}%",
            s["rays"].as_str().unwrap_or(""),
            s["count"],
            f(&s["mrays_per_s_1_thread"]),
            f(&s["mrays_per_s_1_thread_packets"]),
            f(&s["mrays_per_s_all_threads"]),
            f(&s["mrays_per_s_1_thread_with_interaction"]),
            f(&s["nodes_per_ray"]),
            100.0 * f(&s["agreement"])
        );
    }
    let baseline = &out["binary_bvh_baseline"];
    println!(
        "  baseline, 1 thread, triangles only: binary BVH build {:.3} s, primary {:.2} / bounce {:.2} Mrays/s; 4-wide build {:.3} s, {:.2} / {:.2} Mrays/s",
        f(&baseline["binary"]["build_seconds"]),
        f(&baseline["binary"]["primary"]),
        f(&baseline["binary"]["bounce"]),
        f(&baseline["wide"]["build_seconds"]),
        f(&baseline["wide"]["primary"]),
        f(&baseline["wide"]["bounce"]),
    );
    if let Some(o) = baseline.get("obvhs") {
        println!(
            "  obvhs (medium build), 1 thread: build {:.3} s, primary {:.2} / bounce {:.2} Mrays/s, hits agreeing {:.4}% / {:.4}%",
            f(&o["build_seconds"]),
            f(&o["primary"]["mrays_per_s"]),
            f(&o["bounce"]["mrays_per_s"]),
            100.0 * f(&o["primary"]["agreement"]),
            100.0 * f(&o["bounce"]["agreement"]),
        );
    }
}

/// The binary BVH against the 4-wide one on the same triangles and rays, one thread, without
/// the scene around them (closest hit by Möller–Trumbore in a closure): what the wide tree
/// gains by itself.
fn binary_baseline(
    desc: &pathlab_render::desc::SceneDesc,
    primary: &[FileRay],
    bounce: &[FileRay],
    repeat: u32,
) -> serde_json::Value {
    use pathlab_render::accel::{Bvh, Bvh4, BvhParams};
    use pathlab_render::shape::Triangle;
    let triangles: Vec<Triangle> = desc
        .meshes
        .iter()
        .flat_map(|m| {
            m.indices.chunks_exact(3).filter_map(move |t| {
                let p = |k: usize| m.positions.get(t[k] as usize).copied();
                Some(Triangle {
                    p: [p(0)?, p(1)?, p(2)?],
                })
            })
        })
        .collect();
    let bounds: Vec<_> = triangles.iter().map(|t| t.bounds()).collect();
    let hit = |i: u32, r: &mut Ray| match triangles[i as usize].intersect(r) {
        Some(h) => {
            r.t_max = h.t;
            true
        }
        None => false,
    };
    let rate = |rays: &[FileRay], trace: &dyn Fn(&mut Ray) -> bool| {
        let mut best = 0.0f64;
        for _ in 0..repeat.max(1) {
            let start = Instant::now();
            let hits = rays.iter().filter(|r| trace(&mut to_ray(r))).count();
            std::hint::black_box(hits);
            best = best.max(rays.len() as f64 / start.elapsed().as_secs_f64() / 1e6);
        }
        best
    };
    let start = Instant::now();
    let binary = Bvh::build(&bounds, BvhParams::default());
    let binary_build = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let wide = Bvh4::build(&bounds, BvhParams::default());
    let wide_build = start.elapsed().as_secs_f64();
    let trace_binary = |r: &mut Ray| binary.intersect(r, hit).0;
    let trace_wide = |r: &mut Ray| wide.intersect(r, hit).0;
    #[allow(unused_mut)]
    let mut out = json!({
        "binary": {
            "build_seconds": binary_build,
            "primary": rate(primary, &trace_binary),
            "bounce": rate(bounce, &trace_binary),
        },
        "wide": {
            "build_seconds": wide_build,
            "primary": rate(primary, &trace_wide),
            "bounce": rate(bounce, &trace_wide),
        },
    });
    #[cfg(feature = "obvhs")]
    {
        out["obvhs"] = obvhs_baseline(&triangles, primary, bounce, repeat);
    }
    out
}

/// The obvhs crate's compressed wide BVH (its `medium_build` preset, "around the same build
/// time as Embree") on the same triangles and rays, one thread, with its own Möller–Trumbore
/// test: build seconds, Mrays/s and agreement with Embree's hits.
#[cfg(feature = "obvhs")]
fn obvhs_baseline(
    triangles: &[pathlab_render::shape::Triangle],
    primary: &[FileRay],
    bounce: &[FileRay],
    repeat: u32,
) -> serde_json::Value {
    use obvhs::{cwbvh::builder::build_cwbvh_from_tris, ray::RayHit, BvhBuildParams};
    let tris: Vec<obvhs::triangle::Triangle> = triangles
        .iter()
        .map(|t| obvhs::triangle::Triangle {
            v0: t.p[0].into(),
            v1: t.p[1].into(),
            v2: t.p[2].into(),
        })
        .collect();
    let start = Instant::now();
    let bvh = build_cwbvh_from_tris(
        &tris,
        BvhBuildParams::medium_build(),
        &mut std::time::Duration::default(),
    );
    let build_seconds = start.elapsed().as_secs_f64();
    let trace = |r: &FileRay| {
        let ray = obvhs::ray::Ray::new(r.o.into(), r.d.into(), r.t_near, f32::INFINITY);
        let mut hit = RayHit::none();
        if bvh.ray_traverse(ray, &mut hit, |ray, id| {
            tris[bvh.primitive_indices[id] as usize].intersect(ray)
        }) {
            hit.t
        } else {
            f32::INFINITY
        }
    };
    let set = |rays: &[FileRay]| {
        let mut hits = vec![0.0f32; rays.len()];
        let best = timed_into(rays.len(), repeat, || {
            for (r, hit) in rays.iter().zip(hits.iter_mut()) {
                *hit = trace(r);
            }
        });
        json!({
            "mrays_per_s": best,
            "agreement": agreement(rays, &hits) as f64 / rays.len().max(1) as f64,
        })
    };
    json!({
        "build_seconds": build_seconds,
        "primary": set(primary),
        "bounce": set(bounce),
    })
}
