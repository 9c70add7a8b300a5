//! What planning produces: the joined trajectory and one report per segment, the data that
//! the CLI's summary table, the MCAP annotations and the Python `Plan` are made from.

use crate::decompose::{ActionType, SegmentPattern};
use crate::language::{Measure, SolverChoice, Space, Variable};
use crate::math::{Real, UnitQuaternion, Vector3};
use crate::solve::map::MapSummary;
use crate::spelling::spelled;
use crate::trajectory::{CapsuleDistances, Clearance, Trajectory};

/// How close a goal must be reached.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Tolerance {
    /// Position error (m), default 1 mm.
    pub position: Real,
    /// Rotation (geodesic) and angle error (rad), default 1°.
    pub angle: Real,
}

impl Tolerance {
    /// The tolerance of `variable`, by what its errors [measure](Variable::measure):
    /// [`Self::position`] for a length (m), [`Self::angle`] for an angle (rad).
    pub fn of(&self, variable: Variable) -> Real {
        match variable.measure() {
            Measure::Length => self.position,
            Measure::Angle => self.angle,
        }
    }
}

impl Default for Tolerance {
    fn default() -> Self {
        Self {
            position: Measure::Length.default_tolerance(),
            angle: Measure::Angle.default_tolerance(),
        }
    }
}

/// The final error of one state variable of a segment: distance (m) for Pw, geodesic angle
/// for Ow and Os, absolute angle difference for θsw and θe (rad).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct VariableError {
    /// The variable.
    pub variable: Variable,
    /// Its error at the segment's end (m or rad).
    pub error: Real,
    /// Whether it is within the tolerance.
    pub within: bool,
}

/// Why `auto` went on from the QP to the constrained RRT on a segment with a path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fallback {
    /// The QP stopped making progress short of the goal.
    QpStalled,
    /// The QP's time ran out short of the goal.
    QpMissedGoal,
    /// The QP left the segment's hard path.
    QpLeftPath,
}

spelled!(Fallback, "fallback", [Fallback::QpStalled, Fallback::QpMissedGoal, Fallback::QpLeftPath]);

impl Fallback {
    /// As a sentence: `the QP stalled`.
    pub fn describe(self) -> &'static str {
        match self {
            Self::QpStalled => "the QP stalled",
            Self::QpMissedGoal => "the QP missed the goal",
            Self::QpLeftPath => "the QP left the hard path",
        }
    }
}

/// Counters and timings of the velocity QP over one segment. The wall-clock timings are not
/// serialised (they read back as 0): plan files hold only what the same task and seed
/// reproduce.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct QpStats {
    /// Control steps taken.
    pub steps: usize,
    /// Steps that needed Clarabel: the exact dual active-set method found the step's
    /// constraints infeasible (Clarabel confirms it or solves the step) or degenerate (see
    /// [`crate::solve::qp`]).
    pub clarabel_steps: usize,
    /// Of those, the steps Clarabel ended `almost_solved` (see [`crate::solve::qp`] on why they
    /// are accepted).
    pub clarabel_almost_solved: usize,
    /// Mean wall time of a step (s): Jacobian, distances and the solve.
    #[serde(skip)]
    pub mean_step_time: Real,
    /// Longest step (s).
    #[serde(skip)]
    pub worst_step_time: Real,
    /// Median time of the steps solved without Clarabel (s): the weighted least-squares step,
    /// or the active-set step on it when a bound or row binds.
    #[serde(skip)]
    pub median_fast_time: Real,
    /// Median time of the steps that needed Clarabel (s); 0 when none did.
    #[serde(skip)]
    pub median_clarabel_time: Real,
}

