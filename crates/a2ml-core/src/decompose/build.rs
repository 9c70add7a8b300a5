//! The whole decomposition: every action, in planned order, to fully
//! parameterised movement segments (docs/design.md §4, paper fig. 3, eq. 12).
//!
//! Actions run one after another from the task's start configuration; each
//! segment records the configuration it is expected to start and end in, so
//! that the next can be planned from there. Opt1 and Opt2 fill in the goals
//! and path sizes the table leaves open.

use super::opt::{ArmState, OptOptions, OptSolution, along_path, opt1, opt2};
use super::{
    ActionType, Classification, DecomposeError, SegmentPattern, StripsOptions, classify,
    order_with, segment_pattern,
};
use crate::collision::CollisionScene;
use crate::kinematics::{CpsaState, HatState, ik_cpsa, ik_hat};
use crate::language::{
    ActionBody, GoalConstraint, PathConstraint, PathFeature, Primitive, PrimitiveConstraint,
    SolverChoice, Space, Start, Target, Task, Variable,
};
use crate::math::{JointVector, Real};
use crate::robot::Robot;

/// Fitts' law for a default duration: T = a + b log2(2A / W) (LANGUAGE.md).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FittsLaw {
    /// a (s).
    pub a: Real,
    /// b (s).
    pub b: Real,
    /// W, the target width (m).
    pub width: Real,
}

impl Default for FittsLaw {
    fn default() -> Self {
        Self { a: 0.3625, b: 0.1325, width: 0.02 }
    }
}

impl FittsLaw {
    /// The duration for a wrist travel of `amplitude` metres (at least `a`).
    pub fn duration(&self, amplitude: Real) -> Real {
        self.a + self.b * (2.0 * amplitude / self.width).max(1.0).log2()
    }
}

/// Settings of the decomposition.
#[derive(Debug, Clone, Default)]
pub struct DecomposeOptions {
    /// Opt1 and Opt2.
    pub opt: OptOptions,
    /// The action planner.
    pub strips: StripsOptions,
    /// Default durations.
    pub fitts: FittsLaw,
}

/// Which optimiser filled in a segment's goals, and how well.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct OptReport {
    /// "Opt1" or "Opt2".
    pub solver: &'static str,
    /// The error of the goals it could not meet exactly (m / rad).
    pub residual: Real,
    /// Path sizes it chose (Opt2).
    pub sizes: Vec<Real>,
    /// Candidates evaluated.
    pub evaluations: usize,
}

/// A movement segment with every value known.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PlannedSegment {
    /// Its space.
    pub space: Space,
    /// 1 (paths), 2 (goals) or 3 (mixed).
    pub pattern: SegmentPattern,
    /// Duration (s).
    pub duration: Real,
    /// Whether the duration was raised to respect joint velocity limits.
    pub duration_raised: bool,
    /// Solver to use.
    pub solver: SolverChoice,
    /// Primitives in parallel, with goals and path sizes filled in.
    pub primitives: Vec<Primitive>,
    /// Variables the table holds but that had to move for the end to be
    /// reachable within the joint limits (moved as little as possible).
    pub relaxed: Vec<Variable>,
    /// Configuration it starts from.
    pub start: JointVector,
    /// Configuration it is expected to end in.
    pub end: JointVector,
}

/// One action, decomposed.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PlannedAction {
    /// Index in `Task::actions`.
    pub index: usize,
    /// Name.
    pub name: String,
    /// Type and spaces (`None` for an explicit action).
    pub classification: Option<Classification>,
    /// Segments joined by +Tr.
    pub segments: Vec<PlannedSegment>,
    /// The optimisations that parameterised them, in order.
    pub optimisations: Vec<OptReport>,
}

/// A decomposed task.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Decomposition {
    /// Task name.
    pub task: String,
    /// Start configuration.
    pub start: JointVector,
    /// Actions in execution order.
    pub actions: Vec<PlannedAction>,
}

