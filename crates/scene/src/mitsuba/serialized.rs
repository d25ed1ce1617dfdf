//! Mitsuba's `.serialized` meshes: a little-endian header (format 0x041C, version 3 or 4)
//! followed by zlib streams, one per shape, each holding flags, (version 4) a name, the vertex
//! and triangle counts, positions, optional normals, texture coordinates and colours, and the
//! triangles; a file with several shapes ends with their offsets and count.

use crate::Error;
use flate2::read::ZlibDecoder;
use glam::{Vec2, Vec3};
use pathlab_render::desc::MeshDesc;
use std::io::Read;
use std::path::Path;

const FORMAT: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const SINGLE: u32 = 0x1000;
const DOUBLE: u32 = 0x2000;

/// Largest vertex or triangle count accepted (far above any real mesh; a corrupt count
/// cannot make the reader allocate the machine's memory).
const MAX_COUNT: u64 = 1 << 28;

/// Reads shape `index` of the file.
pub fn load(path: &Path, index: usize) -> Result<MeshDesc, Error> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse(&bytes, index).map_err(|message| Error::Parse {
        path: path.display().to_string(),
        line: 0,
        column: 0,
        message,
    })
}

/// Parses shape `index` of a `.serialized` file's bytes.
pub fn parse(bytes: &[u8], index: usize) -> Result<MeshDesc, String> {
    let header = |at: usize| -> Result<(u16, u16), String> {
        let b = bytes
            .get(at..at + 4)
            .ok_or("the file ends inside a shape header")?;
        Ok((
            u16::from_le_bytes([b[0], b[1]]),
            u16::from_le_bytes([b[2], b[3]]),
        ))
    };
    let (format, version) = header(0)?;
    if format != FORMAT {
        return Err(format!(
            "not a Mitsuba serialized mesh (format 0x{format:04X}, expected 0x041C)"
        ));
    }
    if !(3..=4).contains(&version) {
        return Err(format!(
            "serialized mesh version {version} is not supported (3 or 4)"
        ));
    }
    let offset = if index == 0 {
        0
    } else {
        shape_offset(bytes, index, version)?
    };
    let (f, v) = header(offset)?;
    if f != FORMAT || v != version {
        return Err(format!("shape {index}: no shape header at byte {offset}"));
    }
    let mut data = Vec::new();
    ZlibDecoder::new(&bytes[offset + 4..])
        .read_to_end(&mut data)
        .map_err(|e| format!("shape {index}: the compressed data is corrupt ({e})"))?;
    let mut r = Reader { data: &data, at: 0 };
    let flags = r.u32()?;
    let mut name = String::new();
    if version >= 4 {
        let mut raw = Vec::new();
        loop {
            match r.u8()? {
                0 => break,
                c => raw.push(c),
            }
        }
        name = String::from_utf8_lossy(&raw).into_owned();
    }
    let vertices = r.u64()?;
    let triangles = r.u64()?;
    if vertices > MAX_COUNT || triangles > MAX_COUNT {
        return Err(format!(
            "shape {index}: {vertices} vertices and {triangles} triangles is more than pathlab reads"
        ));
    }
    let double = match (flags & SINGLE != 0, flags & DOUBLE != 0) {
        (_, true) => true,
        (true, false) => false,
        (false, false) => false,
    };
    let n = vertices as usize;
    let read_vec3 = |r: &mut Reader| -> Result<Vec<Vec3>, String> {
        (0..n)
            .map(|_| Ok(Vec3::new(r.real(double)?, r.real(double)?, r.real(double)?)))
            .collect()
    };
    let positions = read_vec3(&mut r)?;
    let normals = if flags & HAS_NORMALS != 0 {
        read_vec3(&mut r)?
    } else {
        Vec::new()
    };
    let uvs = if flags & HAS_TEXCOORDS != 0 {
        (0..n)
            .map(|_| Ok(Vec2::new(r.real(double)?, r.real(double)?)))
            .collect::<Result<Vec<_>, String>>()?
    } else {
        Vec::new()
    };
    if flags & HAS_COLORS != 0 {
        read_vec3(&mut r)?;
    }
    let wide = vertices > u32::MAX as u64;
    // Reserve no more than the data left could hold: the declared count may be corrupt.
    let index_bytes = if wide { 8 } else { 4 };
    let mut indices = Vec::with_capacity((3 * triangles as usize).min(r.remaining() / index_bytes));
    for _ in 0..3 * triangles {
        let i = if wide { r.u64()? } else { r.u32()? as u64 };
        if i >= vertices {
            return Err(format!(
                "shape {index}: triangle index {i} out of range ({vertices} vertices)"
            ));
        }
        indices.push(i as u32);
    }
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(format!(
            "shape {index}: a vertex position is not a finite number"
        ));
    }
    Ok(MeshDesc {
        name,
        positions,
        indices,
        normals: if flags & FACE_NORMALS != 0 {
            Vec::new()
        } else {
            normals
        },
        // Mitsuba stores (u, v) with v growing downwards; pathlab's grows upwards.
        uvs: uvs
            .into_iter()
            .map(|uv| Vec2::new(uv.x, 1.0 - uv.y))
            .collect(),
        ..Default::default()
    })
}

