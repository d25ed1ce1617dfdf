//! A render streamed to the tev image viewer as it converges, over tev's IPC protocol (TCP).
//!
//! Each packet is a little-endian `u32` length (counting itself), a `u8` type and the fields:
//! CreateImage (type 4): grab focus (`u8`), the image's name (NUL-terminated), width and
//! height (`i32`), the number of channels (`i32`) and their names (NUL-terminated);
//! UpdateImage (type 6): grab focus, name, the number of channels and their names, the
//! region's x, y, width and height (`i32`), per channel an offset and a stride (`i64`, in
//! floats, into the data) and the data (`f32`); CloseImage (type 2): the name.
//!
//! [`TevDisplay`] keeps its own copy of the film, adds each tile's samples to it as the render
//! reports them ([`TileDone`]) and, from a thread of its own, sends the tiles that changed a
//! few times a second, so the render never waits on the network.

use crate::film::{Film, PixelStats};
use crate::render::TileDone;
use std::io::Write;
use std::net::{TcpStream, ToSocketAddrs};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError, Sender};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Packet types of tev's protocol.
const CLOSE_IMAGE: u8 = 2;
const CREATE_IMAGE: u8 = 4;
const UPDATE_IMAGE: u8 = 6;

/// A packet under construction: the length is filled in by [`Packet::finish`].
struct Packet(Vec<u8>);

impl Packet {
    fn new(kind: u8) -> Self {
        let mut p = Packet(vec![0; 4]);
        p.0.push(kind);
        p
    }
    fn u8(&mut self, v: u8) -> &mut Self {
        self.0.push(v);
        self
    }
    fn i32(&mut self, v: i32) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn i64(&mut self, v: i64) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn string(&mut self, s: &str) -> &mut Self {
        self.0.extend(s.as_bytes());
        self.0.push(0);
        self
    }
    fn finish(&mut self) -> Vec<u8> {
        let len = self.0.len() as u32;
        self.0[..4].copy_from_slice(&len.to_le_bytes());
        std::mem::take(&mut self.0)
    }
}

/// The CreateImage packet of a `width` x `height` image with these channels.
pub fn create_image_packet(name: &str, width: u32, height: u32, channels: &[&str]) -> Vec<u8> {
    let mut p = Packet::new(CREATE_IMAGE);
    p.u8(0)
        .string(name)
        .i32(width as i32)
        .i32(height as i32)
        .i32(channels.len() as i32);
    for c in channels {
        p.string(c);
    }
    p.finish()
}

/// The UpdateImage packet of the region at (`x`, `y`), `width` x `height`: `planar` holds
/// each channel's values in turn, row-major.
pub fn update_image_packet(
    name: &str,
    channels: &[&str],
    [x, y, width, height]: [u32; 4],
    planar: &[f32],
) -> Vec<u8> {
    let n = width as i64 * height as i64;
    let mut p = Packet::new(UPDATE_IMAGE);
    p.u8(0).string(name).i32(channels.len() as i32);
    for c in channels {
        p.string(c);
    }
    p.i32(x as i32)
        .i32(y as i32)
        .i32(width as i32)
        .i32(height as i32);
    for k in 0..channels.len() as i64 {
        p.i64(k * n);
    }
    for _ in channels {
        p.i64(1);
    }
    p.0.reserve(planar.len() * 4);
    for v in planar {
        p.0.extend(v.to_le_bytes());
    }
    p.finish()
}

/// The CloseImage packet.
pub fn close_image_packet(name: &str) -> Vec<u8> {
    Packet::new(CLOSE_IMAGE).string(name).finish()
}

/// Which channels are streamed besides R, G, B: the variance of each pixel's mean
/// (`variance.R/G/B`) and its sample count (`samples.Y`), as in pathlab's EXR files.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Layers {
    /// `variance.R`, `variance.G`, `variance.B`.
    pub variance: bool,
    /// `samples.Y`.
    pub samples: bool,
}

impl Layers {
    fn channels(&self) -> Vec<&'static str> {
        let mut c = vec!["R", "G", "B"];
        if self.variance {
            c.extend(["variance.R", "variance.G", "variance.B"]);
        }
        if self.samples {
            c.push("samples.Y");
        }
        c
    }
}

