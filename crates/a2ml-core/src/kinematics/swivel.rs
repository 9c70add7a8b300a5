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
//! feasibility cannot change; one decomposition at each piece's midpoint
//! decides it, per group, since q4 does not depend on θ.

use super::error::KinematicsError;
use super::ik::{Split, triangle_placements};
use super::spaces::{CpsaState, cpsa_to_hat, hat_points};
use crate::math::{
    Few, Matrix3, PI, Real, Rotation3, Vector3, projector, rotation_about, skew, solve_trig,
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

/// One three-axis joint group (shoulder 1-3 or wrist 5-7) whose rotation
/// turns with θsw.
struct Group<'a> {
    rotation: TrigMatrix,
    axes: [&'a Vector3; 3],
    limits: [(Real, Real); 3],
}

impl TrigMatrix {
    fn at(&self, theta: Real) -> Matrix3 {
        let (s, c) = theta.sin_cos();
        self.a * c + self.b * s + self.c
    }

    /// The θ where `uᵀ R(θ) v = k`.
    fn roots(&self, u: &Vector3, v: &Vector3, k: Real) -> Few<Real, 2> {
        let f = |m: &Matrix3| u.dot(&(m * v));
        solve_trig(f(&self.a), f(&self.b), k - f(&self.c))
    }
}

/// Whether `v` or `v ± 2π` lies in [lower, upper].
fn angle_within((lower, upper): (Real, Real), v: Real) -> bool {
    [v, v - 2.0 * PI, v + 2.0 * PI].iter().any(|x| *x >= lower && *x <= upper)
}

impl Group<'_> {
    /// Every θ where one joint of the group reaches a limit.
    fn limit_roots(&self) -> Vec<Real> {
        let [wa, wb, wc] = self.axes;
        let mut out = Vec::new();
        for (i, (lower, upper)) in self.limits.into_iter().enumerate() {
            if upper - lower >= 2.0 * PI {
                continue;
            }
            for limit in [lower, upper] {
                let r = &self.rotation;
                out.extend(match i {
                    // R = Ra Rb Rc: fixing one angle leaves one scalar of R fixed.
                    0 => r.roots(&(rotation_about(wa, limit) * wb), wc, wb.dot(wc)),
                    1 => r.roots(wa, wc, wa.dot(&(rotation_about(wb, limit) * wc))),
                    _ => r.roots(wa, &(rotation_about(wc, -limit) * wb), wa.dot(wb)),
                });
            }
        }
        out
    }

    /// Whether some solution of the group at θ lies within its limits. A solution's middle
    /// angle comes first: one outside its limits is not finished (its outer angles cost two
    /// more turns each).
    fn feasible_at(&self, theta: Real, near_a: Real) -> bool {
        let [wa, wb, wc] = self.axes;
        let Ok(split) = Split::new(&self.rotation.at(theta), wa, wb, wc, near_a) else {
            return false;
        };
        (0..split.len).any(|i| {
            angle_within(self.limits[1], split.middle(i)) && {
                let [a, _, c] = split.solution(i);
                angle_within(self.limits[0], a) && angle_within(self.limits[2], c)
            }
        })
    }

    /// The feasible θ as sorted disjoint intervals of [-π, π].
    fn feasible(&self, near_a: Real) -> Vec<SwivelInterval> {
        let mut cuts = self.limit_roots();
        cuts.extend([-PI, PI]);
        cuts.sort_by(Real::total_cmp);
        cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
        let mut out: Vec<SwivelInterval> = Vec::new();
        for pair in cuts.windows(2) {
            let (lower, upper) = (pair[0], pair[1]);
            if !self.feasible_at(0.5 * (lower + upper), near_a) {
                continue;
            }
            match out.last_mut() {
                Some(last) if (last.upper - lower).abs() < 1e-12 => last.upper = upper,
                _ => out.push(SwivelInterval { lower, upper }),
            }
        }
        out
    }
}

fn intersect(a: &[SwivelInterval], b: &[SwivelInterval]) -> Vec<SwivelInterval> {
    let mut out = Vec::new();
    for x in a {
        for y in b {
            let (lower, upper) = (x.lower.max(y.lower), x.upper.min(y.upper));
            if lower < upper {
                out.push(SwivelInterval { lower, upper });
            }
        }
    }
    out
}

fn union(mut all: Vec<SwivelInterval>) -> Vec<SwivelInterval> {
    all.sort_by(|a, b| a.lower.total_cmp(&b.lower));
    let mut out: Vec<SwivelInterval> = Vec::with_capacity(all.len());
    for i in all {
        match out.last_mut() {
            Some(last) if i.lower <= last.upper + 1e-12 => last.upper = last.upper.max(i.upper),
            _ => out.push(i),
        }
    }
    out
}

/// The swivel angles for which some IK branch reaching (Pw, Ow) lies within
/// the joint limits, as sorted disjoint intervals of [-π, π] (an interval
/// through ±π appears as two pieces).
///
/// # Errors
/// [`KinematicsError::NotAnalytic`] unless the arm has analytic IK;
/// [`KinematicsError::Unreachable`]; the wrist above the shoulder.
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
    let hat = cpsa_to_hat(robot, &CpsaState { pw: *pw, ow: *ow, swivel: 0.0 })?;
    let (elbow0, wrist) = hat_points(robot, &hat);
    let x = wrist.normalize();
    let xx = x * x.transpose();
    let hand = ow.matrix() * s.hand_zero.matrix().transpose();
    let near = robot.middle();

    // The shoulder and wrist groups are independent once q4 is fixed (it
    // does not depend on θ), so each q4 branch contributes the intersection
    // of the two groups' feasible sets.
    let mut feasible = Vec::new();
    for (q4, r0, r1234) in triangle_placements(robot, &s.wrist_zero, &elbow0, &wrist)? {
        if !angle_within(limit(3), q4) {
            continue;
        }
        let shoulder = Group {
            rotation: TrigMatrix { a: projector(&x) * r0, b: -skew(&x) * r0, c: xx * r0 },
            axes: [&w[0], &w[1], &w[2]],
            limits: [limit(0), limit(1), limit(2)],
        };
        let r1234t = r1234.transpose();
        let wrist_group = Group {
            rotation: TrigMatrix {
                a: r1234t * projector(&x) * hand,
                b: r1234t * skew(&x) * hand,
                c: r1234t * xx * hand,
            },
            axes: [&w[4], &w[5], &w[6]],
            limits: [limit(4), limit(5), limit(6)],
        };
        feasible.extend(intersect(&shoulder.feasible(near[0]), &wrist_group.feasible(near[4])));
    }
    Ok(union(feasible))
}
