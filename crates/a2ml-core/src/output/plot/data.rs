//! What the plots show, taken out of a plan once as plain numbers: series in SI units over the
//! plan's time, the limits, the segments, the clearances and the scene's outlines. Drawing
//! reads only this.

use crate::collision::{self, CollisionScene, DistanceOptions};
use crate::decompose::{ArmState, DecomposeOptions, PlannedSegment, decompose};
use crate::kinematics::arm_pose;
use crate::language::{Obstacle, PathFeature, PrimitiveConstraint, Target, Task, Variable};
use crate::math::{DOF, JointVector, Real, Rotation3, Vector3};
use crate::robot::Robot;
use crate::solve::{Plan, SegmentReport};

/// Far enough that every capsule-obstacle pair of a workspace is measured (m).
const EVERY_PAIR: Real = 1e3;

/// One segment as the plots mark it.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentMark {
    /// Start in the plan's time (s).
    pub start: Real,
    /// End in the plan's time (s).
    pub end: Real,
    /// 1-based number over the whole plan, as the boundary is labelled.
    pub number: usize,
    /// `push/1 IV qp`: action, segment, action type, solver.
    pub label: String,
}

/// A line over time that may have gaps: runs of (t, value) points.
pub type Runs = Vec<Vec<(Real, Real)>>;

/// The featured variable of some segments, as one scalar or three, against what was asked.
#[derive(Debug, Clone, PartialEq)]
pub struct FeaturedPanel {
    /// The variable.
    pub variable: Variable,
    /// The y axis: quantity and unit.
    pub axis: String,
    /// Named actual series (solid).
    pub actual: Vec<(String, Runs)>,
    /// Named reference series (dashed), the same names as `actual` where they pair.
    pub reference: Vec<(String, Runs)>,
    /// Goal or path-end values over their segments: (start, end, value, series index).
    pub targets: Vec<(Real, Real, Real, usize)>,
    /// The segments that feature the variable: (start, end).
    pub spans: Vec<(Real, Real)>,
}

/// The distance of one arm capsule to one obstacle over time (m).
#[derive(Debug, Clone, PartialEq)]
pub struct DistanceSeries {
    /// The capsule's name.
    pub capsule: String,
    /// Index of the capsule in the robot's list (its colour).
    pub capsule_index: usize,
    /// The obstacle's name.
    pub obstacle: String,
    /// Signed distance (m); a gap where the obstacle is a contact of the action.
    pub runs: Runs,
}

/// Everything the plots draw.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotData {
    /// `task … · robot … · solver …`.
    pub caption: String,
    /// Joint names, in the order of q.
    pub joint_names: Vec<String>,
    /// Sample times (s).
    pub times: Vec<Real>,
    /// q (rad) per sample.
    pub q: Vec<JointVector>,
    /// q' (rad/s) per sample.
    pub qd: Vec<JointVector>,
    /// q'' (rad/s²) per sample, by central differences of q'.
    pub qdd: Vec<JointVector>,
    /// Lower position limits (rad).
    pub lower: JointVector,
    /// Upper position limits (rad).
    pub upper: JointVector,
    /// Speed limits (rad/s).
    pub speed: JointVector,
    /// The segments in time order.
    pub segments: Vec<SegmentMark>,
    /// One panel per variable featured by some segment.
    pub featured: Vec<FeaturedPanel>,
    /// Capsule names, in the robot's order.
    pub capsules: Vec<String>,
    /// One series per moving capsule and obstacle.
    pub distances: Vec<DistanceSeries>,
    /// The safety distance the solvers kept (m).
    pub safety_distance: Real,
    /// Planned Pw per sample, {b} (m).
    pub wrist: Vec<Vector3>,
    /// Reference Pw, {b} (m).
    pub wrist_reference: Vec<Vector3>,
    /// The scene in {b}.
    pub obstacles: Vec<Obstacle>,
}

