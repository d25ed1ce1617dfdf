//! The renderable scene: flattened shapes, the BVH over them, materials, lights and camera.

use crate::accel::{Bvh8, TriBlock, TRIS_PER_BLOCK};
use crate::bsdf::{Material, ShadingPoint};
use crate::camera::Camera;
use crate::desc::{MaterialDesc, RayKind, Rgb};
use crate::geometry::{Aabb, Ray};
use crate::light::{sphere_uv, Light, LightSampler};
use crate::sdf_grid::SdfGrid;
use crate::shape::Sphere;
use crate::texture::{AttributeTable, TexPoint};
use glam::{Mat3, Vec2, Vec3};
use thiserror::Error;

mod build;
mod trace;

use trace::BlockInfo;

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

/// A triangle's material and light ([`NO_LIGHT`] for none).
#[derive(Clone, Copy, Debug, PartialEq)]
struct TriSurface {
    material: u32,
    light: u32,
}

/// A [`Prim`] in 32 bits, as the scene keeps one per BVH leaf slot: its kind in the top two
/// bits and its index in the others (indices are below the BVH's
/// [`crate::accel::MAX_PRIMITIVES`], 2²⁷).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct PackedPrim(u32);

impl PackedPrim {
    /// Bits of the index.
    const INDEX_BITS: u32 = 30;

    fn new(p: Prim) -> PackedPrim {
        let (kind, i) = match p {
            Prim::Triangle(i) => (0, i),
            Prim::Sphere(i) => (1, i),
            Prim::Voxel(i) => (2, i),
        };
        debug_assert!(i < 1 << Self::INDEX_BITS);
        PackedPrim(kind << Self::INDEX_BITS | i)
    }

    #[inline(always)]
    fn get(self) -> Prim {
        let i = self.0 & ((1 << Self::INDEX_BITS) - 1);
        match self.0 >> Self::INDEX_BITS {
            0 => Prim::Triangle(i),
            1 => Prim::Sphere(i),
            _ => Prim::Voxel(i),
        }
    }
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
    /// Texture coordinates (the mesh's, else barycentric; spherical on spheres, where they
    /// are computed only if the sphere's material or light reads a texture: (0, 0) otherwise).
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
    /// Where each triangle's vertices are: `block · TRIS_PER_BLOCK + lane` in `blocks` (of
    /// its first copy; the BVH's leaf blocks are the one copy of the triangles the scene
    /// keeps).
    tri_slot: Vec<u32>,
    /// Unit geometric normal of each triangle (its winding's side), computed once.
    tri_ng: Vec<Vec3>,
    /// Each triangle's material and light, as an index into `tri_surfaces`; empty where
    /// every triangle has the same, `same_surface`.
    tri_surface: Vec<u32>,
    /// The index into `tri_surfaces` of every triangle's material and light, where
    /// `tri_surface` is empty.
    same_surface: u32,
    /// The (material, light) pairs of the triangles: entry `m` is material `m` without a
    /// light, then one entry per emitting triangle.
    tri_surfaces: Vec<TriSurface>,
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
    /// Whether each sphere's material or light reads a texture, at its (u, v): the angles
    /// cost an `atan2` and an `acos` per hit, wasted on the others.
    sphere_reads_uv: Vec<bool>,
    grids: Vec<SdfGrid>,
    grid_material: Vec<u32>,
    voxels: Vec<Voxel>,
    /// Whether every primitive is a triangle (no spheres or SDF grids).
    only_triangles: bool,
    /// Mesh attributes read by textures, per triangle corner.
    attributes: Vec<AttributeTable>,
    prims: Vec<PackedPrim>,
    /// Whether every primitive is seen by every ray (the common case, checked once).
    all_visible: bool,
    /// The BVH, whose leaves name ranges of `blocks`.
    bvh: Bvh8,
    /// The primitives of the BVH's leaves, four to a block, in leaf order.
    blocks: Vec<TriBlock>,
    block_info: Vec<BlockInfo>,
    /// The box of each block's triangles, in scenes small enough for
    /// [`Scene::nearest_of_rays`] (empty in others).
    block_bounds: Vec<Aabb>,
    materials: Vec<Material>,
    /// Whether each material needs the surface's tangents.
    needs_tangents: Vec<bool>,
    lights: Vec<Light>,
    light_sampler: LightSampler,
    environment: Option<u32>,
    /// A box around every emitting surface, a little larger (none without one).
    emitter_bounds: Option<Aabb>,
    camera: Camera,
    stats: BuildStats,
}

