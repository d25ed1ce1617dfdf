//! Micro-benchmarks of the renderer's hot paths, so that regressions show: the ray–triangle
//! test, closest-hit and any-hit traversal of the 4-wide BVH (and the binary one it replaced),
//! BSDF sampling, the samplers, and an environment map's light samples and lookups.
//! `cargo bench -p pathlab-render`. Not tests.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use glam::{Vec2, Vec3};
use pathlab_mc::rng::Pcg32;
use pathlab_mc::sampler::{AnySampler, Sampler, SamplerKind};
use pathlab_render::accel::{Bvh, Bvh4, BvhParams, TriBlock};
use pathlab_render::bsdf::{Bxdf, Conductor, Microfacet, NormalDistribution, RoughDielectric};
use pathlab_render::geometry::Ray;
use pathlab_render::shape::Triangle;
use pathlab_render::simd::lanes::F8;

/// A bumpy sphere of about `n` triangles.
fn mesh(n: usize) -> Vec<Triangle> {
    let rings = ((n / 2) as f32).sqrt() as usize;
    let segs = n / (2 * rings);
    let point = |i: usize, j: usize| {
        let (th, ph) = (
            std::f32::consts::PI * i as f32 / rings as f32,
            std::f32::consts::TAU * j as f32 / segs as f32,
        );
        let r = 1.0 + 0.05 * (7.0 * th).sin() * (5.0 * ph).cos();
        r * Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin())
    };
    let mut tris = Vec::new();
    for i in 0..rings {
        for j in 0..segs {
            let (a, b, c, d) = (
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            );
            tris.push(Triangle { p: [a, b, c] });
            tris.push(Triangle { p: [a, c, d] });
        }
    }
    tris
}

/// Rays from a sphere of radius 3 towards random points near the mesh.
fn rays(n: usize) -> Vec<Ray> {
    let mut rng = Pcg32::new(7, 7);
    let mut u = || Vec2::new(rng.uniform_f32(), rng.uniform_f32());
    (0..n)
        .map(|_| {
            let o = 3.0 * pathlab_mc::warp::sample_uniform_sphere(u());
            let target = 0.8 * pathlab_mc::warp::sample_uniform_sphere(u());
            Ray::new(o, (target - o).normalize())
        })
        .collect()
}

fn traversal(c: &mut Criterion) {
    let tris = mesh(100_000);
    let bounds: Vec<_> = tris.iter().map(|t| t.bounds()).collect();
    let rays = rays(4096);
    let hit = |i: u32, r: &mut Ray| match tris[i as usize].intersect(r) {
        Some(h) => {
            r.t_max = h.t;
            true
        }
        None => false,
    };
    let wide = Bvh4::build(&bounds, BvhParams::default());
    let binary = Bvh::build(&bounds, BvhParams::default());
    c.bench_function("bvh4 closest hit, 4096 rays, 100k triangles", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| wide.intersect(&mut black_box(**r), hit).0)
                .count()
        })
    });
    c.bench_function("binary bvh closest hit, 4096 rays, 100k triangles", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| binary.intersect(&mut black_box(**r), hit).0)
                .count()
        })
    });
    c.bench_function("bvh4 any hit, 4096 rays, 100k triangles", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|r| {
                    wide.occluded(black_box(r), |i, r| tris[i as usize].intersect(r).is_some())
                })
                .count()
        })
    });
    c.bench_function("bvh4 build, 100k triangles", |b| {
        b.iter(|| Bvh4::build(black_box(&bounds), BvhParams::default()))
    });
    let tri = tris[12345];
    let ray = Ray::new(
        Vec3::new(0.0, 0.0, 3.0),
        (tri.p[0] - Vec3::new(0.0, 0.0, 3.0)).normalize(),
    );
    let block = TriBlock::new(&tris[12344..12348]);
    c.bench_function("ray against a block of 4 triangles", |b| {
        b.iter(|| black_box(&block).intersect(black_box(&ray), 0b1111))
    });
    c.bench_function("ray-triangle test", |b| {
        b.iter(|| black_box(&tri).intersect(black_box(&ray)))
    });
}

