//! pbrt-v4's materials as pathlab's, and the parameters they read (numbers, booleans,
//! strings, texture references, roughness, indices of refraction); spectra are
//! [`super::spectra`]'s.

use super::params::ParamList;
use super::spectra::Use;
use super::Builder;
use crate::mitsuba::ior::named_conductor;
use crate::Error;
use glam::Vec3;
use pathlab_render::desc::{
    CoatedBase, CoatedDesc, FresnelModel, MaterialDesc, NormalDistribution, Rgb, TextureDesc,
};

/// A surface's roughness as pbrt-v4's conductors and dielectrics give it.
enum Roughness {
    /// One α everywhere, both ways.
    Isotropic(f32),
    /// α along u and along v, textures (constants where the two numbers differ).
    Varying([TextureDesc; 2]),
}

impl Builder {
    /// A float parameter (exactly one value, as pbrt-v4 requires) or `default`.
    pub(crate) fn float(&self, params: &ParamList, name: &str, default: f64) -> Result<f64, Error> {
        match params.get(name) {
            None => Ok(default),
            Some(p) => match p.numbers() {
                Some([v]) => Ok(*v),
                Some(v) if v.len() > 1 => Err(self.error(format!(
                    "\"{} {}\" (line {}): expected one number, found {}",
                    p.ty,
                    p.name,
                    p.line,
                    v.len()
                ))),
                _ => Err(self.error(format!(
                    "\"{} {}\" (line {}): expected a number",
                    p.ty, p.name, p.line
                ))),
            },
        }
    }

    /// A bool parameter or `default`.
    pub(crate) fn bool(
        &self,
        params: &ParamList,
        name: &str,
        default: bool,
    ) -> Result<bool, Error> {
        match params.get(name) {
            None => Ok(default),
            Some(p) => match &p.values {
                super::params::Values::Bools(v) if v.len() == 1 => Ok(v[0]),
                _ => Err(self.error(format!(
                    "\"{} {}\" (line {}): expected one true or false",
                    p.ty, p.name, p.line
                ))),
            },
        }
    }

    /// A string parameter.
    pub(crate) fn string(&self, params: &ParamList, name: &str) -> Result<Option<String>, Error> {
        match params.get(name) {
            None => Ok(None),
            Some(p) => match p.strings() {
                Some([s]) => Ok(Some(s.clone())),
                _ => Err(self.error(format!(
                    "\"{} {}\" (line {}): expected one string",
                    p.ty, p.name, p.line
                ))),
            },
        }
    }

    /// The named texture a `"texture NAME"` parameter refers to (`None` when the parameter is
    /// not a texture reference).
    pub(crate) fn texture_param(
        &self,
        params: &ParamList,
        name: &str,
    ) -> Result<Option<TextureDesc>, Error> {
        let Some(p) = params
            .params
            .iter()
            .rev()
            .find(|p| p.name == name && p.ty == "texture")
        else {
            return Ok(None);
        };
        p.used.set(true);
        let tex = match p.strings() {
            Some([t]) => t.clone(),
            _ => {
                return Err(self.error(format!(
                    "\"texture {name}\" (line {}): expected one texture name",
                    p.line
                )))
            }
        };
        match self.textures.get(&tex) {
            Some(t) => Ok(Some(t.clone())),
            None => Err(self.error(format!(
                "\"texture {name}\" (line {}): no texture named \"{tex}\"",
                p.line
            ))),
        }
    }

    /// A colour that may be a texture: `"texture NAME"` or a spectrum.
    pub(super) fn color_texture(
        &mut self,
        params: &ParamList,
        name: &str,
        default: Rgb,
    ) -> Result<TextureDesc, Error> {
        if let Some(t) = self.texture_param(params, name)? {
            return Ok(t);
        }
        Ok(TextureDesc::Constant(
            self.spectrum(params, name, Use::Albedo)?.unwrap_or(default),
        ))
    }

    /// A number that may be a texture; textures other than constants are used by their mean
    /// (with a warning).
    fn float_value(&mut self, params: &ParamList, name: &str, default: f64) -> Result<f64, Error> {
        if let Some(t) = self.texture_param(params, name)? {
            if t.as_constant().is_none() {
                self.warn(format!(
                    "\"texture {name}\": a textured {name} is not supported; its mean is used"
                ));
            }
            return Ok(t.mean().x as f64);
        }
        self.float(params, name, default)
    }