/// One movement segment as solved.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SegmentReport {
    /// The action's name.
    pub action: String,
    /// The action's index in `Task::actions`.
    pub action_index: usize,
    /// The segment's index within its action (0-based).
    pub segment: usize,
    /// The action's type (`None` for an action written as explicit segments).
    pub action_type: Option<ActionType>,
    /// CPSA or HAT.
    pub space: Space,
    /// 1, 2 or 3.
    pub pattern: SegmentPattern,
    /// The solver that produced the segment's motion (never `Auto`).
    pub solver: SolverChoice,
    /// The focus of interest: the variables of the segment's featured primitive.
    pub focus: Vec<Variable>,
    /// Start in the plan's time (s).
    pub start: Real,
    /// End in the plan's time (s), settling included.
    pub end: Real,
    /// The segment's own duration before joining (s).
    pub duration: Real,
    /// Time the solver ran past the reference's end to settle on the goal (s).
    pub settle: Real,
    /// Final error of every variable of the segment's space.
    pub errors: Vec<VariableError>,
    /// Largest distance of each path variable (paths and holds) from its path over the
    /// segment: from the path's locus, whatever the timing along it (see
    /// [`crate::solve::constrained_rrt::Chart::deviation`]).
    pub path_errors: Vec<VariableError>,
    /// Whether the path is a hard constraint (an action of type IV or VI).
    pub hard_path: bool,
    /// Whether the path was kept within tolerance throughout; always true for a soft path,
    /// which may give way.
    pub path_kept: bool,
    /// Smallest clearance over the segment's samples, if there is any pair to measure.
    pub clearance: Option<Clearance>,
    /// Smallest distance of any joint to its position limits over the segment (rad).
    pub limit_margin: Real,
    /// Whether the solver stopped making progress short of the goal.
    pub stalled: bool,
    /// Whether every variable is within the tolerance at the end.
    pub reached: bool,
    /// QP counters and timings (zero when another solver ran).
    pub qp: QpStats,
    /// RRT counters, when the RRT solved the segment.
    pub rrt: Option<crate::solve::rrt::RrtStats>,
    /// Why `auto` went on from the QP to the solver that produced the segment.
    pub fallback: Option<Fallback>,
    /// The largest |q'_i| / velocity limit_i over the segment's time in the output, at every
    /// instant of its curve.
    pub peak_velocity_ratio: Real,
    /// The largest |q̈_i| / acceleration limit_i over the segment's time in the output.
    pub peak_acceleration_ratio: Real,
    /// Whether the output holds every position, velocity and acceleration limit over the
    /// segment's time.
    pub limits_kept: bool,
    /// The factor the segment was slowed down by to keep the limits (1: as solved).
    pub slowed_down: Real,
    /// The normalised jerk of the joints' motion over the segment's time in the output
    /// (dimensionless; a minimum-jerk movement scores about 19).
    pub joint_jerk: Real,
    /// The normalised jerk of the wrist's path over the segment's time in the output.
    pub wrist_jerk: Real,
    /// The number of peaks of the speed of the segment's featured variable (the first of its
    /// focus) over the segment as solved: 1 for a human-like movement (paper Rule 5).
    pub speed_peaks: usize,
}

/// A planned task: the whole joint trajectory at the output rate and what each segment did.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Plan {
    /// The task's name.
    pub task: String,
    /// Joint names, in the order of q.
    pub joint_names: Vec<String>,
    /// Output rate (Hz).
    pub rate: Real,
    /// Time (s), q (rad), q' (rad/s), at `rate`, segments joined (+Tr within an action, +Se
    /// between actions).
    pub trajectory: Trajectory,
    /// One report per segment, in time order.
    pub segments: Vec<SegmentReport>,
    /// The reference wrist path Pw(t) in {b} (m) at `rate`, in the plan's time: what the
    /// segments were asked to follow, to compare with the planned one.
    pub wrist_reference: Vec<(Real, Vector3)>,
    /// The safety distance the solvers kept from obstacles (m).
    pub safety_distance: Real,
    /// Goals missed beyond tolerance, solver fallbacks and repairs, each with the action and
    /// segment it names.
    pub warnings: Vec<Warning>,
    /// What the running segment asked for at each sample of `trajectory` (empty without a
    /// segment): its references at that instant, slowed as the segment was, held at their
    /// ends past T.
    pub references: Vec<ReferenceSample>,
    /// Each segment's references at its end T, in the order of `segments`: its goals, the
    /// ends of its paths, its holds.
    pub reference_ends: Vec<ReferenceState>,
    /// The distance of every moving arm capsule to every obstacle at each sample.
    pub distances: Vec<CapsuleDistances>,
    /// The map and profile of every segment the swivel map solved, in segment order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub swivel_maps: Vec<SegmentSwivelMap>,
}

