//! The viewer end to end: a server on the built-in Cornell box, the page fetched over HTTP,
//! and a WebSocket client that reads frames and changes settings as the page does.

use futures_util::{SinkExt, StreamExt};
use pathlab_view::{serve, ViewOptions};
use serde_json::Value;
use std::io::{Read, Write};
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tokio_tungstenite::tungstenite::Message;

type Socket =
    tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

/// A frame as the page gets it: the statistics, then the pixels.
struct Frame {
    stats: Value,
    rgba: Vec<u8>,
}

/// The next message of `ws` (failing the test after a while).
async fn next(ws: &mut Socket) -> Message {
    tokio::time::timeout(Duration::from_secs(60), ws.next())
        .await
        .expect("no message within a minute")
        .expect("the server closed the socket")
        .expect("a WebSocket error")
}

/// The next frame whose statistics satisfy `want` (errors are returned as `Err`).
async fn frame_where(ws: &mut Socket, want: impl Fn(&Value) -> bool) -> Frame {
    loop {
        let Message::Text(text) = next(ws).await else {
            continue;
        };
        let stats: Value = serde_json::from_str(text.as_str()).unwrap();
        assert!(stats.get("error").is_none(), "unexpected error {stats}");
        let Message::Binary(rgba) = next(ws).await else {
            panic!("statistics not followed by pixels");
        };
        if want(&stats) {
            return Frame {
                stats,
                rgba: rgba.to_vec(),
            };
        }
    }
}

/// The next error reply, skipping frames.
async fn error_reply(ws: &mut Socket) -> String {
    loop {
        if let Message::Text(text) = next(ws).await {
            let v: Value = serde_json::from_str(text.as_str()).unwrap();
            if let Some(e) = v.get("error") {
                return e.as_str().unwrap().to_string();
            }
        }
    }
}

async fn send(ws: &mut Socket, text: &str) {
    ws.send(Message::Text(text.into())).await.unwrap();
}

fn get_page(addr: SocketAddr) -> String {
    let mut s = std::net::TcpStream::connect(addr).unwrap();
    s.write_all(b"GET / HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n")
        .unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    out
}

/// Runs `talk` on a WebSocket connected to the server at `addr`.
fn on_socket<F: std::future::Future<Output = ()>>(
    addr: SocketAddr,
    talk: impl FnOnce(Socket) -> F,
) {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let (ws, _) = tokio_tungstenite::connect_async(format!("ws://{addr}/ws"))
            .await
            .unwrap();
        talk(ws).await
    });
}

/// A server on the built-in Cornell box at `size`: its address, its stop flag and its thread.
fn start(
    size: u32,
) -> (
    SocketAddr,
    Arc<AtomicBool>,
    std::thread::JoinHandle<anyhow::Result<()>>,
) {
    let mut desc = pathlab_scene::builtin::load("cornell-box").unwrap();
    desc.resolution = [size, size];
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = std::sync::mpsc::channel();
    let server = {
        let stop = Arc::clone(&stop);
        std::thread::spawn(move || {
            let options = ViewOptions {
                host: "127.0.0.1".into(),
                port: 0,
                title: "cornell <box>".into(),
            };
            serve(desc, &options, stop, |addr| tx.send(addr).unwrap())
        })
    };
    let addr = rx.recv_timeout(Duration::from_secs(60)).unwrap();
    (addr, stop, server)
}

