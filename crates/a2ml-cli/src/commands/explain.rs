//! `a2ml explain`: how a task decomposes. Loads the task and its robot, runs
//! [`decompose`] and shows the tree task -> actions (type, GC, PC) ->
//! segments -> primitives, with the Opt1/Opt2 results. The report is built
//! once ([`ExplainReport`], whose field names are the JSON keys of
//! docs/cli.md) and printed as an indented tree or as JSON. Values are in
//! {b}; the tree writes them in A2ML syntax with units, JSON in SI units with
//! `_deg` twins for angles.

use std::path::{Path, PathBuf};

use clap::Args;
use serde::Serialize;

use a2ml_core::Robot;
use a2ml_core::decompose::{
    self, DecomposeError, DecomposeOptions, Decomposition, OptReport, PlannedAction, PlannedSegment,
};
use a2ml_core::language::display::{number_list, path_size, rpy_degrees, short_number};
use a2ml_core::language::{
    self as language, ActionBody, Goal, PathFeature, Primitive, PrimitiveConstraint, Space, Target,
    Task, Variable,
};
use a2ml_core::math::{DOF, JointVector, Real};

use crate::error::CliError;
use crate::output::{self, COARSE, FINE, deg, num, quaternion, unsigned_zero, vec3};

/// Decimals for durations (s) in the tree.
const SECONDS: usize = 3;

/// Arguments of `a2ml explain`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  a2ml explain examples/type_iv_forward_bar.a2ml
  a2ml explain examples/type_vii_column.a2ml --json

Shows the actions in execution order, each with its type (I-VII), its goal
and path constraints, its movement segments and their primitives, and what
Opt1 and Opt2 computed. Values are in the base frame {b}.

Exit codes: 0 success, 1 the task or robot file cannot be read, 2 the task is
not valid or cannot be decomposed.")]
pub struct ExplainArgs {
    /// The task file.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// Print JSON instead of the tree.
    #[arg(long)]
    pub json: bool,
    /// Which chain of the URDF, and where its capsules come from.
    #[command(flatten)]
    pub arm: crate::args::ArmArgs,
    #[command(flatten)]
    pub limits: super::LimitArgs,
}

/// Runs `a2ml explain`.
///
/// # Errors
/// [`CliError::Io`] when the task or robot file cannot be read;
/// [`CliError::Input`] when the task is invalid (its diagnostics go to
/// stderr first), the robot is unusable, or the decomposition fails.
pub fn run(args: &ExplainArgs) -> Result<(), CliError> {
    let (task, source) = super::load_task(&args.file, &args.limits.limits())?;
    let robot = task.load_robot(&args.arm.options()?)?;
    let decomposition = decompose::decompose(&robot, &task, &DecomposeOptions::default())
        .map_err(|e| decomposition_error(&args.file, &source, &e))?;
    let report = ExplainReport::new(&args.file, &robot, &task, &decomposition);
    output::emit(&report, args.json, &report.warnings, || report.to_text())
}

/// A decomposition that failed: located in the task file, with the line and
/// a caret, when the error points at what was written.
fn decomposition_error(file: &Path, source: &str, error: &DecomposeError) -> CliError {
    if let DecomposeError::NoSuchSegment { span, .. } = error {
        let diagnostics = language::Diagnostics {
            path: Some(file.display().to_string()),
            source: source.to_owned(),
            items: vec![language::Diagnostic::new(*span, error.to_string())],
            omitted: 0,
        };
        output::report(&diagnostics.to_string());
    }
    CliError::Input(format!("{}: {error}", file.display()))
}

/// Everything `a2ml explain` reports; its field names are the JSON keys.
#[derive(Debug, Serialize)]
pub struct ExplainReport {
    /// Task name.
    pub task: String,
    /// The task file as given.
    pub file: String,
    /// The robot URDF, resolved relative to the task file.
    pub robot: String,
    /// The URDF robot name.
    pub robot_name: String,
    /// Start configuration (rad).
    pub start: [Real; DOF],
    /// Start configuration (deg).
    pub start_deg: [Real; DOF],
    /// Where the action order comes from.
    pub order: Order,
    /// The actions in execution order.
    pub actions: Vec<ActionReport>,
    /// Held variables that had to move, one message per segment.
    pub warnings: Vec<String>,
}

