//! Tests of the scene's ray tracing: the BVH against testing every primitive, at every SIMD
//! level.

use super::*;
use crate::desc::{MeshDesc, SceneDesc};
use crate::scene::diffuse;
use crate::shape::Sphere;

/// Nearest distance along `ray` by testing every shape the ray kind sees.
fn brute_force(desc: &SceneDesc, ray: &Ray, kind: RayKind) -> Option<f32> {
    let mut best: Option<f32> = None;
    let mut r = *ray;
    for m in &desc.meshes {
        if !m.visibility.seen_by(kind) {
            continue;
        }
        for f in m.indices.chunks(3) {
            let tri = Triangle {
                p: [0, 1, 2].map(|k| m.positions[f[k] as usize]),
            };
            if let Some(h) = tri.intersect(&r) {
                r.t_max = h.t;
                best = Some(h.t);
            }
        }
    }
    for s in &desc.spheres {
        let sphere = Sphere {
            center: s.center,
            radius: s.radius,
        };
        if let Some(t) = sphere.intersect(&r) {
            r.t_max = t;
            best = Some(t);
        }
    }
    for g in &desc.sdf_grids {
        let grid = crate::sdf_grid::SdfGrid::new(g).unwrap();
        for (corner, _) in grid.occupied_voxels(&g.to_world) {
            if let Some(t) = grid.intersect_voxel(corner, &r) {
                r.t_max = t;
                best = Some(t);
            }
        }
    }
    best
}

/// A torus's signed distance sampled on an `n`³ grid over the unit cube.
fn torus_grid(n: u32, to_world: glam::Affine3A) -> crate::desc::SdfGridDesc {
    let mut values = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let p = Vec3::new(x as f32, y as f32, z as f32) / (n - 1) as f32 - 0.5;
                let ring = glam::Vec2::new(glam::Vec2::new(p.x, p.z).length() - 0.3, p.y);
                values.push(ring.length() - 0.1);
            }
        }
    }
    crate::desc::SdfGridDesc {
        values,
        resolution: [n; 3],
        to_world,
        smooth_normals: true,
        material: 0,
    }
}

#[test]
fn simd_traversal_finds_what_testing_every_shape_finds() {
    // Two triangle soups (one hidden from camera rays), spheres and SDF grids among them,
    // so that blocks mix triangles, other shapes and visibilities.
    let mut rng = pathlab_mc::rng::Pcg32::new(21, 3);
    let mut point = || Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
    let soup = |point: &mut dyn FnMut() -> Vec3, n: usize, visibility| {
        let mut positions = Vec::new();
        for _ in 0..n {
            let c = point() * 10.0;
            positions.extend([c, c + point() - 0.5, c + point() - 0.5]);
        }
        MeshDesc {
            name: "soup".into(),
            indices: (0..positions.len() as u32).collect(),
            positions,
            visibility,
            ..Default::default()
        }
    };
    let hidden = Visibility {
        camera: false,
        indirect: true,
    };
    let desc = SceneDesc {
        meshes: vec![
            soup(&mut point, 300, Visibility::ALL),
            soup(&mut point, 100, hidden),
        ],
        spheres: (0..20)
            .map(|_| crate::desc::SphereDesc {
                center: point() * 10.0,
                radius: 0.2,
                material: 0,
                emission: None,
                ..Default::default()
            })
            .collect(),
        sdf_grids: vec![
            torus_grid(
                24,
                glam::Affine3A::from_scale_rotation_translation(
                    Vec3::new(3.0, 2.0, 2.5),
                    glam::Quat::from_rotation_y(0.7),
                    Vec3::new(4.0, 5.0, 3.0),
                ),
            ),
            torus_grid(16, glam::Affine3A::from_translation(Vec3::splat(6.0))),
        ],
        materials: vec![diffuse(Vec3::ONE, false)],
        resolution: [4, 4],
        ..Default::default()
    };
    let scene = Scene::build(&desc).unwrap();
    agrees_with_testing_every_shape(&scene, &desc, &mut point);
}

