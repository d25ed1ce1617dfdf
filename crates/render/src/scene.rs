//! The renderable scene: flattened shapes, the BVH over them, materials, lights and camera.

use crate::accel::{Bvh8, BvhParams, TriBlock, MAX_PRIMITIVES, TRIS_PER_BLOCK};
use crate::bsdf::{Material, ShadingPoint};
use crate::camera::Camera;
use crate::desc::{Emission, MaterialDesc, Rgb, SceneDesc, Visibility};
use crate::envmap::EnvironmentMap;
use crate::geometry::{Aabb, Ray};
use crate::light::{
    bounding_radius, sphere_uv, AreaShape, AreaTexture, AreaTriangle, Light, LightSampler,
    Projector,
};
use crate::sdf_grid::SdfGrid;
use crate::shape::{Sphere, Triangle};
use crate::texture::{AttributeTable, Tex, TexPoint};
use glam::{Mat3, Vec2, Vec3};
use std::sync::Arc;
use std::time::Instant;
use thiserror::Error;

mod trace;

use trace::{leaf_blocks, BlockInfo};

/// Marks a shape that emits no light.
const NO_LIGHT: u32 = u32::MAX;

/// What can be wrong with a scene description.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SceneError {
    /// A shape names a material that does not exist.
    #[error("{shape}: material index {index} does not exist ({count} materials)")]
    MissingMaterial {
        /// Which shape.
        shape: String,
        /// The index it names.
        index: usize,
        /// How many materials there are.
        count: usize,
    },
    /// A mesh's index list is malformed.
    #[error("mesh '{mesh}': {message}")]
    BadMesh {
        /// Which mesh.
        mesh: String,
        /// What is wrong.
        message: String,
    },
    /// A value is out of range.
    #[error("{0}")]
    Invalid(String),
}

/// A primitive of the BVH.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Prim {
    Triangle(u32),
    Sphere(u32),
    /// A voxel of an SDF grid that the surface passes through.
    Voxel(u32),
}

/// A voxel of an SDF grid: which grid, and the voxel's lower corner in its samples.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Voxel {
    grid: u32,
    corner: [u32; 3],
}

/// `items` rearranged so that position `i` holds `items[order[i]]`.
fn permute<T: Copy>(items: &[T], order: &[u32]) -> Vec<T> {
    order.iter().map(|&i| items[i as usize]).collect()
}

/// A ray's nearest hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceInteraction {
    /// The point.
    pub p: Vec3,
    /// Ray parameter.
    pub t: f32,
    /// Unit geometric normal on the shape's front side (winding or outward).
    pub ng: Vec3,
    /// Unit shading normal.
    pub ns: Vec3,
    /// Material index.
    pub material: u32,
    /// Index of the light the surface belongs to, if it emits.
    pub light: Option<u32>,
    /// Texture coordinates (the mesh's, else barycentric; spherical on spheres).
    pub uv: Vec2,
    /// The triangle hit, in the scene's order (`u32::MAX` on a sphere or an SDF grid), for
    /// mesh attributes.
    pub prim: u32,
    /// Barycentrics of the triangle's vertices 1 and 2.
    pub b: Vec2,
}

/// Build statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BuildStats {
    /// Seconds spent building the BVH.
    pub bvh_seconds: f64,
    /// Nodes of the BVH.
    pub bvh_nodes: usize,
    /// Triangles.
    pub triangles: usize,
    /// Spheres.
    pub spheres: usize,
    /// Lights.
    pub lights: usize,
}

