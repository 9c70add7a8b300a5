use crate::language::{ValueKind, Variable};
use crate::math::Real;

/// Why a profile, reference or join cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProfileError {
    /// The duration is negative or not finite, or zero while the distance is not.
    #[error("invalid duration {duration} s for a distance of {distance}")]
    InvalidDuration {
        /// Duration asked for (s).
        duration: Real,
        /// Distance to travel in it.
        distance: Real,
    },
    /// The distance of a bell profile is negative or not finite.
    #[error("invalid distance {distance} (must be finite and non-negative)")]
    InvalidDistance {
        /// Distance asked for.
        distance: Real,
    },
    /// A speed limit is not positive and finite.
    #[error("invalid speed limit {limit} (must be positive and finite)")]
    InvalidSpeedLimit {
        /// The limit.
        limit: Real,
    },
    /// A start or goal value is of the wrong kind for its variable.
    #[error("{} takes a {expected:?} value, not a {found:?}", variable.symbol())]
    KindMismatch {
        /// The variable.
        variable: Variable,
        /// The kind it takes.
        expected: ValueKind,
        /// The kind given.
        found: ValueKind,
    },
    /// The path feature does not apply to the variable (`line` on a rotation, ...).
    #[error("the path feature `{feature}` does not apply to {}", variable.symbol())]
    FeatureMismatch {
        /// The variable.
        variable: Variable,
        /// The feature's keyword.
        feature: &'static str,
    },
    /// The path feature has no size S yet (Opt2 fills it in).
    #[error("the path feature `{feature}` of {} has no size", variable.symbol())]
    MissingSize {
        /// The variable.
        variable: Variable,
        /// The feature's keyword.
        feature: &'static str,
    },
    /// A direction or axis has (nearly) zero length.
    #[error("the {what} has zero length")]
    DegenerateAxis {
        /// Which vector.
        what: &'static str,
    },
    /// No semi-ellipse runs from the start to the goal through the given point.
    #[error("no semi-elliptic arc through the point: {reason}")]
    DegenerateArc {
        /// Why.
        reason: &'static str,
    },
    /// A value contains NaN or infinity.
    #[error("non-finite {what}")]
    NonFinite {
        /// Which value.
        what: &'static str,
    },
    /// A transitional overlap is negative, not finite, or longer than a segment.
    #[error(
        "invalid overlap {overlap} s between segments of {first_duration} s and {second_duration} s"
    )]
    InvalidOverlap {
        /// Overlap asked for (s).
        overlap: Real,
        /// Duration of the first segment (s).
        first_duration: Real,
        /// Duration of the second segment (s).
        second_duration: Real,
    },
    /// A sequential join where the next segment does not start where the last one ended.
    #[error("joint {joint} jumps by {gap:.3e} rad at the sequential seam")]
    Discontinuous {
        /// Joint index (0-based).
        joint: usize,
        /// |q2(0) - q1(T1)| (rad).
        gap: Real,
    },
    /// A sequential join where a segment is not at rest at the seam.
    #[error("joint {joint} moves at {velocity:.3e} rad/s at the sequential seam")]
    NotAtRest {
        /// Joint index (0-based).
        joint: usize,
        /// The velocity at the seam (rad/s).
        velocity: Real,
    },
}
