//! Tracing rays through the scene: the BVH's leaves hold blocks of four triangles tested
//! together (other shapes, spheres and the voxels of SDF grids, are tested one by one in
//! their lanes), and the traversal is
//! compiled twice, for AVX2 and for the target's baseline, the CPU choosing at run time.
//! Small scenes skip the BVH for camera and bounce rays: eight rays against every primitive
//! at once ([`Scene::nearest_of_rays`]), at the best SIMD level the CPU has. In scenes of
//! triangles only, eight rays that go the same way can walk the BVH together
//! ([`Scene::nearest_of_packet`]), each tested exactly at the leaves: the ray benchmark's
//! packets ([`Scene::hit_distances`]); renders trace their rays alone (a pixel's camera rays
//! over a finely tessellated mesh reach many leaves between them, each testing all eight).

use super::{Prim, Scene};
use crate::accel::{
    BoxTest, Bvh8, Nearest, PacketBounds, Portable, RayBoxLanes, RayLanes, TriBlock, BVH_WIDTH,
    TRIS_PER_BLOCK,
};
use crate::desc::{RayKind, Visibility};
use crate::geometry::{Aabb, Ray};
use crate::shape::Triangle;
use crate::simd::lanes::{F8, W};
#[cfg(target_arch = "x86_64")]
use crate::simd::{Avx2, Avx512};
use glam::Vec3;

/// Where a ray's nearest hit is, before the surface interaction is made from it, and how
/// many BVH nodes the search visited: packed in two 64-bit words, so that it comes back from
/// the (not inlined) traversal in two registers rather than through memory, where reading it
/// back would wait for its stores.
#[derive(Clone, Copy)]
pub(super) struct Hit {
    /// Leaf slot of the primitive (low half; [`Hit::NONE`] where nothing was hit) and BVH
    /// nodes visited (high half).
    slot_visited: u64,
    /// Bits of the barycentrics of vertices 1 (low half) and 2 (high half), for triangles.
    barycentrics: u64,
}

impl Hit {
    /// The slot of a miss (no leaf slot reaches it: slots are below `MAX_PRIMITIVES`).
    pub(super) const NONE: u32 = u32::MAX;

    #[inline(always)]
    fn new(slot: u32, b1: f32, b2: f32, visited: u32) -> Hit {
        Hit {
            slot_visited: u64::from(slot) | u64::from(visited) << 32,
            barycentrics: u64::from(b1.to_bits()) | u64::from(b2.to_bits()) << 32,
        }
    }

    /// Whether the ray hit anything.
    #[inline(always)]
    pub(super) fn found(&self) -> bool {
        self.slot() != Hit::NONE
    }

    /// Leaf slot of the primitive hit.
    #[inline(always)]
    pub(super) fn slot(&self) -> u32 {
        self.slot_visited as u32
    }

    /// BVH nodes visited.
    #[inline(always)]
    pub(super) fn visited(&self) -> u32 {
        (self.slot_visited >> 32) as u32
    }

    /// Barycentric coordinates of vertices 1 and 2.
    #[inline(always)]
    pub(super) fn barycentrics(&self) -> (f32, f32) {
        (
            f32::from_bits(self.barycentrics as u32),
            f32::from_bits((self.barycentrics >> 32) as u32),
        )
    }
}

/// What a [`TriBlock`]'s lanes hold: their primitives' leaf slots (consecutive: lane `i`
/// holds slot `first_slot + i`), and which lanes are used, other shapes than triangles
/// (tested one by one), or seen by camera and other rays.
#[derive(Clone, Copy, Debug)]
pub(super) struct BlockInfo {
    /// Leaf slot of lane 0's primitive.
    first_slot: u32,
    /// Lanes that hold a primitive (the first ones).
    used: u8,
    /// Lanes that hold other shapes than triangles.
    shapes: u8,
    /// Lanes seen by camera rays.
    camera: u8,
    /// Lanes seen by other rays.
    indirect: u8,
}

