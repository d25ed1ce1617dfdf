//! pbrt-v4's shapes as pathlab's triangle meshes and spheres.
//!
//! Orientation follows pbrt-v4: a triangle's surface normal is its winding's (the edges
//! p0 - p2, p1 - p2 crossed) carried as a normal into the world, turned towards the mesh's
//! shading normals where it has them, and reversed by `ReverseOrientation`; one-sided area
//! lights emit on that side. pathlab takes the front of a triangle from its winding, so the
//! winding is swapped where the two disagree.

use super::params::ParamList;
use super::quadrics::SphereExtent;
use super::spectra::Use;
use super::{Builder, GraphicsState};
use crate::Error;
use glam::{DMat3, DMat4, DVec3, Vec2, Vec3};
use pathlab_render::desc::{Emission, MaterialDesc, MeshDesc, Rgb, TextureDesc};
use std::sync::Arc;

/// Segments around a tessellated disk or cylinder: the area is right to 0.03%.
pub(super) const SEGMENTS: usize = 256;

/// An area light's emission: its radiance (times the image's texel where it has one), and
/// the power each of its shapes emits where the file gives one.
pub(super) struct AreaEmission {
    emission: Emission,
    power: Option<f64>,
    pub(super) texture: Option<TextureDesc>,
}

impl AreaEmission {
    /// The radiance scaled, where a power is given, so that a shape of `area` emits it: pbrt-v4
    /// divides by π A × sides and by the image's mean luminance.
    pub(super) fn for_area(&self, area: f64) -> Emission {
        let Some(watts) = self.power else {
            return self.emission;
        };
        let image = self
            .texture
            .as_ref()
            .map_or(1.0, |t| pathlab_render::color::luminance(t.mean()) as f64);
        let sides = if self.emission.two_sided { 2.0 } else { 1.0 };
        let k = watts / (std::f64::consts::PI * area * sides * image.max(1e-12));
        Emission {
            radiance: self.emission.radiance * k as f32,
            ..self.emission
        }
    }
}

/// A mesh in the shape's own space.
#[derive(Default)]
pub(super) struct ObjectMesh {
    pub(super) positions: Vec<DVec3>,
    pub(super) indices: Vec<u32>,
    pub(super) normals: Vec<DVec3>,
    pub(super) uvs: Vec<Vec2>,
}

impl Builder {
    /// `Shape "kind" ...` with the graphics state `state`.
    pub(crate) fn shape(
        &mut self,
        kind: &str,
        params: ParamList,
        state: &GraphicsState,
    ) -> Result<(), Error> {
        let m = self.world_fix * state.ctm;
        if m.determinant().abs() < 1e-300 || !m.is_finite() {
            return Err(self.error(format!("Shape \"{kind}\": its transform is singular")));
        }
        let material = self.shape_material(&params, state)?;
        let emission = self.area_emission(state)?;
        let mesh = match kind {
            "sphere" => match self.sphere_extent(&params)? {
                SphereExtent::Whole(radius) => {
                    self.sphere(radius, m, material, emission.as_ref(), state)?;
                    self.warn_unused(&format!("Shape \"{kind}\""), &params);
                    return Ok(());
                }
                SphereExtent::Partial(mesh) => mesh,
            },
            "trianglemesh" => self.triangle_mesh(&params)?,
            "plymesh" => self.ply_mesh(&params)?,
            "bilinearmesh" => self.bilinear_mesh(&params)?,
            "loopsubdiv" => self.loop_subdiv(&params)?,
            "disk" => self.disk(&params)?,
            "cylinder" => self.cylinder(&params)?,
            other => {
                for p in &params.params {
                    p.used.set(true);
                }
                self.warn(format!("Shape \"{other}\": not supported; skipped"));
                return Ok(());
            }
        };
        self.warn_unused(&format!("Shape \"{kind}\""), &params);
        let mut out = place(mesh, m, state.reverse_orientation);
        out.name = format!("{}:{} {kind}", self.file.display(), self.line);
        out.material = material;
        out.emission = emission.as_ref().map(|e| e.emission);
        out.emission_texture = emission.as_ref().and_then(|e| e.texture.clone());
        match emission {
            Some(e) if e.power.is_some() => {
                // pbrt-v4 makes a light of each triangle of a mesh (each patch of a bilinear
                // mesh), each emitting `power`; a disk or cylinder is one light.
                let per_unit = match kind {
                    "disk" | "cylinder" | "sphere" => out.indices.len() / 3,
                    "bilinearmesh" => 2,
                    _ => 1,
                };
                self.desc.meshes.extend(split_by_power(out, &e, per_unit));
            }
            _ => self.desc.meshes.push(out),
        }
        Ok(())
    }

