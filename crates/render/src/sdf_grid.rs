//! Signed distance grids (Mitsuba's `sdfgrid`): a signed distance sampled on a regular grid
//! over the object-space unit cube, the surface being the zero set of its trilinear
//! interpolant. Each voxel the surface passes through is a primitive of the BVH; a ray meets
//! a voxel's surface where the interpolant, a cubic along the ray, first changes sign.
//!
//! The intersection follows Hansson-Söderlund, Evans and Akenine-Möller, "Ray Tracing of
//! Signed Distance Function Grids" (JCGT 11(3), 2022): the cubic's bracket is split at the
//! roots of its derivative, so that the first monotonic piece with a sign change holds the
//! nearest root, found by Newton's method safeguarded by bisection. Shading normals are the
//! interpolant's gradient (`analytic`) or that paper's blend of the gradients of the eight
//! voxels around the nearest grid vertex (`smooth`, continuous across voxels).

use crate::desc::SdfGridDesc;
use crate::geometry::{Aabb, Ray};
use glam::{Affine3A, Mat3, Vec3, Vec3A};

/// The iteration ends when a step moves the ray parameter less than this.
const SOLVE_EPSILON: f32 = 1e-5;
/// Most Newton / bisection steps per voxel.
const SOLVE_MAX_STEPS: u32 = 50;

/// A signed distance grid ready to trace.
#[derive(Clone, Debug)]
pub struct SdfGrid {
    /// Samples, x fastest, then y, then z.
    values: Vec<f32>,
    /// Samples per axis (at least 2).
    res: [u32; 3],
    /// Voxels per axis as floats (res - 1).
    cells: Vec3,
    to_object: Affine3A,
    /// Object-to-world for normals (the inverse transpose of the linear part).
    normal_to_world: Mat3,
    smooth: bool,
}

impl SdfGrid {
    /// The grid of `desc`, or why it cannot be traced.
    pub fn new(desc: &SdfGridDesc) -> Result<SdfGrid, String> {
        let [nx, ny, nz] = desc.resolution;
        if nx < 2 || ny < 2 || nz < 2 {
            return Err(format!(
                "an SDF grid needs at least 2 samples per axis, got {nx} x {ny} x {nz}"
            ));
        }
        let count = nx as u64 * ny as u64 * nz as u64;
        if desc.values.len() as u64 != count {
            return Err(format!(
                "an SDF grid of {nx} x {ny} x {nz} needs {count} samples, got {}",
                desc.values.len()
            ));
        }
        if desc.values.iter().any(|v| !v.is_finite()) {
            return Err("an SDF grid sample is not a finite number".into());
        }
        let det = desc.to_world.matrix3.determinant();
        if !(det.is_finite() && det != 0.0 && desc.to_world.translation.is_finite()) {
            return Err("an SDF grid's transform is not invertible".into());
        }
        let linear = Mat3::from(desc.to_world.matrix3);
        Ok(SdfGrid {
            values: desc.values.clone(),
            res: desc.resolution,
            cells: Vec3::new((nx - 1) as f32, (ny - 1) as f32, (nz - 1) as f32),
            to_object: desc.to_world.inverse(),
            normal_to_world: linear.inverse().transpose(),
            smooth: desc.smooth_normals,
        })
    }

    #[inline]
    fn index(&self, x: u32, y: u32, z: u32) -> usize {
        ((z as usize * self.res[1] as usize) + y as usize) * self.res[0] as usize + x as usize
    }

    /// The sample at integer grid position `q`, clamped to the grid.
    #[inline]
    fn sample(&self, q: [i64; 3]) -> f32 {
        let c = |a: usize| q[a].clamp(0, self.res[a] as i64 - 1) as u32;
        self.values[self.index(c(0), c(1), c(2))]
    }

    /// The eight samples of voxel `v` (its lower corner), indexed x + 2y + 4z.
    fn corners(&self, v: [u32; 3]) -> [f32; 8] {
        std::array::from_fn(|i| {
            self.values[self.index(
                v[0] + (i as u32 & 1),
                v[1] + ((i as u32 >> 1) & 1),
                v[2] + (i as u32 >> 2),
            )]
        })
    }