impl Scene {
    /// The camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Replaces the camera (a viewer that moves it keeps the rest of the scene).
    pub fn set_camera(&mut self, camera: Camera) {
        self.camera = camera;
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
        size_of_val(self.tri_slot.as_slice())
            + size_of_val(self.tri_ng.as_slice())
            + size_of_val(self.tri_surface.as_slice())
            + size_of_val(self.tri_surfaces.as_slice())
            + size_of_val(self.tri_uv.as_slice())
            + size_of_val(self.tri_normals.as_slice())
            + size_of_val(self.spheres.as_slice())
            + size_of_val(self.sphere_material.as_slice())
            + size_of_val(self.sphere_light.as_slice())
            + size_of_val(self.sphere_to_object.as_slice())
            + size_of_val(self.sphere_reads_uv.as_slice())
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
        self.materials[si.material as usize].bsdf(&self.shading_point(si), wo)
    }

    /// What a material reads at `si`: the shading and geometric normals, the tangents where
    /// the material needs them (zero otherwise), and where textures are read.
    #[inline]
    pub fn shading_point(&self, si: &SurfaceInteraction) -> ShadingPoint<'_> {
        let (dpdu, dpdv) = if self.needs_tangents[si.material as usize] {
            self.tangents(si)
        } else {
            (Vec3::ZERO, Vec3::ZERO)
        };
        ShadingPoint {
            n: si.ns,
            dpdu,
            dpdv,
            ng: si.ng,
            tex: self.tex_point(si),
        }
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
        let [_, dp0, dp1] = self.triangle_corner_and_edges(i as u32);
        let uv = self
            .tri_uv
            .get(i)
            .copied()
            .unwrap_or([Vec2::ZERO, Vec2::X, Vec2::Y]);
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

    /// Whether the unbounded ray from `o` along `d` may find emission: the scene has an
    /// environment, or the ray meets the box around its emitting surfaces (a little larger,
    /// so that rounding cannot hide a hit). Where it cannot, the ray that ends a path of
    /// bounded depth, traced only to find emission, need not be traced.
    #[inline(always)]
    pub fn may_find_emission(&self, o: Vec3, d: Vec3) -> bool {
        self.environment.is_some() || self.meets_emitter_bounds(o.x, o.y, o.z, d.x, d.y, d.z)
    }

    /// Whether the unbounded ray from `o` along `d` meets the box around the emitting
    /// surfaces. Out of line: asked only at a path's last bounce, inlined it would keep the
    /// end of every bounce (`PathIntegrator::survive`) from being inlined into the path loop.
    /// The ray comes as six numbers, in registers (vectors and arrays would be passed through
    /// memory): a ray its caller has only just written to memory, read back by wider loads
    /// than the stores that wrote it, waits for those stores to reach the cache, and that
    /// was a tenth of the time of direct lighting in the Cornell box.
    #[inline(never)]
    fn meets_emitter_bounds(&self, ox: f32, oy: f32, oz: f32, dx: f32, dy: f32, dz: f32) -> bool {
        let (o, d) = (Vec3::new(ox, oy, oz), Vec3::new(dx, dy, dz));
        self.emitter_bounds
            .is_some_and(|b| b.hit(o, d.recip(), f32::INFINITY).is_some())
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
        self.intersect_as(ray, RayKind::Camera)
    }