    /// The shape's material: the current one (pbrt's default diffuse 0.5 without one),
    /// under a mask where the shape has an `alpha`.
    fn shape_material(
        &mut self,
        params: &ParamList,
        state: &GraphicsState,
    ) -> Result<usize, Error> {
        let base = match state.material {
            Some(m) => m,
            None => self.default_material(),
        };
        if !params.has("alpha") {
            return Ok(base);
        }
        let alpha = match self.texture_param(params, "alpha")? {
            Some(t) => t,
            None => TextureDesc::value(self.float(params, "alpha", 1.0)?.clamp(0.0, 1.0) as f32),
        };
        if alpha.as_constant() == Some(Rgb::ONE) {
            return Ok(base);
        }
        let inner = self.desc.materials[base].clone();
        self.desc.materials.push(MaterialDesc::Mask {
            opacity: alpha,
            inner: Box::new(inner),
        });
        Ok(self.desc.materials.len() - 1)
    }

    /// pbrt-v4's default material: diffuse, reflectance 0.5 (made once).
    fn default_material(&mut self) -> usize {
        if let Some(&m) = self.named_materials.get("\0default") {
            return m;
        }
        self.desc.materials.push(MaterialDesc::Diffuse {
            reflectance: Rgb::splat(0.5),
            two_sided: true,
        });
        let m = self.desc.materials.len() - 1;
        self.named_materials.insert("\0default".into(), m);
        m
    }

    /// The emission of the current area light, if any.
    fn area_emission(&mut self, state: &GraphicsState) -> Result<Option<AreaEmission>, Error> {
        let Some((kind, params, line)) = &state.area_light else {
            return Ok(None);
        };
        let (params, line) = (params.clone(), *line);
        let here = self.line;
        self.line = line;
        if kind != "diffuse" {
            self.warn(format!(
                "AreaLightSource \"{kind}\": not supported; the shape does not emit"
            ));
            self.line = here;
            return Ok(None);
        }
        let l = self.spectrum(&params, "L", Use::Illuminant)?;
        let scale = self.emission_scale(&params)?;
        let two_sided = self.bool(&params, "twosided", false)?;
        // pbrt-v4: a power of 0 or less is no power at all.
        let power = Some(self.float(&params, "power", -1.0)?).filter(|&p| p > 0.0);
        let mut texture = None;
        if let Some(file) = self.string(&params, "filename")? {
            if l.is_some() {
                return Err(self.error("AreaLightSource: both \"L\" and \"filename\" are given"));
            }
            match crate::texture::load(&self.resolve(&file), false) {
                Ok(image) => texture = Some(TextureDesc::image(image)),
                Err(e) => self.warn(format!(
                    "AreaLightSource: {e}; it emits white light of radiance scale instead"
                )),
            }
        }
        self.warn_unused("AreaLightSource \"diffuse\"", &params);
        self.line = here;
        Ok(Some(AreaEmission {
            emission: Emission {
                radiance: l.unwrap_or(Vec3::ONE) * scale,
                two_sided,
            },
            power,
            texture,
        }))
    }