    /// The lower corners of the voxels the surface passes through (some corner ≤ 0 and
    /// some ≥ 0), with tight world-space boxes around the surface's part in each: the box
    /// of the corners on the surface and of the points where it crosses the voxel's edges
    /// (the interpolant is linear along edges, and its zero set within a voxel lies in the
    /// box of those points), slightly padded.
    pub fn occupied_voxels(&self, to_world: &Affine3A) -> Vec<([u32; 3], Aabb)> {
        let mut out = Vec::new();
        for z in 0..self.res[2] - 1 {
            for y in 0..self.res[1] - 1 {
                for x in 0..self.res[0] - 1 {
                    let f = self.corners([x, y, z]);
                    let any_neg = f.iter().any(|&v| v <= 0.0);
                    let any_pos = f.iter().any(|&v| v >= 0.0);
                    if !(any_neg && any_pos) {
                        continue;
                    }
                    let corner = |i: usize| {
                        Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32)
                    };
                    let (mut lo, mut hi) = (Vec3::ONE, Vec3::ZERO);
                    for (i, &fi) in f.iter().enumerate() {
                        if fi == 0.0 {
                            lo = lo.min(corner(i));
                            hi = hi.max(corner(i));
                        }
                        for axis in 0..3 {
                            if i & (1 << axis) != 0 {
                                continue;
                            }
                            let fj = f[i | (1 << axis)];
                            if fi * fj <= 0.0 && fi != fj {
                                let mut p = corner(i);
                                p[axis] = fi / (fi - fj);
                                lo = lo.min(p);
                                hi = hi.max(p);
                            }
                        }
                    }
                    if lo.x > hi.x {
                        continue;
                    }
                    let v = Vec3::new(x as f32, y as f32, z as f32);
                    let mut b = Aabb::EMPTY;
                    for i in 0..8 {
                        let c = Vec3::select(
                            glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0),
                            hi,
                            lo,
                        );
                        b = b.grow(to_world.transform_point3((c + v) / self.cells));
                    }
                    let extent = to_world.matrix3 * Vec3A::from(Vec3::ONE / self.cells);
                    let pad = Vec3::from(extent.abs()) * 1e-3
                        + b.min.abs().max(b.max.abs()) * (8.0 * f32::EPSILON);
                    out.push((
                        [x, y, z],
                        Aabb {
                            min: b.min - pad,
                            max: b.max + pad,
                        },
                    ));
                }
            }
        }
        out
    }

    /// The nearest distance within `ray`'s extent at which it meets the surface inside voxel
    /// `v`.
    pub fn intersect_voxel(&self, v: [u32; 3], ray: &Ray) -> Option<f32> {
        // In voxel space the voxel is the unit cube; the direction is scaled, not normalised,
        // so distances along the ray keep their meaning.
        let vf = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
        let o = self.to_object.transform_point3(ray.o) * self.cells - vf;
        let d = self.to_object.transform_vector3(ray.d) * self.cells;
        let inv = d.recip();
        let (mut t0, mut t1) = (ray.t_min.max(0.0), ray.t_max);
        let (mut entry, mut exit) = (None, None);
        for a in 0..3 {
            let (mut near, mut far) = ((0.0 - o[a]) * inv[a], (1.0 - o[a]) * inv[a]);
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            // A ray in a face's plane gives NaN: it counts as inside that slab.
            if near > t0 {
                t0 = near;
                entry = Some(a);
            }
            if far < t1 {
                t1 = far;
                exit = Some(a);
            }
        }
        // NaN (a degenerate ray) fails too.
        if t0.partial_cmp(&t1) != Some(std::cmp::Ordering::Less) {
            return None;
        }
        let s = self.corners(v);
        // The values where the ray enters and leaves, with the crossed face's coordinate set
        // exactly: neighbouring voxels then agree on their shared face, and a surface close
        // to it is found by one of them.
        let at = |t: f32, face: Option<usize>, entering: bool| {
            let mut p = (o + d * t).clamp(Vec3::ZERO, Vec3::ONE);
            if let Some(a) = face {
                p[a] = if (d[a] >= 0.0) == entering { 0.0 } else { 1.0 };
            }
            trilerp(&s, p)
        };
        let (f0, f1) = (at(t0, entry, true), at(t1, exit, false));
        let cubic = Cubic::along(&s, o + d * t0, d);
        cubic.first_root(t1 - t0, f0, f1).map(|t| t + t0)
    }

    /// The geometric and shading normals (unit, world space) at world point `p` on the
    /// surface in voxel `v`.
    pub fn normals(&self, v: [u32; 3], p: Vec3) -> (Vec3, Vec3) {
        let local = self.to_object.transform_point3(p);
        let vf = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
        let w = (local * self.cells - vf).clamp(Vec3::ZERO, Vec3::ONE);
        let grad = trilerp_grad(&self.corners(v), w) * self.cells;
        let ng = (self.normal_to_world * grad).normalize_or(Vec3::Z);
        if !self.smooth {
            return (ng, ng);
        }
        let ns = (self.normal_to_world * self.smooth_gradient(local))
            .try_normalize()
            .unwrap_or(ng);
        (ng, ns)
    }

    /// The smooth normal's direction at object-space point `p`: the gradients of the eight
    /// voxels around the grid vertex nearest `p`, each a finite difference of the interpolant
    /// across the voxel along each axis, normalised and blended trilinearly by where `p` lies
    /// between those voxels' centres. Voxels outside the grid get no weight.
    fn smooth_gradient(&self, p: Vec3) -> Vec3 {
        let scaled = p * self.cells;
        let n = self.res.map(|r| r as i64);
        // Lower corner of the 2 x 2 x 2 voxels around the nearest vertex, and p relative to
        // their centres.
        let v: [i64; 3] = std::array::from_fn(|a| scaled[a].round() as i64 - 1);
        let mut uvw = Vec3::from_array(std::array::from_fn(|a| scaled[a] - v[a] as f32 - 0.5));
        // The cell holding p, and p within it.
        let cell: [i64; 3] = std::array::from_fn(|a| (scaled[a].floor() as i64).clamp(0, n[a] - 2));
        let w = Vec3::from_array(std::array::from_fn(|a| scaled[a] - cell[a] as f32));
        // The interpolant on the sample plane q along axis a, at p's other two coordinates.
        let plane = |a: usize, q: i64| {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            let f: [f32; 4] = std::array::from_fn(|i| {
                let mut idx = [0i64; 3];
                idx[a] = q;
                idx[b] = cell[b] + (i & 1) as i64;
                idx[c] = cell[c] + (i >> 1) as i64;
                self.sample(idx)
            });
            bilerp(&f, w[b], w[c])
        };
        // Differences across the lower (d0) and upper (d1) voxel along each axis: one spans
        // p's cell, the other reaches the next sample plane on the other voxel's side.
        let (mut d0, mut d1) = (Vec3::ZERO, Vec3::ZERO);
        for a in 0..3 {
            let upper = cell[a] != v[a];
            let g0 = plane(a, cell[a]);
            let g1 = plane(a, cell[a] + 1);
            let gq = plane(a, cell[a] + if upper { -1 } else { 2 });
            let across_cell = g1 - g0;
            let beside = if upper { g0 - gq } else { gq - g1 };
            d0[a] = if upper { beside } else { across_cell } * self.cells[a];
            d1[a] = if upper { across_cell } else { beside } * self.cells[a];
        }
        let inside: [bool; 3] = std::array::from_fn(|a| v[a] >= 0);
        for a in 0..3 {
            if !inside[a] {
                uvw[a] = 1.0;
            }
        }
        let corner = |i: usize| {
            let hi = [i & 1 != 0, i & 2 != 0, i & 4 != 0];
            if (0..3).all(|a| hi[a] || inside[a]) {
                Vec3::from_array(std::array::from_fn(|a| if hi[a] { d1[a] } else { d0[a] }))
                    .normalize_or_zero()
            } else {
                Vec3::ZERO
            }
        };
        let lerp = |a: Vec3, b: Vec3, t: f32| a + (b - a) * t;
        lerp(
            lerp(
                lerp(corner(0), corner(1), uvw.x),
                lerp(corner(2), corner(3), uvw.x),
                uvw.y,
            ),
            lerp(
                lerp(corner(4), corner(5), uvw.x),
                lerp(corner(6), corner(7), uvw.x),
                uvw.y,
            ),
            uvw.z,
        )
    }
}

