//! COLLADA geometry: `<source>` arrays through their accessors, and the triangles of
//! `<triangles>`, `<polylist>` and `<polygons>` with any input offsets (polygons split into
//! fans).

use super::Loader;
use crate::xml::{child, children, path as xpath};
use crate::Error;
use glam::{Vec2, Vec3};
use roxmltree::Node;

impl<'a, 'input> Loader<'_, 'a, 'input> {
    /// Reads a `<source>`'s values (float_array via its accessor) as `stride`-tuples.
    pub(super) fn source(&self, source: Node<'a, 'input>, want: usize) -> Result<Vec<f32>, Error> {
        let array = child(source, "float_array")
            .ok_or_else(|| self.file.error(source, "expected a <float_array>"))?;
        let values = self.file.floats(array)?;
        if let Some(count) = array.attribute("count") {
            let count: usize = count.parse().map_err(|_| {
                self.file
                    .error(array, format!("count '{count}' is not a number"))
            })?;
            if count != values.len() {
                return Err(self.file.error(
                    array,
                    format!("count says {count} values but {} are given", values.len()),
                ));
            }
        }
        let accessor = xpath(source, &["technique_common", "accessor"]);
        let stride = match accessor.and_then(|a| a.attribute("stride")) {
            Some(s) => s
                .parse::<usize>()
                .ok()
                .filter(|&s| s >= want)
                .ok_or_else(|| {
                    self.file.error(
                        source,
                        format!("accessor stride '{s}' must be at least {want}"),
                    )
                })?,
            None => want,
        };
        Ok(values
            .chunks_exact(stride)
            .flat_map(|c| c[..want].to_vec())
            .collect())
    }

    /// The triangles of a `<triangles>`, `<polylist>` or `<polygons>` element, polygons split
    /// into fans.
    pub(super) fn primitive(&self, prim: Node<'a, 'input>) -> Result<Triangles, Error> {
        let Inputs {
            stride,
            pos,
            nor,
            tex,
        } = self.inputs(prim)?;
        let (positions, pos_offset) =
            pos.ok_or_else(|| self.file.error(prim, "expected a VERTEX input"))?;
        let stride = stride.max(1);
        let polygons = self.polygons(prim, stride)?;
        if let Some(count) = prim
            .attribute("count")
            .and_then(|c| c.parse::<usize>().ok())
        {
            if count != polygons.len() {
                return Err(self.file.error(
                    prim,
                    format!(
                        "count says {count} polygons but {} are given",
                        polygons.len()
                    ),
                ));
            }
        }
        let mut out = Triangles::default();
        let fetch =
            |list: &[u32], corner: usize, offset: usize| list[corner * stride + offset] as usize;
        for poly in &polygons {
            if poly.len() % stride != 0 {
                return Err(self.file.error(
                    prim,
                    "a polygon's index count is not a multiple of the input count",
                ));
            }
            let corners = poly.len() / stride;
            for k in 1..corners.saturating_sub(1) {
                for corner in [0, k, k + 1] {
                    let pi = fetch(poly, corner, pos_offset);
                    let p = *positions.get(pi).ok_or_else(|| {
                        self.file.error(
                            prim,
                            format!(
                                "position index {pi} out of range ({} positions)",
                                positions.len()
                            ),
                        )
                    })?;
                    out.positions.push(p);
                    if let Some((normals, off)) = &nor {
                        let ni = fetch(poly, corner, *off);
                        out.normals.push(*normals.get(ni).ok_or_else(|| {
                            self.file.error(
                                prim,
                                format!(
                                    "normal index {ni} out of range ({} normals)",
                                    normals.len()
                                ),
                            )
                        })?);
                    }
                    if let Some((uvs, off)) = &tex {
                        let ti = fetch(poly, corner, *off);
                        out.uvs.push(*uvs.get(ti).ok_or_else(|| {
                            self.file.error(
                                prim,
                                format!(
                                    "texture coordinate index {ti} out of range ({})",
                                    uvs.len()
                                ),
                            )
                        })?);
                    }
                }
            }
        }
        Ok(out)
    }

    /// A primitive's inputs (semantic, source, offset): its positions, normals and texture
    /// coordinates with their offsets in each corner's indices, and the number of indices per
    /// corner.
    fn inputs(&self, prim: Node<'a, 'input>) -> Result<Inputs, Error> {
        let mut stride = 0usize;
        let mut pos: Option<(Vec<Vec3>, usize)> = None;
        let mut nor: Option<(Vec<Vec3>, usize)> = None;
        let mut tex: Option<(Vec<Vec2>, usize)> = None;
        for input in children(prim, "input") {
            let offset: usize = input
                .attribute("offset")
                .unwrap_or("0")
                .parse()
                .map_err(|_| self.file.error(input, "offset is not a number"))?;
            if offset > 64 {
                return Err(self
                    .file
                    .error(input, format!("offset {offset} is implausibly large")));
            }
            stride = stride.max(offset + 1);
            let semantic = input.attribute("semantic").unwrap_or("");
            let src = self.lookup(input, input.attribute("source").unwrap_or(""))?;
            let vec3s = |v: Vec<f32>| v.chunks_exact(3).map(Vec3::from_slice).collect::<Vec<_>>();
            match semantic {
                "VERTEX" => {
                    let p = children(src, "input")
                        .find(|i| i.attribute("semantic") == Some("POSITION"))
                        .ok_or_else(|| self.file.error(src, "expected a POSITION input"))?;
                    let psrc = self.lookup(p, p.attribute("source").unwrap_or(""))?;
                    pos = Some((vec3s(self.source(psrc, 3)?), offset));
                    if let Some(n) =
                        children(src, "input").find(|i| i.attribute("semantic") == Some("NORMAL"))
                    {
                        let nsrc = self.lookup(n, n.attribute("source").unwrap_or(""))?;
                        nor = Some((vec3s(self.source(nsrc, 3)?), offset));
                    }
                }
                "POSITION" => pos = Some((vec3s(self.source(src, 3)?), offset)),
                "NORMAL" => nor = Some((vec3s(self.source(src, 3)?), offset)),
                "TEXCOORD" if tex.is_none() => {
                    let v = self.source(src, 2)?;
                    tex = Some((v.chunks_exact(2).map(Vec2::from_slice).collect(), offset));
                }
                _ => {}
            }
        }
        Ok(Inputs {
            stride,
            pos,
            nor,
            tex,
        })
    }

    /// A primitive's polygons, each the list of its corners' indices (`stride` per corner).
    fn polygons(&self, prim: Node<'a, 'input>, stride: usize) -> Result<Vec<Vec<u32>>, Error> {
        Ok(match prim.tag_name().name() {
            "polygons" => children(prim, "p")
                .map(|p| self.file.indices(p))
                .collect::<Result<_, _>>()?,
            kind => {
                let p = child(prim, "p")
                    .map(|p| self.file.indices(p))
                    .transpose()?
                    .unwrap_or_default();
                let counts: Vec<u32> = if kind == "polylist" {
                    child(prim, "vcount")
                        .map(|v| self.file.indices(v))
                        .transpose()?
                        .unwrap_or_default()
                } else {
                    vec![3; p.len() / (3 * stride)]
                };
                let mut out = Vec::with_capacity(counts.len().min(p.len()));
                let mut at = 0usize;
                for &c in &counts {
                    let len = c as usize * stride;
                    let Some(slice) = p.get(at..at + len) else {
                        return Err(self.file.error(
                            prim,
                            format!(
                                "<p> has {} indices but the polygon counts need more",
                                p.len()
                            ),
                        ));
                    };
                    out.push(slice.to_vec());
                    at += len;
                }
                out
            }
        })
    }
}

/// The inputs of a primitive: each source with its offset in a corner's indices, and the
/// number of indices per corner.
struct Inputs {
    stride: usize,
    pos: Option<(Vec<Vec3>, usize)>,
    nor: Option<(Vec<Vec3>, usize)>,
    tex: Option<(Vec<Vec2>, usize)>,
}

/// Triangles expanded per corner.
#[derive(Default)]
pub(super) struct Triangles {
    pub(super) positions: Vec<Vec3>,
    pub(super) normals: Vec<Vec3>,
    pub(super) uvs: Vec<Vec2>,
}