/// One action and its decomposition.
#[derive(Debug, Serialize)]
pub struct ActionReport {
    /// Index in the file's written order (0-based).
    pub index: usize,
    /// Name.
    pub name: String,
    /// Description, if given.
    pub description: Option<String>,
    /// `i` to `vii`; `None` for an explicit action.
    pub action_type: Option<&'static str>,
    /// What the type means.
    pub type_description: String,
    /// Space of G (or G1).
    pub goal_space: Option<&'static str>,
    /// Space of G2.
    pub secondary_goal_space: Option<&'static str>,
    /// Space of the path.
    pub path_space: Option<&'static str>,
    /// GC as written.
    pub goal: Option<GoalConstraintReport>,
    /// PC as written.
    pub path: Option<PathConstraintReport>,
    /// The action's `duration` (s), if given.
    pub duration: Option<Real>,
    /// Segments, joined by +Tr.
    pub segments: Vec<SegmentReport>,
    /// Opt1 and Opt2 runs, in order.
    pub optimisations: Vec<OptimisationReport>,
}

/// A goal constraint `G` or `G1 ≻ G2`.
#[derive(Debug, Serialize)]
pub struct GoalConstraintReport {
    /// In A2ML syntax.
    pub text: String,
    /// G, or G1.
    pub primary: GoalReport,
    /// G2.
    pub secondary: Option<GoalReport>,
}

/// Goals for variables of one space.
#[derive(Debug, Serialize)]
pub struct GoalReport {
    /// Its space; `None` for Ow alone.
    pub space: Option<&'static str>,
    /// One target per variable.
    pub targets: Vec<TargetReport>,
}

/// A value of one variable; the fields of the other kinds are `None`.
#[derive(Debug, Serialize)]
pub struct TargetReport {
    /// The variable, in its one spelling (`pw`, `ow`, `swivel`, `shoulder_frame`, `elbow`).
    pub variable: &'static str,
    /// `position`, `rotation` or `angle`.
    pub kind: &'static str,
    /// In A2ML syntax, with its unit.
    pub text: String,
    /// A position (m).
    pub position: Option<[Real; 3]>,
    /// A rotation as a quaternion w, x, y, z.
    pub quaternion: Option<[Real; 4]>,
    /// A rotation as roll, pitch, yaw about the fixed axes x, y, z (deg).
    pub rpy_deg: Option<[Real; 3]>,
    /// An angle (rad).
    pub angle: Option<Real>,
    /// An angle (deg).
    pub angle_deg: Option<Real>,
}

/// A path constraint.
#[derive(Debug, Serialize)]
pub struct PathConstraintReport {
    /// In A2ML syntax.
    pub text: String,
    /// Hard or soft.
    pub hard: bool,
    /// Its space; `None` for Ow alone.
    pub space: Option<&'static str>,
    /// Its items.
    pub items: Vec<PathItemReport>,
}

/// One item of a path constraint.
#[derive(Debug, Serialize)]
pub struct PathItemReport {
    /// The variables keeping the feature.
    pub variables: Vec<&'static str>,
    /// The feature.
    #[serde(flatten)]
    pub feature: FeatureReport,
}

/// A path feature and its size.
#[derive(Debug, Serialize)]
pub struct FeatureReport {
    /// `line`, `about`, `by` or `hold`.
    pub feature: &'static str,
    /// Unit direction of a line, in {b}.
    pub direction: Option<[Real; 3]>,
    /// Axis of `about`: x, y, z of {b} or r, l, f, p of the body, maybe negated.
    pub axis: Option<String>,
    /// Length (m) or angle (rad); `None` for hold or a size left open.
    pub size: Option<Real>,
    /// An angle size in degrees.
    pub size_deg: Option<Real>,
    /// The point an `arc` passes through (m, {b}).
    pub through: Option<[Real; 3]>,
    /// The end of an `arc`, the action's Pw goal (m, {b}).
    pub to: Option<[Real; 3]>,
}

