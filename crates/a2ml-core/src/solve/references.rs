//! What the segments asked for at each sample of the plan (issue 16 item 5): the reference of
//! every variable of the running segment, mapped to the other space as well, so that a plot
//! draws each featured variable against its reference.

use super::problem::SegmentProblem;
use super::report::{ReferenceSample, ReferenceState};
use crate::kinematics::{CpsaState, HatState, cpsa_to_hat, hat_to_cpsa};
use crate::language::Space;
use crate::math::{Real, Rotation3, UnitQuaternion};
use crate::profile::Sample;
use crate::robot::Robot;

/// A segment as joined into the plan: where it starts, how much it was slowed, its problem.
pub(super) struct Placed<'a> {
    /// Start in the plan's time (s).
    pub start: Real,
    /// The factor it was slowed down by (1: as solved).
    pub stretch: Real,
    /// Its references.
    pub problem: &'a SegmentProblem,
}

fn quaternion(r: &Rotation3) -> UnitQuaternion {
    UnitQuaternion::from_rotation_matrix(r)
}

/// The references of `problem` at its own time `t`, held at their ends outside [0, T].
pub(super) fn reference_state(robot: &Robot, problem: &SegmentProblem, t: Real) -> ReferenceState {
    let t = t.clamp(0.0, problem.duration);
    let [a, b, c] = problem.components.each_ref().map(|c| c.reference.sample(t));
    match (problem.space, a, b, c) {
        (
            Space::Cpsa,
            Sample::Position { value: pw, .. },
            Sample::Rotation { value: ow, .. },
            Sample::Angle { value: swivel, .. },
        ) => {
            let hat = cpsa_to_hat(robot, &CpsaState { pw, ow, swivel }).ok();
            ReferenceState {
                pw: Some(pw),
                ow: Some(quaternion(&ow)),
                swivel: Some(swivel),
                shoulder_frame: hat.map(|h| quaternion(&h.shoulder_frame)),
                elbow_angle: hat.map(|h| h.elbow_angle),
            }
        }
        (
            Space::Hat,
            Sample::Rotation { value: shoulder_frame, .. },
            Sample::Angle { value: elbow_angle, .. },
            Sample::Rotation { value: ow, .. },
        ) => {
            let cpsa = hat_to_cpsa(robot, &HatState { shoulder_frame, elbow_angle, ow }).ok();
            ReferenceState {
                pw: cpsa.map(|s| s.pw),
                ow: Some(quaternion(&ow)),
                swivel: cpsa.map(|s| s.swivel),
                shoulder_frame: Some(quaternion(&shoulder_frame)),
                elbow_angle: Some(elbow_angle),
            }
        }
        _ => ReferenceState::default(),
    }
}

/// The reference at each of `times` of the segment running then (the latest to start, the
/// first before it starts); its own time runs `stretch` times slower than the plan's.
pub(super) fn reference_samples(
    robot: &Robot,
    segments: &[Placed],
    times: &[Real],
) -> Vec<ReferenceSample> {
    if segments.is_empty() {
        return Vec::new();
    }
    times
        .iter()
        .map(|&t| {
            let segment = segments.iter().rposition(|s| s.start <= t).unwrap_or(0);
            let s = &segments[segment];
            let state = reference_state(robot, s.problem, (t - s.start) / s.stretch);
            ReferenceSample { segment, state }
        })
        .collect()
}

/// Each segment's references at its end T.
pub(super) fn reference_ends(robot: &Robot, segments: &[Placed]) -> Vec<ReferenceState> {
    segments.iter().map(|s| reference_state(robot, s.problem, s.problem.duration)).collect()
}
