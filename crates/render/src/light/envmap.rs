//! Environment maps: radiance from every direction at infinity, read from an equirectangular
//! (latitude–longitude) image, and sampled in proportion to luminance × sin θ.
//!
//! Convention (Mitsuba 3's `envmap`, so that scenes and references agree): in the map's local
//! frame (y up), a direction d pointing from the scene into the environment has
//! u = atan2(d.x, -d.z) / 2π (mod 1) and v = acos(d.y) / π; row 0 of the image is the top
//! (v = 0). Radiance is the bilinear interpolation of the texels on a grid whose columns sit
//! at u = (i + ½) / W (periodic in u) and whose rows sit at v = j / (H - 1), poles included.
//!
//! Sampling: the (u, v) square is cut into W × (H - 1) cells between grid points; each cell's
//! weight is the largest luminance of its four corners (which bounds the interpolated
//! radiance inside it) times ∫ sin θ over its rows, so the density per solid angle,
//! p(ω) = p(u, v) / (2π² sin θ), follows the radiance and small bright suns are found. A cell
//! is chosen by alias tables ([`PiecewiseConstantAlias2D`]): a sample reads one bin of the
//! large table, where a search of the rows' CDFs reads several cache lines one after another.

use crate::color::{luminance, LUMINANCE_WEIGHTS};
use crate::desc::Rgb;
use glam::{Mat3, Vec2, Vec3};
use pathlab_mc::distribution::PiecewiseConstantAlias2D;
use pathlab_mc::simd::lanes::{Real, Vector3, F8, M8, V8, W};
use pathlab_mc::simd::prefetch;
use pathlab_mc::simd::trig::{acos, atan2, sin_cos_turns};
use std::f32::consts::{PI, TAU};

/// An environment map ready to evaluate and sample.
#[derive(Clone, Debug)]
pub struct EnvironmentMap {
    width: usize,
    height: usize,
    /// Texels, row-major, `height` rows of `width`.
    texels: Vec<Rgb>,
    to_world: Mat3,
    to_local: Mat3,
    distribution: PiecewiseConstantAlias2D,
    /// ∫ luminance dω over the sphere.
    luminance_integral: f32,
    /// Half a texel in u, 0.5 / W: grid column i sits at u = (i + ½) / W.
    half_texel: f32,
    /// ∫ sin θ dθ over each row of cells (H - 1 of them).
    bands: Vec<f32>,
}

/// Why an environment map cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EnvironmentMapError {
    /// Too small to interpolate.
    #[error("an environment map needs at least 2 x 3 texels, got {0} x {1}")]
    TooSmall(usize, usize),
    /// Pixel count does not match the size.
    #[error("{0} x {1} texels expected, got {2}")]
    SizeMismatch(usize, usize, usize),
    /// The rotation is not invertible.
    #[error("the environment map's to_world transform is singular")]
    Singular,
}

impl EnvironmentMap {
    /// A map of `width` × `height` linear RGB texels (row 0 at the top), scaled by `scale` and
    /// rotated into the world by `to_world` (a rotation; its inverse is taken as given).
    /// Negative and non-finite texels count as black.
    pub fn new(
        texels: Vec<Rgb>,
        width: usize,
        height: usize,
        to_world: Mat3,
        scale: f32,
    ) -> Result<Self, EnvironmentMapError> {
        if width < 2 || height < 3 {
            return Err(EnvironmentMapError::TooSmall(width, height));
        }
        if texels.len() != width * height {
            return Err(EnvironmentMapError::SizeMismatch(
                width,
                height,
                texels.len(),
            ));
        }
        if to_world.determinant().abs() < 1e-12 || !to_world.is_finite() {
            return Err(EnvironmentMapError::Singular);
        }
        let texels: Vec<Rgb> = texels
            .into_iter()
            .map(|c| {
                let c = c * scale;
                if c.is_finite() {
                    c.max(Vec3::ZERO)
                } else {
                    Vec3::ZERO
                }
            })
            .collect();
        let (nu, nv) = (width, height - 1);
        let dtheta = PI / nv as f32;
        // ∫ sin θ dθ over each row of cells.
        let bands: Vec<f32> = (0..nv)
            .map(|j| (j as f32 * dtheta).cos() - ((j + 1) as f32 * dtheta).cos())
            .collect();
        let mut weights = Vec::with_capacity(nu * nv);
        let mut luminance_integral = 0.0f64;
        for (j, &band) in bands.iter().enumerate() {
            for i in 0..nu {
                let i1 = (i + 1) % width;
                let corners = [
                    texels[j * width + i],
                    texels[j * width + i1],
                    texels[(j + 1) * width + i],
                    texels[(j + 1) * width + i1],
                ];
                let mean = corners.iter().map(|&c| luminance(c)).sum::<f32>() / 4.0;
                weights.push(cell_weight(&corners, band));
                luminance_integral += (mean * band) as f64 * (TAU / nu as f32) as f64;
            }
        }
        let distribution = PiecewiseConstantAlias2D::new(&weights, nu, nv).map_err(|_| {
            // Only reachable for empty input, excluded above.
            EnvironmentMapError::TooSmall(width, height)
        })?;
        Ok(EnvironmentMap {
            width,
            height,
            texels,
            to_world,
            to_local: to_world.inverse(),
            distribution,
            luminance_integral: luminance_integral as f32,
            half_texel: 0.5 / width as f32,
            bands,
        })
    }