/// Where the action order comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Order {
    /// The STRIPS plan from `init` to `goal`.
    Planned,
    /// The order the actions are written in.
    Written,
}

/// How a segment joins what runs before it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Connection {
    /// The task's first segment, from the start configuration.
    Start,
    /// +Se: the first segment of a later action, from rest.
    Sequential,
    /// +Tr: overlapping the previous segment of the same action.
    Transitional,
}

/// A planned segment.
#[derive(Debug, Serialize)]
pub struct SegmentReport {
    /// 1-based, as in error messages.
    pub number: usize,
    /// `cpsa` or `hat`.
    pub space: &'static str,
    /// `path` (all path), `goal` (all goal) or `mixed`.
    pub pattern: &'static str,
    /// Duration (s).
    pub duration: Real,
    /// Whether the duration was raised for joint velocity limits.
    pub duration_raised: bool,
    /// The solver chosen for it.
    pub solver: &'static str,
    /// How it joins what runs before it.
    pub connection: Connection,
    /// Primitives in parallel (+Pa).
    pub primitives: Vec<PrimitiveReport>,
    /// Held variables that had to move to keep the end reachable.
    pub relaxed: Vec<&'static str>,
    /// Start configuration (rad).
    pub start: [Real; DOF],
    /// Start configuration (deg).
    pub start_deg: [Real; DOF],
    /// Expected end configuration (rad).
    pub end: [Real; DOF],
    /// Expected end configuration (deg).
    pub end_deg: [Real; DOF],
}

/// One primitive of a segment.
#[derive(Debug, Serialize)]
pub struct PrimitiveReport {
    /// `goal`, `path` or `hold`.
    pub constraint: &'static str,
    /// The variables it drives.
    pub variables: Vec<&'static str>,
    /// In A2ML syntax.
    pub text: String,
    /// Goal values, one per variable (goal only).
    pub targets: Vec<TargetReport>,
    /// The feature with its size (path only).
    pub path: Option<FeatureReport>,
}

/// One run of Opt1 or Opt2.
#[derive(Debug, Serialize)]
pub struct OptimisationReport {
    /// `Opt1` or `Opt2`.
    pub solver: &'static str,
    /// Error left in the goals it served: the largest of position (m) and
    /// rotation or angle (rad) errors.
    pub residual: Real,
    /// Opt2: the size of each path item (m for line, rad otherwise, 0 for hold).
    pub sizes: Vec<Real>,
    /// Candidates evaluated.
    pub evaluations: usize,
}

/// Seven joint values, negative zero made positive.
fn joints(q: &JointVector) -> [Real; DOF] {
    std::array::from_fn(|i| unsigned_zero(q[i]))
}

/// Seven joint values in degrees.
fn joints_deg(q: &JointVector) -> [Real; DOF] {
    std::array::from_fn(|i| unsigned_zero(deg(q[i])))
}

/// Variables in their one spelling (docs/cli.md, "Enum values").
fn spelled(variables: &[Variable]) -> Vec<&'static str> {
    variables.iter().map(|v| v.as_str()).collect()
}

impl TargetReport {
    fn new(variable: Variable, target: &Target) -> Self {
        let blank = Self {
            variable: variable.as_str(),
            kind: "",
            text: target.to_string(),
            position: None,
            quaternion: None,
            rpy_deg: None,
            angle: None,
            angle_deg: None,
        };
        match target {
            Target::Position(p) => Self { kind: "position", position: Some(vec3(p)), ..blank },
            Target::Rotation(r) => Self {
                kind: "rotation",
                quaternion: Some(quaternion(r)),
                rpy_deg: Some(rpy_degrees(r)),
                ..blank
            },
            Target::Angle(a) => Self {
                kind: "angle",
                angle: Some(unsigned_zero(*a)),
                angle_deg: Some(unsigned_zero(deg(*a))),
                ..blank
            },
        }
    }
}

