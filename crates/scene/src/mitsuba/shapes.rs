//! Mitsuba shape plugins: `obj`, `ply`, `serialized`, `rectangle`, `cube`, `disk`,
//! `cylinder`, `sphere`, `sdfgrid`, and `shapegroup` + `instance` (flattened into world
//! space).

use super::{emitters, Ctx, Obj};
use crate::meshfile;
use crate::Error;
use glam::{DMat4, DVec3, Mat3, Vec2, Vec3};
use pathlab_render::desc::*;
use std::f32::consts::TAU;

/// Segments of the triangulated disk and cylinder (their silhouettes are within 1e-4 of the
/// analytic shapes' radius).
const ROUND_SEGMENTS: u32 = 256;

/// The material and emission every shape takes.
struct Surface {
    material: usize,
    emission: Option<Emission>,
    emission_texture: Option<TextureDesc>,
}

fn surface(ctx: &mut Ctx, s: Obj, m: DMat4) -> Result<Surface, Error> {
    let bsdfs = ctx.children(s, "bsdf")?;
    let material = match bsdfs.as_slice() {
        [] => {
            ctx.desc.materials.push(super::default_bsdf());
            ctx.desc.materials.len() - 1
        }
        [(_, b)] => ctx.material(*b)?,
        [(_, b), ..] => {
            ctx.warn(
                s.loc,
                format!("{} has more than one BSDF; using the first", ctx.what(s)),
            );
            ctx.material(*b)?
        }
    };
    let mut emission = None;
    let mut emission_texture = None;
    for (_, e) in ctx.children(s, "emitter")? {
        if e.plugin == "area" {
            let (radiance, texture) = emitters::area_radiance(ctx, e)?;
            emission = Some(Emission {
                radiance,
                two_sided: false,
            });
            emission_texture = texture;
        } else {
            let what = ctx.what(e);
            ctx.warn(
                e.loc,
                format!("{what} inside a shape is not supported (only area emitters); skipped"),
            );
            let _ = m;
        }
    }
    Ok(Surface {
        material,
        emission,
        emission_texture,
    })
}

/// The shape `s` with object-to-world transform `parent` × its own `to_world`, added to the
/// scene. `group` is the shape group being instanced, if any.
pub(super) fn shape(
    ctx: &mut Ctx,
    s: Obj,
    parent: DMat4,
    group: Option<usize>,
) -> Result<(), Error> {
    if s.plugin == "shapegroup" {
        if group.is_none() {
            // Drawn only through instances; check that its shapes are ones pathlab reads.
            ctx.accept(s, &[]);
            for (_, child) in ctx.children(s, "shape")? {
                let _ = child;
            }
        }
        return Ok(());
    }
    if s.plugin == "instance" {
        let to_world = parent * ctx.transform(s, "to_world")?;
        let groups = ctx.children(s, "shape")?;
        let [(_, g)] = groups.as_slice() else {
            return Err(ctx.error(
                s.loc,
                "<shape type=\"instance\"> needs one <ref> to a shapegroup",
            ));
        };
        if g.plugin != "shapegroup" {
            return Err(ctx.error(
                s.loc,
                format!(
                    "<shape type=\"instance\"> refers to a '{}' shape, not a shapegroup",
                    g.plugin
                ),
            ));
        }
        if group == Some(g.index) {
            return Err(ctx.error(s.loc, "a shapegroup instances itself"));
        }
        for (_, child) in ctx.children(*g, "shape")? {
            shape(ctx, child, to_world, Some(g.index))?;
        }
        return Ok(());
    }
    let m = parent * ctx.transform(s, "to_world")?;
    let flip = ctx.boolean(s, "flip_normals", false)?;
    let mesh = match s.plugin {
        "sphere" => return sphere(ctx, s, m, flip),
        "rectangle" => rectangle(),
        "cube" => cube(),
        "disk" => disk(),
        "cylinder" => cylinder(ctx, s)?,
        "obj" | "ply" | "serialized" => {
            let path = ctx.file(s, "filename")?;
            // Mitsuba flips an OBJ file's v unless told not to (`flip_tex_coords`), keeps a
            // PLY file's as it is, and stores a serialized mesh's in its own convention.
            let flip_uv = match s.plugin {
                "obj" => ctx.boolean(s, "flip_tex_coords", true)?,
                "ply" => false,
                _ => true,
            };
            let face_normals = ctx.boolean(s, "face_normals", false)?;
            let mut meshes = match s.plugin {
                "obj" => meshfile::obj_meshes(&path),
                "ply" => meshfile::ply_mesh(&path).map(|m| vec![m]),
                _ => {
                    let index = ctx.int(s, "shape_index", 0)?;
                    if index < 0 {
                        return Err(
                            ctx.error(ctx.loc_of(s, "shape_index"), "shape_index must be >= 0")
                        );
                    }
                    super::serialized::load(&path, index as usize).map(|m| vec![m])
                }
            }
            .map_err(|e| ctx.file_error(s, "filename", e))?;
            for mesh in &mut meshes {
                // The readers give a file's (u, v) as they are, which is pathlab's convention
                // where Mitsuba flips v on reading; where it does not, pathlab's v is flipped.
                if !flip_uv {
                    for uv in &mut mesh.uvs {
                        uv.y = 1.0 - uv.y;
                    }
                }
                if face_normals {
                    mesh.normals.clear();
                } else if mesh.normals.is_empty() {
                    // Mitsuba gives meshes without normals smooth ones.
                    mesh.normals = vertex_normals(&mesh.positions, &mesh.indices);
                }
            }
            ctx.accept(s, &["maxSmoothAngle", "max_smooth_angle"]);
            let surface = surface(ctx, s, m)?;
            for mesh in meshes {
                push_mesh(ctx, s, mesh, m, flip, &surface);
            }
            return Ok(());
        }
        "sdfgrid" => return sdf_grid(ctx, s, m, flip),
        other => {
            let what = ctx.what(s);
            ctx.warn(
                s.loc,
                format!("{what} is not supported by pathlab; skipped"),
            );
            ctx.accept_all(s);
            let _ = other;
            return Ok(());
        }
    };
    let surface = surface(ctx, s, m)?;
    push_mesh(ctx, s, mesh, m, flip, &surface);
    Ok(())
}