    /// `roughness`, `uroughness`, `vroughness` and `remaproughness` of a conductor or a
    /// dielectric: one α, or α along u and v where they differ or are textured.
    fn surface_roughness(&mut self, params: &ParamList) -> Result<Roughness, Error> {
        if let Some(alphas) = self.textured_roughness(params, "")? {
            return Ok(Roughness::Varying(alphas));
        }
        let (au, av) = self.roughness_of(params, "")?;
        Ok(if au == av {
            Roughness::Isotropic(au)
        } else {
            Roughness::Varying([TextureDesc::value(au), TextureDesc::value(av)])
        })
    }

    /// `{prefix}roughness`, `{prefix}uroughness` and `{prefix}vroughness` as α along u and v,
    /// each a texture, where one of them is a texture that varies (`None` where all are
    /// numbers): `uroughness` and `vroughness` default to `roughness`, and the remapping √ is
    /// a texture node.
    fn textured_roughness(
        &mut self,
        params: &ParamList,
        prefix: &str,
    ) -> Result<Option<[TextureDesc; 2]>, Error> {
        let mut varies = false;
        let mut get = |b: &mut Self, name: &str| -> Result<Option<TextureDesc>, Error> {
            Ok(match b.texture_param(params, name)? {
                Some(t) => {
                    varies |= t.as_constant().is_none();
                    Some(t)
                }
                None if params.has(name) => {
                    let value = b.float(params, name, 0.0)?;
                    b.check_roughness(params, name, value)?;
                    Some(TextureDesc::value(value as f32))
                }
                None => None,
            })
        };
        let r = get(self, &format!("{prefix}roughness"))?;
        let u = get(self, &format!("{prefix}uroughness"))?;
        let v = get(self, &format!("{prefix}vroughness"))?;
        if !varies {
            return Ok(None);
        }
        let r = r.unwrap_or(TextureDesc::value(0.0));
        let remap = self.bool(params, "remaproughness", true)?;
        let alpha = |t: TextureDesc| if remap { t.sqrt() } else { t };
        Ok(Some([
            alpha(u.unwrap_or_else(|| r.clone())),
            alpha(v.unwrap_or(r)),
        ]))
    }

    /// An error naming parameter `name` unless its roughness `value` is a number ≥ 0 (pbrt-v4
    /// would take the square root of a negative one).
    fn check_roughness(&self, params: &ParamList, name: &str, value: f64) -> Result<(), Error> {
        self.check_non_negative(params, name, value, "roughness")
    }

    /// An error naming parameter `name` and its line unless `value`, what it gave for `what`,
    /// is a number ≥ 0.
    pub(crate) fn check_non_negative(
        &self,
        params: &ParamList,
        name: &str,
        value: f64,
        what: &str,
    ) -> Result<(), Error> {
        match params.get(name) {
            Some(p) if !(value >= 0.0 && value.is_finite()) => Err(self.error(format!(
                "\"{} {}\" (line {}): {what} must be a number >= 0, got {value}",
                p.ty, p.name, p.line
            ))),
            _ => Ok(()),
        }
    }

    /// `{prefix}roughness`, `{prefix}uroughness` and `{prefix}vroughness` as α along u and v,
    /// remapped as `remaproughness` says (pbrt-v4's default: remapped).
    fn roughness_of(&mut self, params: &ParamList, prefix: &str) -> Result<(f32, f32), Error> {
        let r = self.float_value(params, &format!("{prefix}roughness"), 0.0)?;
        let u = self.float_value(params, &format!("{prefix}uroughness"), r)?;
        let v = self.float_value(params, &format!("{prefix}vroughness"), r)?;
        for (value, name) in [(r, "roughness"), (u, "uroughness"), (v, "vroughness")] {
            self.check_roughness(params, &format!("{prefix}{name}"), value)?;
        }
        let remap = self.bool(params, "remaproughness", true)?;
        // pbrt-v4's TrowbridgeReitzDistribution::RoughnessToAlpha is √roughness; below
        // α = 10⁻³ a surface is smooth.
        let alpha = |x: f64| {
            let a = if remap { x.sqrt() } else { x } as f32;
            if a < 1e-3 {
                0.0
            } else {
                a
            }
        };
        Ok((alpha(u), alpha(v)))
    }

