//! A film's exact state in a file: the checkpoints of a render, and the parts of a render
//! split over machines (shards).
//!
//! Layout (little-endian): the magic `PLFILM01`; a u32 length and that many bytes of header,
//! `key=value` lines ([`FilmHeader`]); a u64 pixel count (width × height); each pixel's
//! [`PixelStats::to_bytes`]; for a film with light traced to the lens (the bidirectional path
//! tracer's splats), a u64 count of light paths and each pixel's three i128 splat sums; a u64
//! FNV-1a hash of everything before it. Files are written to
//! a temporary name and renamed, so a file is either whole or absent; reading checks the
//! sizes against the file's length before allocating, and the hash.

use crate::film::{Film, PixelStats, PIXEL_BYTES};
use std::io::Write;
use std::path::Path;

/// The file's first bytes.
pub const MAGIC: &[u8; 8] = b"PLFILM01";

/// Longest header read.
const MAX_HEADER: usize = 1 << 20;

/// Bytes of one pixel's splat sums (three `i128`), after the pixels in films with light traced
/// to the lens.
const SPLAT_BYTES: usize = 3 * 16;

/// What a film file says about the render it belongs to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FilmHeader {
    /// Width and height in pixels.
    pub resolution: [u32; 2],
    /// Identifies the scene and every setting that changes the image (a hash, compared
    /// as it is).
    pub key: String,
    /// The same in words, for messages.
    pub description: String,
    /// The render's seed.
    pub seed: u64,
    /// Samples per pixel of the whole render.
    pub spp: u32,
    /// The sample indices `[start, end)` this film covers when whole.
    pub range: [u32; 2],
    /// The program that wrote it.
    pub writer: String,
}

/// Why a film file cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum FilmFileError {
    /// The file could not be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What failed.
        message: String,
    },
    /// The file is not a whole film file.
    #[error("{path}: not a pathlab film file: {message}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
}

/// 64-bit FNV-1a.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    fnv1a_more(FNV_OFFSET, bytes)
}