/// Adds object-space `mesh` transformed by `m`.
fn push_mesh(ctx: &mut Ctx, s: Obj, mut mesh: MeshDesc, m: DMat4, flip: bool, surface: &Surface) {
    let normal_matrix = m.inverse().transpose();
    mesh.positions = mesh
        .positions
        .iter()
        .map(|p| m.transform_point3(p.as_dvec3()).as_vec3())
        .collect();
    mesh.normals = mesh
        .normals
        .iter()
        .map(|n| {
            normal_matrix
                .transform_vector3(n.as_dvec3())
                .normalize_or_zero()
                .as_vec3()
        })
        .collect();
    mesh.tangents = mesh
        .tangents
        .iter()
        .map(|t| m.transform_vector3(t.as_dvec3()).as_vec3())
        .collect();
    // A mirroring transform turns the winding's side inside out; Mitsuba's face normals follow
    // the transformed winding, so flip the triangles to keep the same outside.
    if m.determinant() < 0.0 {
        flip_winding(&mut mesh.indices);
    }
    if flip {
        flip_winding(&mut mesh.indices);
        for n in &mut mesh.normals {
            *n = -*n;
        }
    }
    if mesh.name.is_empty() {
        mesh.name = ctx.tree.nodes[s.index]
            .id
            .clone()
            .unwrap_or_else(|| s.plugin.to_string());
    }
    mesh.material = surface.material;
    mesh.emission = surface.emission;
    mesh.emission_texture = surface.emission_texture.clone();
    ctx.desc.meshes.push(mesh);
}

/// Angle-weighted vertex normals (Thürmer and Wüthrich), as Mitsuba computes for meshes
/// that bring none.
pub(crate) fn vertex_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let p = [0, 1, 2].map(|k| positions.get(t[k] as usize).copied().unwrap_or(Vec3::ZERO));
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        for k in 0..3 {
            let (a, b) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            let angle = a
                .normalize_or_zero()
                .dot(b.normalize_or_zero())
                .clamp(-1.0, 1.0)
                .acos();
            if let Some(v) = normals.get_mut(t[k] as usize) {
                *v += n * angle;
            }
        }
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}

fn flip_winding(indices: &mut [u32]) {
    for t in indices.chunks_exact_mut(3) {
        t.swap(1, 2);
    }
}

