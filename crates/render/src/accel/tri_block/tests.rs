//! Every lane of a block against the one-triangle test, to the bit.

use super::*;
use glam::Vec3;
use pathlab_mc::rng::Pcg32;

fn random_point(rng: &mut Pcg32) -> Vec3 {
    Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 2.0 - 1.0
}

fn random_triangles(rng: &mut Pcg32, n: usize) -> Vec<Triangle> {
    (0..n)
        .map(|_| Triangle {
            p: [random_point(rng), random_point(rng), random_point(rng)],
        })
        .collect()
}

#[test]
fn agrees_with_the_scalar_test_to_the_bit() {
    let mut rng = Pcg32::new(3, 5);
    for round in 0..20_000 {
        let n = round % (TRIS_PER_BLOCK + 1);
        let mut tris = random_triangles(&mut rng, n);
        if n > 1 && round % 7 == 0 {
            // Equal distances in two lanes, and a degenerate triangle.
            tris[1] = tris[0];
            tris[n - 1].p[2] = tris[n - 1].p[1];
        }
        let block = TriBlock::new(&tris);
        let o = random_point(&mut rng) * 3.0;
        let d = random_point(&mut rng) - o * 0.3;
        let ray = Ray {
            t_min: if round % 3 == 0 { 0.5 } else { 0.0 },
            t_max: if round % 5 == 0 { 1.5 } else { f32::INFINITY },
            ..Ray::new(o, d)
        };
        let lanes = if round % 11 == 0 { 0b0101 } else { 0b1111 };
        let mut scalar: Option<BlockHit> = None;
        let mut r = ray;
        for (lane, tri) in tris.iter().enumerate() {
            if lanes & (1 << lane) == 0 {
                continue;
            }
            if let Some(h) = tri.intersect(&r) {
                r.t_max = h.t;
                scalar = Some(BlockHit {
                    lane,
                    t: h.t,
                    b1: h.b1,
                    b2: h.b2,
                });
            }
        }
        assert_eq!(block.intersect(&ray, lanes), scalar, "round {round}");
        let any: u32 = tris
            .iter()
            .enumerate()
            .map(|(lane, tri)| u32::from(tri.intersect(&ray).is_some()) << lane)
            .sum();
        assert_eq!(block.hits(&ray, lanes), any & lanes);
    }
}

#[cfg(target_arch = "x86_64")]
#[test]
fn sse_and_lane_loops_give_the_same_bits() {
    let mut rng = Pcg32::new(11, 2);
    let bits = |a: [f32; TRIS_PER_BLOCK]| a.map(f32::to_bits);
    let specials = [0.0, -0.0, f32::INFINITY, f32::NAN, 1e-30];
    for round in 0..20_000 {
        let tris = random_triangles(&mut rng, round % (TRIS_PER_BLOCK + 1));
        let block = TriBlock::new(&tris);
        let o = random_point(&mut rng) * 3.0;
        let mut d = random_point(&mut rng) - o * 0.3;
        if round % 13 == 0 {
            // Zero, infinite, NaN and tiny components.
            d[round % 3] = specials[(round / 13) % specials.len()];
        }
        let ray = Ray {
            t_min: if round % 3 == 0 { 0.5 } else { 0.0 },
            t_max: if round % 5 == 0 { 1.5 } else { f32::INFINITY },
            ..Ray::new(o, d)
        };
        let (a, b) = (block.test_sse(&ray), block.test_lanes(&ray));
        assert_eq!(a.mask, b.mask, "round {round}");
        assert_eq!(bits(a.t), bits(b.t), "round {round}");
        assert_eq!(bits(a.b1), bits(b.b1), "round {round}");
        assert_eq!(bits(a.b2), bits(b.b2), "round {round}");
    }
}

#[test]
fn unused_lanes_and_bad_rays_never_hit() {
    let tri = Triangle {
        p: [Vec3::ZERO, Vec3::X, Vec3::Y],
    };
    let block = TriBlock::new(&[tri]);
    let through = Ray::new(Vec3::new(0.2, 0.2, -1.0), Vec3::Z);
    assert_eq!(block.hits(&through, 0b1111), 0b0001);
    for (o, d) in [
        (Vec3::splat(f32::NAN), Vec3::Z),
        (
            Vec3::new(0.2, 0.2, -1.0),
            Vec3::new(0.0, f32::INFINITY, 1.0),
        ),
        (Vec3::new(0.2, 0.2, -1.0), Vec3::ZERO),
    ] {
        assert_eq!(block.hits(&Ray::new(o, d), 0b1111), 0);
    }
}
