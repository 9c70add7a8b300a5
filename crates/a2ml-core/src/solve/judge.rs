//! The judgement of a solved segment, the same whichever solver made it: each component's
//! error at the end against its goal, whether every one is within its tolerance, and how far
//! the motion kept the segment's path (its distance from the path's locus, whatever the
//! timing).
//!
//! Every "reached" and "within tolerance" of the solvers is decided by [`within`] and
//! [`reached`]; the velocity loops settle on [`tolerance_units`].

use super::chart::Chart;
use super::problem::{Component, SegmentProblem};
use super::report::Tolerance;
use crate::decompose::{ArmState, goal_error};
use crate::language::Variable;
use crate::math::{JointVector, Real};
use crate::robot::Robot;
use crate::trajectory::Trajectory;

/// A segment's motion judged on the segment's own terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Judgement {
    /// Each component's error at the motion's end against its reference's end (m or rad).
    pub errors: [Real; 3],
    /// Every component within its tolerance at the end.
    pub reached: bool,
    /// The largest distance of each path component from its path over the motion (0 for
    /// goals; m or rad).
    pub path_errors: [Real; 3],
    /// The path kept within tolerance at every sample, or the path is not hard.
    pub path_kept: bool,
}

/// Whether `error` (m for Pw, rad otherwise) is within the tolerance of `variable`.
pub fn within(tolerance: &Tolerance, variable: Variable, error: Real) -> bool {
    error <= tolerance.of(variable)
}

/// Whether every component's error is within its tolerance.
pub fn reached(tolerance: &Tolerance, components: &[Component; 3], errors: &[Real; 3]) -> bool {
    components.iter().zip(errors).all(|(c, e)| within(tolerance, c.variable, *e))
}

/// Each component's error in units of its tolerance (≤ 1 is within).
pub fn tolerance_units(
    tolerance: &Tolerance,
    components: &[Component; 3],
    errors: &[Real; 3],
) -> [Real; 3] {
    std::array::from_fn(|k| errors[k] / tolerance.of(components[k].variable))
}

/// Each component's error at configuration `q` against its reference's end: distance for
/// Pw, geodesic angle for rotations, (wrapped) angle difference; infinite where `q` has no
/// state (a singular configuration).
pub fn end_errors(robot: &Robot, problem: &SegmentProblem, q: &JointVector) -> [Real; 3] {
    end_errors_at(problem, ArmState::at(robot, q).ok().as_ref())
}

/// [`end_errors`] of the arm in `state` (`None`: singular, infinite errors).
fn end_errors_at(problem: &SegmentProblem, state: Option<&ArmState>) -> [Real; 3] {
    let Some(state) = state else { return [Real::INFINITY; 3] };
    problem.components.map(|c| goal_error(state, &[(c.variable, c.reference.end())]))
}

/// The arm's state at each of the trajectory's samples (`None` where it is singular): what
/// the judgement and a segment's report read, computed once per sample.
pub fn sample_states(robot: &Robot, trajectory: &Trajectory) -> Vec<Option<ArmState>> {
    trajectory.positions().iter().map(|q| ArmState::at(robot, q).ok()).collect()
}

/// The largest distance of each path component from its path over the trajectory's samples,
/// and whether a `hard` path was kept within tolerance (always true for a soft one).
pub fn path_errors(
    robot: &Robot,
    problem: &SegmentProblem,
    chart: &Chart,
    hard: bool,
    trajectory: &Trajectory,
    tolerance: &Tolerance,
) -> ([Real; 3], bool) {
    path_errors_of(problem, chart, hard, &sample_states(robot, trajectory), tolerance)
}

/// [`path_errors`] over the samples' states ([`sample_states`]): infinite errors where a
/// sample is singular.
pub fn path_errors_of(
    problem: &SegmentProblem,
    chart: &Chart,
    hard: bool,
    states: &[Option<ArmState>],
    tolerance: &Tolerance,
) -> ([Real; 3], bool) {
    if states.iter().any(Option::is_none) {
        return ([Real::INFINITY; 3], !hard);
    }
    let worst = chart.largest_deviation(states.iter().flatten(), tolerance);
    (worst, reached(tolerance, &problem.components, &worst) || !hard)
}

/// `trajectory` judged against `problem` (its end from `fallback` when it has no samples).
pub fn judge(
    robot: &Robot,
    problem: &SegmentProblem,
    chart: &Chart,
    hard: bool,
    trajectory: &Trajectory,
    tolerance: &Tolerance,
    fallback: &JointVector,
) -> Judgement {
    let states = sample_states(robot, trajectory);
    judge_states(robot, problem, chart, hard, &states, tolerance, fallback)
}

/// [`judge`] over the states of the trajectory's samples ([`sample_states`]); the end is
/// the last sample's, else `fallback`'s.
pub fn judge_states(
    robot: &Robot,
    problem: &SegmentProblem,
    chart: &Chart,
    hard: bool,
    states: &[Option<ArmState>],
    tolerance: &Tolerance,
    fallback: &JointVector,
) -> Judgement {
    let errors = match states.last() {
        Some(end) => end_errors_at(problem, end.as_ref()),
        None => end_errors(robot, problem, fallback),
    };
    let (path_errors, path_kept) = path_errors_of(problem, chart, hard, states, tolerance);
    Judgement {
        errors,
        reached: reached(tolerance, &problem.components, &errors),
        path_errors,
        path_kept,
    }
}
