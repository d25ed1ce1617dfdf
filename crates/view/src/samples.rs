//! The course's picture of an estimator at one point: N directions drawn there by one
//! strategy (uniform hemisphere, cosine-weighted, BSDF, or points on the lights), where each
//! ends in the image, its weight f·cos/pdf, what it contributes, and the estimate the N give.

use glam::Vec2;
use pathlab_mc::estimator::RunningStats;
use pathlab_render::color::luminance;
use pathlab_render::integrator::{direct_samples, SampleStrategy};
use pathlab_render::scene::Scene;

/// The most samples a page may ask to see.
pub const MAX_SHOWN: u32 = 4096;

/// What a page asked to see: `n` samples by `strategy` at the surface seen through `pixel`.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    pub pixel: [u32; 2],
    pub strategy: SampleStrategy,
    pub n: u32,
}

impl Request {
    /// The request of a page's `{"samples_at": [x, y], "strategy": ..., "n": ...}` (`None`
    /// for `"samples_at": null`), checked against an image of `size`.
    pub fn parse(
        fields: &serde_json::Map<String, serde_json::Value>,
        [w, h]: [u32; 2],
    ) -> Result<Option<Request>, String> {
        if let Some(unknown) = fields
            .keys()
            .find(|k| !["samples_at", "strategy", "n"].contains(&k.as_str()))
        {
            return Err(format!("samples_at: unexpected field '{unknown}'"));
        }
        let at = &fields["samples_at"];
        if at.is_null() {
            return Ok(None);
        }
        let pixel = at
            .as_array()
            .filter(|a| a.len() == 2)
            .and_then(|a| Some([a[0].as_u64()?, a[1].as_u64()?]))
            .filter(|&[x, y]| x < w as u64 && y < h as u64)
            .ok_or_else(|| format!("samples_at: {at} is not a pixel of the {w}x{h} image"))?;
        let strategy = fields
            .get("strategy")
            .map_or(Some("cosine"), |s| s.as_str())
            .ok_or("samples_at: strategy must be a string")?
            .parse::<SampleStrategy>()?;
        let n = match fields.get("n") {
            None => 64,
            Some(v) => v
                .as_u64()
                .filter(|&n| (1..=MAX_SHOWN as u64).contains(&n))
                .ok_or_else(|| format!("samples_at: n must be 1 to {MAX_SHOWN}, got {v}"))?
                as u32,
        };
        Ok(Some(Request {
            pixel: [pixel[0] as u32, pixel[1] as u32],
            strategy,
            n,
        }))
    }
}

/// One drawn sample, for the page.
#[derive(Clone, Debug, PartialEq)]
pub struct Shown {
    /// Where its ray (or shadow ray) ends in the image (film coordinates, pixels); a
    /// direction that leaves the scene is drawn to a point as far from the surface as the
    /// camera is.
    pub end: Option<[f32; 2]>,
    /// Whether the ray left the scene.
    pub escaped: bool,
    /// Luminance of f·cos/pdf.
    pub weight: f32,
    /// Luminance of what it contributes (weight times the light it finds).
    pub contribution: f32,
}

/// The samples a [`Request`] asked for.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleView {
    pub request: Request,
    /// The surface point's place in the image; `None` where the pixel sees no surface.
    pub origin: Option<[f32; 2]>,
    pub samples: Vec<Shown>,
    /// Their mean contribution (RGB), its luminance and that's standard error.
    pub estimate: [f64; 3],
    pub luminance: f64,
    pub std_error: f64,
    /// Every strategy's estimate from as many samples at the same point: (strategy,
    /// luminance, its standard error, how many samples brought light).
    pub compared: Vec<(&'static str, f64, f64, u32)>,
}

/// The mean of `values` and its standard error.
fn mean_and_error(values: &[f64]) -> (f64, f64) {
    let mut stats = RunningStats::new();
    values.iter().for_each(|&v| stats.push(v));
    (stats.mean(), stats.std_error())
}

