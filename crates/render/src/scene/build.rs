//! Building a [`Scene`] from its description, in named steps: the materials (and the mesh
//! attributes they read), the meshes flattened into triangles, the spheres, the lights with a
//! position, the SDF grids, the BVH with every array laid out in its leaf order, and last the
//! lights at infinity, which need the scene's bounds.

use super::{permute, PackedPrim, Prim, Scene, SceneError, TriSurface, Voxel, NO_LIGHT};
use crate::accel::{split_box, Bvh8, BvhParams, MAX_PRIMITIVES, TRIS_PER_BLOCK};
use crate::bsdf::Material;
use crate::camera::Camera;
use crate::desc::{Emission, MeshAttribute, MeshDesc, SceneDesc, Visibility};
use crate::envmap::EnvironmentMap;
use crate::geometry::Aabb;
use crate::light::{
    bounding_radius, AreaShape, AreaTexture, AreaTriangle, Light, LightSampler, Projector,
};
use crate::sdf_grid::SdfGrid;
use crate::shape::{Sphere, Triangle};
use crate::texture::{AttributeTable, Tex};
use glam::{Mat3, Vec2, Vec3};
use std::sync::Arc;
use std::time::Instant;

use super::trace::{leaf_blocks, SMALL_SCENE_BLOCKS};
use super::BuildStats;

impl Scene {
    /// Builds the scene: flattens meshes into triangles, builds the BVH, creates the lights.
    pub fn build(desc: &SceneDesc) -> Result<Scene, SceneError> {
        let [w, h] = desc.resolution;
        if w == 0 || h == 0 {
            return Err(SceneError::Invalid(format!("resolution {w}x{h} is empty")));
        }
        let (materials, attribute_names) = materials(desc);
        let check = MaterialCheck(materials.len());
        let mut lights = Lights::new(desc.meshes.len());
        let triangles = Triangles::flatten(desc, &attribute_names, check, &mut lights)?;
        let spheres = Spheres::new(desc, check, &mut lights)?;
        add_positioned_lights(desc, &mut lights);
        let grids = Grids::new(desc, check)?;

        let start = Instant::now();
        let (mut bvh, prims, tri_order) = bvh_in_leaf_order(&triangles, &spheres, &grids)?;
        let triangles = triangles.permuted(&tri_order);
        let bvh_seconds = start.elapsed().as_secs_f64();

        let environment =
            add_lights_at_infinity(desc, bounding_radius(&bvh.bounds()), &mut lights)?;
        let light_sampler = LightSampler::new(&lights.lights, &lights.sampleable, &lights.groups);
        let prim_visibility: Vec<Visibility> = prims
            .iter()
            .map(|p| match *p {
                Prim::Triangle(i) => triangles.visibility[i as usize],
                Prim::Sphere(_) | Prim::Voxel(_) => Visibility::ALL,
            })
            .collect();
        let all_visible = prim_visibility.iter().all(|v| *v == Visibility::ALL);
        let only_triangles = spheres.spheres.is_empty() && grids.voxels.is_empty();
        let leaves = leaf_blocks(&mut bvh, &prims, &triangles.triangles, &prim_visibility);
        let (tri_surface, tri_surfaces, same_surface) =
            surface_table(&triangles.material, &triangles.light, materials.len());
        let emitter_bounds = emitter_bounds(&lights.lights, &bvh.bounds());
        let stats = BuildStats {
            bvh_seconds,
            bvh_nodes: bvh.node_count(),
            triangles: triangles.triangles.len(),
            spheres: spheres.spheres.len(),
            lights: lights.lights.len(),
        };
        Ok(Scene {
            tri_ng: triangles.triangles.iter().map(Triangle::normal).collect(),
            tri_slot: leaves.tri_slot,
            tri_surface,
            tri_surfaces,
            same_surface,
            tri_uv: triangles.uv,
            tri_normals: triangles.normals,
            spheres: spheres.spheres,
            sphere_reads_uv: spheres
                .material
                .iter()
                .zip(&spheres.light)
                .map(|(&m, &l)| {
                    materials[m as usize].reads_textures()
                        || lights
                            .lights
                            .get(l as usize)
                            .is_some_and(Light::reads_texture)
                })
                .collect(),
            sphere_material: spheres.material,
            sphere_light: spheres.light,
            sphere_to_object: spheres.to_object,
            grids: grids.grids,
            grid_material: grids.material,
            voxels: grids.voxels,
            only_triangles,
            attributes: triangles.attributes,
            prims: prims.into_iter().map(PackedPrim::new).collect(),
            all_visible,
            bvh,
            blocks: leaves.blocks,
            block_info: leaves.info,
            block_bounds: leaves.bounds,
            needs_tangents: materials.iter().map(Material::needs_tangents).collect(),
            materials,
            lights: lights.lights,
            light_sampler,
            environment,
            emitter_bounds,
            camera: Camera::new(&desc.camera, desc.resolution).with_filter(desc.filter),
            stats,
        })
    }
}