/// Decomposes a task into segments for `robot`.
///
/// # Errors
/// [`DecomposeError`]: no start, no action order, a combination outside
/// the table, or a goal no configuration within the limits reaches.
pub fn decompose(
    robot: &Robot,
    task: &Task,
    options: &DecomposeOptions,
) -> Result<Decomposition, DecomposeError> {
    // Lines, axes and rotations are the same in the root frame and in {b};
    // positions move by the shoulder centre.
    let task = &task.in_base_frame(&robot.structure.shoulder_in_base_link);
    crate::collision::check_shapes(robot, &task.scene)?;
    let start = start_configuration(robot, task)?;
    let order = order_with(task, &options.strips)?;
    let mut q = start;
    let mut actions = Vec::with_capacity(order.len());
    for index in order {
        // The obstacles the action may touch (its `contact`) are no obstacles to it.
        let scene = CollisionScene::new(&task.action_scene(index));
        let planned = Planner { robot, task, options, scene: &scene, index }.action(q)?;
        if let Some(last) = planned.segments.last() {
            q = last.end;
        }
        actions.push(planned);
    }
    Ok(Decomposition { task: task.name.clone(), start, actions })
}

fn start_configuration(robot: &Robot, task: &Task) -> Result<JointVector, DecomposeError> {
    let unreachable =
        |reason: String| DecomposeError::InvalidStart { task: task.name.clone(), reason };
    match &task.start {
        None => Err(DecomposeError::NoStart { task: task.name.clone() }),
        Some(Start::Joints(q)) => match robot.limit_violation(q, 1e-9) {
            Some((i, v)) => Err(unreachable(format!(
                "joint `{}` starts at {v:.4} rad, outside its limits",
                robot.joints[i].name
            ))),
            None => Ok(*q),
        },
        Some(Start::State(entries)) => {
            let get = |v: Variable| entries.iter().find(|(w, _)| *w == v).map(|(_, t)| *t);
            let solutions = match (get(Variable::Pw), get(Variable::Swivel), get(Variable::Os)) {
                (Some(Target::Position(pw)), Some(Target::Angle(swivel)), _) => {
                    let Some(Target::Rotation(ow)) = get(Variable::Ow) else {
                        return Err(unreachable("the start state has no Ow".into()));
                    };
                    ik_cpsa(robot, &CpsaState { pw, ow, swivel }, None)
                }
                (_, _, Some(Target::Rotation(os))) => {
                    let (Some(Target::Angle(e)), Some(Target::Rotation(ow))) =
                        (get(Variable::Elbow), get(Variable::Ow))
                    else {
                        return Err(unreachable("the start state is incomplete".into()));
                    };
                    ik_hat(robot, &HatState { shoulder_frame: os, elbow_angle: e, ow }, None)
                }
                _ => return Err(unreachable("the start state is incomplete".into())),
            };
            solutions.map(|s| s[0]).map_err(|e| unreachable(e.to_string()))
        }
    }
}

struct Planner<'a> {
    robot: &'a Robot,
    task: &'a Task,
    options: &'a DecomposeOptions,
    scene: &'a CollisionScene,
    index: usize,
}

/// Targets of a goal, as (variable, target) pairs.
type Targets = Vec<(Variable, Target)>;

