//! Mitsuba 3 XML into a tree of plugin objects with typed, located properties, as Mitsuba's
//! own parser builds it before it instantiates plugins: `<default>` and `$name` substitution
//! (command-line values first), `<include>`, `<path>` search folders, `<alias>`, `<ref>`,
//! property tags (`float`, `integer`, `boolean`, `string`, `point`, `vector`, `rgb`,
//! `spectrum`, `transform`) and object tags (`bsdf`, `shape`, `emitter`, ...). Nothing is
//! interpreted here: [`super::interp`] turns the tree into a scene and reports every property
//! it did not use.

use crate::xml::{parse_document, read_text, truncate};
use crate::Error;
use glam::{DMat4, DVec3, DVec4};
use roxmltree::Node as XmlNode;
use std::cell::Cell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

mod properties;

/// How deep `<include>` may nest (a loop of includes stops here).
const MAX_INCLUDE_DEPTH: usize = 16;

/// Where something was written: a file of [`Tree::files`], line and column from 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Loc {
    pub file: usize,
    pub line: u32,
    pub col: u32,
}

/// A spectrum as written: Mitsuba converts it to RGB by what it describes, which only the
/// plugin that reads it knows.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Spectrum {
    /// One value at every wavelength.
    Constant(f64),
    /// (wavelength nm, value) pairs in increasing order.
    Sampled(Vec<(f64, f64)>),
}

/// A property's value.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Value {
    Float(f64),
    Int(i64),
    Bool(bool),
    Str(String),
    /// `<point>` or `<vector>`.
    Vector(DVec3),
    Rgb(DVec3),
    Spectrum(Spectrum),
    Transform(DMat4),
    /// A nested object (index into [`Tree::nodes`]).
    Object(usize),
    /// `<ref id>`: an object defined elsewhere.
    Ref(String),
}

impl Value {
    /// The kind of value, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Float(_) => "float",
            Value::Int(_) => "integer",
            Value::Bool(_) => "boolean",
            Value::Str(_) => "string",
            Value::Vector(_) => "vector",
            Value::Rgb(_) => "rgb",
            Value::Spectrum(_) => "spectrum",
            Value::Transform(_) => "transform",
            Value::Object(_) | Value::Ref(_) => "object",
        }
    }
}

/// A named property of an object.
#[derive(Debug)]
pub(crate) struct Prop {
    pub name: String,
    pub value: Value,
    pub loc: Loc,
    /// Set when the interpreter reads it; what stays unset is reported.
    pub used: Cell<bool>,
}

/// A plugin object: `<bsdf type="diffuse" id="...">` and its properties.
#[derive(Debug)]
pub(crate) struct Node {
    /// The tag: `bsdf`, `shape`, `emitter`, `sensor`, `film`, `sampler`, `rfilter`,
    /// `texture`, `integrator`, `medium`, `phase`, `volume`, `spectrum`, `scene`.
    pub class: String,
    /// The `type` attribute (the plugin's name).
    pub plugin: String,
    pub id: Option<String>,
    pub loc: Loc,
    pub props: Vec<Prop>,
}

/// A parsed scene file with everything it included.
#[derive(Debug)]
pub(crate) struct Tree {
    pub nodes: Vec<Node>,
    /// Every file read, by [`Loc::file`].
    pub files: Vec<PathBuf>,
    /// Objects by id (aliases included).
    pub ids: HashMap<String, usize>,
    /// `<path>` folders, most recent first, then the main file's folder: where relative file
    /// names are looked for, as Mitsuba's file resolver does.
    pub search: Vec<PathBuf>,
    pub root: usize,
    /// Command-line parameters no `$name` used.
    pub unused_params: Vec<String>,
}

impl Tree {
    /// The located error at `loc`.
    pub fn error(&self, loc: Loc, message: impl Into<String>) -> Error {
        Error::Parse {
            path: self.files[loc.file].display().to_string(),
            line: loc.line as usize,
            column: loc.col as usize,
            message: message.into(),
        }
    }

    /// "file:line:col" of `loc`, for warnings.
    pub fn at(&self, loc: Loc) -> String {
        format!(
            "{}:{}:{}",
            self.files[loc.file].display(),
            loc.line,
            loc.col
        )
    }