    /// The index of refraction `eta` (a number or a named glass), default 1.5.
    fn eta(&mut self, params: &ParamList) -> Result<f32, Error> {
        self.eta_of(params, "eta")
    }

    /// The index of refraction `name` (a number or a named glass), default 1.5.
    fn eta_of(&mut self, params: &ParamList, name: &str) -> Result<f32, Error> {
        match params.params.iter().rev().find(|p| p.name == name) {
            Some(p) if p.ty == "float" => self.float(params, name, 1.5).map(|v| v as f32),
            Some(_) => {
                let c = self
                    .spectrum(params, name, Use::Unbounded)?
                    .unwrap_or(Vec3::splat(1.5));
                Ok(c.x)
            }
            None => Ok(1.5),
        }
    }

    /// `MakeNamedMaterial`: its `type` parameter names the material.
    pub(crate) fn named_material(&mut self, name: &str, params: ParamList) -> Result<usize, Error> {
        let kind = self.string(&params, "type")?.ok_or_else(|| {
            self.error(format!("MakeNamedMaterial \"{name}\": no \"string type\""))
        })?;
        self.material(&kind, params)
    }

    /// A material of `kind` from `params`, added to the scene: its index.
    pub(crate) fn material(&mut self, kind: &str, params: ParamList) -> Result<usize, Error> {
        let params = match self.gs.defaults.get("material") {
            Some(d) => params.with_defaults(d),
            None => params,
        };
        let m = self.material_desc(kind, &params)?;
        let m = match self.string(&params, "normalmap")? {
            Some(file) if !file.is_empty() => {
                let path = self.resolve(&file);
                match crate::texture::load(&path, true) {
                    Ok(image) => MaterialDesc::NormalMap {
                        normals: TextureDesc::image(image),
                        inner: Box::new(m),
                    },
                    Err(e) => {
                        self.warn(format!("normal map: {e}; the surface normal is used"));
                        m
                    }
                }
            }
            _ => m,
        };
        if params.has("displacement") {
            params.get("displacement");
            self.warn("Material: displacement is not supported; ignored");
        }
        self.warn_unused(&format!("Material \"{kind}\""), &params);
        self.desc.materials.push(m);
        Ok(self.desc.materials.len() - 1)
    }

    fn material_desc(&mut self, kind: &str, params: &ParamList) -> Result<MaterialDesc, Error> {
        // `type` was read by MakeNamedMaterial.
        params.get("type");
        Ok(match kind {
            "diffuse" => self.diffuse(params, "reflectance", 0.5)?,
            "conductor" => self.conductor(params)?,
            "dielectric" => self.dielectric(params)?,
            "thindielectric" => MaterialDesc::ThinGlass {
                reflectance: Rgb::ONE,
                transmittance: Rgb::ONE,
                ior: self.eta(params)?,
            },
            "coateddiffuse" => self.coated_diffuse(params)?,
            "coatedconductor" => self.coated_conductor(params)?,
            "diffusetransmission" => self.diffuse_transmission(params)?,
            "mix" => self.mix(params)?,
            "interface" | "" | "none" => MaterialDesc::Mask {
                opacity: TextureDesc::value(0.0),
                inner: Box::new(MaterialDesc::Diffuse {
                    reflectance: Rgb::ZERO,
                    two_sided: true,
                }),
            },
            other => {
                self.warn(format!(
                    "Material \"{other}\": not supported; rendered as diffuse 0.5"
                ));
                for p in &params.params {
                    p.used.set(true);
                }
                MaterialDesc::Diffuse {
                    reflectance: Rgb::splat(0.5),
                    two_sided: true,
                }
            }
        })
    }

    /// pbrt-v4's `conductor`: by its `reflectance`, or `eta` and `k` (copper by default), smooth or rough (anisotropic where `uroughness` and `vroughness` differ).
    fn conductor(&mut self, params: &ParamList) -> Result<MaterialDesc, Error> {
        let roughness = self.surface_roughness(params)?;
        let (eta, k) = self.conductor_optics(params, "eta", "k")?;
        let distribution = NormalDistribution::Ggx;
        // pbrt-v4's materials are two-sided.
        Ok(MaterialDesc::on_both_sides(match roughness {
            Roughness::Isotropic(alpha) => MaterialDesc::Conductor {
                alpha,
                eta,
                k,
                distribution,
            },
            Roughness::Varying([alpha_u, alpha_v]) => MaterialDesc::RoughConductor {
                alpha_u,
                alpha_v,
                eta,
                k,
                specular: TextureDesc::value(1.0),
                distribution,
            },
        }))
    }

