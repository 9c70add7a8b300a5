//! The plan as a CSV table: per sample the joint trajectory, the running segment's references
//! and every capsule-obstacle distance.

use std::io::Write;

use super::atomic::Failure;
use super::messages::QuaternionSeries;
use crate::math::{Real, UnitQuaternion};
use crate::robot::Robot;
use crate::solve::Plan;

/// A number in its shortest form that reads back exactly: plain for magnitudes in
/// [1e-4, 1e16) and zero, scientific otherwise (so 1e-300 does not print 300 zeros).
pub(super) fn number(x: Real) -> String {
    let magnitude = x.abs();
    if x == 0.0 || (1e-4..1e16).contains(&magnitude) || !x.is_finite() {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A header field, quoted (RFC 4180) when it holds a comma, a quote or a line break.
fn field(name: &str) -> String {
    if name.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", name.replace('"', "\"\""))
    } else {
        name.to_owned()
    }
}

/// `t`, then `<joint>_pos` for every joint, then `<joint>_vel`.
pub(super) fn header(joint_names: &[&str]) -> String {
    let positions = joint_names.iter().map(|j| field(&format!("{j}_pos")));
    let velocities = joint_names.iter().map(|j| field(&format!("{j}_vel")));
    std::iter::once("t".to_owned()).chain(positions).chain(velocities).collect::<Vec<_>>().join(",")
}

/// The reference columns, after the joints': the running segment's index, then Pw (m), Ow
/// (quaternion x y z w), θsw (rad), Os (quaternion), θe (rad); each named by its variable's
/// spelling ([`crate::language::Variable::as_str`]).
pub(super) const REFERENCE_COLUMNS: [&str; 14] = [
    "ref_segment",
    "ref_pw_x",
    "ref_pw_y",
    "ref_pw_z",
    "ref_ow_x",
    "ref_ow_y",
    "ref_ow_z",
    "ref_ow_w",
    "ref_swivel",
    "ref_shoulder_frame_x",
    "ref_shoulder_frame_y",
    "ref_shoulder_frame_z",
    "ref_shoulder_frame_w",
    "ref_elbow",
];

/// The distance column of a capsule and an obstacle (m).
pub(super) fn distance_column(capsule: &str, obstacle: &str) -> String {
    format!("distance_{capsule}_to_{obstacle}")
}

/// The whole header: [`header`], [`REFERENCE_COLUMNS`], then one distance column per pair.
fn full_header(robot: &Robot, plan: &Plan) -> String {
    let references = REFERENCE_COLUMNS.iter().map(|c| (*c).to_owned());
    let distances = plan.distances.iter().map(|d| field(&distance_column(&d.capsule, &d.obstacle)));
    std::iter::once(header(&robot.joint_names()))
        .chain(references)
        .chain(distances)
        .collect::<Vec<_>>()
        .join(",")
}

/// A value that may be missing: empty when it is.
fn optional(x: Option<Real>) -> String {
    x.map(number).unwrap_or_default()
}

/// The quaternion's x y z w, or four empty fields.
fn quaternion_fields(q: Option<UnitQuaternion>, series: &mut QuaternionSeries) -> [String; 4] {
    let q = q.map(|q| series.next_quaternion(q));
    [q.map(|q| q.i), q.map(|q| q.j), q.map(|q| q.k), q.map(|q| q.w)].map(optional)
}

pub(super) fn write(out: &mut impl Write, robot: &Robot, plan: &Plan) -> Result<(), Failure> {
    writeln!(out, "{}", full_header(robot, plan))?;
    let trajectory = &plan.trajectory;
    let samples =
        trajectory.times().iter().zip(trajectory.positions()).zip(trajectory.velocities());
    let (mut ow, mut os) = (QuaternionSeries::default(), QuaternionSeries::default());
    for (k, ((&t, q), qd)) in samples.enumerate() {
        let mut row: Vec<String> = std::iter::once(t)
            .chain(q.iter().copied())
            .chain(qd.iter().copied())
            .map(number)
            .collect();
        let reference = plan.references.get(k);
        let state = reference.map(|r| r.state).unwrap_or_default();
        row.push(reference.map(|r| r.segment.to_string()).unwrap_or_default());
        row.extend((0..3).map(|i| optional(state.pw.map(|p| p[i]))));
        row.extend(quaternion_fields(state.ow, &mut ow));
        row.push(optional(state.swivel));
        row.extend(quaternion_fields(state.shoulder_frame, &mut os));
        row.push(optional(state.elbow_angle));
        row.extend(plan.distances.iter().map(|d| optional(d.distance.get(k).copied().flatten())));
        writeln!(out, "{}", row.join(","))?;
    }
    Ok(())
}