    /// Resolves a file name as Mitsuba does: absolute names as they are; relative ones in the
    /// `<path>` folders, then the folder of the file that named it, then the main file's
    /// folder. The first candidate that exists wins; when none does, the name relative to the
    /// declaring file's folder (for the error message).
    pub fn resolve(&self, name: &str, declared_in: usize) -> PathBuf {
        let p = Path::new(name);
        if p.is_absolute() {
            return p.to_path_buf();
        }
        let own = self.files[declared_in]
            .parent()
            .unwrap_or(Path::new("."))
            .to_path_buf();
        let n = self.search.len();
        let mut dirs: Vec<&Path> = self.search[..n.saturating_sub(1)]
            .iter()
            .map(PathBuf::as_path)
            .collect();
        dirs.push(&own);
        dirs.extend(self.search.last().map(PathBuf::as_path));
        dirs.iter()
            .map(|d| d.join(p))
            .find(|c| c.exists())
            .unwrap_or_else(|| own.join(p))
    }
}

/// Parses `path` with command-line parameters `params` (`-D name=value`), which take the place
/// of the file's `<default>`s.
pub(crate) fn parse(path: &Path, params: &[(String, String)]) -> Result<Tree, Error> {
    let main_dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let mut p = Parser {
        tree: Tree {
            nodes: Vec::new(),
            files: Vec::new(),
            ids: HashMap::new(),
            search: vec![main_dir],
            root: 0,
            unused_params: Vec::new(),
        },
        params: params
            .iter()
            .map(|(k, v)| Param {
                key: format!("${k}"),
                value: v.clone(),
                used: false,
                from_command_line: true,
            })
            .collect(),
        anonymous: 0,
    };
    p.sort_params();
    let root = p.file(path, None, 0)?;
    let Some(root) = root else {
        return Err(Error::Parse {
            path: path.display().to_string(),
            line: 1,
            column: 1,
            message: "expected a <scene> document".into(),
        });
    };
    p.tree.root = root;
    p.tree.unused_params = p
        .params
        .iter()
        .filter(|q| q.from_command_line && !q.used)
        .map(|q| q.key[1..].to_string())
        .collect();
    Ok(p.tree)
}

struct Param {
    /// `$name`.
    key: String,
    value: String,
    used: bool,
    from_command_line: bool,
}

struct Parser {
    tree: Tree,
    /// Longest key first, so that `$spp` does not replace the start of `$spp_max`.
    params: Vec<Param>,
    anonymous: usize,
}

/// The XML document being read, for locations.
struct Source<'a, 'input> {
    doc: &'a roxmltree::Document<'input>,
    file: usize,
    /// Mitsuba 0.x files (version < 2) use camelCase names: upgraded on the fly.
    legacy: bool,
}

impl Source<'_, '_> {
    fn loc(&self, node: XmlNode) -> Loc {
        let pos = self.doc.text_pos_at(node.range().start);
        Loc {
            file: self.file,
            line: pos.row,
            col: pos.col,
        }
    }
}

/// camelCase to snake_case (Mitsuba 0.x parameter names).
fn snake_case(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    let mut prev_lower = false;
    for c in name.chars() {
        if c.is_ascii_uppercase() {
            if prev_lower {
                out.push('_');
            }
            out.push(c.to_ascii_lowercase());
            prev_lower = false;
        } else {
            prev_lower = c.is_ascii_lowercase() || c.is_ascii_digit();
            out.push(c);
        }
    }
    out
}

const OBJECT_TAGS: &[&str] = &[
    "scene",
    "bsdf",
    "shape",
    "emitter",
    "sensor",
    "film",
    "sampler",
    "rfilter",
    "texture",
    "integrator",
    "medium",
    "phase",
    "volume",
];

impl Parser {
    fn sort_params(&mut self) {
        self.params.sort_by_key(|p| std::cmp::Reverse(p.key.len()));
    }

