//! What the page can change while the render runs: the integrator and its strategy, the
//! depth, the sampler, the exposure and the camera's orbit, and the messages that change them.

use glam::{Mat3, Vec3};
use pathlab_mc::sampler::SamplerKind;
use pathlab_render::desc::{CameraDesc, RenderHints};
use pathlab_render::integrator::{
    BdptIntegrator, DebugView, DirectIntegrator, DirectStrategy, IntegratorKind, PathIntegrator,
};
use serde_json::{json, Value};

/// The settings the page controls.
#[derive(Clone, Debug, PartialEq)]
pub struct Controls {
    /// "path", "bdpt", "direct", or a debug view: "normals", "depth", "bvh" (nodes visited per
    /// camera ray, shown as a heat map over its range).
    pub integrator: String,
    /// The direct integrator's strategy.
    pub direct: DirectStrategy,
    /// The path tracer's largest bounce.
    pub max_depth: u32,
    /// The path tracer's bounce from which Russian roulette may end paths.
    pub rr_depth: u32,
    /// Only the light of this bounce (0: emission seen directly, 1: direct lighting, ...).
    pub only_bounce: Option<u32>,
    /// Light samples per vertex (the direct integrator's per camera ray).
    pub light_samples: u32,
    /// Where the random numbers come from.
    pub sampler: SamplerKind,
    /// Stops of exposure before the sRGB encoding of the frames sent.
    pub exposure: f32,
    /// What the frames show: "image", or a heat map of "variance" (of a sample's luminance),
    /// "relative_error" (of the pixel's mean) or "samples" (per pixel).
    pub display: String,
    /// Degrees of the camera's orbit about its target: around the up axis, and up or down.
    pub orbit: [f32; 2],
    /// The camera's distance to its target relative to the scene's.
    pub zoom: f32,
    /// How far the camera and its target have moved sideways and up (in the view's plane),
    /// in units of their distance.
    pub pan: [f32; 2],
    /// Whether camera rays do not see emitters (the scene's choice; not switchable).
    pub hide_emitters: bool,
}

impl Default for Controls {
    fn default() -> Self {
        Controls {
            integrator: "path".into(),
            direct: DirectStrategy::Mis,
            max_depth: 5,
            rr_depth: 5,
            only_bounce: None,
            light_samples: 1,
            sampler: SamplerKind::Independent,
            exposure: 0.0,
            display: "image".into(),
            orbit: [0.0, 0.0],
            zoom: 1.0,
            pan: [0.0, 0.0],
            hide_emitters: false,
        }
    }
}

impl Controls {
    /// The defaults, with what the scene file asks for: its largest bounce (an unbounded one
    /// as 1000, the most the page offers), Russian-roulette depth, sampler and hidden emitters.
    pub fn for_scene(hints: &RenderHints) -> Controls {
        let d = Controls::default();
        Controls {
            max_depth: hints.max_depth.map_or(d.max_depth, |m| m.clamp(1, 1000)),
            rr_depth: hints.rr_depth.map_or(d.rr_depth, |r| r.min(1000)),
            sampler: hints.sampler.unwrap_or(d.sampler),
            hide_emitters: hints.hide_emitters,
            ..d
        }
    }

