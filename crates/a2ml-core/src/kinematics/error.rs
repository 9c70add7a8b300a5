use crate::math::Real;

/// A configuration or target where a representation or IK breaks down.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Singularity {
    /// The arm is straight (or fully folded): the arm plane is undefined.
    StraightArm,
    /// The wrist centre lies on the vertical through the shoulder: the
    /// reference plane of the swivel angle is undefined.
    WristAboveShoulder,
    /// Two consecutive axes of a spherical group are parallel.
    ParallelAxes,
}

impl std::fmt::Display for Singularity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::StraightArm => "the arm is straight or folded, so the arm plane is undefined",
            Self::WristAboveShoulder => {
                "the wrist centre is on the vertical through the shoulder, so the swivel angle is undefined"
            }
            Self::ParallelAxes => "two axes of a spherical joint group are parallel",
        })
    }
}

/// Why a kinematic query has no answer.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KinematicsError {
    /// The wrist target is outside the reachable annulus.
    #[error(
        "wrist target at {distance:.6} m from the shoulder is unreachable (reach {min:.6}..{max:.6} m)"
    )]
    Unreachable {
        /// |Pw| asked for (m).
        distance: Real,
        /// Smallest reachable |Pw| (m).
        min: Real,
        /// Largest reachable |Pw| (m).
        max: Real,
    },
    /// Every solution leaves the joint limits; the least violating one is named.
    #[error(
        "joint `{joint}` would be at {value:.6} rad, outside [{lower:.6}, {upper:.6}] by {excess:.6} rad"
    )]
    JointOutOfLimits {
        /// Joint name.
        joint: String,
        /// Its value in the least violating solution (rad).
        value: Real,
        /// Lower limit (rad).
        lower: Real,
        /// Upper limit (rad).
        upper: Real,
        /// How far outside (rad).
        excess: Real,
    },
    /// The configuration or target is singular for the representation.
    #[error("singular: {0}")]
    Singular(Singularity),
    /// Newton's method did not converge from any start.
    #[error("IK did not converge (best residual {residual:.3e} after {starts} starts)")]
    NoConvergence {
        /// Smallest residual norm reached.
        residual: Real,
        /// Number of starting points tried.
        starts: usize,
    },
    /// A target or configuration contains NaN or infinity.
    #[error("non-finite input: {what}")]
    NonFinite {
        /// Which input.
        what: &'static str,
    },
    /// The query needs analytic IK: a spherical shoulder and a wrist centre
    /// that joints 5-7 do not move.
    #[error("{what} needs a spherical shoulder and a wrist centre that joints 5-7 do not move")]
    NotAnalytic {
        /// The query.
        what: &'static str,
    },
}
