//! Mitsuba's binary grid volume format (`.vol`), read for `sdfgrid` shapes: "VOL", version 3,
//! encoding (1: 32-bit floats), the resolution in x, y and z, the channel count and a
//! bounding box (six floats, unused by an SDF grid), then the samples, x fastest and the
//! channels of a sample together; all little-endian.

use crate::Error;
use std::path::Path;

/// Most samples accepted (4096 x 256 x 256: far above real grids; a corrupt header cannot
/// make the reader allocate the machine's memory).
const MAX_SAMPLES: u64 = 1 << 28;
/// Header bytes before the samples.
const HEADER: usize = 3 + 1 + 4 * 5 + 4 * 6;

/// A single-channel grid: its samples and resolution.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Samples, x fastest, then y, then z.
    pub values: Vec<f32>,
    /// Samples along x, y and z.
    pub resolution: [u32; 3],
}

/// Reads the single-channel grid in `path`.
pub fn load(path: &Path) -> Result<Grid, Error> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse(&bytes).map_err(|message| Error::Parse {
        path: path.display().to_string(),
        line: 0,
        column: 0,
        message,
    })
}

/// Parses a single-channel grid from a `.vol` file's bytes.
pub fn parse(bytes: &[u8]) -> Result<Grid, String> {
    if bytes.len() < 4 || &bytes[..3] != b"VOL" {
        return Err("not a Mitsuba grid volume (the file does not start with 'VOL')".into());
    }
    if bytes[3] != 3 {
        return Err(format!(
            "grid volume version {} is not supported (3)",
            bytes[3]
        ));
    }
    if bytes.len() < HEADER {
        return Err("the file ends inside the grid volume's header".into());
    }
    let int =
        |at: usize| i32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let encoding = int(4);
    if encoding != 1 {
        return Err(format!(
            "grid volume encoding {encoding} is not supported (1: 32-bit floats)"
        ));
    }
    let (nx, ny, nz, channels) = (int(8), int(12), int(16), int(20));
    if nx <= 0 || ny <= 0 || nz <= 0 {
        return Err(format!(
            "grid volume resolution {nx} x {ny} x {nz} is empty"
        ));
    }
    if channels != 1 {
        return Err(format!(
            "the grid has {channels} channels; an SDF grid needs 1"
        ));
    }
    let count = nx as u64 * ny as u64 * nz as u64;
    if count > MAX_SAMPLES {
        return Err(format!(
            "a grid of {nx} x {ny} x {nz} samples is more than pathlab reads"
        ));
    }
    let data = &bytes[HEADER..];
    if (data.len() as u64) < 4 * count {
        return Err(format!(
            "the grid volume ends early: {nx} x {ny} x {nz} samples need {} bytes, {} remain",
            4 * count,
            data.len()
        ));
    }
    let values: Vec<f32> = data[..4 * count as usize]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        let (x, y, z) = (
            i % nx as usize,
            (i / nx as usize) % ny as usize,
            i / (nx * ny) as usize,
        );
        return Err(format!(
            "grid sample ({x}, {y}, {z}) is not a finite number ({})",
            values[i]
        ));
    }
    Ok(Grid {
        values,
        resolution: [nx as u32, ny as u32, nz as u32],
    })
}

/// The bytes of a single-channel `.vol` file holding `values` at `resolution` (for tests and
/// tools that write grids).
pub fn write(values: &[f32], resolution: [u32; 3]) -> Vec<u8> {
    let mut out = b"VOL\x03".to_vec();
    for v in [
        1,
        resolution[0] as i32,
        resolution[1] as i32,
        resolution[2] as i32,
        1,
    ] {
        out.extend(v.to_le_bytes());
    }
    for v in [0.0f32, 0.0, 0.0, 1.0, 1.0, 1.0] {
        out.extend(v.to_le_bytes());
    }
    for v in values {
        out.extend(v.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_what_it_writes_and_rejects_damage() {
        let values: Vec<f32> = (0..24).map(|i| i as f32 - 12.0).collect();
        let bytes = write(&values, [2, 3, 4]);
        let g = parse(&bytes).unwrap();
        assert_eq!(g.resolution, [2, 3, 4]);
        assert_eq!(g.values, values);
        for cut in [0, 3, 10, HEADER, bytes.len() - 1] {
            assert!(parse(&bytes[..cut]).is_err(), "cut at {cut}");
        }
        let mut two_channels = bytes.clone();
        two_channels[20] = 2;
        assert!(parse(&two_channels).unwrap_err().contains("channels"));
        let mut huge = bytes.clone();
        huge[8..12].copy_from_slice(&i32::MAX.to_le_bytes());
        assert!(parse(&huge).is_err());
        let mut nan = bytes.clone();
        nan[HEADER + 8..HEADER + 12].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(parse(&nan).unwrap_err().contains("(0, 1, 0)"));
        let mut negative = bytes;
        negative[12..16].copy_from_slice(&(-3i32).to_le_bytes());
        assert!(parse(&negative).is_err());
    }
}