fn sphere(ctx: &mut Ctx, s: Obj, m: DMat4, flip: bool) -> Result<(), Error> {
    let center = ctx.vector(s, "center")?.unwrap_or(DVec3::ZERO);
    let radius = ctx.positive(s, "radius", 1.0)?;
    let c = m.transform_point3(center);
    let axes = [
        m.transform_vector3(DVec3::X),
        m.transform_vector3(DVec3::Y),
        m.transform_vector3(DVec3::Z),
    ];
    let scale = axes[0].length();
    if axes
        .iter()
        .any(|a| (a.length() - scale).abs() > 1e-4 * scale.max(1e-12))
    {
        ctx.warn(
            s.loc,
            "<shape type=\"sphere\">: a non-uniform scale is drawn as a sphere of the x axis's scale",
        );
    }
    let r = radius * scale;
    if !(r > 0.0 && r.is_finite()) {
        return Err(ctx.error(s.loc, format!("sphere radius must be positive, got {r}")));
    }
    if flip {
        ctx.warn(
            s.loc,
            "<shape type=\"sphere\">: flip_normals is not supported on spheres; ignored",
        );
    }
    let surface = surface(ctx, s, m)?;
    let to_world = Mat3::from_cols(
        (axes[0] / scale).as_vec3(),
        (axes[1] / scale).as_vec3(),
        (axes[2] / scale).as_vec3(),
    );
    ctx.desc.spheres.push(SphereDesc {
        center: c.as_vec3(),
        radius: r as f32,
        material: surface.material,
        emission: surface.emission,
        to_object: to_world.transpose(),
        emission_texture: surface.emission_texture,
    });
    Ok(())
}

/// Mitsuba's `sdfgrid`: a signed distance grid from a `.vol` file over the object-space unit
/// cube.
fn sdf_grid(ctx: &mut Ctx, s: Obj, m: DMat4, flip: bool) -> Result<(), Error> {
    let path = ctx.file(s, "filename")?;
    let smooth = ctx.choice(s, "normals", &["smooth", "analytic"])? == "smooth";
    let grid = super::volume::load(&path).map_err(|e| ctx.file_error(s, "filename", e))?;
    if grid.resolution.iter().any(|&n| n < 2) {
        let [x, y, z] = grid.resolution;
        return Err(ctx.error(
            s.loc,
            format!("<shape type=\"sdfgrid\">: a grid needs at least 2 samples per axis, the file has {x} x {y} x {z}"),
        ));
    }
    if flip {
        ctx.warn(
            s.loc,
            "<shape type=\"sdfgrid\">: flip_normals is not supported on SDF grids; ignored",
        );
    }
    let surface = surface(ctx, s, m)?;
    if surface.emission.is_some() {
        ctx.warn(
            s.loc,
            "<shape type=\"sdfgrid\"> cannot be an area emitter (as in Mitsuba); its emitter is skipped",
        );
    }
    let to_world = glam::Affine3A::from_mat4(super::mat4(m));
    let det = to_world.matrix3.determinant();
    if det == 0.0 || !det.is_finite() {
        return Err(ctx.error(
            s.loc,
            "<shape type=\"sdfgrid\">: to_world is not invertible",
        ));
    }
    ctx.desc.sdf_grids.push(SdfGridDesc {
        values: grid.values,
        resolution: grid.resolution,
        to_world,
        smooth_normals: smooth,
        material: surface.material,
    });
    Ok(())
}

/// Mitsuba's `rectangle`: [-1, 1]² in the xy plane facing +z, (u, v) over the unit square
/// (pathlab's v = 1 - Mitsuba's).
fn rectangle() -> MeshDesc {
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    let uvs = positions
        .iter()
        .map(|p| Vec2::new(0.5 * (p.x + 1.0), 0.5 * (1.0 - p.y)))
        .collect();
    MeshDesc {
        positions,
        indices: vec![0, 1, 2, 0, 2, 3],
        normals: vec![Vec3::Z; 4],
        uvs,
        tangents: vec![Vec3::X; 4],
        ..Default::default()
    }
}