/// Checks 3000 rays from `point` (camera and indirect, nearest and any hit) against testing
/// every shape.
fn agrees_with_testing_every_shape(
    scene: &Scene,
    desc: &SceneDesc,
    point: &mut dyn FnMut() -> Vec3,
) {
    let mut hits = 0;
    for k in 0..3000 {
        let o = point() * 14.0 - 2.0;
        let ray = Ray::new(o, point() * 10.0 - o);
        let kind = if k % 2 == 0 {
            RayKind::Camera
        } else {
            RayKind::Indirect
        };
        let expected = brute_force(desc, &ray, kind);
        let mut r = ray;
        let portable = scene.closest_hit_with(Portable, &mut r, kind);
        assert_eq!(portable.found().then_some(r.t_max), expected);
        let found = match kind {
            RayKind::Camera => scene.intersect_camera(&ray).0,
            RayKind::Indirect => scene.intersect(&ray).0,
        };
        assert_eq!(found.map(|si| si.t), expected);
        if kind == RayKind::Indirect {
            assert_eq!(scene.occluded(&ray), expected.is_some());
            assert_eq!(
                scene.any_hit_with(Portable, &ray, RayKind::Indirect),
                expected.is_some()
            );
        }
        hits += usize::from(expected.is_some());
    }
    assert!(hits > 300, "{hits} rays hit");
}

#[test]
fn spatial_splits_find_what_testing_every_shape_finds() {
    // Small triangles among large ones that cross the whole scene (walls of a room), enough
    // of them for spatial splits to cut the large ones; a sphere among them.
    let mut rng = pathlab_mc::rng::Pcg32::new(23, 5);
    let mut point = || Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
    let mut positions = Vec::new();
    for _ in 0..6000 {
        let c = point() * 10.0;
        positions.extend([c, c + (point() - 0.5) * 0.3, c + (point() - 0.5) * 0.3]);
    }
    for k in 0..30 {
        let (a, b) = (point() * 12.0 - 1.0, point() * 12.0 - 1.0);
        let mut c = point() * 10.0;
        c[k % 3] = if k % 2 == 0 { -1.0 } else { 11.0 };
        positions.extend([a, b, c]);
    }
    let desc = SceneDesc {
        meshes: vec![MeshDesc {
            name: "room".into(),
            indices: (0..positions.len() as u32).collect(),
            positions,
            ..Default::default()
        }],
        spheres: vec![crate::desc::SphereDesc {
            center: Vec3::splat(5.0),
            radius: 2.0,
            material: 0,
            emission: None,
            ..Default::default()
        }],
        materials: vec![diffuse(Vec3::ONE, false)],
        resolution: [4, 4],
        ..Default::default()
    };
    let scene = Scene::build(&desc).unwrap();
    // Some triangles sit in several leaves.
    assert!(scene.prims.len() > scene.tri_slot.len() + 1);
    agrees_with_testing_every_shape(&scene, &desc, &mut point);
}

/// A closed box of two-triangle quads with a smaller box inside: few enough triangles to
/// test them all, with shared edges and corners for rays to hit.
fn boxes() -> SceneDesc {
    let cube = |lo: Vec3, hi: Vec3| {
        let c = |i: u32| {
            Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let quads = [
            [0, 1, 3, 2],
            [4, 6, 7, 5],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 2, 6, 4],
            [1, 5, 7, 3],
        ];
        MeshDesc {
            name: "cube".into(),
            positions: (0..8).map(c).collect(),
            indices: quads
                .iter()
                .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
                .collect(),
            ..Default::default()
        }
    };
    SceneDesc {
        meshes: vec![
            cube(Vec3::splat(-1.0), Vec3::splat(1.0)),
            cube(Vec3::new(-0.5, -1.0, -0.3), Vec3::new(0.2, 0.1, 0.4)),
        ],
        materials: vec![diffuse(Vec3::ONE, true)],
        resolution: [4, 4],
        ..Default::default()
    }
}