fn bsdfs(c: &mut Criterion) {
    let ggx = Bxdf::Conductor(Conductor {
        specular: glam::Vec3::ONE,
        eta: Vec3::new(0.143, 0.374, 1.442),
        k: Vec3::new(3.983, 2.385, 1.603),
        distribution: Some(Microfacet::new(NormalDistribution::Ggx, 0.2)),
    });
    let glass = Bxdf::RoughDielectric(RoughDielectric {
        eta: 1.5,
        distribution: Microfacet::new(NormalDistribution::Ggx, 0.15),
        reflectance: Vec3::ONE,
        transmittance: Vec3::ONE,
    });
    let wo = Vec3::new(0.5, 0.1, 0.8).normalize();
    let mut rng = Pcg32::new(3, 3);
    let us: Vec<(f32, Vec2)> = (0..1024)
        .map(|_| {
            (
                rng.uniform_f32(),
                Vec2::new(rng.uniform_f32(), rng.uniform_f32()),
            )
        })
        .collect();
    for (name, bxdf) in [("GGX conductor", ggx), ("GGX rough glass", glass)] {
        c.bench_function(&format!("{name} sample, 1024 draws"), |b| {
            b.iter(|| {
                us.iter()
                    .filter_map(|&(uc, u)| bxdf.sample(black_box(wo), uc, u))
                    .count()
            })
        });
    }
}

fn samplers(c: &mut Criterion) {
    for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
        let mut s: AnySampler = kind.build(64, 1);
        c.bench_function(&format!("{} sampler, 64 x 16 2D draws", kind.name()), |b| {
            b.iter(|| {
                let mut acc = Vec2::ZERO;
                for i in 0..64 {
                    s.start_pixel_sample([3, 4], i, 0);
                    for _ in 0..16 {
                        acc += s.next_2d();
                    }
                }
                acc
            })
        });
    }
    // A new pixel's first sample: the stream's hash and its jump to the sample.
    c.bench_function("pixel sample generator, 64 pixels", |b| {
        b.iter(|| {
            let mut acc = 0u32;
            for i in 0..64u32 {
                let mut rng = Pcg32::for_pixel_sample(1, [i, 7], black_box(37), 0);
                acc = acc.wrapping_add(rng.next_u32());
            }
            acc
        })
    });
}

/// A 512 × 256 sky: a gradient from the horizon up and a small sun of radiance 5,000.
fn sky() -> pathlab_render::envmap::EnvironmentMap {
    let (w, h) = (512, 256);
    let sun = Vec3::new(0.3, 0.8, -0.5).normalize();
    let texels = (0..w * h)
        .map(|k| {
            let d = pathlab_render::envmap::EnvironmentMap::grid_direction(k % w, k / w, w, h);
            let up = d.y.max(0.0);
            let near_sun = if d.dot(sun) > 0.9995 { 5000.0 } else { 0.0 };
            Vec3::new(0.3 + up, 0.5 + up, 1.0) + Vec3::splat(near_sun)
        })
        .collect();
    pathlab_render::envmap::EnvironmentMap::new(texels, w, h, glam::Mat3::IDENTITY, 1.0)
        .expect("a valid map")
}

fn environment_map(c: &mut Criterion) {
    let map = sky();
    let mut rng = Pcg32::new(5, 1);
    let us: Vec<Vec2> = (0..1024)
        .map(|_| Vec2::new(rng.uniform_f32(), rng.uniform_f32()))
        .collect();
    c.bench_function("environment map sample, 1024 draws", |b| {
        b.iter(|| us.iter().filter_map(|&u| map.sample(black_box(u))).count())
    });
    c.bench_function("environment map sample in lanes, 1024 draws", |b| {
        b.iter(|| {
            us.chunks_exact(8)
                .map(|u| {
                    let lanes = [0, 1].map(|k| F8(std::array::from_fn(|i| u[i][k])));
                    map.sample_direction_lanes(black_box(lanes), 0xff).pdf.0[3]
                })
                .sum::<f32>()
        })
    });
    // Draws spread over the whole table, as a render's are: the rows a lane reads are then
    // mostly out of the first-level caches, as they are there.
    let many: Vec<F8> = (0..2 * 65536 / 8)
        .map(|_| F8(std::array::from_fn(|_| rng.uniform_f32())))
        .collect();
    c.bench_function(
        "environment map sample in lanes, 65536 distinct draws",
        |b| {
            b.iter(|| {
                many.chunks_exact(2)
                    .map(|u| {
                        map.sample_direction_lanes(black_box([u[0], u[1]]), 0xff)
                            .pdf
                            .0[3]
                    })
                    .sum::<f32>()
            })
        },
    );
    let ws: Vec<Vec3> = us
        .iter()
        .map(|u| pathlab_mc::warp::sample_uniform_sphere(*u))
        .collect();
    c.bench_function("environment map radiance and pdf, 1024 directions", |b| {
        b.iter(|| {
            ws.iter()
                .map(|&w| map.eval_and_pdf(black_box(w)).1)
                .sum::<f32>()
        })
    });
}

criterion_group!(benches, traversal, bsdfs, samplers, environment_map);
criterion_main!(benches);
