//! What a scene contains, for `pathlab info`.

use glam::Vec3;
use pathlab_render::desc::{ProjectorKind, SceneDesc, Visibility};
use std::collections::BTreeMap;

/// A summary of a scene description.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneInfo {
    /// Number of meshes (area lights not counted).
    pub meshes: usize,
    /// Number of triangles over all meshes (area lights not counted).
    pub triangles: usize,
    /// Number of spheres.
    pub spheres: usize,
    /// Number of signed distance grids.
    pub sdf_grids: usize,
    /// Materials by kind (diffuse, mirror, ...).
    pub materials: BTreeMap<String, usize>,
    /// Lights by kind (area meshes, area spheres, point, spot, projector, directional,
    /// environment).
    pub lights: BTreeMap<String, usize>,
    /// Camera position, target, vertical field of view (degrees) and image size.
    pub camera: (Vec3, Vec3, f32, [u32; 2]),
    /// Bounds of all shapes (min, max), or `None` for an empty scene.
    pub bounds: Option<(Vec3, Vec3)>,
    /// The loader's warnings.
    pub warnings: Vec<String>,
}

/// Summarises `desc`.
pub fn summarize(desc: &SceneDesc) -> SceneInfo {
    let mut materials = BTreeMap::new();
    for m in &desc.materials {
        *materials.entry(m.kind().to_string()).or_insert(0) += 1;
    }
    let mut lights = BTreeMap::new();
    let mut add = |k: &str, n: usize| {
        if n > 0 {
            *lights.entry(k.to_string()).or_insert(0) += n;
        }
    };
    // CGL area lights arrive as parallelograms hidden from the camera; emissive meshes they
    // replace are shown to the camera only.
    let is_area_light = |m: &&pathlab_render::desc::MeshDesc| {
        m.emission.is_some() && m.visibility == Visibility::INDIRECT_ONLY
    };
    add(
        "area (parallelogram)",
        desc.meshes.iter().filter(is_area_light).count(),
    );
    add(
        "emissive mesh",
        desc.meshes
            .iter()
            .filter(|m| m.emission.is_some() && m.visibility == Visibility::ALL)
            .count(),
    );
    add(
        "emissive mesh (camera only)",
        desc.meshes
            .iter()
            .filter(|m| m.emission.is_some() && !m.visibility.indirect)
            .count(),
    );
    add(
        "area (sphere)",
        desc.spheres.iter().filter(|s| s.emission.is_some()).count(),
    );
    add("point", desc.point_lights.len());
    add("spot", desc.spot_lights.len());
    // Mitsuba's spot lights load as projectors: an image over the cone (a constant one where
    // the file gives none).
    for p in &desc.projectors {
        let kind = match p.kind {
            ProjectorKind::Spot { .. } => "spot",
            ProjectorKind::Projector { .. } => "projector",
        };
        add(kind, 1);
    }
    add("directional", desc.directional_lights.len());
    match &desc.environment_map {
        Some(m) => add(&format!("environment map ({} x {})", m.width, m.height), 1),
        None => add("environment", desc.environment.is_some() as usize),
    }
    let cam = pathlab_render::camera::Camera::new(&desc.camera, desc.resolution);
    let shapes = || desc.meshes.iter().filter(|m| !is_area_light(m));
    SceneInfo {
        meshes: shapes().count(),
        triangles: shapes().map(|m| m.indices.len() / 3).sum(),
        spheres: desc.spheres.len(),
        sdf_grids: desc.sdf_grids.len(),
        materials,
        lights,
        camera: (
            desc.camera.origin,
            desc.camera.target,
            cam.vertical_fov_degrees(),
            desc.resolution,
        ),
        bounds: desc.bounds(),
        warnings: desc.warnings.clone(),
    }
}
