//! When a module leaves the sandbox (seed 000 §4.3.1, No-Surplus variant).
//!
//! The paper fixes *how many* modules the sandbox sends through each entry
//! point (exactly what the scaffold above needs) but not *when*. Two
//! readings, chosen in the scenario (`feed = "just-in-time" | "eager"`):
//!
//! * **just in time** (default): a module leaves so as to arrive when its
//!   component becomes buildable, and is delayed only as far as traffic
//!   forces. Every figure in `docs/scaffold.md` before `feed` existed was
//!   made this way.
//! * **eager**: the authors' implementation (VisibleSim 1aa66fe4,
//!   `scaffolding_csg`, `feedIncidentBranches`): every round each ground
//!   tile root inserts a module into each incident branch whose entry
//!   point's light pivot is green, as long as that branch's requirement is
//!   not met. Modules travel ahead of need and wait in the structure. The
//!   planner lets a module leave up to a window of steps before its
//!   just-in-time departure when that makes it arrive sooner: by default
//!   [`EAGER_WINDOW`], which does not bind; the scenario's `eager_window`
//!   narrows it, to study the readings between the two (0 is just in time
//!   except where traffic delays a departure).

/// How far ahead of its just-in-time departure an eager module may leave
/// (steps). Measured: 40 and 100 give the same step counts on pyramid
/// h = 6, cube-d6, cylinder-d6, half-sphere-d6 and the sandcastle (both
/// protocols), so the window does not bind; the cost of a wider one is
/// generation time (the sandcastle: 10 s just in time, 33 s at 40, 86 s at
/// 100, debug-profile tests).
pub const EAGER_WINDOW: usize = 48;

/// When modules leave the sandbox.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default)]
pub enum Feed {
    /// Leave so as to arrive when the component becomes buildable.
    #[default]
    JustInTime,
    /// Leave as early as the path allows, at most `window` steps before
    /// the just-in-time departure, as the authors' sandbox feeds its entry
    /// points.
    Eager { window: usize },
}

impl Feed {
    /// The authors' feeding, with the window that does not bind.
    pub const EAGER: Feed = Feed::Eager {
        window: EAGER_WINDOW,
    };

    /// Parses a scenario's `feed` parameter.
    pub fn parse(s: &str) -> Option<Feed> {
        match s {
            "just-in-time" => Some(Feed::JustInTime),
            "eager" => Some(Feed::EAGER),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Feed::JustInTime => "just-in-time",
            Feed::Eager { .. } => "eager",
        }
    }
}