/// The box around every emitting surface among `lights`, grown on every side by a
/// thousandth of its diagonal and a hundred-thousandth of the scene's (`scene`): far more
/// than the rounding of a ray's slab test, so that a ray the box turns away cannot meet an
/// emitter. None without emitting surfaces.
fn emitter_bounds(lights: &[Light], scene: &Aabb) -> Option<Aabb> {
    let b = lights
        .iter()
        .filter_map(Light::surface_bounds)
        .reduce(Aabb::union)?;
    let pad = 1e-3 * b.extent().length() + 1e-5 * scene.extent().length();
    Some(Aabb {
        min: b.min - Vec3::splat(pad),
        max: b.max + Vec3::splat(pad),
    })
}

/// The materials, and the names of the mesh attributes they read (a material's attribute
/// index is its name's position here).
fn materials(desc: &SceneDesc) -> (Vec<Material>, Vec<String>) {
    let mut attribute_names: Vec<String> = Vec::new();
    let materials = desc
        .materials
        .iter()
        .map(|m| {
            Material::from_desc(m, &mut |name| {
                let i = attribute_names
                    .iter()
                    .position(|n| n == name)
                    .unwrap_or_else(|| {
                        attribute_names.push(name.to_string());
                        attribute_names.len() - 1
                    });
                i as u32
            })
        })
        .collect();
    (materials, attribute_names)
}

/// Checks a shape's material index against the number of materials.
#[derive(Clone, Copy)]
struct MaterialCheck(usize);

impl MaterialCheck {
    fn index(self, shape: &str, index: usize) -> Result<u32, SceneError> {
        if index < self.0 {
            Ok(index as u32)
        } else {
            Err(SceneError::MissingMaterial {
                shape: shape.to_string(),
                index,
                count: self.0,
            })
        }
    }
}

/// The lights as they are made, with whether each is sampled and the emitter it belongs to:
/// emitters are chosen equally, a mesh's triangles (one emitter, numbered by the mesh) in
/// proportion to their power. Every other light is an emitter of its own.
struct Lights {
    lights: Vec<Light>,
    sampleable: Vec<bool>,
    groups: Vec<u32>,
    meshes: u32,
}

impl Lights {
    fn new(meshes: usize) -> Self {
        Lights {
            lights: Vec::new(),
            sampleable: Vec::new(),
            groups: Vec::new(),
            meshes: meshes as u32,
        }
    }

    /// A group no mesh and no other light has.
    fn own_group(&self) -> u32 {
        self.lights.len() as u32 + self.meshes
    }

    /// Adds a light that is sampled and an emitter of its own; returns its index.
    fn push(&mut self, light: Light) -> u32 {
        let group = self.own_group();
        self.lights.push(light);
        self.sampleable.push(true);
        self.groups.push(group);
        (self.lights.len() - 1) as u32
    }

    /// Adds the area light of a shape when it emits, in `group`; returns the light's index or
    /// [`NO_LIGHT`]. Light sampling skips it where indirect rays do not see it.
    fn push_area(
        &mut self,
        group: u32,
        shape: AreaShape,
        emission: Option<Emission>,
        texture: Option<Arc<AreaTexture>>,
        visibility: Visibility,
    ) -> u32 {
        match emission {
            Some(e) if e.radiance.max_element() > 0.0 => {
                self.lights.push(Light::Area {
                    shape,
                    radiance: e.radiance,
                    two_sided: e.two_sided,
                    texture,
                });
                self.sampleable.push(visibility.indirect);
                self.groups.push(group);
                (self.lights.len() - 1) as u32
            }
            _ => NO_LIGHT,
        }
    }
}

