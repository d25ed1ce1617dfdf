//! pbrt's typed parameter lists: `"float fov" [ 45 ]`, `"rgb L" [ 1 1 1 ]`, `"string
//! filename" "a.ply"`, read after a directive's own arguments. Each parameter remembers
//! whether it was read, so that those no one reads become warnings.

use super::lexer::{Lexer, TokenKind};
use crate::Error;
use std::cell::Cell;

/// A parameter's values.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Values {
    /// Numbers (float, integer, point, vector, normal, rgb, blackbody, sampled spectra).
    Numbers(Vec<f64>),
    /// Strings (string, texture, named spectra).
    Strings(Vec<String>),
    /// Booleans.
    Bools(Vec<bool>),
}

/// One parameter.
#[derive(Clone, Debug)]
pub(crate) struct Param {
    /// Its declared type (`float`, `rgb`, `point3`, ...).
    pub ty: String,
    /// Its name.
    pub name: String,
    /// Its values.
    pub values: Values,
    /// The line it was declared on.
    pub line: usize,
    /// Whether anything read it.
    pub used: Cell<bool>,
}

/// The types pbrt-v4 declares, with the number of values that make one item.
const TYPES: &[(&str, usize)] = &[
    ("integer", 1),
    ("float", 1),
    ("point2", 2),
    ("vector2", 2),
    ("point3", 3),
    ("vector3", 3),
    ("normal", 3),
    ("normal3", 3),
    ("point", 3),
    ("vector", 3),
    ("color", 3),
    ("rgb", 3),
    ("spectrum", 1),
    ("blackbody", 1),
    ("bool", 1),
    ("string", 1),
    ("texture", 1),
];

/// A directive's parameters.
#[derive(Clone, Debug, Default)]
pub(crate) struct ParamList {
    /// In the order given.
    pub params: Vec<Param>,
}

impl ParamList {
    /// Reads parameters until the next bare word (a directive) or the end.
    pub(crate) fn parse(lx: &mut Lexer) -> Result<ParamList, Error> {
        let mut params = Vec::new();
        while let Some(t) = lx.next()? {
            let decl = match &t.kind {
                TokenKind::Str(s) => s.clone(),
                _ => {
                    lx.unread(t);
                    break;
                }
            };
            let line = t.line;
            let mut parts = decl.split_whitespace();
            let (Some(ty), Some(name), None) = (parts.next(), parts.next(), parts.next()) else {
                return Err(lx.error(
                    line,
                    format!("\"{decl}\": expected a parameter declaration \"TYPE NAME\""),
                ));
            };
            let Some(&(_, arity)) = TYPES.iter().find(|(k, _)| *k == ty) else {
                return Err(lx.error(
                    line,
                    format!(
                        "\"{decl}\": unknown parameter type '{ty}' (expected one of {})",
                        TYPES.iter().map(|(k, _)| *k).collect::<Vec<_>>().join(", ")
                    ),
                ));
            };
            let values = Self::values(lx, line, ty, name)?;
            if let Values::Numbers(v) = &values {
                if arity > 1 && v.len() % arity != 0 {
                    return Err(lx.error(
                        line,
                        format!(
                            "\"{decl}\": {} numbers, not a whole number of {ty} values ({arity} each)",
                            v.len()
                        ),
                    ));
                }
            }
            let kind_ok = match (&values, ty) {
                (Values::Strings(_), "string" | "texture" | "spectrum") => true,
                (Values::Bools(_), "bool") => true,
                (Values::Numbers(_), "string" | "texture" | "bool") => false,
                (Values::Numbers(_), _) => true,
                _ => false,
            };
            if !kind_ok {
                return Err(lx.error(
                    line,
                    format!("\"{decl}\": the values do not fit the type '{ty}'"),
                ));
            }
            if ty == "integer" {
                if let Values::Numbers(v) = &values {
                    if let Some(bad) = v.iter().find(|x| x.fract() != 0.0) {
                        return Err(lx.error(line, format!("\"{decl}\": {bad} is not an integer")));
                    }
                }
            }
            params.push(Param {
                ty: ty.to_string(),
                name: name.to_string(),
                values,
                line,
                used: Cell::new(false),
            });
        }
        Ok(ParamList { params })
    }