    /// Size in texels.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Approximately ∫ luminance(L(ω)) dω over the sphere (for the light's power).
    pub fn luminance_integral(&self) -> f32 {
        self.luminance_integral
    }

    /// The local direction of grid point (column `i`, row `j`) of a `width` × `height` map:
    /// u = (i + ½) / W, v = j / (H - 1) (see the module notes).
    pub fn grid_direction(i: usize, j: usize, width: usize, height: usize) -> Vec3 {
        let uv = Vec2::new(
            (i as f32 + 0.5) / width as f32,
            j as f32 / (height.max(2) - 1) as f32,
        );
        Self::uv_to_direction(uv).0
    }

    /// The local direction of (u, v), and sin θ.
    pub fn uv_to_direction(uv: Vec2) -> (Vec3, f32) {
        direction_of_uv(uv.x, uv.y)
    }

    /// Grid coordinates (x in [0, W), y in [0, H - 1]) of (u, v), for one value or lanes.
    #[inline(always)]
    fn grid<R: Real>(&self, u: R, v: R) -> (R, R) {
        (
            wrap_u(u - R::splat(self.half_texel)) * R::splat(self.width as f32),
            v * R::splat((self.height - 1) as f32),
        )
    }

    /// The cell of grid coordinates (`gx`, `gy`): its corner texels' indices, (x0, y0), (x1, y0),
    /// (x0, y0 + 1), (x1, y0 + 1), where the point lies between its columns and between its
    /// rows, and its row y0. The same products and truncations pick the cell the distribution
    /// finds for (u, v).
    #[inline(always)]
    fn cell_at(&self, gx: f32, gy: f32) -> ([usize; 4], f32, f32, usize) {
        let x0 = (gx as usize).min(self.width - 1);
        let y0 = (gy as usize).min(self.height - 2);
        let (fx, fy) = (gx - x0 as f32, (gy - y0 as f32).clamp(0.0, 1.0));
        // The next column, wrapping around in u (a comparison, not an integer division).
        let x1 = if x0 + 1 == self.width { 0 } else { x0 + 1 };
        let (top, bottom) = (y0 * self.width, (y0 + 1) * self.width);
        ([top + x0, top + x1, bottom + x0, bottom + x1], fx, fy, y0)
    }

    /// The four texels that (u, v) interpolates between, which are the corners of the cell the
    /// distribution finds for (u, v) too, and where (u, v) lies between them.
    #[inline]
    fn texels_around(&self, uv: Vec2) -> TexelCell {
        let (gx, gy) = self.grid(uv.x, uv.y);
        let (corners, fx, fy, row) = self.cell_at(gx, gy);
        TexelCell {
            corners: corners.map(|k| self.texels[k]),
            fx,
            fy,
            row,
        }
    }

    /// The local direction of world direction `w`, and its (u, v).
    #[inline]
    fn local(&self, w: Vec3) -> (Vec3, Vec2) {
        let (d, u, v) = self.local_of(w);
        (d, Vec2::new(u, v))
    }