    /// Reads a file; returns its root object, or `None` when it is a `<scene>` being included
    /// (whose children went to `parent`).
    fn file(
        &mut self,
        path: &Path,
        parent: Option<usize>,
        depth: usize,
    ) -> Result<Option<usize>, Error> {
        let text = read_text(path)?;
        let doc = parse_document(&text, path)?;
        let file = self.tree.files.len();
        self.tree.files.push(path.to_path_buf());
        let root = doc.root_element();
        let legacy = root
            .attribute("version")
            .and_then(|v| v.split('.').next())
            .and_then(|major| major.trim().parse::<u32>().ok())
            .is_some_and(|major| major < 2);
        let src = Source {
            doc: &doc,
            file,
            legacy,
        };
        let tag = root.tag_name().name();
        match parent {
            None => {
                if tag != "scene" {
                    return Err(self.tree.error(
                        src.loc(root),
                        format!("expected a <scene> document, found <{tag}>"),
                    ));
                }
                let index = self.object(&src, root, depth)?;
                Ok(Some(index))
            }
            Some(parent) if tag == "scene" => {
                for child in root.children().filter(|c| c.is_element()) {
                    self.child(&src, child, parent, depth)?;
                }
                Ok(None)
            }
            Some(parent) => {
                self.child(&src, root, parent, depth)?;
                Ok(None)
            }
        }
    }