/// The swivel map a segment of the plan was solved on.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SegmentSwivelMap {
    /// Index in [`Plan::segments`].
    pub segment: usize,
    /// The map's cells and the profile chosen through them.
    #[serde(flatten)]
    pub map: MapSummary,
}

impl Plan {
    /// Whether every segment reached its goals within tolerance, kept its hard path and kept
    /// the joint limits.
    pub fn reached(&self) -> bool {
        self.segments.iter().all(|s| s.reached && s.path_kept && s.limits_kept)
    }
}

/// A state of the five variables as a reference gives it: the segment's own space from its
/// references, the other space mapped from them (`None` where the mapping is singular).
/// Rotations as unit quaternions, serialised `[x, y, z, w]`.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct ReferenceState {
    /// Pw in {b} (m).
    pub pw: Option<Vector3>,
    /// Ow in {b}.
    pub ow: Option<UnitQuaternion>,
    /// θsw (rad).
    pub swivel: Option<Real>,
    /// Os in {b}.
    pub shoulder_frame: Option<UnitQuaternion>,
    /// θe (rad).
    pub elbow_angle: Option<Real>,
}

/// The reference state at one sample of the plan and the segment it belongs to.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ReferenceSample {
    /// Index in [`Plan::segments`] of the segment running at the sample (the latest to start).
    pub segment: usize,
    /// Its references there.
    #[serde(flatten)]
    pub state: ReferenceState,
}

/// What a warning is about: the one spelling of its kind in JSON, MCAP and Python, where
/// warnings are filtered by it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningKind {
    /// An action starts closer to an obstacle than the safety distance (planned anyway, as
    /// asked).
    CloseStart,
    /// The robot's collision geometry is partly made up (skeleton capsules, unread meshes).
    CollisionGeometry,
    /// The RRT found no path, and the QP's result is kept.
    RrtFailed,
    /// The constrained RRT did no better than the QP, whose result is kept.
    RrtNoBetter,
    /// The HAMP motion exceeds a joint speed limit.
    HampOverSpeed,
    /// An RRT path was timed slower than the segment's duration to keep the limits.
    RrtSlowed,
    /// A segment was slowed down as a whole to keep the limits.
    SlowedDown,
    /// A +Tr blend was shortened to keep the limits.
    BlendShortened,
    /// The arm came closer to an obstacle than the safety distance.
    TooClose,
    /// A goal was missed beyond tolerance.
    MissedGoal,
    /// A hard path was left beyond tolerance.
    LeftPath,
    /// The output exceeds a joint limit.
    OverLimits,
}

spelled!(
    WarningKind,
    "warning kind",
    [
        WarningKind::CloseStart,
        WarningKind::CollisionGeometry,
        WarningKind::RrtFailed,
        WarningKind::RrtNoBetter,
        WarningKind::HampOverSpeed,
        WarningKind::RrtSlowed,
        WarningKind::SlowedDown,
        WarningKind::BlendShortened,
        WarningKind::TooClose,
        WarningKind::MissedGoal,
        WarningKind::LeftPath,
        WarningKind::OverLimits,
    ]
);

/// Something a plan did that its user should know: a goal missed, a fallback, a repair.
/// Typed so that JSON and Python can filter by kind, action and segment; rendered as text
/// ([`Warning::message`], `Display`) at the edges.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Warning {
    /// What it is about.
    pub kind: WarningKind,
    /// The action it names, if any (the robot's geometry names none).
    pub action: Option<String>,
    /// The segment it names within that action (0-based, as [`SegmentReport::segment`]), if
    /// it names one.
    pub segment: Option<usize>,
    /// The warning as one sentence, naming its action and segment (1-based) as the CLI prints
    /// it.
    pub message: String,
}

impl Warning {
    /// A warning about segment `segment` (0-based) of action `action`.
    pub fn on_segment(kind: WarningKind, action: &str, segment: usize, message: String) -> Self {
        Self { kind, action: Some(action.to_owned()), segment: Some(segment), message }
    }

    /// A warning about a whole action.
    pub fn on_action(kind: WarningKind, action: &str, message: String) -> Self {
        Self { kind, action: Some(action.to_owned()), segment: None, message }
    }

    /// A warning about the whole task.
    pub fn on_task(kind: WarningKind, message: String) -> Self {
        Self { kind, action: None, segment: None, message }
    }
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}
