//! The validated task: SI units, typed variables, resolved paths. What the
//! decomposition and the solvers read.

use std::path::PathBuf;

use super::ast::Span;
use crate::math::{JointVector, Real, Rotation3, Vector3};
use crate::robot::{Robot, RobotError, RobotOptions};
use crate::spelling::spelled;

spelled!(Space, "space", [Space::Cpsa, Space::Hat]);
spelled!(Variable, "variable", Variable::ALL);
spelled!(
    SolverChoice,
    "solver",
    [
        SolverChoice::Auto,
        SolverChoice::Qp,
        SolverChoice::Rrt,
        SolverChoice::Map,
        SolverChoice::Gpm,
        SolverChoice::Clik,
        SolverChoice::Pmp,
        SolverChoice::Hamp,
    ]
);
spelled!(PositionFrame, "frame", [PositionFrame::Base, PositionFrame::Root]);

/// The two representation spaces (docs/design.md §3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Space {
    /// (Pw, Ow, θsw).
    Cpsa,
    /// (Os, θe, Ow).
    Hat,
}

impl Space {
    /// The space's variables in canonical order.
    pub fn variables(self) -> [Variable; 3] {
        match self {
            Space::Cpsa => [Variable::Pw, Variable::Ow, Variable::Swivel],
            Space::Hat => [Variable::Os, Variable::Elbow, Variable::Ow],
        }
    }

    /// "CPSA" or "HAT", the paper's names, for prose (diagnostics, explanations); values
    /// are spelled [`Self::as_str`].
    pub fn name(self) -> &'static str {
        match self {
            Space::Cpsa => "CPSA",
            Space::Hat => "HAT",
        }
    }
}

/// The five state variables.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum Variable {
    /// Wrist position Pw.
    Pw,
    /// Wrist orientation Ow (in both spaces).
    Ow,
    /// Swivel angle θsw.
    Swivel,
    /// Shoulder frame Os, spelled `shoulder_frame` as the paper's name for it (`os` reads as
    /// nothing).
    #[serde(rename = "shoulder_frame")]
    Os,
    /// Elbow angle θe.
    Elbow,
}

impl Variable {
    /// Every variable.
    pub const ALL: [Variable; 5] =
        [Variable::Pw, Variable::Ow, Variable::Swivel, Variable::Os, Variable::Elbow];

    /// The paper's symbol.
    pub fn symbol(self) -> &'static str {
        match self {
            Variable::Pw => "Pw",
            Variable::Ow => "Ow",
            Variable::Swivel => "θsw",
            Variable::Os => "Os",
            Variable::Elbow => "θe",
        }
    }

    /// The ASCII spelling.
    pub fn ascii(self) -> &'static str {
        match self {
            Variable::Swivel => "sw",
            Variable::Elbow => "e",
            other => other.symbol(),
        }
    }

    /// Reads a symbol or its ASCII spelling.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|v| v.symbol() == name || v.ascii() == name)
    }

    /// The space the variable belongs to; `None` for Ow, which is in both.
    pub fn space(self) -> Option<Space> {
        match self {
            Variable::Pw | Variable::Swivel => Some(Space::Cpsa),
            Variable::Os | Variable::Elbow => Some(Space::Hat),
            Variable::Ow => None,
        }
    }

    /// The kind of value the variable takes.
    pub fn kind(self) -> ValueKind {
        match self {
            Variable::Pw => ValueKind::Position,
            Variable::Ow | Variable::Os => ValueKind::Rotation,
            Variable::Swivel | Variable::Elbow => ValueKind::Angle,
        }
    }
}

/// What kind of value a variable takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ValueKind {
    /// A point in {b} (m).
    Position,
    /// A rotation in {b}.
    Rotation,
    /// An angle (rad).
    Angle,
}

/// A goal value of one variable, in SI units and {b}.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// Pw (m).
    Position(Vector3),
    /// Ow or Os.
    Rotation(Rotation3),
    /// θsw or θe (rad).
    Angle(Real),
}

/// Goals for variables of one space: `Pw Ow = (..)`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Goal {
    /// Each variable with its target.
    pub targets: Vec<(Variable, Target)>,
    /// The space, when the variables fix it (not for Ow alone).
    pub space: Option<Space>,
    /// Where it was written.
    pub span: Span,
}

