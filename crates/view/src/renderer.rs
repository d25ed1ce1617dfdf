//! The render behind the page: passes of the whole frame (1, 1, 2, 4, ... samples per pixel,
//! then steady passes) with the current controls, each finished pass published as a frame;
//! a change of the controls stops the pass under way and starts the image again.

use crate::controls::Controls;
use crate::probe::{probe, probe_size, Probe};
use crate::samples::{sample_view, Request, SampleView};
use pathlab_render::camera::Camera;
use pathlab_render::color::luminance_f64;
use pathlab_render::desc::SceneDesc;
use pathlab_render::film::{Film, PixelStats};
use pathlab_render::film_image::heat_colour;
use pathlab_render::image_io::srgb_encode;
use pathlab_render::progressive::estimated_relative_rmse;
use pathlab_render::render::{render_from, RenderSettings};
use pathlab_render::scene::Scene;
use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tokio::sync::watch;

/// Samples per pixel at which an image is done (it then waits for a change).
pub const MAX_SPP: u32 = 65536;

/// An inspected pixel and its probe.
pub type PixelProbe = ([u32; 2], Arc<Probe>);

/// The seed of every image.
const SEED: u64 = 0;

/// One finished pass, as the page gets it.
#[derive(Clone, Debug, Default)]
pub struct Frame {
    /// Which image (it grows by one with each change of the controls).
    pub generation: u64,
    /// Width and height.
    pub size: [u32; 2],
    /// Samples per pixel so far.
    pub spp: u32,
    /// Samples per second of the image so far.
    pub samples_per_second: f64,
    /// The film's estimated relative RMSE.
    pub relative_error: f64,
    /// The mean luminance of the image (linear).
    pub mean: [f64; 3],
    /// The controls the image is rendered with.
    pub controls: Option<Controls>,
    /// The range a heat-map display's colours run over (zero for the image).
    pub display_range: [f64; 2],
    /// The statistics of the pixels pages inspect.
    pub inspected: Vec<([u32; 2], PixelStats)>,
    /// The histograms and bounce splits of the pixels pages inspect.
    pub probes: Vec<PixelProbe>,
    /// The samples at a point a page asked to see.
    pub sample_view: Option<Arc<SampleView>>,
    /// sRGB pixels, four bytes each (alpha 255), rows from the top.
    pub rgba: Arc<Vec<u8>>,
}

/// What the page and the render thread share.
pub struct Shared {
    /// The current controls.
    pub controls: Mutex<Controls>,
    /// Bumped by every change that restarts the image.
    pub generation: AtomicU64,
    /// Set to stop the pass under way (a change, or the server stopping).
    pub restart: AtomicBool,
    /// Set when the server stops.
    pub stop: AtomicBool,
    /// The latest frame.
    pub frames: watch::Sender<Arc<Frame>>,
    /// The pixels pages inspect, with how many pages inspect each (each frame carries their
    /// statistics).
    pub inspected: Mutex<BTreeMap<[u32; 2], usize>>,
    /// The samples at a point a page asked to see (the last request of any page).
    pub sample_view: Mutex<Option<crate::samples::Request>>,
}

impl Shared {
    /// Moves a page's inspected pixel from `from` to `to` (either may be none).
    pub fn inspect(&self, from: Option<[u32; 2]>, to: Option<[u32; 2]>) {
        let Ok(mut set) = self.inspected.lock() else {
            return;
        };
        if let Some(p) = to {
            *set.entry(p).or_insert(0) += 1;
        }
        if let Some(p) = from {
            if let Some(n) = set.get_mut(&p) {
                *n -= 1;
                if *n == 0 {
                    set.remove(&p);
                }
            }
        }
    }

    /// Applies a message of the page (see [`Controls::apply`]); a change that alters the
    /// samples restarts the image.
    pub fn apply(&self, message: &str) -> Result<(), String> {
        let mut c = self
            .controls
            .lock()
            .map_err(|_| "the render stopped".to_string())?;
        if c.apply(message)? {
            self.generation.fetch_add(1, Ordering::SeqCst);
            self.restart.store(true, Ordering::SeqCst);
        }
        Ok(())
    }
}