/// A scene ready to render.
#[derive(Clone, Debug)]
pub struct Scene {
    triangles: Vec<Triangle>,
    /// Unit geometric normal of each triangle (its winding's side), computed once.
    tri_ng: Vec<Vec3>,
    tri_material: Vec<u32>,
    tri_light: Vec<u32>,
    /// Per-triangle vertex texture coordinates (empty when no mesh has any).
    tri_uv: Vec<[Vec2; 3]>,
    /// Per-triangle vertex normals for smooth shading (empty when no mesh has any; a mesh
    /// without them gets its face normal at each corner).
    tri_normals: Vec<[Vec3; 3]>,
    spheres: Vec<Sphere>,
    sphere_material: Vec<u32>,
    sphere_light: Vec<u32>,
    /// Each sphere's rotation from world to its own frame (for its texture coordinates).
    sphere_to_object: Vec<Mat3>,
    grids: Vec<SdfGrid>,
    grid_material: Vec<u32>,
    voxels: Vec<Voxel>,
    /// Whether every primitive is a triangle (no spheres or SDF grids).
    only_triangles: bool,
    /// Mesh attributes read by textures, per triangle corner.
    attributes: Vec<AttributeTable>,
    prims: Vec<Prim>,
    /// Whether every primitive is seen by every ray (the common case, checked once).
    all_visible: bool,
    /// The BVH, whose leaves name ranges of `blocks`.
    bvh: Bvh8,
    /// The primitives of the BVH's leaves, four to a block, in leaf order.
    blocks: Vec<TriBlock>,
    block_info: Vec<BlockInfo>,
    materials: Vec<Material>,
    /// Whether each material needs the surface's tangents.
    needs_tangents: Vec<bool>,
    lights: Vec<Light>,
    light_sampler: LightSampler,
    environment: Option<u32>,
    camera: Camera,
    stats: BuildStats,
}