/// `f` (indexed u + 2v) interpolated bilinearly at (u, v); exact at 0 and 1.
#[inline]
fn bilerp(f: &[f32; 4], u: f32, v: f32) -> f32 {
    let lerp = |a: f32, b: f32, t: f32| a * (1.0 - t) + b * t;
    lerp(lerp(f[0], f[1], u), lerp(f[2], f[3], u), v)
}

/// The corner values `f` (indexed x + 2y + 4z) interpolated trilinearly at `p` in the unit
/// cube.
#[inline]
fn trilerp(f: &[f32; 8], p: Vec3) -> f32 {
    let lo = bilerp(&[f[0], f[1], f[2], f[3]], p.x, p.y);
    let hi = bilerp(&[f[4], f[5], f[6], f[7]], p.x, p.y);
    lo * (1.0 - p.z) + hi * p.z
}

/// The gradient of [`trilerp`]: each partial derivative is the bilinear interpolant of the
/// differences along the four edges parallel to its axis.
#[inline]
fn trilerp_grad(f: &[f32; 8], p: Vec3) -> Vec3 {
    let dx = [f[1] - f[0], f[3] - f[2], f[5] - f[4], f[7] - f[6]];
    let dy = [f[2] - f[0], f[3] - f[1], f[6] - f[4], f[7] - f[5]];
    let dz = [f[4] - f[0], f[5] - f[1], f[6] - f[2], f[7] - f[3]];
    Vec3::new(
        bilerp(&dx, p.y, p.z),
        bilerp(&dy, p.x, p.z),
        bilerp(&dz, p.x, p.y),
    )
}