    pub(super) fn param_numbers<'p>(
        &self,
        params: &'p ParamList,
        name: &str,
    ) -> Result<Option<&'p [f64]>, Error> {
        match params.get(name) {
            None => Ok(None),
            Some(p) => p.numbers().map(Some).ok_or_else(|| {
                self.error(format!(
                    "\"{} {name}\" (line {}): expected numbers",
                    p.ty, p.line
                ))
            }),
        }
    }

    /// `P`, `N`, `uv` and `indices` as pbrt-v4's triangle and bilinear meshes give them.
    fn mesh_arrays(&self, params: &ParamList, per_face: usize) -> Result<ObjectMesh, Error> {
        let p = self
            .param_numbers(params, "P")?
            .ok_or_else(|| self.error("the mesh has no \"point3 P\""))?;
        let positions: Vec<DVec3> = p
            .chunks_exact(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect();
        let n = positions.len();
        let indices: Vec<u32> = match self.param_numbers(params, "indices")? {
            Some(v) => v
                .iter()
                .map(|&i| {
                    if i < 0.0 || i >= n as f64 {
                        Err(self.error(format!("index {i} out of range ({n} vertices)")))
                    } else {
                        Ok(i as u32)
                    }
                })
                .collect::<Result<_, _>>()?,
            None if n == per_face => (0..n as u32).collect(),
            None => {
                return Err(self.error(format!(
                    "the mesh has {n} vertices and no \"integer indices\""
                )))
            }
        };
        if !indices.len().is_multiple_of(per_face) {
            return Err(self.error(format!(
                "{} indices are not a whole number of {}",
                indices.len(),
                if per_face == 3 {
                    "triangles"
                } else {
                    "bilinear patches"
                }
            )));
        }
        let normals: Vec<DVec3> = match self.param_numbers(params, "N")? {
            Some(v) => {
                if v.len() != 3 * n {
                    return Err(self.error(format!(
                        "\"normal N\": {} normals for {n} vertices",
                        v.len() / 3
                    )));
                }
                v.chunks_exact(3)
                    .map(|c| DVec3::new(c[0], c[1], c[2]))
                    .collect()
            }
            None => Vec::new(),
        };
        let uv = match self.param_numbers(params, "uv")? {
            Some(v) => Some(v),
            None => self.param_numbers(params, "st")?,
        };
        let uvs: Vec<Vec2> = match uv {
            Some(v) => {
                if v.len() != 2 * n {
                    return Err(self.error(format!(
                        "\"point2 uv\": {} coordinates for {n} vertices",
                        v.len() / 2
                    )));
                }
                v.chunks_exact(2)
                    .map(|c| Vec2::new(c[0] as f32, c[1] as f32))
                    .collect()
            }
            None => Vec::new(),
        };
        if params.has("S") {
            params.get("S");
        }
        for name in ["faceIndices", "emissionfilename"] {
            if params.has(name) {
                params.get(name);
            }
        }
        Ok(ObjectMesh {
            positions,
            indices,
            normals,
            uvs,
        })
    }

    fn triangle_mesh(&self, params: &ParamList) -> Result<ObjectMesh, Error> {
        self.mesh_arrays(params, 3)
    }

    /// `loopsubdiv`: the control mesh subdivided `levels` times (3 by default) and moved to
    /// its limit surface.
    fn loop_subdiv(&mut self, params: &ParamList) -> Result<ObjectMesh, Error> {
        let levels = self.float(params, "levels", 3.0)?;
        let m = self.mesh_arrays(params, 3)?;
        let triangles = (m.indices.len() / 3) as f64;
        if !(0.0..=12.0).contains(&levels) || triangles * 4f64.powf(levels.floor()) > 64e6 {
            return Err(self.error(format!(
                "Shape \"loopsubdiv\": {levels} levels of {triangles} triangles would make more than 64 million"
            )));
        }
        if !m.uvs.is_empty() || !m.normals.is_empty() {
            self.warn("Shape \"loopsubdiv\": its uv and N are not subdivided; the limit surface's normals are used");
        }
        let (positions, indices, normals) =
            super::loop_subdiv::subdivide(m.positions, m.indices, levels as u32);
        Ok(ObjectMesh {
            positions,
            indices,
            normals,
            uvs: Vec::new(),
        })
    }

    /// Bilinear patches (vertices p00, p10, p01, p11) as two triangles each.
    fn bilinear_mesh(&mut self, params: &ParamList) -> Result<ObjectMesh, Error> {
        let mut m = self.mesh_arrays(params, 4)?;
        let quads = std::mem::take(&mut m.indices);
        let mut curved = false;
        for q in quads.chunks_exact(4) {
            let [a, b, c, d] = [q[0], q[1], q[2], q[3]];
            let p = |i: u32| m.positions[i as usize];
            let n = (p(b) - p(a)).cross(p(c) - p(a));
            curved |= n.length() > 0.0
                && (p(d) - p(a)).dot(n.normalize()).abs() > 1e-6 * (p(d) - p(a)).length();
            m.indices.extend([a, b, d, a, d, c]);
        }
        if curved {
            self.warn(
                "Shape \"bilinearmesh\": curved patches are rendered as two flat triangles each",
            );
        }
        Ok(m)
    }

    /// A PLY file's mesh (read once per file; `.ply.gz` decompressed).
    fn ply_mesh(&mut self, params: &ParamList) -> Result<ObjectMesh, Error> {
        let file = self
            .string(params, "filename")?
            .ok_or_else(|| self.error("Shape \"plymesh\": no \"string filename\""))?;
        if params.has("displacement") {
            params.get("displacement");
            params.get("edgelength");
            self.warn("Shape \"plymesh\": displacement is not supported; ignored");
        }
        let path = self.resolve(&file);
        let mesh = match self.ply_cache.get(&path) {
            Some(m) => Arc::clone(m),
            None => {
                let gz = path
                    .extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("gz"));
                // A file that cannot be opened is a warning (scenes are shared without some of
                // their meshes); one that does not decompress or parse is an error.
                let mesh = if gz {
                    super::read_bytes(&path).and_then(|bytes| {
                        crate::meshfile::ply_mesh_from(&mut std::io::Cursor::new(bytes), &path)
                    })
                } else {
                    crate::meshfile::ply_mesh(&path)
                };
                let mesh = match mesh {
                    Ok(m) => Arc::new(m),
                    Err(crate::Error::Io { message, .. }) => {
                        self.warn(format!(
                            "Shape \"plymesh\": cannot read {} ({message}); the shape is skipped",
                            path.display()
                        ));
                        Arc::new(MeshDesc::default())
                    }
                    Err(e) => return Err(e),
                };
                self.ply_cache.insert(path, Arc::clone(&mesh));
                mesh
            }
        };
        Ok(ObjectMesh {
            positions: mesh.positions.iter().map(|p| p.as_dvec3()).collect(),
            indices: mesh.indices.clone(),
            normals: mesh.normals.iter().map(|n| n.as_dvec3()).collect(),
            uvs: mesh.uvs.clone(),
        })
    }
}

