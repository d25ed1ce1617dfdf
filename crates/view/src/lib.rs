//! # pathlab-view: watch a render converge in the browser
//!
//! [`serve`] starts a local web server (axum on tokio) for one scene: `GET /` is the viewer
//! page (one static HTML file compiled in, no build step, nothing fetched from elsewhere),
//! `GET /ws` a WebSocket. The scene renders in its own threads ([`renderer`]), pass by pass;
//! after each pass every connected page gets a text message with the frame's statistics (JSON:
//! `generation`, `width`, `height`, `spp`, `samples_per_second`, `relative_error`, `mean`,
//! `controls`, `display_range`, and `pixel` for a page that inspects one) and a binary message of its sRGB pixels (RGBA, rows from the top). The page
//! sends JSON objects of [`controls::Controls`] settings; a change restarts the image, a bad
//! message gets `{"error": "..."}` back and changes nothing. A slow page skips frames; it never
//! holds up the render.

pub mod controls;
pub mod probe;
pub mod renderer;
pub mod samples;

use anyhow::{Context, Result};
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::State;
use axum::response::{Html, IntoResponse};
use axum::routing::get;
use axum::Router;
use pathlab_render::desc::SceneDesc;
use pathlab_render::scene::Scene;
use renderer::{Frame, Shared};
use serde_json::json;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::sync::watch;

/// The viewer page.
const PAGE: &str = include_str!("page.html");

/// Where to listen.
#[derive(Clone, Debug)]
pub struct ViewOptions {
    /// The address to bind: 127.0.0.1 keeps the viewer to this machine.
    pub host: String,
    /// The port (0: any free one).
    pub port: u16,
    /// The scene's name, shown on the page.
    pub title: String,
}

/// Serves the viewer for `desc` until `stop` is set; `ready` gets the address bound (before
/// the first request is answered).
pub fn serve(
    desc: SceneDesc,
    options: &ViewOptions,
    stop: Arc<AtomicBool>,
    ready: impl FnOnce(SocketAddr),
) -> Result<()> {
    let scene = Scene::build(&desc).context("cannot build the scene")?;
    let (frames, _) = watch::channel(Arc::new(Frame::default()));
    let shared = Arc::new(Shared {
        controls: Mutex::new(controls::Controls::for_scene(&desc.hints)),
        generation: AtomicU64::new(0),
        restart: AtomicBool::new(false),
        stop: AtomicBool::new(false),
        frames,
        inspected: Mutex::new(Default::default()),
        sample_view: Mutex::new(None),
    });
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .context("cannot start the web server's runtime")?;
    let listener = runtime
        .block_on(tokio::net::TcpListener::bind((
            options.host.as_str(),
            options.port,
        )))
        .with_context(|| format!("cannot listen on {}:{}", options.host, options.port))?;
    let addr = listener.local_addr()?;
    let render = {
        let shared = Arc::clone(&shared);
        std::thread::spawn(move || renderer::run(&desc, scene, &shared))
    };
    ready(addr);
    let state = AppState {
        shared: Arc::clone(&shared),
        title: options.title.clone(),
    };
    let app = Router::new()
        .route("/", get(page))
        .route("/ws", get(socket))
        .with_state(state);
    let served = runtime.block_on(async {
        axum::serve(listener, app)
            .with_graceful_shutdown(async move {
                while !stop.load(Ordering::Relaxed) {
                    tokio::time::sleep(Duration::from_millis(50)).await;
                }
            })
            .await
    });
    shared.stop.store(true, Ordering::SeqCst);
    shared.restart.store(true, Ordering::SeqCst);
    let _ = render.join();
    runtime.shutdown_timeout(Duration::from_millis(200));
    served.context("the web server failed")
}

/// A page's inspected pixel, registered with the render while the page is connected.
struct Inspector {
    shared: Arc<Shared>,
    pixel: Option<[u32; 2]>,
}

impl Drop for Inspector {
    fn drop(&mut self) {
        self.shared.inspect(self.pixel, None);
    }
}

/// The image size of the latest frame.
fn size(frames: &watch::Receiver<Arc<Frame>>) -> [u32; 2] {
    frames.borrow().size
}

/// `{"inspect": [x, y]}`: the pixel a page inspects (`None` for any other message; an error
/// for a pixel outside the image).
fn inspect_request(text: &str, [w, h]: [u32; 2]) -> Option<Result<[u32; 2], String>> {
    let v: serde_json::Value = serde_json::from_str(text).ok()?;
    let fields = v.as_object()?;
    let p = fields.get("inspect")?;
    if fields.len() != 1 {
        return Some(Err("inspect: send it on its own".into()));
    }
    let xy = p
        .as_array()
        .filter(|a| a.len() == 2)
        .and_then(|a| Some([a[0].as_u64()?, a[1].as_u64()?]));
    Some(match xy {
        Some([x, y]) if x < w as u64 && y < h as u64 => Ok([x as u32, y as u32]),
        _ => Err(format!("inspect: {p} is not a pixel of the {w}x{h} image")),
    })
}

