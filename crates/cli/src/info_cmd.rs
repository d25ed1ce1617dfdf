//! `pathlab info`: what a scene contains, without rendering it.

use anyhow::Result;
use clap::Args;
use serde_json::json;

/// Raw command-line arguments of `pathlab info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The scene: a file (.xml Mitsuba 3, .dae the course's COLLADA, .obj, .ply, .gltf, .glb) or
    /// a built-in scene's name (cornell-box).
    pub scene: String,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `pathlab info`.
pub fn run(args: &InfoArgs) -> Result<()> {
    let desc = pathlab_scene::load(&args.scene)?;
    let info = pathlab_scene::info::summarize(&desc);
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
    for w in &info.warnings {
        println!("  warning    {w}");
    }
    Ok(())
}
