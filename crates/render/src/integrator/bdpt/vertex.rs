//! The vertices of the bidirectional path tracer's subpaths, and the change of a direction's
//! density into a density per unit area at the vertex it reaches.

use crate::bsdf::Bsdf;
use crate::desc::Rgb;
use crate::scene::SurfaceInteraction;
use glam::Vec3;

/// What a subpath vertex is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Kind {
    /// The lens.
    Camera,
    /// A point on a light: a light subpath's start, or one sampled for s = 1.
    Light,
    /// A surface point (possibly on an emitter: `light` is then set).
    Surface,
    /// A camera ray that left the scene, or a light at infinity: `p` holds the direction.
    Infinite,
}

/// A subpath vertex.
#[derive(Clone, Copy, Debug)]
pub(super) struct Vertex {
    pub(super) kind: Kind,
    /// Position (the direction for [`Kind::Infinite`]).
    pub(super) p: Vec3,
    /// Geometric normal, for points on surfaces.
    pub(super) n: Option<Vec3>,
    /// The light it lies on (or, at infinity, comes from).
    pub(super) light: Option<u32>,
    /// Throughput from the subpath's start to here (for a sampled light vertex, its radiance
    /// over its density).
    pub(super) beta: Rgb,
    /// Density per unit area with which its own subpath produced it.
    pub(super) pdf_fwd: f32,
    /// Density per unit area with which the other direction would have produced it.
    pub(super) pdf_rev: f32,
    /// Whether the subpath left it through a delta lobe.
    pub(super) delta: bool,
    /// Direction to the vertex before it on its subpath.
    pub(super) wo: Vec3,
    /// The surface point and its BSDF (surfaces only).
    pub(super) surface: Option<(SurfaceInteraction, Bsdf)>,
}

impl Vertex {
    pub(super) fn endpoint(
        kind: Kind,
        p: Vec3,
        n: Option<Vec3>,
        light: Option<u32>,
        beta: Rgb,
    ) -> Self {
        Vertex {
            kind,
            p,
            n,
            light,
            beta,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            delta: false,
            wo: Vec3::ZERO,
            surface: None,
        }
    }

    /// The BSDF of a surface vertex a connection can pass through (one with a lobe that is not
    /// a delta).
    pub(super) fn connectible(&self) -> Option<&(SurfaceInteraction, Bsdf)> {
        self.surface.as_ref().filter(|(_, b)| !b.is_delta())
    }

    /// Density per unit solid angle `pdf` of the direction from here to `next`, per unit area
    /// at `next` (unchanged towards infinity).
    pub(super) fn convert_density(&self, pdf: f32, next: &Vertex) -> f32 {
        if next.kind == Kind::Infinite {
            return pdf;
        }
        let w = next.p - self.p;
        let d2 = w.length_squared();
        if d2 == 0.0 {
            return 0.0;
        }
        let cos = next.n.map_or(1.0, |n| n.dot(w).abs() / d2.sqrt());
        pdf * cos / d2
    }

    /// Unit direction from here to `other`.
    pub(super) fn towards(&self, other: &Vertex) -> Vec3 {
        match other.kind {
            Kind::Infinite => other.p,
            _ => (other.p - self.p).normalize_or_zero(),
        }
    }
}
