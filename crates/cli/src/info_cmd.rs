//! `pathlab info`: what a scene contains, without rendering it.

use anyhow::Result;
use clap::Args;
use serde_json::json;

/// Raw command-line arguments of `pathlab info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The scene: a file (.xml Mitsuba 3, .pbrt pbrt-v4, .dae the course's COLLADA, .obj, .ply,
    /// .gltf, .glb) or
    /// a built-in scene's name (cornell-box).
    pub scene: String,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `pathlab info`.
pub fn run(args: &InfoArgs) -> Result<()> {
    let start = std::time::Instant::now();
    let desc = pathlab_scene::load(&args.scene)?;
    let load_seconds = start.elapsed().as_secs_f64();
    let info = pathlab_scene::info::summarize(&desc);
    // The renderer's own form of the scene: what rendering it holds in memory.
    let scene = pathlab_render::scene::Scene::build(&desc)
        .map_err(|e| anyhow::anyhow!("{}: cannot build the scene: {e}", args.scene))?;
    let bytes = scene.geometry_bytes();
    let per_triangle = (info.triangles > 0).then(|| bytes as f64 / info.triangles as f64);
    let build_seconds = scene.stats().bvh_seconds;
    let (origin, target, vfov, [w, h]) = info.camera;
    if args.json {
        let out = json!({
            "scene": args.scene,
            "meshes": info.meshes,
            "triangles": info.triangles,
            "spheres": info.spheres,
            "sdf_grids": info.sdf_grids,
            "materials": info.materials,
            "lights": info.lights,
            "camera": {
                "origin": origin.to_array(),
                "target": target.to_array(),
                "vertical_fov_degrees": vfov,
                "resolution": [w, h],
            },
            "bounds": info.bounds.map(|(lo, hi)| [lo.to_array(), hi.to_array()]),
            "geometry_bytes": bytes,
            "bytes_per_triangle": per_triangle,
            "load_seconds": load_seconds,
            "bvh_build_seconds": build_seconds,
            "warnings": info.warnings,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    let list = |m: &std::collections::BTreeMap<String, usize>| {
        if m.is_empty() {
            "none".to_string()
        } else {
            m.iter()
                .map(|(k, v)| format!("{v} {k}"))
                .collect::<Vec<_>>()
                .join(", ")
        }
    };
    println!("{}", args.scene);
    let grids = match info.sdf_grids {
        0 => String::new(),
        1 => ", 1 SDF grid".to_string(),
        n => format!(", {n} SDF grids"),
    };
    println!(
        "  shapes     {} meshes ({} triangles), {} spheres{grids}",
        info.meshes, info.triangles, info.spheres
    );
    println!("  materials  {}", list(&info.materials));
    println!("  lights     {}", list(&info.lights));
    println!(
        "  camera     at ({:.3}, {:.3}, {:.3}) looking at ({:.3}, {:.3}, {:.3}), vertical fov {vfov:.2}°, {w}x{h}",
        origin.x, origin.y, origin.z, target.x, target.y, target.z
    );
    match info.bounds {
        Some((lo, hi)) => println!(
            "  bounds     ({:.3}, {:.3}, {:.3}) to ({:.3}, {:.3}, {:.3})",
            lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
        ),
        None => println!("  bounds     empty"),
    }
    println!(
        "  memory     {:.1} MiB of geometry and BVH{}; loaded in {load_seconds:.2} s, BVH built in {build_seconds:.2} s",
        bytes as f64 / (1 << 20) as f64,
        per_triangle.map_or(String::new(), |b| format!(" ({b:.0} bytes per triangle)"))
    );
    for w in &info.warnings {
        println!("  warning    {w}");
    }
    Ok(())
}