impl Scene {
    /// Builds the scene: flattens meshes into triangles, builds the BVH, creates the lights.
    pub fn build(desc: &SceneDesc) -> Result<Scene, SceneError> {
        let [w, h] = desc.resolution;
        if w == 0 || h == 0 {
            return Err(SceneError::Invalid(format!("resolution {w}x{h} is empty")));
        }
        // Mesh attributes the materials read: one table each, filled per triangle below.
        let mut attribute_names: Vec<String> = Vec::new();
        let materials: Vec<Material> = desc
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
        let mut attributes: Vec<AttributeTable> = vec![Vec::new(); attribute_names.len()];
        let check_material = |shape: &str, index: usize| {
            if index < materials.len() {
                Ok(index as u32)
            } else {
                Err(SceneError::MissingMaterial {
                    shape: shape.to_string(),
                    index,
                    count: materials.len(),
                })
            }
        };
        let mut triangles = Vec::new();
        let mut tri_material = Vec::new();
        let mut tri_light = Vec::new();
        let mut tri_visibility = Vec::new();
        let mut tri_uv = Vec::new();
        let any_uvs = desc.meshes.iter().any(|m| !m.uvs.is_empty());
        let mut tri_normals = Vec::new();
        let any_normals = desc
            .meshes
            .iter()
            .any(|m| !m.normals.is_empty() && m.normals.len() == m.positions.len());
        let mut lights = Vec::new();
        let mut sampleable = Vec::new();
        // The emitter each light belongs to (a mesh's triangles share one): emitters are chosen
        // equally, a mesh's triangles in proportion to their power.
        let mut light_group: Vec<u32> = Vec::new();
        for (mesh_index, mesh) in desc.meshes.iter().enumerate() {
            let material = check_material(&mesh.name, mesh.material)?;
            let mesh_attributes: Vec<Option<&crate::desc::MeshAttribute>> = attribute_names
                .iter()
                .map(|n| mesh.attributes.iter().find(|a| &a.name == n))
                .collect();
            let emission_texture = mesh
                .emission_texture
                .as_ref()
                .map(|t| Tex::new(t, &mut |_| u32::MAX));
            if mesh.indices.len() % 3 != 0 {
                return Err(SceneError::BadMesh {
                    mesh: mesh.name.clone(),
                    message: format!("{} indices is not a multiple of 3", mesh.indices.len()),
                });
            }
            for (face_index, tri) in mesh.indices.chunks_exact(3).enumerate() {
                let mut p = [Vec3::ZERO; 3];
                for (k, &i) in tri.iter().enumerate() {
                    p[k] = *mesh
                        .positions
                        .get(i as usize)
                        .ok_or_else(|| SceneError::BadMesh {
                            mesh: mesh.name.clone(),
                            message: format!(
                                "index {i} is out of range ({} vertices)",
                                mesh.positions.len()
                            ),
                        })?;
                }
                let t = Triangle { p };
                if t.area() <= 0.0 || !t.area().is_finite() {
                    continue; // degenerate: invisible and unsampleable
                }
                triangles.push(t);
                if any_uvs {
                    let uv = |k: usize| {
                        mesh.uvs
                            .get(tri[k] as usize)
                            .copied()
                            .unwrap_or([Vec2::ZERO, Vec2::X, Vec2::Y][k])
                    };
                    tri_uv.push([uv(0), uv(1), uv(2)]);
                }
                if any_normals {
                    let face = t.normal();
                    let normal = |k: usize| {
                        if mesh.normals.len() != mesh.positions.len() {
                            return face;
                        }
                        let n = mesh.normals[tri[k] as usize];
                        // Shading normals stay on the front (winding) side of the face.
                        match n.try_normalize() {
                            Some(n) if n.dot(face) >= 0.0 => n,
                            Some(n) => -n,
                            None => face,
                        }
                    };
                    tri_normals.push([normal(0), normal(1), normal(2)]);
                }
                tri_material.push(material);
                tri_visibility.push(mesh.visibility);
                for (table, attribute) in attributes.iter_mut().zip(&mesh_attributes) {
                    let corner = |k: usize| -> Vec3 {
                        let Some(a) = attribute else {
                            return Vec3::ZERO;
                        };
                        let i = if a.per_face {
                            face_index
                        } else {
                            tri[k] as usize
                        };
                        a.values.get(i).copied().unwrap_or(Vec3::ZERO)
                    };
                    table.push([corner(0), corner(1), corner(2)]);
                }
                let texture = emission_texture.as_ref().map(|tex| {
                    let uv = |k: usize| {
                        mesh.uvs
                            .get(tri[k] as usize)
                            .copied()
                            .unwrap_or([Vec2::ZERO, Vec2::X, Vec2::Y][k])
                    };
                    Arc::new(AreaTexture {
                        tex: tex.clone(),
                        corner_uvs: [uv(0), uv(1), uv(2)],
                        to_object: Mat3::IDENTITY,
                    })
                });
                tri_light.push(add_area_light(
                    &mut lights,
                    &mut sampleable,
                    (&mut light_group, mesh_index as u32),
                    AreaShape::Triangle(AreaTriangle::new(t)),
                    mesh.emission,
                    texture,
                    mesh.visibility,
                ));
            }
        }
        let mut spheres = Vec::new();
        let mut sphere_material = Vec::new();
        let mut sphere_light = Vec::new();
        let mut sphere_to_object = Vec::new();
        for (i, s) in desc.spheres.iter().enumerate() {
            let material = check_material(&format!("sphere {i}"), s.material)?;
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
            spheres.push(sphere);
            sphere_material.push(material);
            sphere_to_object.push(s.to_object);
            let texture = s.emission_texture.as_ref().map(|t| {
                Arc::new(AreaTexture {
                    tex: Tex::from_desc(t),
                    corner_uvs: [Vec2::ZERO; 3],
                    to_object: s.to_object,
                })
            });
            let group = lights.len() as u32 + desc.meshes.len() as u32;
            sphere_light.push(add_area_light(
                &mut lights,
                &mut sampleable,
                (&mut light_group, group),
                AreaShape::Sphere(sphere),
                s.emission,
                texture,
                Visibility::ALL,
            ));
        }
        for pl in &desc.point_lights {
            lights.push(Light::Point {
                position: pl.position,
                intensity: pl.intensity,
                attenuation: pl.attenuation,
            });
            sampleable.push(true);
            light_group.push(lights.len() as u32 + desc.meshes.len() as u32);
        }
        for pr in &desc.projectors {
            lights.push(Light::Projector(Arc::new(Projector {
                position: pr.position,
                to_local: pr.frame.transpose(),
                texture: Tex::from_desc(&pr.texture),
                kind: pr.kind,
            })));
            sampleable.push(true);
            light_group.push(lights.len() as u32 + desc.meshes.len() as u32);
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
            sampleable.push(true);
            light_group.push(lights.len() as u32 + desc.meshes.len() as u32);
        }
        let mut grids = Vec::new();
        let mut grid_material = Vec::new();
        let mut voxels = Vec::new();
        let mut voxel_bounds = Vec::new();
        for (i, g) in desc.sdf_grids.iter().enumerate() {
            grid_material.push(check_material(&format!("SDF grid {i}"), g.material)?);
            let grid =
                SdfGrid::new(g).map_err(|e| SceneError::Invalid(format!("SDF grid {i}: {e}")))?;
            for (corner, b) in grid.occupied_voxels(&g.to_world) {
                voxels.push(Voxel {
                    grid: i as u32,
                    corner,
                });
                voxel_bounds.push(b);
            }
            grids.push(grid);
        }
        let prims: Vec<Prim> = (0..triangles.len() as u32)
            .map(Prim::Triangle)
            .chain((0..spheres.len() as u32).map(Prim::Sphere))
            .chain((0..voxels.len() as u32).map(Prim::Voxel))
            .collect();
        let bounds: Vec<Aabb> = prims
            .iter()
            .map(|p| match *p {
                Prim::Triangle(i) => triangles[i as usize].bounds(),
                Prim::Sphere(i) => spheres[i as usize].bounds(),
                Prim::Voxel(i) => voxel_bounds[i as usize],
            })
            .collect();
        if prims.len() > MAX_PRIMITIVES {
            return Err(SceneError::Invalid(format!(
                "{} primitives: at most {MAX_PRIMITIVES} fit the BVH",
                prims.len()
            )));
        }
        let start = Instant::now();
        let mut bvh = Bvh8::build(
            &bounds,
            BvhParams {
                leaf_block: TRIS_PER_BLOCK,
                // Measured against 1.0: 0.25 keeps the walls of a room in separate leaves (the
                // Cornell box renders 12-17% faster); the blobs and maxplanck trace as fast as
                // before, a soup of random triangles (smaller leaves) about 15% slower.
                leaf_split_cost: 0.25,
                ..BvhParams::default()
            },
        );
        // Lay primitives and triangles out in leaf order, so that a leaf's triangles are
        // neighbours in memory (one cache miss per leaf rather than one per triangle).
        let order = bvh.take_leaf_order();
        let mut tri_order: Vec<u32> = Vec::with_capacity(triangles.len());
        let prims: Vec<Prim> = order
            .iter()
            .map(|&p| match prims[p as usize] {
                Prim::Triangle(t) => {
                    tri_order.push(t);
                    Prim::Triangle(tri_order.len() as u32 - 1)
                }
                shape => shape,
            })
            .collect();
        if tri_order.len() < triangles.len() {
            // Triangles the BVH left out (non-finite boxes) keep their data, unreachable.
            let mut seen = vec![false; triangles.len()];
            for &t in &tri_order {
                seen[t as usize] = true;
            }
            tri_order.extend((0..triangles.len() as u32).filter(|&t| !seen[t as usize]));
        }
        let triangles = permute(&triangles, &tri_order);
        let tri_ng: Vec<Vec3> = triangles.iter().map(Triangle::normal).collect();
        let tri_material = permute(&tri_material, &tri_order);
        let tri_light = permute(&tri_light, &tri_order);
        let tri_visibility = permute(&tri_visibility, &tri_order);
        let tri_uv = if tri_uv.is_empty() {
            tri_uv
        } else {
            permute(&tri_uv, &tri_order)
        };
        let tri_normals = if tri_normals.is_empty() {
            tri_normals
        } else {
            permute(&tri_normals, &tri_order)
        };
        let attributes: Vec<AttributeTable> =
            attributes.iter().map(|t| permute(t, &tri_order)).collect();
        let bvh_seconds = start.elapsed().as_secs_f64();
        let scene_radius = bounding_radius(&bvh.bounds());
        for dl in &desc.directional_lights {
            lights.push(Light::Directional {
                direction: dl.direction.normalize_or(Vec3::NEG_Y),
                irradiance: dl.irradiance,
                scene_radius,
            });
            sampleable.push(true);
            light_group.push(lights.len() as u32 + desc.meshes.len() as u32);
        }
        let environment_light = match &desc.environment_map {
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
        let environment = environment_light.map(|light| {
            lights.push(light);
            sampleable.push(true);
            light_group.push(lights.len() as u32 + desc.meshes.len() as u32);
            (lights.len() - 1) as u32
        });
        let light_sampler = LightSampler::new(&lights, &sampleable, &light_group);
        let prim_visibility: Vec<Visibility> = prims
            .iter()
            .map(|p| match *p {
                Prim::Triangle(i) => tri_visibility[i as usize],
                Prim::Sphere(_) | Prim::Voxel(_) => Visibility::ALL,
            })
            .collect();
        let all_visible = prim_visibility.iter().all(|v| *v == Visibility::ALL);
        let only_triangles = spheres.is_empty() && voxels.is_empty();
        let (blocks, block_info) = leaf_blocks(&mut bvh, &prims, &triangles, &prim_visibility);
        let stats = BuildStats {
            bvh_seconds,
            bvh_nodes: bvh.node_count(),
            triangles: triangles.len(),
            spheres: spheres.len(),
            lights: lights.len(),
        };
        Ok(Scene {
            triangles,
            tri_ng,
            tri_material,
            tri_light,
            tri_uv,
            tri_normals,
            spheres,
            sphere_material,
            sphere_light,
            sphere_to_object,
            grids,
            grid_material,
            voxels,
            only_triangles,
            attributes,
            prims,
            all_visible,
            bvh,
            blocks,
            block_info,
            needs_tangents: materials.iter().map(Material::needs_tangents).collect(),
            materials,
            lights,
            light_sampler,
            environment,
            camera: Camera::new(&desc.camera, desc.resolution).with_filter(desc.filter),
            stats,
        })
    }

    /// The camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Build statistics.
    pub fn stats(&self) -> BuildStats {
        self.stats
    }

    /// Bounds of all shapes.
    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    /// Bytes held by the geometry and the acceleration structure (shapes, per-primitive tables,
    /// BVH), for memory reports.
    pub fn geometry_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(self.triangles.as_slice())
            + size_of_val(self.tri_ng.as_slice())
            + size_of_val(self.tri_material.as_slice())
            + size_of_val(self.tri_light.as_slice())
            + size_of_val(self.tri_uv.as_slice())
            + size_of_val(self.tri_normals.as_slice())
            + size_of_val(self.spheres.as_slice())
            + size_of_val(self.sphere_material.as_slice())
            + size_of_val(self.sphere_light.as_slice())
            + size_of_val(self.sphere_to_object.as_slice())
            + size_of_val(self.voxels.as_slice())
            + self
                .attributes
                .iter()
                .map(|t| size_of_val(t.as_slice()))
                .sum::<usize>()
            + size_of_val(self.prims.as_slice())
            + size_of_val(self.blocks.as_slice())
            + size_of_val(self.block_info.as_slice())
            + self.bvh.memory_bytes()
    }