/// The channels of `film`'s pixels in the region, planar (see [`update_image_packet`]): the
/// mean, the variance of the mean and the count, computed as [`Film::mean_image`],
/// [`Film::variance_image`] and [`Film::sample_counts`] compute them.
fn region_values(film: &Film, layers: Layers, [x0, y0, w, h]: [u32; 4]) -> Vec<f32> {
    let index = |x: u32, y: u32| (y * film.width() + x) as usize;
    let plane = |f: &dyn Fn(usize) -> f32| -> Vec<f32> {
        (y0..y0 + h)
            .flat_map(|y| (x0..x0 + w).map(move |x| (x, y)))
            .map(|(x, y)| f(index(x, y)))
            .collect()
    };
    let pixels = film.pixels();
    let mut out = Vec::new();
    for c in 0..3 {
        out.extend(plane(&|i| film.pixel_value(i).as_vec3()[c]));
    }
    if layers.variance {
        for c in 0..3 {
            out.extend(plane(&|i| pixels[i].variance_of_mean().as_vec3()[c]));
        }
    }
    if layers.samples {
        out.extend(plane(&|i| pixels[i].count() as f32));
    }
    out
}

enum Message {
    Tile {
        x0: u32,
        y0: u32,
        w: u32,
        pixels: Vec<PixelStats>,
    },
    Finish(Box<Film>),
}

/// The port tev listens on unless told otherwise.
pub const TEV_PORT: u16 = 14158;

/// Seconds between updates sent to tev.
const UPDATE_INTERVAL: Duration = Duration::from_millis(250);
/// Edge of the tiles the display tracks and sends (the render's own tile size).
const TILE: u32 = crate::render::TILE_SIZE;

/// A live view of a render in tev (see the module documentation).
pub struct TevDisplay {
    to_thread: Sender<Message>,
    thread: JoinHandle<Option<String>>,
}

impl TevDisplay {
    /// Connects to tev at `addr` (`HOST:PORT`, or `HOST` for tev's port 14158), creates the image
    /// `name` and shows `film` (the render's starting film) in it. An error is a sentence for
    /// a warning: nothing listening, or a refused connection.
    pub fn connect(addr: &str, name: &str, film: &Film, layers: Layers) -> Result<Self, String> {
        // A host alone means tev's own port.
        let with_port = if addr.contains(':') {
            addr.to_string()
        } else {
            format!("{addr}:{TEV_PORT}")
        };
        let target = with_port
            .to_socket_addrs()
            .map_err(|e| format!("--display {addr}: {e}; rendering without it"))?
            .next()
            .ok_or_else(|| format!("--display {addr}: no such address; rendering without it"))?;
        let stream = TcpStream::connect_timeout(&target, Duration::from_secs(1)).map_err(|e| {
            format!("--display {addr}: cannot reach tev ({e}); rendering without it")
        })?;
        let _ = stream.set_nodelay(true);
        let _ = stream.set_write_timeout(Some(Duration::from_secs(5)));
        let mut link = Link {
            stream,
            name: name.to_string(),
            channels: layers.channels(),
            layers,
        };
        let (w, h) = (film.width(), film.height());
        let packet = create_image_packet(name, w, h, &link.channels);
        link.stream
            .write_all(&packet)
            .and_then(|_| link.send_all(film))
            .map_err(|e| format!("--display {addr}: tev stopped listening ({e})"))?;
        let (to_thread, from_render) = channel();
        let mut shadow = film.clone();
        let addr = addr.to_string();
        let thread = std::thread::spawn(move || {
            run(&mut link, &mut shadow, &from_render).map(|e| {
                format!(
                    "--display {addr}: tev stopped listening ({e}); the render went on without it"
                )
            })
        });
        Ok(TevDisplay { to_thread, thread })
    }

    /// The render finished a tile: its samples are added to the display's film (cheap; called
    /// from the render's worker threads).
    pub fn tile(&self, t: &TileDone) {
        if !t.pixels.is_empty() {
            let _ = self.to_thread.send(Message::Tile {
                x0: t.x0,
                y0: t.y0,
                w: t.w,
                pixels: t.pixels.to_vec(),
            });
        }
    }

    /// The render is done: `film` (its final state) is sent whole, so that tev shows exactly
    /// the image written. A warning if tev stopped listening on the way.
    pub fn finish(self, film: &Film) -> Option<String> {
        let _ = self.to_thread.send(Message::Finish(Box::new(film.clone())));
        drop(self.to_thread);
        self.thread.join().unwrap_or(None)
    }
}