    /// The local direction of world direction `w` and its (u, v), for one value or lanes:
    /// `to_local · w` ([`rotate`]), normalised as glam's `normalize_or_zero` does,
    /// u = atan2(x, -z) / 2π (mod 1) and v = acos y / π.
    #[inline(always)]
    fn local_of<V: Vector3>(&self, w: V) -> (V, V::R, V::R) {
        let d = rotate(&self.to_local, w);
        let zero = V::R::splat(0.0);
        let rcp = V::R::splat(1.0) / d.dot(d).sqrt();
        let d = V::select(
            rcp.is_finite() & rcp.gt(zero),
            d.scale(rcp),
            V::splat(Vec3::ZERO),
        );
        let u = atan2(d.x(), -d.z()) / V::R::splat(TAU);
        let (one, y) = (V::R::splat(1.0), d.y());
        let y = V::R::select(y.lt(-one), -one, V::R::select(y.gt(one), one, y));
        (d, wrap_u(u), acos(y) / V::R::splat(PI))
    }

    /// [`EnvironmentMap::eval_and_pdf`] of the lanes `active` of `w`, each to the bit as one
    /// direction at a time (the other lanes give zeros): the same functions on eight lanes,
    /// the texels read lane by lane.
    #[inline(always)]
    pub fn eval_and_pdf_lanes(&self, w: V8, active: u32) -> (V8, F8) {
        let (d, u, v) = self.local_of(w);
        let (gx, gy) = self.grid(u, v);
        let mut corners = [V8::default(); 4];
        let (mut fx, mut fy, mut band) = (F8::splat(0.0), F8::splat(0.0), F8::splat(0.0));
        for i in (0..W).filter(|i| active & (1 << i) != 0) {
            let (at, x, y, row) = self.cell_at(gx.0[i], gy.0[i]);
            for (c, k) in corners.iter_mut().zip(at) {
                c.set(i, self.texels[k]);
            }
            (fx.0[i], fy.0[i], band.0[i]) = (x, y, self.bands[row]);
        }
        let pdf_uv = self.cell_pdf(cell_weight(&corners, band));
        (bilinear(corners, fx, fy), solid_angle_pdf(d, pdf_uv))
    }

    /// The density per unit (u, v) area of a cell of weight `weight`, for one value or lanes.
    #[inline(always)]
    fn cell_pdf<R: Real>(&self, weight: R) -> R {
        let integral = self.distribution.integral();
        if integral > 0.0 {
            weight / R::splat(integral)
        } else {
            // A black map is sampled uniformly over the unit square.
            R::splat(1.0)
        }
    }

    /// Radiance arriving from world direction `w` (pointing into the environment).
    pub fn eval(&self, w: Vec3) -> Rgb {
        self.radiance_at(self.local(w).1)
    }

    /// [`EnvironmentMap::eval`] and [`EnvironmentMap::pdf`] of one direction, which find its
    /// (u, v) once.
    pub fn eval_and_pdf(&self, w: Vec3) -> (Rgb, f32) {
        let (d, uv) = self.local(w);
        // The density from the cell's weight, found from the texels the radiance reads rather
        // than from the distribution's table (one lookup in memory instead of two; the same
        // number: the table holds the same weight of the same cell).
        let cell = self.texels_around(uv);
        let pdf_uv = self.cell_pdf(cell_weight(&cell.corners, self.bands[cell.row]));
        (cell.radiance(), solid_angle_pdf(d, pdf_uv))
    }

