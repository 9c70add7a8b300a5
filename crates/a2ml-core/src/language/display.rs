//! Typed task values written back in A2ML syntax, with units: positions in m, angles in deg,
//! rotations as `rpy(..) deg`, numbers without trailing zeros. Every surface that shows a
//! value to a person (`a2ml explain`, the Python package) prints it through these `Display`
//! impls, so a value reads the same everywhere. `{:#}` on a [`PathFeature`] puts a comma
//! before its size, as the feature is written inside `.path(..)`.

use std::fmt;

use super::task::{
    Axis, Goal, GoalConstraint, PathConstraint, PathFeature, Primitive, PrimitiveConstraint,
    Target, Variable,
};
use crate::math::{Real, Rotation3, Vector3};

/// Decimals for lengths (m).
pub const LENGTH_DECIMALS: usize = 4;
/// Decimals for angles in degrees.
pub const DEGREE_DECIMALS: usize = 2;

/// `x` to at most `decimals` decimals, trailing zeros dropped and never `-0`.
pub fn short_number(x: Real, decimals: usize) -> String {
    let text = format!("{x:.decimals$}");
    let text = if text.starts_with('-') && text[1..].chars().all(|c| c == '0' || c == '.') {
        text[1..].to_owned()
    } else {
        text
    };
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        text
    }
}

/// `[a, b, c]` through [`short_number`].
pub fn number_list(values: &[Real], decimals: usize) -> String {
    let items: Vec<String> = values.iter().map(|v| short_number(*v, decimals)).collect();
    format!("[{}]", items.join(", "))
}

/// A path feature's size with its unit: m for `line`, deg for `about` and `by` (the
/// keyword names the feature, as [`PathFeature::keyword`] gives it).
pub fn path_size(keyword: &str, size: Real) -> String {
    if keyword == "line" {
        format!("{} m", short_number(size, LENGTH_DECIMALS))
    } else {
        format!("{} deg", short_number(size.to_degrees(), DEGREE_DECIMALS))
    }
}

/// Roll, pitch, yaw (deg) of R = Rz·Ry·Rx, as `rpy(..)` reads them.
pub fn rpy_degrees(r: &Rotation3) -> [Real; 3] {
    let (roll, pitch, yaw) = r.euler_angles();
    // + 0.0: no -0 where the angle is zero.
    [roll, pitch, yaw].map(|a| a.to_degrees() + 0.0)
}

fn vector(v: &Vector3) -> String {
    number_list(&[v.x, v.y, v.z], LENGTH_DECIMALS)
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Target::Position(p) => write!(f, "{} m", vector(p)),
            Target::Rotation(r) => {
                let [roll, pitch, yaw] = rpy_degrees(r).map(|a| short_number(a, DEGREE_DECIMALS));
                write!(f, "rpy({roll}, {pitch}, {yaw}) deg")
            }
            Target::Angle(a) => {
                write!(f, "{} deg", short_number(a.to_degrees(), DEGREE_DECIMALS))
            }
        }
    }
}

/// An axis as written: `x`, `-z`, `r`, `-l`; another direction of {b} as a vector.
impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Axis::Base(v) => {
                let names = [(Vector3::x(), "x"), (Vector3::y(), "y"), (Vector3::z(), "z")];
                for (unit, name) in names {
                    if (v - unit).norm() < 1e-12 {
                        return f.write_str(name);
                    }
                    if (v + unit).norm() < 1e-12 {
                        return write!(f, "-{name}");
                    }
                }
                f.write_str(&vector(v))
            }
            Axis::Body(body, sign) => {
                let name = body.name();
                if *sign < 0.0 { write!(f, "-{name}") } else { f.write_str(name) }
            }
        }
    }
}

impl PathFeature {
    /// The feature's keyword: `line`, `about`, `by`, `arc` or `hold`.
    pub fn keyword(&self) -> &'static str {
        match self {
            PathFeature::Line { .. } => "line",
            PathFeature::About { .. } => "about",
            PathFeature::By { .. } => "by",
            PathFeature::Arc { .. } => "arc",
            PathFeature::Hold => "hold",
        }
    }
}

/// `line [..] 0.1 m`, `about r 30 deg`, `by -5 deg`, `arc through [..]` (`to [..]` once the
/// goal is known), `hold`; `{:#}` writes `about r, 30 deg`.
impl fmt::Display for PathFeature {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let before = if f.alternate() { ", " } else { " " };
        let size = match self {
            PathFeature::Line { direction, length } => {
                write!(f, "line {}", vector(direction))?;
                *length
            }
            PathFeature::About { axis, angle } => {
                write!(f, "about {axis}")?;
                *angle
            }
            PathFeature::By { angle } => {
                return write!(f, "by {}", path_size("by", *angle));
            }
            PathFeature::Arc { through, to } => {
                write!(f, "arc through {}", vector(through))?;
                return match to {
                    Some(to) => write!(f, " to {}", vector(to)),
                    None => Ok(()),
                };
            }
            PathFeature::Hold => return f.write_str("hold"),
        };
        match size {
            Some(s) => write!(f, "{before}{}", path_size(self.keyword(), s)),
            None => Ok(()),
        }
    }
}