/// Whether the hit `(slot, t, b1, b2)` that eight rays tested together report for `ray` is
/// another primitive than the one the ray's own BVH walk found, `alone`: it must then be a
/// triangle at exactly the same distance (a shared edge); the same one, at the same
/// barycentrics.
fn is_tie(scene: &Scene, ray: &Ray, (slot, t, b1, b2): (u32, f32, f32, f32), alone: &Hit) -> bool {
    if slot == alone.slot() {
        assert_eq!((b1, b2), alone.barycentrics());
        return false;
    }
    let Prim::Triangle(i) = scene.prims[slot as usize].get() else {
        panic!("a shape other than the BVH's in slot {slot}")
    };
    let (block, lane) = scene.triangle_block(i);
    assert_eq!(block.intersect(ray, 1 << lane).map(|h| h.t), Some(t));
    true
}

/// Rays from inside and outside the boxes against `scene` by testing every primitive (at
/// every SIMD level) and by the BVH: the same distances, and the same primitive but for
/// ties (another triangle at exactly the same distance). Returns (hits, ties of rays not
/// aimed at a corner or an edge, sphere hits), each counted once per ray.
fn every_primitive_agrees_with_the_bvh(scene: &Scene, seed: u64) -> (usize, usize, usize) {
    assert!(scene.tests_every_primitive());
    let mut rng = pathlab_mc::rng::Pcg32::new(seed, 1);
    let mut point = || Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
    let (mut hits, mut ties, mut spheres) = (0, 0, 0);
    let mut culled = 0;
    for k in 0..2000 {
        let mut rays = RayLanes::default();
        let mut t_max = F8::splat(f32::INFINITY);
        let mut each = [Ray::new(Vec3::ZERO, Vec3::X); 8];
        // Every other packet goes one way: eight rays from one point towards points close
        // together, as a pixel's camera rays (the packets whose boxes culling skips).
        let (shared_o, shared_target) = (point() * 3.0 - 1.5, point() * 2.0 - 1.0);
        for (i, ray) in each.iter_mut().enumerate() {
            // Origins inside and outside the boxes, some rays aimed at corners and edges
            // (where triangles meet), some with a finite extent.
            let o = if k % 2 == 0 {
                shared_o
            } else {
                point() * 3.0 - 1.5
            };
            let target = match (k + i) % 3 {
                _ if k % 2 == 0 => shared_target + (point() - 0.5) * 0.05,
                0 => point() * 2.0 - 1.0,
                1 => point().round() * 2.0 - 1.0,
                _ => Vec3::new(point().x * 2.0 - 1.0, 1.0, -1.0),
            };
            *ray = Ray::new(o, target - o);
            if i % 4 == 3 {
                ray.t_max = 0.5;
            }
            rays.set(i, ray);
            t_max.0[i] = ray.t_max;
        }
        // Every SIMD level, with and without culling blocks, finds the same.
        let mut levels = scene.nearest_of_rays_each_level(&rays, t_max, false);
        levels.extend(scene.nearest_of_rays_each_level(&rays, t_max, true));
        let dispatched = scene.nearest_of_rays(&rays, t_max, true);
        let boxes = RayBoxLanes::new(&rays);
        culled += (scene.block_bounds.iter())
            .filter(|b| !boxes.meets(b, t_max))
            .count();
        for (i, ray) in each.iter().enumerate() {
            let mut r = *ray;
            let bvh = scene.closest_hit(&mut r, RayKind::Indirect);
            hits += usize::from(bvh.found());
            let lane = dispatched.lane(i);
            for (name, nearest) in &levels {
                assert_eq!(nearest.lane(i), lane, "{name} against the dispatched test");
            }
            assert_eq!(lane.map(|(_, t, _, _)| t), bvh.found().then_some(r.t_max));
            let Some(hit) = lane else {
                continue;
            };
            spheres += usize::from(matches!(scene.prims[hit.0 as usize].get(), Prim::Sphere(_)));
            // Rays aimed at the boxes' corners and edges meet several triangles at one
            // distance, and which of them each search reports depends on the order it tests
            // them in: their ties (still checked to be at exactly one distance) are not
            // counted.
            let at_edge = k % 2 == 1 && (k + i) % 3 != 0;
            ties += usize::from(is_tie(scene, ray, hit, &bvh) && !at_edge);
        }
    }
    assert!(
        culled > 1000,
        "{culled} blocks missed by all rays of a packet"
    );
    (hits, ties, spheres)
}

