//! A direct reader for the binary PLY files meshes mostly come as: vertices of scalar
//! positions (with optional normals and texture coordinates) and faces of one index list.
//! It decodes straight into the mesh's arrays, where the general reader (`ply-rs-bw`) builds
//! a map per element first; files with anything else (ASCII, attributes pathlab keeps, lists
//! in other elements) are left to the general reader, which gives the same mesh.

use glam::{Vec2, Vec3};

/// A scalar type of the PLY format, by size and kind.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// The value at the start of `b` (at least `size` bytes).
    #[inline]
    fn read(self, b: &[u8], little: bool) -> f64 {
        macro_rules! get {
            ($t:ty, $n:expr) => {{
                let a: [u8; $n] = b[..$n].try_into().unwrap_or([0; $n]);
                if little {
                    <$t>::from_le_bytes(a) as f64
                } else {
                    <$t>::from_be_bytes(a) as f64
                }
            }};
        }
        match self {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => get!(i16, 2),
            Scalar::U16 => get!(u16, 2),
            Scalar::I32 => get!(i32, 4),
            Scalar::U32 => get!(u32, 4),
            Scalar::F32 => get!(f32, 4),
            Scalar::F64 => get!(f64, 8),
        }
    }
}

/// An element of the header: its name, count, scalar properties and index list (count and
/// item types).
type Element = (String, u64, Vec<(String, Scalar)>, Option<(Scalar, Scalar)>);

/// A decoded mesh: positions, indices (triangulated as fans), normals and uvs (empty when
/// absent).
pub(crate) struct BinaryMesh {
    pub positions: Vec<Vec3>,
    pub indices: Vec<u32>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
}

/// Reads `bytes` when they are a binary PLY of the simple kind: `None` when they are not
/// (the general reader takes them), `Some(Err)` for a file of that kind that is broken.
pub(crate) fn read(bytes: &[u8]) -> Option<Result<BinaryMesh, String>> {
    let end = find(bytes, b"end_header")?;
    let header = std::str::from_utf8(&bytes[..end]).ok()?;
    let mut body = end + b"end_header".len();
    // The header ends with its line break (\n or \r\n).
    if bytes.get(body) == Some(&b'\r') {
        body += 1;
    }
    if bytes.get(body) != Some(&b'\n') {
        return None;
    }
    body += 1;
    let mut lines = header.lines();
    if lines.next()?.trim() != "ply" {
        return None;
    }
    let mut little = None;
    // (name, count, scalar properties, list property)
    let mut elements: Vec<Element> = Vec::new();
    for line in lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", "binary_little_endian", _] => little = Some(true),
            ["format", "binary_big_endian", _] => little = Some(false),
            ["format", ..] => return None,
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", name, count] => {
                elements.push((name.to_string(), count.parse().ok()?, Vec::new(), None))
            }
            ["property", "list", count, item, name] => {
                let e = elements.last_mut()?;
                if e.3.is_some()
                    || !matches!(*name, "vertex_indices" | "vertex_index")
                    || e.0 != "face"
                {
                    return None;
                }
                e.3 = Some((Scalar::parse(count)?, Scalar::parse(item)?));
            }
            ["property", ty, name] => {
                let e = elements.last_mut()?;
                if e.3.is_some() {
                    return None; // a scalar after the list: not this reader's layout
                }
                e.2.push((name.to_string(), Scalar::parse(ty)?));
            }
            _ => return None,
        }
    }
    let little = little?;
    // Faces after the vertices they index.
    let order: Vec<&str> = elements.iter().map(|e| e.0.as_str()).collect();
    if order.iter().position(|&n| n == "face") < order.iter().position(|&n| n == "vertex") {
        return None;
    }
    // Only vertex and face elements, with nothing the general reader would keep.
    for (name, _, props, list) in &elements {
        match name.as_str() {
            "vertex"
                if list.is_none()
                    && props
                        .iter()
                        .all(|(n, _)| crate::meshfile::PLY_GEOMETRY.contains(&n.as_str())) => {}
            "face" if list.is_some() && props.is_empty() => {}
            _ => return None,
        }
    }
    Some(decode(&bytes[body..], little, &elements))
}