/// Each triangle's (material, light) as an index into a table of pairs: entry `m` of the
/// table is material `m` (of `materials`) without a light, and each emitting triangle has an
/// entry of its own. One index per triangle instead of two, and none where every triangle
/// has the same pair (a mesh of one material, not emitting: the index list is then empty
/// and the third value is that one index).
fn surface_table(
    material: &[u32],
    light: &[u32],
    materials: usize,
) -> (Vec<u32>, Vec<TriSurface>, u32) {
    let mut table: Vec<TriSurface> = (0..materials as u32)
        .map(|material| TriSurface {
            material,
            light: NO_LIGHT,
        })
        .collect();
    let index: Vec<u32> = material
        .iter()
        .zip(light)
        .map(|(&material, &light)| {
            if light == NO_LIGHT && (material as usize) < materials {
                material
            } else {
                table.push(TriSurface { material, light });
                table.len() as u32 - 1
            }
        })
        .collect();
    match index.first() {
        Some(&first) if index.iter().all(|&s| s == first) => (Vec::new(), table, first),
        _ => (index, table, 0),
    }
}

/// Every mesh's triangles, with what each carries, in one array per property.
struct Triangles {
    triangles: Vec<Triangle>,
    material: Vec<u32>,
    light: Vec<u32>,
    visibility: Vec<Visibility>,
    /// Vertex texture coordinates (empty when no mesh has any).
    uv: Vec<[Vec2; 3]>,
    /// Vertex normals (empty when no mesh has any).
    normals: Vec<[Vec3; 3]>,
    /// One table per attribute name.
    attributes: Vec<AttributeTable>,
}

/// The texture coordinates of a triangle's corner `k`: the mesh's, else those of the unit
/// triangle's corner.
fn corner_uv(mesh: &MeshDesc, tri: &[u32], k: usize) -> Vec2 {
    mesh.uvs
        .get(tri[k] as usize)
        .copied()
        .unwrap_or([Vec2::ZERO, Vec2::X, Vec2::Y][k])
}