    /// The BSDF at a surface point seen from `wo`.
    #[inline]
    pub fn bsdf(&self, si: &SurfaceInteraction, wo: Vec3) -> crate::bsdf::Bsdf {
        let m = &self.materials[si.material as usize];
        let (dpdu, dpdv) = if self.needs_tangents[si.material as usize] {
            self.tangents(si)
        } else {
            (Vec3::ZERO, Vec3::ZERO)
        };
        m.bsdf(
            &ShadingPoint {
                n: si.ns,
                dpdu,
                dpdv,
                ng: si.ng,
                tex: self.tex_point(si),
            },
            wo,
        )
    }

    /// ∂p/∂u and ∂p/∂v at `si` (pathlab's (u, v)): from a triangle's texture coordinates
    /// (an arbitrary pair around the normal when they are degenerate), or a sphere's angles.
    pub fn tangents(&self, si: &SurfaceInteraction) -> (Vec3, Vec3) {
        let fallback = || {
            let (s, t) = pathlab_mc::warp::coordinate_system(si.ns);
            (s, t)
        };
        if si.prim == u32::MAX {
            // A sphere: find it by the point's distance from each centre (spheres are few).
            let Some(i) = self
                .spheres
                .iter()
                .position(|s| ((si.p - s.center).length() - s.radius).abs() <= 1e-3 * s.radius)
            else {
                return fallback();
            };
            let (s, to_object) = (&self.spheres[i], self.sphere_to_object[i]);
            let d = to_object * si.ng;
            let r = s.radius;
            let phi = d.y.atan2(d.x);
            let sin_theta = (1.0 - d.z * d.z).max(0.0).sqrt();
            let tau = std::f32::consts::TAU;
            let dpdu = Vec3::new(-d.y, d.x, 0.0) * (tau * r);
            // Mitsuba's v = θ/π grows downwards from the pole; pathlab's v is 1 - that.
            let dpdv = Vec3::new(d.z * phi.cos(), d.z * phi.sin(), -sin_theta)
                * (-std::f32::consts::PI * r);
            let to_world = to_object.transpose();
            return (to_world * dpdu, to_world * dpdv);
        }
        let i = si.prim as usize;
        let p = self.triangles[i].p;
        let uv = self
            .tri_uv
            .get(i)
            .copied()
            .unwrap_or([Vec2::ZERO, Vec2::X, Vec2::Y]);
        let (dp0, dp1) = (p[1] - p[0], p[2] - p[0]);
        let (duv0, duv1) = (uv[1] - uv[0], uv[2] - uv[0]);
        let det = duv0.x * duv1.y - duv0.y * duv1.x;
        if det.abs() < 1e-12 {
            return fallback();
        }
        let inv = 1.0 / det;
        (
            (dp0 * duv1.y - dp1 * duv0.y) * inv,
            (dp1 * duv0.x - dp0 * duv1.x) * inv,
        )
    }

