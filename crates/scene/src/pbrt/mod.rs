//! pbrt-v4 scenes (`.pbrt`, `.pbrt.gz`), read as pbrt-v4 defines them.
//!
//! - The file: comments, quoted strings with escapes, typed parameter lists ([`params`]),
//!   `Include`/`Import`, `AttributeBegin/End` (and the older `TransformBegin/End`),
//!   `Attribute` defaults, every transform directive, named coordinate systems, named
//!   materials and textures, `ObjectBegin/End` + `ObjectInstance`, `ReverseOrientation`;
//!   `MakeNamedMedium`/`MediumInterface` are read and warned about (no media).
//! - Handedness: pbrt's camera space is left-handed (x right, y up, z forward). When the
//!   camera's transform keeps orientation, the whole world is mirrored in x (camera included),
//!   which renders the same image with pathlab's right-handed camera.
//! - The graphics state's transforms and attributes ([`state`]); shapes ([`shapes`], the
//!   quadrics in [`quadrics`]), materials ([`materials`]), textures ([`textures`]), spectra
//!   ([`spectra`]), lights ([`lights`]); camera, film, sampler and integrator ([`world`]). What
//!   pathlab cannot render is a warning naming the file and line, never ignored silently.

mod lexer;
mod lights;
mod loop_subdiv;
mod materials;
mod params;
mod quadrics;
mod shapes;
mod spectra;
mod state;
mod textures;
mod world;

use crate::Error;
use glam::{DMat4, DVec3};
use lexer::{Lexer, TokenKind};
use params::ParamList;
use pathlab_render::desc::SceneDesc;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Largest scene file (after decompression) read: far above real scenes, small enough that a
/// bogus file cannot exhaust memory.
pub const MAX_PBRT_BYTES: u64 = 4 << 30;

/// Deepest chain of `Include`s.
const MAX_INCLUDE_DEPTH: usize = 32;

/// Loads a pbrt-v4 scene.
pub fn load(path: &Path) -> Result<SceneDesc, Error> {
    let mut b = Builder::new(path);
    // pbrt-v4's default pixel filter: a Gaussian of σ = 0.5 pixels.
    b.desc.filter = world::PBRT_DEFAULT_FILTER;
    b.parse_file(path, 0)?;
    b.finish()
}

/// Reads a text file, decompressing `.gz`, at most [`MAX_PBRT_BYTES`].
pub(crate) fn read_text(path: &Path) -> Result<String, Error> {
    let bytes = read_bytes(path)?;
    String::from_utf8(bytes).map_err(|e| Error::Parse {
        path: path.display().to_string(),
        line: 1 + e.as_bytes()[..e.utf8_error().valid_up_to()]
            .iter()
            .filter(|&&c| c == b'\n')
            .count(),
        column: 0,
        message: "not a text file (invalid UTF-8)".into(),
    })
}

/// A file's bytes, decompressed when its name ends in `.gz`, at most [`MAX_PBRT_BYTES`].
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, Error> {
    use std::io::Read;
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let gz = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"));
    let mut out = Vec::new();
    let limited = |r: &mut dyn Read, out: &mut Vec<u8>| r.take(MAX_PBRT_BYTES + 1).read_to_end(out);
    let result = if gz {
        limited(&mut flate2::read::MultiGzDecoder::new(file), &mut out)
    } else {
        limited(&mut std::io::BufReader::new(file), &mut out)
    };
    result.map_err(|e| Error::Parse {
        path: path.display().to_string(),
        line: 0,
        column: 0,
        message: if gz {
            format!("not a valid gzip file ({e})")
        } else {
            format!("cannot read the file ({e})")
        },
    })?;
    if out.len() as u64 > MAX_PBRT_BYTES {
        return Err(Error::Parse {
            path: path.display().to_string(),
            line: 0,
            column: 0,
            message: format!("larger than {} GiB", MAX_PBRT_BYTES >> 30),
        });
    }
    Ok(out)
}

