//! The time × swivel obstacle-avoidance map (METHODS.md §1, DESIGN.md §5 "map"): for a fixed
//! wrist motion (Pw(t), Ow(t)) every arm configuration is a cell (t, θsw); cells are forbidden
//! by joint limits, by obstacles against the arm's capsules, or by self-collision, and the
//! smoothest swivel profile through the free cells gives the joints by analytic IK.
//!
//! Entry points: [`build_map`] (the grid), [`plan_profile`] (the profile and its joints),
//! [`segment_map`] (both for one segment of a task), [`MapSummary`] (both as a plan keeps
//! them). Angles are periodic on [−π, π); cell j of N covers [−π + jΔθ, −π + (j+1)Δθ) and is
//! labelled at its centre.

mod grid;
mod profile;
pub mod sphere;
pub mod spline;
mod summary;
mod task;

pub use grid::{Cell, ColumnFault, ForbiddenInterval, SwivelMap, build_map};
pub use profile::{SwivelProfile, plan_profile};
pub use spline::{ClampedSpline, SplineError, chord_length_times};
pub use summary::{CellRun, MapSummary};
pub use task::{SegmentMap, SegmentMapError, map_segment, segment_map};

use crate::kinematics::KinematicsError;
use crate::language::{Space, Variable};
use crate::math::{JointVector, Real, Rotation3, Vector3};
use crate::profile::Role;
use crate::profile::{Reference, Sample};
use crate::solve::problem::SegmentProblem;

/// Settings of the map and its profile.
#[derive(Debug, Clone, PartialEq)]
pub struct MapOptions {
    /// Time samples over the segment, ends included (≥ 2).
    pub time_steps: usize,
    /// Angle cells over the full turn (≥ 8).
    pub angle_steps: usize,
    /// A cell closer than this to an obstacle, or a self-collision pair, is forbidden (m).
    pub safety_distance: Real,
    /// Largest swivel speed the profile search may use (rad/s).
    pub max_swivel_speed: Real,
    /// Weight of θsw'² in the profile cost.
    pub velocity_weight: Real,
    /// Weight of θsw''² in the profile cost.
    pub acceleration_weight: Real,
    /// Weight of the squared (wrapped) distance from the segment's own θsw reference.
    pub reference_weight: Real,
    /// Rate at which the smoothed profile is verified and its joints sampled (Hz).
    pub verify_rate: Real,
    /// Joint acceleration limits the verification also enforces (rad/s²); `None` checks
    /// positions and speeds only.
    pub acceleration_limits: Option<JointVector>,
}

impl Default for MapOptions {
    fn default() -> Self {
        Self {
            time_steps: 200,
            angle_steps: 360,
            safety_distance: 0.0,
            max_swivel_speed: 2.0,
            velocity_weight: 1.0,
            acceleration_weight: 0.01,
            reference_weight: 0.1,
            verify_rate: 1000.0,
            acceleration_limits: None,
        }
    }
}

/// Why a map or its profile cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapError {
    /// The options are out of range.
    #[error("invalid map options: {0}")]
    Options(&'static str),
    /// The arm has no analytic IK (the map needs the swivel to parametrise the self-motion).
    #[error("the map needs an arm with analytic IK (spherical shoulder and wrist)")]
    NotAnalytic,
    /// The segment does not fix the wrist: it is not in CPSA space.
    #[error("the map solves CPSA segments only (the wrist's Pw and Ow fix the motion)")]
    NotWristSegment,
    /// At some time the wrist pose itself cannot be held: unreachable, singular, or the hand
    /// collides at every swivel angle.
    #[error("path infeasible at t = {time:.3} s: {why}")]
    PathInfeasible {
        /// Time from the segment's start (s).
        time: Real,
        /// What rules the whole column out.
        why: String,
    },
    /// The free region does not connect the start to the end.
    #[error(
        "no swivel profile: the free region is cut at t = {time:.3} s (no free angle reachable \
         from the start within {speed:.2} rad/s)"
    )]
    NoProfile {
        /// The first time no free cell can be reached (s).
        time: Real,
        /// The swivel speed bound used (rad/s).
        speed: Real,
    },
    /// The start configuration's swivel angle is not usable.
    #[error("the start configuration: {0}")]
    Start(KinematicsError),
    /// The start configuration is already too close to an obstacle or itself.
    #[error(
        "the start configuration is {:.1} mm from the nearest obstacle or self-collision pair, \
         closer than the safety distance {:.1} mm",
        clearance * 1e3,
        safety * 1e3
    )]
    StartBlocked {
        /// Its clearance (m).
        clearance: Real,
        /// The safety distance (m).
        safety: Real,
    },
    /// Even the least smoothed profile fails the fine check.
    #[error("the swivel profile fails its check at t = {time:.4} s: {why}")]
    Verification {
        /// Time from the segment's start (s).
        time: Real,
        /// What failed.
        why: String,
    },
    /// A wrist path through points cannot be built.
    #[error(transparent)]
    Spline(#[from] SplineError),
}

