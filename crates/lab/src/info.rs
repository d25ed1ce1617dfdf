//! What a scene contains, without rendering it: its shapes, materials, lights, camera and
//! bounds ([`pathlab_scene::info`]), and what building it costs in time and memory. The
//! experiment of `pathlab info`.

use anyhow::{anyhow, Result};
use pathlab_render::film::Film;
use pathlab_scene::info::SceneInfo;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::time::Instant;

/// A scene's contents and costs.
pub struct SceneReport {
    /// The scene as named.
    pub scene: String,
    /// What it contains.
    pub info: SceneInfo,
    /// Bytes of geometry and BVH the renderer holds.
    pub geometry_bytes: usize,
    /// Seconds to load the file.
    pub load_seconds: f64,
    /// Seconds to build the BVH.
    pub build_seconds: f64,
}

impl SceneReport {
    /// Loads and builds the scene `scene` names, and measures it.
    pub fn of(scene: &str) -> Result<SceneReport> {
        let start = Instant::now();
        let desc = pathlab_scene::load(scene)?;
        let load_seconds = start.elapsed().as_secs_f64();
        let info = pathlab_scene::info::summarize(&desc);
        // The renderer's own form of the scene: what rendering it holds in memory.
        let built = pathlab_render::scene::Scene::build(&desc)
            .map_err(|e| anyhow!("{scene}: cannot build the scene: {e}"))?;
        Ok(SceneReport {
            scene: scene.to_string(),
            info,
            geometry_bytes: built.geometry_bytes(),
            load_seconds,
            build_seconds: built.stats().bvh_seconds,
        })
    }

    /// Bytes of geometry and BVH per triangle, for scenes with triangles.
    pub fn bytes_per_triangle(&self) -> Option<f64> {
        let t = self.info.triangles;
        (t > 0).then(|| self.geometry_bytes as f64 / t as f64)
    }

    /// The report as the JSON object of `pathlab info --json`.
    pub fn json(&self) -> Value {
        let info = &self.info;
        let (origin, target, vfov, [w, h]) = info.camera;
        json!({
            "scene": self.scene,
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
            "geometry_bytes": self.geometry_bytes,
            "film_bytes": Film::bytes_for(w, h),
            "bytes_per_triangle": self.bytes_per_triangle(),
            "load_seconds": self.load_seconds,
            "bvh_build_seconds": self.build_seconds,
            "warnings": info.warnings,
        })
    }

    /// The report as lines of text.
    pub fn text(&self) -> String {
        let info = &self.info;
        let (origin, target, vfov, [w, h]) = info.camera;
        let grids = match info.sdf_grids {
            0 => String::new(),
            1 => ", 1 SDF grid".to_string(),
            n => format!(", {n} SDF grids"),
        };
        let bounds = match info.bounds {
            Some((lo, hi)) => format!(
                "({:.3}, {:.3}, {:.3}) to ({:.3}, {:.3}, {:.3})",
                lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
            ),
            None => "empty".to_string(),
        };
        let per_triangle = self
            .bytes_per_triangle()
            .map_or(String::new(), |b| format!(" ({b:.0} bytes per triangle)"));
        let mut lines = vec![
            self.scene.clone(),
            format!(
                "  shapes     {} meshes ({} triangles), {} spheres{grids}",
                info.meshes, info.triangles, info.spheres
            ),
            format!("  materials  {}", counts(&info.materials)),
            format!("  lights     {}", counts(&info.lights)),
            format!(
                "  camera     at ({:.3}, {:.3}, {:.3}) looking at ({:.3}, {:.3}, {:.3}), vertical fov {vfov:.2}°, {w}x{h}",
                origin.x, origin.y, origin.z, target.x, target.y, target.z
            ),
            format!("  bounds     {bounds}"),
            format!(
                "  memory     {:.1} MiB of geometry and BVH{per_triangle}, {:.1} MiB of film at {w}x{h}; loaded in {:.2} s, BVH built in {:.2} s",
                self.geometry_bytes as f64 / (1 << 20) as f64,
                Film::bytes_for(w, h) as f64 / (1 << 20) as f64,
                self.load_seconds,
                self.build_seconds
            ),
        ];
        lines.extend(info.warnings.iter().map(|w| format!("  warning    {w}")));
        lines.join("\n")
    }
}

/// Counts by kind as "2 diffuse, 1 glass", or "none".
fn counts(m: &BTreeMap<String, usize>) -> String {
    if m.is_empty() {
        return "none".to_string();
    }
    let parts: Vec<String> = m.iter().map(|(k, v)| format!("{v} {k}")).collect();
    parts.join(", ")
}
