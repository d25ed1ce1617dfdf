//! Mitsuba 3 XML scenes, read as Mitsuba's RGB variants render them.
//!
//! [`parse`] reads the XML (with `<include>`, `<path>`, `<default>` and `-D` parameters) into
//! a tree of plugin objects; the interpreter here turns the plugins pathlab implements into a
//! [`SceneDesc`]: shapes ([`shapes`]), BSDFs ([`bsdfs`]), textures ([`textures`]), emitters
//! ([`emitters`]), the sensor, film, sampler and integrator ([`sensors`]). Every property is
//! tracked: one that no plugin read, and every plugin pathlab does not implement, is reported
//! as a warning naming the file, line and column. Spectra become RGB as Mitsuba's RGB variants
//! make them ([`crate::spectrum`]); named indices of refraction and conductors are Mitsuba's
//! tables ([`ior`]).
//!
//! Mitsuba counts depth from the camera ray: its `max_depth` is pathlab's + 1.

mod bsdfs;
mod emitters;
pub mod export;
pub mod ior;
mod parse;
mod sensors;
pub mod serialized;
mod shapes;
mod textures;
pub mod volume;

use crate::spectrum::{constant_to_rgb, is_emission, sampled_to_rgb, SpectrumKind};
use crate::Error;
use glam::{DMat4, DVec3, Mat4, Vec3};
use parse::{Prop, Spectrum, Tree, Value};
use pathlab_render::desc::*;
use std::cell::Cell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

pub(crate) use parse::Loc;

/// Loads a Mitsuba 3 XML scene with the file's own `<default>` parameters.
pub fn load(path: &Path) -> Result<SceneDesc, Error> {
    load_with(path, &[])
}

/// Loads a Mitsuba 3 XML scene; `params` (`-D name=value` on the command line, Mitsuba's
/// `load_file(path, name=value)`) take the place of the file's `<default>`s.
pub fn load_with(path: &Path, params: &[(String, String)]) -> Result<SceneDesc, Error> {
    let tree = parse::parse(path, params)?;
    let mut ctx = Ctx {
        visited: (0..tree.nodes.len()).map(|_| Cell::new(false)).collect(),
        tree: &tree,
        desc: SceneDesc {
            resolution: [768, 576],
            filter: PixelFilter::gaussian(0.5),
            ..Default::default()
        },
        materials: HashMap::new(),
        warnings: Vec::new(),
        sensor_seen: false,
    };
    ctx.scene(tree.root)?;
    ctx.report_unused();
    for p in &tree.unused_params {
        ctx.warnings.push(format!(
            "{}: parameter '{p}' given on the command line is not used by the scene",
            path.display()
        ));
    }
    if ctx.desc.materials.is_empty() {
        ctx.desc.materials.push(default_bsdf());
    }
    let mut desc = ctx.desc;
    desc.warnings.extend(ctx.warnings);
    Ok(desc)
}

/// Mitsuba's BSDF for a shape that names none: diffuse, reflectance 0.5.
fn default_bsdf() -> MaterialDesc {
    MaterialDesc::Diffuse {
        reflectance: Vec3::splat(0.5),
        two_sided: false,
    }
}

/// The interpreter's state.
pub(crate) struct Ctx<'t> {
    tree: &'t Tree,
    /// Which objects were interpreted (their unused properties are reported).
    visited: Vec<Cell<bool>>,
    desc: SceneDesc,
    /// Material index of each BSDF object already converted.
    materials: HashMap<usize, usize>,
    warnings: Vec<String>,
    sensor_seen: bool,
}

/// A node index with its class and plugin name, for dispatch.
#[derive(Clone, Copy)]
pub(crate) struct Obj<'t> {
    pub index: usize,
    pub class: &'t str,
    pub plugin: &'t str,
    pub loc: Loc,
}