impl Triangles {
    /// Flattens the meshes into triangles (dropping degenerate ones), adding the area light
    /// of each emitting triangle to `lights`.
    fn flatten(
        desc: &SceneDesc,
        attribute_names: &[String],
        check: MaterialCheck,
        lights: &mut Lights,
    ) -> Result<Self, SceneError> {
        let any_normals = desc
            .meshes
            .iter()
            .any(|m| !m.normals.is_empty() && m.normals.len() == m.positions.len());
        let mut out = Triangles {
            triangles: Vec::new(),
            material: Vec::new(),
            light: Vec::new(),
            visibility: Vec::new(),
            uv: Vec::new(),
            normals: Vec::new(),
            attributes: vec![Vec::new(); attribute_names.len()],
        };
        let any_uvs = desc.meshes.iter().any(|m| !m.uvs.is_empty());
        // Whether every triangle's corner normals are its face normal (see below).
        let mut all_flat = true;
        for (mesh_index, mesh) in desc.meshes.iter().enumerate() {
            let material = check.index(&mesh.name, mesh.material)?;
            let mesh_attributes: Vec<Option<&MeshAttribute>> = attribute_names
                .iter()
                .map(|n| mesh.attributes.iter().find(|a| &a.name == n))
                .collect();
            let emission_texture = mesh
                .emission_texture
                .as_ref()
                .map(|t| Tex::new(t, &mut |_| u32::MAX));
            if mesh.indices.len() % 3 != 0 {
                return Err(bad_mesh(
                    mesh,
                    format!("{} indices is not a multiple of 3", mesh.indices.len()),
                ));
            }
            for (face_index, tri) in mesh.indices.chunks_exact(3).enumerate() {
                let mut p = [Vec3::ZERO; 3];
                for (k, &i) in tri.iter().enumerate() {
                    p[k] = *mesh.positions.get(i as usize).ok_or_else(|| {
                        bad_mesh(
                            mesh,
                            format!(
                                "index {i} is out of range ({} vertices)",
                                mesh.positions.len()
                            ),
                        )
                    })?;
                }
                let t = Triangle { p };
                if t.area() <= 0.0 || !t.area().is_finite() {
                    continue; // degenerate: invisible and unsampleable
                }
                out.triangles.push(t);
                if any_uvs {
                    out.uv.push([0, 1, 2].map(|k| corner_uv(mesh, tri, k)));
                }
                if any_normals {
                    let face = t.normal();
                    let corners = corner_normals(mesh, tri, face);
                    all_flat &= is_flat(&corners, face);
                    out.normals.push(corners);
                }
                out.material.push(material);
                out.visibility.push(mesh.visibility);
                for (table, attribute) in out.attributes.iter_mut().zip(&mesh_attributes) {
                    table.push(corner_attributes(*attribute, tri, face_index));
                }
                let texture = emission_texture.as_ref().map(|tex| {
                    Arc::new(AreaTexture {
                        tex: tex.clone(),
                        corner_uvs: [0, 1, 2].map(|k| corner_uv(mesh, tri, k)),
                        to_object: Mat3::IDENTITY,
                    })
                });
                out.light.push(lights.push_area(
                    mesh_index as u32,
                    AreaShape::Triangle(AreaTriangle::new(t)),
                    mesh.emission,
                    texture,
                    mesh.visibility,
                ));
            }
        }
        if all_flat {
            // Flat meshes (such as Mitsuba's rectangles and cubes) shade with their faces'
            // normals: keeping theirs would renormalise the same normal at every hit.
            out.normals = Vec::new();
        }
        Ok(out)
    }

    /// Every array rearranged so that position `i` holds triangle `order[i]`.
    fn permuted(self, order: &[u32]) -> Self {
        Triangles {
            triangles: permute(&self.triangles, order),
            material: permute(&self.material, order),
            light: permute(&self.light, order),
            visibility: permute(&self.visibility, order),
            uv: if self.uv.is_empty() {
                self.uv
            } else {
                permute(&self.uv, order)
            },
            normals: if self.normals.is_empty() {
                self.normals
            } else {
                permute(&self.normals, order)
            },
            attributes: self.attributes.iter().map(|t| permute(t, order)).collect(),
        }
    }
}

fn bad_mesh(mesh: &MeshDesc, message: String) -> SceneError {
    SceneError::BadMesh {
        mesh: mesh.name.clone(),
        message,
    }
}

/// The shading normals at a triangle's corners: the mesh's vertex normals turned to the
/// front (winding) side of the face, else the face normal.
fn corner_normals(mesh: &MeshDesc, tri: &[u32], face: Vec3) -> [Vec3; 3] {
    [0, 1, 2].map(|k| {
        if mesh.normals.len() != mesh.positions.len() {
            return face;
        }
        match mesh.normals[tri[k] as usize].try_normalize() {
            Some(n) if n.dot(face) >= 0.0 => n,
            Some(n) => -n,
            None => face,
        }
    })
}

/// Whether a triangle's corner normals (as [`corner_normals`] gives them) are its face normal
/// `face` but for rounding: every component within 10⁻⁶, an angle of at most about 10⁻⁶
/// radians, far below what shading can show.
fn is_flat(corners: &[Vec3; 3], face: Vec3) -> bool {
    corners
        .iter()
        .all(|&n| (n - face).abs().max_element() <= 1e-6)
}

/// An attribute's values at a triangle's corners (per face or per vertex; zero where the
/// mesh lacks the attribute or a value).
fn corner_attributes(attribute: Option<&MeshAttribute>, tri: &[u32], face: usize) -> [Vec3; 3] {
    [0, 1, 2].map(|k| {
        let Some(a) = attribute else {
            return Vec3::ZERO;
        };
        let i = if a.per_face { face } else { tri[k] as usize };
        a.values.get(i).copied().unwrap_or(Vec3::ZERO)
    })
}