    /// Applies a message of the page: a JSON object of settings (`integrator`, `direct`,
    /// `max_depth`, `sampler`, `exposure`, `display`), an `orbit` step `[yaw, pitch]` in
    /// degrees or a `zoom` factor. Returns whether the image must restart (the exposure and
    /// the display do not change the samples); an unknown setting or a bad value is an error,
    /// and nothing changes.
    pub fn apply(&mut self, message: &str) -> Result<bool, String> {
        let v: Value =
            serde_json::from_str(message).map_err(|e| format!("not a JSON message: {e}"))?;
        let Some(fields) = v.as_object() else {
            return Err("expected a JSON object of settings".into());
        };
        let mut next = self.clone();
        for (key, value) in fields {
            let bad = || format!("{key}: {value} is not a valid value");
            match key.as_str() {
                "integrator" => match value.as_str() {
                    Some(s @ ("path" | "bdpt" | "direct" | "normals" | "depth" | "bvh")) => {
                        next.integrator = s.to_string()
                    }
                    _ => {
                        return Err(format!(
                            "integrator: expected path, bdpt, direct, normals, depth or bvh, got {value}"
                        ))
                    }
                },
                "rr_depth" => {
                    next.rr_depth = value
                        .as_u64()
                        .filter(|&d| d <= 1000)
                        .ok_or_else(|| format!("rr_depth: expected 0 to 1000, got {value}"))?
                        as u32
                }
                "only_bounce" => {
                    next.only_bounce = match value {
                        Value::Null => None,
                        v => Some(v.as_u64().filter(|&k| k <= 1000).ok_or_else(|| {
                            format!("only_bounce: expected 0 to 1000 or null, got {value}")
                        })? as u32),
                    }
                }
                "light_samples" => {
                    next.light_samples = value
                        .as_u64()
                        .filter(|&n| (1..=256).contains(&n))
                        .ok_or_else(|| format!("light_samples: expected 1 to 256, got {value}"))?
                        as u32
                }
                "direct" => {
                    next.direct = value
                        .as_str()
                        .ok_or_else(bad)?
                        .parse()
                        .map_err(|e: String| format!("direct: {e}"))?
                }
                "max_depth" => {
                    next.max_depth = value
                        .as_u64()
                        .filter(|&d| (1..=1000).contains(&d))
                        .ok_or_else(|| format!("max_depth: expected 1 to 1000, got {value}"))?
                        as u32
                }
                "sampler" => {
                    next.sampler = value
                        .as_str()
                        .ok_or_else(bad)?
                        .parse()
                        .map_err(|e: String| format!("sampler: {e}"))?
                }
                "exposure" => {
                    next.exposure = value
                        .as_f64()
                        .filter(|e| e.is_finite() && e.abs() <= 20.0)
                        .ok_or_else(|| format!("exposure: expected -20 to 20 stops, got {value}"))?
                        as f32
                }
                "display" => match value.as_str() {
                    Some(d @ ("image" | "variance" | "relative_error" | "samples")) => {
                        next.display = d.to_string()
                    }
                    _ => {
                        return Err(format!(
                            "display: expected \"image\", \"variance\", \"relative_error\" or \"samples\", got {value}"
                        ))
                    }
                },
                "orbit" => {
                    let step = finite_pair(value).ok_or_else(|| {
                        format!("orbit: expected [yaw, pitch] in degrees, got {value}")
                    })?;
                    next.orbit[0] = (next.orbit[0] + step[0] as f32).rem_euclid(360.0);
                    next.orbit[1] = (next.orbit[1] + step[1] as f32).clamp(-85.0, 85.0);
                }
                "pan" => {
                    let step = finite_pair(value).ok_or_else(|| {
                        format!("pan: expected [right, up] in view widths, got {value}")
                    })?;
                    for (p, d) in next.pan.iter_mut().zip(step) {
                        *p = (*p + d as f32).clamp(-10.0, 10.0);
                    }
                }
                "zoom" => {
                    let f = value
                        .as_f64()
                        .filter(|f| f.is_finite() && *f > 0.0)
                        .ok_or_else(|| format!("zoom: expected a positive factor, got {value}"))?;
                    next.zoom = (next.zoom * f as f32).clamp(0.05, 20.0);
                }
                other => return Err(format!("unknown setting '{other}'")),
            }
        }
        let restart = Controls {
            exposure: self.exposure,
            display: self.display.clone(),
            ..next.clone()
        } != *self;
        *self = next;
        Ok(restart)
    }

