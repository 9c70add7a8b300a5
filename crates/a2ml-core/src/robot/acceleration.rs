//! Joint acceleration limits, which URDF does not have: the a2ml extension attribute
//! `a2ml_acceleration` (rad/s²) on a joint's `<limit>` element, which the ROS URDF parsers
//! ignore as an unknown attribute (read with the rest of the URDF in `urdf.rs`), else
//! [`DEFAULT_ACCELERATION_PER_SECOND`] times the joint's velocity limit.

use crate::math::Real;

/// The default acceleration limit of a joint is its velocity limit times this (1/s): the joint
/// reaches full speed from rest in 0.1 s. Human reaching peaks near 10-30 rad/s² at the
/// shoulder and elbow (3.14 rad/s here gives 31); Franka's datasheet gives the Panda 7.5-20
/// rad/s² for 2.2-2.6 rad/s (3.4-8 per second), so a robot file with datasheet values should
/// state them with the attribute.
pub const DEFAULT_ACCELERATION_PER_SECOND: Real = 10.0;

/// The attribute of `<limit>` holding a joint's acceleration limit (rad/s²).
pub const ATTRIBUTE: &str = "a2ml_acceleration";
