//! The swivel angles at which an arm with a spherical shoulder and wrist can
//! hold a wrist pose (Pw, Ow) inside its joint limits, in closed form.
//!
//! As in the arm-angle method of Shimizu et al. (2008): changing θsw turns
//! the arm triangle about the S-W line, so the shoulder rotation is
//! `R123(θ) = Rot(x, -θ) R123(0)` and the wrist rotation
//! `R567(θ) = R1234(0)ᵀ Rot(x, θ) Ow Ow0ᵀ`, both of the form
//! `A cos θ + B sin θ + C`. A joint of a three-axis group sits at a limit L
//! exactly when one scalar `uᵀ R(θ) v` equals a constant, so every limit
//! crossing is a root of `a cos θ + b sin θ = c`. Between consecutive roots
//! feasibility cannot change; one IK at each piece's midpoint decides it.

use super::error::KinematicsError;
use super::ik::analytic_branches;
use super::spaces::{CpsaState, cpsa_to_hat, hat_points};
use crate::math::{
    DOF, Matrix3, PI, Real, Rotation3, Vector3, projector, rotation_about, skew, solve_trig,
};
use crate::robot::Robot;

/// A closed interval of swivel angles [lower, upper] within [-π, π] (rad).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SwivelInterval {
    /// Smallest angle (rad).
    pub lower: Real,
    /// Largest angle (rad).
    pub upper: Real,
}

impl SwivelInterval {
    /// Whether θ lies in the interval.
    pub fn contains(&self, theta: Real) -> bool {
        theta >= self.lower && theta <= self.upper
    }
}

/// `A cos θ + B sin θ + C` for a rotation that depends on θ.
struct TrigMatrix {
    a: Matrix3,
    b: Matrix3,
    c: Matrix3,
}

impl TrigMatrix {
    /// The θ where `uᵀ R(θ) v = k`.
    fn roots(&self, u: &Vector3, v: &Vector3, k: Real) -> Vec<Real> {
        let f = |m: &Matrix3| u.dot(&(m * v));
        solve_trig(f(&self.a), f(&self.b), k - f(&self.c))
    }

    /// The θ where one joint of the group about axes `w` reaches a limit.
    fn limit_roots(&self, w: [&Vector3; 3], limits: [(Real, Real); 3], out: &mut Vec<Real>) {
        let [wa, wb, wc] = w;
        for (i, (lower, upper)) in limits.into_iter().enumerate() {
            if upper - lower >= 2.0 * PI {
                continue;
            }
            for limit in [lower, upper] {
                out.extend(match i {
                    0 => self.roots(&(rotation_about(wa, limit) * wb), wc, wb.dot(wc)),
                    1 => self.roots(wa, wc, wa.dot(&(rotation_about(wb, limit) * wc))),
                    _ => self.roots(wa, &(rotation_about(wc, -limit) * wb), wa.dot(wb)),
                });
            }
        }
    }
}

/// The swivel angles for which some IK branch reaching (Pw, Ow) lies within
/// the joint limits, as sorted disjoint intervals of [-π, π] (an interval
/// through ±π appears as two pieces).
///
/// # Errors
/// [`KinematicsError::NotAnalytic`] unless shoulder and wrist are
/// spherical; [`KinematicsError::Unreachable`]; the wrist above the shoulder.
pub fn swivel_intervals(
    robot: &Robot,
    pw: &Vector3,
    ow: &Rotation3,
) -> Result<Vec<SwivelInterval>, KinematicsError> {
    if !robot.has_analytic_ik() {
        return Err(KinematicsError::NotAnalytic { what: "swivel feasibility" });
    }
    let s = &robot.structure;
    let w = &s.axes_zero;
    let limit = |i: usize| (robot.joints[i].limits.lower, robot.joints[i].limits.upper);
    let near = robot.middle();
    let points_at = |theta: Real| -> Result<(Vector3, Vector3), KinematicsError> {
        let hat = cpsa_to_hat(robot, &CpsaState { pw: *pw, ow: *ow, swivel: theta })?;
        Ok(hat_points(robot, &hat))
    };
    let (elbow0, wrist) = points_at(0.0)?;
    let x = wrist.normalize();
    let xx = x * x.transpose();
    let hand = ow.matrix() * s.hand_zero.matrix().transpose();

    let mut roots = Vec::new();
    // Every q4 branch: its elbow-triangle rotation R123(0) and wrist group.
    for q in analytic_branches(robot, &elbow0, &wrist, ow, &near)? {
        let r0 = rotation_about(&w[0], q[0]) * rotation_about(&w[1], q[1]) * rotation_about(&w[2], q[2]);
        let shoulder = TrigMatrix { a: projector(&x) * r0, b: -skew(&x) * r0, c: xx * r0 };
        shoulder.limit_roots([&w[0], &w[1], &w[2]], [limit(0), limit(1), limit(2)], &mut roots);
        let r1234t = (r0 * rotation_about(&w[3], q[3])).transpose();
        let wrist_group =
            TrigMatrix { a: r1234t * projector(&x) * hand, b: r1234t * skew(&x) * hand, c: r1234t * xx * hand };
        wrist_group.limit_roots([&w[4], &w[5], &w[6]], [limit(4), limit(5), limit(6)], &mut roots);
    }
    roots.extend([-PI, PI]);
    roots.sort_by(Real::total_cmp);
    roots.dedup_by(|a, b| (*a - *b).abs() < 1e-12);

    let feasible = |theta: Real| {
        points_at(theta)
            .and_then(|(e, w)| analytic_branches(robot, &e, &w, ow, &near))
            .map(|branches| branches.iter().any(|q| robot.within_limits(q, 0.0)))
            .unwrap_or(false)
    };
    let mut intervals: Vec<SwivelInterval> = Vec::new();
    for pair in roots.windows(2) {
        let (lower, upper) = (pair[0], pair[1]);
        if !feasible(0.5 * (lower + upper)) {
            continue;
        }
        match intervals.last_mut() {
            Some(last) if (last.upper - lower).abs() < 1e-12 => last.upper = upper,
            _ => intervals.push(SwivelInterval { lower, upper }),
        }
    }
    debug_assert!(intervals.iter().all(|i| i.lower <= i.upper && i.upper - i.lower <= 2.0 * PI + 1e-9));
    let _ = DOF;
    Ok(intervals)
}