/// The trilinear interpolant along a ray, c0 + c1 t + c2 t² + c3 t³.
#[derive(Clone, Copy, Debug)]
struct Cubic {
    c: [f32; 4],
}

impl Cubic {
    /// The interpolant of corners `s` along a + t b (voxel space).
    fn along(s: &[f32; 8], a: Vec3, b: Vec3) -> Cubic {
        // f = k0 + k1 x + k2 y + k4 z + k3 xy + k5 xz + k6 yz + k7 xyz.
        let k0 = s[0];
        let k1 = s[1] - s[0];
        let k2 = s[2] - s[0];
        let k4 = s[4] - s[0];
        let k3 = s[3] - s[2] - s[1] + s[0];
        let k5 = s[5] - s[4] - s[1] + s[0];
        let k6 = s[6] - s[4] - s[2] + s[0];
        let k7 = s[7] - s[6] - s[5] - s[3] + s[4] + s[2] + s[1] - s[0];
        let c0 = k0
            + k1 * a.x
            + k2 * a.y
            + k4 * a.z
            + k3 * a.x * a.y
            + k5 * a.x * a.z
            + k6 * a.y * a.z
            + k7 * a.x * a.y * a.z;
        let c1 = k1 * b.x
            + k2 * b.y
            + k4 * b.z
            + k3 * (a.x * b.y + a.y * b.x)
            + k5 * (a.x * b.z + a.z * b.x)
            + k6 * (a.y * b.z + a.z * b.y)
            + k7 * (a.x * a.y * b.z + a.x * a.z * b.y + a.y * a.z * b.x);
        let c2 = k3 * b.x * b.y
            + k5 * b.x * b.z
            + k6 * b.y * b.z
            + k7 * (a.x * b.y * b.z + a.y * b.x * b.z + a.z * b.x * b.y);
        let c3 = k7 * b.x * b.y * b.z;
        Cubic {
            c: [c0, c1, c2, c3],
        }
    }

    #[inline]
    fn eval(&self, t: f32) -> f32 {
        ((self.c[3] * t + self.c[2]) * t + self.c[1]) * t + self.c[0]
    }

    #[inline]
    fn derivative(&self, t: f32) -> f32 {
        (3.0 * self.c[3] * t + 2.0 * self.c[2]) * t + self.c[1]
    }