impl BlockInfo {
    /// Leaf slot of lane `lane`'s primitive.
    #[inline(always)]
    fn slot(&self, lane: usize) -> u32 {
        self.first_slot + lane as u32
    }
}

impl Scene {
    /// The lanes of block `b` that a ray of `kind` tests as triangles,
    /// and the lanes it tests as other shapes.
    #[inline(always)]
    fn block_lanes(&self, b: usize, kind: RayKind) -> (u32, u32) {
        if self.all_visible && self.only_triangles {
            // Unused lanes never hit, so all four can be tested.
            return (0b1111, 0);
        }
        let info = &self.block_info[b];
        let seen = u32::from(match kind {
            RayKind::Camera => info.camera,
            RayKind::Indirect => info.indirect,
        });
        let shapes = u32::from(info.shapes);
        (seen & !shapes, seen & shapes)
    }

    /// Where `ray` meets the shape (not a triangle) in leaf slot `slot` within its extent.
    #[inline]
    fn shape_hit(&self, slot: u32, ray: &Ray) -> Option<f32> {
        match self.prims[slot as usize].get() {
            Prim::Sphere(s) => self.spheres[s as usize].intersect(ray),
            Prim::Voxel(v) => {
                let voxel = self.voxels[v as usize];
                self.grids[voxel.grid as usize].intersect_voxel(voxel.corner, ray)
            }
            Prim::Triangle(_) => unreachable!("block lanes marked as shapes hold shapes"),
        }
    }

    /// The nearest hit along `ray` (whose `t_max` it shortens to the hit), and the number of
    /// BVH nodes visited. Compiled twice: for CPUs with AVX2 and FMA, chosen at run time, and
    /// for the target's baseline.
    #[inline]
    pub(super) fn closest_hit(&self, ray: &mut Ray, kind: RayKind) -> Hit {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = Avx2::detect() {
            // SAFETY: `closest_hit_avx2` requires AVX2 and FMA, which `avx2` proves this CPU
            // has. Its body is safe code.
            return unsafe { self.closest_hit_avx2(avx2, ray, kind) };
        }
        self.closest_hit_with(Portable, ray, kind)
    }