/// An action's goal constraint GC: `G` or `G1 ≻ G2`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GoalConstraint {
    /// G, or the higher-priority G1.
    pub primary: Goal,
    /// G2, lower priority, in another space.
    pub secondary: Option<Goal>,
}

/// An axis of a path feature.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// A fixed unit direction of {b} (x, y, z and their negations).
    Base(Vector3),
    /// A body axis taken at the start of the primitive, with a sign.
    Body(BodyAxis, Real),
}

/// Body axes: upper arm r, arm-plane normal l, finger f, palm normal p.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyAxis {
    /// Upper-arm direction r.
    R,
    /// Arm-plane normal l.
    L,
    /// Finger direction f.
    F,
    /// Palm normal p.
    P,
}

/// A path feature P with its size S (SI).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PathFeature {
    /// Pw along a straight line; the length may be left to Opt2.
    Line {
        /// Unit direction in {b}.
        direction: Vector3,
        /// Distance (m).
        length: Option<Real>,
    },
    /// Pw, Ow or Os rotating about an axis; the angle may be left to Opt2.
    About {
        /// The axis.
        axis: Axis,
        /// Angle (rad).
        angle: Option<Real>,
    },
    /// θsw or θe changing by a signed angle (rad).
    By {
        /// Angle (rad).
        angle: Real,
    },
    /// Pw along half an ellipse from where the action starts to `to` through `through`
    /// (`arc through [..]`, paper §6.3 fig. 12). The action's Pw goal is its end: validation
    /// moves it here from the goal, which keeps the other variables.
    Arc {
        /// The point the arc passes through (m, the task's frame).
        through: Vector3,
        /// The arc's end, the action's Pw goal (m, the task's frame); `None` only before
        /// validation has found the goal.
        to: Option<Vector3>,
    },
    /// Kept constant.
    Hold,
}

/// One item of a path constraint.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PathItem {
    /// Variables that keep the feature.
    pub variables: Vec<Variable>,
    /// The feature.
    pub feature: PathFeature,
}

/// An action's path constraint PC.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PathConstraint {
    /// Items, all of one space.
    pub items: Vec<PathItem>,
    /// The space (`None` when only Ow is constrained).
    pub space: Option<Space>,
    /// Hard (kept exactly) or soft.
    pub hard: bool,
    /// Where it was written.
    pub span: Span,
}

/// A primitive of an explicit segment.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Primitive {
    /// Variables it drives.
    pub variables: Vec<Variable>,
    /// How.
    pub constraint: PrimitiveConstraint,
}

/// The constraint of a primitive.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PrimitiveConstraint {
    /// Reach these targets (one per variable).
    Goal(Vec<Target>),
    /// Keep this feature.
    Path(PathFeature),
    /// Keep constant.
    Hold,
}

/// An explicit movement segment: primitives covering one space exactly.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Segment {
    /// Its space.
    pub space: Space,
    /// Duration (s), if given.
    pub duration: Option<Real>,
    /// Primitives in parallel.
    pub primitives: Vec<Primitive>,
}

/// The body of an action.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ActionBody {
    /// Constraints to decompose.
    Constraints {
        /// GC.
        goal: Option<GoalConstraint>,
        /// PC.
        path: Option<PathConstraint>,
        /// Duration (s), if given.
        duration: Option<Real>,
    },
    /// Segments joined by +Tr.
    Explicit(Vec<Segment>),
}

/// Which solver to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolverChoice {
    /// docs/design.md §5 policy.
    Auto,
    /// Velocity QP.
    Qp,
    /// RRT-Connect.
    Rrt,
    /// Swivel obstacle map.
    Map,
    /// Gradient projection baseline.
    Gpm,
    /// CLIK baseline.
    Clik,
    /// λ0-PMP baseline.
    Pmp,
    /// The HAMP handover planner (goal actions; docs/metrics.md).
    Hamp,
}