/// The object-space mesh `o` in the world by `m`, wound so that its fronts are pbrt's
/// surface normals (see the module notes).
fn place(o: ObjectMesh, m: DMat4, reverse: bool) -> MeshDesc {
    let normal_matrix = DMat3::from_mat4(m).inverse().transpose();
    let positions: Vec<Vec3> = o
        .positions
        .iter()
        .map(|&p| m.transform_point3(p).as_vec3())
        .collect();
    let sign = if reverse { -1.0 } else { 1.0 };
    let normals: Vec<Vec3> = o
        .normals
        .iter()
        .map(|&n| (sign * (normal_matrix * n)).normalize_or_zero().as_vec3())
        .collect();
    let mut indices = o.indices;
    // Without shading normals, pbrt's normal is the winding's carried as a normal: the
    // world winding agrees with it unless the transform reverses orientation, and
    // ReverseOrientation reverses it.
    let swap_all = (m.determinant() < 0.0) != reverse;
    for t in indices.chunks_exact_mut(3) {
        let swap = if normals.is_empty() {
            swap_all
        } else {
            let p = |i: u32| positions[i as usize];
            let w = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
            let n = normals[t[0] as usize] + normals[t[1] as usize] + normals[t[2] as usize];
            w.dot(n) < 0.0
        };
        if swap {
            t.swap(1, 2);
        }
    }
    MeshDesc {
        positions,
        indices,
        normals,
        uvs: o.uvs,
        ..Default::default()
    }
}