    /// Where textures are evaluated at `si`.
    #[inline]
    pub fn tex_point<'a>(&'a self, si: &SurfaceInteraction) -> TexPoint<'a> {
        TexPoint {
            uv: si.uv,
            triangle: (si.prim != u32::MAX).then_some((si.prim, si.b)),
            attributes: &self.attributes,
        }
    }

    /// Material `i`.
    #[inline]
    pub fn material(&self, i: u32) -> &Material {
        &self.materials[i as usize]
    }

    /// All lights.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// The power-proportional light chooser.
    pub fn light_sampler(&self) -> &LightSampler {
        &self.light_sampler
    }

    /// The environment light's index, if there is one.
    pub fn environment(&self) -> Option<u32> {
        self.environment
    }

    /// Radiance from the environment along direction `w` (zero without one).
    #[inline]
    pub fn environment_le(&self, w: Vec3) -> Rgb {
        self.environment
            .map_or(Rgb::ZERO, |i| self.lights[i as usize].le_environment(w))
    }

    /// The nearest surface along a camera ray, and the number of BVH nodes visited.
    #[inline]
    pub fn intersect_camera(&self, ray: &Ray) -> (Option<SurfaceInteraction>, u32) {
        self.intersect_as(ray, true)
    }

    /// The nearest surface along any other ray, and the number of BVH nodes visited.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> (Option<SurfaceInteraction>, u32) {
        self.intersect_as(ray, false)
    }

    /// The distance to the nearest surface along a non-camera ray, without making its surface
    /// interaction: the query a ray-tracing kernel answers (`rtcIntersect1`), for measuring
    /// traversal alone.
    pub fn hit_distance(&self, ray: &Ray) -> Option<f32> {
        let mut r = *ray;
        self.closest_hit(&mut r, false).found().then_some(r.t_max)
    }

    #[inline(always)]
    fn intersect_as(&self, ray: &Ray, camera: bool) -> (Option<SurfaceInteraction>, u32) {
        let mut si = None;
        let visited = self.intersect_into(ray, camera, &mut si);
        (si, visited)
    }

    /// The nearest surface along a camera ray (`camera`) or another ray, written to `si`
    /// (`None` where the ray escapes); returns the number of BVH nodes visited. Made in place,
    /// for callers that keep it in an array: moving a fresh interaction there would copy it
    /// with wide loads of its narrow stores, which wait for them.
    #[inline(always)]
    pub fn intersect_into(
        &self,
        ray: &Ray,
        camera: bool,
        si: &mut Option<SurfaceInteraction>,
    ) -> u32 {
        let mut r = *ray;
        let hit = self.closest_hit(&mut r, camera);
        if !hit.found() {
            *si = None;
            return hit.visited();
        }
        let (b1, b2) = hit.barycentrics();
        self.interaction_into(ray, hit.slot(), r.t_max, b1, b2, si);
        hit.visited()
    }

    /// Writes to `si` the surface interaction where `ray` meets the primitive in leaf slot
    /// `slot` at distance `t` (barycentrics `b1`, `b2` for a triangle).
    #[inline(always)]
    pub(crate) fn interaction_into(
        &self,
        ray: &Ray,
        slot: u32,
        t: f32,
        b1: f32,
        b2: f32,
        si: &mut Option<SurfaceInteraction>,
    ) {
        match self.prims[slot as usize] {
            Prim::Triangle(i) => *si = Some(self.triangle_interaction(i, b1, b2, t)),
            Prim::Sphere(i) => *si = Some(self.sphere_interaction(i, ray, t)),
            Prim::Voxel(i) => *si = Some(self.voxel_interaction(i, ray, t)),
        }
    }

    /// The surface interaction at barycentrics (b1, b2) of triangle `i`, at distance `t`.
    #[inline(always)]
    fn triangle_interaction(&self, i: u32, b1: f32, b2: f32, t: f32) -> SurfaceInteraction {
        let tri = &self.triangles[i as usize];
        let p = (1.0 - b1 - b2) * tri.p[0] + b1 * tri.p[1] + b2 * tri.p[2];
        let ng = self.tri_ng[i as usize];
        let light = self.tri_light[i as usize];
        let uv = match self.tri_uv.get(i as usize) {
            Some(uv) => (1.0 - b1 - b2) * uv[0] + b1 * uv[1] + b2 * uv[2],
            None => Vec2::new(b1, b2),
        };
        let ns = match self.tri_normals.get(i as usize) {
            Some(n) => ((1.0 - b1 - b2) * n[0] + b1 * n[1] + b2 * n[2])
                .try_normalize()
                .filter(|ns| ns.dot(ng) > 0.0)
                .unwrap_or(ng),
            None => ng,
        };
        SurfaceInteraction {
            p,
            t,
            ng,
            ns,
            material: self.tri_material[i as usize],
            light: (light != NO_LIGHT).then_some(light),
            uv,
            prim: i,
            b: Vec2::new(b1, b2),
        }
    }

    /// The surface interaction where `ray` meets sphere `i` at distance `t`. Out of line:
    /// spheres are rare, and their set-up would weigh on every triangle hit.
    #[inline(never)]
    fn sphere_interaction(&self, i: u32, ray: &Ray, t: f32) -> SurfaceInteraction {
        let s = &self.spheres[i as usize];
        let p = ray.at(t);
        let ng = ((p - s.center) / s.radius).normalize();
        // Project onto the surface to remove the rounding of the ray parameter.
        let p = s.center + ng * s.radius;
        let light = self.sphere_light[i as usize];
        let uv = sphere_uv(self.sphere_to_object[i as usize] * ng);
        SurfaceInteraction {
            p,
            t,
            ng,
            ns: ng,
            material: self.sphere_material[i as usize],
            light: (light != NO_LIGHT).then_some(light),
            uv,
            prim: u32::MAX,
            b: Vec2::ZERO,
        }
    }

    /// The surface interaction where `ray` meets the SDF grid surface in voxel `i` at
    /// distance `t` (out of line, as spheres are).
    #[inline(never)]
    fn voxel_interaction(&self, i: u32, ray: &Ray, t: f32) -> SurfaceInteraction {
        let v = self.voxels[i as usize];
        let p = ray.at(t);
        let (ng, ns) = self.grids[v.grid as usize].normals(v.corner, p);
        // A blended shading normal may lean past the geometric one's hemisphere; the
        // geometric side decides.
        let ns = if ns.dot(ng) > 0.0 { ns } else { ng };
        SurfaceInteraction {
            p,
            t,
            ng,
            ns,
            material: self.grid_material[v.grid as usize],
            light: None,
            uv: Vec2::ZERO,
            prim: u32::MAX,
            b: Vec2::ZERO,
        }
    }

    /// Whether anything seen by non-camera rays blocks `ray` within its extent.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.any_hit(ray, false)
    }
}