fn symbols(variables: &[Variable]) -> String {
    variables.iter().map(|v| v.symbol()).collect::<Vec<_>>().join(" ")
}

/// A primitive: `(Ow θsw).goal(..)`, `Pw.path(line ..)`, `(Pw Ow).hold`.
impl fmt::Display for Primitive {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.variables.as_slice() {
            [one] => f.write_str(one.symbol())?,
            many => write!(f, "({})", symbols(many))?,
        }
        match &self.constraint {
            PrimitiveConstraint::Goal(targets) => {
                let values: Vec<String> = targets.iter().map(Target::to_string).collect();
                write!(f, ".goal({})", values.join(", "))
            }
            PrimitiveConstraint::Path(feature) => write!(f, ".path({feature:#})"),
            PrimitiveConstraint::Hold => f.write_str(".hold"),
        }
    }
}

/// `Pw Ow = ([..] m, rpy(..) deg)`, or `Pw = [..] m` for one variable.
impl fmt::Display for Goal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let vars: Vec<&str> = self.targets.iter().map(|(v, _)| v.symbol()).collect();
        let values: Vec<String> = self.targets.iter().map(|(_, t)| t.to_string()).collect();
        if values.len() == 1 {
            write!(f, "{} = {}", vars.join(" "), values[0])
        } else {
            write!(f, "{} = ({})", vars.join(" "), values.join(", "))
        }
    }
}

/// `G` or `G1 ≻ G2`.
impl fmt::Display for GoalConstraint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.secondary {
            Some(secondary) => write!(f, "{} ≻ {}", self.primary, secondary),
            None => write!(f, "{}", self.primary),
        }
    }
}

/// `Pw line [..], Ow hold : hard`.
impl fmt::Display for PathConstraint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let items: Vec<String> =
            self.items.iter().map(|i| format!("{} {}", symbols(&i.variables), i.feature)).collect();
        write!(f, "{} : {}", items.join(", "), if self.hard { "hard" } else { "soft" })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::language::task::BodyAxis;

    #[test]
    fn short_numbers_drop_trailing_zeros() {
        assert_eq!(short_number(0.4, LENGTH_DECIMALS), "0.4");
        assert_eq!(short_number(-1e-9, LENGTH_DECIMALS), "0");
        assert_eq!(short_number(96.3, DEGREE_DECIMALS), "96.3");
        assert_eq!(short_number(10.0, DEGREE_DECIMALS), "10");
        assert_eq!(short_number(-0.35, DEGREE_DECIMALS), "-0.35");
    }

    #[test]
    fn values_read_as_a2ml() {
        let r = Rotation3::from_euler_angles(0.1, -0.2, 0.3);
        let rpy = rpy_degrees(&r);
        assert!((rpy[0] - 0.1_f64.to_degrees()).abs() < 1e-9);
        assert!((rpy[2] - 0.3_f64.to_degrees()).abs() < 1e-9);
        assert_eq!(Target::Angle(0.5_f64.to_radians()).to_string(), "0.5 deg");
        assert_eq!(
            Target::Position(Vector3::new(0.25, -0.1, 0.0)).to_string(),
            "[0.25, -0.1, 0] m"
        );
        assert_eq!(Axis::Base(-Vector3::z()).to_string(), "-z");
        assert_eq!(Axis::Body(BodyAxis::L, -1.0).to_string(), "-l");
        let p = Primitive {
            variables: vec![Variable::Pw, Variable::Ow],
            constraint: PrimitiveConstraint::Hold,
        };
        assert_eq!(p.to_string(), "(Pw Ow).hold");
        let p = Primitive {
            variables: vec![Variable::Swivel],
            constraint: PrimitiveConstraint::Path(PathFeature::By { angle: -0.2_f64.to_radians() }),
        };
        assert_eq!(p.to_string(), "θsw.path(by -0.2 deg)");
        let about = PathFeature::About { axis: Axis::Body(BodyAxis::R, 1.0), angle: Some(0.5) };
        assert_eq!(format!("{about:#}"), "about r, 28.65 deg");
        assert_eq!(about.to_string(), "about r 28.65 deg");
    }
}