#[test]
fn testing_every_triangle_finds_what_the_bvh_finds() {
    let scene = Scene::build(&boxes()).unwrap();
    let (hits, ties, _) = every_primitive_agrees_with_the_bvh(&scene, 8);
    // Away from the boxes' corners and edges, rays rarely meet two triangles at one
    // distance (a quad's diagonal).
    assert!(
        hits > 10_000 && ties < hits / 100,
        "{hits} hits, {ties} ties"
    );
}

#[test]
fn testing_every_primitive_finds_the_spheres_the_bvh_finds() {
    // The boxes with two spheres, one inside the large box and one cutting its wall.
    let mut desc = boxes();
    desc.spheres = vec![
        crate::desc::SphereDesc {
            center: Vec3::new(0.5, 0.4, -0.2),
            radius: 0.3,
            ..Default::default()
        },
        crate::desc::SphereDesc {
            center: Vec3::new(-1.0, -0.6, 0.7),
            radius: 0.45,
            ..Default::default()
        },
    ];
    let scene = Scene::build(&desc).unwrap();
    assert!(!scene.only_triangles);
    let (hits, ties, spheres) = every_primitive_agrees_with_the_bvh(&scene, 9);
    assert!(
        hits > 10_000 && ties < hits / 100 && spheres > 500,
        "{hits} hits, {ties} ties, {spheres} on spheres"
    );
}

#[test]
fn every_simd_level_finds_the_same_triangles_to_the_bit() {
    // Each box twice (every triangle has a twin at exactly its distance, so which of
    // the two a ray keeps shows the order of the tests) and one triangle more, so that
    // the AVX-512 pairs end with an odd triangle.
    let mut desc = boxes();
    let twins: Vec<MeshDesc> = desc.meshes.clone();
    desc.meshes.extend(twins);
    desc.meshes.push(MeshDesc {
        name: "odd".into(),
        positions: vec![
            Vec3::new(-0.9, -0.9, 0.5),
            Vec3::new(0.9, -0.9, 0.5),
            Vec3::new(0.0, 0.9, 0.5),
        ],
        indices: vec![0, 1, 2],
        ..Default::default()
    });
    let scene = Scene::build(&desc).unwrap();
    assert!(scene.tests_every_primitive());
    assert_eq!(scene.tri_slot.len() % 2, 1);
    let mut rng = pathlab_mc::rng::Pcg32::new(11, 3);
    let mut point = || Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
    let bits = |n: &Nearest| [n.t, n.b1, n.b2, n.slot].map(|f| f.0.map(f32::to_bits));
    let mut hits = 0;
    for k in 0..3000 {
        let mut rays = RayLanes::default();
        let mut t_max = F8::splat(f32::INFINITY);
        for i in 0..8 {
            let o = point() * 3.0 - 1.5;
            let target = if (k + i) % 2 == 0 {
                point() * 2.0 - 1.0
            } else {
                point().round() * 2.0 - 1.0
            };
            rays.o.set(i, o);
            rays.d.set(i, target - o);
            rays.t_min.0[i] = if i % 3 == 0 { 1e-3 } else { 0.0 };
            if i % 4 == 3 {
                t_max.0[i] = 0.7;
            }
        }
        let mut all = scene.nearest_of_rays_each_level(&rays, t_max, false);
        all.extend(scene.nearest_of_rays_each_level(&rays, t_max, true));
        let (_, portable) = &all[0];
        for (name, n) in &all[1..] {
            assert_eq!(bits(n), bits(portable), "{name} against the portable lanes");
        }
        hits += (0..8).filter(|&i| portable.lane(i).is_some()).count();
    }
    assert!(hits > 15_000, "{hits} hits");
}