impl PlotData {
    /// Takes out of `plan` (made from `task` on `robot`) what the plots draw. The goals drawn
    /// against the featured variables are the decomposition's, with default options, as
    /// `solve::plan` uses them.
    pub fn new(robot: &Robot, task: &Task, plan: &Plan) -> Self {
        let task_b = task.in_base_frame(&robot.structure.shoulder_in_base_link);
        let times = plan.trajectory.times().to_vec();
        let q = plan.trajectory.positions().to_vec();
        let qd = plan.trajectory.velocities().to_vec();
        let states: Vec<Option<ArmState>> = q.iter().map(|q| ArmState::at(robot, q).ok()).collect();
        let planned = decompose(robot, task, &DecomposeOptions::default())
            .map(|d| d.actions.into_iter().map(|a| (a.index, a.segments)).collect::<Vec<_>>())
            .unwrap_or_default();
        let featured = featured_panels(plan, &times, &states, &planned);
        Self {
            caption: caption(robot, plan),
            joint_names: plan.joint_names.clone(),
            qdd: differentiate(&times, &qd),
            lower: robot.lower(),
            upper: robot.upper(),
            speed: robot.velocity_limits(),
            segments: marks(plan),
            featured,
            capsules: robot.capsules.iter().map(|c| c.name.clone()).collect(),
            distances: distances(robot, &task_b, plan, &times, &q),
            safety_distance: plan.safety_distance,
            wrist: states.iter().flatten().map(|s| s.cpsa.pw).collect(),
            wrist_reference: plan.wrist_reference.iter().map(|(_, p)| *p).collect(),
            obstacles: task_b.scene.clone(),
            times,
            q,
            qd,
        }
    }

    /// The plan's time span (s), never empty.
    pub fn time_range(&self) -> (Real, Real) {
        let start = self.times.first().copied().unwrap_or(0.0);
        let end = self.times.last().copied().unwrap_or(start);
        (start, if end > start { end } else { start + 1.0 })
    }
}

/// `task push · robot iiwa14 · solver qp, rrt`.
fn caption(robot: &Robot, plan: &Plan) -> String {
    let mut solvers: Vec<&str> = Vec::new();
    for s in &plan.segments {
        if !solvers.contains(&s.solver.name()) {
            solvers.push(s.solver.name());
        }
    }
    let solvers = if solvers.is_empty() { "-".to_owned() } else { solvers.join(", ") };
    format!("task {} · robot {} · solver {solvers}", plan.task, robot.name)
}

/// The segments with their numbers and labels.
fn marks(plan: &Plan) -> Vec<SegmentMark> {
    plan.segments
        .iter()
        .enumerate()
        .map(|(i, s)| SegmentMark {
            start: s.start,
            end: s.end,
            number: i + 1,
            label: format!(
                "{}/{} {} {}",
                s.action,
                s.segment + 1,
                s.action_type.map_or("-", |t| t.numeral()),
                s.solver.name()
            ),
        })
        .collect()
}

/// q'' by central differences (one-sided at the ends); zeros for a single sample.
fn differentiate(times: &[Real], qd: &[JointVector]) -> Vec<JointVector> {
    let n = times.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n.saturating_sub(1)));
            let dt = times.get(b).zip(times.get(a)).map_or(0.0, |(tb, ta)| tb - ta);
            match (qd.get(b), qd.get(a)) {
                (Some(vb), Some(va)) if dt > 0.0 => (vb - va) / dt,
                _ => JointVector::zeros(),
            }
        })
        .collect()
}