/// The spheres, with the area light of each emitting one added to `lights`.
struct Spheres {
    spheres: Vec<Sphere>,
    material: Vec<u32>,
    light: Vec<u32>,
    to_object: Vec<Mat3>,
}

impl Spheres {
    fn new(
        desc: &SceneDesc,
        check: MaterialCheck,
        lights: &mut Lights,
    ) -> Result<Self, SceneError> {
        let mut out = Spheres {
            spheres: Vec::new(),
            material: Vec::new(),
            light: Vec::new(),
            to_object: Vec::new(),
        };
        for (i, s) in desc.spheres.iter().enumerate() {
            let material = check.index(&format!("sphere {i}"), s.material)?;
            if !(s.radius > 0.0 && s.radius.is_finite() && s.center.is_finite()) {
                return Err(SceneError::Invalid(format!(
                    "sphere {i}: radius must be positive and finite, got {}",
                    s.radius
                )));
            }
            let sphere = Sphere {
                center: s.center,
                radius: s.radius,
            };
            out.spheres.push(sphere);
            out.material.push(material);
            out.to_object.push(s.to_object);
            let texture = s.emission_texture.as_ref().map(|t| {
                Arc::new(AreaTexture {
                    tex: Tex::from_desc(t),
                    corner_uvs: [Vec2::ZERO; 3],
                    to_object: s.to_object,
                })
            });
            let group = lights.own_group();
            out.light.push(lights.push_area(
                group,
                AreaShape::Sphere(sphere),
                s.emission,
                texture,
                Visibility::ALL,
            ));
        }
        Ok(out)
    }
}

/// Adds the point lights, projectors and spot lights.
fn add_positioned_lights(desc: &SceneDesc, lights: &mut Lights) {
    for pl in &desc.point_lights {
        lights.push(Light::Point {
            position: pl.position,
            intensity: pl.intensity,
            attenuation: pl.attenuation,
        });
    }
    for pr in &desc.projectors {
        lights.push(Light::Projector(Arc::new(Projector {
            position: pr.position,
            to_local: pr.frame.transpose(),
            texture: Tex::from_desc(&pr.texture),
            kind: pr.kind,
        })));
    }
    for sl in &desc.spot_lights {
        lights.push(Light::Spot {
            position: sl.position,
            direction: sl.direction.normalize_or(Vec3::NEG_Y),
            intensity: sl.intensity,
            cos_cutoff: sl.cutoff_degrees.to_radians().cos(),
            exponent: sl.exponent.max(0.0),
            attenuation: sl.attenuation,
        });
    }
}

/// The SDF grids, and the voxels their surfaces pass through (the BVH's primitives).
struct Grids {
    grids: Vec<SdfGrid>,
    material: Vec<u32>,
    voxels: Vec<Voxel>,
    voxel_bounds: Vec<Aabb>,
}

impl Grids {
    fn new(desc: &SceneDesc, check: MaterialCheck) -> Result<Self, SceneError> {
        let mut out = Grids {
            grids: Vec::new(),
            material: Vec::new(),
            voxels: Vec::new(),
            voxel_bounds: Vec::new(),
        };
        for (i, g) in desc.sdf_grids.iter().enumerate() {
            out.material
                .push(check.index(&format!("SDF grid {i}"), g.material)?);
            let grid =
                SdfGrid::new(g).map_err(|e| SceneError::Invalid(format!("SDF grid {i}: {e}")))?;
            for (corner, b) in grid.occupied_voxels(&g.to_world) {
                out.voxels.push(Voxel {
                    grid: i as u32,
                    corner,
                });
                out.voxel_bounds.push(b);
            }
            out.grids.push(grid);
        }
        Ok(out)
    }
}