/// Mitsuba's `cube`: [-1, 1]³, each face its own four vertices with outward normals, laid
/// out as Mitsuba lays them out (which corner of a face gets which (u, v) decides where a
/// texture lands).
fn cube() -> MeshDesc {
    // Per face: its outward normal and its corners in order; the corners take Mitsuba's
    // (u, v) = (0, 1), (1, 1), (1, 0), (0, 0), and the triangles (0, 1, 2) and (3, 0, 2).
    const FACES: [([f32; 3], [[f32; 3]; 4]); 6] = [
        (
            [0., -1., 0.],
            [
                [1., -1., -1.],
                [1., -1., 1.],
                [-1., -1., 1.],
                [-1., -1., -1.],
            ],
        ),
        (
            [0., 1., 0.],
            [[1., 1., -1.], [-1., 1., -1.], [-1., 1., 1.], [1., 1., 1.]],
        ),
        (
            [1., 0., 0.],
            [[1., -1., -1.], [1., 1., -1.], [1., 1., 1.], [1., -1., 1.]],
        ),
        (
            [0., 0., 1.],
            [[1., -1., 1.], [1., 1., 1.], [-1., 1., 1.], [-1., -1., 1.]],
        ),
        (
            [-1., 0., 0.],
            [
                [-1., -1., 1.],
                [-1., 1., 1.],
                [-1., 1., -1.],
                [-1., -1., -1.],
            ],
        ),
        (
            [0., 0., -1.],
            [
                [1., 1., -1.],
                [1., -1., -1.],
                [-1., -1., -1.],
                [-1., 1., -1.],
            ],
        ),
    ];
    // Mitsuba's v grows downwards; pathlab's is 1 - that.
    const UVS: [[f32; 2]; 4] = [[0., 0.], [1., 0.], [1., 1.], [0., 1.]];
    let mut mesh = MeshDesc::default();
    for (normal, corners) in FACES {
        let base = mesh.positions.len() as u32;
        for (corner, uv) in corners.iter().zip(UVS) {
            mesh.positions.push(Vec3::from_array(*corner));
            mesh.normals.push(Vec3::from_array(normal));
            mesh.uvs.push(Vec2::from_array(uv));
        }
        mesh.indices
            .extend([base, base + 1, base + 2, base + 3, base, base + 2]);
    }
    mesh
}

/// Mitsuba's `disk`: the unit disk in the xy plane facing +z, (u, v) = (r, φ/2π) in Mitsuba's
/// convention, as a fan of triangles.
fn disk() -> MeshDesc {
    let mut mesh = MeshDesc::default();
    let n = ROUND_SEGMENTS;
    for i in 0..=n {
        let phi = i as f32 / n as f32 * TAU;
        // The centre, repeated per segment so that u = φ/2π is continuous within each.
        mesh.positions.push(Vec3::ZERO);
        mesh.uvs
            .push(Vec2::new(0.0, 1.0 - (i as f32 + 0.5) / n as f32));
        mesh.normals.push(Vec3::Z);
        mesh.tangents.push(Vec3::new(phi.cos(), phi.sin(), 0.0));
        mesh.positions.push(Vec3::new(phi.cos(), phi.sin(), 0.0));
        mesh.uvs.push(Vec2::new(1.0, 1.0 - i as f32 / n as f32));
        mesh.normals.push(Vec3::Z);
        mesh.tangents.push(Vec3::new(phi.cos(), phi.sin(), 0.0));
    }
    for i in 0..n {
        let (c, a, b) = (2 * i, 2 * i + 1, 2 * i + 3);
        mesh.indices.extend([c, a, b]);
    }
    mesh
}

/// Mitsuba's `cylinder`: an open tube of `radius` from `p0` to `p1` (default the unit tube
/// along z), normals outwards, (u, v) = (φ/2π, z) in Mitsuba's convention.
fn cylinder(ctx: &mut Ctx, s: Obj) -> Result<MeshDesc, Error> {
    let p0 = ctx.vector(s, "p0")?.unwrap_or(DVec3::ZERO);
    let p1 = ctx.vector(s, "p1")?.unwrap_or(DVec3::Z);
    let radius = ctx.positive(s, "radius", 1.0)?;
    let axis = p1 - p0;
    let length = axis.length();
    if length <= 0.0 {
        return Err(ctx.error(
            s.loc,
            "<shape type=\"cylinder\">: p0 and p1 are the same point",
        ));
    }
    // Mitsuba's frame around the axis (Duff et al.'s basis), from which φ is measured.
    let n_axis = axis.normalize();
    let (t1, t2) = n_axis.any_orthonormal_pair();
    let frame = DMat4::from_cols(
        (t1 * radius).extend(0.0),
        (t2 * radius).extend(0.0),
        axis.extend(0.0),
        p0.extend(1.0),
    );
    let mut mesh = MeshDesc::default();
    let n = ROUND_SEGMENTS;
    for i in 0..=n {
        let phi = i as f32 / n as f32 * TAU;
        let (c, sn) = (phi.cos(), phi.sin());
        for z in [0.0f32, 1.0] {
            let local = DVec3::new(c as f64, sn as f64, z as f64);
            mesh.positions.push(frame.transform_point3(local).as_vec3());
            let normal = (t1 * c as f64 + t2 * sn as f64).as_vec3();
            mesh.normals.push(normal);
            mesh.uvs.push(Vec2::new(i as f32 / n as f32, 1.0 - z));
            mesh.tangents
                .push((t2 * c as f64 - t1 * sn as f64).as_vec3());
        }
    }
    for i in 0..n {
        let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
        mesh.indices.extend([a, c, d, a, d, b]);
    }
    Ok(mesh)
}