/// Renders `desc` until `shared.stop`, publishing each pass.
pub fn run(desc: &SceneDesc, mut scene: Scene, shared: &Shared) {
    // What the last frame showed: its controls, the pixels it carried and the samples a
    // page asked to see.
    let mut shown: Option<(Controls, Vec<[u32; 2]>, Option<Request>)> = None;
    let mut last_film: Option<(u64, u32, Film, f64)> = None;
    let mut probes = Probes::default();
    while !shared.stop.load(Ordering::SeqCst) {
        shared.restart.store(false, Ordering::SeqCst);
        let generation = shared.generation.load(Ordering::SeqCst);
        let Ok(controls) = shared.controls.lock().map(|c| c.clone()) else {
            return;
        };
        if let Some((g, spp, film, rate)) = &last_film {
            // The image is done: only a new display (exposure, heat map), a newly inspected
            // pixel or a new request for samples at a point is worth a frame.
            if *g == generation {
                let now = (controls, inspected_pixels(shared), requested(shared));
                if shown.as_ref() != Some(&now) {
                    let probed = probes.of(&scene, &now.0, *g, film, &now.1);
                    let view = probes.view(&scene, *g, now.2.as_ref());
                    publish(
                        shared,
                        film,
                        *g,
                        *spp,
                        *rate,
                        &now.0,
                        (&now.1, probed, view),
                    );
                    shown = Some(now);
                }
                std::thread::sleep(Duration::from_millis(20));
                continue;
            }
        }
        let camera =
            Camera::new(&controls.camera(&desc.camera), desc.resolution).with_filter(desc.filter);
        scene.set_camera(camera);
        let integrator = controls.integrator();
        let settings = RenderSettings::new(MAX_SPP, SEED, controls.sampler);
        let [w, h] = desc.resolution;
        let start = Instant::now();
        let mut done = 0u32;
        let (film, stats) = render_from(
            &scene,
            &integrator,
            &settings,
            Film::new(w, h),
            &|_| {},
            &shared.restart,
            &mut |film, stats| {
                done = film.sample_count_range().max as u32;
                let rate = stats.samples as f64 / start.elapsed().as_secs_f64().max(1e-9);
                let now = shared
                    .controls
                    .lock()
                    .map(|c| c.clone())
                    .unwrap_or_default();
                // `shown` is what this frame carries: a pixel inspected after the set was
                // read gets a frame of its own once the image is done.
                let (pixels, request) = (inspected_pixels(shared), requested(shared));
                let probed = probes.of(&scene, &controls, generation, film, &pixels);
                let view = probes.view(&scene, generation, request.as_ref());
                publish(
                    shared,
                    film,
                    generation,
                    done,
                    rate,
                    &now,
                    (&pixels, probed, view),
                );
                shown = Some((now, pixels, request));
            },
        );
        if !stats.cancelled {
            let rate = stats.samples as f64 / start.elapsed().as_secs_f64().max(1e-9);
            last_film = Some((generation, done, film, rate));
        } else {
            last_film = None;
        }
    }
}

/// The samples at a point a page asked to see.
fn requested(shared: &Shared) -> Option<Request> {
    shared.sample_view.lock().ok().and_then(|r| r.clone())
}

/// The pixels pages inspect.
fn inspected_pixels(shared: &Shared) -> Vec<[u32; 2]> {
    shared
        .inspected
        .lock()
        .map(|set| set.keys().copied().collect())
        .unwrap_or_default()
}

/// The probes of inspected pixels, each kept until its image changes or its pixel holds
/// twice the samples it was made from.
#[derive(Default)]
struct Probes {
    made: HashMap<[u32; 2], (u64, u32, Arc<Probe>)>,
    /// The last sample view made, and for which image.
    view: Option<(u64, Arc<SampleView>)>,
}

impl Probes {
    /// The samples `request` asks to see in image `generation`, made when missing.
    fn view(
        &mut self,
        scene: &Scene,
        generation: u64,
        request: Option<&Request>,
    ) -> Option<Arc<SampleView>> {
        let request = request?;
        match &self.view {
            Some((g, v)) if *g == generation && &v.request == request => Some(Arc::clone(v)),
            _ => {
                let v = Arc::new(sample_view(scene, request));
                self.view = Some((generation, Arc::clone(&v)));
                Some(v)
            }
        }
    }