/// What the inspector shows of pixel `p` in `frame`: its samples, mean luminance and the 95%
/// confidence interval of that mean.
fn pixel_json(frame: &Frame, p: [u32; 2]) -> Option<serde_json::Value> {
    let (_, stats) = frame.inspected.iter().find(|(q, _)| *q == p)?;
    let l = stats.luminance();
    let half = 1.96 * l.std_error();
    let probe = frame
        .probes
        .iter()
        .find(|(q, _)| *q == p)
        .map(|(_, probe)| {
            json!({
                "samples": probe.samples,
                "zero": probe.zero,
                "log10_range": probe.log10_range,
                "counts": probe.counts,
                "bounces": probe.bounces,
            })
        });
    Some(json!({
        "probe": probe,
        "x": p[0],
        "y": p[1],
        "samples": stats.count(),
        "mean": l.mean(),
        "ci95": [l.mean() - half, l.mean() + half],
        "rgb": stats.mean().to_array(),
    }))
}

/// A page's request to see the samples at a point (`{"samples_at": ...}`), checked against
/// an image of `size`; `None` for any other message.
fn samples_request(text: &str, size: [u32; 2]) -> Option<Result<Option<samples::Request>, String>> {
    let v: serde_json::Value = serde_json::from_str(text).ok()?;
    let fields = v.as_object()?;
    fields
        .contains_key("samples_at")
        .then(|| samples::Request::parse(fields, size))
}

/// The samples at a point, as the page draws them.
fn sample_view_json(v: &samples::SampleView) -> serde_json::Value {
    json!({
        "x": v.request.pixel[0],
        "y": v.request.pixel[1],
        "strategy": v.request.strategy.name(),
        "n": v.request.n,
        "origin": v.origin,
        "ends": v.samples.iter().map(|s| s.end).collect::<Vec<_>>(),
        "escaped": v.samples.iter().map(|s| s.escaped).collect::<Vec<_>>(),
        "weights": v.samples.iter().map(|s| s.weight).collect::<Vec<_>>(),
        "contributions": v.samples.iter().map(|s| s.contribution).collect::<Vec<_>>(),
        "estimate": v.estimate,
        "luminance": v.luminance,
        "std_error": v.std_error,
        "compared": v.compared.iter().map(|(strategy, mean, error, lit)| json!({
            "strategy": strategy, "luminance": mean, "std_error": error, "lit": lit,
        })).collect::<Vec<_>>(),
    })
}

#[derive(Clone)]
struct AppState {
    shared: Arc<Shared>,
    title: String,
}

async fn page(State(state): State<AppState>) -> Html<String> {
    let title = state
        .title
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;");
    Html(PAGE.replace("{{TITLE}}", &title))
}

async fn socket(ws: WebSocketUpgrade, State(state): State<AppState>) -> impl IntoResponse {
    ws.on_upgrade(move |socket| client(socket, state.shared))
}

/// One page: frames out as they come (the latest only, when the page is slower than the
/// render), settings in.
async fn client(mut socket: WebSocket, shared: Arc<Shared>) {
    let mut frames = shared.frames.subscribe();
    frames.mark_changed();
    // The page's inspected pixel, given back when the page goes.
    let mut inspector = Inspector {
        shared: Arc::clone(&shared),
        pixel: None,
    };
    loop {
        tokio::select! {
            message = socket.recv() => match message {
                Some(Ok(Message::Text(text))) => {
                    let handled = match inspect_request(text.as_str(), size(&frames)) {
                        Some(Ok(pixel)) => {
                            inspector.shared.inspect(inspector.pixel, Some(pixel));
                            inspector.pixel = Some(pixel);
                            Ok(())
                        }
                        Some(Err(e)) => Err(e),
                        None => match samples_request(text.as_str(), size(&frames)) {
                            Some(Ok(request)) => shared
                                .sample_view
                                .lock()
                                .map(|mut r| *r = request)
                                .map_err(|_| "the render stopped".to_string()),
                            Some(Err(e)) => Err(e),
                            None => shared.apply(text.as_str()),
                        },
                    };
                    if let Err(e) = handled {
                        let reply = json!({ "error": e }).to_string();
                        if socket.send(Message::Text(reply.into())).await.is_err() {
                            return;
                        }
                    }
                }
                Some(Ok(Message::Binary(_))) => {
                    let reply = json!({ "error": "expected a JSON text message" }).to_string();
                    if socket.send(Message::Text(reply.into())).await.is_err() {
                        return;
                    }
                }
                Some(Ok(_)) => {}
                Some(Err(_)) | None => return,
            },
            changed = frames.changed() => {
                if changed.is_err() {
                    return;
                }
                let frame = Arc::clone(&frames.borrow_and_update());
                if frame.rgba.is_empty() {
                    continue;
                }
                let stats = json!({
                    "generation": frame.generation,
                    "width": frame.size[0],
                    "height": frame.size[1],
                    "spp": frame.spp,
                    "samples_per_second": frame.samples_per_second,
                    "relative_error": frame.relative_error,
                    "mean": frame.mean,
                    "controls": frame.controls.as_ref().map(|c| c.to_json()),
                    "display_range": frame.display_range,
                    "pixel": inspector.pixel.and_then(|p| pixel_json(&frame, p)),
                    "sample_view": frame.sample_view.as_deref().map(sample_view_json),
                });
                if socket.send(Message::Text(stats.to_string().into())).await.is_err()
                    || socket
                        .send(Message::Binary(frame.rgba.as_ref().clone().into()))
                        .await
                        .is_err()
                {
                    return;
                }
            }
        }
    }
}