    /// The nearest surface along any other ray, and the number of BVH nodes visited.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> (Option<SurfaceInteraction>, u32) {
        self.intersect_as(ray, RayKind::Indirect)
    }

    /// The distance to the nearest surface along a non-camera ray, without making its surface
    /// interaction: the query a ray-tracing kernel answers (`rtcIntersect1`), for measuring
    /// traversal alone.
    #[inline]
    pub fn hit_distance(&self, ray: &Ray) -> Option<f32> {
        let mut r = *ray;
        self.closest_hit(&mut r, RayKind::Indirect)
            .found()
            .then_some(r.t_max)
    }

    /// [`Scene::hit_distance`] of eight rays, which walk the BVH together where the scene
    /// allows (one by one otherwise): the query of a ray-tracing
    /// kernel's packets of eight (`rtcIntersect8`). Pays for rays that go the same way.
    pub fn hit_distances(&self, rays: &[Ray; crate::simd::lanes::W]) -> [Option<f32>; 8] {
        if !self.traces_packets() {
            return rays.map(|r| self.hit_distance(&r));
        }
        let mut lanes = crate::accel::RayLanes::default();
        let mut t_max = crate::simd::lanes::F8::splat(0.0);
        for (i, r) in rays.iter().enumerate() {
            lanes.set(i, r);
            t_max.0[i] = r.t_max;
        }
        let (nearest, _) = self.nearest_of_packet(&lanes, t_max);
        std::array::from_fn(|i| nearest.lane(i).map(|(_, t, _, _)| t))
    }

    #[inline(always)]
    fn intersect_as(&self, ray: &Ray, kind: RayKind) -> (Option<SurfaceInteraction>, u32) {
        let mut si = None;
        let visited = self.intersect_into(ray, kind, &mut si);
        (si, visited)
    }

    /// The nearest surface along a ray of `kind`, written to `si`
    /// (`None` where the ray escapes); returns the number of BVH nodes visited. Made in place,
    /// for callers that keep it in an array: moving a fresh interaction there would copy it
    /// with wide loads of its narrow stores, which wait for them.
    #[inline(always)]
    pub fn intersect_into(
        &self,
        ray: &Ray,
        kind: RayKind,
        si: &mut Option<SurfaceInteraction>,
    ) -> u32 {
        let mut r = *ray;
        let hit = self.closest_hit(&mut r, kind);
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
        match self.prims[slot as usize].get() {
            Prim::Triangle(i) => *si = Some(self.triangle_interaction(i, b1, b2, t)),
            Prim::Sphere(i) => *si = Some(self.sphere_interaction(i, ray, t)),
            Prim::Voxel(i) => *si = Some(self.voxel_interaction(i, ray, t)),
        }
    }

    /// The leaf block and lane that hold triangle `i` (its first copy).
    #[inline(always)]
    fn triangle_block(&self, i: u32) -> (&TriBlock, usize) {
        let slot = self.tri_slot[i as usize] as usize;
        (&self.blocks[slot / TRIS_PER_BLOCK], slot % TRIS_PER_BLOCK)
    }

    /// Triangle `i`'s first vertex and its edges to the second and third, from its leaf
    /// block.
    #[inline(always)]
    fn triangle_corner_and_edges(&self, i: u32) -> [Vec3; 3] {
        let (block, lane) = self.triangle_block(i);
        block.corner_and_edges(lane)
    }

    /// The surface interaction at barycentrics (b1, b2) of triangle `i`, at distance `t`.
    #[inline(always)]
    fn triangle_interaction(&self, i: u32, b1: f32, b2: f32, t: f32) -> SurfaceInteraction {
        let [p0, e1, e2] = self.triangle_corner_and_edges(i);
        let p = p0 + b1 * e1 + b2 * e2;
        let ng = self.tri_ng[i as usize];
        let surface = match self.tri_surface.get(i as usize) {
            Some(&s) => s,
            None => self.same_surface,
        };
        let TriSurface { material, light } = self.tri_surfaces[surface as usize];
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
            material,
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
        let uv = if self.sphere_reads_uv[i as usize] {
            sphere_uv(self.sphere_to_object[i as usize] * ng)
        } else {
            Vec2::ZERO
        };
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
        self.any_hit(ray, RayKind::Indirect)
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
    use crate::desc::{MeshDesc, SceneDesc};

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
    fn spheres_find_their_texture_coordinates_where_a_texture_reads_them() {
        // Sphere 0 plain, sphere 1 textured, sphere 2 plain but with a textured emission.
        let checker = crate::desc::TextureDesc::Checkerboard {
            color0: Vec3::ZERO,
            color1: Vec3::ONE,
            to_uv: glam::Affine2::IDENTITY,
        };
        let desc = SceneDesc {
            spheres: (0..3)
                .map(|k| crate::desc::SphereDesc {
                    center: Vec3::new(3.0 * k as f32, 0.0, 0.0),
                    material: usize::from(k == 1),
                    emission: (k == 2).then_some(crate::desc::Emission {
                        radiance: Vec3::ONE,
                        two_sided: false,
                    }),
                    emission_texture: (k == 2).then(|| checker.clone()),
                    ..Default::default()
                })
                .collect(),
            materials: vec![
                diffuse(Vec3::ONE, false),
                MaterialDesc::TexturedDiffuse {
                    texture: checker.clone(),
                    scale: Vec3::ONE,
                    two_sided: false,
                },
            ],
            resolution: [4, 4],
            ..Default::default()
        };
        let scene = Scene::build(&desc).unwrap();
        let d = Vec3::new(0.3, -0.4, -1.0).normalize();
        for k in 0..3 {
            let o = Vec3::new(3.0 * k as f32, 0.0, 0.0) - 3.0 * d;
            let si = scene.intersect(&Ray::new(o, d)).0.unwrap();
            let expected = if k == 0 { Vec2::ZERO } else { sphere_uv(si.ng) };
            assert_eq!(si.uv, expected, "sphere {k}");
            assert_ne!(sphere_uv(si.ng), Vec2::ZERO);
        }
    }

    #[test]
    fn packed_primitives_keep_their_kind_and_index() {
        let max = (1 << PackedPrim::INDEX_BITS) - 1;
        for p in [
            Prim::Triangle(0),
            Prim::Triangle(max),
            Prim::Sphere(0),
            Prim::Sphere(12345),
            Prim::Voxel(1),
            Prim::Voxel(max),
        ] {
            assert_eq!(PackedPrim::new(p).get(), p);
        }
    }

    /// Quads side by side along x, each its own mesh with its own material; some emit.
    fn quads(emitting: &[bool]) -> Scene {
        Scene::build(&quads_desc(emitting)).unwrap()
    }

    /// The scene description of [`quads`].
    fn quads_desc(emitting: &[bool]) -> SceneDesc {
        let meshes = emitting
            .iter()
            .enumerate()
            .map(|(k, &emits)| {
                let x = 2.0 * k as f32;
                MeshDesc {
                    name: format!("quad {k}"),
                    positions: vec![
                        Vec3::new(x, 0.0, 0.0),
                        Vec3::new(x + 1.0, 0.0, 0.0),
                        Vec3::new(x + 1.0, 1.0, 0.0),
                        Vec3::new(x, 1.0, 0.0),
                    ],
                    indices: vec![0, 1, 2, 0, 2, 3],
                    material: k,
                    emission: emits.then_some(crate::desc::Emission {
                        radiance: Vec3::splat(1.0 + k as f32),
                        two_sided: false,
                    }),
                    ..Default::default()
                }
            })
            .collect();
        SceneDesc {
            meshes,
            materials: (0..emitting.len())
                .map(|k| diffuse(Vec3::splat(0.1 * k as f32), false))
                .collect(),
            resolution: [4, 4],
            ..Default::default()
        }
    }

    #[test]
    fn each_triangle_reports_its_material_and_its_own_light() {
        let emitting = [false, true, false, true, true, false];
        let scene = quads(&emitting);
        let mut lights_seen = Vec::new();
        for (k, &emits) in emitting.iter().enumerate() {
            // Both triangles of quad k.
            for (dx, dy) in [(0.7, 0.2), (0.2, 0.7)] {
                let o = Vec3::new(2.0 * k as f32 + dx, dy, 1.0);
                let si = scene.intersect(&Ray::new(o, -Vec3::Z)).0.unwrap();
                assert_eq!(si.material, k as u32, "quad {k}");
                assert_eq!(si.light.is_some(), emits, "quad {k}");
                if let Some(light) = si.light {
                    assert!((light as usize) < scene.lights().len());
                    lights_seen.push(light);
                }
            }
        }
        // Every emitting triangle is a light of its own.
        let n = lights_seen.len();
        lights_seen.sort_unstable();
        lights_seen.dedup();
        assert_eq!((n, lights_seen.len()), (6, 6));
        // One table entry per material, and one per emitting triangle.
        assert_eq!(scene.tri_surfaces.len(), emitting.len() + 6);
    }

    #[test]
    fn triangles_of_one_surface_keep_no_index_each() {
        // Every quad of the last material, none emitting: no per-triangle index, and every
        // hit still reports that material.
        let mut desc = quads_desc(&[false; 4]);
        for m in &mut desc.meshes {
            m.material = 3;
        }
        let scene = Scene::build(&desc).unwrap();
        assert!(scene.tri_surface.is_empty());
        // The same quads, each of its own material.
        let with_index = quads(&[false; 4]);
        assert_eq!(with_index.tri_surface.len(), 8);
        assert_eq!(
            scene.geometry_bytes() + 8 * std::mem::size_of::<u32>(),
            with_index.geometry_bytes()
        );
        for k in 0..4 {
            for (dx, dy) in [(0.7, 0.2), (0.2, 0.7)] {
                let o = Vec3::new(2.0 * k as f32 + dx, dy, 1.0);
                let si = scene.intersect(&Ray::new(o, -Vec3::Z)).0.unwrap();
                assert_eq!((si.material, si.light), (3, None), "quad {k}");
            }
        }
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
        // Normals that are the face's but for rounding are not kept: shading is flat.
        let nearly = Vec3::new(3e-7, -2e-7, 1.0);
        let scene = triangle_with_normals(vec![nearly, Vec3::Z, -nearly]);
        assert!(scene.tri_normals.is_empty());
        assert_eq!(scene.intersect(&ray).0.unwrap().ns, Vec3::Z);
        // Another beyond that: all are kept.
        let scene = triangle_with_normals(vec![nearly, Vec3::new(1e-4, 0.0, 1.0), Vec3::Z]);
        assert_eq!(scene.tri_normals.len(), 1);
    }
}
