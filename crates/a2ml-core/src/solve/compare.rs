//! The same task planned by several solvers, side by side: one [`ComparisonRecord`] per solver
//! and segment, judged from the plan itself (goal errors, path kept, the worst joint-limit
//! margin and its joint, the smallest clearance and its link, the peak joint speed against the
//! limits), plus the wall time each solver took.

use std::collections::BTreeMap;
use std::time::Instant;

use super::plan::{PlanOptions, SolveError, plan};
use super::report::{Plan, SegmentReport};
use crate::language::{SolverChoice, Task};
use crate::math::{DOF, Real};
use crate::robot::Robot;

/// One solver's attempt at the task.
#[derive(Debug, Clone)]
pub struct Attempt {
    /// The solver asked for.
    pub solver: SolverChoice,
    /// The plan, or why there is none.
    pub outcome: Result<Plan, SolveError>,
    /// Wall time of planning (s): reported, never used to decide anything.
    pub planning_time: Real,
}

/// Plans `task` once per solver in `solvers`, each overriding the task's own choices.
pub fn compare(
    robot: &Robot,
    task: &Task,
    solvers: &[SolverChoice],
    options: &PlanOptions,
) -> Vec<Attempt> {
    solvers
        .iter()
        .map(|&solver| {
            let started = Instant::now();
            let outcome =
                plan(robot, task, &PlanOptions { solver: Some(solver), ..options.clone() });
            Attempt { solver, outcome, planning_time: started.elapsed().as_secs_f64() }
        })
        .collect()
}

/// One row of the comparison: a solver on one segment (or its failure, with `error` set and
/// the segment fields empty).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ComparisonRecord {
    /// The solver asked for (`auto`, `gpm`, ...).
    pub solver: String,
    /// The solver that produced the segment (`auto` resolves to `qp` or `rrt`).
    pub solved_by: Option<String>,
    /// The action.
    pub action: Option<String>,
    /// The segment's index in its action (0-based).
    pub segment: Option<usize>,
    /// Final error of each variable of the segment's space, keyed by its spelling
    /// ([`crate::language::Variable::as_str`]) (m or rad).
    pub errors: BTreeMap<String, Real>,
    /// Every goal within tolerance at the end.
    pub reached: Option<bool>,
    /// The hard path kept (always true for a soft one).
    pub path_kept: Option<bool>,
    /// Largest distance from the path of any path variable (m for Pw, rad otherwise), by
    /// its spelling.
    pub path_errors: BTreeMap<String, Real>,
    /// Smallest distance of any joint to its position limits (rad; negative = outside).
    pub limit_margin: Option<Real>,
    /// The joint where that margin occurs.
    pub limit_joint: Option<String>,
    /// Smallest clearance to the scene (m; negative = penetration), when there is a scene.
    pub clearance: Option<Real>,
    /// The link capsule of that clearance.
    pub clearance_link: Option<String>,
    /// The largest |q'_i| / q'_max,i over the segment's samples (> 1 = too fast).
    pub peak_speed_ratio: Option<Real>,
    /// The segment's duration in the plan, settling included (s).
    pub duration: Option<Real>,
    /// Wall time of planning the whole task with this solver (s).
    pub planning_time: Real,
    /// Why the solver produced no plan.
    pub error: Option<String>,
}

/// The records of one attempt: one per segment, or one carrying the error.
pub fn records(robot: &Robot, attempt: &Attempt) -> Vec<ComparisonRecord> {
    let empty = ComparisonRecord {
        solver: attempt.solver.name().to_owned(),
        solved_by: None,
        action: None,
        segment: None,
        errors: BTreeMap::new(),
        reached: None,
        path_kept: None,
        path_errors: BTreeMap::new(),
        limit_margin: None,
        limit_joint: None,
        clearance: None,
        clearance_link: None,
        peak_speed_ratio: None,
        duration: None,
        planning_time: attempt.planning_time,
        error: None,
    };
    match &attempt.outcome {
        Err(e) => vec![ComparisonRecord { error: Some(e.to_string()), ..empty }],
        Ok(plan) => plan.segments.iter().map(|s| segment_record(robot, plan, s, &empty)).collect(),
    }
}

fn segment_record(
    robot: &Robot,
    plan: &Plan,
    s: &SegmentReport,
    empty: &ComparisonRecord,
) -> ComparisonRecord {
    let by_name = |errors: &[super::VariableError]| {
        errors.iter().map(|e| (e.variable.as_str().to_owned(), e.error)).collect()
    };
    let (lower, upper, speed) = (robot.lower(), robot.upper(), robot.velocity_limits());
    let t = &plan.trajectory;
    let mut margin: Option<(Real, usize)> = None;
    let mut peak: Option<Real> = None;
    let samples = t.times().iter().zip(t.positions()).zip(t.velocities());
    for ((_, q), v) in
        samples.filter(|((time, _), _)| **time >= s.start - 1e-9 && **time <= s.end + 1e-9)
    {
        for i in 0..DOF {
            let m = (q[i] - lower[i]).min(upper[i] - q[i]);
            if margin.is_none_or(|(best, _)| m < best) {
                margin = Some((m, i));
            }
            let ratio = v[i].abs() / speed[i];
            peak = Some(peak.map_or(ratio, |p: Real| p.max(ratio)));
        }
    }
    ComparisonRecord {
        solved_by: Some(s.solver.name().to_owned()),
        action: Some(s.action.clone()),
        segment: Some(s.segment),
        errors: by_name(&s.errors),
        reached: Some(s.reached),
        path_kept: Some(s.path_kept),
        path_errors: by_name(&s.path_errors),
        limit_margin: margin.map(|(m, _)| m),
        limit_joint: margin.map(|(_, i)| robot.joints[i].name.clone()),
        clearance: s.clearance.as_ref().map(|c| c.distance),
        clearance_link: s.clearance.as_ref().map(|c| c.link.clone()),
        peak_speed_ratio: peak,
        duration: Some(s.end - s.start),
        ..empty.clone()
    }
}