/// The samples of `request` in `scene` (with its current camera).
pub fn sample_view(scene: &Scene, request: &Request) -> SampleView {
    let camera = scene.camera();
    let [x, y] = request.pixel;
    let ray = camera.generate_ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::splat(0.5));
    let mut view = SampleView {
        request: request.clone(),
        origin: None,
        samples: Vec::new(),
        estimate: [0.0; 3],
        luminance: 0.0,
        std_error: 0.0,
        compared: Vec::new(),
    };
    let Some(si) = scene.intersect(&ray).0 else {
        return view;
    };
    let drawn = direct_samples(scene, &si, -ray.d, request.strategy, request.n, 1);
    let far = (si.p - ray.o).length();
    let raster = |p: glam::Vec3| camera.raster_position(p).map(|f| f.to_array());
    view.origin = camera.raster_position(si.p).map(|f| f.to_array());
    let n = drawn.len().max(1) as f64;
    let mut sum = [0.0f64; 3];
    let mut lum = Vec::with_capacity(drawn.len());
    for s in &drawn {
        let c = s.contribution.as_dvec3();
        for (acc, v) in sum.iter_mut().zip(c.to_array()) {
            *acc += v;
        }
        let l = luminance(s.contribution);
        lum.push(l as f64);
        let end = s
            .end
            .or((s.wi != glam::Vec3::ZERO).then(|| si.p + s.wi * far));
        view.samples.push(Shown {
            end: end.and_then(raster),
            escaped: s.end.is_none(),
            weight: luminance(s.weight),
            contribution: l,
        });
    }
    view.estimate = sum.map(|v| v / n);
    (view.luminance, view.std_error) = mean_and_error(&lum);
    // The other strategies from as many samples (the drawn one's are those above).
    view.compared = SampleStrategy::ALL
        .into_iter()
        .map(|other| {
            let others: Vec<f64>;
            let lum = if other == request.strategy {
                &lum
            } else {
                others = direct_samples(scene, &si, -ray.d, other, request.n, 1)
                    .iter()
                    .map(|s| luminance(s.contribution) as f64)
                    .collect();
                &others
            };
            let (mean, error) = mean_and_error(lum);
            let lit = lum.iter().filter(|&&l| l > 0.0).count() as u32;
            (other.name(), mean, error, lit)
        })
        .collect();
    view
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Option<Request>, String> {
        let v: serde_json::Value = serde_json::from_str(text).unwrap();
        Request::parse(v.as_object().unwrap(), [10, 8])
    }

    #[test]
    fn requests_are_checked() {
        assert_eq!(
            parse(r#"{"samples_at": [3, 4], "strategy": "light", "n": 16}"#),
            Ok(Some(Request {
                pixel: [3, 4],
                strategy: SampleStrategy::Light,
                n: 16
            }))
        );
        assert_eq!(parse(r#"{"samples_at": null}"#), Ok(None));
        assert!(parse(r#"{"samples_at": [10, 0]}"#)
            .unwrap_err()
            .contains("10x8"));
        assert!(parse(r#"{"samples_at": [1, 1], "strategy": "magic"}"#)
            .unwrap_err()
            .contains("magic"));
        assert!(parse(r#"{"samples_at": [1, 1], "n": 0}"#).is_err());
        assert!(parse(r#"{"samples_at": [1, 1], "bogus": 0}"#).is_err());
    }

    #[test]
    fn light_samples_end_on_the_light_and_estimate_what_cosine_samples_do() {
        let mut desc = pathlab_scene::builtin::load("cornell-box").unwrap();
        desc.resolution = [32, 32];
        let scene = Scene::build(&desc).unwrap();
        let at = |strategy: SampleStrategy| {
            sample_view(
                &scene,
                &Request {
                    pixel: [10, 28],
                    strategy,
                    n: 4096,
                },
            )
        };
        let (light, cosine) = (at(SampleStrategy::Light), at(SampleStrategy::Cosine));
        let origin = light.origin.expect("the floor");
        // The floor is below the middle of the image, the light at its top.
        assert!(origin[1] > 16.0, "{origin:?}");
        let lit: Vec<_> = light
            .samples
            .iter()
            .filter(|s| s.contribution > 0.0)
            .collect();
        assert!(lit.len() > 2000, "{} of 4096 lit", lit.len());
        assert!(lit.iter().all(|s| s.end.is_some_and(|e| e[1] < 8.0)));
        let (l, c) = (light.luminance, cosine.luminance);
        let se = (light.std_error.powi(2) + cosine.std_error.powi(2)).sqrt();
        assert!((l - c).abs() < 4.0 * se, "{l} against {c} (± {se})");
        assert!(cosine.std_error > light.std_error);
        // Every strategy's estimate from as many samples, the drawn one's among them.
        let names: Vec<_> = light.compared.iter().map(|c| c.0).collect();
        assert_eq!(names, ["hemisphere", "cosine", "bsdf", "light"]);
        assert_eq!(light.compared[3].1, light.luminance);
        assert_eq!(cosine.compared[1].1, cosine.luminance);
        for (name, mean, error, _) in &light.compared {
            let se = (error * error + light.std_error.powi(2)).sqrt();
            assert!(
                (mean - l).abs() < 4.0 * se.max(1e-12),
                "{name}: {mean} against {l}"
            );
        }
        // A pixel outside the box sees nothing.
        let none = sample_view(
            &scene,
            &Request {
                pixel: [0, 0],
                strategy: SampleStrategy::Light,
                n: 4,
            },
        );
        assert!(none.origin.is_none() && none.samples.is_empty());
    }
}