    /// [`Scene::closest_hit`] compiled for AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn closest_hit_avx2(&self, avx2: Avx2, ray: &mut Ray, kind: RayKind) -> Hit {
        self.closest_hit_with(avx2, ray, kind)
    }

    /// [`Scene::any_hit`] compiled for AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn any_hit_avx2(&self, avx2: Avx2, ray: &Ray, kind: RayKind) -> bool {
        self.any_hit_with(avx2, ray, kind)
    }

    /// Whether anything a ray of `kind` sees blocks `ray`; compiled
    /// twice, as [`Scene::closest_hit`] is.
    #[inline]
    pub(super) fn any_hit(&self, ray: &Ray, kind: RayKind) -> bool {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = Avx2::detect() {
            // SAFETY: as in `closest_hit`: `avx2` proves the features `any_hit_avx2` requires.
            return unsafe { self.any_hit_avx2(avx2, ray, kind) };
        }
        self.any_hit_with(Portable, ray, kind)
    }

    /// [`Scene::closest_hit`] with the box test `boxes`.
    #[inline(always)]
    fn closest_hit_with(
        &self,
        boxes: impl BoxTest<BVH_WIDTH>,
        ray: &mut Ray,
        kind: RayKind,
    ) -> Hit {
        // The nearest hit's fields as separate scalars (`slot` Hit::NONE: none): the leaf test
        // writes them one by one, and reading them back one by one lets the loads take the
        // stored values directly, where reading a whole `Option<Hit>` with one wide load waits
        // for the narrow stores to complete.
        let (mut slot, mut b1, mut b2) = (Hit::NONE, 0.0f32, 0.0f32);
        let (_, visited) = self.bvh.intersect_leaves_with(boxes, ray, |leaf, r| {
            let (first, count) = Bvh8::leaf_range(leaf);
            let mut any = false;
            for b in first as usize..(first + count) as usize {
                let (triangles, shapes) = self.block_lanes(b, kind);
                if let Some(h) = self.blocks[b].intersect(r, triangles) {
                    r.t_max = h.t;
                    (slot, b1, b2) = (self.block_info[b].slot(h.lane), h.b1, h.b2);
                    any = true;
                }
                if shapes != 0 {
                    if let Some(s) = self.nearest_shape(b, shapes, r) {
                        (slot, b1, b2) = (s, 0.0, 0.0);
                        any = true;
                    }
                }
            }
            any
        });
        Hit::new(slot, b1, b2, visited)
    }

    /// The leaf slot of the nearest shape among lanes `shapes` of block `b` that `ray` hits
    /// within its extent, shortening `ray.t_max` to it. Kept out of line: other shapes are
    /// rare, and inlined, a sphere's set-up (in `f64`) is hoisted to the start of every
    /// traversal.
    #[cold]
    #[inline(never)]
    fn nearest_shape(&self, b: usize, mut shapes: u32, ray: &mut Ray) -> Option<u32> {
        let mut nearest = None;
        while shapes != 0 {
            let lane = shapes.trailing_zeros() as usize;
            shapes &= shapes - 1;
            let slot = self.block_info[b].slot(lane);
            if let Some(t) = self.shape_hit(slot, ray) {
                ray.t_max = t;
                nearest = Some(slot);
            }
        }
        nearest
    }

    /// Whether `ray` hits any shape among lanes `shapes` of block `b` within its extent
    /// (out of line, as [`Scene::nearest_shape`]).
    #[cold]
    #[inline(never)]
    fn hits_shape(&self, b: usize, mut shapes: u32, ray: &Ray) -> bool {
        while shapes != 0 {
            let lane = shapes.trailing_zeros() as usize;
            shapes &= shapes - 1;
            if self.shape_hit(self.block_info[b].slot(lane), ray).is_some() {
                return true;
            }
        }
        false
    }

    /// Whether the scene is small enough to intersect rays by testing every primitive
    /// ([`Scene::nearest_of_rays`]): at most [`SMALL_SCENE_BLOCKS`] blocks of primitives
    /// (triangles, spheres, voxels), of them at most [`SMALL_SCENE_SHAPES`] other shapes than
    /// triangles, each seen by every ray.
    pub(crate) fn tests_every_primitive(&self) -> bool {
        let shapes = || -> u32 { self.block_info.iter().map(|b| b.shapes.count_ones()).sum() };
        self.all_visible
            && self.blocks.len() <= SMALL_SCENE_BLOCKS
            && (self.only_triangles || shapes() <= SMALL_SCENE_SHAPES)
    }

    /// The nearest hits of eight rays ending at `t_max`, by testing every primitive against
    /// all eight at once. For a few dozen triangles and a few spheres this costs a fraction
    /// of walking the BVH with each ray, and finds the same distance (the same triangle and
    /// sphere tests, to the bit); of several primitives at exactly that distance (a ray
    /// through a shared edge) it may report another than the BVH would. Only for scenes
    /// where [`Scene::tests_every_primitive`].
    ///
    /// With `cull`, a block of triangles that no ray meets the box of is skipped (same
    /// result): worth its box tests where the rays go the same way, as camera rays of one
    /// pixel and the first bounce from it do; rays from scattered points meet nearly every
    /// box.
    pub(crate) fn nearest_of_rays(&self, rays: &RayLanes, t_max: F8, cull: bool) -> Nearest {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx512) = Avx512::detect() {
            // SAFETY: `nearest_of_rays_avx512` requires AVX-512 F, VL and DQ, AVX2 and FMA,
            // which `avx512` proves this CPU has. Its body is safe code.
            return unsafe { self.nearest_of_rays_avx512(avx512, rays, t_max, cull) };
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = Avx2::detect() {
            // SAFETY: `nearest_of_rays_avx2` requires AVX2 and FMA, which `avx2` proves this
            // CPU has. Its body is safe code.
            return unsafe { self.nearest_of_rays_avx2(avx2, rays, t_max, cull) };
        }
        self.nearest_of_rays_lanes(rays, t_max, cull)
    }

    /// [`Scene::nearest_of_rays`] compiled for AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn nearest_of_rays_avx2(&self, _: Avx2, rays_in: &RayLanes, t_max: F8, cull: bool) -> Nearest {
        use crate::accel::{AvxNearest, AvxRays};
        let rays = AvxRays::new(rays_in);
        let mut nearest = AvxNearest::new(t_max);
        self.for_each_triangle_seen(
            rays_in,
            cull,
            &mut nearest,
            |n| n.t(),
            |n, block, lane, slot| block.nearest_for_rays_avx(lane, slot, &rays, n),
        );
        self.with_nearest_shapes(rays_in, nearest.lanes())
    }

    /// [`Scene::nearest_of_rays`] with AVX-512: the triangles in pairs, sixteen lanes (two
    /// triangles against the eight rays) at a time, with the same result as one at a time
    /// (an odd last triangle is paired with itself).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
    fn nearest_of_rays_avx512(
        &self,
        _: Avx512,
        rays_in: &RayLanes,
        t_max: F8,
        cull: bool,
    ) -> Nearest {
        use crate::accel::{nearest_for_rays_pair_avx512, Avx512Nearest, Avx512Rays, AvxRays};
        let rays = Avx512Rays::new(&AvxRays::new(rays_in));
        let mut nearest = Avx512Nearest::new(t_max);
        let mut first = None;
        self.for_each_triangle_seen(
            rays_in,
            cull,
            &mut nearest,
            |n| n.t(),
            |n, block, lane, slot| match first.take() {
                None => first = Some((block, lane, slot)),
                Some(a) => nearest_for_rays_pair_avx512(a, (block, lane, slot), &rays, n),
            },
        );
        if let Some(a) = first {
            nearest_for_rays_pair_avx512(a, a, &rays, &mut nearest);
        }
        self.with_nearest_shapes(rays_in, nearest.lanes())
    }

    /// [`Scene::nearest_of_rays`] at every SIMD level this CPU has (AVX-512, AVX2, then the
    /// portable lane loops), named, for the tests that compare them.
    #[cfg(test)]
    fn nearest_of_rays_each_level(
        &self,
        rays: &RayLanes,
        t_max: F8,
        cull: bool,
    ) -> Vec<(&str, Nearest)> {
        let mut all = vec![("portable", self.nearest_of_rays_lanes(rays, t_max, cull))];
        #[cfg(target_arch = "x86_64")]
        {
            if let Some(avx2) = Avx2::detect() {
                // SAFETY: `avx2` proves the features `nearest_of_rays_avx2` requires.
                all.push(("AVX2", unsafe {
                    self.nearest_of_rays_avx2(avx2, rays, t_max, cull)
                }));
            }
            if let Some(avx512) = Avx512::detect() {
                // SAFETY: `avx512` proves the features `nearest_of_rays_avx512` requires.
                all.push(("AVX-512", unsafe {
                    self.nearest_of_rays_avx512(avx512, rays, t_max, cull)
                }));
            }
        }
        all
    }

    #[inline(always)]
    fn nearest_of_rays_lanes(&self, rays: &RayLanes, t_max: F8, cull: bool) -> Nearest {
        let mut nearest = Nearest::new(t_max);
        self.for_each_triangle_seen(
            rays,
            cull,
            &mut nearest,
            |n| n.t,
            |n, block, lane, slot| block.nearest_for_rays(lane, slot, rays, n),
        );
        self.with_nearest_shapes(rays, nearest)
    }

    /// Whether eight rays may walk the BVH together ([`Scene::nearest_of_packet`]): scenes of
    /// triangles only, each seen by every ray.
    pub(crate) fn traces_packets(&self) -> bool {
        self.all_visible && self.only_triangles
    }

    /// The nearest hits of eight rays ending at `t_max` (-∞ for a lane without a ray), the
    /// eight walking the BVH together ([`crate::accel::WideBvh::packet_leaves`]), and the
    /// nodes visited. Each ray finds the distance its own walk would find (the same triangle
    /// tests, to the bit, and boxes skipped only where its own walk would skip them); of
    /// several triangles at exactly that distance it may report another. Pays where the rays
    /// go the same way. Only for scenes where [`Scene::traces_packets`].
    pub(crate) fn nearest_of_packet(&self, rays: &RayLanes, t_max: F8) -> (Nearest, u32) {
        let t_max = Self::packet_ends(t_max);
        let (active, bounds) = Self::packet_bounds(rays, t_max);
        let Some(bounds) = &bounds else {
            return self.nearest_one_by_one(rays, t_max, active);
        };
        #[cfg(target_arch = "x86_64")]
        if let Some(avx512) = Avx512::detect() {
            // SAFETY: `nearest_of_packet_avx512` requires AVX-512 F, VL and DQ, AVX2 and FMA,
            // which `avx512` proves this CPU has. Its body is safe code.
            return unsafe { self.nearest_of_packet_avx512(avx512, bounds, rays, t_max) };
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = Avx2::detect() {
            // SAFETY: `nearest_of_packet_avx2` requires AVX2 and FMA, which `avx2` proves
            // this CPU has. Its body is safe code.
            return unsafe { self.nearest_of_packet_avx2(avx2, bounds, rays, t_max) };
        }
        self.nearest_of_packet_lanes(bounds, rays, t_max)
    }

    /// The lanes of `rays` that have a ray (`t_max` above -∞), and their interval ray, if one
    /// bounds them.
    #[inline(always)]
    fn packet_bounds(rays: &RayLanes, t_max: F8) -> (u32, Option<PacketBounds>) {
        let active = (0..W).fold(0u32, |m, i| {
            m | u32::from(t_max.0[i] > f32::NEG_INFINITY) << i
        });
        (active, PacketBounds::new(rays, active))
    }

    /// `t_max` with -∞ in the lanes that have no ray (NaN included), so that the packet's
    /// farthest end is that of its rays.
    #[inline(always)]
    fn packet_ends(t_max: F8) -> F8 {
        let none = F8::splat(f32::NEG_INFINITY);
        t_max.gt(none).select(t_max, none)
    }

    /// The nearest hits of the lanes `active` of `rays`, each walking the BVH alone (packets
    /// that no interval ray bounds).
    #[cold]
    fn nearest_one_by_one(&self, rays: &RayLanes, t_max: F8, active: u32) -> (Nearest, u32) {
        let mut nearest = Nearest::new(t_max);
        let mut visited = 0;
        for i in (0..W).filter(|&i| active & (1 << i) != 0) {
            let mut ray = Ray {
                o: rays.o.get(i),
                d: rays.d.get(i),
                t_min: rays.t_min.0[i],
                t_max: t_max.0[i],
            };
            let hit = self.closest_hit(&mut ray, RayKind::Indirect);
            visited += hit.visited();
            if hit.found() {
                let (b1, b2) = hit.barycentrics();
                nearest.t.0[i] = ray.t_max;
                nearest.b1.0[i] = b1;
                nearest.b2.0[i] = b2;
                nearest.slot.0[i] = f32::from_bits(hit.slot());
            }
        }
        (nearest, visited)
    }

    /// [`Scene::nearest_of_packet`] compiled for AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn nearest_of_packet_avx2(
        &self,
        _: Avx2,
        bounds: &PacketBounds,
        rays_in: &RayLanes,
        t_max: F8,
    ) -> (Nearest, u32) {
        use crate::accel::{AvxNearest, AvxRays};
        let rays = AvxRays::new(rays_in);
        let mut nearest = AvxNearest::new(t_max);
        let visited = self.packet_triangles(
            bounds,
            &mut nearest,
            |n| n.t(),
            |n, block, lane, slot| block.nearest_for_rays_avx(lane, slot, &rays, n),
            |_| {},
        );
        (nearest.lanes(), visited)
    }

    /// [`Scene::nearest_of_packet`] with AVX-512: a leaf's triangles in pairs, as
    /// [`Scene::nearest_of_rays`] tests them (an odd last one paired with itself).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
    fn nearest_of_packet_avx512(
        &self,
        _: Avx512,
        bounds: &PacketBounds,
        rays_in: &RayLanes,
        t_max: F8,
    ) -> (Nearest, u32) {
        use crate::accel::{nearest_for_rays_pair_avx512, Avx512Nearest, Avx512Rays, AvxRays};
        let rays = Avx512Rays::new(&AvxRays::new(rays_in));
        // The nearest hits and a triangle waiting for its pair.
        let mut state = (Avx512Nearest::new(t_max), None);
        let visited = self.packet_triangles(
            bounds,
            &mut state,
            |(n, _)| n.t(),
            |(n, first), block, lane, slot| match first.take() {
                None => *first = Some((block, lane, slot)),
                Some(a) => nearest_for_rays_pair_avx512(a, (block, lane, slot), &rays, n),
            },
            // The leaf's last triangle before the walk reads the distances again.
            |(n, first)| {
                if let Some(a) = first.take() {
                    nearest_for_rays_pair_avx512(a, a, &rays, n);
                }
            },
        );
        (state.0.lanes(), visited)
    }

    #[inline(always)]
    fn nearest_of_packet_lanes(
        &self,
        bounds: &PacketBounds,
        rays: &RayLanes,
        t_max: F8,
    ) -> (Nearest, u32) {
        let mut nearest = Nearest::new(t_max);
        let visited = self.packet_triangles(
            bounds,
            &mut nearest,
            |n| n.t,
            |n, block, lane, slot| block.nearest_for_rays(lane, slot, rays, n),
            |_| {},
        );
        (nearest, visited)
    }

    /// [`Scene::nearest_of_packet`] at every SIMD level this CPU has, named, for the tests.
    #[cfg(test)]
    fn nearest_of_packet_each_level(&self, rays: &RayLanes, t_max: F8) -> Vec<(&str, Nearest)> {
        let (active, bounds) = Self::packet_bounds(rays, t_max);
        let Some(b) = &bounds else {
            return vec![("one by one", self.nearest_one_by_one(rays, t_max, active).0)];
        };
        let mut all = vec![("portable", self.nearest_of_packet_lanes(b, rays, t_max).0)];
        #[cfg(target_arch = "x86_64")]
        {
            if let Some(avx2) = Avx2::detect() {
                // SAFETY: `avx2` proves the features `nearest_of_packet_avx2` requires.
                all.push(("AVX2", unsafe {
                    self.nearest_of_packet_avx2(avx2, b, rays, t_max).0
                }));
            }
            if let Some(avx512) = Avx512::detect() {
                // SAFETY: `avx512` proves the features `nearest_of_packet_avx512` requires.
                all.push(("AVX-512", unsafe {
                    self.nearest_of_packet_avx512(avx512, b, rays, t_max).0
                }));
            }
        }
        all
    }

    /// `f(nearest, block, lane, leaf slot)` for every triangle of every leaf the packet
    /// bounded by `bounds` reaches, walking the BVH together
    /// ([`crate::accel::WideBvh::packet_leaves`]); `end_leaf(nearest)` after each leaf.
    /// Returns the nodes visited.
    #[inline(always)]
    fn packet_triangles<'a, N>(
        &'a self,
        bounds: &PacketBounds,
        nearest: &mut N,
        t_now: impl Fn(&N) -> F8,
        mut f: impl FnMut(&mut N, &'a TriBlock, usize, u32),
        mut end_leaf: impl FnMut(&mut N),
    ) -> u32 {
        self.bvh.packet_leaves(bounds, nearest, t_now, |n, word| {
            let (first, count) = Bvh8::leaf_range(word);
            for b in first as usize..(first + count) as usize {
                let info = &self.block_info[b];
                for lane in 0..TRIS_PER_BLOCK {
                    if info.used & (1 << lane) != 0 {
                        f(n, &self.blocks[b], lane, info.slot(lane));
                    }
                }
            }
            end_leaf(n);
        })
    }

    /// `nearest` (the triangles' nearest hits of eight rays) with the other shapes tested
    /// too: a lane's hit is replaced by a shape's where the shape is nearer. Spheres are
    /// tested eight rays at once ([`crate::shape::Sphere::intersect_lanes`], compiled with
    /// the caller's SIMD level), voxels one ray at a time.
    #[inline(always)]
    fn with_nearest_shapes(&self, rays: &RayLanes, mut nearest: Nearest) -> Nearest {
        if self.only_triangles {
            return nearest;
        }
        for info in &self.block_info {
            let mut shapes = u32::from(info.shapes);
            while shapes != 0 {
                let lane = shapes.trailing_zeros() as usize;
                shapes &= shapes - 1;
                let slot = info.slot(lane);
                let t: [f32; W] = match self.prims[slot as usize].get() {
                    Prim::Sphere(k) => self.spheres[k as usize].intersect_lanes(
                        &rays.o,
                        &rays.d,
                        &rays.t_min,
                        &nearest.t,
                    ),
                    _ => self.shape_hits_one_by_one(slot, rays, nearest.t),
                };
                for (i, &t) in t.iter().enumerate() {
                    if !t.is_nan() {
                        nearest.t.0[i] = t;
                        nearest.b1.0[i] = 0.0;
                        nearest.b2.0[i] = 0.0;
                        nearest.slot.0[i] = f32::from_bits(slot);
                    }
                }
            }
        }
        nearest
    }

    /// The distances at which each lane's ray, up to its `t_max`, meets the shape in leaf
    /// slot `slot` (NaN where it does not), one ray at a time. Out of line: the shapes that
    /// take it (voxel grids) are rare, and the trace's loop stays small without it.
    #[inline(never)]
    fn shape_hits_one_by_one(&self, slot: u32, rays: &RayLanes, t_max: F8) -> [f32; W] {
        let mut t = [f32::NAN; W];
        for (i, t) in t.iter_mut().enumerate() {
            let ray = Ray {
                o: rays.o.get(i),
                d: rays.d.get(i),
                t_min: rays.t_min.0[i],
                t_max: t_max.0[i],
            };
            *t = self.shape_hit(slot, &ray).unwrap_or(f32::NAN);
        }
        t
    }

    /// `f(nearest, block, lane, leaf slot)` for every lane of every leaf block that holds a
    /// triangle, except, with `cull`, in the blocks whose box none of the rays meets before
    /// its nearest hit so far (`t_now(nearest)`). The box test is the BVH's (its far
    /// distances widened against rounding), so a block is skipped only where the BVH would
    /// not look either, and the nearest hits are those of testing every triangle.
    #[inline(always)]
    fn for_each_triangle_seen<'a, N>(
        &'a self,
        rays: &RayLanes,
        cull: bool,
        nearest: &mut N,
        t_now: impl Fn(&N) -> F8,
        mut f: impl FnMut(&mut N, &'a TriBlock, usize, u32),
    ) {
        let boxes = (cull && !self.block_bounds.is_empty()).then(|| RayBoxLanes::new(rays));
        for (b, (block, info)) in self.blocks.iter().zip(&self.block_info).enumerate() {
            if let Some(boxes) = &boxes {
                if !boxes.meets(&self.block_bounds[b], t_now(nearest)) {
                    continue;
                }
            }
            for lane in 0..TRIS_PER_BLOCK {
                if (info.used & !info.shapes) & (1 << lane) != 0 {
                    f(nearest, block, lane, info.slot(lane));
                }
            }
        }
    }

    /// [`Scene::any_hit`] with the box test `boxes`.
    #[inline(always)]
    fn any_hit_with(&self, boxes: impl BoxTest<BVH_WIDTH>, ray: &Ray, kind: RayKind) -> bool {
        self.bvh.occluded_leaves_with(boxes, ray, |leaf, r| {
            let (first, count) = Bvh8::leaf_range(leaf);
            (first as usize..(first + count) as usize).any(|b| {
                let (triangles, shapes) = self.block_lanes(b, kind);
                self.blocks[b].hits(r, triangles) != 0
                    || (shapes != 0 && self.hits_shape(b, shapes, r))
            })
        })
    }
}