    /// The first root in [0, `end`], given the values `f_start` and `f_end` there (computed
    /// consistently between neighbouring voxels), or `None` without a sign change.
    fn first_root(&self, end: f32, f_start: f32, f_end: f32) -> Option<f32> {
        let (mut near, mut far, mut f_near, mut f_far) = (0.0f32, end, f_start, f_end);
        // Split at the derivative's roots, keeping the first piece that changes sign:
        // between them the cubic is monotonic, so that piece holds exactly one root.
        for r in self.derivative_roots().into_iter().flatten() {
            if !(near <= r && r <= far) {
                continue;
            }
            let f_r = self.eval(r);
            if f_near * f_r <= 0.0 {
                far = r;
                f_far = f_r;
            } else {
                near = r;
                f_near = f_r;
            }
        }
        if f_near * f_far > 0.0 || f_near.is_nan() || f_far.is_nan() {
            return None;
        }
        // Newton's method from the secant estimate, bisecting when a step leaves the bracket.
        let mut t = near + (far - near) * (-f_near / (f_far - f_near));
        if !(t >= near && t <= far) {
            t = 0.5 * (near + far);
        }
        for _ in 0..SOLVE_MAX_STEPS {
            let f_t = self.eval(t);
            if f_t == 0.0 {
                break;
            }
            if f_t * f_near <= 0.0 {
                far = t;
            } else {
                near = t;
            }
            let newton = t - f_t / self.derivative(t);
            let next = if newton > near && newton < far {
                newton
            } else {
                0.5 * (near + far)
            };
            let step = (next - t).abs();
            t = next;
            // A NaN step ends the iteration too.
            if step.is_nan() || step < SOLVE_EPSILON {
                break;
            }
        }
        t.is_finite().then_some(t)
    }

    /// The roots of 3 c3 t² + 2 c2 t + c1, in increasing order.
    fn derivative_roots(&self) -> [Option<f32>; 2] {
        let (a, b, c) = (3.0 * self.c[3], 2.0 * self.c[2], self.c[1]);
        if a == 0.0 {
            return [(b != 0.0).then(|| -c / b), None];
        }
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return [None, None];
        }
        // The numerically stable pair of roots.
        let q = -0.5 * (b + b.signum() * disc.sqrt());
        let (r0, r1) = if q != 0.0 { (q / a, c / q) } else { (0.0, 0.0) };
        [Some(r0.min(r1)), Some(r0.max(r1))]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pathlab_mc::rng::Pcg32;