impl Planner<'_> {
    fn name(&self) -> &str {
        &self.task.actions[self.index].name
    }

    /// The solver of the action's segment `k`: its own, the action's, else the task's.
    fn solver(&self, k: usize) -> SolverChoice {
        self.task.actions[self.index].solver_of(k).unwrap_or(self.task.settings.solver)
    }

    fn state(&self, q: &JointVector, segment: usize) -> Result<ArmState, DecomposeError> {
        ArmState::at(self.robot, q).map_err(|e| self.unreachable(segment, e.to_string()))
    }

    fn unreachable(&self, segment: usize, reason: String) -> DecomposeError {
        DecomposeError::Unreachable { action: self.name().to_owned(), segment, reason }
    }

    fn opt_failed(&self, segment: usize, e: impl std::fmt::Display) -> DecomposeError {
        self.unreachable(segment, format!("optimisation failed: {e}"))
    }

    fn action(&self, q: JointVector) -> Result<PlannedAction, DecomposeError> {
        let action = &self.task.actions[self.index];
        let mut optimisations = Vec::new();
        let (classification, segments) = match &action.body {
            ActionBody::Explicit(segments) => {
                let mut planned = Vec::with_capacity(segments.len());
                let mut at = q;
                for (k, s) in segments.iter().enumerate() {
                    let seg = self.segment(k, s.space, s.primitives.clone(), at, s.duration)?;
                    at = seg.end;
                    planned.push(seg);
                }
                (None, planned)
            }
            ActionBody::Constraints { goal, path, duration } => {
                let Some(c) = classify(action)? else {
                    return Err(self.unreachable(0, "an action without constraints".into()));
                };
                let segments =
                    self.table(&c, goal.as_ref(), path.as_ref(), q, &mut optimisations)?;
                (Some(c), self.fit_duration(segments, *duration))
            }
        };
        if let Some(chosen) = action.segment_solvers.iter().find(|s| s.segment >= segments.len()) {
            return Err(DecomposeError::NoSuchSegment {
                action: action.name.clone(),
                segment: chosen.segment,
                count: segments.len(),
                span: chosen.span,
            });
        }
        Ok(PlannedAction {
            index: self.index,
            name: action.name.clone(),
            classification,
            segments,
            optimisations,
        })
    }

    /// The rows of docs/design.md §4's table.
    fn table(
        &self,
        c: &Classification,
        goal: Option<&GoalConstraint>,
        path: Option<&PathConstraint>,
        q: JointVector,
        reports: &mut Vec<OptReport>,
    ) -> Result<Vec<PlannedSegment>, DecomposeError> {
        let g1: Targets = goal.map(|g| g.primary.targets.clone()).unwrap_or_default();
        let g2: Targets =
            goal.and_then(|g| g.secondary.as_ref()).map(|g| g.targets.clone()).unwrap_or_default();
        let goal_space = c.goal_space.unwrap_or(Space::Cpsa);
        let path_space = c.path_space.unwrap_or(goal_space);
        let opt = &self.options.opt;
        let mut record = |name: &'static str, s: &OptSolution| {
            reports.push(OptReport {
                solver: name,
                residual: s.residual,
                sizes: s.sizes.clone(),
                evaluations: s.evaluations,
            })
        };
        Ok(match c.action_type {
            ActionType::I => {
                let path = path.ok_or_else(|| self.unreachable(0, "type I needs a path".into()))?;
                vec![self.path_segment(0, path_space, path, None, q, Fill::Hold)?]
            }
            ActionType::II => {
                let mut prims = goal_primitives(&g1);
                if let Some(path) = path.filter(|_| c.path_in_goal_space()) {
                    prims.extend(path_primitives(path, None));
                }
                vec![self.complete(0, goal_space, prims, q, None, Fill::Hold)?]
            }
            ActionType::III => {
                let ms1 =
                    self.complete(0, goal_space, goal_primitives(&g1), q, None, Fill::Hold)?;
                let g3 = self.opt1_complement(1, goal_space, &g1, &g2, &ms1.end, &mut record)?;
                let mut prims = hold_primitives(&g1);
                prims.extend(goal_primitives(&g3));
                let ms2 = self.segment(1, goal_space, prims, ms1.end, None)?;
                vec![ms1, ms2]
            }
            ActionType::IV | ActionType::V => {
                let path = path.ok_or_else(|| self.unreachable(0, "a path is needed".into()))?;
                let sol = opt2(self.robot, &g1, path, &q, Some(self.scene), opt)
                    .map_err(|e| self.opt_failed(0, e))?;
                record("Opt2", &sol);
                let fill = Fill::GoalAt(sol.state);
                let ms1 = self.path_segment(0, path_space, path, Some(&sol.sizes), q, fill)?;
                if c.action_type == ActionType::IV {
                    return Ok(vec![ms1]);
                }
                // V: MS2 reaches G1, the rest of its space as close as it can
                // stay to where MS1 ended.
                let end = self.state(&ms1.end, 0)?;
                let rest = complement_targets(goal_space, &g1, &end);
                let g4 = self.opt1_complement(1, goal_space, &g1, &rest, &ms1.end, &mut record)?;
                let mut prims = goal_primitives(&g1);
                prims.extend(goal_primitives(&g4));
                let ms2 = self.segment(1, goal_space, prims, ms1.end, None)?;
                vec![ms1, ms2]
            }
            ActionType::VI | ActionType::VII => {
                let path = path.ok_or_else(|| self.unreachable(0, "a path is needed".into()))?;
                // The goal configuration: G1 with the rest of its space from Opt1.
                let goal = opt1(self.robot, &g1, &g2, &q, Some(self.scene), opt)
                    .map_err(|e| self.opt_failed(0, e))?;
                record("Opt1", &goal);
                let g4 = complement_targets(goal_space, &g1, &goal.state);
                // Eq. 14: the end of the path nearest the goal configuration (G1, G4),
                // measured in the path's own space, where the variables left free at
                // the end of the path (G5) are matched one for one (docs/paper.md).
                let nearest: Targets =
                    path_space.variables().into_iter().map(|v| (v, goal.state.value(v))).collect();
                let sol2 = opt2(self.robot, &nearest, path, &q, Some(self.scene), opt)
                    .map_err(|e| self.opt_failed(0, e))?;
                record("Opt2", &sol2);
                let fill = Fill::GoalAt(sol2.state);
                let ms1 = self.path_segment(0, path_space, path, Some(&sol2.sizes), q, fill)?;
                if c.action_type == ActionType::VI {
                    return Ok(vec![ms1]);
                }
                // VII, eq. 12: MS2 takes G1 with the rest held, MS3 the rest to G4.
                let ms2 =
                    self.complete(1, goal_space, goal_primitives(&g1), ms1.end, None, Fill::Hold)?;
                let mut prims = hold_primitives(&g1);
                prims.extend(goal_primitives(&g4));
                let ms3 = self.segment(2, goal_space, prims, ms2.end, None)?;
                vec![ms1, ms2, ms3]
            }
        })
    }

    /// Opt1(G1, G2) from `q`: the goals of the rest of G1's space, recorded.
    fn opt1_complement(
        &self,
        k: usize,
        space: Space,
        g1: &Targets,
        g2: &Targets,
        q: &JointVector,
        record: &mut impl FnMut(&'static str, &OptSolution),
    ) -> Result<Targets, DecomposeError> {
        let sol = opt1(self.robot, g1, g2, q, Some(self.scene), &self.options.opt)
            .map_err(|e| self.opt_failed(k, e))?;
        record("Opt1", &sol);
        Ok(complement_targets(space, g1, &sol.state))
    }

    /// A segment of `path` (sizes from Opt2 where given), the rest of its
    /// space filled in by `fill`.
    fn path_segment(
        &self,
        k: usize,
        space: Space,
        path: &PathConstraint,
        sizes: Option<&[Real]>,
        q: JointVector,
        fill: Fill,
    ) -> Result<PlannedSegment, DecomposeError> {
        self.complete(k, space, path_primitives(path, sizes), q, None, fill)
    }

    /// Adds the variables of `space` that `prims` leave out, held or sent to
    /// their value in a state, then plans the segment.
    fn complete(
        &self,
        k: usize,
        space: Space,
        mut prims: Vec<Primitive>,
        q: JointVector,
        duration: Option<Real>,
        fill: Fill,
    ) -> Result<PlannedSegment, DecomposeError> {
        let covered: Vec<Variable> = prims.iter().flat_map(|p| p.variables.clone()).collect();
        let rest: Vec<Variable> =
            space.variables().into_iter().filter(|v| !covered.contains(v)).collect();
        let relaxable = if matches!(fill, Fill::Hold) { rest.clone() } else { Vec::new() };
        if !rest.is_empty() {
            prims.push(match fill {
                Fill::Hold => Primitive { variables: rest, constraint: PrimitiveConstraint::Hold },
                Fill::GoalAt(state) => Primitive {
                    constraint: PrimitiveConstraint::Goal(
                        rest.iter().map(|v| state.value(*v)).collect(),
                    ),
                    variables: rest,
                },
            });
        }
        self.segment_relaxing(k, space, prims, q, duration, &relaxable)
    }

    /// Plans a segment whose primitives cover `space`: its end configuration
    /// and duration.
    fn segment(
        &self,
        k: usize,
        space: Space,
        primitives: Vec<Primitive>,
        q: JointVector,
        duration: Option<Real>,
    ) -> Result<PlannedSegment, DecomposeError> {
        self.segment_relaxing(k, space, primitives, q, duration, &[])
    }

    /// [`Self::segment`], where the holds of `relaxable` variables (the
    /// complement the table holds, never a path the user asked for) may
    /// give way when holding them is out of reach.
    fn segment_relaxing(
        &self,
        k: usize,
        space: Space,
        primitives: Vec<Primitive>,
        q: JointVector,
        duration: Option<Real>,
        relaxable: &[Variable],
    ) -> Result<PlannedSegment, DecomposeError> {
        let start = self.state(&q, k)?;
        let mut values = start.space_values(space);
        let vars = space.variables();
        for p in &primitives {
            for (i, v) in p.variables.iter().enumerate() {
                let Some(slot) = vars.iter().position(|w| w == v) else { continue };
                values[slot] = match &p.constraint {
                    PrimitiveConstraint::Goal(targets) => targets[i],
                    PrimitiveConstraint::Path(feature) => {
                        along_path(*v, feature, feature_size(feature), &start)
                    }
                    PrimitiveConstraint::Hold => start.value(*v),
                };
            }
        }
        let reached = ArmState::from_space(self.robot, space, &values)
            .ok_or_else(|| "the segment's end state is out of reach".to_owned())
            .and_then(|state| {
                ik_cpsa(self.robot, &state.cpsa, Some(&q))
                    .map(|s| (state, s[0]))
                    .map_err(|e| e.to_string())
            });
        let (primitives, end_state, end, relaxed) = match reached {
            Ok((state, end)) => (primitives, state, end, Vec::new()),
            Err(reason) if relaxable.is_empty() => return Err(self.unreachable(k, reason)),
            Err(reason) => {
                self.relax_holds(k, primitives, relaxable, &vars, &values, &start, &q, reason)?
            }
        };
        let amplitude = (end_state.cpsa.pw - start.cpsa.pw).norm();
        let wanted = duration.unwrap_or_else(|| self.options.fitts.duration(amplitude));
        let (duration, duration_raised) = self.respect_velocity(&q, &end, wanted);
        Ok(PlannedSegment {
            space,
            pattern: segment_pattern(&primitives).unwrap_or(SegmentPattern::Path),
            duration,
            duration_raised,
            solver: self.solver(k),
            primitives,
            relaxed,
            start: q,
            end,
        })
    }

    /// When holding some variables makes the end unreachable within the
    /// joint limits, moves them as little as possible instead (Opt1 with the
    /// other variables fixed and the held values as the goal), and turns
    /// their hold into a goal. The variables moved are reported.
    #[allow(clippy::too_many_arguments)]
    fn relax_holds(
        &self,
        k: usize,
        primitives: Vec<Primitive>,
        relaxable: &[Variable],
        vars: &[Variable; 3],
        values: &[Target; 3],
        start: &ArmState,
        q: &JointVector,
        reason: String,
    ) -> Result<(Vec<Primitive>, ArmState, JointVector, Vec<Variable>), DecomposeError> {
        let held = relaxable.to_vec();
        let fixed: Targets = vars
            .iter()
            .zip(values)
            .filter(|(v, _)| !held.contains(v))
            .map(|(v, t)| (*v, *t))
            .collect();
        let keep: Targets = held.iter().map(|v| (*v, start.value(*v))).collect();
        let sol = opt1(self.robot, &fixed, &keep, q, Some(self.scene), &self.options.opt).map_err(
            |e| self.unreachable(k, format!("{reason}; relaxing the held variables: {e}")),
        )?;
        let mut prims: Vec<Primitive> = primitives
            .into_iter()
            .filter(|p| !(matches!(p.constraint, PrimitiveConstraint::Hold) && p.variables == held))
            .collect();
        prims.push(Primitive {
            constraint: PrimitiveConstraint::Goal(
                held.iter().map(|v| sol.state.value(*v)).collect(),
            ),
            variables: held.clone(),
        });
        Ok((prims, sol.state, sol.q, held))
    }

    /// The bell profile peaks at twice the mean speed: T ≥ 2 |Δq_i| / v_i.
    fn respect_velocity(&self, q0: &JointVector, q1: &JointVector, t: Real) -> (Real, bool) {
        let needed = (0..q0.len())
            .map(|i| 2.0 * (q1[i] - q0[i]).abs() / self.robot.joints[i].limits.velocity)
            .fold(0.0, Real::max);
        if needed > t { (needed, true) } else { (t, false) }
    }

    /// Scales the segments to an action's given duration (then re-raises
    /// any that would exceed a velocity limit).
    fn fit_duration(
        &self,
        mut segments: Vec<PlannedSegment>,
        total: Option<Real>,
    ) -> Vec<PlannedSegment> {
        let Some(total) = total else { return segments };
        let sum: Real = segments.iter().map(|s| s.duration).sum();
        if sum <= 0.0 {
            return segments;
        }
        for s in &mut segments {
            let wanted = s.duration * total / sum;
            (s.duration, s.duration_raised) = self.respect_velocity(&s.start, &s.end, wanted);
        }
        segments
    }
}

