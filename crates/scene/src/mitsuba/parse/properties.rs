//! The values of property elements: numbers, booleans and strings, points and vectors,
//! colours, spectra (values, wavelength lists, files, blackbodies) and transforms built from
//! their operations.

use super::*;

impl Parser {
    /// The value of property element `node` named `name` (`<float>`, `<rgb>`, `<transform>`...).
    pub(super) fn property(
        &mut self,
        src: &Source,
        node: XmlNode,
        name: &str,
    ) -> Result<Value, Error> {
        let loc = src.loc(node);
        Ok(match node.tag_name().name() {
            "float" => {
                let v = self.required(src, node, "value")?;
                let f = parse_f64(&v).ok_or_else(|| {
                    self.tree.error(
                        loc,
                        format!(
                            "<float name=\"{name}\">: '{}' is not a number",
                            truncate(&v)
                        ),
                    )
                })?;
                Value::Float(f)
            }
            "integer" => {
                let v = self.required(src, node, "value")?;
                let i = v.trim().parse::<i64>().map_err(|_| {
                    self.tree.error(
                        loc,
                        format!(
                            "<integer name=\"{name}\">: '{}' is not an integer",
                            truncate(&v)
                        ),
                    )
                })?;
                Value::Int(i)
            }
            "boolean" => {
                let v = self.required(src, node, "value")?;
                let b = match v.trim().to_ascii_lowercase().as_str() {
                    "true" => true,
                    "false" => false,
                    _ => {
                        return Err(self.tree.error(
                            loc,
                            format!(
                                "<boolean name=\"{name}\">: '{}' is neither true nor false",
                                truncate(&v)
                            ),
                        ))
                    }
                };
                Value::Bool(b)
            }
            "string" => {
                let v = self.required(src, node, "value")?;
                Value::Str(v)
            }
            "point" | "vector" => {
                let v = self.xyz(src, node, 0.0)?;
                Value::Vector(v)
            }
            "rgb" | "color" => {
                let v = self.required(src, node, "value")?;
                let n = numbers(&v).ok_or_else(|| {
                    self.tree.error(
                        loc,
                        format!("<rgb name=\"{name}\">: '{}' is not numbers", truncate(&v)),
                    )
                })?;
                let c = match n.len() {
                    1 => DVec3::splat(n[0]),
                    3 => DVec3::new(n[0], n[1], n[2]),
                    k => {
                        return Err(self.tree.error(
                            loc,
                            format!("<rgb name=\"{name}\">: expected 1 or 3 values, found {k}"),
                        ))
                    }
                };
                Value::Rgb(c)
            }
            "spectrum" => {
                let spectrum = self.spectrum(src, node, name)?;
                Value::Spectrum(spectrum)
            }
            "transform" => {
                let mut m = DMat4::IDENTITY;
                for op in node.children().filter(|c| c.is_element()) {
                    m = self.transform_op(src, op)? * m;
                }
                if !m.is_finite() {
                    return Err(self.tree.error(loc, "<transform>: not finite"));
                }
                Value::Transform(m)
            }
            other => unreachable!("property() is called for property elements, not <{other}>"),
        })
    }

    /// x, y, z attributes (missing ones `default`) or a `value` of 1 or 3 numbers.
    pub(super) fn xyz(
        &mut self,
        src: &Source,
        node: XmlNode,
        default: f64,
    ) -> Result<DVec3, Error> {
        let loc = src.loc(node);
        let tag = node.tag_name().name().to_string();
        if let Some(v) = self.attr(src, node, "value")? {
            let n = numbers(&v).ok_or_else(|| {
                self.tree
                    .error(loc, format!("<{tag}>: '{}' is not numbers", truncate(&v)))
            })?;
            return match n.len() {
                1 => Ok(DVec3::splat(n[0])),
                3 => Ok(DVec3::new(n[0], n[1], n[2])),
                k => Err(self.tree.error(
                    loc,
                    format!("<{tag}>: 'value' needs 1 or 3 numbers, found {k}"),
                )),
            };
        }
        let get = |p: &mut Parser, k: &str| -> Result<f64, Error> {
            match p.attr(src, node, k)? {
                Some(v) => parse_f64(&v).ok_or_else(|| {
                    p.tree.error(
                        loc,
                        format!("<{tag}>: {k}='{}' is not a number", truncate(&v)),
                    )
                }),
                None => Ok(default),
            }
        };
        Ok(DVec3::new(
            get(self, "x")?,
            get(self, "y")?,
            get(self, "z")?,
        ))
    }