    /// An attribute with `$name` parameters substituted.
    fn attr(&mut self, src: &Source, node: XmlNode, name: &str) -> Result<Option<String>, Error> {
        let Some(raw) = node.attribute(name) else {
            return Ok(None);
        };
        if !raw.contains('$') {
            return Ok(Some(raw.to_string()));
        }
        let mut value = raw.to_string();
        for p in &mut self.params {
            if value.contains(&p.key) {
                value = value.replace(&p.key, &p.value);
                p.used = true;
            }
        }
        if let Some(i) = value.find('$') {
            let rest: String = value[i + 1..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            return Err(self.tree.error(
                src.loc(node),
                format!(
                    "<{}>: parameter '${rest}' has no <default> (and none was given with -D {rest}=VALUE)",
                    node.tag_name().name()
                ),
            ));
        }
        Ok(Some(value))
    }

    fn required(&mut self, src: &Source, node: XmlNode, name: &str) -> Result<String, Error> {
        self.attr(src, node, name)?.ok_or_else(|| {
            self.tree.error(
                src.loc(node),
                format!(
                    "<{}>: expected a '{name}' attribute",
                    node.tag_name().name()
                ),
            )
        })
    }

    /// A property or object's `name` attribute (upgraded from camelCase in old files).
    fn name(&mut self, src: &Source, node: XmlNode) -> Result<Option<String>, Error> {
        Ok(self
            .attr(src, node, "name")?
            .map(|n| if src.legacy { snake_case(&n) } else { n }))
    }

    /// An object element and everything in it.
    fn object(&mut self, src: &Source, node: XmlNode, depth: usize) -> Result<usize, Error> {
        let loc = src.loc(node);
        let class = node.tag_name().name().to_string();
        let plugin = if class == "scene" {
            "scene".to_string()
        } else {
            self.required(src, node, "type")?
        };
        let id = self.attr(src, node, "id")?;
        let index = self.tree.nodes.len();
        self.tree.nodes.push(Node {
            class,
            plugin,
            id: id.clone(),
            loc,
            props: Vec::new(),
        });
        if let Some(id) = id {
            if let Some(&previous) = self.tree.ids.get(&id) {
                let at = self.tree.at(self.tree.nodes[previous].loc);
                return Err(self
                    .tree
                    .error(loc, format!("duplicate id '{id}' (first defined at {at})")));
            }
            self.tree.ids.insert(id, index);
        }
        for child in node.children().filter(|c| c.is_element()) {
            self.child(src, child, index, depth)?;
        }
        Ok(index)
    }

    fn push(&mut self, parent: usize, name: String, value: Value, loc: Loc) {
        let props = &mut self.tree.nodes[parent].props;
        // A later definition of the same name replaces the earlier one (as in Mitsuba).
        props.retain(|p| p.name != name);
        props.push(Prop {
            name,
            value,
            loc,
            used: Cell::new(false),
        });
    }

    fn anonymous_name(&mut self) -> String {
        self.anonymous += 1;
        format!("_arg_{}", self.anonymous)
    }

    /// A child element of object `parent`.
    fn child(
        &mut self,
        src: &Source,
        node: XmlNode,
        parent: usize,
        depth: usize,
    ) -> Result<(), Error> {
        let loc = src.loc(node);
        let tag = node.tag_name().name();
        let spectrum_object = tag == "spectrum" && node.has_attribute("type");
        if OBJECT_TAGS.contains(&tag) || spectrum_object {
            if tag == "scene" {
                return Err(self.tree.error(loc, "<scene> inside another object"));
            }
            let name = match self.name(src, node)? {
                Some(n) => n,
                None => self.anonymous_name(),
            };
            let child = self.object(src, node, depth)?;
            self.push(parent, name, Value::Object(child), loc);
            return Ok(());
        }
        match tag {
            "default" | "path" | "include" | "alias" | "ref" => {
                self.structural(src, node, parent, depth)
            }
            "float" | "integer" | "boolean" | "string" | "point" | "vector" | "rgb" | "color"
            | "spectrum" | "transform" => {
                let name = self.name(src, node)?.ok_or_else(|| {
                    self.tree
                        .error(loc, format!("<{tag}>: expected a 'name' attribute"))
                })?;
                let value = self.property(src, node, &name)?;
                self.push(parent, name, value, loc);
                Ok(())
            }
            "translate" | "rotate" | "scale" | "lookat" | "matrix" => Err(self
                .tree
                .error(loc, format!("<{tag}> outside a <transform>"))),
            "lookAt" if src.legacy => Err(self.tree.error(loc, "<lookAt> outside a <transform>")),
            other => Err(self.tree.error(
                loc,
                format!("unknown element <{other}> (not a Mitsuba 3 property or object tag)"),
            )),
        }
    }

    /// The elements that shape the file rather than its objects: `<default>`, `<path>`,
    /// `<include>`, `<alias>` and `<ref>` (a child of `parent`).
    fn structural(
        &mut self,
        src: &Source,
        node: XmlNode,
        parent: usize,
        depth: usize,
    ) -> Result<(), Error> {
        let loc = src.loc(node);
        match node.tag_name().name() {
            "default" => {
                let key = format!("${}", self.required(src, node, "name")?);
                let value = self.required(src, node, "value")?;
                if !self.params.iter().any(|p| p.key == key) {
                    self.params.push(Param {
                        key,
                        value,
                        used: false,
                        from_command_line: false,
                    });
                    self.sort_params();
                }
            }
            "path" => {
                let value = self.required(src, node, "value")?;
                let declared = self.tree.files[src.file]
                    .parent()
                    .unwrap_or(Path::new("."))
                    .join(&value);
                let dir = if declared.is_dir() {
                    declared
                } else {
                    self.tree.resolve(&value, src.file)
                };
                if !dir.is_dir() {
                    return Err(self
                        .tree
                        .error(loc, format!("<path>: folder '{}' not found", dir.display())));
                }
                self.tree.search.insert(0, dir);
            }
            "include" => {
                if depth >= MAX_INCLUDE_DEPTH {
                    return Err(self.tree.error(loc, "includes nest too deeply (a loop?)"));
                }
                let name = self.required(src, node, "filename")?;
                let path = self.tree.resolve(&name, src.file);
                if !path.is_file() {
                    return Err(self.tree.error(
                        loc,
                        format!("<include>: file '{}' not found", path.display()),
                    ));
                }
                self.file(&path, Some(parent), depth + 1)?;
            }
            "alias" => {
                let id = self.required(src, node, "id")?;
                let alias = self.required(src, node, "as")?;
                let Some(&target) = self.tree.ids.get(&id) else {
                    return Err(self
                        .tree
                        .error(loc, format!("<alias>: no object has id '{id}'")));
                };
                self.tree.ids.insert(alias, target);
            }
            "ref" => {
                let id = self.required(src, node, "id")?;
                let name = match self.name(src, node)? {
                    Some(n) => n,
                    None => self.anonymous_name(),
                };
                self.push(parent, name, Value::Ref(id), loc);
            }
            other => unreachable!("structural() is called for structural elements, not <{other}>"),
        }
        Ok(())
    }
}

/// A finite number.
pub(crate) fn parse_f64(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Finite numbers separated by commas and/or white space.
pub(crate) fn numbers(text: &str) -> Option<Vec<f64>> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(parse_f64)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camel_case_becomes_snake_case() {
        assert_eq!(snake_case("diffuseReflectance"), "diffuse_reflectance");
        assert_eq!(snake_case("intIOR"), "int_ior");
        assert_eq!(snake_case("toWorld"), "to_world");
        assert_eq!(snake_case("fov"), "fov");
    }

    #[test]
    fn numbers_split_on_commas_and_spaces() {
        assert_eq!(numbers("1, 2 3").unwrap(), vec![1.0, 2.0, 3.0]);
        assert!(numbers("1 x").is_none());
        assert!(numbers("1 inf").is_none());
    }
}