impl GoalReport {
    fn new(goal: &Goal) -> Self {
        Self {
            space: goal.space.map(Space::as_str),
            targets: goal.targets.iter().map(|(v, t)| TargetReport::new(*v, t)).collect(),
        }
    }
}

impl FeatureReport {
    fn new(feature: &PathFeature) -> Self {
        let angle = |a: Option<Real>| (a.map(unsigned_zero), a.map(|a| unsigned_zero(deg(a))));
        let (name, direction, axis, (size, size_deg)) = match feature {
            PathFeature::Line { direction, length } => {
                ("line", Some(vec3(direction)), None, (length.map(unsigned_zero), None))
            }
            PathFeature::About { axis, angle: a } => {
                ("about", None, Some(axis.to_string()), angle(*a))
            }
            PathFeature::By { angle: a } => ("by", None, None, angle(Some(*a))),
            PathFeature::Arc { .. } => ("arc", None, None, (None, None)),
            PathFeature::Hold => ("hold", None, None, (None, None)),
        };
        let (through, to) = match feature {
            PathFeature::Arc { through, to } => (Some(vec3(through)), to.as_ref().map(vec3)),
            _ => (None, None),
        };
        Self { feature: name, direction, axis, size, size_deg, through, to }
    }
}

impl PrimitiveReport {
    fn new(p: &Primitive) -> Self {
        let (constraint, targets, path) = match &p.constraint {
            PrimitiveConstraint::Goal(targets) => (
                "goal",
                p.variables.iter().zip(targets).map(|(v, t)| TargetReport::new(*v, t)).collect(),
                None,
            ),
            PrimitiveConstraint::Path(feature) => {
                ("path", Vec::new(), Some(FeatureReport::new(feature)))
            }
            PrimitiveConstraint::Hold => ("hold", Vec::new(), None),
        };
        Self { constraint, variables: spelled(&p.variables), text: p.to_string(), targets, path }
    }
}

impl SegmentReport {
    fn new(k: usize, first_action: bool, s: &PlannedSegment) -> Self {
        let connection = match (k, first_action) {
            (0, true) => Connection::Start,
            (0, false) => Connection::Sequential,
            _ => Connection::Transitional,
        };
        Self {
            number: k + 1,
            space: Space::as_str(s.space),
            pattern: s.pattern.as_str(),
            duration: s.duration,
            duration_raised: s.duration_raised,
            solver: s.solver.name(),
            connection,
            primitives: s.primitives.iter().map(PrimitiveReport::new).collect(),
            relaxed: spelled(&s.relaxed),
            start: joints(&s.start),
            start_deg: joints_deg(&s.start),
            end: joints(&s.end),
            end_deg: joints_deg(&s.end),
        }
    }
}

impl OptimisationReport {
    fn new(o: &OptReport) -> Self {
        Self {
            solver: o.solver,
            residual: o.residual,
            sizes: o.sizes.iter().copied().map(unsigned_zero).collect(),
            evaluations: o.evaluations,
        }
    }
}

