//! The rules of the five state variables (Pw, Ow, θsw, Os, θe) that every stage asks
//! instead of deciding again: how many rows a variable takes, that θsw wraps and θe does
//! not, the difference and distance between two values, and the body axes read from a
//! frame, what its errors measure (their default tolerance and the unit a user reads them
//! in). Names, spaces and kinds are on [`Variable`] beside its definition.

use super::task::{BodyAxis, Target, ValueKind, Variable};
use crate::math::{Real, Vector3, rotation_distance, rotation_log, wrap_angle};

/// What a variable's errors measure: a length (Pw, in m) or an angle (the geodesic angle of
/// a rotation, or an angle's difference, in rad). A goal tolerance is one per measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measure {
    /// Metres, shown in millimetres.
    Length,
    /// Radians, shown in degrees.
    Angle,
}

impl Measure {
    /// The default goal tolerance: 1 mm for a length, 1° for an angle.
    pub fn default_tolerance(self) -> Real {
        match self {
            Measure::Length => 1e-3,
            Measure::Angle => 1.0_f64.to_radians(),
        }
    }

    /// `value` (m or rad) in the unit a user reads it in: mm or degrees.
    pub fn shown(self, value: Real) -> Real {
        match self {
            Measure::Length => value * 1e3,
            Measure::Angle => value.to_degrees(),
        }
    }

    /// The shown unit as it follows a number: ` mm` (spaced) or `°` (not).
    pub fn shown_unit(self) -> &'static str {
        match self {
            Measure::Length => " mm",
            Measure::Angle => "°",
        }
    }

    /// The decimals a message shows by default: tenths of a millimetre, hundredths of a
    /// degree, finer than either default tolerance.
    pub fn decimals(self) -> usize {
        match self {
            Measure::Length => 1,
            Measure::Angle => 2,
        }
    }

    /// `value` (m or rad) as a user reads it, `decimals` shown: `0.42 mm`, `0.31°`.
    pub fn text(self, value: Real, decimals: usize) -> String {
        // + 0.0 turns -0 into 0, so no `-0.00` is shown.
        format!("{:.decimals$}{}", self.shown(value) + 0.0, self.shown_unit())
    }
}

impl Variable {
    /// What the variable's errors measure: a length for Pw, an angle for the rotations and
    /// the angles.
    pub fn measure(self) -> Measure {
        match self.kind() {
            ValueKind::Position => Measure::Length,
            ValueKind::Rotation | ValueKind::Angle => Measure::Angle,
        }
    }

    /// An error of the variable as a user reads it, `decimals` shown: `pw 0.42 mm`,
    /// `swivel 0.31°`.
    pub fn error_text(self, error: Real, decimals: usize) -> String {
        format!("{self} {}", self.measure().text(error, decimals))
    }

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

    #[test]
    fn errors_measure_a_length_for_pw_and_an_angle_otherwise() {
        let lengths: Vec<Variable> =
            Variable::ALL.into_iter().filter(|v| v.measure() == Measure::Length).collect();
        assert_eq!(lengths, [Variable::Pw]);
        assert_eq!(Measure::Length.default_tolerance(), 1e-3);
        assert!((Measure::Angle.shown(Measure::Angle.default_tolerance()) - 1.0).abs() < 1e-12);
        assert_eq!(Variable::Pw.error_text(0.42e-3, 2), "pw 0.42 mm");
        assert_eq!(Variable::Swivel.error_text(0.31_f64.to_radians(), 2), "swivel 0.31°");
        assert_eq!(Measure::Length.text(-0.0, 1), "0.0 mm");
        assert_eq!(Measure::Angle.text(1.5_f64.to_radians(), Measure::Angle.decimals()), "1.50°");
    }
}