/// Builds the BVH over every primitive. Returns it, the primitives in its leaf order (a
/// triangle numbered by its new position), and the order to lay the triangles out in, so that
/// a leaf's triangles are neighbours in memory (one cache miss per leaf rather than one per
/// triangle).
fn bvh_in_leaf_order(
    triangles: &Triangles,
    spheres: &Spheres,
    grids: &Grids,
) -> Result<(Bvh8, Vec<Prim>, Vec<u32>), SceneError> {
    let triangles = &triangles.triangles;
    let prims: Vec<Prim> = (0..triangles.len() as u32)
        .map(Prim::Triangle)
        .chain((0..spheres.spheres.len() as u32).map(Prim::Sphere))
        .chain((0..grids.voxels.len() as u32).map(Prim::Voxel))
        .collect();
    if prims.len() > MAX_PRIMITIVES {
        return Err(SceneError::Invalid(format!(
            "{} primitives: at most {MAX_PRIMITIVES} fit the BVH",
            prims.len()
        )));
    }
    let bounds: Vec<Aabb> = prims
        .iter()
        .map(|p| match *p {
            Prim::Triangle(i) => triangles[i as usize].bounds(),
            Prim::Sphere(i) => spheres.spheres[i as usize].bounds(),
            Prim::Voxel(i) => grids.voxel_bounds[i as usize],
        })
        .collect();
    let params = BvhParams {
        leaf_block: TRIS_PER_BLOCK,
        // Measured against 1.0: 0.25 keeps the walls of a room in separate leaves (the
        // Cornell box renders 12-17% faster); the blobs and maxplanck trace as fast as
        // before, a soup of random triangles (smaller leaves) about 15% slower.
        leaf_split_cost: 0.25,
        ..BvhParams::default()
    };
    // Spatial splits cut large triangles into the boxes of their parts; scenes small enough
    // to test every primitive at once ([`Scene::nearest_of_rays`]) keep one reference each.
    let split = |prim: u32, bounds: &Aabb, axis: usize, pos: f32| match prims[prim as usize] {
        Prim::Triangle(i) => triangles[i as usize].split_bounds(bounds, axis, pos),
        Prim::Sphere(_) | Prim::Voxel(_) => split_box(prim, bounds, axis, pos),
    };
    let mut bvh = if prims.len() > SMALL_SCENE_BLOCKS * TRIS_PER_BLOCK {
        Bvh8::build_with_splits(&bounds, params, &split)
    } else {
        Bvh8::build(&bounds, params)
    };
    let order = bvh.take_leaf_order();
    // Triangles are numbered by their first leaf slot; a triangle that spatial splits put in
    // several leaves keeps that one number.
    let mut renamed = vec![u32::MAX; triangles.len()];
    let mut tri_order: Vec<u32> = Vec::with_capacity(triangles.len());
    let prims: Vec<Prim> = order
        .iter()
        .map(|&p| match prims[p as usize] {
            Prim::Triangle(t) => {
                if renamed[t as usize] == u32::MAX {
                    renamed[t as usize] = tri_order.len() as u32;
                    tri_order.push(t);
                }
                Prim::Triangle(renamed[t as usize])
            }
            shape => shape,
        })
        .collect();
    // Triangles the BVH left out (non-finite boxes) keep their data, unreachable.
    tri_order.extend((0..triangles.len() as u32).filter(|&t| renamed[t as usize] == u32::MAX));
    Ok((bvh, prims, tri_order))
}

/// Adds the directional lights and the environment, which reach the scene from beyond its
/// bounding sphere of radius `scene_radius`; returns the environment's light index.
fn add_lights_at_infinity(
    desc: &SceneDesc,
    scene_radius: f32,
    lights: &mut Lights,
) -> Result<Option<u32>, SceneError> {
    for dl in &desc.directional_lights {
        lights.push(Light::Directional {
            direction: dl.direction.normalize_or(Vec3::NEG_Y),
            irradiance: dl.irradiance,
            scene_radius,
        });
    }
    let environment = match &desc.environment_map {
        Some(m) => Some(Light::EnvironmentMap {
            map: Arc::new(
                EnvironmentMap::new(m.texels.to_vec(), m.width, m.height, m.to_world, m.scale)
                    .map_err(|e| SceneError::Invalid(format!("{}: {e}", m.source)))?,
            ),
            scene_radius,
        }),
        None => desc
            .environment
            .filter(|e| e.max_element() > 0.0)
            .map(|radiance| Light::Environment {
                radiance,
                scene_radius,
            }),
    };
    Ok(environment.map(|light| lights.push(light)))
}