impl SolverChoice {
    /// Every solver with its name.
    pub const NAMES: [(&'static str, SolverChoice); 8] = [
        ("auto", SolverChoice::Auto),
        ("qp", SolverChoice::Qp),
        ("rrt", SolverChoice::Rrt),
        ("map", SolverChoice::Map),
        ("gpm", SolverChoice::Gpm),
        ("clik", SolverChoice::Clik),
        ("pmp", SolverChoice::Pmp),
        ("hamp", SolverChoice::Hamp),
    ];

    /// The name used in task files: its one spelling.
    pub fn name(self) -> &'static str {
        self.as_str()
    }
}

/// A solver chosen for one segment of an action: `solver MS2 rrt`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SegmentSolver {
    /// The segment's index in its action, from 0 (`MS1` is 0).
    pub segment: usize,
    /// The solver.
    pub solver: SolverChoice,
    /// Where the entry was written.
    pub span: Span,
}

impl Action {
    /// The solver chosen for the action's segment `segment` (from 0): its
    /// own, else the action's, if any.
    pub fn solver_of(&self, segment: usize) -> Option<SolverChoice> {
        let own = self.segment_solvers.iter().find(|s| s.segment == segment);
        own.map(|s| s.solver).or(self.solver)
    }
}

/// One action of a task.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Action {
    /// Name.
    pub name: String,
    /// Description, if given.
    pub description: Option<String>,
    /// STRIPS preconditions.
    pub pre: Vec<String>,
    /// STRIPS add effects.
    pub add: Vec<String>,
    /// STRIPS delete effects.
    pub del: Vec<String>,
    /// Names of the scene's obstacles the arm may touch during this action
    /// (the box a push moves): every collision check of the action leaves
    /// them out. See [`Task::action_scene`].
    pub contact: Vec<String>,
    /// Solver for this action's segments, if chosen.
    pub solver: Option<SolverChoice>,
    /// Solvers chosen for single segments (`solver MS1 rrt`), before
    /// [`Action::solver`].
    pub segment_solvers: Vec<SegmentSolver>,
    /// Constraints or segments.
    pub body: ActionBody,
    /// Where its name was written.
    pub span: Span,
}

/// The start of the motion.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Start {
    /// Joint angles (rad).
    Joints(JointVector),
    /// A complete state of one space.
    State(Vec<(Variable, Target)>),
}

/// An obstacle's shape, in {b} (or the root frame, per settings), SI.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// Box: centre, full edge lengths along its own axes, and its rotation.
    Box {
        /// Centre.
        center: Vector3,
        /// Edge lengths.
        size: Vector3,
        /// The box's axes in the scene frame (the identity for an axis-aligned box).
        rotation: Rotation3,
    },
    /// Sphere.
    Sphere {
        /// Centre.
        center: Vector3,
        /// Radius.
        radius: Real,
    },
    /// Capsule around a segment.
    Capsule {
        /// Segment start.
        a: Vector3,
        /// Segment end.
        b: Vector3,
        /// Radius.
        radius: Real,
    },
    /// Cylinder along the z axis of its rotation.
    Cylinder {
        /// Centre.
        center: Vector3,
        /// Radius.
        radius: Real,
        /// Height.
        height: Real,
        /// The cylinder's axes in the scene frame: its own z is its axis (the identity for a
        /// vertical one).
        rotation: Rotation3,
    },
}

/// A named obstacle.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Obstacle {
    /// Unique name.
    pub name: String,
    /// Shape.
    pub shape: Shape,
}

/// The frame positions are given in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PositionFrame {
    /// {b}: origin at the shoulder centre (default).
    Base,
    /// The URDF root link frame.
    Root,
}

/// Task settings with their defaults.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Settings {
    /// Output rate (Hz), default 100.
    pub rate: Real,
    /// Default solver, default auto.
    pub solver: SolverChoice,
    /// Seed of randomised solvers, default 0.
    pub seed: u64,
    /// Transitional overlap as a fraction of the shorter segment, default 0.2.
    pub transition: Real,
    /// Frame of positions, default {b}.
    pub frame: PositionFrame,
    /// The joints' acceleration limits as a fraction of the robot file's, default 1 (100 %).
    pub acceleration: Real,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            rate: 100.0,
            solver: SolverChoice::Auto,
            seed: 0,
            transition: 0.2,
            frame: PositionFrame::Base,
            acceleration: 1.0,
        }
    }
}