impl<'t> Ctx<'t> {
    /// The object at `index`, marked as interpreted.
    pub(crate) fn obj(&self, index: usize) -> Obj<'t> {
        self.visited[index].set(true);
        let n = &self.tree.nodes[index];
        Obj {
            index,
            class: &n.class,
            plugin: &n.plugin,
            loc: n.loc,
        }
    }

    pub(crate) fn error(&self, loc: Loc, message: impl Into<String>) -> Error {
        self.tree.error(loc, message)
    }

    /// A warning located at `loc`.
    pub(crate) fn warn(&mut self, loc: Loc, message: impl AsRef<str>) {
        let w = format!("{}: {}", self.tree.at(loc), message.as_ref());
        if !self.warnings.contains(&w) {
            self.warnings.push(w);
        }
    }

    /// "<class type="plugin">" of an object, for messages.
    pub(crate) fn what(&self, o: Obj) -> String {
        format!("<{} type=\"{}\">", o.class, o.plugin)
    }

    /// The property `name` of `o`, marked as used.
    fn prop(&self, o: Obj, name: &str) -> Option<&'t parse::Prop> {
        let p = self.tree.nodes[o.index]
            .props
            .iter()
            .find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// Whether `o` has property `name` (without using it).
    pub(crate) fn has(&self, o: Obj, name: &str) -> bool {
        self.tree.nodes[o.index]
            .props
            .iter()
            .any(|p| p.name == name)
    }

    /// Marks every property of `o` (and of the objects nested in it) as read: for a plugin
    /// that is reported as unsupported as a whole.
    pub(crate) fn accept_all(&self, o: Obj) {
        let mut stack = vec![o.index];
        while let Some(i) = stack.pop() {
            self.visited[i].set(true);
            for p in &self.tree.nodes[i].props {
                p.used.set(true);
                if let parse::Value::Object(child) = p.value {
                    stack.push(child);
                }
            }
        }
    }

    /// Marks properties as read without interpreting them: settings that change nothing in
    /// pathlab's image (an output pixel format, say).
    pub(crate) fn accept(&self, o: Obj, names: &[&str]) {
        for n in names {
            self.prop(o, n);
        }
    }

    fn wrong_type(&self, o: Obj, p: &parse::Prop, expected: &str) -> Error {
        self.error(
            p.loc,
            format!(
                "{}: '{}' must be {expected}, found a {}",
                self.what(o),
                p.name,
                p.value.kind()
            ),
        )
    }

    /// A number (`<float>` or `<integer>`).
    pub(crate) fn float(&self, o: Obj, name: &str, default: f64) -> Result<f64, Error> {
        Ok(self.opt_float(o, name)?.unwrap_or(default))
    }

    pub(crate) fn opt_float(&self, o: Obj, name: &str) -> Result<Option<f64>, Error> {
        match self.prop(o, name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Float(v) => Ok(Some(v)),
                Value::Int(v) => Ok(Some(v as f64)),
                _ => Err(self.wrong_type(o, p, "a number")),
            },
        }
    }

    /// A positive number.
    pub(crate) fn positive(&self, o: Obj, name: &str, default: f64) -> Result<f64, Error> {
        self.number_where(o, name, default, |v| v > 0.0, "positive")
    }

    /// A number >= 0.
    pub(crate) fn non_negative(&self, o: Obj, name: &str, default: f64) -> Result<f64, Error> {
        self.number_where(
            o,
            name,
            default,
            |v| v >= 0.0 && v.is_finite(),
            "a number >= 0",
        )
    }

    /// A number for which `ok` holds, or an error at the property saying it must be `what`.
    fn number_where(
        &self,
        o: Obj,
        name: &str,
        default: f64,
        ok: fn(f64) -> bool,
        what: &str,
    ) -> Result<f64, Error> {
        let v = self.float(o, name, default)?;
        if ok(v) {
            return Ok(v);
        }
        let loc = self.prop(o, name).map_or(o.loc, |p| p.loc);
        Err(self.error(
            loc,
            format!("{}: '{name}' must be {what}, got {v}", self.what(o)),
        ))
    }

    /// An integer.
    pub(crate) fn int(&self, o: Obj, name: &str, default: i64) -> Result<i64, Error> {
        match self.prop(o, name) {
            None => Ok(default),
            Some(p) => match p.value {
                Value::Int(v) => Ok(v),
                Value::Float(v) if v.fract() == 0.0 => Ok(v as i64),
                _ => Err(self.wrong_type(o, p, "an integer")),
            },
        }
    }

    pub(crate) fn boolean(&self, o: Obj, name: &str, default: bool) -> Result<bool, Error> {
        match self.prop(o, name) {
            None => Ok(default),
            Some(p) => match p.value {
                Value::Bool(v) => Ok(v),
                _ => Err(self.wrong_type(o, p, "a boolean")),
            },
        }
    }

    pub(crate) fn string(&self, o: Obj, name: &str) -> Result<Option<String>, Error> {
        match self.prop(o, name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Str(s) => Ok(Some(s.clone())),
                _ => Err(self.wrong_type(o, p, "a string")),
            },
        }
    }

    /// A string that must be one of `choices` (case-insensitive); the first is the default.
    pub(crate) fn choice(
        &self,
        o: Obj,
        name: &str,
        choices: &[&'static str],
    ) -> Result<&'static str, Error> {
        let Some(s) = self.string(o, name)? else {
            return Ok(choices[0]);
        };
        choices
            .iter()
            .find(|c| c.eq_ignore_ascii_case(&s))
            .copied()
            .ok_or_else(|| {
                let loc = self.prop(o, name).map_or(o.loc, |p| p.loc);
                self.error(
                    loc,
                    format!(
                        "{}: {name} '{s}' is not one of {}",
                        self.what(o),
                        choices.join(", ")
                    ),
                )
            })
    }

    /// A `<point>` or `<vector>`.
    pub(crate) fn vector(&self, o: Obj, name: &str) -> Result<Option<DVec3>, Error> {
        match self.prop(o, name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Vector(v) => Ok(Some(v)),
                _ => Err(self.wrong_type(o, p, "a point or vector")),
            },
        }
    }

    /// A `<transform>` (identity when absent).
    pub(crate) fn transform(&self, o: Obj, name: &str) -> Result<DMat4, Error> {
        match self.prop(o, name) {
            None => Ok(DMat4::IDENTITY),
            Some(p) => match p.value {
                Value::Transform(m) => Ok(m),
                _ => Err(self.wrong_type(o, p, "a transform")),
            },
        }
    }

    /// The object a property names: a nested object or a `<ref>`.
    pub(crate) fn object_value(&self, p: &parse::Prop) -> Result<Option<usize>, Error> {
        match &p.value {
            Value::Object(i) => Ok(Some(*i)),
            Value::Ref(id) => self
                .tree
                .ids
                .get(id)
                .copied()
                .map(Some)
                .ok_or_else(|| self.error(p.loc, format!("<ref>: no object has id '{id}'"))),
            _ => Ok(None),
        }
    }

    /// Every object nested in (or referenced by) `o` whose class is `class`, in order, with
    /// the property's name; marks those properties used.
    pub(crate) fn children(&self, o: Obj, class: &str) -> Result<Vec<(String, Obj<'t>)>, Error> {
        let mut out = Vec::new();
        for p in &self.tree.nodes[o.index].props {
            if let Some(i) = self.object_value(p)? {
                if self.tree.nodes[i].class == class {
                    p.used.set(true);
                    out.push((p.name.clone(), self.obj(i)));
                }
            }
        }
        Ok(out)
    }

    /// A spectrum value as RGB, for a property that means `kind`.
    fn spectrum_rgb(&self, s: &Spectrum, kind: SpectrumKind) -> Vec3 {
        let rgb = match s {
            Spectrum::Constant(v) => constant_to_rgb(*v, kind),
            Spectrum::Sampled(samples) => sampled_to_rgb(samples, kind),
        };
        rgb.as_vec3()
    }

    /// A constant colour: `<rgb>`, `<float>`, `<spectrum>`, or a constant texture object
    /// (`srgb`, `uniform`, `blackbody`). `None` when absent.
    pub(crate) fn opt_color(
        &mut self,
        o: Obj,
        name: &str,
        kind: SpectrumKind,
    ) -> Result<Option<Vec3>, Error> {
        let Some(p) = self.prop(o, name) else {
            return Ok(None);
        };
        let c = self.color_of(o, name, p, kind)?;
        let negative_sample = match &p.value {
            Value::Spectrum(Spectrum::Sampled(samples)) => {
                samples.iter().any(|s| s.1 < 0.0 || s.1.is_nan())
            }
            _ => false,
        };
        let negative = negative_sample || !is_emission(c);
        if kind == SpectrumKind::Emission && negative {
            return Err(self.error(
                p.loc,
                format!(
                    "{}: '{name}' is an emission and must be >= 0 {}",
                    self.what(o),
                    if negative_sample {
                        "at every wavelength".to_string()
                    } else {
                        format!("in every channel, got {c}")
                    }
                ),
            ));
        }
        Ok(Some(c))
    }

    /// The constant colour property `p` (named `name`) of `o` holds.
    fn color_of(
        &mut self,
        o: Obj,
        name: &str,
        p: &Prop,
        kind: SpectrumKind,
    ) -> Result<Vec3, Error> {
        match &p.value {
            Value::Rgb(c) => Ok(c.as_vec3()),
            Value::Float(v) => Ok(Vec3::splat(*v as f32)),
            Value::Int(v) => Ok(Vec3::splat(*v as f32)),
            Value::Spectrum(s) => Ok(self.spectrum_rgb(s, kind)),
            Value::Object(_) | Value::Ref(_) => {
                let t = self.object_value(p)?.map(|i| self.obj(i));
                let Some(t) = t else { unreachable!() };
                match textures::constant(self, t, kind)? {
                    Some(c) => Ok(c),
                    None => Err(self.error(
                        p.loc,
                        format!(
                            "{}: '{name}' must be a constant colour here, not a {} texture",
                            self.what(o),
                            t.plugin
                        ),
                    )),
                }
            }
            _ => Err(self.wrong_type(o, p, "a colour")),
        }
    }

    /// A constant colour with a default.
    pub(crate) fn color(
        &mut self,
        o: Obj,
        name: &str,
        default: Vec3,
        kind: SpectrumKind,
    ) -> Result<Vec3, Error> {
        Ok(self.opt_color(o, name, kind)?.unwrap_or(default))
    }

    /// A texture or constant: whatever Mitsuba accepts for a textured parameter.
    pub(crate) fn texture(
        &mut self,
        o: Obj,
        name: &str,
        default: Vec3,
        kind: SpectrumKind,
    ) -> Result<TextureDesc, Error> {
        Ok(self
            .opt_texture(o, name, kind)?
            .unwrap_or(TextureDesc::Constant(default)))
    }

    pub(crate) fn opt_texture(
        &mut self,
        o: Obj,
        name: &str,
        kind: SpectrumKind,
    ) -> Result<Option<TextureDesc>, Error> {
        let Some(p) = self.prop(o, name) else {
            return Ok(None);
        };
        match self.object_value(p)? {
            Some(i) => {
                let t = self.obj(i);
                if t.class != "texture" && t.class != "spectrum" {
                    return Err(self.wrong_type(o, p, "a texture"));
                }
                textures::texture(self, t, kind).map(Some)
            }
            None => self
                .opt_color(o, name, kind)
                .map(|c| c.map(TextureDesc::Constant)),
        }
    }

    /// Resolves a file name property (`filename`) of `o` as Mitsuba's file resolver would,
    /// with an error naming the property's location when the file does not exist.
    pub(crate) fn file(&self, o: Obj, name: &str) -> Result<PathBuf, Error> {
        let p = self.prop(o, name).ok_or_else(|| {
            self.error(
                o.loc,
                format!("{}: expected a '{name}' string", self.what(o)),
            )
        })?;
        let Value::Str(s) = &p.value else {
            return Err(self.wrong_type(o, p, "a string"));
        };
        let path = self.tree.resolve(s, p.loc.file);
        if !path.is_file() {
            return Err(self.error(
                p.loc,
                format!(
                    "{}: file '{}' not found (looked in the <path> folders and beside the scene)",
                    self.what(o),
                    s
                ),
            ));
        }
        Ok(path)
    }

    /// An error from loading a file that property `name` of `o` refers to, located there.
    pub(crate) fn file_error(&self, o: Obj, name: &str, e: Error) -> Error {
        let loc = self.tree.nodes[o.index]
            .props
            .iter()
            .find(|p| p.name == name)
            .map_or(o.loc, |p| p.loc);
        self.error(loc, format!("{}: {e}", self.what(o)))
    }

    /// The scene: every top-level object, in order.
    fn scene(&mut self, root: usize) -> Result<(), Error> {
        let scene = self.obj(root);
        let props: Vec<usize> = (0..self.tree.nodes[root].props.len()).collect();
        let mut defined = Vec::new();
        for k in props {
            let p = &self.tree.nodes[root].props[k];
            let Some(i) = self.object_value(p)? else {
                // A property of the scene itself.
                continue;
            };
            p.used.set(true);
            let o = self.obj(i);
            match o.class {
                "shape" => shapes::shape(self, o, DMat4::IDENTITY, None)?,
                "emitter" => emitters::emitter(self, o)?,
                "sensor" => {
                    if self.sensor_seen {
                        self.warn(o.loc, "more than one <sensor>: pathlab renders the first");
                        continue;
                    }
                    self.sensor_seen = true;
                    sensors::sensor(self, o)?
                }
                "integrator" => sensors::integrator(self, o)?,
                // Defined here, used where referenced.
                "bsdf" | "texture" | "spectrum" => {
                    self.visited[i].set(false);
                    defined.push(i);
                }
                _ => {
                    let what = self.what(o);
                    self.warn(
                        o.loc,
                        format!("{what} is not supported by pathlab; skipped"),
                    );
                    self.accept_all(o);
                }
            }
        }
        // Definitions nothing referenced are not converted (an unknown plugin among them would
        // otherwise pass unseen): said, not dropped silently.
        for i in defined {
            if !self.visited[i].get() {
                let n = &self.tree.nodes[i];
                let id = n.id.as_ref().map(|id| format!(" id=\"{id}\""));
                let id = id.unwrap_or_default();
                let message = format!(
                    "<{} type=\"{}\"{id}> is not used by anything in the scene; not loaded",
                    n.class, n.plugin
                );
                self.warn(n.loc, message);
            }
        }
        let _ = scene;
        Ok(())
    }

    /// The material index of BSDF object `b` (converted once however often it is referenced).
    pub(crate) fn material(&mut self, b: Obj) -> Result<usize, Error> {
        if let Some(&m) = self.materials.get(&b.index) {
            return Ok(m);
        }
        let m = bsdfs::bsdf(self, b)?;
        self.desc.materials.push(m);
        let index = self.desc.materials.len() - 1;
        self.materials.insert(b.index, index);
        Ok(index)
    }

    /// Warnings for every property of an interpreted object that nothing read.
    fn report_unused(&mut self) {
        let mut out = Vec::new();
        for (i, n) in self.tree.nodes.iter().enumerate() {
            if !self.visited[i].get() {
                continue;
            }
            for p in &n.props {
                if !p.used.get() && !p.name.starts_with("_arg_") {
                    out.push((
                        p.loc,
                        format!(
                            "<{} type=\"{}\">: parameter '{}' is not supported by pathlab; ignored",
                            n.class, n.plugin, p.name
                        ),
                    ));
                } else if !p.used.get() {
                    out.push((
                        p.loc,
                        format!(
                            "<{} type=\"{}\">: a nested {} is not used by pathlab; ignored",
                            n.class,
                            n.plugin,
                            p.value.kind()
                        ),
                    ));
                }
            }
        }
        for (loc, m) in out {
            self.warn(loc, m);
        }
    }
}

/// A double-precision transform as `f32`.
pub(crate) fn mat4(m: DMat4) -> Mat4 {
    m.as_mat4()
}