/// The most other shapes than triangles (spheres, voxels) a scene may have for
/// [`Scene::nearest_of_rays`]: a sphere costs a few triangles' tests (it is solved in `f64`),
/// and with 34 spheres in the Cornell box the BVH was 15% faster, with 18, 9% slower.
const SMALL_SCENE_SHAPES: u32 = 16;

/// The most blocks of primitives a scene may have for [`Scene::nearest_of_rays`] (64):
/// beyond a few dozen triangles the BVH culls more than testing them all costs.
pub(super) const SMALL_SCENE_BLOCKS: usize = 16;

/// The blocks of a scene's BVH: the primitives of each leaf packed into blocks of
/// [`TRIS_PER_BLOCK`] (the leaves' ranges renamed from leaf slots to blocks), what each
/// block's lanes hold, and where each triangle sits (`block · TRIS_PER_BLOCK + lane` of its
/// first copy; `u32::MAX` for a triangle the BVH left out).
pub(super) struct LeafBlocks {
    pub blocks: Vec<TriBlock>,
    pub info: Vec<BlockInfo>,
    pub tri_slot: Vec<u32>,
    /// The box of each block's triangles, where there are at most [`SMALL_SCENE_BLOCKS`]
    /// blocks (for [`Scene::nearest_of_rays`]); empty otherwise.
    pub bounds: Vec<Aabb>,
}