/// Points where `value` is defined, split into runs at the samples where it is not.
pub(super) fn runs(points: impl Iterator<Item = (Real, Option<Real>)>) -> Runs {
    let mut out: Runs = Vec::new();
    let mut current = Vec::new();
    for (t, v) in points {
        match v {
            Some(v) if v.is_finite() => current.push((t, v)),
            _ if !current.is_empty() => out.push(std::mem::take(&mut current)),
            _ => {}
        }
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

/// Every moving capsule's distance to every obstacle of the scene, left out (a gap) during
/// the actions that touch the obstacle on purpose (`contact`).
fn distances(
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    times: &[Real],
    q: &[JointVector],
) -> Vec<DistanceSeries> {
    let options = DistanceOptions { influence: EVERY_PAIR };
    let scenes: Vec<CollisionScene> =
        task.scene.iter().map(|o| CollisionScene::new(std::slice::from_ref(o))).collect();
    // Per sample and obstacle, the distance of every moving capsule (by name).
    let measured: Vec<Vec<Vec<(String, Real)>>> = q
        .iter()
        .map(|q| {
            let pose = arm_pose(robot, q);
            scenes
                .iter()
                .map(|scene| {
                    collision::distances(robot, &pose, scene, &options)
                        .into_iter()
                        .filter(|p| p.obstacle_frame.is_none())
                        .map(|p| (p.link, p.distance))
                        .collect()
                })
                .collect()
        })
        .collect();
    let contact_at = |t: Real, obstacle: &str| {
        action_at(plan, t).is_some_and(|a| {
            task.actions.get(a).is_some_and(|a| a.contact.iter().any(|c| c == obstacle))
        })
    };
    let mut out = Vec::new();
    for (k, obstacle) in task.scene.iter().enumerate() {
        for (capsule_index, capsule) in robot.capsules.iter().enumerate() {
            let values = times.iter().zip(&measured).map(|(&t, per_obstacle)| {
                let d = per_obstacle.get(k).and_then(|pairs| {
                    pairs.iter().find(|(name, _)| *name == capsule.name).map(|(_, d)| *d)
                });
                (t, if contact_at(t, &obstacle.name) { None } else { d })
            });
            let runs = runs(values);
            if !runs.is_empty() {
                out.push(DistanceSeries {
                    capsule: capsule.name.clone(),
                    capsule_index,
                    obstacle: obstacle.name.clone(),
                    runs,
                });
            }
        }
    }
    out
}

/// The decomposition's segment that `s` solved.
fn planned_segment<'p>(
    planned: &'p [(usize, Vec<PlannedSegment>)],
    s: &SegmentReport,
) -> Option<&'p PlannedSegment> {
    planned.iter().find(|(index, _)| *index == s.action_index)?.1.get(s.segment)
}

/// The index in `Task::actions` of the action running at time `t`.
fn action_at(plan: &Plan, t: Real) -> Option<usize> {
    plan.segments.iter().rev().find(|s| s.start <= t).map(|s| s.action_index)
}

/// A segment's target for `variable`: the goal's value, or the path's end for a sized
/// rotation `about` an axis (as an angle from the segment's start).
enum Asked {
    Goal(Target),
    Turn(Real),
    Hold,
}

fn asked(segment: &PlannedSegment, variable: Variable) -> Option<Asked> {
    segment.primitives.iter().find_map(|p| {
        let i = p.variables.iter().position(|v| *v == variable)?;
        Some(match &p.constraint {
            PrimitiveConstraint::Goal(targets) => Asked::Goal(*targets.get(i)?),
            PrimitiveConstraint::Path(PathFeature::About { angle: Some(a), .. }) => {
                Asked::Turn(a.abs())
            }
            PrimitiveConstraint::Path(_) => return None,
            PrimitiveConstraint::Hold => Asked::Hold,
        })
    })
}

fn rotation_of(state: &ArmState, variable: Variable) -> Option<Rotation3> {
    match state.value(variable) {
        Target::Rotation(r) => Some(r),
        _ => None,
    }
}

fn angle_of(state: &ArmState, variable: Variable) -> Option<Real> {
    match state.value(variable) {
        Target::Angle(a) => Some(a),
        _ => None,
    }
}