/// The byte offset of shape `index`, from the dictionary at the end of the file.
fn shape_offset(bytes: &[u8], index: usize, version: u16) -> Result<usize, String> {
    let len = bytes.len();
    let count = bytes
        .get(len.saturating_sub(4)..)
        .filter(|b| b.len() == 4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
        .ok_or("the file is too short for a shape dictionary")?;
    if index >= count {
        return Err(format!(
            "shape_index {index}: the file holds {count} shapes"
        ));
    }
    let width = if version >= 4 { 8 } else { 4 };
    let table = len
        .checked_sub(4 + count * width)
        .ok_or("the shape dictionary is corrupt")?;
    let at = table + index * width;
    let b = &bytes[at..at + width];
    let offset = if width == 8 {
        u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]) as usize
    } else {
        u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize
    };
    if offset + 4 > len {
        return Err(format!(
            "shape {index}: offset {offset} is past the end of the file"
        ));
    }
    Ok(offset)
}

struct Reader<'a> {
    data: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn remaining(&self) -> usize {
        self.data.len() - self.at
    }
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let s = self
            .data
            .get(self.at..self.at + n)
            .ok_or("the mesh data ends early (truncated or corrupt)")?;
        self.at += n;
        Ok(s)
    }
    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn u64(&mut self) -> Result<u64, String> {
        let b = self.take(8)?;
        Ok(u64::from_le_bytes([
            b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7],
        ]))
    }
    fn real(&mut self, double: bool) -> Result<f32, String> {
        if double {
            let b = self.take(8)?;
            Ok(f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]) as f32)
        } else {
            let b = self.take(4)?;
            Ok(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A version-4 file of one shape, built here: flags, name, counts, arrays.
    fn file(flags: u32, positions: &[[f32; 3]], uvs: &[[f32; 2]], tris: &[u32]) -> Vec<u8> {
        let mut body = Vec::new();
        body.extend(flags.to_le_bytes());
        body.extend(b"quad\0");
        body.extend((positions.len() as u64).to_le_bytes());
        body.extend(((tris.len() / 3) as u64).to_le_bytes());
        for p in positions {
            for c in p {
                body.extend(c.to_le_bytes());
            }
        }
        for uv in uvs {
            for c in uv {
                body.extend(c.to_le_bytes());
            }
        }
        for i in tris {
            body.extend(i.to_le_bytes());
        }
        let mut out = vec![0x1C, 0x04, 0x04, 0x00];
        let mut enc = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        std::io::Write::write_all(&mut enc, &body).unwrap();
        out.extend(enc.finish().unwrap());
        out
    }

    #[test]
    fn reads_positions_uvs_and_triangles() {
        let bytes = file(
            HAS_TEXCOORDS | SINGLE,
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            &[0, 1, 2],
        );
        let m = parse(&bytes, 0).unwrap();
        assert_eq!(m.name, "quad");
        assert_eq!(m.positions[1], Vec3::X);
        assert_eq!(m.indices, vec![0, 1, 2]);
        assert_eq!(m.uvs[2], Vec2::new(0.0, 0.0));
        assert_eq!(m.uvs[0], Vec2::new(0.0, 1.0));
    }

    #[test]
    fn truncated_or_corrupt_files_are_errors() {
        let bytes = file(SINGLE, &[[0.0; 3]; 3], &[], &[0, 1, 2]);
        for cut in [0, 2, 5, 10, bytes.len() - 3] {
            assert!(parse(&bytes[..cut], 0).is_err(), "cut at {cut}");
        }
        let mut bad = bytes.clone();
        bad[0] = 0;
        assert!(parse(&bad, 0).unwrap_err().contains("format"));
        let out_of_range = file(SINGLE, &[[0.0; 3]; 3], &[], &[0, 1, 7]);
        assert!(parse(&out_of_range, 0)
            .unwrap_err()
            .contains("out of range"));
        assert!(parse(&bytes, 1).is_err());
    }
}