    pub(super) fn spectrum(
        &mut self,
        src: &Source,
        node: XmlNode,
        name: &str,
    ) -> Result<Spectrum, Error> {
        let loc = src.loc(node);
        let value = self.attr(src, node, "value")?;
        let filename = self.attr(src, node, "filename")?;
        match (value, filename) {
            (Some(v), None) => {
                let tokens: Vec<&str> = v
                    .split(|c: char| c == ',' || c.is_whitespace())
                    .filter(|t| !t.is_empty())
                    .collect();
                if tokens.len() == 1 && !tokens[0].contains(':') {
                    return parse_f64(tokens[0]).map(Spectrum::Constant).ok_or_else(|| {
                        self.tree.error(
                            loc,
                            format!(
                                "<spectrum name=\"{name}\">: '{}' is not a number",
                                truncate(tokens[0])
                            ),
                        )
                    });
                }
                let mut samples: Vec<(f64, f64)> = Vec::with_capacity(tokens.len());
                for t in tokens {
                    let pair = t
                        .split_once(':')
                        .and_then(|(w, v)| Some((parse_f64(w)?, parse_f64(v)?)));
                    let Some((w, v)) = pair else {
                        return Err(self.tree.error(
                            loc,
                            format!(
                                "<spectrum name=\"{name}\">: expected wavelength:value pairs such as 500:0.8, found '{}'",
                                truncate(t)
                            ),
                        ));
                    };
                    if let Some(&(prev, _)) = samples.last() {
                        if w <= prev {
                            return Err(self.tree.error(
                                loc,
                                format!("<spectrum name=\"{name}\">: wavelengths must increase ({w} after {prev})"),
                            ));
                        }
                    }
                    samples.push((w, v));
                }
                Ok(Spectrum::Sampled(samples))
            }
            (None, Some(f)) => {
                let path = self.tree.resolve(&f, src.file);
                let text = read_text(&path).map_err(|e| {
                    self.tree
                        .error(loc, format!("<spectrum name=\"{name}\">: {e}"))
                })?;
                let samples = crate::spectrum::parse_spd(&text)
                    .map_err(|e| self.tree.error(loc, format!("{}: {e}", path.display())))?;
                Ok(Spectrum::Sampled(samples))
            }
            _ => Err(self.tree.error(
                loc,
                format!("<spectrum name=\"{name}\">: needs either 'value' or 'filename'"),
            )),
        }
    }

    /// One operation of a `<transform>`, as a matrix (Mitsuba: later operations apply after
    /// earlier ones).
    pub(super) fn transform_op(&mut self, src: &Source, op: XmlNode) -> Result<DMat4, Error> {
        let loc = src.loc(op);
        let tag = op.tag_name().name();
        let m = match tag {
            "translate" => DMat4::from_translation(self.xyz(src, op, 0.0)?),
            "scale" => DMat4::from_scale(self.xyz(src, op, 1.0)?),
            "rotate" => {
                let axis = self.xyz(src, op, 0.0)?;
                let Some(axis) = axis.try_normalize() else {
                    return Err(self.tree.error(loc, "<rotate>: the axis is zero"));
                };
                let a = self.required(src, op, "angle")?;
                let angle = parse_f64(&a).ok_or_else(|| {
                    self.tree.error(
                        loc,
                        format!("<rotate>: angle '{}' is not a number", truncate(&a)),
                    )
                })?;
                DMat4::from_axis_angle(axis, angle.to_radians())
            }
            "matrix" => {
                let v = self.required(src, op, "value")?;
                let n = numbers(&v).ok_or_else(|| {
                    self.tree
                        .error(loc, format!("<matrix>: '{}' is not numbers", truncate(&v)))
                })?;
                match n.len() {
                    16 => DMat4::from_cols_slice(&n).transpose(),
                    9 => {
                        let mut m = DMat4::IDENTITY;
                        for r in 0..3 {
                            for c in 0..3 {
                                m.col_mut(c)[r] = n[r * 3 + c];
                            }
                        }
                        m
                    }
                    k => {
                        return Err(self.tree.error(
                            loc,
                            format!("<matrix>: expected 16 numbers (or 9), found {k}"),
                        ))
                    }
                }
            }
            "lookat" | "lookAt" => {
                let point = |p: &mut Parser, k: &str| -> Result<Option<DVec3>, Error> {
                    let Some(v) = p.attr(src, op, k)? else {
                        return Ok(None);
                    };
                    match numbers(&v) {
                        Some(n) if n.len() == 3 => Ok(Some(DVec3::new(n[0], n[1], n[2]))),
                        _ => Err(p.tree.error(
                            loc,
                            format!("<lookat>: '{k}' needs 3 numbers, found '{}'", truncate(&v)),
                        )),
                    }
                };
                let origin = point(self, "origin")?
                    .ok_or_else(|| self.tree.error(loc, "<lookat>: expected an 'origin'"))?;
                let target = point(self, "target")?
                    .ok_or_else(|| self.tree.error(loc, "<lookat>: expected a 'target'"))?;
                let dir = (target - origin).try_normalize().ok_or_else(|| {
                    self.tree
                        .error(loc, "<lookat>: origin and target are the same point")
                })?;
                let up = match point(self, "up")? {
                    Some(u) if u != DVec3::ZERO => u,
                    _ => dir.any_orthonormal_vector(),
                };
                let left = up.cross(dir).try_normalize().ok_or_else(|| {
                    self.tree
                        .error(loc, "<lookat>: 'up' is parallel to the viewing direction")
                })?;
                let new_up = dir.cross(left);
                DMat4::from_cols(
                    left.extend(0.0),
                    new_up.extend(0.0),
                    dir.extend(0.0),
                    DVec4::new(origin.x, origin.y, origin.z, 1.0),
                )
            }
            other => {
                return Err(self
                    .tree
                    .error(loc, format!("<{other}> inside a <transform>")))
            }
        };
        Ok(m)
    }
}
