//! End-to-end test of `render --display`: a listener in the test decodes the tev packets.

mod common;

use common::*;

/// tev's packets as a listener decodes them: CreateImage (name, size, channels) and
/// UpdateImage (channels, region, planar values); others are only counted.
#[derive(Debug, Default)]
struct TevStream {
    created: Vec<(String, i32, i32, Vec<String>)>,
    updates: Vec<(Vec<String>, [i32; 4], Vec<f32>)>,
    others: usize,
}

fn decode_tev(bytes: &[u8]) -> TevStream {
    struct R<'a>(&'a [u8], usize);
    impl R<'_> {
        fn take(&mut self, n: usize) -> &[u8] {
            let s = &self.0[self.1..self.1 + n];
            self.1 += n;
            s
        }
        fn i32(&mut self) -> i32 {
            i32::from_le_bytes(self.take(4).try_into().unwrap())
        }
        fn i64(&mut self) -> i64 {
            i64::from_le_bytes(self.take(8).try_into().unwrap())
        }
        fn string(&mut self) -> String {
            let end = self.0[self.1..].iter().position(|&b| b == 0).unwrap();
            let s = String::from_utf8(self.take(end).to_vec()).unwrap();
            self.1 += 1;
            s
        }
    }
    let mut out = TevStream::default();
    let mut at = 0;
    while at < bytes.len() {
        let len = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        let mut r = R(&bytes[at..at + len], 4);
        match r.take(1)[0] {
            4 => {
                r.take(1);
                let name = r.string();
                let (w, h, n) = (r.i32(), r.i32(), r.i32());
                let channels = (0..n).map(|_| r.string()).collect();
                out.created.push((name, w, h, channels));
            }
            6 => {
                r.take(1);
                r.string();
                let n = r.i32() as usize;
                let channels: Vec<String> = (0..n).map(|_| r.string()).collect();
                let region = [r.i32(), r.i32(), r.i32(), r.i32()];
                let count = (region[2] * region[3]) as usize;
                let offsets: Vec<i64> = (0..n).map(|_| r.i64()).collect();
                let strides: Vec<i64> = (0..n).map(|_| r.i64()).collect();
                let data: Vec<f32> = r
                    .take(len - r.1)
                    .chunks_exact(4)
                    .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                    .collect();
                // Planar in the channels' order: value c of pixel p at offset_c + p stride_c.
                let mut planar = Vec::with_capacity(n * count);
                for c in 0..n {
                    for p in 0..count {
                        planar.push(data[(offsets[c] + p as i64 * strides[c]) as usize]);
                    }
                }
                out.updates.push((channels, region, planar));
            }
            _ => out.others += 1,
        }
        at += len;
    }
    out
}

#[test]
fn display_streams_the_render_to_tev_and_ends_on_the_image_written() {
    use std::io::Read;
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap().to_string();
    let reader = std::thread::spawn(move || {
        let (mut s, _) = listener.accept().unwrap();
        let mut bytes = Vec::new();
        s.read_to_end(&mut bytes).unwrap();
        bytes
    });
    let exr = scratch("display.exr");
    // Long enough (about a second) for updates while it renders.
    let (w, h) = (64, 40);
    let o = pathlab(&[
        "render",
        "-r",
        "64",
        "40",
        "-s",
        "1024",
        "--aov",
        "variance,samples",
        "--display",
        &addr,
        "-o",
        exr.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let tev = decode_tev(&reader.join().unwrap());
    let channels = [
        "R",
        "G",
        "B",
        "variance.R",
        "variance.G",
        "variance.B",
        "samples.Y",
    ];
    assert_eq!(tev.created.len(), 1);
    let (name, cw, ch, cc) = &tev.created[0];
    assert_eq!((name.as_str(), *cw, *ch), ("cornell-box", w, h));
    assert_eq!(cc, &channels);
    // The last value each update gave each pixel's channels.
    let mut last = vec![vec![f32::NAN; (w * h) as usize]; channels.len()];
    for (uc, [x0, y0, rw, rh], planar) in &tev.updates {
        assert_eq!(uc, &channels);
        let n = (rw * rh) as usize;
        for (c, plane) in last.iter_mut().enumerate() {
            for p in 0..n {
                let (x, y) = (x0 + p as i32 % rw, y0 + p as i32 / rw);
                plane[(y * w + x) as usize] = planar[c * n + p];
            }
        }
    }
    // Besides the first and last whole images, tiles re-sent as passes changed them.
    let tiles = tev.updates.iter().filter(|u| u.1[2] <= 16).count();
    assert!(tiles > 0, "no tile updates during the render");
    for (c, name) in channels.iter().enumerate() {
        let written = read_exr_layer(&exr, name);
        assert!(
            last[c]
                .iter()
                .zip(&written)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{name}: tev's last values differ from the EXR's"
        );
    }
    // Nothing listening: one warning, and the render goes on.
    let free = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = free.local_addr().unwrap().port();
    drop(free);
    let o = pathlab(&[
        "render",
        "-r",
        "8",
        "8",
        "-s",
        "4",
        "--display",
        &format!("127.0.0.1:{port}"),
        "-o",
        scratch("display-alone.exr").to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("warning: --display"), "{stderr}");
}
