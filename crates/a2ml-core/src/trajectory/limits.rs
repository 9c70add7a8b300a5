//! Joint limits held at every instant of a trajectory, between its samples too: q follows the
//! cubic Hermite curve of the samples' q and q', so on each interval q̈ is linear (its extremes
//! at the ends), q' quadratic (at the ends or where q̈ = 0) and q cubic (at the ends or where
//! q' = 0). Every extreme is computed exactly, not sampled.

use crate::math::{DOF, JointVector, Real};
use crate::robot::Robot;

use super::Trajectory;

/// The limits a trajectory must hold, per joint.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Limits {
    /// Lower position limits (rad).
    pub lower: JointVector,
    /// Upper position limits (rad).
    pub upper: JointVector,
    /// Speed limits (rad/s).
    pub velocity: JointVector,
    /// Acceleration limits (rad/s²).
    pub acceleration: JointVector,
}

impl Limits {
    /// The robot's own limits.
    pub fn of(robot: &Robot) -> Self {
        Self {
            lower: robot.lower(),
            upper: robot.upper(),
            velocity: robot.velocity_limits(),
            acceleration: robot.acceleration_limits(),
        }
    }

    /// The same limits with every acceleration limit times `scale`.
    pub fn with_acceleration_scale(self, scale: Real) -> Self {
        Self { acceleration: self.acceleration * scale, ..self }
    }
}

/// The largest |q'| and |q̈| per joint over part of a trajectory.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Peaks {
    /// Largest |q'| per joint (rad/s).
    pub velocity: JointVector,
    /// Largest |q̈| per joint (rad/s²).
    pub acceleration: JointVector,
    /// Lowest q per joint (rad).
    pub lowest: JointVector,
    /// Highest q per joint (rad).
    pub highest: JointVector,
}

impl Peaks {
    /// The largest |q'_i| / velocity_i over the joints.
    pub fn velocity_ratio(&self, limits: &Limits) -> Real {
        self.velocity.component_div(&limits.velocity).amax()
    }

    /// The largest |q̈_i| / acceleration_i over the joints.
    pub fn acceleration_ratio(&self, limits: &Limits) -> Real {
        self.acceleration.component_div(&limits.acceleration).amax()
    }

    /// The factor by which time must be stretched for both rates to be within their limits
    /// (velocities scale with 1/k, accelerations with 1/k²); at most 1 when they are.
    pub fn stretch(&self, limits: &Limits) -> Real {
        self.velocity_ratio(limits).max(self.acceleration_ratio(limits).sqrt())
    }

    /// Whether every position is within [lower - tolerance, upper + tolerance].
    pub fn positions_within(&self, limits: &Limits, tolerance: Real) -> bool {
        (0..DOF).all(|i| {
            self.lowest[i] >= limits.lower[i] - tolerance
                && self.highest[i] <= limits.upper[i] + tolerance
        })
    }
}

/// The extremes of one joint on one Hermite interval: (min q, max q, max |q'|, max |q̈|).
fn interval_extremes(p0: Real, p1: Real, v0: Real, v1: Real, h: Real) -> [Real; 4] {
    let (m0, m1, delta) = (v0 * h, v1 * h, p1 - p0);
    // d²q/ds² at s = 0 and s = 1 (s = (t - t0)/h), linear between.
    let a0 = 6.0 * delta - 4.0 * m0 - 2.0 * m1;
    let a1 = -6.0 * delta + 2.0 * m0 + 4.0 * m1;
    // dq/ds = c2 s² + c1 s + c0.
    let (c2, c1, c0) = (-6.0 * delta + 3.0 * m0 + 3.0 * m1, a0, m0);
    let rate = |s: Real| (c2 * s + c1) * s + c0;
    let position = |s: Real| {
        let (s2, s3) = (s * s, s * s * s);
        p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
            + m0 * (s3 - 2.0 * s2 + s)
            + p1 * (-2.0 * s3 + 3.0 * s2)
            + m1 * (s3 - s2)
    };
    let mut speed = v0.abs().max(v1.abs());
    if a0 * a1 < 0.0 {
        speed = speed.max(rate(a0 / (a0 - a1)).abs() / h);
    }
    let (mut low, mut high) = (p0.min(p1), p0.max(p1));
    let mut stationary = |s: Real| {
        if s > 0.0 && s < 1.0 {
            let q = position(s);
            low = low.min(q);
            high = high.max(q);
        }
    };
    if c2.abs() > 1e-300 {
        let disc = c1 * c1 - 4.0 * c2 * c0;
        if disc >= 0.0 {
            let root = disc.sqrt();
            stationary((-c1 + root) / (2.0 * c2));
            stationary((-c1 - root) / (2.0 * c2));
        }
    } else if c1.abs() > 1e-300 {
        stationary(-c0 / c1);
    }
    [low, high, speed, a0.abs().max(a1.abs()) / (h * h)]
}