/// How `complete` fills the variables a segment's primitives leave out.
#[derive(Clone, Copy)]
#[allow(clippy::large_enum_variant)] // short-lived, on the stack, copied once
enum Fill {
    Hold,
    GoalAt(ArmState),
}

fn feature_size(feature: &PathFeature) -> Real {
    match feature {
        PathFeature::Line { length, .. } => length.unwrap_or(0.0),
        PathFeature::About { angle, .. } => angle.unwrap_or(0.0),
        PathFeature::By { angle } => *angle,
        PathFeature::Arc { .. } => crate::math::PI,
        PathFeature::Hold => 0.0,
    }
}

fn goal_primitives(goals: &Targets) -> Vec<Primitive> {
    if goals.is_empty() {
        return Vec::new();
    }
    vec![Primitive {
        variables: goals.iter().map(|(v, _)| *v).collect(),
        constraint: PrimitiveConstraint::Goal(goals.iter().map(|(_, t)| *t).collect()),
    }]
}

fn hold_primitives(goals: &Targets) -> Vec<Primitive> {
    if goals.is_empty() {
        return Vec::new();
    }
    vec![Primitive {
        variables: goals.iter().map(|(v, _)| *v).collect(),
        constraint: PrimitiveConstraint::Hold,
    }]
}

/// The path's items as primitives, open sizes filled from `sizes`.
fn path_primitives(path: &PathConstraint, sizes: Option<&[Real]>) -> Vec<Primitive> {
    path.items
        .iter()
        .enumerate()
        .map(|(i, item)| {
            let size = sizes.and_then(|s| s.get(i)).copied();
            let feature = match item.feature {
                PathFeature::Line { direction, length } => {
                    PathFeature::Line { direction, length: length.or(size) }
                }
                PathFeature::About { axis, angle } => {
                    PathFeature::About { axis, angle: angle.or(size) }
                }
                other => other,
            };
            let constraint = match feature {
                PathFeature::Hold => PrimitiveConstraint::Hold,
                f => PrimitiveConstraint::Path(f),
            };
            Primitive { variables: item.variables.clone(), constraint }
        })
        .collect()
}

/// The variables of `space` not in `goals`, with their values in `state`.
fn complement_targets(space: Space, goals: &Targets, state: &ArmState) -> Targets {
    space
        .variables()
        .into_iter()
        .filter(|v| !goals.iter().any(|(g, _)| g == v))
        .map(|v| (v, state.value(v)))
        .collect()
}