    /// A grid of `n`³ samples of `sdf` over the unit cube.
    fn grid(n: u32, sdf: impl Fn(Vec3) -> f32, smooth: bool) -> SdfGrid {
        let mut values = Vec::new();
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let p = Vec3::new(x as f32, y as f32, z as f32) / (n - 1) as f32;
                    values.push(sdf(p));
                }
            }
        }
        SdfGrid::new(&SdfGridDesc {
            values,
            resolution: [n; 3],
            to_world: Affine3A::IDENTITY,
            smooth_normals: smooth,
            ..Default::default()
        })
        .unwrap()
    }

    /// The nearest hit over all voxels (what the BVH finds), and the voxel.
    fn trace(g: &SdfGrid, ray: &Ray) -> Option<(f32, [u32; 3])> {
        g.occupied_voxels(&Affine3A::IDENTITY)
            .into_iter()
            .filter_map(|(v, _)| g.intersect_voxel(v, ray).map(|t| (t, v)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    #[test]
    fn a_plane_is_found_exactly_with_its_normal() {
        // A linear function is its own trilinear interpolant: the surface is the plane.
        let n = Vec3::new(0.3, -0.5, 0.8).normalize();
        let g = grid(9, |p| n.dot(p - Vec3::splat(0.5)), true);
        let mut rng = Pcg32::new(3, 1);
        let mut hits = 0;
        for _ in 0..2000 {
            let o = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 3.0
                - Vec3::ONE;
            let target = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
            let ray = Ray::new(o, (target - o).normalize());
            let denom = n.dot(ray.d);
            let t_plane = n.dot(Vec3::splat(0.5) - o) / denom;
            let p = ray.at(t_plane);
            let in_cube = t_plane > 0.0 && p.cmpge(Vec3::ZERO).all() && p.cmple(Vec3::ONE).all();
            match trace(&g, &ray) {
                Some((t, v)) => {
                    assert!(in_cube, "hit at {t} where the plane is outside the grid");
                    assert!((t - t_plane).abs() < 1e-4, "t {t} vs plane {t_plane}");
                    let p = ray.at(t);
                    let (ng, ns) = g.normals(v, p);
                    assert!((ng - n).length() < 1e-4, "{ng}");
                    // Every voxel's difference of a linear function is its gradient, except
                    // across the grid's last half voxel, where (as in Mitsuba) the sample
                    // beyond is the clamped last one.
                    let margin = 1.5 / 8.0;
                    if p.max_element() < 1.0 - margin {
                        assert!((ns - n).length() < 1e-3, "{ns} at {p}");
                    }
                    hits += 1;
                }
                None => assert!(
                    !in_cube || p.min_element() < 1e-4 || p.max_element() > 1.0 - 1e-4,
                    "missed the plane at {p}"
                ),
            }
        }
        assert!(hits > 500, "only {hits} hits");
    }

    #[test]
    fn a_sphere_grid_is_close_to_the_sphere_and_smooth_normals_are_continuous() {
        let (c, r) = (Vec3::splat(0.5), 0.35);
        for smooth in [false, true] {
            let g = grid(33, |p| (p - c).length() - r, smooth);
            let h = 1.0 / 32.0;
            let mut rng = Pcg32::new(5, 2);
            for _ in 0..2000 {
                let dir = pathlab_mc::warp::sample_uniform_sphere(glam::Vec2::new(
                    rng.uniform_f32(),
                    rng.uniform_f32(),
                ));
                // Aim at a point inside the sphere from outside the grid.
                let aim = c + 0.2 * Vec3::new(rng.uniform_f32(), rng.uniform_f32(), 0.5);
                let o = aim - 2.0 * dir;
                let ray = Ray::new(o, dir);
                let (t, v) = trace(&g, &ray).expect("a ray through the centre hits the sphere");
                let p = ray.at(t);
                // Interpolating a sphere's distance errs by O(h²/r).
                assert!(
                    ((p - c).length() - r).abs() < h * h / r,
                    "p {p} off the sphere"
                );
                let (ng, ns) = g.normals(v, p);
                let exact = (p - c).normalize();
                assert!(
                    ng.dot(exact) > 0.99 && ns.dot(exact) > 0.99,
                    "{ng} {ns} vs {exact}"
                );
            }
            if smooth {
                // Across a voxel face the smooth normal does not jump.
                let a = Vec3::new(0.5 + 1e-4, 0.5, 0.5 + r);
                let b = Vec3::new(0.5 - 1e-4, 0.5, 0.5 + r);
                let va = [16, 16, 26];
                let vb = [15, 16, 26];
                let (_, na) = g.normals(va, a);
                let (_, nb) = g.normals(vb, b);
                assert!((na - nb).length() < 1e-3, "{na} vs {nb}");
            }
        }
    }

    #[test]
    fn the_first_of_several_roots_is_found() {
        // Along a line through a voxel whose interpolant crosses zero three times.
        let c = Cubic {
            c: [0.06, -1.1, 3.0, -2.0],
        };
        // Roots of -2t³ + 3t² - 1.1t + 0.06: near 0.0612, ~0.5, ~0.94.
        let t = c.first_root(1.0, c.eval(0.0), c.eval(1.0)).unwrap();
        assert!(c.eval(t).abs() < 1e-5 && t < 0.2, "t = {t}");
    }

    #[test]
    fn bad_grids_are_errors() {
        let desc = |values: Vec<f32>, resolution| SdfGridDesc {
            values,
            resolution,
            ..Default::default()
        };
        assert!(SdfGrid::new(&desc(vec![0.0; 8], [2, 2, 2])).is_ok());
        assert!(SdfGrid::new(&desc(vec![0.0; 7], [2, 2, 2])).is_err());
        assert!(SdfGrid::new(&desc(vec![0.0; 4], [1, 2, 2])).is_err());
        assert!(SdfGrid::new(&desc(vec![f32::NAN; 8], [2, 2, 2])).is_err());
    }
}
