//! The segment problem every solver takes: the three variables of one representation space,
//! each with its reference over the segment and its role (a goal, weighted on a schedule, or a
//! path, kept). Built once per segment by [`super::plan`] from where the arm really is.

use crate::language::{Space, Variable};
use crate::math::Real;
use crate::profile::{Reference, Role};

/// One state variable of a segment: what it follows and how it is weighted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Component {
    /// The variable.
    pub variable: Variable,
    /// Its reference over the segment.
    pub reference: Reference,
    /// Goal (scheduled weight) or path (constant weight).
    pub role: Role,
}

/// A segment for any solver: the three components of one space, in [`Space::variables`] order.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentProblem {
    /// CPSA or HAT.
    pub space: Space,
    /// One component per variable of the space, in its order.
    pub components: [Component; 3],
    /// The references' duration T (s).
    pub duration: Real,
}

/// Rows of a variable in its space's Jacobian: its [dimension](Variable::dimension).
pub(crate) fn width(variable: Variable) -> usize {
    variable.dimension()
}