impl ActionReport {
    fn new(task: &Task, planned: &PlannedAction, first: bool) -> Self {
        let action = &task.actions[planned.index];
        let (goal, path, duration) = match &action.body {
            ActionBody::Constraints { goal, path, duration } => {
                (goal.as_ref(), path.as_ref(), *duration)
            }
            ActionBody::Explicit(_) => (None, None, None),
        };
        let c = planned.classification;
        Self {
            index: planned.index,
            name: planned.name.clone(),
            description: action.description.clone(),
            action_type: c.map(|c| c.action_type.as_str()),
            type_description: c.map_or_else(
                || "explicit: the segments are written out".to_owned(),
                |c| c.to_string(),
            ),
            goal_space: c.and_then(|c| c.goal_space).map(Space::as_str),
            secondary_goal_space: c.and_then(|c| c.secondary_goal_space).map(Space::as_str),
            path_space: c.and_then(|c| c.path_space).map(Space::as_str),
            goal: goal.map(|g| GoalConstraintReport {
                text: g.to_string(),
                primary: GoalReport::new(&g.primary),
                secondary: g.secondary.as_ref().map(GoalReport::new),
            }),
            path: path.map(|p| PathConstraintReport {
                text: p.to_string(),
                hard: p.hard,
                space: p.space.map(Space::as_str),
                items: p
                    .items
                    .iter()
                    .map(|i| PathItemReport {
                        variables: spelled(&i.variables),
                        feature: FeatureReport::new(&i.feature),
                    })
                    .collect(),
            }),
            duration,
            segments: planned
                .segments
                .iter()
                .enumerate()
                .map(|(k, s)| SegmentReport::new(k, first, s))
                .collect(),
            optimisations: planned.optimisations.iter().map(OptimisationReport::new).collect(),
        }
    }
}

impl ExplainReport {
    /// The report on `decomposition`, of `task` (read from `file`) for `robot`.
    pub fn new(file: &Path, robot: &Robot, task: &Task, decomposition: &Decomposition) -> Self {
        let actions: Vec<ActionReport> = decomposition
            .actions
            .iter()
            .enumerate()
            .map(|(i, a)| ActionReport::new(task, a, i == 0))
            .collect();
        let warnings = actions
            .iter()
            .flat_map(|a| {
                a.segments.iter().filter(|s| !s.relaxed.is_empty()).map(|s| {
                    format!("action `{}`, segment {}: {}", a.name, s.number, relaxed(&s.relaxed))
                })
            })
            .collect();
        Self {
            task: task.name.clone(),
            file: file.display().to_string(),
            robot: task.robot.display().to_string(),
            robot_name: robot.name.clone(),
            start: joints(&decomposition.start),
            start_deg: joints_deg(&decomposition.start),
            order: if task.init.is_some() { Order::Planned } else { Order::Written },
            actions,
            warnings,
        }
    }

    /// The report as an indented tree.
    pub fn to_text(&self) -> String {
        let mut out = Tree::default();
        out.line(0, format!("task {}", self.task));
        out.line(1, format!("file   {}", self.file));
        out.line(1, format!("robot  {} ({})", self.robot_name, self.robot));
        out.line(1, format!("start  {}", text::joints_deg(&self.start_deg)));
        let order = match self.order {
            Order::Planned => "planned from `init` to `goal` (STRIPS)",
            Order::Written => "as written",
        };
        out.line(1, format!("order  {order}, {}", output::count(self.actions.len(), "action")));
        for (i, a) in self.actions.iter().enumerate() {
            a.render(i + 1, &mut out);
        }
        out.0
    }
}

impl ActionReport {
    fn render(&self, step: usize, out: &mut Tree) {
        let description = self.description.as_ref().map_or_else(String::new, |d| format!(": {d}"));
        out.blank();
        out.line(1, format!("action {step} `{}`{description}", self.name));
        out.line(2, self.type_description.clone());
        let spaces = |primary: Option<&'static str>, secondary: Option<&'static str>| match (
            primary, secondary,
        ) {
            (Some(p), Some(s)) => format!("  [{p} ≻ {s}]"),
            (Some(p), None) => format!("  [{p}]"),
            _ => String::new(),
        };
        if let Some(g) = &self.goal {
            let space = spaces(self.goal_space, self.secondary_goal_space);
            out.line(2, format!("GC    goal {}{space}", g.text));
        }
        if let Some(p) = &self.path {
            let open = p
                .items
                .iter()
                .any(|i| i.feature.size.is_none() && matches!(i.feature.feature, "line" | "about"));
            let note = if open { "  (size left to Opt2)" } else { "" };
            out.line(2, format!("PC    path {}{}{note}", p.text, spaces(self.path_space, None)));
        }
        if let Some(d) = self.duration {
            out.line(2, format!("duration {} s (given for the action)", short_number(d, SECONDS)));
        }
        for s in &self.segments {
            s.render(out);
        }
        for o in &self.optimisations {
            let sizes = match (o.solver, &self.path) {
                ("Opt2", Some(path)) if path.items.len() == o.sizes.len() => {
                    let items: Vec<String> = path
                        .items
                        .iter()
                        .zip(&o.sizes)
                        .filter(|(i, _)| i.feature.feature != "hold")
                        .map(|(i, s)| {
                            let variables: Vec<&str> =
                                i.variables.iter().map(|v| symbol(v)).collect();
                            format!(
                                "{} {} {}",
                                variables.join(" "),
                                i.feature.feature,
                                path_size(i.feature.feature, *s)
                            )
                        })
                        .collect();
                    format!(", sizes {}", items.join(", "))
                }
                _ if !o.sizes.is_empty() => {
                    format!(", sizes {}", number_list(&o.sizes, FINE))
                }
                _ => String::new(),
            };
            out.line(
                2,
                format!(
                    "{}  residual {} (m or rad){sizes}, {}",
                    o.solver,
                    text::residual(o.residual),
                    output::count(o.evaluations, "evaluation")
                ),
            );
        }
    }
}