/// What `AttributeBegin` saves and `AttributeEnd` restores.
#[derive(Clone, Debug)]
pub(crate) struct GraphicsState {
    /// Object to (pbrt's) world.
    pub ctm: DMat4,
    /// `ReverseOrientation` in effect.
    pub reverse_orientation: bool,
    /// The current material: an index into the scene's materials (`None`: pbrt's default,
    /// diffuse 0.5).
    pub material: Option<usize>,
    /// The current area light: its parameters and line.
    pub area_light: Option<(String, ParamList, usize)>,
    /// `Attribute` defaults by target (`shape`, `light`, `material`, `medium`, `texture`).
    pub defaults: HashMap<String, ParamList>,
    /// Whether the block was opened by `TransformBegin` (which restores the transform only).
    pub transform_only: bool,
}

/// A shape inside `ObjectBegin`/`ObjectEnd`, made when the object is instanced.
#[derive(Clone, Debug)]
pub(crate) struct ObjectShape {
    pub kind: String,
    pub params: ParamList,
    pub state: GraphicsState,
    pub file: PathBuf,
    pub line: usize,
}

/// The scene as the file builds it.
pub(crate) struct Builder {
    pub desc: SceneDesc,
    pub gs: GraphicsState,
    stack: Vec<(GraphicsState, PathBuf, usize)>,
    /// Named coordinate systems (`CoordinateSystem`; `camera` from `Camera`).
    coord_systems: HashMap<String, DMat4>,
    /// Named materials.
    pub named_materials: HashMap<String, usize>,
    /// Named textures (spectrum and float).
    pub textures: HashMap<String, pathlab_render::desc::TextureDesc>,
    /// Object definitions.
    objects: HashMap<String, Vec<ObjectShape>>,
    /// The object being defined.
    current_object: Option<(String, Vec<ObjectShape>)>,
    /// Maps pbrt's world to pathlab's: a mirror in x, or the identity (see the module notes).
    pub world_fix: DMat4,
    /// Whether `WorldBegin` has been read.
    in_world: bool,
    /// Camera, film and the rest, read before `WorldBegin`.
    pub options: world::Options,
    /// The scene file's folder (relative file names are read from it).
    pub base: PathBuf,
    /// The file and line being read, for messages.
    pub file: PathBuf,
    pub line: usize,
    /// Warnings already given (each once).
    warned: std::collections::HashSet<String>,
    /// Meshes read from PLY files, by path (instances and repeated files read them once).
    pub ply_cache: HashMap<PathBuf, std::sync::Arc<pathlab_render::desc::MeshDesc>>,
}

impl Builder {
    fn new(path: &Path) -> Self {
        Builder {
            desc: SceneDesc::default(),
            gs: GraphicsState {
                ctm: DMat4::IDENTITY,
                reverse_orientation: false,
                material: None,
                area_light: None,
                defaults: HashMap::new(),
                transform_only: false,
            },
            stack: Vec::new(),
            coord_systems: HashMap::new(),
            named_materials: HashMap::new(),
            textures: HashMap::new(),
            objects: HashMap::new(),
            current_object: None,
            world_fix: DMat4::IDENTITY,
            in_world: false,
            options: world::Options::default(),
            base: path.parent().map(Path::to_path_buf).unwrap_or_default(),
            file: path.to_path_buf(),
            line: 0,
            warned: Default::default(),
            ply_cache: HashMap::new(),
        }
    }

    /// An error at the current file and line.
    pub(crate) fn error(&self, message: impl Into<String>) -> Error {
        Error::Parse {
            path: self.file.display().to_string(),
            line: self.line,
            column: 0,
            message: message.into(),
        }
    }

    /// A warning at the current file and line (each text once).
    pub(crate) fn warn(&mut self, message: impl Into<String>) {
        let text = format!("{}:{}: {}", self.file.display(), self.line, message.into());
        if self.warned.insert(text.clone()) {
            self.desc.warnings.push(text);
        }
    }

    /// Warns of the parameters nobody read.
    pub(crate) fn warn_unused(&mut self, what: &str, params: &ParamList) {
        let unused = params.unused();
        if !unused.is_empty() {
            self.warn(format!(
                "{what}: {} not supported; ignored",
                unused.join(", ")
            ));
        }
    }