    /// pbrt-v4's `dielectric`: smooth or rough glass, its roughness textured or anisotropic
    /// where the file says so.
    fn dielectric(&mut self, params: &ParamList) -> Result<MaterialDesc, Error> {
        let distribution = NormalDistribution::Ggx;
        let ior = self.eta(params)?;
        Ok(match self.surface_roughness(params)? {
            Roughness::Isotropic(roughness) => MaterialDesc::Glass {
                reflectance: Rgb::ONE,
                transmittance: Rgb::ONE,
                roughness,
                ior,
                distribution,
                fresnel: FresnelModel::Exact,
            },
            Roughness::Varying([alpha_u, alpha_v]) => MaterialDesc::RoughGlass {
                alpha_u,
                alpha_v,
                ior,
                distribution,
                reflectance: Rgb::ONE,
                transmittance: Rgb::ONE,
            },
        })
    }

    /// A conductor's complex index: from its `reflectance` r (pbrt-v4: η = 1 and
    /// k = 2 √r / √(1 - r)), or the `eta_name` and `k_name` spectra, copper by default.
    fn conductor_optics(
        &mut self,
        params: &ParamList,
        eta_name: &str,
        k_name: &str,
    ) -> Result<(Rgb, Rgb), Error> {
        Ok(match self.spectrum(params, "reflectance", Use::Albedo)? {
            Some(r) => {
                let r = r.clamp(Vec3::ZERO, Vec3::splat(0.9999));
                (
                    Vec3::ONE,
                    2.0 * r.map(f32::sqrt) / (Vec3::ONE - r).map(f32::sqrt),
                )
            }
            None => {
                let eta = self.spectrum(params, eta_name, Use::Unbounded)?;
                let k = self.spectrum(params, k_name, Use::Unbounded)?;
                let (cu_eta, cu_k) = named_conductor("Cu").unwrap_or(([1.0; 3], [0.0; 3]));
                (
                    eta.unwrap_or(Vec3::from(cu_eta)),
                    k.unwrap_or(Vec3::from(cu_k)),
                )
            }
        })
    }

    /// pbrt-v4's `diffusetransmission`: reflectance and transmittance (0.25 each by default),
    /// both times `scale`.
    fn diffuse_transmission(&mut self, params: &ParamList) -> Result<MaterialDesc, Error> {
        let scale = self.float(params, "scale", 1.0)? as f32;
        let reflectance = self.color_texture(params, "reflectance", Rgb::splat(0.25))?;
        let transmittance = self.color_texture(params, "transmittance", Rgb::splat(0.25))?;
        Ok(MaterialDesc::DiffuseTransmission {
            reflectance: reflectance.scaled(scale),
            transmittance: transmittance.scaled(scale),
        })
    }

    /// pbrt-v4's `coateddiffuse`: a dielectric coat (`roughness`, `eta`) over a Lambertian
    /// base (`reflectance`), with the layer's `thickness`, `albedo`, `g`, `maxdepth` and
    /// `nsamples`.
    fn coated_diffuse(&mut self, params: &ParamList) -> Result<MaterialDesc, Error> {
        let coat_alpha = self.layer_roughness(params, "")?;
        let coat_eta = self.eta_of(params, "eta")?;
        let reflectance = self.color_texture(params, "reflectance", Rgb::splat(0.5))?;
        self.coated(
            params,
            CoatedBase::Diffuse(reflectance),
            coat_eta,
            coat_alpha,
        )
    }

    /// pbrt-v4's `coatedconductor`: a dielectric coat (`interface.roughness`,
    /// `interface.eta`) over a conductor (`conductor.eta` and `conductor.k`, copper by
    /// default, or `reflectance`; `conductor.roughness`), with the layer's parameters.
    fn coated_conductor(&mut self, params: &ParamList) -> Result<MaterialDesc, Error> {
        let coat_alpha = self.layer_roughness(params, "interface.")?;
        let coat_eta = self.eta_of(params, "interface.eta")?;
        let alpha = self.layer_roughness(params, "conductor.")?;
        let (eta, k) = self.conductor_optics(params, "conductor.eta", "conductor.k")?;
        let base = CoatedBase::Conductor { eta, k, alpha };
        self.coated(params, base, coat_eta, coat_alpha)
    }