impl SegmentReport {
    fn render(&self, out: &mut Tree) {
        let connection = match self.connection {
            Connection::Start => "from the start",
            Connection::Sequential => "+Se: from rest where the last action ended",
            Connection::Transitional => "+Tr: overlaps the previous segment",
        };
        let pattern = match self.pattern {
            "path" => "all path",
            "goal" => "all goal",
            _ => "path and goal",
        };
        let raised = if self.duration_raised { " (raised for velocity limits)" } else { "" };
        out.line(
            2,
            format!(
                "segment {}  {}, pattern {} ({pattern}), {} s{raised}, solver {}, {connection}",
                self.number,
                self.space,
                self.pattern,
                short_number(self.duration, SECONDS),
                self.solver
            ),
        );
        for (k, p) in self.primitives.iter().enumerate() {
            let join = if k == 0 { "    " } else { "+Pa " };
            out.line(3, format!("{join}{}", p.text));
        }
        if !self.relaxed.is_empty() {
            out.line(3, format!("warning: {}", relaxed(&self.relaxed)));
        }
        out.line(3, format!("ends at {}", text::joints_deg(&self.end_deg)));
    }
}

/// The warning for held variables that had to move.
fn relaxed(variables: &[&str]) -> String {
    let symbols: Vec<&str> = variables.iter().map(|v| symbol(v)).collect();
    let (list, it) = match symbols.as_slice() {
        [one] => ((*one).to_owned(), "it"),
        many => (many.join(", "), "them"),
    };
    format!(
        "{list} could not be held: with {it} held the end is out of reach within the joint \
         limits, so {it} moves as little as possible (now a goal)"
    )
}

/// The paper's symbol of a variable given in its spelling (`swivel` -> `θsw`): the text
/// report reads as A2ML, the JSON carries the spelling.
fn symbol(spelling: &str) -> &str {
    spelling.parse::<Variable>().map_or(spelling, |v| v.symbol())
}

/// Indented lines, two spaces per level.
#[derive(Default)]
struct Tree(String);

impl Tree {
    fn blank(&mut self) {
        self.0.push('\n');
    }

    fn line(&mut self, level: usize, text: String) {
        self.0.push_str(&"  ".repeat(level));
        self.0.push_str(&text);
        self.0.push('\n');
    }
}

/// The tree's own numbers; values are written by the core's `Display` impls
/// ([`a2ml_core::language::display`]).
mod text {
    use super::*;

    /// Seven joint angles in degrees.
    pub fn joints_deg(q: &[Real]) -> String {
        format!("{} deg", number_list(q, COARSE))
    }

    /// A residual: fixed decimals while readable, else scientific.
    pub fn residual(x: Real) -> String {
        if x == 0.0 || x >= 1e-4 { num(x, 6) } else { format!("{x:.2e}") }
    }
}
