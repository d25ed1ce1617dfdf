//! The graphics state's directives: the transforms (`Translate`, `Rotate`, `Scale`, `LookAt`,
//! `Transform`, `ConcatTransform`, named coordinate systems) and the blocks and attributes
//! (`AttributeBegin/End`, `TransformBegin/End`, `Attribute`, `ReverseOrientation`).

use super::lexer::{Lexer, TokenKind};
use super::params::ParamList;
use super::{look_at, Builder};
use crate::Error;
use glam::{DMat4, DVec3};

impl Builder {
    /// The transform directives: each changes the current transformation matrix. Returns whether `word` is one of them.
    pub(super) fn transform_directive(
        &mut self,
        word: &str,
        lx: &mut Lexer,
    ) -> Result<bool, Error> {
        match word {
            "Translate" => {
                let v = self.numbers(lx, word, 3)?;
                self.concat(DMat4::from_translation(DVec3::new(v[0], v[1], v[2])));
            }
            "Scale" => {
                let v = self.numbers(lx, word, 3)?;
                self.concat(DMat4::from_scale(DVec3::new(v[0], v[1], v[2])));
            }
            "Rotate" => {
                let v = self.numbers(lx, word, 4)?;
                let axis = DVec3::new(v[1], v[2], v[3]);
                if axis.length_squared() == 0.0 {
                    return Err(self.error("Rotate: the axis is zero"));
                }
                self.concat(DMat4::from_axis_angle(axis.normalize(), v[0].to_radians()));
            }
            "LookAt" => {
                let v = self.numbers(lx, word, 9)?;
                let m = look_at(
                    DVec3::new(v[0], v[1], v[2]),
                    DVec3::new(v[3], v[4], v[5]),
                    DVec3::new(v[6], v[7], v[8]),
                )
                .ok_or_else(|| {
                    self.error("LookAt: the eye, the target and the up vector must span a frame")
                })?;
                self.concat(m);
            }
            "Transform" | "ConcatTransform" => {
                let v = self.numbers(lx, word, 16)?;
                // pbrt reads the 16 numbers as the transpose of the matrix: column-major for
                // column vectors, as glam stores them.
                let m = DMat4::from_cols_slice(&v);
                if word == "Transform" {
                    self.gs.ctm = m;
                } else {
                    self.concat(m);
                }
            }
            "Identity" => self.gs.ctm = DMat4::IDENTITY,
            "CoordinateSystem" => {
                let name = self.string_arg(lx, word)?;
                self.coord_systems.insert(name, self.gs.ctm);
            }
            "CoordSysTransform" => {
                let name = self.string_arg(lx, word)?;
                match self.coord_systems.get(&name) {
                    Some(m) => self.gs.ctm = *m,
                    None => self.warn(format!(
                        "CoordSysTransform: no coordinate system named '{name}'; ignored"
                    )),
                }
            }
            "ActiveTransform" => {
                let Some(t) = lx.next()? else {
                    return Err(self.error("ActiveTransform: the file ends"));
                };
                match t.kind {
                    TokenKind::Word("All") | TokenKind::Word("StartTime") => {}
                    TokenKind::Word("EndTime") => self.warn(
                        "ActiveTransform EndTime: motion blur is not supported; the start transform is used",
                    ),
                    _ => return Err(self.error("ActiveTransform: expected All, StartTime or EndTime")),
                }
            }
            "TransformTimes" => {
                self.numbers(lx, word, 2)?;
                self.warn("TransformTimes: motion blur is not supported; ignored");
            }
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// The graphics-state directives: blocks that save and restore it, and the attributes set in it. Returns whether `word` is one of them.
    pub(super) fn attribute_directive(
        &mut self,
        word: &str,
        lx: &mut Lexer,
    ) -> Result<bool, Error> {
        match word {
            "ReverseOrientation" => self.gs.reverse_orientation = !self.gs.reverse_orientation,
            "AttributeBegin" | "TransformBegin" => {
                if word == "TransformBegin" {
                    self.warn("TransformBegin is deprecated in pbrt-v4; read as it was in pbrt-v3");
                }
                let mut saved = self.gs.clone();
                saved.transform_only = word == "TransformBegin";
                self.stack.push((saved, self.file.clone(), self.line));
            }
            "AttributeEnd" | "TransformEnd" => {
                let Some((saved, _, _)) = self.stack.pop() else {
                    return Err(self.error(format!("{word} without a matching begin")));
                };
                if saved.transform_only != (word == "TransformEnd") {
                    return Err(self.error(format!(
                        "{word} closes a block opened by {}",
                        if saved.transform_only {
                            "TransformBegin"
                        } else {
                            "AttributeBegin"
                        }
                    )));
                }
                if saved.transform_only {
                    self.gs.ctm = saved.ctm;
                } else {
                    self.gs = saved;
                }
            }
            "Attribute" => {
                let target = self.string_arg(lx, word)?;
                let params = ParamList::parse(lx)?;
                if !["shape", "light", "material", "medium", "texture"].contains(&target.as_str()) {
                    return Err(self.error(format!(
                        "Attribute \"{target}\": expected shape, light, material, medium or texture"
                    )));
                }
                let entry = self.gs.defaults.entry(target).or_default();
                for p in params.params {
                    entry.params.retain(|q| q.name != p.name);
                    entry.params.push(p);
                }
            }
            _ => return Ok(false),
        }
        Ok(true)
    }
}