    /// A coated material's roughness (`{prefix}roughness` and its u and v), of the coat or of
    /// a conductor base, as α along u and v: numbers where they are numbers, else textures
    /// read at each point.
    fn layer_roughness(
        &mut self,
        params: &ParamList,
        prefix: &str,
    ) -> Result<[TextureDesc; 2], Error> {
        if let Some(alphas) = self.textured_roughness(params, prefix)? {
            return Ok(alphas);
        }
        let (au, av) = self.roughness_of(params, prefix)?;
        Ok([TextureDesc::value(au), TextureDesc::value(av)])
    }

    /// The layer's parameters shared by both coated materials, with pbrt-v4's defaults.
    fn coated(
        &mut self,
        params: &ParamList,
        base: CoatedBase,
        coat_eta: f32,
        coat_alpha: [TextureDesc; 2],
    ) -> Result<MaterialDesc, Error> {
        // Thickness, albedo and g may be textures (read at each point and kept in range there,
        // by `LayerMedium::new`, as numbers are); numbers are checked here.
        let thickness = self.texture_or_value(params, "thickness", "float", 0.01)?;
        let albedo = self.color_texture(params, "albedo", Rgb::ZERO)?;
        let g = self.texture_or_value(params, "g", "float", 0.0)?;
        let max_depth = self.float(params, "maxdepth", 10.0)?;
        let samples = self.float(params, "nsamples", 1.0)?;
        if let Some(t) = thickness.as_constant().map(|t| t.x) {
            if !(t > 0.0 && t.is_finite()) {
                return Err(self.error(format!("thickness {t}: must be a positive number")));
            }
        }
        if !(0.0..=1_000.0).contains(&max_depth) || !(1.0..=1_000.0).contains(&samples) {
            return Err(self.error(format!(
                "maxdepth {max_depth} and nsamples {samples}: expected 0 to 1000 and 1 to 1000"
            )));
        }
        if let Some(g) = g.as_constant().map(|g| g.x) {
            if !(-1.0 < g && g < 1.0) {
                return Err(self.error(format!("g {g}: must lie strictly between -1 and 1")));
            }
        }
        Ok(MaterialDesc::Coated(Box::new(CoatedDesc {
            base,
            coat_eta,
            coat_alpha,
            thickness,
            albedo,
            g,
            max_depth: max_depth as u32,
            samples: samples as u32,
        })))
    }

    /// pbrt-v4's `mix` of two named materials.
    fn mix(&mut self, params: &ParamList) -> Result<MaterialDesc, Error> {
        let names = params
            .get("materials")
            .and_then(|p| p.strings().map(<[String]>::to_vec))
            .unwrap_or_default();
        if names.len() != 2 {
            return Err(self.error("mix: \"string materials\" must name two materials"));
        }
        let pick = |n: &str| -> Result<MaterialDesc, Error> {
            self.named_materials
                .get(n)
                .map(|&i| self.desc.materials[i].clone())
                .ok_or_else(|| self.error(format!("mix: no material named \"{n}\"")))
        };
        let (first, second) = (pick(&names[0])?, pick(&names[1])?);
        // pbrt-v4 picks the second with probability `amount` (a number or a texture, read at
        // each point and kept in [0, 1] there): the same expectation as a blend.
        let weight = match self.texture_or_value(params, "amount", "float", 0.5)? {
            TextureDesc::Constant(a) => TextureDesc::Constant(a.clamp(Rgb::ZERO, Rgb::ONE)),
            t => t,
        };
        Ok(MaterialDesc::Blend {
            weight,
            first: Box::new(first),
            second: Box::new(second),
        })
    }

    /// A two-sided Lambertian material from a (possibly textured) reflectance.
    fn diffuse(
        &mut self,
        params: &ParamList,
        name: &str,
        default: f32,
    ) -> Result<MaterialDesc, Error> {
        let t = self.color_texture(params, name, Rgb::splat(default))?;
        Ok(match t {
            TextureDesc::Constant(c) => MaterialDesc::Diffuse {
                reflectance: c.clamp(Rgb::ZERO, Rgb::ONE),
                two_sided: true,
            },
            t => MaterialDesc::TexturedDiffuse {
                texture: t,
                scale: Rgb::ONE,
                two_sided: true,
            },
        })
    }
}