/// Pw and Ow at one instant, with their rates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WristSample {
    /// Pw (m).
    pub pw: Vector3,
    /// Pw' (m/s).
    pub velocity: Vector3,
    /// Ow.
    pub ow: Rotation3,
    /// Angular velocity of Ow in {b} (rad/s).
    pub angular_velocity: Vector3,
}

/// A fixed wrist motion over [0, duration].
#[derive(Debug, Clone, PartialEq)]
pub enum WristMotion {
    /// Pw along a clamped cubic spline (e.g. through via points), Ow held.
    Through {
        /// Pw(t).
        pw: ClampedSpline<Vector3>,
        /// The held Ow.
        ow: Rotation3,
    },
    /// A CPSA segment's Pw and Ow references (goals, paths or holds).
    References {
        /// Pw's reference.
        pw: Reference,
        /// Ow's reference.
        ow: Reference,
    },
}

impl WristMotion {
    /// Pw through `points` (first = start, last = end) with chord-length knots over
    /// `duration`, at rest at both ends, Ow held at `ow`.
    ///
    /// # Errors
    /// [`MapError::Spline`] for fewer than two points, repeated points or a bad duration.
    pub fn through(points: &[Vector3], duration: Real, ow: Rotation3) -> Result<Self, MapError> {
        if !(duration.is_finite() && duration > 0.0) {
            return Err(MapError::Options("the wrist path's duration must be positive"));
        }
        let times = chord_length_times(points, duration);
        Ok(Self::Through { pw: ClampedSpline::at_rest(times, points.to_vec())?, ow })
    }

    /// The wrist motion of a CPSA segment.
    ///
    /// # Errors
    /// [`MapError::NotWristSegment`] for a HAT segment.
    pub fn of_problem(problem: &SegmentProblem) -> Result<Self, MapError> {
        let find = |v: Variable| problem.components.iter().find(|c| c.variable == v);
        match (problem.space, find(Variable::Pw), find(Variable::Ow)) {
            (Space::Cpsa, Some(pw), Some(ow)) => {
                Ok(Self::References { pw: pw.reference, ow: ow.reference })
            }
            _ => Err(MapError::NotWristSegment),
        }
    }

    /// The motion's duration (s).
    pub fn duration(&self) -> Real {
        match self {
            Self::Through { pw, .. } => pw.times().last().copied().unwrap_or(0.0),
            Self::References { pw, .. } => pw.duration(),
        }
    }

    /// Pw, Ow and their rates at `t`.
    pub fn at(&self, t: Real) -> WristSample {
        match self {
            Self::Through { pw, ow } => {
                let (p, v, _) = pw.sample(t);
                WristSample { pw: p, velocity: v, ow: *ow, angular_velocity: Vector3::zeros() }
            }
            Self::References { pw, ow } => {
                let (p, v) = match pw.sample(t) {
                    Sample::Position { value, velocity } => (value, velocity),
                    _ => (Vector3::zeros(), Vector3::zeros()),
                };
                let (r, w) = match ow.sample(t) {
                    Sample::Rotation { value, angular_velocity } => (value, angular_velocity),
                    _ => (Rotation3::identity(), Vector3::zeros()),
                };
                WristSample { pw: p, velocity: v, ow: r, angular_velocity: w }
            }
        }
    }
}

/// The swivel end a profile must meet, and the reference it should stay near.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SwivelTargets {
    /// θsw at the end (rad), or free.
    pub end: Option<Real>,
    /// θsw the profile should stay near at each map column (rad); empty for none.
    pub reference: Vec<Real>,
}

impl SwivelTargets {
    /// The targets of a segment: its θsw goal fixes the end; its θsw reference, sampled at the
    /// map's times, is the one to stay near.
    pub fn of_problem(problem: &SegmentProblem, times: &[Real]) -> Self {
        let Some(swivel) = problem.components.iter().find(|c| c.variable == Variable::Swivel)
        else {
            return Self::default();
        };
        let angle = |s: Sample| match s {
            Sample::Angle { value, .. } => value,
            _ => 0.0,
        };
        let end = match (swivel.role, swivel.reference.end()) {
            (Role::Goal, crate::language::Target::Angle(a)) => Some(a),
            _ => None,
        };
        Self { end, reference: times.iter().map(|&t| angle(swivel.reference.sample(t))).collect() }
    }
}
