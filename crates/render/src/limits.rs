//! The values a setting may take, in one place for every front end.
//!
//! Each rule returns the value, or what was expected of it ("must be ..."); the caller puts in
//! front the name it gave the setting and the value: `--fov 200: must be an angle between 0
//! and 180 degrees` on the command line, `camera['fov'] 200: ...` in Python. These are the
//! values that need no scene to be judged, refused before anything is loaded; what depends on
//! the scene (a scale that makes the image too large) is refused where the scene is edited.

/// What a rule expected, when a value broke it.
pub type Expected = &'static str;

fn rule<T>(value: T, holds: bool, expected: Expected) -> Result<T, Expected> {
    if holds {
        Ok(value)
    } else {
        Err(expected)
    }
}

/// Largest width or height of an image, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// An image's width and height.
pub fn resolution(size: [u32; 2]) -> Result<[u32; 2], Expected> {
    let side = 1..=MAX_IMAGE_SIDE;
    rule(
        size,
        side.contains(&size[0]) && side.contains(&size[1]),
        "width and height must be between 1 and 16384",
    )
}

/// Exposure in stops (PNG encoding).
pub fn exposure(stops: f32) -> Result<f32, Expected> {
    rule(stops, stops.is_finite(), "must be a finite number of stops")
}

/// A thin lens's aperture radius (0: a pinhole).
pub fn lens_radius(r: f32) -> Result<f32, Expected> {
    rule(r, r.is_finite() && r >= 0.0, "must be a finite number >= 0")
}

/// The distance in focus.
pub fn focal_distance(d: f32) -> Result<f32, Expected> {
    rule(d, d.is_finite() && d > 0.0, "must be a positive distance")
}

/// A field of view in degrees.
pub fn fov_degrees(deg: f32) -> Result<f32, Expected> {
    rule(
        deg,
        deg.is_finite() && deg > 0.0 && deg < 180.0,
        "must be an angle between 0 and 180 degrees",
    )
}

/// A factor on the image's size.
pub fn image_scale(f: f32) -> Result<f32, Expected> {
    rule(
        f,
        f.is_finite() && f > 0.0,
        "must be a positive factor such as 0.5 or 2",
    )
}

/// A factor on a light's radiance.
pub fn radiance_scale(s: f32) -> Result<f32, Expected> {
    rule(s, s.is_finite() && s >= 0.0, "must be a number >= 0")
}

/// A progressive render's target: the estimated relative RMSE of the image.
pub fn target_error(e: f64) -> Result<f64, Expected> {
    rule(
        e,
        e.is_finite() && e > 0.0,
        "must be a positive number such as 0.02",
    )
}

/// A time to render for, in seconds.
pub fn render_seconds(t: f64) -> Result<f64, Expected> {
    rule(
        t,
        t.is_finite() && t > 0.0,
        "must be a positive number of seconds",
    )
}

/// Seconds between checkpoints (0: after every pass).
pub fn checkpoint_seconds(t: f64) -> Result<f64, Expected> {
    rule(
        t,
        t.is_finite() && t >= 0.0,
        "must be a number of seconds >= 0",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_rule_takes_its_range_and_refuses_the_rest() {
        assert_eq!(resolution([1, MAX_IMAGE_SIDE]), Ok([1, MAX_IMAGE_SIDE]));
        assert!(resolution([0, 4]).is_err() && resolution([4, MAX_IMAGE_SIDE + 1]).is_err());
        let said = resolution([0, 0]).unwrap_err();
        assert!(said.contains(&MAX_IMAGE_SIDE.to_string()), "{said}");
        assert_eq!(exposure(-3.5), Ok(-3.5));
        assert!(exposure(f32::NAN).is_err() && exposure(f32::INFINITY).is_err());
        assert_eq!(lens_radius(0.0), Ok(0.0));
        assert!(lens_radius(-0.1).is_err() && lens_radius(f32::INFINITY).is_err());
        assert_eq!(focal_distance(2.0), Ok(2.0));
        assert!(focal_distance(0.0).is_err() && focal_distance(f32::NAN).is_err());
        assert_eq!(fov_degrees(179.0), Ok(179.0));
        assert!(fov_degrees(0.0).is_err() && fov_degrees(180.0).is_err());
        assert_eq!(image_scale(0.5), Ok(0.5));
        assert!(image_scale(0.0).is_err() && image_scale(-2.0).is_err());
        assert_eq!(radiance_scale(0.0), Ok(0.0));
        assert!(radiance_scale(-1.0).is_err() && radiance_scale(f32::NAN).is_err());
        assert_eq!(target_error(0.02), Ok(0.02));
        assert!(target_error(0.0).is_err() && target_error(f64::INFINITY).is_err());
        assert_eq!(render_seconds(0.5), Ok(0.5));
        assert!(render_seconds(0.0).is_err() && render_seconds(f64::NAN).is_err());
        assert_eq!(checkpoint_seconds(0.0), Ok(0.0));
        assert!(checkpoint_seconds(-1.0).is_err() && checkpoint_seconds(f64::NAN).is_err());
    }
}
