//! # pathlab-render: the renderer core
//!
//! Geometry, the BVH, the camera, BSDFs, lights, integrators, the film and the parallel render
//! loop, built on [`pathlab_mc`].
//!
//! The path of one image: a [`desc::SceneDesc`] (plain data, from a loader) is built into a
//! [`scene::Scene`] (flattened shapes, BVH, lights); [`render::render`] runs an
//! [`integrator::Integrator`] for every pixel sample, tile by tile on all threads, into a
//! [`film::Film`] that keeps each pixel's sample count, mean and variance; [`image_io`] writes
//! the result.
//!
//! Conventions: linear RGB in `f32`; directions `wo`, `wi` point away from the surface; BSDF
//! values exclude the cosine; pdfs are per unit solid angle unless named `_area`; bounces are
//! counted as the course does (0 = emission seen directly, 1 = direct lighting).
//!
//! ```
//! use glam::Vec3;
//! use pathlab_render::desc::*;
//! use pathlab_render::integrator::{IntegratorKind, PathIntegrator};
//! use pathlab_render::render::{render, RenderSettings};
//! use pathlab_render::scene::{diffuse, Scene};
//! use pathlab_mc::sampler::SamplerKind;
//!
//! // A grey sphere under a white sky: at one bounce it reflects its albedo.
//! let desc = SceneDesc {
//!     spheres: vec![SphereDesc { center: Vec3::ZERO, radius: 1.0, ..Default::default() }],
//!     materials: vec![diffuse(Vec3::splat(0.5), false)],
//!     environment: Some(Vec3::ONE),
//!     camera: CameraDesc { origin: Vec3::new(0.0, 0.0, 5.0), fov_degrees: 5.0, ..Default::default() },
//!     resolution: [4, 4],
//!     ..Default::default()
//! };
//! let scene = Scene::build(&desc).unwrap();
//! let integrator = IntegratorKind::Path(PathIntegrator { max_depth: 1, ..Default::default() });
//! let settings = RenderSettings::new(256, 1, SamplerKind::Independent);
//! let (film, _) = render(&scene, &integrator, &settings, &|_| {}, &Default::default());
//! let m = film.image_mean();
//! assert!((m.x - 0.5).abs() < 4.0 * film.image_mean_std_error().x + 1e-6);
//! ```
#![deny(missing_docs)]

pub mod accel;
pub mod bsdf;
pub mod camera;
pub mod color;
pub mod desc;
pub mod film;
pub mod film_file;
pub mod film_image;
pub mod geometry;
pub mod image_io;
pub mod integrator;
pub mod light;
pub mod limits;
/// Environment maps (in [`light`]), by their old path.
pub use light::envmap;
pub mod progressive;
pub mod render;
pub mod scene;
pub mod sdf_grid;
pub mod shape;
pub use pathlab_mc::simd;
pub mod tev;
pub mod texture;

pub use pathlab_mc as mc;