/// The connection to tev and what is sent over it.
struct Link {
    stream: TcpStream,
    name: String,
    channels: Vec<&'static str>,
    layers: Layers,
}

impl Link {
    /// Sends `film`'s pixels in `region` (`[x, y, width, height]`).
    fn send_region(&mut self, film: &Film, region: [u32; 4]) -> std::io::Result<()> {
        let values = region_values(film, self.layers, region);
        let packet = update_image_packet(&self.name, &self.channels, region, &values);
        self.stream.write_all(&packet)
    }

    /// Sends the whole film, in bands of rows so that no packet is large.
    fn send_all(&mut self, film: &Film) -> std::io::Result<()> {
        let (w, h) = (film.width(), film.height());
        let band = (65536 / w.max(1)).clamp(1, h.max(1));
        for y in (0..h).step_by(band as usize) {
            self.send_region(film, [0, y, w, band.min(h - y)])?;
        }
        Ok(())
    }
}

/// The display thread: tiles merged into `shadow` as they come, the changed ones sent every
/// [`UPDATE_INTERVAL`], the final film sent whole. The first write error (as text) ends the
/// sending; messages are still taken so that the render never blocks.
fn run(link: &mut Link, shadow: &mut Film, from_render: &Receiver<Message>) -> Option<String> {
    let (w, h) = (shadow.width(), shadow.height());
    let tiles_x = w.div_ceil(TILE);
    let mut dirty = vec![false; (tiles_x * h.div_ceil(TILE)) as usize];
    let mut failed: Option<String> = None;
    let mut last = Instant::now();
    loop {
        match from_render.recv_timeout(UPDATE_INTERVAL / 4) {
            // Once tev is gone nothing more is shown: the tiles are only taken.
            Ok(Message::Tile { .. }) if failed.is_some() => {}
            Ok(Message::Tile {
                x0,
                y0,
                w: tw,
                pixels,
            }) => {
                for (i, p) in pixels.iter().enumerate() {
                    let (x, y) = (x0 + i as u32 % tw, y0 + i as u32 / tw);
                    shadow.pixel_mut(x, y).merge(p);
                }
                dirty[((y0 / TILE) * tiles_x + x0 / TILE) as usize] = true;
            }
            Ok(Message::Finish(film)) => {
                if failed.is_none() {
                    failed = link.send_all(&film).err().map(|e| e.to_string());
                }
                return failed;
            }
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => return failed,
        }
        if failed.is_none() && last.elapsed() >= UPDATE_INTERVAL {
            last = Instant::now();
            for (k, d) in dirty.iter_mut().enumerate() {
                if !std::mem::take(d) {
                    continue;
                }
                let (x0, y0) = ((k as u32 % tiles_x) * TILE, (k as u32 / tiles_x) * TILE);
                let region = [x0, y0, TILE.min(w - x0), TILE.min(h - y0)];
                if let Err(e) = link.send_region(shadow, region) {
                    failed = Some(e.to_string());
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packets_follow_tevs_layout() {
        let p = create_image_packet("a", 3, 2, &["R", "G"]);
        let want: Vec<u8> = [
            &(p.len() as u32).to_le_bytes()[..],
            &[4, 0, b'a', 0],
            &3i32.to_le_bytes(),
            &2i32.to_le_bytes(),
            &2i32.to_le_bytes(),
            b"R\0G\0",
        ]
        .concat();
        assert_eq!(p, want);
        let u = update_image_packet("a", &["R"], [1, 0, 2, 1], &[0.5, 2.0]);
        let want: Vec<u8> = [
            &(u.len() as u32).to_le_bytes()[..],
            &[6, 0, b'a', 0],
            &1i32.to_le_bytes(),
            b"R\0",
            &1i32.to_le_bytes(),
            &0i32.to_le_bytes(),
            &2i32.to_le_bytes(),
            &1i32.to_le_bytes(),
            &0i64.to_le_bytes(),
            &1i64.to_le_bytes(),
            &0.5f32.to_le_bytes(),
            &2.0f32.to_le_bytes(),
        ]
        .concat();
        assert_eq!(u, want);
        let c = close_image_packet("ab");
        assert_eq!(c, [8, 0, 0, 0, 2, b'a', b'b', 0].to_vec());
        assert_eq!(
            u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as usize,
            c.len()
        );
    }
}