/// The extremes of q, |q'| and |q̈| per joint over every interval of `trajectory` that
/// overlaps [from, to] (every sample's own values included).
pub fn peaks(trajectory: &Trajectory, from: Real, to: Real) -> Peaks {
    let (times, q, qd) = (trajectory.times(), trajectory.positions(), trajectory.velocities());
    let mut out = Peaks {
        velocity: JointVector::zeros(),
        acceleration: JointVector::zeros(),
        lowest: JointVector::repeat(Real::INFINITY),
        highest: JointVector::repeat(Real::NEG_INFINITY),
    };
    for k in 0..times.len() {
        let inside = times[k] >= from && times[k] <= to;
        let next_overlaps = k + 1 < times.len() && times[k + 1] > from && times[k] < to;
        if inside {
            for i in 0..DOF {
                out.lowest[i] = out.lowest[i].min(q[k][i]);
                out.highest[i] = out.highest[i].max(q[k][i]);
                out.velocity[i] = out.velocity[i].max(qd[k][i].abs());
            }
        }
        if next_overlaps {
            let h = times[k + 1] - times[k];
            for i in 0..DOF {
                let [low, high, speed, accel] =
                    interval_extremes(q[k][i], q[k + 1][i], qd[k][i], qd[k + 1][i], h);
                out.lowest[i] = out.lowest[i].min(low);
                out.highest[i] = out.highest[i].max(high);
                out.velocity[i] = out.velocity[i].max(speed);
                out.acceleration[i] = out.acceleration[i].max(accel);
            }
        }
    }
    out
}

/// Per interval (index of its first sample), per joint: the extremes (min q, max q, max |q'|,
/// max |q̈|) of the Hermite curve, for [`super::check_limits`].
pub(super) fn intervals(
    trajectory: &Trajectory,
) -> impl Iterator<Item = (usize, usize, [Real; 4])> + '_ {
    let (times, q, qd) = (trajectory.times(), trajectory.positions(), trajectory.velocities());
    (0..times.len().saturating_sub(1)).flat_map(move |k| {
        let h = times[k + 1] - times[k];
        (0..DOF).map(move |i| {
            (k, i, interval_extremes(q[k][i], q[k + 1][i], qd[k][i], qd[k + 1][i], h))
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The extremes found exactly agree with a dense sampling of the same curve.
    #[test]
    fn interval_extremes_match_dense_sampling() {
        let cases =
            [(0.0, 1.0, 0.0, 0.0, 1.0), (0.2, -0.3, 3.0, -2.0, 0.5), (1.0, 1.0, -4.0, 4.0, 0.1)];
        for (p0, p1, v0, v1, h) in cases {
            let [low, high, speed, accel] = interval_extremes(p0, p1, v0, v1, h);
            let (m0, m1) = (v0 * h, v1 * h);
            let (mut dl, mut dh, mut ds, mut da) = (Real::INFINITY, Real::NEG_INFINITY, 0.0, 0.0);
            for k in 0..=10_000 {
                let s = k as Real / 10_000.0;
                let q = p0 * (2.0 * s * s * s - 3.0 * s * s + 1.0)
                    + m0 * (s * s * s - 2.0 * s * s + s)
                    + p1 * (-2.0 * s * s * s + 3.0 * s * s)
                    + m1 * (s * s * s - s * s);
                let dq = p0 * (6.0 * s * s - 6.0 * s)
                    + m0 * (3.0 * s * s - 4.0 * s + 1.0)
                    + p1 * (-6.0 * s * s + 6.0 * s)
                    + m1 * (3.0 * s * s - 2.0 * s);
                let ddq = p0 * (12.0 * s - 6.0)
                    + m0 * (6.0 * s - 4.0)
                    + p1 * (6.0 - 12.0 * s)
                    + m1 * (6.0 * s - 2.0);
                (dl, dh) = (dl.min(q), dh.max(q));
                ds = Real::max(ds, dq.abs() / h);
                da = Real::max(da, ddq.abs() / (h * h));
            }
            assert!(low <= dl + 1e-12 && low >= dl - 1e-6, "{low} {dl}");
            assert!(high >= dh - 1e-12 && high <= dh + 1e-6, "{high} {dh}");
            assert!(speed >= ds - 1e-9 && speed <= ds * (1.0 + 1e-6) + 1e-9, "{speed} {ds}");
            assert!((accel - da).abs() <= 1e-9 * da.max(1.0), "{accel} {da}");
        }
    }
}