/// FNV-1a's starting value.
const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a of what hashed to `h` followed by `bytes`: `fnv1a(a ++ b) == fnv1a_more(fnv1a(a), b)`.
fn fnv1a_more(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// A file written through a buffer of bounded size, hashing what passes through it.
struct HashedFile {
    file: std::fs::File,
    buf: Vec<u8>,
    hash: u64,
}

impl HashedFile {
    /// Bytes gathered before they are hashed and written.
    const CHUNK: usize = 1 << 16;

    /// Hashes and writes what the buffer holds once it is a chunk or more.
    fn maybe_flush(&mut self) -> std::io::Result<()> {
        if self.buf.len() >= Self::CHUNK {
            self.flush()?;
        }
        Ok(())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.hash = fnv1a_more(self.hash, &self.buf);
        self.file.write_all(&self.buf)?;
        self.buf.clear();
        Ok(())
    }
}

impl FilmHeader {
    fn to_text(&self) -> String {
        let one_line = |s: &str| s.replace(['\n', '\r'], " ");
        format!(
            "resolution={} {}\nkey={}\ndescription={}\nseed={}\nspp={}\nrange={} {}\nwriter={}\n",
            self.resolution[0],
            self.resolution[1],
            one_line(&self.key),
            one_line(&self.description),
            self.seed,
            self.spp,
            self.range[0],
            self.range[1],
            one_line(&self.writer)
        )
    }

    fn from_text(text: &str) -> Result<FilmHeader, String> {
        let get = |k: &str| -> Result<&str, String> {
            text.lines()
                .find_map(|l| l.strip_prefix(k).and_then(|r| r.strip_prefix('=')))
                .ok_or_else(|| format!("the header has no '{k}'"))
        };
        let pair = |k: &str| -> Result<[u32; 2], String> {
            let v = get(k)?;
            let mut it = v.split_whitespace().map(str::parse::<u32>);
            match (it.next(), it.next(), it.next()) {
                (Some(Ok(a)), Some(Ok(b)), None) => Ok([a, b]),
                _ => Err(format!("'{k}={v}' is not two numbers")),
            }
        };
        let number = |k: &str| -> Result<u64, String> {
            let v = get(k)?;
            v.parse().map_err(|_| format!("'{k}={v}' is not a number"))
        };
        Ok(FilmHeader {
            resolution: pair("resolution")?,
            key: get("key")?.to_string(),
            description: get("description")?.to_string(),
            seed: number("seed")?,
            spp: u32::try_from(number("spp")?).map_err(|_| "spp out of range".to_string())?,
            range: pair("range")?,
            writer: get("writer")?.to_string(),
        })
    }
}

/// Writes `film` with `header` to `path` atomically (a temporary file renamed into place).
pub fn write(path: &Path, header: &FilmHeader, film: &Film) -> Result<(), FilmFileError> {
    let io = |e: std::io::Error| FilmFileError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let text = header.to_text();
    let mut tmp_name = path.as_os_str().to_owned();
    tmp_name.push(".tmp");
    let tmp = std::path::PathBuf::from(tmp_name);
    // Written a chunk at a time (a film's bytes are as large as the film), hashed on the way.
    let mut out = HashedFile {
        file: std::fs::File::create(&tmp).map_err(io)?,
        buf: Vec::with_capacity(HashedFile::CHUNK + PIXEL_BYTES),
        hash: FNV_OFFSET,
    };
    out.buf.extend(MAGIC);
    out.buf.extend((text.len() as u32).to_le_bytes());
    out.buf.extend(text.as_bytes());
    out.buf.extend((film.pixels().len() as u64).to_le_bytes());
    for p in film.pixels() {
        p.to_bytes(&mut out.buf);
        out.maybe_flush().map_err(io)?;
    }
    // Light traced to the lens, when there is any: the light paths, then each pixel's sums.
    if film.light_paths() > 0 {
        out.buf.extend(film.light_paths().to_le_bytes());
        let zero = [[0i128; 3]];
        let sums = film.splat_sums();
        for s in (0..film.pixels().len()).map(|i| sums.get(i).unwrap_or(&zero[0])) {
            for v in s {
                out.buf.extend(v.to_le_bytes());
            }
            out.maybe_flush().map_err(io)?;
        }
    }
    out.flush().map_err(io)?;
    out.file.write_all(&out.hash.to_le_bytes()).map_err(io)?;
    out.file.sync_all().map_err(io)?;
    drop(out);
    std::fs::rename(&tmp, path).map_err(io)
}

/// Reads a film file (a chunk at a time: it holds the film, not a copy of the file besides).
pub fn read(path: &Path) -> Result<(FilmHeader, Film), FilmFileError> {
    let io = |e: std::io::Error| FilmFileError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    parse_from(std::io::BufReader::new(file), len).map_err(|e| match e {
        Parse::Io(e) => io(e),
        Parse::Invalid(message) => FilmFileError::Invalid {
            path: path.display().to_string(),
            message,
        },
    })
}

/// [`read`] from bytes.
pub fn parse(bytes: &[u8]) -> Result<(FilmHeader, Film), String> {
    parse_from(bytes, bytes.len() as u64).map_err(|e| match e {
        Parse::Io(_) => "truncated".to_string(),
        Parse::Invalid(message) => message,
    })
}

/// Why a film could not be read: the source failed, or its contents are not a film.
enum Parse {
    Io(std::io::Error),
    Invalid(String),
}

impl From<String> for Parse {
    fn from(message: String) -> Parse {
        Parse::Invalid(message)
    }
}

impl From<&str> for Parse {
    fn from(message: &str) -> Parse {
        Parse::Invalid(message.to_string())
    }
}

/// What a film file holds, read from `source` of `len` bytes a record at a time, hashed on the
/// way; the film is returned only if the hash at the end matches.
fn parse_from(mut source: impl std::io::Read, len: u64) -> Result<(FilmHeader, Film), Parse> {
    let mut hash = FNV_OFFSET;
    // Reads exactly `n` bytes into `buf` and hashes them; a short source is "truncated".
    let mut take = |buf: &mut Vec<u8>, n: usize, hash: &mut u64| -> Result<(), Parse> {
        buf.resize(n, 0);
        source.read_exact(buf).map_err(|e| match e.kind() {
            std::io::ErrorKind::UnexpectedEof => Parse::Invalid("truncated".into()),
            _ => Parse::Io(e),
        })?;
        *hash = fnv1a_more(*hash, buf);
        Ok(())
    };
    let mut buf = Vec::new();
    if len < 12 {
        return Err("wrong magic (expected PLFILM01)".into());
    }
    take(&mut buf, 12, &mut hash)?;
    if &buf[..8] != MAGIC {
        return Err("wrong magic (expected PLFILM01)".into());
    }
    let header_len = u32::from_le_bytes([buf[8], buf[9], buf[10], buf[11]]) as usize;
    if header_len > MAX_HEADER {
        return Err(format!("a header of {header_len} bytes").into());
    }
    if len < 12 + header_len as u64 {
        return Err("truncated in its header".into());
    }
    take(&mut buf, header_len, &mut hash)?;
    let text = std::str::from_utf8(&buf).map_err(|_| "a header that is not text")?;
    let header = FilmHeader::from_text(text)?;
    take(&mut buf, 8, &mut hash)?;
    let count = u64::from_le_bytes(buf[..8].try_into().map_err(|_| "truncated")?);
    let [w, h] = header.resolution;
    if count != w as u64 * h as u64 || w == 0 || h == 0 {
        return Err(format!("{count} pixels for a {w} x {h} image").into());
    }
    let body = 12 + header_len as u64 + 8;
    let pixels_end = count
        .checked_mul(PIXEL_BYTES as u64)
        .and_then(|n| n.checked_add(body))
        .ok_or("sizes out of range")?;
    let splat_bytes = count
        .checked_mul(SPLAT_BYTES as u64)
        .and_then(|n| n.checked_add(8))
        .ok_or("sizes out of range")?;
    // With or without the light traced to the lens.
    let splats = len == pixels_end + splat_bytes + 8;
    let expected = pixels_end + if splats { splat_bytes } else { 0 } + 8;
    if len != expected {
        return Err(
            format!("{len} bytes where its sizes say {expected} (truncated or padded)").into(),
        );
    }
    if header.range[0] > header.range[1] || header.range[1] > header.spp {
        return Err(format!(
            "sample range {}..{} outside 0..{}",
            header.range[0], header.range[1], header.spp
        )
        .into());
    }
    let mut film = Film::try_new(w, h)?;
    // Pixel records a chunk at a time.
    let per_chunk = (HashedFile::CHUNK / PIXEL_BYTES).max(1);
    for pixels in film.pixels_mut().chunks_mut(per_chunk) {
        take(&mut buf, pixels.len() * PIXEL_BYTES, &mut hash)?;
        for (p, record) in pixels.iter_mut().zip(buf.chunks_exact(PIXEL_BYTES)) {
            *p = PixelStats::from_bytes(record).ok_or("a pixel record of the wrong size")?;
        }
    }
    if splats {
        take(&mut buf, 8, &mut hash)?;
        let light_paths = u64::from_le_bytes(buf[..8].try_into().map_err(|_| "truncated")?);
        let mut sums = Vec::with_capacity(count as usize);
        let per_chunk = (HashedFile::CHUNK / SPLAT_BYTES).max(1) as u64;
        let mut left = count;
        while left > 0 {
            let n = left.min(per_chunk);
            take(&mut buf, n as usize * SPLAT_BYTES, &mut hash)?;
            sums.extend(buf.chunks_exact(SPLAT_BYTES).map(|c| {
                let v = |k: usize| {
                    let mut b = [0u8; 16];
                    b.copy_from_slice(&c[16 * k..16 * k + 16]);
                    i128::from_le_bytes(b)
                };
                [v(0), v(1), v(2)]
            }));
            left -= n;
        }
        film.set_splats(sums, light_paths);
    }
    let computed = hash;
    take(&mut buf, 8, &mut hash)?;
    let stored = u64::from_le_bytes(buf[..8].try_into().map_err(|_| "truncated")?);
    if computed != stored {
        return Err("its contents do not match its checksum (corrupt)".into());
    }
    Ok((header, film))
}

/// Adds the films of a render's shards into the film of the whole render, after checking that
/// they are parts of one render (same key, resolution, seed and samples per pixel), each whole
/// (every pixel holds its range's samples) and that their sample ranges cover `[0, spp)` once.
/// `parts` are (name for messages, header, film). The sums are exact, so the result is the
/// single render's film to the bit; its header is the first part's with the whole range. An
/// error says which part differs, which is incomplete, and which samples are missing or
/// covered twice. [`Merge`] does the same a part at a time.
pub fn merge(
    parts: impl IntoIterator<Item = (String, FilmHeader, Film)>,
) -> Result<(FilmHeader, Film), String> {
    let mut merged = Merge::default();
    for (name, header, film) in parts {
        merged.add(name, header, film)?;
    }
    merged.finish()
}

/// [`merge`] one part at a time, so that a merge holds the sum and the part being added, not
/// every part at once: [`Merge::add`] each part as it is read, then [`Merge::finish`] for the
/// whole render's film.
#[derive(Default)]
pub struct Merge {
    /// The first part's name and header, and the sum of the parts so far.
    sum: Option<(String, FilmHeader, Film)>,
    /// Each part's sample range and name.
    ranges: Vec<(u32, u32, String)>,
}

impl Merge {
    /// Adds a part, checked whole and (after the first) of the same render as the first.
    pub fn add(&mut self, name: String, h: FilmHeader, film: Film) -> Result<(), String> {
        if let Some((first_name, first, _)) = &self.sum {
            if h.key != first.key
                || h.resolution != first.resolution
                || h.seed != first.seed
                || h.spp != first.spp
            {
                return Err(format!(
                    "{name}: not a part of the same render as {first_name} ({} vs {})",
                    h.description, first.description
                ));
            }
        }
        check_whole(&name, &h, &film)?;
        self.ranges.push((h.range[0], h.range[1], name.clone()));
        match &mut self.sum {
            None => self.sum = Some((name, h, film)),
            Some((_, _, sum)) => {
                for (a, b) in sum.pixels_mut().iter_mut().zip(film.pixels()) {
                    a.merge(b);
                }
                sum.merge_splats(&film);
            }
        }
        Ok(())
    }

    /// The whole render's header and film, once the parts' ranges are checked to cover its
    /// samples once.
    pub fn finish(mut self) -> Result<(FilmHeader, Film), String> {
        let Some((_, first, film)) = self.sum else {
            return Err("no parts to merge".to_string());
        };
        self.ranges.sort();
        let mut problems = Vec::new();
        let (mut at, mut last) = (0u32, "");
        for (a, b, name) in &self.ranges {
            let (a, b) = (*a, *b);
            if a > at {
                problems.push(format!("samples {at}..{a} are missing"));
            } else if a < at {
                problems.push(format!(
                    "{name} overlaps {last} (samples {a}..{})",
                    at.min(b)
                ));
            }
            at = at.max(b);
            last = name;
        }
        let spp = first.spp;
        if at < spp {
            problems.push(format!("samples {at}..{spp} are missing"));
        }
        if !problems.is_empty() {
            return Err(format!(
                "the parts do not cover the render's {spp} samples once: {}",
                problems.join("; ")
            ));
        }
        let mut header = first;
        header.range = [0, spp];
        Ok((header, film))
    }
}

/// An error unless every pixel of a part holds its range's samples.
fn check_whole(name: &str, h: &FilmHeader, film: &Film) -> Result<(), String> {
    let want = (h.range[1] - h.range[0]) as u64;
    match film.pixels().iter().find(|px| px.count() != want) {
        Some(px) => Err(format!(
            "{name}: incomplete (a pixel holds {} of its {want} samples); render it again",
            px.count()
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> FilmHeader {
        FilmHeader {
            resolution: [3, 2],
            key: "abc".into(),
            description: "a test".into(),
            seed: 7,
            spp: 16,
            range: [0, 16],
            writer: "test".into(),
        }
    }

    #[test]
    fn films_round_trip_exactly_and_corruption_is_an_error() {
        let mut film = Film::new(3, 2);
        for (i, p) in film.pixels_mut().iter_mut().enumerate() {
            for k in 0..=i {
                p.add(glam::Vec3::new(0.1 * k as f32, 1e-7, 3e5));
            }
        }
        let dir = std::env::temp_dir().join(format!("pathlab-film-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("f.plf");
        write(&path, &header(), &film).unwrap();
        let (h, back) = read(&path).unwrap();
        assert_eq!(h, header());
        assert_eq!(back, film);
        let bytes = std::fs::read(&path).unwrap();
        for cut in [0, 5, 12, 40, bytes.len() - 1] {
            assert!(parse(&bytes[..cut]).is_err(), "cut {cut}");
        }
        for flip in [0, 9, 20, bytes.len() / 2, bytes.len() - 3] {
            let mut b = bytes.clone();
            b[flip] ^= 0x10;
            assert!(parse(&b).is_err(), "flip {flip}");
        }
        // The same from a file, read a chunk at a time.
        let bad = dir.join("bad.plf");
        let mut b = bytes.clone();
        b[bytes.len() / 2] ^= 0x10;
        std::fs::write(&bad, &b).unwrap();
        assert!(matches!(read(&bad), Err(FilmFileError::Invalid { .. })));
        std::fs::write(&bad, &bytes[..bytes.len() - 1]).unwrap();
        assert!(matches!(read(&bad), Err(FilmFileError::Invalid { .. })));
        // A huge declared header or pixel count is refused before any allocation.
        let mut b = bytes.clone();
        b[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(parse(&b).unwrap_err().contains("header of"));
        let _ = std::fs::remove_dir_all(dir);
    }

    /// A part of [`header`]'s render holding samples `range` of every pixel (values that
    /// differ by pixel and sample).
    fn part(range: [u32; 2]) -> (FilmHeader, Film) {
        let mut film = Film::new(3, 2);
        for (i, p) in film.pixels_mut().iter_mut().enumerate() {
            for k in range[0]..range[1] {
                p.add(glam::Vec3::new(0.1 * k as f32, i as f32, 1.0));
            }
        }
        let h = FilmHeader { range, ..header() };
        (h, film)
    }

    #[test]
    fn merging_a_part_at_a_time_checks_each_part_and_gives_the_whole_render() {
        let named = |name: &str, range| {
            let (h, f) = part(range);
            (name.to_string(), h, f)
        };
        let (whole_header, whole) = part([0, 16]);
        let (h, merged) = merge([
            named("a", [0, 5]),
            named("b", [5, 12]),
            named("c", [12, 16]),
        ])
        .unwrap();
        assert_eq!((h, merged), (whole_header.clone(), whole.clone()));
        // In any order.
        let (_, merged) = merge([
            named("c", [12, 16]),
            named("a", [0, 5]),
            named("b", [5, 12]),
        ])
        .unwrap();
        assert_eq!(merged, whole);
        // A part missing, twice, of another render, or not whole.
        let e = merge([named("a", [0, 5]), named("c", [12, 16])]).unwrap_err();
        assert!(e.contains("samples 5..12 are missing"), "{e}");
        let e = merge([named("a", [0, 12]), named("b", [5, 16])]).unwrap_err();
        assert!(e.contains("b overlaps a (samples 5..12)"), "{e}");
        let (mut other, f) = part([5, 16]);
        other.seed += 1;
        let e = merge([named("a", [0, 5]), ("o".to_string(), other, f)]).unwrap_err();
        assert!(e.contains("o: not a part of the same render as a"), "{e}");
        let (h, mut f) = part([5, 16]);
        f.pixels_mut()[4] = crate::film::PixelStats::default();
        let e = merge([named("a", [0, 5]), ("short".to_string(), h, f)]).unwrap_err();
        assert!(
            e.contains("short: incomplete (a pixel holds 0 of its 11 samples)"),
            "{e}"
        );
        assert!(merge(std::iter::empty()).unwrap_err().contains("no parts"));
    }
}