/// One panel per featured variable, in the order the variables are listed.
fn featured_panels(
    plan: &Plan,
    times: &[Real],
    states: &[Option<ArmState>],
    planned: &[(usize, Vec<PlannedSegment>)],
) -> Vec<FeaturedPanel> {
    Variable::ALL
        .iter()
        .filter_map(|&variable| {
            let featuring: Vec<&SegmentReport> =
                plan.segments.iter().filter(|s| s.focus.contains(&variable)).collect();
            if featuring.is_empty() {
                return None;
            }
            let spans = featuring.iter().map(|s| (s.start, s.end)).collect();
            let mut panel = match variable {
                Variable::Pw => wrist_panel(plan, times, states),
                Variable::Swivel | Variable::Elbow => angle_panel(variable, times, states),
                Variable::Ow | Variable::Os => {
                    rotation_panel(variable, &featuring, times, states, planned)
                }
            };
            panel.spans = spans;
            for s in &featuring {
                let Some(asked) = planned_segment(planned, s).and_then(|p| asked(p, variable))
                else {
                    continue;
                };
                match (variable, asked) {
                    (Variable::Pw, Asked::Goal(Target::Position(p))) => {
                        for (k, value) in [p.x, p.y, p.z].into_iter().enumerate() {
                            panel.targets.push((s.start, s.end, value, k));
                        }
                    }
                    (Variable::Swivel | Variable::Elbow, Asked::Goal(Target::Angle(a))) => {
                        panel.targets.push((s.start, s.end, a.to_degrees(), 0));
                    }
                    (Variable::Ow | Variable::Os, Asked::Goal(_) | Asked::Hold) => {
                        panel.targets.push((s.start, s.end, 0.0, 0));
                    }
                    (Variable::Ow | Variable::Os, Asked::Turn(a)) => {
                        panel.targets.push((s.start, s.end, a.to_degrees(), 0));
                    }
                    _ => {}
                }
            }
            Some(panel)
        })
        .collect()
}

/// Pw's components against the reference the segments followed.
fn wrist_panel(plan: &Plan, times: &[Real], states: &[Option<ArmState>]) -> FeaturedPanel {
    let component = |k: usize| {
        runs(times.iter().zip(states).map(|(&t, s)| (t, s.as_ref().map(|s| s.cpsa.pw[k]))))
    };
    let reference = |k: usize| runs(plan.wrist_reference.iter().map(|(t, p)| (*t, Some(p[k]))));
    let names = ["x", "y", "z"];
    FeaturedPanel {
        variable: Variable::Pw,
        axis: "Pw (m)".to_owned(),
        actual: (0..3).map(|k| (names[k].to_owned(), component(k))).collect(),
        reference: (0..3).map(|k| (names[k].to_owned(), reference(k))).collect(),
        targets: Vec::new(),
        spans: Vec::new(),
    }
}

/// θsw or θe over the whole plan (deg).
fn angle_panel(variable: Variable, times: &[Real], states: &[Option<ArmState>]) -> FeaturedPanel {
    let values = times
        .iter()
        .zip(states)
        .map(|(&t, s)| (t, s.as_ref().and_then(|s| angle_of(s, variable)).map(Real::to_degrees)));
    FeaturedPanel {
        variable,
        axis: format!("{} (°)", variable.symbol()),
        actual: vec![(variable.symbol().to_owned(), runs(values))],
        reference: Vec::new(),
        targets: Vec::new(),
        spans: Vec::new(),
    }
}

/// Ow or Os over the segments that feature it: the angle to the segment's goal (0 is
/// reached), or the angle turned from the segment's start for a path about an axis (deg).
fn rotation_panel(
    variable: Variable,
    featuring: &[&SegmentReport],
    times: &[Real],
    states: &[Option<ArmState>],
    planned: &[(usize, Vec<PlannedSegment>)],
) -> FeaturedPanel {
    let mut runs_all: Runs = Vec::new();
    for s in featuring {
        let inside =
            || times.iter().zip(states).filter(move |(t, _)| **t >= s.start && **t <= s.end);
        let first =
            inside().find_map(|(_, st)| st.as_ref().and_then(|st| rotation_of(st, variable)));
        let from = match planned_segment(planned, s).and_then(|p| asked(p, variable)) {
            Some(Asked::Goal(Target::Rotation(goal))) => Some(goal),
            Some(Asked::Turn(_) | Asked::Hold) => first,
            _ => None,
        };
        let Some(from) = from else { continue };
        runs_all.extend(runs(inside().map(|(&t, st)| {
            let angle = st
                .as_ref()
                .and_then(|st| rotation_of(st, variable))
                .map(|r| r.angle_to(&from).to_degrees());
            (t, angle)
        })));
    }
    FeaturedPanel {
        variable,
        axis: format!("{} angle (°)", variable.symbol()),
        actual: vec![(format!("{} to goal or from start", variable.symbol()), runs_all)],
        reference: Vec::new(),
        targets: Vec::new(),
        spans: Vec::new(),
    }
}

/// The joint count, for loops that read better with a name.
pub(super) const JOINTS: usize = DOF;