#[test]
fn the_viewer_streams_passes_and_restarts_on_a_change_of_settings() {
    let (addr, stop, server) = start(48);
    assert!(addr.ip().is_loopback());
    let page = get_page(addr);
    assert!(page.starts_with("HTTP/1.1 200"), "{page}");
    assert!(page.contains("<canvas") && page.contains("cornell &lt;box&gt;"));

    on_socket(addr, |mut ws| async move {
        // Passes arrive with growing sample counts; the box is not black.
        let first = frame_where(&mut ws, |_| true).await;
        assert_eq!(first.stats["width"], 48);
        assert_eq!(first.rgba.len(), 48 * 48 * 4);
        let later = frame_where(&mut ws, |s| s["spp"].as_u64().unwrap() >= 8).await;
        let bright = later.rgba.chunks(4).map(|p| p[1] as f64).sum::<f64>() / (48.0 * 48.0);
        assert!(bright > 20.0, "mean green {bright}");
        assert_eq!(later.stats["controls"]["integrator"], "path");

        // Bad messages get an error reply and change nothing; the server goes on.
        send(&mut ws, "not json").await;
        assert!(error_reply(&mut ws).await.contains("not a JSON message"));
        send(&mut ws, r#"{"bogus": 1}"#).await;
        assert_eq!(error_reply(&mut ws).await, "unknown setting 'bogus'");
        send(&mut ws, r#"{"max_depth": 0}"#).await;
        assert!(error_reply(&mut ws).await.starts_with("max_depth"));
        send(&mut ws, r#"{"direct": "sideways"}"#).await;
        assert!(error_reply(&mut ws).await.contains("sideways"));

        // A heat map of the samples per pixel runs over 0 to the samples taken; the display
        // changes without restarting the image.
        let generation = later.stats["generation"].clone();
        send(&mut ws, r#"{"display": "samples"}"#).await;
        let heat = frame_where(&mut ws, |s| s["controls"]["display"] == "samples").await;
        assert_eq!(heat.stats["generation"], generation);
        assert_eq!(
            heat.stats["display_range"][1],
            heat.stats["spp"].as_f64().unwrap()
        );
        send(&mut ws, r#"{"display": "image"}"#).await;

        // The BVH view is a heat map of the nodes each camera ray visits, over their range.
        send(&mut ws, r#"{"integrator": "bvh"}"#).await;
        let bvh = frame_where(&mut ws, |s| s["controls"]["integrator"] == "bvh").await;
        assert!(bvh.stats["display_range"][1].as_f64().unwrap() >= 1.0);
        send(&mut ws, r#"{"integrator": "path"}"#).await;

        // The inspector: the pixel's samples, mean luminance and 95% interval, every frame.
        send(&mut ws, r#"{"inspect": [24, 30]}"#).await;
        let inspected = frame_where(&mut ws, |s| s["pixel"].is_object()).await;
        let p = &inspected.stats["pixel"];
        assert_eq!((p["x"].as_u64(), p["y"].as_u64()), (Some(24), Some(30)));
        assert_eq!(p["samples"], inspected.stats["spp"]);
        let (lo, mean, hi) = (
            p["ci95"][0].as_f64().unwrap(),
            p["mean"].as_f64().unwrap(),
            p["ci95"][1].as_f64().unwrap(),
        );
        assert!(lo <= mean && mean <= hi && mean > 0.0, "{p}");
        // Its first samples' histogram (every one counted once) and their split by bounce.
        let probe = &p["probe"];
        let n = probe["samples"].as_u64().unwrap();
        assert!(n >= 1 && n <= p["samples"].as_u64().unwrap(), "{p}");
        let counts = probe["counts"].as_array().unwrap().iter();
        let counted = counts.map(|c| c.as_u64().unwrap()).sum::<u64>();
        assert_eq!(counted + probe["zero"].as_u64().unwrap(), n);
        assert!(!probe["bounces"].as_array().unwrap().is_empty());
        send(&mut ws, r#"{"inspect": [48, 0]}"#).await;
        assert!(error_reply(&mut ws)
            .await
            .contains("not a pixel of the 48x48 image"));

        // The course's comparison: uniform hemisphere sampling against light sampling at the
        // same samples per pixel; each change restarts the image.
        send(
            &mut ws,
            r#"{"integrator": "direct", "direct": "hemisphere"}"#,
        )
        .await;
        let hemisphere = frame_where(&mut ws, |s| {
            s["controls"]["direct"] == "hemisphere" && s["spp"].as_u64().unwrap() >= 16
        })
        .await;
        let generation = hemisphere.stats["generation"].as_u64().unwrap();
        assert!(generation >= 1);
        send(&mut ws, r#"{"direct": "light"}"#).await;
        let restarted = frame_where(&mut ws, |s| s["controls"]["direct"] == "light").await;
        // A new image (the next generation) from its first passes: a page gets only the
        // latest frame, so under load it may see the 8-spp pass rather than the 1-spp one, but
        // never the hemisphere image's count or more.
        assert_eq!(restarted.stats["generation"], generation + 1);
        let first = restarted.stats["spp"].as_u64().unwrap();
        assert!(
            first < hemisphere.stats["spp"].as_u64().unwrap(),
            "a change starts the image again: {first} spp"
        );
        // The first light-sampling frame with at least as many samples (a page gets only the
        // latest frame, so one with exactly as many may be skipped); the errors compared at
        // one sample per pixel (they fall as 1/√spp).
        let spp = |f: &Frame| f.stats["spp"].as_f64().unwrap();
        let light = frame_where(&mut ws, |s| {
            s["controls"]["direct"] == "light" && s["spp"].as_f64().unwrap() >= spp(&hemisphere)
        })
        .await;
        let (eh, el) = (
            hemisphere.stats["relative_error"].as_f64().unwrap() * spp(&hemisphere).sqrt(),
            light.stats["relative_error"].as_f64().unwrap() * spp(&light).sqrt(),
        );
        assert!(
            el < 0.75 * eh,
            "relative error at 1 spp: light {el}, hemisphere {eh}"
        );
    });
    stop.store(true, Ordering::SeqCst);
    server.join().unwrap().unwrap();
}

#[test]
fn a_finished_image_is_sent_again_for_a_new_display_or_inspected_pixel() {
    // 2 x 2 pixels reach the last pass quickly; then the render waits for a change.
    let (addr, stop, server) = start(2);
    on_socket(addr, |mut ws| async move {
        let max = pathlab_view::renderer::MAX_SPP as u64;
        frame_where(&mut ws, |s| s["spp"].as_u64() == Some(max)).await;
        send(&mut ws, r#"{"inspect": [1, 1]}"#).await;
        let inspected = frame_where(&mut ws, |s| s["pixel"].is_object()).await;
        assert_eq!(inspected.stats["pixel"]["samples"].as_u64(), Some(max));
        send(&mut ws, r#"{"exposure": 2}"#).await;
        let brighter = frame_where(&mut ws, |s| s["controls"]["exposure"] == 2.0).await;
        assert_eq!(brighter.stats["generation"], inspected.stats["generation"]);
    });
    stop.store(true, Ordering::SeqCst);
    server.join().unwrap().unwrap();
}