/// Packs the primitives of each of `bvh`'s leaves into blocks (see [`LeafBlocks`]).
pub(super) fn leaf_blocks(
    bvh: &mut Bvh8,
    prims: &[Prim],
    triangles: &[Triangle],
    visibility: &[Visibility],
) -> LeafBlocks {
    let mut blocks = Vec::with_capacity(prims.len() / 2 + 1);
    let mut info = Vec::with_capacity(prims.len() / 2 + 1);
    let mut tri_slot = vec![u32::MAX; triangles.len()];
    let mut bounds = Vec::new();
    bvh.remap_leaves(|start, count| {
        let first = blocks.len() as u32;
        for chunk_start in (start..start + count).step_by(TRIS_PER_BLOCK) {
            let chunk = chunk_start..(chunk_start + TRIS_PER_BLOCK as u32).min(start + count);
            let mut lanes = BlockInfo {
                first_slot: chunk_start,
                used: 0,
                shapes: 0,
                camera: 0,
                indirect: 0,
            };
            let mut tris = [Triangle { p: [Vec3::ZERO; 3] }; TRIS_PER_BLOCK];
            let mut block_box = Aabb::EMPTY;
            for (lane, slot) in chunk.enumerate() {
                lanes.used |= 1 << lane;
                match prims[slot as usize] {
                    Prim::Triangle(t) => {
                        tris[lane] = triangles[t as usize];
                        block_box = block_box.union(tris[lane].bounds());
                        if tri_slot[t as usize] == u32::MAX {
                            tri_slot[t as usize] = (blocks.len() * TRIS_PER_BLOCK + lane) as u32;
                        }
                    }
                    Prim::Sphere(_) | Prim::Voxel(_) => lanes.shapes |= 1 << lane,
                }
                let v = visibility[slot as usize];
                lanes.camera |= u8::from(v.camera) << lane;
                lanes.indirect |= u8::from(v.indirect) << lane;
            }
            blocks.push(TriBlock::new(&tris));
            info.push(lanes);
            if blocks.len() <= SMALL_SCENE_BLOCKS {
                bounds.push(block_box);
            }
        }
        (first, blocks.len() as u32 - first)
    });
    if blocks.len() > SMALL_SCENE_BLOCKS {
        bounds = Vec::new();
    }
    LeafBlocks {
        blocks,
        info,
        tri_slot,
        bounds,
    }
}

#[cfg(test)]
mod tests;