/// A validated A2ML task.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Task {
    /// The task's name.
    pub name: String,
    /// The robot URDF, resolved relative to the task file.
    pub robot: PathBuf,
    /// The chain's base link, when the `robot` line names one.
    pub robot_base: Option<String>,
    /// The chain's tip link, when the `robot` line names one.
    pub robot_tip: Option<String>,
    /// The start, if given.
    pub start: Option<Start>,
    /// Obstacles.
    pub scene: Vec<Obstacle>,
    /// Settings.
    pub settings: Settings,
    /// STRIPS initial facts, when the planner orders the actions.
    pub init: Option<Vec<String>>,
    /// STRIPS goal facts.
    pub goal: Option<Vec<String>>,
    /// Actions in written order.
    pub actions: Vec<Action>,
}

impl Target {
    /// The target with a position moved by `offset` (rotations and angles
    /// are the same in frames that differ by a translation).
    fn shifted(self, offset: &Vector3) -> Self {
        match self {
            Target::Position(p) => Target::Position(p + offset),
            other => other,
        }
    }
}

fn shift_targets(targets: &mut [(Variable, Target)], offset: &Vector3) {
    for (_, t) in targets {
        *t = t.shifted(offset);
    }
}

impl Task {
    /// The obstacles the arm must keep clear of during action `action` (an
    /// index into [`Task::actions`]): the scene without the action's
    /// `contact` obstacles, in the scene's order.
    ///
    /// # Panics
    /// If `action` is not an index into [`Task::actions`].
    pub fn action_scene(&self, action: usize) -> Vec<Obstacle> {
        let contact = &self.actions[action].contact;
        self.scene.iter().filter(|o| !contact.contains(&o.name)).cloned().collect()
    }

    /// Loads the task's robot: its URDF (resolved relative to the task file) with the `robot`
    /// line's `base` and `tip`, unless `options` names its own.
    ///
    /// # Errors
    /// As [`Robot::from_urdf_file`]: a missing or unreadable file, no such link, or no unique
    /// 7-joint chain between them.
    pub fn load_robot(&self, options: &RobotOptions) -> Result<Robot, RobotError> {
        let options = RobotOptions {
            base: options.base.clone().or_else(|| self.robot_base.clone()),
            tip: options.tip.clone().or_else(|| self.robot_tip.clone()),
            ..options.clone()
        };
        Robot::from_urdf_file_with(&self.robot, &options)
    }

    /// The task with every position (goals, start state, obstacles) in {b},
    /// given S in the root link's frame: `settings { frame root }` tasks are
    /// written in the root link's frame, which differs from {b} by the
    /// translation to the shoulder centre only. A {b} task is returned as is.
    pub fn in_base_frame(&self, shoulder_in_root: &Vector3) -> Task {
        if self.settings.frame == PositionFrame::Base {
            return self.clone();
        }
        let offset = -shoulder_in_root;
        let mut task = self.clone();
        task.settings.frame = PositionFrame::Base;
        if let Some(Start::State(entries)) = &mut task.start {
            shift_targets(entries, &offset);
        }
        for o in &mut task.scene {
            match &mut o.shape {
                Shape::Box { center, .. }
                | Shape::Sphere { center, .. }
                | Shape::Cylinder { center, .. } => *center += offset,
                Shape::Capsule { a, b, .. } => {
                    *a += offset;
                    *b += offset;
                }
            }
        }
        for action in &mut task.actions {
            match &mut action.body {
                ActionBody::Constraints { goal, path, .. } => {
                    for item in path.iter_mut().flat_map(|p| &mut p.items) {
                        if let PathFeature::Arc { through, to } = &mut item.feature {
                            *through += offset;
                            if let Some(to) = to {
                                *to += offset;
                            }
                        }
                    }
                    if let Some(g) = goal {
                        shift_targets(&mut g.primary.targets, &offset);
                        if let Some(s) = &mut g.secondary {
                            shift_targets(&mut s.targets, &offset);
                        }
                    }
                }
                ActionBody::Explicit(segments) => {
                    for p in segments.iter_mut().flat_map(|s| &mut s.primitives) {
                        if let PrimitiveConstraint::Goal(targets) = &mut p.constraint {
                            for t in targets {
                                *t = t.shifted(&offset);
                            }
                        }
                    }
                }
            }
        }
        task
    }
}