    /// A file name from the scene, relative to the scene file's folder.
    pub(crate) fn resolve(&self, name: &str) -> PathBuf {
        let p = Path::new(name);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.base.join(p)
        }
    }

    fn parse_file(&mut self, path: &Path, depth: usize) -> Result<(), Error> {
        let text = read_text(path)?;
        let name = path.display().to_string();
        let mut lx = Lexer::new(&text, &name);
        let saved_file = std::mem::replace(&mut self.file, path.to_path_buf());
        let result = self.parse(&mut lx, depth);
        self.file = saved_file;
        result
    }

    fn parse(&mut self, lx: &mut Lexer, depth: usize) -> Result<(), Error> {
        while let Some(t) = lx.next()? {
            self.line = t.line;
            let word = match t.kind {
                TokenKind::Word(w) => w,
                TokenKind::Str(s) => {
                    return Err(self.error(format!("\"{s}\": expected a directive")))
                }
                TokenKind::Open | TokenKind::Close => {
                    return Err(self.error("a bracket where a directive was expected"))
                }
            };
            self.directive(word, lx, depth)?;
        }
        Ok(())
    }

    /// The next token as a quoted string (a directive's argument).
    fn string_arg(&self, lx: &mut Lexer, directive: &str) -> Result<String, Error> {
        match lx.next()? {
            Some(t) => match t.kind {
                TokenKind::Str(s) => Ok(s.into_owned()),
                _ => Err(self.error(format!("{directive}: expected a quoted name"))),
            },
            None => Err(self.error(format!("{directive}: the file ends before its name"))),
        }
    }

    /// `n` numbers, bare or in brackets.
    fn numbers(&self, lx: &mut Lexer, directive: &str, n: usize) -> Result<Vec<f64>, Error> {
        let mut out = Vec::with_capacity(n);
        let mut bracket = false;
        loop {
            let Some(t) = lx.next()? else {
                return Err(
                    self.error(format!("{directive}: the file ends before its {n} numbers"))
                );
            };
            match t.kind {
                TokenKind::Open if out.is_empty() && !bracket => bracket = true,
                TokenKind::Close if bracket => break,
                TokenKind::Word(w) => {
                    let Some(v) = w.parse::<f64>().ok().filter(|v| v.is_finite()) else {
                        if !bracket && w.starts_with(|c: char| c.is_ascii_alphabetic()) {
                            // The next directive: too few numbers.
                            lx.unread(lexer::Token {
                                kind: TokenKind::Word(w),
                                line: t.line,
                            });
                            break;
                        }
                        return Err(
                            self.error(format!("{directive}: '{w}' is not a finite number"))
                        );
                    };
                    out.push(v);
                    if !bracket && out.len() == n {
                        break;
                    }
                }
                _ => {
                    return Err(self.error(format!("{directive}: expected {n} numbers")));
                }
            }
            if out.len() > n {
                break;
            }
        }
        if out.len() != n {
            return Err(self.error(format!(
                "{directive}: expected {n} numbers, found {}",
                out.len()
            )));
        }
        Ok(out)
    }

    fn directive(&mut self, word: &str, lx: &mut Lexer, depth: usize) -> Result<(), Error> {
        let known = self.transform_directive(word, lx)?
            || self.attribute_directive(word, lx)?
            || self.structure_directive(word, lx, depth)?
            || self.appearance_directive(word, lx)?
            || self.shapes_directive(word, lx)?;
        if known {
            Ok(())
        } else {
            Err(self.error(format!("unknown directive '{word}'")))
        }
    }

    /// The file's structure and options: rendering options before `WorldBegin`, includes, colour space. Returns whether `word` is one of them.
    fn structure_directive(
        &mut self,
        word: &str,
        lx: &mut Lexer,
        depth: usize,
    ) -> Result<bool, Error> {
        match word {
            "Option" => {
                let params = ParamList::parse(lx)?;
                let names: Vec<String> = params.params.iter().map(|p| p.name.clone()).collect();
                self.warn(format!(
                    "Option {}: not supported; ignored",
                    names.join(", ")
                ));
            }
            "ColorSpace" => {
                let name = self.string_arg(lx, word)?;
                if name != "srgb" {
                    self.warn(format!(
                        "ColorSpace \"{name}\": pathlab renders in linear sRGB; colours are read as sRGB"
                    ));
                }
            }
            "Camera" | "Film" | "Sampler" | "PixelFilter" | "Integrator" | "Accelerator" => {
                let kind = self.string_arg(lx, word)?;
                let params = ParamList::parse(lx)?;
                if self.in_world {
                    return Err(self.error(format!("{word} must come before WorldBegin")));
                }
                if word == "Camera" {
                    self.coord_systems
                        .insert("camera".into(), self.gs.ctm.inverse());
                }
                let ctm = self.gs.ctm;
                self.options_directive(word, kind, params, ctm)?;
            }
            "WorldBegin" => {
                if self.in_world {
                    return Err(self.error("a second WorldBegin"));
                }
                self.in_world = true;
                self.world_fix = self.options.world_fix();
                self.gs.ctm = DMat4::IDENTITY;
                self.coord_systems.insert("world".into(), DMat4::IDENTITY);
            }
            "WorldEnd" => {
                self.warn("WorldEnd is not part of pbrt-v4 files; ignored");
            }
            "Include" | "Import" => {
                let name = self.string_arg(lx, word)?;
                if depth >= MAX_INCLUDE_DEPTH {
                    return Err(self.error(format!(
                        "{word} \"{name}\": more than {MAX_INCLUDE_DEPTH} nested includes (a cycle?)"
                    )));
                }
                let path = self.resolve(&name);
                // A file that is not there is a warning (scenes are shared without some of
                // their parts); one that cannot be read or parsed is an error.
                if !path.exists() {
                    self.warn(format!(
                        "{word} \"{name}\": {} does not exist; its contents are skipped",
                        path.display()
                    ));
                    return Ok(true);
                }
                let line = self.line;
                self.parse_file(&path, depth + 1)?;
                self.line = line;
            }
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// Materials, textures and media. Returns whether `word` is one of them.
    fn appearance_directive(&mut self, word: &str, lx: &mut Lexer) -> Result<bool, Error> {
        match word {
            "MakeNamedMaterial" => {
                let name = self.string_arg(lx, word)?;
                let params = ParamList::parse(lx)?;
                self.world_only(word)?;
                let m = self.named_material(&name, params)?;
                self.named_materials.insert(name, m);
            }
            "Material" => {
                let kind = self.string_arg(lx, word)?;
                let params = ParamList::parse(lx)?;
                self.world_only(word)?;
                let m = self.material(&kind, params)?;
                self.gs.material = Some(m);
            }
            "NamedMaterial" => {
                let name = self.string_arg(lx, word)?;
                self.world_only(word)?;
                match self.named_materials.get(&name) {
                    Some(&m) => self.gs.material = Some(m),
                    None => {
                        return Err(self.error(format!(
                            "NamedMaterial \"{name}\": no material of that name was made (MakeNamedMaterial)"
                        )))
                    }
                }
            }
            "Texture" => {
                let name = self.string_arg(lx, word)?;
                let ty = self.string_arg(lx, word)?;
                let class = self.string_arg(lx, word)?;
                let params = ParamList::parse(lx)?;
                self.world_only(word)?;
                self.texture(name, &ty, &class, params)?;
            }
            "MakeNamedMedium" => {
                let name = self.string_arg(lx, word)?;
                let _ = ParamList::parse(lx)?;
                self.warn(format!(
                    "MakeNamedMedium \"{name}\": participating media are not supported; ignored"
                ));
            }
            "MediumInterface" => {
                let inside = self.string_arg(lx, word)?;
                // The outside medium is optional.
                let outside = match lx.next()? {
                    Some(t) => match t.kind {
                        TokenKind::Str(s) => s.into_owned(),
                        other => {
                            lx.unread(lexer::Token {
                                kind: other,
                                line: t.line,
                            });
                            inside.clone()
                        }
                    },
                    None => inside.clone(),
                };
                if !(inside.is_empty() && outside.is_empty()) {
                    self.warn("MediumInterface: participating media are not supported; ignored");
                }
            }
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// Lights, shapes and object instancing. Returns whether `word` is one of them.
    fn shapes_directive(&mut self, word: &str, lx: &mut Lexer) -> Result<bool, Error> {
        match word {
            "LightSource" => {
                let kind = self.string_arg(lx, word)?;
                let params = ParamList::parse(lx)?;
                self.world_only(word)?;
                let params = self.with_defaults("light", params);
                self.light(&kind, params)?;
            }
            "AreaLightSource" => {
                let kind = self.string_arg(lx, word)?;
                let params = ParamList::parse(lx)?;
                self.world_only(word)?;
                let params = self.with_defaults("light", params);
                self.gs.area_light = Some((kind, params, self.line));
            }
            "Shape" => {
                let kind = self.string_arg(lx, word)?;
                let params = ParamList::parse(lx)?;
                self.world_only(word)?;
                let params = self.with_defaults("shape", params);
                if let Some((_, shapes)) = self.current_object.as_mut() {
                    shapes.push(ObjectShape {
                        kind,
                        params,
                        state: self.gs.clone(),
                        file: self.file.clone(),
                        line: self.line,
                    });
                } else {
                    let state = self.gs.clone();
                    self.shape(&kind, params, &state)?;
                }
            }
            "ObjectBegin" => {
                let name = self.string_arg(lx, word)?;
                self.world_only(word)?;
                if self.current_object.is_some() {
                    return Err(self.error(format!(
                        "ObjectBegin \"{name}\" inside another object's definition"
                    )));
                }
                self.stack
                    .push((self.gs.clone(), self.file.clone(), self.line));
                self.current_object = Some((name, Vec::new()));
            }
            "ObjectEnd" => {
                let Some((name, shapes)) = self.current_object.take() else {
                    return Err(self.error("ObjectEnd without ObjectBegin"));
                };
                let Some((saved, _, _)) = self.stack.pop() else {
                    return Err(self.error("ObjectEnd without ObjectBegin"));
                };
                self.gs = saved;
                self.objects.insert(name, shapes);
            }
            "ObjectInstance" => {
                let name = self.string_arg(lx, word)?;
                self.world_only(word)?;
                let Some(shapes) = self.objects.get(&name).cloned() else {
                    return Err(self.error(format!(
                        "ObjectInstance \"{name}\": no object of that name was defined"
                    )));
                };
                let (file, line) = (self.file.clone(), self.line);
                for s in shapes {
                    let mut state = s.state.clone();
                    state.ctm = self.gs.ctm * s.state.ctm;
                    self.file = s.file.clone();
                    self.line = s.line;
                    self.shape(&s.kind, s.params.clone(), &state)?;
                }
                self.file = file;
                self.line = line;
            }
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// Directives that belong after `WorldBegin`.
    fn world_only(&self, directive: &str) -> Result<(), Error> {
        if self.in_world {
            Ok(())
        } else {
            Err(self.error(format!("{directive} must come after WorldBegin")))
        }
    }

    /// `params` with the `Attribute` defaults for `target` added.
    fn with_defaults(&self, target: &str, params: ParamList) -> ParamList {
        match self.gs.defaults.get(target) {
            Some(d) => params.with_defaults(d),
            None => params,
        }
    }

    fn concat(&mut self, m: DMat4) {
        self.gs.ctm *= m;
    }

    fn finish(mut self) -> Result<SceneDesc, Error> {
        if let Some((_, file, line)) = self.stack.last() {
            return Err(Error::Parse {
                path: file.display().to_string(),
                line: *line,
                column: 0,
                message: "AttributeBegin (or ObjectBegin) never closed".into(),
            });
        }
        if !self.in_world {
            self.line = 0;
            return Err(self.error("no WorldBegin: the file describes no scene"));
        }
        self.finish_options()?;
        Ok(self.desc)
    }
}

/// pbrt's `LookAt`: the camera-from-world transform of a camera at `eye` looking at `target`
/// with `up` (left-handed: x = up × dir).
fn look_at(eye: DVec3, target: DVec3, up: DVec3) -> Option<DMat4> {
    let dir = (target - eye).try_normalize()?;
    let right = up.try_normalize()?.cross(dir).try_normalize()?;
    let new_up = dir.cross(right);
    let world_from_camera = DMat4::from_cols(
        right.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        eye.extend(1.0),
    );
    Some(world_from_camera.inverse())
}
