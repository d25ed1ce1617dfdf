//! Writing a scene as Mitsuba 3 XML, so that Mitsuba renders what pathlab loaded from any
//! format (a pbrt-v4 file, the course's COLLADA, glTF): the scene file, and its meshes as
//! binary PLY files in a folder beside it.
//!
//! The conventions are those the Mitsuba loader ([`super::load`]) reads, so that loading the
//! written file gives back the same scene: depths are Mitsuba's (`max_depth` one more than
//! pathlab's, -1 for unbounded), PLY texture coordinates have v flipped (see the loader's
//! shapes), meshes without normals are marked `face_normals`, each material is a `<bsdf>`
//! with an id that the shapes reference. Whatever Mitsuba cannot express (textures, layered
//! and principled materials, two-sided emitters, environment maps, spot lights, hidden
//! shapes...) is an error naming it, never dropped; what it expresses only approximately (a
//! pixel filter of another radius, an integrator Mitsuba lacks) is written as the nearest
//! equivalent with a warning.

use pathlab_render::bsdf::{FresnelModel, NormalDistribution};
use pathlab_render::desc::{
    FovAxis, IntegratorHint, MaterialDesc, MeshDesc, PixelFilter, Projection, Rgb, SceneDesc,
    TextureDesc, INVERSE_SQUARE,
};
use pathlab_render::mc::sampler::SamplerKind;
use std::fmt::Write as _;
use std::path::Path;

/// Why a scene cannot be written as Mitsuba XML.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExportError {
    /// Something in the scene that Mitsuba 3 has no equivalent for.
    #[error("cannot write as Mitsuba XML: {0}")]
    Unsupported(String),
    /// A file could not be written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What failed.
        message: String,
    },
}

/// A scene as Mitsuba XML: the scene file's text and the meshes it names.
#[derive(Debug, Clone)]
pub struct MitsubaScene {
    /// The XML document.
    pub xml: String,
    /// Each mesh's file name (relative to the XML file, in the folder given) and its bytes
    /// (binary PLY).
    pub meshes: Vec<(String, Vec<u8>)>,
    /// What was written only approximately.
    pub warnings: Vec<String>,
}

