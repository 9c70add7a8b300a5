//! The rules of the five state variables (Pw, Ow, θsw, Os, θe) that every stage asks
//! instead of deciding again: how many rows a variable takes, that θsw wraps and θe does
//! not, the difference and distance between two values, and the body axes read from a
//! frame. Names, spaces and kinds are on [`Variable`] beside its definition.

use super::task::{BodyAxis, Target, ValueKind, Variable};
use crate::math::{Real, Vector3, rotation_distance, rotation_log, wrap_angle};

impl Variable {
    /// Whether the variable's value is an angle taken modulo a turn: θsw is (an arm plane
    /// half a turn round is the same plane reached the other way), θe is not (it is fixed
    /// in [0, π] by the arm triangle, so its plain difference is the motion).
    pub fn wraps(self) -> bool {
        self == Variable::Swivel
    }

    /// Rows the variable takes in a task vector: 3 for a position or a rotation (its
    /// rotation vector), 1 for an angle.
    pub fn dimension(self) -> usize {
        match self.kind() {
            ValueKind::Position | ValueKind::Rotation => 3,
            ValueKind::Angle => 1,
        }
    }

    /// `to - from` for an angle of this variable (rad): the shorter way round, in (-π, π],
    /// when it [wraps](Self::wraps), the plain difference otherwise.
    pub fn angle_difference(self, to: Real, from: Real) -> Real {
        if self.wraps() { wrap_angle(to - from) } else { to - from }
    }

    /// The difference `to - from` in the variable's tangent space, in {b}: the position
    /// difference (m), the spatial rotation vector log(to · from⁻¹) (rad), or the
    /// [angle difference](Self::angle_difference) in x (the first
    /// [`dimension`](Self::dimension) components count). `None` when the values are not
    /// both of one kind.
    pub fn difference(self, to: &Target, from: &Target) -> Option<Vector3> {
        match (to, from) {
            (Target::Position(a), Target::Position(b)) => Some(a - b),
            (Target::Rotation(a), Target::Rotation(b)) => Some(rotation_log(&(a * b.inverse()))),
            (Target::Angle(a), Target::Angle(b)) => {
                Some(Vector3::new(self.angle_difference(*a, *b), 0.0, 0.0))
            }
            _ => None,
        }
    }

    /// The distance between two values: Euclidean for a position (m), the geodesic angle
    /// for a rotation (rad), the absolute [angle difference](Self::angle_difference) for an
    /// angle. `None` when the values are not both of one kind.
    pub fn distance(self, a: &Target, b: &Target) -> Option<Real> {
        match (a, b) {
            (Target::Position(a), Target::Position(b)) => Some((a - b).norm()),
            (Target::Rotation(a), Target::Rotation(b)) => Some(rotation_distance(a, b)),
            (Target::Angle(a), Target::Angle(b)) => Some(self.angle_difference(*a, *b).abs()),
            _ => None,
        }
    }

    /// The two body axes named after the frame's first two columns: r, l for Os and f, p
    /// for Ow (`axes(r: .., l: ..)` writes them); `None` for a variable that is no frame.
    pub fn body_axes(self) -> Option<[BodyAxis; 2]> {
        match self {
            Variable::Os => Some([BodyAxis::R, BodyAxis::L]),
            Variable::Ow => Some([BodyAxis::F, BodyAxis::P]),
            Variable::Pw | Variable::Swivel | Variable::Elbow => None,
        }
    }
}

impl BodyAxis {
    /// The axis as the language names it: `r`, `l`, `f` or `p`.
    pub fn name(self) -> &'static str {
        match self {
            BodyAxis::R => "r",
            BodyAxis::L => "l",
            BodyAxis::F => "f",
            BodyAxis::P => "p",
        }
    }

    /// The frame the axis is read from (Os for r, l; Ow for f, p) and its column there.
    pub fn frame(self) -> (Variable, usize) {
        match self {
            BodyAxis::R => (Variable::Os, 0),
            BodyAxis::L => (Variable::Os, 1),
            BodyAxis::F => (Variable::Ow, 0),
            BodyAxis::P => (Variable::Ow, 1),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{PI, Rotation3};

    #[test]
    fn the_swivel_wraps_and_the_elbow_does_not() {
        assert!(Variable::Swivel.wraps());
        assert!(!Variable::Elbow.wraps());
        let (to, from) = (3.0, -3.0);
        assert!((Variable::Swivel.angle_difference(to, from) - (6.0 - 2.0 * PI)).abs() < 1e-15);
        assert_eq!(Variable::Elbow.angle_difference(to, from), 6.0);
        let d = Variable::Swivel.distance(&Target::Angle(to), &Target::Angle(from));
        assert!((d.expect("angles") - (2.0 * PI - 6.0)).abs() < 1e-15);
    }

    #[test]
    fn rows_differences_and_axes_follow_the_kind() {
        let rows: Vec<usize> = Variable::ALL.iter().map(|v| v.dimension()).collect();
        assert_eq!(rows.iter().sum::<usize>(), 11);
        let a = Rotation3::from_euler_angles(0.1, 0.2, 0.3);
        let b = Rotation3::from_euler_angles(-0.2, 0.1, 0.4);
        let d = Variable::Ow.difference(&Target::Rotation(a), &Target::Rotation(b)).expect("rot");
        assert!((Rotation3::new(d) * b).angle_to(&a) < 1e-12);
        let distance = Variable::Ow.distance(&Target::Rotation(a), &Target::Rotation(b));
        assert!((distance.expect("rotations") - d.norm()).abs() < 1e-12);
        assert_eq!(
            Variable::Pw.difference(&Target::Angle(0.0), &Target::Position(a * Vector3::x())),
            None
        );
        for v in [Variable::Os, Variable::Ow] {
            for axis in v.body_axes().expect("a frame") {
                assert_eq!(axis.frame().0, v);
            }
        }
        assert_eq!(Variable::Swivel.body_axes(), None);
        assert_eq!(BodyAxis::P.name(), "p");
    }
}
