//! What the plots show, taken out of a plan once as plain numbers: series in SI units over the
//! plan's time, the limits, the segments, the clearances and the scene's outlines. Drawing
//! reads only this.

use crate::decompose::ArmState;
use crate::language::{Obstacle, SolverChoice, Target, Task, ValueKind, Variable};
use crate::math::{DOF, JointVector, Real, Rotation3, Vector3};
use crate::output::{RecordedPlan, RecordedSegment};
use crate::robot::Robot;
use crate::solve::{Plan, ReferenceSample, ReferenceState};

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
    /// Takes out of `plan` (made from `task` on `robot`) what the plots draw.
    pub fn new(robot: &Robot, task: &Task, plan: &Plan) -> Self {
        let task_b = task.in_base_frame(&robot.structure.shoulder_in_base_link);
        Self::recorded(robot, &task_b.scene, &RecordedPlan::of(plan))
    }

    /// Takes out of a plan read back from its recording what the plots draw; `obstacles` are
    /// the task's scene in {b}. A plan and its MCAP recording give the same data.
    pub fn recorded(robot: &Robot, obstacles: &[Obstacle], plan: &RecordedPlan) -> Self {
        let times = plan.trajectory.times().to_vec();
        let q = plan.trajectory.positions().to_vec();
        let qd = plan.trajectory.velocities().to_vec();
        let states: Vec<Option<ArmState>> = q.iter().map(|q| ArmState::at(robot, q).ok()).collect();
        let featured = featured_panels(plan, &times, &states);
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
            distances: distances(plan, &times),
            safety_distance: plan.safety_distance.unwrap_or(0.0),
            wrist: states.iter().flatten().map(|s| s.cpsa.pw).collect(),
            wrist_reference: plan.wrist_reference.clone(),
            obstacles: obstacles.to_vec(),
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
fn caption(robot: &Robot, plan: &RecordedPlan) -> String {
    let mut solvers: Vec<&str> = Vec::new();
    for s in plan.segments.iter().filter_map(|s| s.solver) {
        if !solvers.contains(&s.name()) {
            solvers.push(s.name());
        }
    }
    let solvers = if solvers.is_empty() { "-".to_owned() } else { solvers.join(", ") };
    let task = plan.task.as_deref().unwrap_or("-");
    format!("task {task} · robot {} · solver {solvers}", robot.name)
}

/// The segments with their numbers and labels.
fn marks(plan: &RecordedPlan) -> Vec<SegmentMark> {
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
                s.solver.map_or("-", SolverChoice::name)
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

/// The recorded distance of every capsule-obstacle pair over time, a gap where it was not
/// measured (the action touches the obstacle on purpose).
fn distances(plan: &RecordedPlan, times: &[Real]) -> Vec<DistanceSeries> {
    plan.distances
        .iter()
        .filter_map(|d| {
            let runs = runs(times.iter().zip(&d.distance).map(|(&t, d)| (t, *d)));
            (!runs.is_empty()).then(|| DistanceSeries {
                capsule: d.capsule.clone(),
                capsule_index: d.capsule_index,
                obstacle: d.obstacle.clone(),
                runs,
            })
        })
        .collect()
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

/// A rotation variable of a reference state.
fn reference_rotation(state: &ReferenceState, variable: Variable) -> Option<Rotation3> {
    let q = match variable {
        Variable::Ow => state.ow,
        Variable::Os => state.shoulder_frame,
        _ => None,
    };
    q.map(|q| q.to_rotation_matrix())
}

/// An angle variable of a reference state (rad).
fn reference_angle(state: &ReferenceState, variable: Variable) -> Option<Real> {
    match variable {
        Variable::Swivel => state.swivel,
        Variable::Elbow => state.elbow_angle,
        _ => None,
    }
}

/// One panel per featured variable, in the order the variables are listed.
fn featured_panels(
    plan: &RecordedPlan,
    times: &[Real],
    states: &[Option<ArmState>],
) -> Vec<FeaturedPanel> {
    Variable::ALL
        .iter()
        .filter_map(|&variable| {
            let featuring: Vec<(usize, &RecordedSegment)> = plan
                .segments
                .iter()
                .enumerate()
                .filter(|(_, s)| s.focus.contains(&variable))
                .collect();
            if featuring.is_empty() {
                return None;
            }
            let mut panel = match variable.kind() {
                ValueKind::Position => wrist_panel(plan, times, states),
                ValueKind::Angle => angle_panel(variable, plan, times, states),
                ValueKind::Rotation => rotation_panel(variable, &featuring, plan, times, states),
            };
            panel.spans = featuring.iter().map(|(_, s)| (s.start, s.end)).collect();
            for (_, s) in &featuring {
                let end = &s.reference_end;
                match variable.kind() {
                    ValueKind::Position => {
                        for (k, value) in end.pw.iter().flat_map(|p| [p.x, p.y, p.z]).enumerate() {
                            panel.targets.push((s.start, s.end, value, k));
                        }
                    }
                    ValueKind::Angle => {
                        if let Some(a) = reference_angle(end, variable) {
                            panel.targets.push((s.start, s.end, a.to_degrees(), 0));
                        }
                    }
                    ValueKind::Rotation => {
                        if reference_rotation(end, variable).is_some() {
                            panel.targets.push((s.start, s.end, 0.0, 0));
                        }
                    }
                }
            }
            Some(panel)
        })
        .collect()
}

/// The reference of each sample, where it gives `value`.
fn reference_runs(
    plan: &RecordedPlan,
    times: &[Real],
    value: impl Fn(&ReferenceSample) -> Option<Real>,
) -> Runs {
    runs(times.iter().zip(&plan.references).map(|(&t, r)| (t, value(r))))
}

/// Pw's components against the reference the segments followed.
fn wrist_panel(plan: &RecordedPlan, times: &[Real], states: &[Option<ArmState>]) -> FeaturedPanel {
    let component = |k: usize| {
        runs(times.iter().zip(states).map(|(&t, s)| (t, s.as_ref().map(|s| s.cpsa.pw[k]))))
    };
    let reference = |k: usize| reference_runs(plan, times, |r| r.state.pw.map(|p| p[k]));
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

/// θsw or θe over the whole plan (deg), against the running segment's reference.
fn angle_panel(
    variable: Variable,
    plan: &RecordedPlan,
    times: &[Real],
    states: &[Option<ArmState>],
) -> FeaturedPanel {
    let values = times
        .iter()
        .zip(states)
        .map(|(&t, s)| (t, s.as_ref().and_then(|s| angle_of(s, variable)).map(Real::to_degrees)));
    let reference =
        reference_runs(plan, times, |r| reference_angle(&r.state, variable).map(Real::to_degrees));
    let symbol = variable.symbol().to_owned();
    FeaturedPanel {
        variable,
        axis: format!("{} (°)", variable.symbol()),
        actual: vec![(symbol.clone(), runs(values))],
        reference: vec![(symbol, reference)],
        targets: Vec::new(),
        spans: Vec::new(),
    }
}

/// Ow or Os over the segments that feature it: the angle to the segment's reference end (its
/// goal, or the end of its path; 0 is reached), planned and reference (deg).
fn rotation_panel(
    variable: Variable,
    featuring: &[(usize, &RecordedSegment)],
    plan: &RecordedPlan,
    times: &[Real],
    states: &[Option<ArmState>],
) -> FeaturedPanel {
    let (mut actual, mut reference): (Runs, Runs) = (Vec::new(), Vec::new());
    for (index, s) in featuring {
        let Some(end) = reference_rotation(&s.reference_end, variable) else { continue };
        let inside = times.iter().zip(states).filter(|(t, _)| **t >= s.start && **t <= s.end);
        actual.extend(runs(inside.map(|(&t, st)| {
            let angle = st
                .as_ref()
                .and_then(|st| rotation_of(st, variable))
                .map(|r| r.angle_to(&end).to_degrees());
            (t, angle)
        })));
        let own = times.iter().zip(&plan.references).filter(|(_, r)| r.segment == *index);
        reference.extend(runs(own.map(|(&t, r)| {
            (t, reference_rotation(&r.state, variable).map(|r| r.angle_to(&end).to_degrees()))
        })));
    }
    let label = format!("{} to goal or path end", variable.symbol());
    FeaturedPanel {
        variable,
        axis: format!("{} angle (°)", variable.symbol()),
        actual: vec![(label.clone(), actual)],
        reference: vec![(label, reference)],
        targets: Vec::new(),
        spans: Vec::new(),
    }
}

/// The joint count, for loops that read better with a name.
pub(super) const JOINTS: usize = DOF;