    /// The probes of `pixels` in image `generation` (rendered with `c`), made where missing.
    fn of(
        &mut self,
        scene: &Scene,
        c: &Controls,
        generation: u64,
        film: &Film,
        pixels: &[[u32; 2]],
    ) -> Vec<PixelProbe> {
        self.made.retain(|p, _| pixels.contains(p));
        pixels
            .iter()
            .map(|&[x, y]| {
                let n = probe_size(film.pixel(x, y).count() as u32);
                let entry = self
                    .made
                    .entry([x, y])
                    .or_insert((u64::MAX, 0, Arc::default()));
                if (entry.0, entry.1) != (generation, n) {
                    *entry = (
                        generation,
                        n,
                        Arc::new(probe(scene, c, (MAX_SPP, SEED), [x, y], n)),
                    );
                }
                ([x, y], Arc::clone(&entry.2))
            })
            .collect()
    }
}

/// Sends `film` as a frame, drawn as `c.display` says, with the statistics and probes of the
/// inspected pixels.
fn publish(
    shared: &Shared,
    film: &Film,
    generation: u64,
    spp: u32,
    rate: f64,
    c: &Controls,
    (pixels, probes, sample_view): (&[[u32; 2]], Vec<PixelProbe>, Option<Arc<SampleView>>),
) {
    let (rgba, display_range) = draw(film, c);
    let mean = film.image_mean();
    shared.frames.send_replace(Arc::new(Frame {
        generation,
        size: [film.width(), film.height()],
        spp,
        samples_per_second: rate,
        relative_error: estimated_relative_rmse(film),
        mean: [mean.x, mean.y, mean.z],
        controls: Some(c.clone()),
        display_range,
        inspected: pixels
            .iter()
            .map(|&[x, y]| ([x, y], *film.pixel(x, y)))
            .collect(),
        probes,
        sample_view,
        rgba: Arc::new(rgba),
    }));
}

/// The frame's pixels: the image in sRGB after the exposure, or a heat map of a per-pixel
/// statistic over its range (returned); non-finite values (a relative error of a black pixel)
/// are left out of the range and drawn black.
fn draw(film: &Film, c: &Controls) -> (Vec<u8>, [f64; 2]) {
    let stat: fn(&PixelStats) -> f64 = match c.display.as_str() {
        // The BVH view's value is a count, shown over its range whatever the display.
        _ if c.integrator == "bvh" => |p| p.mean().x,
        "variance" => |p| luminance_f64(p.variance()),
        "relative_error" => {
            |p| luminance_f64(p.variance_of_mean()).sqrt() / luminance_f64(p.mean())
        }
        "samples" => |p| p.count() as f64,
        _ => {
            let scale = 2f32.powf(c.exposure);
            let rgba = film
                .mean_image()
                .iter()
                .flat_map(|p| {
                    let v = (*p * scale)
                        .to_array()
                        .map(|x| (srgb_encode(x.clamp(0.0, 1.0)) * 255.0).round() as u8);
                    [v[0], v[1], v[2], 255]
                })
                .collect();
            return (rgba, [0.0, 0.0]);
        }
    };
    let values: Vec<f64> = film.pixels().iter().map(stat).collect();
    let hi = values
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let rgba = values
        .iter()
        .flat_map(|&v| {
            let [r, g, b] = if v.is_finite() {
                heat_colour((v / hi.max(f64::MIN_POSITIVE)) as f32)
            } else {
                [0, 0, 0]
            };
            [r, g, b, 255]
        })
        .collect();
    (rgba, [0.0, hi])
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn heat_maps_run_over_their_statistic_and_draw_undefined_values_black() {
        let mut film = Film::new(2, 1);
        for l in [0.5, 1.5, 1.0] {
            film.pixel_mut(0, 0).add(Vec3::splat(l));
        }
        film.pixel_mut(1, 0).add(Vec3::ZERO);
        let mut c = Controls::default();
        let (rgba, range) = draw(&film, &c);
        assert_eq!((rgba.len(), range), (8, [0.0, 0.0]));
        c.display = "samples".into();
        assert_eq!(draw(&film, &c).1, [0.0, 3.0]);
        c.display = "variance".into();
        let (_, [_, hi]) = draw(&film, &c);
        assert!((hi - 0.25).abs() < 1e-6, "{hi}");
        // The black pixel's relative error is 0/0: left out of the range, drawn black.
        c.display = "relative_error".into();
        let (rgba, [_, hi]) = draw(&film, &c);
        assert!(hi.is_finite() && hi > 0.0);
        assert_eq!(&rgba[4..8], &[0, 0, 0, 255]);
    }
}