    /// A world direction, its density per solid angle and the radiance from it.
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, f32, Rgb)> {
        let (wi, pdf, uv) = self.sample_direction(u)?;
        Some((wi, pdf, self.radiance_at(uv)))
    }

    /// [`EnvironmentMap::sample`] without the radiance: the world direction, its density per
    /// solid angle and its (u, v), where [`EnvironmentMap::radiance_at`] reads the radiance.
    /// The texel lookup is a cache miss more often than not in a large map; a caller that may
    /// reject the direction (the BSDF is zero there, a shadow ray is blocked) reads it after.
    pub fn sample_direction(&self, u: Vec2) -> Option<(Vec3, f32, Vec2)> {
        let (cell_uv, pdf_uv) = self.distribution.sample(u);
        let (wi, pdf, u, found) = self.direction_of_cell(cell_uv.x, cell_uv.y, pdf_uv);
        found.then(|| (wi, pdf, Vec2::new(u, cell_uv.y)))
    }

    /// The world direction of the distribution's point (`cell_u`, `v`) of density `pdf_uv`
    /// per unit (u, v) area, its density per solid angle and its u, and whether it is a
    /// direction (a density above zero, off the poles); for one value or lanes.
    #[inline(always)]
    fn direction_of_cell<R: Real>(&self, cell_u: R, v: R, pdf_uv: R) -> (R::V3, R, R, R::Mask) {
        // Cells start at grid column 0, half a texel into u.
        let u = wrap_u(cell_u + R::splat(self.half_texel));
        let (d, sin_t) = direction_of_uv(u, v);
        let zero = R::splat(0.0);
        let pdf = pdf_uv / (R::splat(2.0 * PI * PI) * sin_t);
        let found = !pdf_uv.le(zero) & !sin_t.le(zero);
        (rotate(&self.to_world, d).normalize(), pdf, u, found)
    }

    /// [`EnvironmentMap::sample_direction`] of the lanes `active` of (`u[0]`, `u[1]`), each
    /// to the bit as one at a time: the lanes that have a direction, and in those lanes the
    /// world direction, its density per solid angle and its (u, v).
    pub fn sample_direction_lanes(&self, u: [F8; 2], active: u32) -> DirectionLanes {
        let ([cell_u, v], pdf_uv) = self.distribution.sample_lanes(u, active);
        // The lanes outside `active` have no direction: their density is zero.
        let (wi, pdf, u, found) = self.direction_of_cell(cell_u, v, pdf_uv);
        // The texels `radiance_at` will read, asked for now: they are read after the shadow
        // ray, and in a large map they are rarely in cache.
        let (gx, gy) = self.grid(u, v);
        for i in (0..W).filter(|&i| found.get(i)) {
            let (corners, ..) = self.cell_at(gx.0[i], gy.0[i]);
            prefetch(&self.texels[corners[0]]);
            prefetch(&self.texels[corners[2]]);
        }
        DirectionLanes {
            found,
            wi,
            pdf,
            uv: [u, v],
        }
    }

    /// Asks memory for what [`EnvironmentMap::sample_direction_lanes`] of the same numbers
    /// will read first (the distribution's table, a cache miss more often than not).
    pub fn prefetch_directions(&self, u: [F8; 2], active: u32) {
        self.distribution.prefetch_lanes(u, active);
    }

    /// Bilinear radiance at the map's (u, v), as [`EnvironmentMap::sample_direction`] gives
    /// them.
    #[inline]
    pub fn radiance_at(&self, uv: Vec2) -> Rgb {
        self.texels_around(uv).radiance()
    }

    /// Density per solid angle with which [`EnvironmentMap::sample`] returns `w`.
    pub fn pdf(&self, w: Vec3) -> f32 {
        let (d, uv) = self.local(w);
        self.pdf_local(d, uv)
    }

    /// [`EnvironmentMap::pdf`] of local direction `d`, whose (u, v) is `uv`.
    #[inline]
    fn pdf_local(&self, d: Vec3, uv: Vec2) -> f32 {
        let cell_uv = Vec2::new(wrap_u(uv.x - self.half_texel), uv.y);
        solid_angle_pdf(d, self.distribution.pdf(cell_uv))
    }
}

/// `m · v` in glam's order of operations (its columns times v's axes, summed from x to z),
/// for one vector or lanes.
#[inline(always)]
fn rotate<V: Vector3>(m: &Mat3, v: V) -> V {
    V::splat(m.x_axis).scale(v.x())
        + V::splat(m.y_axis).scale(v.y())
        + V::splat(m.z_axis).scale(v.z())
}

/// The density per solid angle of local direction `d` whose density per unit (u, v) area is
/// `pdf_uv` (zero at the poles), for one value or lanes.
#[inline(always)]
fn solid_angle_pdf<V: Vector3>(d: V, pdf_uv: V::R) -> V::R {
    let sin2 = d.x() * d.x() + d.z() * d.z();
    let zero = V::R::splat(0.0);
    V::R::select(
        sin2.le(zero),
        zero,
        pdf_uv / (V::R::splat(2.0 * PI * PI) * sin2.sqrt()),
    )
}

/// The bilinear interpolation of a cell's corner radiances (x0, y0), (x1, y0), (x0, y0 + 1),
/// (x1, y0 + 1) at (`fx`, `fy`) between its columns and rows, for one value or lanes.
#[inline(always)]
fn bilinear<V: Vector3>(c: [V; 4], fx: V::R, fy: V::R) -> V {
    let one = V::R::splat(1.0);
    let top = c[0].scale(one - fx) + c[1].scale(fx);
    let bottom = c[2].scale(one - fx) + c[3].scale(fx);
    top.scale(one - fy) + bottom.scale(fy)
}