fn decode(data: &[u8], little: bool, elements: &[Element]) -> Result<BinaryMesh, String> {
    let mut at = 0usize;
    let mut mesh = BinaryMesh {
        positions: Vec::new(),
        indices: Vec::new(),
        normals: Vec::new(),
        uvs: Vec::new(),
    };
    let mut vertex_count = 0usize;
    for (name, count, props, list) in elements {
        if name == "vertex" {
            let stride: usize = props.iter().map(|(_, s)| s.size()).sum();
            let n = *count as usize;
            if (n as u64) != *count || n.checked_mul(stride).is_none_or(|b| b > data.len() - at) {
                return Err(format!(
                    "the header declares {count} vertices, more than the file holds"
                ));
            }
            let offset = |key: &str| {
                let mut o = 0;
                for (k, s) in props {
                    if k == key {
                        return Some((o, *s));
                    }
                    o += s.size();
                }
                None
            };
            let (Some(x), Some(y), Some(z)) = (offset("x"), offset("y"), offset("z")) else {
                return Err("the vertices lack x, y or z".into());
            };
            let normal = offset("nx").zip(offset("ny")).zip(offset("nz"));
            let uv = crate::meshfile::PLY_UV_NAMES
                .iter()
                .find_map(|(a, b)| offset(a).zip(offset(b)));
            mesh.positions.reserve_exact(n);
            if normal.is_some() {
                mesh.normals.reserve_exact(n);
            }
            if uv.is_some() {
                mesh.uvs.reserve_exact(n);
            }
            for i in 0..n {
                let row = &data[at + i * stride..at + (i + 1) * stride];
                let get = |(o, s): (usize, Scalar)| s.read(&row[o..], little) as f32;
                let p = Vec3::new(get(x), get(y), get(z));
                if !p.is_finite() {
                    return Err(format!(
                        "vertex {i} has a coordinate that is not a finite number: {p}"
                    ));
                }
                mesh.positions.push(p);
                if let Some(((a, b), c)) = normal {
                    mesh.normals.push(Vec3::new(get(a), get(b), get(c)));
                }
                if let Some((a, b)) = uv {
                    mesh.uvs.push(Vec2::new(get(a), get(b)));
                }
            }
            at += n * stride;
            vertex_count = n;
        } else {
            let Some((count_ty, item_ty)) = list else {
                return Err("an element without an index list".into());
            };
            // At least one byte per face: a count that cannot fit is refused before reserving.
            if *count > (data.len() - at) as u64 {
                return Err(format!(
                    "the header declares {count} faces, more than the file holds"
                ));
            }
            mesh.indices.reserve((*count as usize).saturating_mul(3));
            for f in 0..*count {
                let Some(b) = data.get(at..at + count_ty.size()) else {
                    return Err(format!("the file ends in face {f}"));
                };
                let k = count_ty.read(b, little);
                at += count_ty.size();
                if !(0.0..=1e6).contains(&k) {
                    return Err(format!("face {f} has {k} vertices"));
                }
                let k = k as usize;
                let size = item_ty.size();
                let Some(items) = data.get(at..at + k * size) else {
                    return Err(format!("the file ends in face {f}"));
                };
                at += k * size;
                let index = |j: usize| -> Result<u32, String> {
                    let v = item_ty.read(&items[j * size..], little);
                    if v < 0.0 || v >= vertex_count as f64 {
                        Err(format!(
                            "face {f}: vertex index {v} out of range ({vertex_count} vertices)"
                        ))
                    } else {
                        Ok(v as u32)
                    }
                };
                for j in 1..k.saturating_sub(1) {
                    mesh.indices.extend([index(0)?, index(j)?, index(j + 1)?]);
                }
            }
        }
    }
    Ok(mesh)
}

/// The position of `needle` in `hay` (within its first 64 KiB: a PLY header is short).
fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    let hay = &hay[..hay.len().min(1 << 16)];
    hay.windows(needle.len()).position(|w| w == needle)
}