/// Adds an area light for `shape` if it emits; returns its index, or [`NO_LIGHT`]. Shapes that
/// only camera rays see show their emission but are never sampled as lights.
fn add_area_light(
    lights: &mut Vec<Light>,
    sampleable: &mut Vec<bool>,
    (groups, group): (&mut Vec<u32>, u32),
    shape: AreaShape,
    emission: Option<Emission>,
    texture: Option<Arc<AreaTexture>>,
    visibility: Visibility,
) -> u32 {
    match emission {
        Some(e) if e.radiance.max_element() > 0.0 => {
            lights.push(Light::Area {
                shape,
                radiance: e.radiance,
                two_sided: e.two_sided,
                texture,
            });
            sampleable.push(visibility.indirect);
            groups.push(group);
            (lights.len() - 1) as u32
        }
        _ => NO_LIGHT,
    }
}

/// A diffuse material description, for tests and simple scenes.
pub fn diffuse(reflectance: Rgb, two_sided: bool) -> MaterialDesc {
    MaterialDesc::Diffuse {
        reflectance,
        two_sided,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::desc::MeshDesc;

    fn triangle_with_normals(normals: Vec<Vec3>) -> Scene {
        let desc = SceneDesc {
            meshes: vec![MeshDesc {
                name: "tri".into(),
                positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
                indices: vec![0, 1, 2],
                normals,
                ..Default::default()
            }],
            materials: vec![diffuse(Vec3::ONE, false)],
            resolution: [4, 4],
            ..Default::default()
        };
        Scene::build(&desc).unwrap()
    }

    #[test]
    fn vertex_normals_are_interpolated_and_kept_on_the_front_side() {
        let tilted = Vec3::new(1.0, 0.0, 1.0).normalize();
        let scene = triangle_with_normals(vec![Vec3::Z, tilted, Vec3::Z]);
        let ray = Ray::new(Vec3::new(0.5, 0.25, 1.0), -Vec3::Z);
        let si = scene.intersect(&ray).0.unwrap();
        assert_eq!(si.ng, Vec3::Z);
        // Barycentrics (0.25, 0.5, 0.25): the tilted normal has weight ½.
        let expected = (0.5 * Vec3::Z + 0.5 * tilted).normalize();
        assert!((si.ns - expected).length() < 1e-5, "{}", si.ns);
        // Normals pointing against the winding are flipped to its side.
        let scene = triangle_with_normals(vec![-Vec3::Z; 3]);
        let si = scene.intersect(&ray).0.unwrap();
        assert!((si.ns - Vec3::Z).length() < 1e-6);
        // Without normals, shading is flat.
        let scene = triangle_with_normals(Vec::new());
        assert_eq!(scene.intersect(&ray).0.unwrap().ns, Vec3::Z);
    }
}