/// The local direction of (u, v), and sin θ, written once for one value and for lanes: θ = πv
/// and φ = 2πu, their sines and cosines by [`sin_cos_turns`] (v/2 and u turns; v/2 is exact).
#[inline(always)]
fn direction_of_uv<R: Real>(u: R, v: R) -> (R::V3, R) {
    let (sin_t, cos_t) = sin_cos_turns(v * R::splat(0.5));
    let (sin_p, cos_p) = sin_cos_turns(u);
    (
        R::V3::new(sin_p * sin_t, cos_t, -cos_p * sin_t),
        sin_t.max(R::splat(0.0)),
    )
}

/// Directions sampled in lanes ([`EnvironmentMap::sample_direction_lanes`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct DirectionLanes {
    /// The lanes that have a direction (the others' fields are meaningless).
    pub found: M8,
    /// World directions.
    pub wi: V8,
    /// Their densities per unit solid angle.
    pub pdf: F8,
    /// Their (u, v), where [`EnvironmentMap::radiance_at`] reads the radiance.
    pub uv: [F8; 2],
}

/// A cell of the map's grid as a radiance lookup finds it ([`EnvironmentMap::texels_around`]).
struct TexelCell {
    /// Radiance at its corners: (x0, y0), (x1, y0), (x0, y0 + 1), (x1, y0 + 1).
    corners: [Rgb; 4],
    /// Where the looked-up point lies between the columns and between the rows.
    fx: f32,
    fy: f32,
    /// y0, the cell's row.
    row: usize,
}

impl TexelCell {
    /// The bilinear interpolation of the corners.
    #[inline]
    fn radiance(&self) -> Rgb {
        bilinear(self.corners, self.fx, self.fy)
    }
}

/// The sampling weight of a cell of the map with corner radiances `corners`: the largest
/// luminance of the four (which bounds the bilinear radiance inside the cell) times `band`,
/// ∫ sin θ dθ over its row. Building the distribution and finding a direction's density both
/// call it.
/// For one value or lanes.
#[inline(always)]
fn cell_weight<V: Vector3>(corners: &[V; 4], band: V::R) -> V::R {
    let [r, g, b] = LUMINANCE_WEIGHTS.map(|w| w as f32);
    let weights = V::splat(Vec3::new(r, g, b));
    // `luminance`'s sum, (r x + g y) + b z, is glam's dot product's. By reference: the
    // lanes' corners are 384 bytes, which an array's `into_iter` copied twice.
    corners
        .iter()
        .map(|&c| weights.dot(c))
        .fold(V::R::splat(0.0), V::R::max)
        * band
}

