//! An integrator chosen by name ([`IntegratorName`]) with settings given or left to the scene
//! file's hints ([`IntegratorChoice`]): what `pathlab render`'s flags, the viewer and the
//! Python module's `render` arguments all turn into an [`IntegratorKind`].

use super::{
    BdptIntegrator, DebugView, DirectIntegrator, DirectStrategy, IntegratorKind, PathIntegrator,
    PathLighting,
};
use crate::desc::{IntegratorHint, RenderHints};
use pathlab_mc::named::by_name;

/// The integrators by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorName {
    /// Path tracing with next-event estimation, MIS and Russian roulette.
    Path,
    /// Bidirectional path tracing.
    Bdpt,
    /// Direct lighting only, by a [`DirectStrategy`].
    Direct,
    /// Debug view: shading normals.
    Normals,
    /// Debug view: distance to the first surface.
    Depth,
    /// Debug view: BVH nodes visited per camera ray.
    Bvh,
}

impl IntegratorName {
    /// Every integrator.
    pub const ALL: [IntegratorName; 6] = [
        IntegratorName::Path,
        IntegratorName::Bdpt,
        IntegratorName::Direct,
        IntegratorName::Normals,
        IntegratorName::Depth,
        IntegratorName::Bvh,
    ];

    /// The name used on command lines and in Python.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorName::Path => "path",
            IntegratorName::Bdpt => "bdpt",
            IntegratorName::Direct => "direct",
            IntegratorName::Normals => "normals",
            IntegratorName::Depth => "depth",
            IntegratorName::Bvh => "bvh",
        }
    }
}

impl std::str::FromStr for IntegratorName {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        by_name(s, &IntegratorName::ALL, IntegratorName::name, "integrator")
    }
}

/// What the user asked of the integrator; `None` leaves a setting to the scene file's hints
/// (and then to the default).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegratorChoice {
    /// Which integrator (`None`: the one the scene file names, else the path tracer).
    pub name: Option<IntegratorName>,
    /// Longest path in bounces (`None`: the file's, else unbounded).
    pub max_depth: Option<u32>,
    /// First bounce where Russian roulette may end a path (`None`: the file's, else 5).
    pub rr_depth: Option<u32>,
    /// Only the light of this bounce (path tracer).
    pub only_bounce: Option<u32>,
    /// Light samples per surface point.
    pub light_samples: u32,
    /// How the path tracer finds light at each vertex.
    pub lighting: PathLighting,
    /// The direct-lighting strategy (`None`: MIS).
    pub direct: Option<DirectStrategy>,
}

impl Default for IntegratorChoice {
    fn default() -> Self {
        IntegratorChoice {
            name: None,
            max_depth: None,
            rr_depth: None,
            only_bounce: None,
            light_samples: 1,
            lighting: PathLighting::Mis,
            direct: None,
        }
    }
}

impl IntegratorChoice {
    /// The longest path: the choice's, the file's, else unbounded (`u32::MAX`).
    pub fn max_depth(&self, hints: &RenderHints) -> u32 {
        self.max_depth.or(hints.max_depth).unwrap_or(u32::MAX)
    }

    /// The integrator, and its name. Direct lighting that the file names (and the choice does
    /// not) is the file's: its light and BSDF sample counts combined by MIS.
    pub fn integrator(&self, hints: &RenderHints) -> (IntegratorName, IntegratorKind) {
        let name = self.name.unwrap_or(match hints.integrator {
            Some(IntegratorHint::Direct { .. }) => IntegratorName::Direct,
            Some(IntegratorHint::Bdpt) => IntegratorName::Bdpt,
            _ => IntegratorName::Path,
        });
        let kind = match name {
            IntegratorName::Direct if self.name.is_none() => IntegratorKind::from_hints(hints),
            IntegratorName::Path => IntegratorKind::Path(PathIntegrator {
                max_depth: self.max_depth(hints),
                rr_depth: self.rr_depth.or(hints.rr_depth).unwrap_or(5),
                hide_emitters: hints.hide_emitters,
                only_bounce: self.only_bounce,
                light_samples: self.light_samples,
                lighting: self.lighting,
            }),
            IntegratorName::Bdpt => IntegratorKind::Bdpt(BdptIntegrator {
                max_depth: self.max_depth(hints),
                rr_depth: self.rr_depth.or(hints.rr_depth).unwrap_or(5),
                hide_emitters: hints.hide_emitters,
            }),
            IntegratorName::Direct => IntegratorKind::Direct(DirectIntegrator {
                strategy: self.direct.unwrap_or(DirectStrategy::Mis),
                samples: self.light_samples,
                hide_emitters: hints.hide_emitters,
                ..Default::default()
            }),
            IntegratorName::Normals => IntegratorKind::Debug(DebugView::Normals),
            IntegratorName::Depth => IntegratorKind::Debug(DebugView::Depth),
            IntegratorName::Bvh => IntegratorKind::Debug(DebugView::BvhHeat),
        };
        (name, kind)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_names_say_what_exists() {
        for n in IntegratorName::ALL {
            assert_eq!(n.name().parse::<IntegratorName>(), Ok(n));
        }
        let e = "pathh".parse::<IntegratorName>().unwrap_err();
        assert!(e.contains("'pathh'") && e.contains("direct"), "{e}");
    }

    #[test]
    fn the_file_fills_what_the_choice_leaves_open() {
        let hints = RenderHints {
            max_depth: Some(3),
            rr_depth: Some(2),
            ..Default::default()
        };
        let (name, kind) = IntegratorChoice::default().integrator(&hints);
        assert_eq!(name, IntegratorName::Path);
        let IntegratorKind::Path(p) = kind else {
            panic!("{kind:?}")
        };
        assert_eq!((p.max_depth, p.rr_depth), (3, 2));
        let choice = IntegratorChoice {
            max_depth: Some(7),
            ..Default::default()
        };
        let IntegratorKind::Path(p) = choice.integrator(&hints).1 else {
            panic!()
        };
        assert_eq!((p.max_depth, p.rr_depth), (7, 2));
        let (_, kind) = IntegratorChoice::default().integrator(&RenderHints::default());
        let IntegratorKind::Path(p) = kind else {
            panic!()
        };
        assert_eq!((p.max_depth, p.rr_depth), (u32::MAX, 5));
    }

    #[test]
    fn direct_lighting_the_file_names_keeps_its_sample_counts() {
        let hints = RenderHints {
            integrator: Some(IntegratorHint::Direct {
                emitter_samples: 3,
                bsdf_samples: 2,
            }),
            ..Default::default()
        };
        let (name, kind) = IntegratorChoice::default().integrator(&hints);
        assert_eq!(name, IntegratorName::Direct);
        assert_eq!(kind, IntegratorKind::from_hints(&hints));
        let choice = IntegratorChoice {
            name: Some(IntegratorName::Direct),
            direct: Some(DirectStrategy::Cosine),
            ..Default::default()
        };
        let IntegratorKind::Direct(d) = choice.integrator(&hints).1 else {
            panic!()
        };
        assert_eq!((d.strategy, d.samples), (DirectStrategy::Cosine, 1));
    }
}
