//! The joint trajectory as a CSV table.

use std::io::Write;

use super::atomic::Failure;
use crate::math::Real;
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

pub(super) fn write(out: &mut impl Write, robot: &Robot, plan: &Plan) -> Result<(), Failure> {
    writeln!(out, "{}", header(&robot.joint_names()))?;
    let trajectory = &plan.trajectory;
    let samples =
        trajectory.times().iter().zip(trajectory.positions()).zip(trajectory.velocities());
    for ((&t, q), qd) in samples {
        let row: Vec<String> = std::iter::once(t)
            .chain(q.iter().copied())
            .chain(qd.iter().copied())
            .map(number)
            .collect();
        writeln!(out, "{}", row.join(","))?;
    }
    Ok(())
}