    /// The integrator these settings choose.
    pub fn integrator(&self) -> IntegratorKind {
        match self.integrator.as_str() {
            "direct" => IntegratorKind::Direct(DirectIntegrator {
                strategy: self.direct,
                samples: self.light_samples,
                hide_emitters: self.hide_emitters,
                ..Default::default()
            }),
            "bdpt" => IntegratorKind::Bdpt(BdptIntegrator {
                max_depth: self.max_depth,
                rr_depth: self.rr_depth,
                hide_emitters: self.hide_emitters,
            }),
            "normals" => IntegratorKind::Debug(DebugView::Normals),
            "depth" => IntegratorKind::Debug(DebugView::Depth),
            "bvh" => IntegratorKind::Debug(DebugView::BvhHeat),
            _ => IntegratorKind::Path(PathIntegrator {
                max_depth: self.max_depth,
                rr_depth: self.rr_depth,
                only_bounce: self.only_bounce,
                light_samples: self.light_samples,
                hide_emitters: self.hide_emitters,
                ..Default::default()
            }),
        }
    }

    /// `camera` orbited about its target by [`Controls::orbit`], moved by the zoom and
    /// panned.
    pub fn camera(&self, camera: &CameraDesc) -> CameraDesc {
        let up = camera.up.normalize_or(Vec3::Y);
        let offset = camera.origin - camera.target;
        let right = offset.cross(up).normalize_or(Vec3::X);
        let [yaw, pitch] = self.orbit.map(f32::to_radians);
        let turn = Mat3::from_axis_angle(up, yaw) * Mat3::from_axis_angle(right, pitch);
        let origin = camera.target + turn * offset * self.zoom;
        let up = turn * up;
        // Panning moves the camera and its target together, across the view.
        let forward = camera.target - origin;
        let side = forward.cross(up).normalize_or_zero();
        let lift = side.cross(forward).normalize_or_zero();
        let shift = (self.pan[0] * side + self.pan[1] * lift) * forward.length();
        CameraDesc {
            origin: origin + shift,
            target: camera.target + shift,
            up,
            ..*camera
        }
    }

    /// The settings as the page shows them.
    pub fn to_json(&self) -> Value {
        json!({
            "integrator": self.integrator,
            "direct": self.direct.name(),
            "max_depth": self.max_depth,
            "rr_depth": self.rr_depth,
            "only_bounce": self.only_bounce,
            "light_samples": self.light_samples,
            "sampler": self.sampler.name(),
            "exposure": self.exposure,
            "display": self.display,
            "orbit": self.orbit,
            "zoom": self.zoom,
            "pan": self.pan,
        })
    }
}