/// `u - floor(u)` for `u` in [-1, 2), the range of every u coordinate this module wraps
/// (shifted by half a texel at most, or from `atan2`'s [-½, ½]): the same subtraction of the
/// same whole number, chosen by comparisons rather than computed by `floor` (a library call
/// on CPUs without SSE4.1). A -0 stays -0 (`floor` would give +0), which no caller tells
/// apart: every one scales it or subtracts from it.
/// For one value or lanes.
#[inline(always)]
fn wrap_u<R: Real>(u: R) -> R {
    let one = R::splat(1.0);
    R::select(
        u.lt(R::splat(0.0)),
        u + one,
        R::select(one.le(u), u - one, u),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(texels: Vec<Rgb>, w: usize, h: usize) -> EnvironmentMap {
        EnvironmentMap::new(texels, w, h, Mat3::IDENTITY, 1.0).unwrap()
    }

    #[test]
    fn follows_mitsubas_lat_long_convention() {
        // One bright texel column per quadrant: direction -z is u = 0, +x is u = 1/4.
        let (w, h) = (8, 5);
        let mut t = vec![Vec3::ZERO; w * h];
        // The grid column at u = (i + ½)/W: i = 0 → u = 1/16; i = 2 → u = 5/16.
        for y in 0..h {
            t[y * w + 2] = Vec3::ONE;
        }
        let m = map(t, w, h);
        let phi = TAU * 5.0 / 16.0;
        let d = Vec3::new(phi.sin(), 0.0, -phi.cos());
        assert!((m.eval(d) - Vec3::ONE).abs().max_element() < 1e-5);
        assert!(m.eval(-d).max_element() < 1e-6);
        // Halfway to the next column: half the radiance.
        let phi = TAU * 6.0 / 16.0;
        let d = Vec3::new(phi.sin(), 0.0, -phi.cos());
        assert!((m.eval(d) - Vec3::splat(0.5)).abs().max_element() < 1e-5);
    }

    #[test]
    fn wrapping_u_subtracts_its_floor() {
        let mut us = vec![
            -1.0f32,
            -0.5,
            -1e-30,
            0.0,
            1e-30,
            0.25,
            0.5,
            1.0,
            1.5,
            2.0f32.next_down(),
        ];
        us.extend(us.clone().iter().flat_map(|u| [u.next_up(), u.next_down()]));
        us.extend((0..1000).map(|i| -1.0 + 3.0 * i as f32 / 1000.0));
        for u in us.into_iter().filter(|u| (-1.0..2.0).contains(u)) {
            let floored = u - u.floor();
            // The same number; -0 only where floor gives +0.
            assert_eq!(wrap_u(u), floored, "u = {u}");
            assert!(
                wrap_u(u).to_bits() == floored.to_bits() || u == 0.0,
                "u = {u}"
            );
        }
    }

    #[test]
    fn rows_run_from_the_top_pole_to_the_bottom_pole() {
        let (w, h) = (4, 3);
        let mut t = vec![Vec3::ZERO; w * h];
        t[..w].fill(Vec3::ONE); // top row: the +y pole
        let m = map(t, w, h);
        assert!((m.eval(Vec3::Y) - Vec3::ONE).abs().max_element() < 1e-6);
        assert!(m.eval(-Vec3::Y).max_element() < 1e-6);
        // The horizon (v = ½) is the middle row.
        assert!(m.eval(Vec3::X).max_element() < 1e-6);
    }

    #[test]
    fn sampling_density_matches_pdf_and_sample_radiance_matches_eval() {
        let (w, h) = (16, 9);
        let t: Vec<Rgb> = (0..w * h)
            .map(|i| Vec3::splat(1.0 + (i % 7) as f32 + if i == 40 { 500.0 } else { 0.0 }))
            .collect();
        let m = EnvironmentMap::new(
            t,
            w,
            h,
            Mat3::from_rotation_y(0.7) * Mat3::from_rotation_x(0.3),
            2.0,
        )
        .unwrap();
        for i in 0..1000 {
            let u = Vec2::new((i as f32 * 0.618_034) % 1.0, (i as f32 + 0.5) / 1000.0);
            if let Some((d, pdf, l)) = m.sample(u) {
                let p = m.pdf(d);
                assert!((p - pdf).abs() <= 2e-3 * pdf, "{p} vs {pdf}");
                assert_eq!(m.eval_and_pdf(d), (m.eval(d), p));
                assert!((m.eval(d) - l).abs().max_element() <= 1e-3 * l.max_element());
            }
        }
    }

    #[test]
    fn the_density_from_the_texels_is_the_distributions_to_the_bit() {
        // `eval_and_pdf` finds the cell's weight from the texels it interpolates; `pdf` reads
        // the distribution's table. Every direction, poles, seams and a black map included.
        let (w, h) = (12, 7);
        let mut rng = pathlab_mc::rng::Pcg32::new(9, 3);
        let bright: Vec<Rgb> = (0..w * h)
            .map(|i| {
                Vec3::new((i % 4) as f32, 1.0 + (i % 3) as f32 * 7.0, 0.25) * rng.uniform_f32()
            })
            .collect();
        for texels in [bright, vec![Vec3::ZERO; w * h]] {
            let m = EnvironmentMap::new(texels, w, h, Mat3::from_rotation_z(0.2), 3.0).unwrap();
            let mut dirs = vec![Vec3::Y, -Vec3::Y, Vec3::X, -Vec3::Z, Vec3::Z];
            for i in 0..w {
                // The seams between grid columns, in the map's frame.
                let phi = TAU * i as f32 / w as f32;
                dirs.push(m.to_world * Vec3::new(phi.sin(), 0.3, -phi.cos()));
            }
            dirs.extend((0..20_000).map(|_| {
                pathlab_mc::warp::sample_uniform_sphere(Vec2::new(
                    rng.uniform_f32(),
                    rng.uniform_f32(),
                ))
            }));
            for d in dirs {
                let (le, pdf) = m.eval_and_pdf(d);
                assert_eq!(
                    le.to_array().map(f32::to_bits),
                    m.eval(d).to_array().map(f32::to_bits)
                );
                assert_eq!(pdf.to_bits(), m.pdf(d).to_bits(), "direction {d}");
            }
        }
    }

    #[test]
    fn eight_lanes_look_up_what_one_direction_at_a_time_looks_up() {
        let (w, h) = (12, 7);
        let mut rng = pathlab_mc::rng::Pcg32::new(4, 8);
        let bright: Vec<Rgb> = (0..w * h)
            .map(|i| Vec3::new((i % 5) as f32, 1.0 + (i % 3) as f32, 0.5) * rng.uniform_f32())
            .collect();
        for texels in [bright, vec![Vec3::ZERO; w * h]] {
            let m = EnvironmentMap::new(texels, w, h, Mat3::from_rotation_x(0.6), 2.0).unwrap();
            // The poles, the seams, unnormalised and zero directions, then random ones.
            let mut dirs = vec![Vec3::Y, -Vec3::Y, Vec3::X * 3.0, -Vec3::Z, Vec3::ZERO];
            dirs.extend((0..w).map(|i| {
                let phi = TAU * i as f32 / w as f32;
                m.to_world * Vec3::new(phi.sin(), -0.2, -phi.cos())
            }));
            dirs.extend((0..8000).map(|_| {
                pathlab_mc::warp::sample_uniform_sphere(Vec2::new(
                    rng.uniform_f32(),
                    rng.uniform_f32(),
                )) * (0.5 + rng.uniform_f32())
            }));
            for (k, chunk) in dirs.chunks(W).enumerate() {
                let mut ws = V8::default();
                for (i, &d) in chunk.iter().enumerate() {
                    ws.set(i, d);
                }
                // Every lane, then every other lane (the others give zeros).
                let all = (1u32 << chunk.len()) - 1;
                for active in [all, all & (0x55 << (k % 2))] {
                    let (le, pdf) = m.eval_and_pdf_lanes(ws, active);
                    for (i, &d) in chunk.iter().enumerate() {
                        let (want_le, want_pdf) = if active & (1 << i) != 0 {
                            m.eval_and_pdf(d)
                        } else {
                            (Vec3::ZERO, pdf.0[i])
                        };
                        assert_eq!(
                            le.get(i).to_array().map(f32::to_bits),
                            want_le.to_array().map(f32::to_bits),
                            "{d}"
                        );
                        assert_eq!(pdf.0[i].to_bits(), want_pdf.to_bits(), "{d}");
                    }
                }
            }
        }
    }

    #[test]
    fn eight_lanes_sample_the_directions_one_at_a_time_samples() {
        let (w, h) = (16, 9);
        let t: Vec<Rgb> = (0..w * h)
            .map(|i| Vec3::splat(1.0 + (i % 7) as f32 + if i == 40 { 500.0 } else { 0.0 }))
            .collect();
        let m = EnvironmentMap::new(t, w, h, Mat3::from_rotation_y(0.7), 2.0).unwrap();
        let mut rng = pathlab_mc::rng::Pcg32::new(6, 6);
        for k in 0..4000u32 {
            let mut draw = || {
                F8(std::array::from_fn(|_| match rng.next_u32() % 40 {
                    0 => 0.0,
                    1 => 1.0f32.next_down(),
                    _ => rng.uniform_f32(),
                }))
            };
            let u = [draw(), draw()];
            let active = if k % 2 == 0 {
                0xff
            } else {
                rng.next_u32() & 0xff
            };
            let lanes = m.sample_direction_lanes(u, active);
            for i in 0..W {
                let one = (active & (1 << i) != 0)
                    .then(|| m.sample_direction(Vec2::new(u[0].0[i], u[1].0[i])))
                    .flatten();
                assert_eq!(lanes.found.get(i), one.is_some(), "lane {i}");
                if let Some((wi, pdf, uv)) = one {
                    let got = (lanes.wi.get(i), lanes.pdf.0[i]);
                    let got_uv = Vec2::new(lanes.uv[0].0[i], lanes.uv[1].0[i]);
                    assert_eq!(
                        got.0.to_array().map(f32::to_bits),
                        wi.to_array().map(f32::to_bits)
                    );
                    assert_eq!(got.1.to_bits(), pdf.to_bits());
                    assert_eq!(
                        got_uv.to_array().map(f32::to_bits),
                        uv.to_array().map(f32::to_bits)
                    );
                }
            }
        }
    }
}