/// The Mitsuba XML of `desc`, its meshes in folder `mesh_folder` (relative to the XML file).
pub fn to_mitsuba(desc: &SceneDesc, mesh_folder: &str) -> Result<MitsubaScene, ExportError> {
    let mut w = Writer::default();
    w.line(0, r#"<scene version="3.0.0">"#);
    // Samples per pixel and depth as parameters, as Mitsuba's own scenes give them (`-D spp=N`).
    w.line(
        1,
        &format!(
            r#"<default name="spp" value="{}"/>"#,
            desc.hints.spp_or_default()
        ),
    );
    if let Some(d) = desc.hints.max_depth {
        w.line(
            1,
            &format!(
                r#"<default name="max_depth" value="{}"/>"#,
                mitsuba_depth(d)
            ),
        );
    }
    w.integrator(desc);
    w.sensor(desc)?;
    for (i, m) in desc.materials.iter().enumerate() {
        w.material(m, Some(&format!("mat{i}")), 1)
            .map_err(|e| match e {
                ExportError::Unsupported(what) => {
                    ExportError::Unsupported(format!("material {i}: {what}"))
                }
                other => other,
            })?;
    }
    for (i, mesh) in desc.meshes.iter().enumerate() {
        w.mesh(desc, i, mesh, mesh_folder)?;
    }
    w.other_shapes(desc)?;
    w.lights(desc)?;
    w.line(0, "</scene>");
    Ok(MitsubaScene {
        xml: w.out,
        meshes: w.meshes,
        warnings: w.warnings,
    })
}

/// Writes `desc` to `xml_path` as Mitsuba XML, its meshes in the folder `STEM-meshes` beside
/// it; returns what was written only approximately.
pub fn write_mitsuba(desc: &SceneDesc, xml_path: &Path) -> Result<Vec<String>, ExportError> {
    let stem = xml_path
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let folder = format!("{stem}-meshes");
    let scene = to_mitsuba(desc, &folder)?;
    let io = |path: &Path, e: std::io::Error| ExportError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let dir = xml_path.parent().unwrap_or(Path::new(""));
    if !scene.meshes.is_empty() {
        let mesh_dir = dir.join(&folder);
        std::fs::create_dir_all(&mesh_dir).map_err(|e| io(&mesh_dir, e))?;
    }
    for (name, bytes) in &scene.meshes {
        let path = dir.join(name);
        std::fs::write(&path, bytes).map_err(|e| io(&path, e))?;
    }
    std::fs::write(xml_path, &scene.xml).map_err(|e| io(xml_path, e))?;
    Ok(scene.warnings)
}

#[derive(Default)]
struct Writer {
    out: String,
    meshes: Vec<(String, Vec<u8>)>,
    warnings: Vec<String>,
}

/// Mitsuba's `max_depth` for pathlab's largest bounce `d`: one more (Mitsuba counts the camera
/// ray), -1 for unbounded.
fn mitsuba_depth(d: u32) -> i64 {
    if d == u32::MAX {
        -1
    } else {
        i64::from(d) + 1
    }
}

/// Three numbers as Mitsuba writes them ("x, y, z"), each the shortest decimal that reads
/// back as the same `f32`.
fn triple(v: Rgb) -> String {
    format!("{}, {}, {}", v.x, v.y, v.z)
}

fn unsupported<T>(what: impl Into<String>) -> Result<T, ExportError> {
    Err(ExportError::Unsupported(what.into()))
}

impl Writer {
    fn line(&mut self, depth: usize, text: &str) {
        let _ = writeln!(self.out, "{:width$}{text}", "", width = 4 * depth);
    }

    fn rgb(&mut self, depth: usize, name: &str, v: Rgb) {
        self.line(
            depth,
            &format!(r#"<rgb name="{name}" value="{}"/>"#, triple(v)),
        );
    }

    fn float(&mut self, depth: usize, name: &str, v: f32) {
        self.line(depth, &format!(r#"<float name="{name}" value="{v}"/>"#));
    }

    fn integer(&mut self, depth: usize, name: &str, v: impl std::fmt::Display) {
        self.line(depth, &format!(r#"<integer name="{name}" value="{v}"/>"#));
    }

    /// `<TAG name="NAME" x=".." y=".." z=".."/>`, for `(TAG, NAME, v)`.
    fn xyz(&mut self, depth: usize, (tag, name, v): (&str, &str, glam::Vec3)) {
        self.line(
            depth,
            &format!(
                r#"<{tag} name="{name}" x="{}" y="{}" z="{}"/>"#,
                v.x, v.y, v.z
            ),
        );
    }

    /// An `<emitter>` of `kind` placed by `at` (a point or a direction, see [`Writer::xyz`]),
    /// whose colour property `name` is `value`.
    fn emitter(
        &mut self,
        kind: &str,
        at: Option<(&str, &str, glam::Vec3)>,
        name: &str,
        value: Rgb,
    ) {
        self.line(1, &format!(r#"<emitter type="{kind}">"#));
        if let Some(at) = at {
            self.xyz(2, at);
        }
        self.rgb(2, name, value);
        self.line(1, "</emitter>");
    }

    fn integrator(&mut self, desc: &SceneDesc) {
        let h = &desc.hints;
        match h.integrator {
            Some(IntegratorHint::Direct {
                emitter_samples,
                bsdf_samples,
            }) => {
                self.line(1, r#"<integrator type="direct">"#);
                self.integer(2, "emitter_samples", emitter_samples);
                self.integer(2, "bsdf_samples", bsdf_samples);
            }
            other => {
                if other == Some(IntegratorHint::Bdpt) {
                    self.warnings.push(
                        "Mitsuba 3 has no bidirectional path tracer: the scene names the path \
                         tracer instead (same image, other noise)"
                            .into(),
                    );
                }
                self.line(1, r#"<integrator type="path">"#);
                if h.max_depth.is_some() {
                    self.integer(2, "max_depth", "$max_depth");
                }
                if let Some(d) = h.rr_depth {
                    self.integer(2, "rr_depth", i64::from(d) + 1);
                }
            }
        }
        if h.hide_emitters {
            self.line(2, r#"<boolean name="hide_emitters" value="true"/>"#);
        }
        self.line(1, "</integrator>");
    }

    fn sensor(&mut self, desc: &SceneDesc) -> Result<(), ExportError> {
        let c = &desc.camera;
        if let Projection::Orthographic { .. } = c.projection {
            return unsupported("an orthographic camera");
        }
        let [width, height] = desc.resolution;
        let (fov, axis) = match c.focal_pixels {
            // The course's cameras: the image plane `f` pixels away, so the vertical field
            // of view follows from the height (where `f` is usable, as the camera takes it).
            Some(f) if f > 0.0 && f.is_finite() => (
                2.0 * (height as f32 * 0.5 / f).atan().to_degrees(),
                FovAxis::Y,
            ),
            _ => (c.fov_degrees, c.fov_axis),
        };
        let axis = match axis {
            FovAxis::X => "x",
            FovAxis::Y => "y",
            FovAxis::Smaller => "smaller",
            FovAxis::Larger => "larger",
            FovAxis::Diagonal => "diagonal",
        };
        let thin_lens = c.lens_radius > 0.0;
        self.line(
            1,
            &format!(
                r#"<sensor type="{}">"#,
                if thin_lens { "thinlens" } else { "perspective" }
            ),
        );
        self.line(2, &format!(r#"<string name="fov_axis" value="{axis}"/>"#));
        self.float(2, "fov", fov);
        if thin_lens {
            self.float(2, "aperture_radius", c.lens_radius);
            self.float(2, "focus_distance", c.focal_distance);
        }
        // Mitsuba needs a positive near plane and a finite far one.
        self.float(
            2,
            "near_clip",
            if c.near_clip > 0.0 { c.near_clip } else { 1e-4 },
        );
        let far = if c.far_clip.is_finite() {
            c.far_clip
        } else {
            let reach = desc.bounds().map_or(0.0, |(lo, hi)| {
                (c.origin - (lo + hi) * 0.5).length() + (hi - lo).length()
            });
            (2.0 * reach).max(1e4)
        };
        self.float(2, "far_clip", far);
        if c.principal_point_offset != glam::Vec2::ZERO {
            self.float(2, "principal_point_offset_x", c.principal_point_offset.x);
            self.float(2, "principal_point_offset_y", c.principal_point_offset.y);
        }
        self.line(2, r#"<transform name="to_world">"#);
        self.line(
            3,
            &format!(
                r#"<lookat origin="{}" target="{}" up="{}"/>"#,
                triple(c.origin),
                triple(c.target),
                triple(c.up)
            ),
        );
        self.line(2, "</transform>");
        let h = &desc.hints;
        let sampler = match h.sampler.unwrap_or(SamplerKind::Independent) {
            SamplerKind::Independent => "independent",
            SamplerKind::Stratified => "stratified",
            // Mitsuba's low-discrepancy sampler (its loader reads it back as Sobol).
            SamplerKind::Sobol => "ldsampler",
        };
        self.line(2, &format!(r#"<sampler type="{sampler}">"#));
        self.integer(3, "sample_count", "$spp");
        self.line(2, "</sampler>");
        self.line(2, r#"<film type="hdrfilm">"#);
        self.integer(3, "width", width);
        self.integer(3, "height", height);
        self.line(3, r#"<string name="pixel_format" value="rgb"/>"#);
        if let Some(crop) = h.crop.and_then(|c| c.window_for(desc.resolution)) {
            let [x0, y0, x1, y1] = crop;
            for (name, v) in [
                ("crop_offset_x", x0),
                ("crop_offset_y", y0),
                ("crop_width", x1 - x0),
                ("crop_height", y1 - y0),
            ] {
                self.integer(3, name, v);
            }
        }
        self.filter(desc.filter);
        self.line(2, "</film>");
        self.line(1, "</sensor>");
        Ok(())
    }

    fn filter(&mut self, filter: PixelFilter) {
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-5 * b.abs().max(1.0);
        match filter {
            PixelFilter::Box => self.line(3, r#"<rfilter type="box"/>"#),
            PixelFilter::Tent { radius } => {
                self.line(3, r#"<rfilter type="tent">"#);
                self.float(4, "radius", radius);
                self.line(3, "</rfilter>");
            }
            PixelFilter::Gaussian { stddev, radius } => {
                if !close(radius, 4.0 * stddev) {
                    self.warnings.push(format!(
                        "Mitsuba's Gaussian filter ends at 4 standard deviations ({} px), \
                         not at {radius} px",
                        4.0 * stddev
                    ));
                }
                self.line(3, r#"<rfilter type="gaussian">"#);
                self.float(4, "stddev", stddev);
                self.line(3, "</rfilter>");
            }
            PixelFilter::Mitchell { radius, b, c } => {
                if !close(radius, 2.0) {
                    self.warnings.push(format!(
                        "Mitsuba's Mitchell filter has radius 2 px, not {radius} px"
                    ));
                }
                self.line(3, r#"<rfilter type="mitchell">"#);
                self.float(4, "B", b);
                self.float(4, "C", c);
                self.line(3, "</rfilter>");
            }
            PixelFilter::LanczosSinc { radius, tau } => {
                if !close(radius, tau) {
                    self.warnings.push(format!(
                        "Mitsuba's Lanczos filter's radius is its lobes ({tau}), not {radius} px"
                    ));
                }
                self.line(3, r#"<rfilter type="lanczos">"#);
                self.integer(4, "lobes", tau.round() as i64);
                self.line(3, "</rfilter>");
            }
        }
    }

    /// A constant texture's value, or an error naming the material's textured `what`.
    fn constant(t: &TextureDesc, what: &str) -> Result<Rgb, ExportError> {
        t.as_constant()
            .ok_or_else(|| ExportError::Unsupported(format!("a textured {what}")))
    }

    fn distribution(&mut self, depth: usize, d: NormalDistribution) {
        let name = match d {
            NormalDistribution::Beckmann => "beckmann",
            NormalDistribution::Ggx => "ggx",
        };
        self.line(
            depth,
            &format!(r#"<string name="distribution" value="{name}"/>"#),
        );
    }

    /// A conductor's `<bsdf>` opening and properties (`open` gives its opening tag): smooth
    /// where both roughnesses are 0, else rough (one α or α along u and v).
    #[allow(clippy::too_many_arguments)]
    fn conductor(
        &mut self,
        open: &dyn Fn(&str) -> String,
        d: usize,
        (alpha_u, alpha_v): (f32, f32),
        distribution: NormalDistribution,
        eta: Rgb,
        k: Rgb,
        specular: Option<Rgb>,
    ) {
        if alpha_u > 0.0 || alpha_v > 0.0 {
            self.line(d - 1, &open("roughconductor"));
            self.distribution(d, distribution);
            if alpha_u == alpha_v {
                self.float(d, "alpha", alpha_u);
            } else {
                self.float(d, "alpha_u", alpha_u);
                self.float(d, "alpha_v", alpha_v);
            }
        } else {
            self.line(d - 1, &open("conductor"));
        }
        self.rgb(d, "eta", eta);
        self.rgb(d, "k", k);
        if let Some(s) = specular {
            self.rgb(d, "specular_reflectance", s);
        }
    }

    /// An index of refraction inside relative to outside, as Mitsuba's pair (outside 1).
    fn ior(&mut self, d: usize, ior: f32) {
        self.float(d, "int_ior", ior);
        self.float(d, "ext_ior", 1.0);
    }

    /// A dielectric interface's index and scales.
    fn interface(&mut self, d: usize, ior: f32, reflectance: Rgb, transmittance: Rgb) {
        self.ior(d, ior);
        self.rgb(d, "specular_reflectance", reflectance);
        self.rgb(d, "specular_transmittance", transmittance);
    }

    /// What a plastic and a rough plastic share: the base, the coat's scale and index, and
    /// whether internal reflections tint.
    fn plastic(&mut self, d: usize, diffuse: Rgb, specular: Rgb, ior: f32, nonlinear: bool) {
        self.rgb(d, "diffuse_reflectance", diffuse);
        self.rgb(d, "specular_reflectance", specular);
        self.ior(d, ior);
        self.line(
            d,
            &format!(r#"<boolean name="nonlinear" value="{nonlinear}"/>"#),
        );
    }

    /// `<bsdf>` of material `m` (with `id` where given), at indentation `depth`.
    fn material(
        &mut self,
        m: &MaterialDesc,
        id: Option<&str>,
        depth: usize,
    ) -> Result<(), ExportError> {
        let id = id.map_or(String::new(), |id| format!(r#" id="{id}""#));
        let open = |kind: &str| format!(r#"<bsdf type="{kind}"{id}>"#);
        let d = depth + 1;
        match m {
            MaterialDesc::Diffuse {
                reflectance,
                two_sided,
            } => {
                let mut inner = depth;
                if *two_sided {
                    self.line(depth, &open("twosided"));
                    inner += 1;
                    self.line(inner, r#"<bsdf type="diffuse">"#);
                } else {
                    self.line(depth, &open("diffuse"));
                }
                self.rgb(inner + 1, "reflectance", *reflectance);
                self.line(inner, "</bsdf>");
                if *two_sided {
                    self.line(depth, "</bsdf>");
                }
                return Ok(());
            }
            MaterialDesc::Mirror { reflectance } => {
                // A conductor of no absorption loss: Mitsuba's `none` material reflects all.
                self.line(depth, &open("conductor"));
                self.line(d, r#"<string name="material" value="none"/>"#);
                self.rgb(d, "specular_reflectance", *reflectance);
            }
            MaterialDesc::Conductor {
                alpha,
                eta,
                k,
                distribution,
            } => self.conductor(&open, d, (*alpha, *alpha), *distribution, *eta, *k, None),
            MaterialDesc::RoughConductor {
                alpha_u,
                alpha_v,
                eta,
                k,
                specular,
                distribution,
            } => {
                let alphas = (
                    Self::constant(alpha_u, "roughness")?.x,
                    Self::constant(alpha_v, "roughness")?.x,
                );
                let specular = Self::constant(specular, "specular reflectance")?;
                self.conductor(&open, d, alphas, *distribution, *eta, *k, Some(specular));
            }
            MaterialDesc::Glass {
                reflectance,
                transmittance,
                roughness,
                ior,
                distribution,
                fresnel,
            } => {
                if *fresnel != FresnelModel::Exact {
                    return unsupported("glass with Schlick's Fresnel approximation");
                }
                if *roughness > 0.0 {
                    self.line(depth, &open("roughdielectric"));
                    self.distribution(d, *distribution);
                    self.float(d, "alpha", *roughness);
                } else {
                    self.line(depth, &open("dielectric"));
                }
                self.interface(d, *ior, *reflectance, *transmittance);
            }
            MaterialDesc::ThinGlass {
                reflectance,
                transmittance,
                ior,
            } => {
                self.line(depth, &open("thindielectric"));
                self.interface(d, *ior, *reflectance, *transmittance);
            }
            MaterialDesc::Plastic {
                diffuse,
                specular,
                ior,
                nonlinear,
            } => {
                self.line(depth, &open("plastic"));
                self.plastic(d, *diffuse, *specular, *ior, *nonlinear);
            }
            MaterialDesc::RoughPlastic {
                diffuse,
                specular,
                alpha,
                ior,
                nonlinear,
                distribution,
            } => {
                self.line(depth, &open("roughplastic"));
                self.distribution(d, *distribution);
                self.float(d, "alpha", *alpha);
                let diffuse = Self::constant(diffuse, "plastic base")?;
                self.plastic(d, diffuse, *specular, *ior, *nonlinear);
            }
            MaterialDesc::TwoSided { front, back } => {
                self.line(depth, &open("twosided"));
                self.material(front, None, d)?;
                if front != back {
                    self.material(back, None, d)?;
                }
            }
            other => {
                return unsupported(format!("a {} material", other.kind()));
            }
        }
        self.line(depth, "</bsdf>");
        Ok(())
    }

    /// An area emitter of radiance `radiance` (one-sided), inside a shape.
    fn area_emitter(
        &mut self,
        emission: Option<&pathlab_render::desc::Emission>,
        textured: bool,
        what: &str,
    ) -> Result<(), ExportError> {
        if textured {
            return unsupported(format!("{what}: a textured emitter"));
        }
        if let Some(e) = emission {
            if e.two_sided {
                return unsupported(format!("{what}: an emitter of both sides"));
            }
            self.line(2, r#"<emitter type="area">"#);
            self.rgb(3, "radiance", e.radiance);
            self.line(2, "</emitter>");
        }
        Ok(())
    }

    fn mesh(
        &mut self,
        desc: &SceneDesc,
        index: usize,
        mesh: &MeshDesc,
        folder: &str,
    ) -> Result<(), ExportError> {
        let what = format!("mesh '{}'", mesh.name);
        if !(mesh.visibility.camera && mesh.visibility.indirect) {
            return unsupported(format!("{what}: a shape some rays do not see"));
        }
        let name = format!("{folder}/mesh{index:04}.ply");
        self.meshes.push((name.clone(), ply(mesh)));
        self.line(1, r#"<shape type="ply">"#);
        self.line(2, &format!(r#"<string name="filename" value="{name}"/>"#));
        if !has_vertex_normals(mesh) {
            self.line(2, r#"<boolean name="face_normals" value="true"/>"#);
        }
        self.material_ref(desc, mesh.material, &what)?;
        self.area_emitter(
            mesh.emission.as_ref(),
            mesh.emission_texture.is_some(),
            &what,
        )?;
        self.line(1, "</shape>");
        Ok(())
    }

    /// A shape's reference to material `index` of `desc` (an error naming shape `what` where
    /// there is no such material).
    fn material_ref(
        &mut self,
        desc: &SceneDesc,
        index: usize,
        what: &str,
    ) -> Result<(), ExportError> {
        if index >= desc.materials.len() {
            return unsupported(format!("{what}: material {index} does not exist"));
        }
        self.line(2, &format!(r#"<ref id="mat{index}"/>"#));
        Ok(())
    }

    /// The shapes besides meshes: spheres (signed distance grids are not written).
    fn other_shapes(&mut self, desc: &SceneDesc) -> Result<(), ExportError> {
        if !desc.sdf_grids.is_empty() {
            return unsupported("a signed distance grid");
        }
        for (i, s) in desc.spheres.iter().enumerate() {
            let what = format!("sphere {i}");
            self.line(1, r#"<shape type="sphere">"#);
            self.xyz(2, ("point", "center", s.center));
            self.float(2, "radius", s.radius);
            self.material_ref(desc, s.material, &what)?;
            self.area_emitter(s.emission.as_ref(), s.emission_texture.is_some(), &what)?;
            self.line(1, "</shape>");
        }
        Ok(())
    }

    fn lights(&mut self, desc: &SceneDesc) -> Result<(), ExportError> {
        if !desc.spot_lights.is_empty() || !desc.projectors.is_empty() {
            return unsupported("a spot light or projector");
        }
        if let Some(map) = &desc.environment_map {
            return unsupported(format!("the environment map {}", map.source));
        }
        for p in &desc.point_lights {
            if p.attenuation != INVERSE_SQUARE {
                return unsupported("a point light whose falloff is not the inverse square");
            }
            let at = ("point", "position", p.position);
            self.emitter("point", Some(at), "intensity", p.intensity);
        }
        for l in &desc.directional_lights {
            let along = ("vector", "direction", l.direction);
            self.emitter("directional", Some(along), "irradiance", l.irradiance);
        }
        if let Some(radiance) = desc.environment {
            self.emitter("constant", None, "radiance", radiance);
        }
        Ok(())
    }
}

/// Whether the mesh's shading normals are its vertex normals: one per vertex, as the renderer
/// takes them (otherwise it shades with face normals).
fn has_vertex_normals(mesh: &MeshDesc) -> bool {
    !mesh.positions.is_empty() && mesh.normals.len() == mesh.positions.len()
}

/// A mesh as binary little-endian PLY: positions, normals and texture coordinates where it has
/// them (v flipped: pathlab's v runs the other way from a PLY file's, see the loader), and its
/// triangles.
fn ply(mesh: &MeshDesc) -> Vec<u8> {
    let n = mesh.positions.len();
    let normals = has_vertex_normals(mesh);
    let uvs = mesh.uvs.len() == n && n > 0;
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by pathlab\nelement vertex {n}\n\
         property float x\nproperty float y\nproperty float z\n"
    );
    if normals {
        header.push_str("property float nx\nproperty float ny\nproperty float nz\n");
    }
    if uvs {
        header.push_str("property float u\nproperty float v\n");
    }
    let _ = write!(
        header,
        "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.indices.len() / 3
    );
    let mut out = header.into_bytes();
    let mut put = |x: f32| out.extend_from_slice(&x.to_le_bytes());
    for i in 0..n {
        for x in mesh.positions[i].to_array() {
            put(x);
        }
        if normals {
            for x in mesh.normals[i].to_array() {
                put(x);
            }
        }
        if uvs {
            put(mesh.uvs[i].x);
            put(1.0 - mesh.uvs[i].y);
        }
    }
    for t in mesh.indices.chunks_exact(3) {
        out.push(3);
        for &i in t {
            out.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    out
}
