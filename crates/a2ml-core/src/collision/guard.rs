//! The shapes a collision query can be trusted with: finite, non-negative sizes within the
//! workspace bound ([`crate::language::MAX_LENGTH`]). Checked once before planning, so that
//! no pair is ever skipped for a shape parry cannot handle (it loses its footing, and even
//! panics, on sizes near the largest number).

use crate::language::{MAX_LENGTH, Obstacle, Shape};
use crate::math::{Matrix3, Real, Rotation3, Vector3};
use crate::robot::Robot;

/// A shape no collision query can check.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ShapeError {
    /// An arm capsule with a radius that is not a finite non-negative number, or an end that
    /// is not finite or lies beyond the workspace bound from its frame.
    #[error(
        "the arm's capsule `{name}` cannot be checked for collisions: {why} (radii and \
         ends must be finite, radii non-negative, ends within {MAX_LENGTH} m)"
    )]
    Capsule {
        /// The capsule's name.
        name: String,
        /// What is wrong.
        why: String,
    },
    /// An obstacle with a size or position that is not finite, not positive or beyond the
    /// workspace bound.
    #[error(
        "obstacle `{name}` cannot be checked for collisions: {why} (sizes positive, \
         rotations orthonormal, everything finite and within {MAX_LENGTH} m)"
    )]
    Obstacle {
        /// The obstacle's name.
        name: String,
        /// What is wrong.
        why: String,
    },
}

fn within(v: &Vector3) -> bool {
    v.iter().all(|x| x.is_finite() && x.abs() <= MAX_LENGTH)
}

/// A rotation matrix within rounding: orthonormal, determinant one (a `Rotation3` built
/// unchecked can be anything).
fn proper(r: &Rotation3) -> bool {
    let m = r.matrix();
    m.iter().all(|x| x.is_finite())
        && (m.transpose() * m - Matrix3::identity()).amax() < 1e-6
        && m.determinant() > 0.0
}

fn size_ok(x: Real, positive: bool) -> bool {
    x.is_finite() && x <= MAX_LENGTH && if positive { x > 0.0 } else { x >= 0.0 }
}

/// Every arm capsule of `robot` and every obstacle checkable.
///
/// # Errors
/// The first [`ShapeError`] found.
pub fn check_shapes(robot: &Robot, obstacles: &[Obstacle]) -> Result<(), ShapeError> {
    for c in &robot.capsules {
        let why = if !size_ok(c.radius, false) {
            Some(format!("its radius is {}", c.radius))
        } else if !(within(&c.a) && within(&c.b)) {
            Some(format!("its ends are {:?} and {:?}", c.a.as_slice(), c.b.as_slice()))
        } else {
            None
        };
        if let Some(why) = why {
            return Err(ShapeError::Capsule { name: c.name.clone(), why });
        }
    }
    for o in obstacles {
        let ok = match &o.shape {
            Shape::Box { center, size, rotation } => {
                within(center) && size.iter().all(|s| size_ok(*s, true)) && proper(rotation)
            }
            Shape::Sphere { center, radius } => within(center) && size_ok(*radius, true),
            Shape::Capsule { a, b, radius } => within(a) && within(b) && size_ok(*radius, true),
            Shape::Cylinder { center, radius, height, rotation } => {
                within(center)
                    && size_ok(*radius, true)
                    && size_ok(*height, true)
                    && proper(rotation)
            }
        };
        if !ok {
            let why = format!("{:?}", o.shape);
            return Err(ShapeError::Obstacle { name: o.name.clone(), why });
        }
    }
    Ok(())
}