/// `[a, b]` of two finite numbers.
fn finite_pair(value: &serde_json::Value) -> Option<[f64; 2]> {
    value
        .as_array()
        .filter(|a| a.len() == 2)
        .and_then(|a| Some([a[0].as_f64()?, a[1].as_f64()?]))
        .filter(|s| s.iter().all(|x| x.is_finite()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_change_atomically_and_only_samples_restart_the_image() {
        let mut c = Controls::default();
        assert_eq!(c.apply(r#"{"exposure": 1.5}"#), Ok(false));
        assert_eq!(c.exposure, 1.5);
        assert_eq!(
            c.apply(r#"{"integrator": "direct", "direct": "cosine"}"#),
            Ok(true)
        );
        assert_eq!(c.direct, DirectStrategy::Cosine);
        // One bad field and nothing changes.
        let before = c.clone();
        assert!(c.apply(r#"{"max_depth": 3, "sampler": "magic"}"#).is_err());
        assert_eq!(c, before);
        assert!(c.apply("[1, 2]").unwrap_err().contains("JSON object"));
        // The orbit accumulates, its pitch stays short of the poles.
        c.apply(r#"{"orbit": [350, 80]}"#).unwrap();
        c.apply(r#"{"orbit": [20, 20]}"#).unwrap();
        assert_eq!(c.orbit, [10.0, 85.0]);
        assert!(c.apply(r#"{"zoom": -1}"#).is_err());
        // The path tracer's course settings, and the debug views.
        c.apply(r#"{"integrator": "path", "only_bounce": 2, "rr_depth": 0, "light_samples": 4}"#)
            .unwrap();
        match c.integrator() {
            IntegratorKind::Path(p) => {
                assert_eq!(
                    (p.only_bounce, p.rr_depth, p.light_samples),
                    (Some(2), 0, 4)
                )
            }
            other => panic!("{other:?}"),
        }
        c.apply(r#"{"only_bounce": null, "integrator": "bvh"}"#)
            .unwrap();
        assert_eq!(c.only_bounce, None);
        assert!(matches!(
            c.integrator(),
            IntegratorKind::Debug(DebugView::BvhHeat)
        ));
        assert!(c.apply(r#"{"light_samples": 0}"#).is_err());
        assert!(c.apply(r#"{"integrator": "mlt"}"#).is_err());
        // The bidirectional path tracer takes the depths.
        c.apply(r#"{"integrator": "bdpt", "max_depth": 4}"#)
            .unwrap();
        match c.integrator() {
            IntegratorKind::Bdpt(b) => assert_eq!((b.max_depth, b.rr_depth), (4, 0)),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_scenes_depth_sampler_and_hidden_emitters_are_the_starting_controls() {
        let hints = RenderHints {
            max_depth: Some(3),
            rr_depth: Some(2),
            sampler: Some(SamplerKind::Sobol),
            hide_emitters: true,
            ..Default::default()
        };
        let c = Controls::for_scene(&hints);
        assert_eq!(
            (c.max_depth, c.rr_depth, c.sampler),
            (3, 2, SamplerKind::Sobol)
        );
        match c.integrator() {
            IntegratorKind::Path(p) => assert!(p.hide_emitters && p.max_depth == 3),
            other => panic!("{other:?}"),
        }
        let unbounded = RenderHints {
            max_depth: Some(u32::MAX),
            ..Default::default()
        };
        assert_eq!(Controls::for_scene(&unbounded).max_depth, 1000);
        assert_eq!(
            Controls::for_scene(&RenderHints::default()),
            Controls::default()
        );
    }

    #[test]
    fn the_orbit_keeps_the_target_and_the_distance() {
        let camera = CameraDesc {
            origin: Vec3::new(0.0, 1.0, 5.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            ..Default::default()
        };
        let mut c = Controls::default();
        c.apply(r#"{"orbit": [90, 30]}"#).unwrap();
        let moved = c.camera(&camera);
        assert_eq!(moved.target, camera.target);
        assert!(((moved.origin - moved.target).length() - 5.0).abs() < 1e-4);
        assert!(moved.origin.y > 1.0 + 1.0, "pitched up: {}", moved.origin);
        c.apply(r#"{"zoom": 0.5}"#).unwrap();
        assert!(((c.camera(&camera).origin - camera.target).length() - 2.5).abs() < 1e-4);
    }

    #[test]
    fn panning_moves_the_camera_and_its_target_across_the_view() {
        let camera = CameraDesc {
            origin: Vec3::new(0.0, 1.0, 5.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            ..Default::default()
        };
        let mut c = Controls::default();
        assert!(
            c.apply(r#"{"pan": [0.1, 0.2]}"#).unwrap(),
            "a pan restarts the image"
        );
        let moved = c.camera(&camera);
        // Looking down -z with +y up, right is +x: 0.1 and 0.2 of the distance 5.
        let shift = Vec3::new(0.5, 1.0, 0.0);
        assert!(
            (moved.target - (camera.target + shift)).length() < 1e-5,
            "{moved:?}"
        );
        assert!((moved.origin - (camera.origin + shift)).length() < 1e-5);
        assert!(c.apply(r#"{"pan": [1]}"#).is_err());
        assert!(c.apply(r#"{"pan": [1, "up"]}"#).is_err());
    }
}
