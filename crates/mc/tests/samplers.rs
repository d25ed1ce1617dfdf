//! Samplers: reproducibility, uniformity, stratification.

mod common;

use common::assert_fits;
use glam::Vec2;
use pathlab_mc::sampler::*;
use pathlab_mc::stats::chi2_test_2d;

fn kinds() -> [SamplerKind; 3] {
    SamplerKind::ALL
}

/// The first `dims` numbers of a pixel sample, taken as 1D values.
fn sample_values(s: &mut AnySampler, pixel: [u32; 2], index: u32, dims: u32) -> Vec<f32> {
    s.start_pixel_sample(pixel, index, 0);
    (0..dims).map(|_| s.next_1d()).collect()
}

#[test]
fn values_depend_only_on_seed_pixel_index_dimension() {
    for kind in kinds() {
        let mut a = kind.build(64, 99);
        let mut b = kind.build(64, 99);
        // Visit in different orders; the values must agree.
        let forward: Vec<Vec<f32>> = (0..64)
            .map(|i| sample_values(&mut a, [3, 5], i, 6))
            .collect();
        let mut backward: Vec<Vec<f32>> = (0..64)
            .rev()
            .map(|i| sample_values(&mut b, [3, 5], i, 6))
            .collect();
        backward.reverse();
        assert_eq!(forward, backward, "{kind:?}");
        // Starting at a later dimension gives that dimension's value.
        b.start_pixel_sample([3, 5], 17, 4);
        assert_eq!(b.next_1d(), forward[17][4], "{kind:?}");
        // Another seed or pixel gives other values.
        let mut c = kind.build(64, 100);
        assert_ne!(sample_values(&mut c, [3, 5], 0, 6), forward[0], "{kind:?}");
        assert_ne!(sample_values(&mut a, [5, 3], 0, 6), forward[0], "{kind:?}");
    }
}

#[test]
fn samplers_are_uniform() {
    // Pool the first 2D dimension pair over many pixels (64 samples each).
    for kind in kinds() {
        let mut s = kind.build(64, 7);
        let mut pts = Vec::new();
        for px in 0..4096u32 {
            for i in 0..64 {
                s.start_pixel_sample([px % 64, px / 64], i, 2);
                let p = s.next_2d();
                pts.push([p.x as f64, p.y as f64]);
            }
        }
        let t = chi2_test_2d(pts, |_, _| 1.0, [[0.0, 1.0], [0.0, 1.0]], [32, 32]);
        assert_fits(kind.name(), &t);
    }
}

#[test]
fn stratified_covers_every_stratum_once() {
    let mut s = StratifiedSampler::new(8, 4, true, 3);
    for dim in [0u32, 2, 6] {
        let mut seen2 = vec![0u32; 32];
        let mut seen1 = vec![0u32; 32];
        for i in 0..32 {
            s.start_pixel_sample([1, 2], i, dim);
            let p = s.next_2d();
            seen2[(p.y * 4.0) as usize * 8 + (p.x * 8.0) as usize] += 1;
            let u = s.next_1d();
            seen1[(u * 32.0) as usize] += 1;
        }
        assert!(
            seen2.iter().all(|&c| c == 1),
            "2D strata at dim {dim}: {seen2:?}"
        );
        assert!(
            seen1.iter().all(|&c| c == 1),
            "1D strata at dim {dim}: {seen1:?}"
        );
    }
}

#[test]
fn stratified_without_jitter_uses_centres() {
    let mut s = StratifiedSampler::new(2, 2, false, 1);
    s.start_pixel_sample([0, 0], 0, 0);
    let p = s.next_2d();
    assert!([0.25, 0.75].contains(&p.x) && [0.25, 0.75].contains(&p.y));
}

#[test]
fn permutation_element_is_a_permutation() {
    for n in [1u32, 2, 3, 7, 16, 100, 1000] {
        for seed in [0u32, 1, 0xdead_beef] {
            let mut seen = vec![false; n as usize];
            for i in 0..n {
                let p = permutation_element(i, n, seed) as usize;
                assert!(!seen[p], "n = {n}, seed = {seed}: {p} twice");
                seen[p] = true;
            }
        }
    }
}

#[test]
fn sobol_first_dimensions_form_nets() {
    // The first 2^k samples of dimensions (0, 1) have exactly one point in every elementary
    // interval of area 2^-k (a (0, k, 2)-net in base 2), for every pixel's scramble.
    let k = 6;
    let n = 1u32 << k;
    let mut s = SobolSampler::new(n, 5);
    for pixel in [[0, 0], [7, 3], [100, 200]] {
        let pts: Vec<Vec2> = (0..n)
            .map(|i| {
                s.start_pixel_sample(pixel, i, 0);
                s.next_2d()
            })
            .collect();
        for a in 0..=k {
            let (nx, ny) = (1usize << a, 1usize << (k - a));
            let mut cells = vec![0u32; n as usize];
            for p in &pts {
                cells[(p.y * ny as f32) as usize * nx + (p.x * nx as f32) as usize] += 1;
            }
            assert!(
                cells.iter().all(|&c| c == 1),
                "pixel {pixel:?}, {nx}x{ny} intervals"
            );
        }
    }
}

#[test]
fn sobol_beyond_table_limits_stays_in_range() {
    let mut s = SobolSampler::new(1, 5);
    for index in [65_535u32, 65_536, 1 << 20, u32::MAX] {
        s.start_pixel_sample([1, 1], index, 250);
        for _ in 0..20 {
            let v = s.next_1d();
            assert!((0.0..1.0).contains(&v));
        }
    }
}

#[test]
fn sampler_kind_parses() {
    assert_eq!("Sobol".parse::<SamplerKind>(), Ok(SamplerKind::Sobol));
    assert!("halton".parse::<SamplerKind>().is_err());
}

#[test]
fn eight_samplers_drawing_together_draw_what_each_draws_alone() {
    let mut rng = pathlab_mc::rng::Pcg32::new(3, 8);
    let dims = [1, 2, 1, 2, 1];
    for kind in kinds() {
        for round in 0..200 {
            let mut together: [AnySampler; PATH_LANES] = std::array::from_fn(|_| kind.build(64, 5));
            for s in &mut together {
                let pixel = [rng.next_u32() % 7, rng.next_u32() % 5];
                let index = if round % 10 == 0 {
                    rng.next_u32()
                } else {
                    rng.next_u32() % 64
                };
                s.start_pixel_sample(pixel, index, rng.next_u32() % 40);
            }
            let mut alone = together.clone();
            let lanes = rng.next_u32() & 0xff;
            let mut out = [[0.0; PATH_LANES]; 7];
            AnySampler::next_lanes(&mut together, lanes, &dims, &mut out);
            for (lane, s) in alone.iter_mut().enumerate() {
                if lanes & (1 << lane) == 0 {
                    continue;
                }
                let mut expected = Vec::new();
                for &n in &dims {
                    if n == 1 {
                        expected.push(s.next_1d());
                    } else {
                        let v = s.next_2d();
                        expected.extend([v.x, v.y]);
                    }
                }
                let got: Vec<f32> = out.iter().map(|row| row[lane]).collect();
                assert_eq!(got, expected, "{kind:?} lane {lane}");
            }
            // Every sampler stands where drawing alone left it (idle lanes where they were).
            for (a, b) in together.iter_mut().zip(&mut alone) {
                assert_eq!(a.next_2d(), b.next_2d(), "{kind:?}");
            }
        }
    }
}