/// The emitting mesh `mesh` as pbrt-v4 lights it when its area light has a `power`: each run
/// of `per_unit` triangles (one pbrt shape) emits that power, so shapes of different areas have
/// different radiance. Shapes of equal area (to 1e-6) share one mesh; each mesh keeps only
/// the vertices its triangles use.
fn split_by_power(mesh: MeshDesc, e: &AreaEmission, per_unit: usize) -> Vec<MeshDesc> {
    let per_unit = per_unit.max(1);
    let corner = |i: u32| mesh.positions[i as usize].as_dvec3();
    let triangle_area = |t: &[u32]| {
        0.5 * (corner(t[1]) - corner(t[0]))
            .cross(corner(t[2]) - corner(t[0]))
            .length()
    };
    let tris: Vec<&[u32]> = mesh.indices.chunks_exact(3).collect();
    let mut units: Vec<(f64, usize)> = tris
        .chunks(per_unit)
        .enumerate()
        .map(|(u, ts)| (ts.iter().map(|t| triangle_area(t)).sum::<f64>(), u))
        .filter(|(a, _)| *a > 0.0 && a.is_finite())
        .collect();
    units.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut groups: Vec<(f64, Vec<usize>)> = Vec::new();
    for (area, u) in units {
        match groups.last_mut() {
            Some((first, members)) if area - *first <= 1e-6 * *first => members.push(u),
            _ => groups.push((area, vec![u])),
        }
    }
    groups
        .into_iter()
        .enumerate()
        .map(|(g, (area, members))| {
            let triangles: Vec<usize> = members
                .iter()
                .flat_map(|&u| u * per_unit..((u + 1) * per_unit).min(tris.len()))
                .collect();
            let mut part = submesh(&mesh, &triangles);
            part.emission = Some(e.for_area(area));
            if g > 0 {
                part.name = format!("{} (shapes of area {area:.4e})", mesh.name);
            }
            part
        })
        .collect()
}

/// The triangles `triangles` of `mesh` as a mesh of their own, with only their vertices (its
/// named attributes, which pbrt-v4 meshes do not have, are left out).
fn submesh(mesh: &MeshDesc, triangles: &[usize]) -> MeshDesc {
    let mut remap = std::collections::HashMap::new();
    let mut used: Vec<u32> = Vec::new();
    let mut indices = Vec::with_capacity(3 * triangles.len());
    for &t in triangles {
        for &i in &mesh.indices[3 * t..3 * t + 3] {
            let j = *remap.entry(i).or_insert_with(|| {
                used.push(i);
                used.len() as u32 - 1
            });
            indices.push(j);
        }
    }
    let pick = |v: &Vec<Vec3>| -> Vec<Vec3> {
        if v.is_empty() {
            Vec::new()
        } else {
            used.iter().map(|&i| v[i as usize]).collect()
        }
    };
    MeshDesc {
        positions: pick(&mesh.positions),
        normals: pick(&mesh.normals),
        tangents: pick(&mesh.tangents),
        uvs: if mesh.uvs.is_empty() {
            Vec::new()
        } else {
            used.iter().map(|&i| mesh.uvs[i as usize]).collect()
        },
        indices,
        name: mesh.name.clone(),
        material: mesh.material,
        emission: mesh.emission,
        visibility: mesh.visibility,
        emission_texture: mesh.emission_texture.clone(),
        // pbrt-v4 meshes carry no named attributes.
        attributes: Vec::new(),
    }
}