#[test]
fn packets_walking_the_bvh_find_what_each_ray_finds() {
    // The boxes and a few hundred random triangles (too many to test them all): eight rays
    // walking the BVH together, at every SIMD level, find each ray's own nearest distance,
    // and the same triangle but for ties. Packets from one point towards nearby points (a
    // pixel's camera rays), from spread points in one octant, and in every direction (which
    // no interval ray bounds: the rays walk alone); some lanes idle or with finite extents.
    let mut desc = boxes();
    let mut rng = pathlab_mc::rng::Pcg32::new(21, 5);
    let mut point = || Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
    let mut positions = Vec::new();
    for _ in 0..300 {
        let c = point() * 4.0 - 2.0;
        positions.extend([c, c + (point() - 0.5) * 0.4, c + (point() - 0.5) * 0.4]);
    }
    desc.meshes.push(MeshDesc {
        name: "soup".into(),
        indices: (0..positions.len() as u32).collect(),
        positions,
        ..Default::default()
    });
    let scene = Scene::build(&desc).unwrap();
    assert!(scene.traces_packets() && !scene.tests_every_primitive());
    let (mut hits, mut ties, mut bounded) = (0, 0, 0);
    for k in 0..3000 {
        let mut rays = RayLanes::default();
        let mut t_max = F8::splat(f32::INFINITY);
        let mut each = [Ray::new(Vec3::ZERO, Vec3::X); 8];
        let (o0, target) = (point() * 6.0 - 3.0, point() * 2.0 - 1.0);
        for (i, ray) in each.iter_mut().enumerate() {
            *ray = match k % 3 {
                0 => Ray::new(o0, target + (point() - 0.5) * 0.05 - o0),
                1 => {
                    let o = o0 + (point() - 0.5) * 0.5;
                    Ray::new(o, target + (point() - 0.5) * 0.3 - o)
                }
                _ => Ray::new(point() * 3.0 - 1.5, point() - 0.5),
            };
            if (k + i) % 5 == 4 {
                ray.t_max = 1.5;
            }
            if (k + i) % 7 == 6 {
                ray.t_min = 0.25;
            }
            rays.set(i, ray);
            // Some lanes idle.
            t_max.0[i] = if (k + i) % 11 == 10 {
                f32::NEG_INFINITY
            } else {
                ray.t_max
            };
        }
        let active = (0..8).fold(0u32, |m, i| {
            m | u32::from(t_max.0[i] > f32::NEG_INFINITY) << i
        });
        bounded += usize::from(PacketBounds::new(&rays, active).is_some());
        let (dispatched, _) = scene.nearest_of_packet(&rays, t_max);
        let levels = scene.nearest_of_packet_each_level(&rays, t_max);
        for (i, ray) in each.iter().enumerate() {
            let lane = dispatched.lane(i);
            for (name, nearest) in &levels {
                assert_eq!(nearest.lane(i), lane, "{name} against the dispatched walk");
            }
            if active & (1 << i) == 0 {
                assert_eq!(lane, None, "an idle lane finds nothing");
                continue;
            }
            let mut r = *ray;
            let alone = scene.closest_hit(&mut r, RayKind::Indirect);
            hits += usize::from(alone.found());
            assert_eq!(
                lane.map(|(_, t, _, _)| t),
                alone.found().then_some(r.t_max),
                "packet {k}, ray {i}"
            );
            let Some(hit) = lane else {
                continue;
            };
            ties += usize::from(is_tie(&scene, ray, hit, &alone));
        }
    }
    assert!(hits > 8000, "only {hits} hits");
    assert!(
        bounded > 1500,
        "only {bounded} packets bounded by an interval ray"
    );
    assert!(ties < hits / 100, "{ties} ties of {hits} hits");
}