    /// The values of one parameter: a bracketed list, or a single value.
    fn values(lx: &mut Lexer, line: usize, ty: &str, name: &str) -> Result<Values, Error> {
        let Some(t) = lx.next()? else {
            return Err(lx.error(
                line,
                format!("\"{ty} {name}\": the file ends before its value"),
            ));
        };
        let mut items = Vec::new();
        match t.kind {
            TokenKind::Open => loop {
                match lx.next()? {
                    None => {
                        return Err(lx.error(
                            line,
                            format!("\"{ty} {name}\": the file ends inside its [ ]"),
                        ))
                    }
                    Some(t) if t.kind == TokenKind::Close => break,
                    Some(t) if t.kind == TokenKind::Open => {
                        return Err(lx.error(t.line, format!("\"{ty} {name}\": a '[' inside [ ]")))
                    }
                    Some(t) => items.push(t.kind),
                }
            },
            TokenKind::Close => {
                return Err(lx.error(t.line, format!("\"{ty} {name}\": a ']' without '['")))
            }
            other => items.push(other),
        }
        let first_string = matches!(items.first(), Some(TokenKind::Str(_)));
        if ty == "bool" {
            let mut out = Vec::with_capacity(items.len());
            for it in &items {
                let word = match it {
                    TokenKind::Word(w) => *w,
                    TokenKind::Str(s) => s.as_ref(),
                    _ => "",
                };
                out.push(match word {
                    "true" => true,
                    "false" => false,
                    other => {
                        return Err(lx.error(
                            line,
                            format!("\"bool {name}\": '{other}' is not true or false"),
                        ))
                    }
                });
            }
            return Ok(Values::Bools(out));
        }
        if first_string {
            let mut out = Vec::with_capacity(items.len());
            for it in items {
                match it {
                    TokenKind::Str(s) => out.push(s.into_owned()),
                    TokenKind::Word(w) => {
                        return Err(lx.error(
                            line,
                            format!("\"{ty} {name}\": '{w}' among strings (quote it)"),
                        ))
                    }
                    _ => {}
                }
            }
            return Ok(Values::Strings(out));
        }
        let mut out = Vec::with_capacity(items.len());
        for it in items {
            match it {
                TokenKind::Word(w) => {
                    let v: f64 = w.parse().map_err(|_| {
                        lx.error(line, format!("\"{ty} {name}\": '{w}' is not a number"))
                    })?;
                    if !v.is_finite() {
                        return Err(lx.error(
                            line,
                            format!("\"{ty} {name}\": '{w}' is not a finite number"),
                        ));
                    }
                    out.push(v);
                }
                TokenKind::Str(s) => {
                    return Err(lx.error(
                        line,
                        format!("\"{ty} {name}\": the string \"{s}\" among numbers"),
                    ))
                }
                _ => {}
            }
        }
        Ok(Values::Numbers(out))
    }

    /// The parameter called `name`, marked as read.
    pub(crate) fn get(&self, name: &str) -> Option<&Param> {
        let p = self.params.iter().rev().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// Whether a parameter called `name` is given (without marking it read).
    pub(crate) fn has(&self, name: &str) -> bool {
        self.params.iter().any(|p| p.name == name)
    }

    /// Parameters nobody read: `"TYPE NAME" (line N)` each.
    pub(crate) fn unused(&self) -> Vec<String> {
        self.params
            .iter()
            .filter(|p| !p.used.get())
            .map(|p| format!("\"{} {}\" (line {})", p.ty, p.name, p.line))
            .collect()
    }

    /// Adds `defaults`' parameters that this list does not give (pbrt-v4's `Attribute`).
    pub(crate) fn with_defaults(mut self, defaults: &ParamList) -> ParamList {
        for d in &defaults.params {
            if !self.has(&d.name) {
                self.params.insert(0, d.clone());
            }
        }
        self
    }
}

impl Param {
    /// The numbers, if it holds numbers.
    pub(crate) fn numbers(&self) -> Option<&[f64]> {
        match &self.values {
            Values::Numbers(v) => Some(v),
            _ => None,
        }
    }

    /// The strings, if it holds strings.
    pub(crate) fn strings(&self) -> Option<&[String]> {
        match &self.values {
            Values::Strings(v) => Some(v),
            _ => None,
        }
    }
}
