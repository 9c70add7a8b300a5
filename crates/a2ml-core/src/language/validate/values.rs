//! Values: units to SI against their dimension, the workspace bound, numbers,
//! vectors, directions, rotations (rpy, quat, axes), named axes and each state
//! variable's target.

use super::Checker;
use super::variables::list;
use crate::language::ast::{self, Name, Span};
use crate::language::bounds::{MAX_ANGLE, MAX_LENGTH};
use crate::language::task::*;
use crate::math::{Matrix3, PI, Real, Rotation3, UnitQuaternion, Vector3};
use crate::names::did_you_mean;

const AXES: [&str; 14] =
    ["x", "y", "z", "-x", "-y", "-z", "r", "l", "f", "p", "-r", "-l", "-f", "-p"];

/// Physical dimension of a quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Dimension {
    Length,
    Angle,
    Time,
    Fraction,
    Frequency,
}

impl Dimension {
    fn describe(self) -> &'static str {
        match self {
            Dimension::Length => "a length (m, cm, mm)",
            Dimension::Angle => "an angle (deg, rad)",
            Dimension::Time => "a time (s, ms)",
            Dimension::Fraction => "a fraction (%)",
            Dimension::Frequency => "a frequency (Hz)",
        }
    }
}

pub(super) const UNITS: [(&str, Dimension, Real); 10] = [
    ("m", Dimension::Length, 1.0),
    ("cm", Dimension::Length, 0.01),
    ("mm", Dimension::Length, 0.001),
    ("rad", Dimension::Angle, 1.0),
    ("deg", Dimension::Angle, PI / 180.0),
    ("°", Dimension::Angle, PI / 180.0),
    ("s", Dimension::Time, 1.0),
    ("ms", Dimension::Time, 0.001),
    ("%", Dimension::Fraction, 0.01),
    ("Hz", Dimension::Frequency, 1.0),
];

impl Checker<'_> {
    /// The factor of a written unit for `dimension`; errors name the problem.
    pub(super) fn unit_factor(
        &mut self,
        unit: &Option<Name>,
        dimension: Dimension,
    ) -> Option<Real> {
        let Some(unit) = unit else { return Some(1.0) };
        match UNITS.iter().find(|(n, ..)| *n == unit.text) {
            Some((_, d, f)) if *d == dimension => Some(*f),
            Some((_, d, _)) => {
                self.error(
                    unit.span,
                    format!(
                        "`{}` is {}, but {} is expected here",
                        unit.text,
                        d.describe(),
                        dimension.describe()
                    ),
                );
                None
            }
            None => {
                self.unknown_unit(unit, Some(dimension));
                None
            }
        }
    }

    /// Reports an unknown unit, suggesting one of the expected dimension
    /// first when it is known.
    pub(super) fn unknown_unit(&mut self, unit: &Name, dimension: Option<Dimension>) {
        let names = |d: Option<Dimension>| {
            UNITS.iter().filter(move |(_, u, _)| d.is_none_or(|d| *u == d)).map(|(n, ..)| *n)
        };
        let help = dimension
            .and_then(|d| did_you_mean(&unit.text, names(Some(d))))
            .or_else(|| did_you_mean(&unit.text, names(None)))
            .map(|s| format!("did you mean `{s}`?"));
        self.error_with_help(unit.span, format!("unknown unit `{}`", unit.text), help);
    }

    pub(super) fn quantity(&mut self, q: &ast::Quantity, dimension: Dimension) -> Option<Real> {
        let f = self.unit_factor(&q.unit, dimension)?;
        let v = q.value * f;
        if !v.is_finite() {
            self.error(q.span, "the number is too large");
            return None;
        }
        if let Some(message) = beyond_bound(v, dimension) {
            self.error(q.span, message);
            return None;
        }
        Some(v)
    }

    /// A positive duration, noted for the sample limit.
    pub(super) fn duration(&mut self, q: &ast::Quantity, what: &str) -> Option<Real> {
        let v = self.positive(q, Dimension::Time, what)?;
        self.durations.push((q.span, v));
        Some(v)
    }

    pub(super) fn positive(
        &mut self,
        q: &ast::Quantity,
        dimension: Dimension,
        what: &str,
    ) -> Option<Real> {
        let v = self.quantity(q, dimension)?;
        if v <= 0.0 {
            self.error(q.span, format!("{what} must be positive"));
            return None;
        }
        Some(v)
    }

    pub(super) fn numbers(
        &mut self,
        v: &ast::Vector,
        dimension: Dimension,
        len: usize,
        what: &str,
    ) -> Option<Vec<Real>> {
        let f = self.unit_factor(&v.unit, dimension)?;
        if v.values.len() != len {
            self.error(
                v.span,
                format!("{what} needs {len} numbers, but {} are given", v.values.len()),
            );
            return None;
        }
        let out: Vec<Real> = v.values.iter().map(|x| x * f).collect();
        if out.iter().any(|x| !x.is_finite()) {
            self.error(v.span, "a number is too large");
            return None;
        }
        if let Some(message) = out.iter().find_map(|x| beyond_bound(*x, dimension)) {
            self.error(v.span, message);
            return None;
        }
        Some(out)
    }

    pub(super) fn vector3(
        &mut self,
        v: &ast::Vector,
        dimension: Dimension,
        what: &str,
    ) -> Option<Vector3> {
        self.numbers(v, dimension, 3, what).map(|n| Vector3::new(n[0], n[1], n[2]))
    }

    pub(super) fn direction(&mut self, v: &ast::Vector, what: &str) -> Option<Vector3> {
        if let Some(unit) = &v.unit {
            self.error(unit.span, format!("{what} is a direction and takes no unit"));
            return None;
        }
        // A direction is not a length: no workspace bound, and scaled before its norm is
        // taken, which would overflow for components near the largest number.
        let d = self.numbers(v, Dimension::Fraction, 3, what)?;
        let d = Vector3::new(d[0], d[1], d[2]);
        let scale = d.amax();
        let d = if scale > 0.0 { d / scale } else { d };
        match d.try_normalize(1e-12) {
            Some(d) => Some(d),
            None => {
                self.error(v.span, format!("{what} must not be zero"));
                None
            }
        }
    }

    pub(super) fn rotation(
        &mut self,
        value: &ast::Value,
        keys: [&str; 2],
        what: &str,
    ) -> Option<Rotation3> {
        match value {
            ast::Value::Rpy { angles, unit, .. } => {
                let f = self.unit_factor(unit, Dimension::Angle)?;
                let angles = angles.map(|a| a * f);
                if let Some(message) =
                    angles.iter().find_map(|a| beyond_bound(*a, Dimension::Angle))
                {
                    self.error(value.span(), message);
                    return None;
                }
                Some(Rotation3::from_euler_angles(angles[0], angles[1], angles[2]))
            }
            ast::Value::Quat { wxyz, span } => {
                let scale = wxyz.iter().fold(0.0, |m: Real, x| m.max(x.abs()));
                if !scale.is_finite() {
                    self.error(*span, "a quaternion's numbers must be finite");
                    return None;
                }
                // Scaled first: the norm of numbers near the largest one would overflow.
                let w = wxyz.map(|x| if scale > 0.0 { x / scale } else { x });
                let q = nalgebra::Quaternion::new(w[0], w[1], w[2], w[3]);
                if !(scale > 1e-300 && q.norm() > 1e-9) {
                    self.error(*span, "a quaternion must not be zero");
                    return None;
                }
                Some(UnitQuaternion::from_quaternion(q).to_rotation_matrix())
            }
            ast::Value::Axes { pairs, span } => self.axes(pairs, *span, keys, what),
            other => {
                self.error(
                    other.span(),
                    format!(
                        "{what} is a rotation: rpy(..), quat(..) or axes({}: .., {}: ..)",
                        keys[0], keys[1]
                    ),
                );
                None
            }
        }
    }

    /// A rotation from two named directions: columns k0, k1, k0 × k1.
    pub(super) fn axes(
        &mut self,
        pairs: &[(Name, ast::Vector); 2],
        span: Span,
        keys: [&str; 2],
        what: &str,
    ) -> Option<Rotation3> {
        let mut found: [Option<Vector3>; 2] = [None, None];
        for (key, vector) in pairs {
            let Some(i) = keys.iter().position(|k| *k == key.text) else {
                let help = did_you_mean(&key.text, keys).map(|s| format!("did you mean `{s}`?"));
                self.error_with_help(
                    key.span,
                    format!(
                        "{what} is given by axes `{}` and `{}`, not `{}`",
                        keys[0], keys[1], key.text
                    ),
                    help,
                );
                return None;
            };
            if found[i].is_some() {
                self.error(key.span, format!("axis `{}` is given twice", key.text));
                return None;
            }
            found[i] = Some(self.direction(vector, &format!("axis `{}`", key.text))?);
        }
        let (a, b) = (found[0]?, found[1]?);
        let cos = a.dot(&b);
        if cos.abs() > 0.01 {
            self.error(
                span,
                format!(
                    "axes `{}` and `{}` must be orthogonal, but they are {:.1}° apart",
                    keys[0],
                    keys[1],
                    cos.clamp(-1.0, 1.0).acos().to_degrees()
                ),
            );
            return None;
        }
        // Rounded inputs such as 0.707 are squared up, keeping the first axis.
        let b = (b - a * cos).normalize();
        Some(Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[a, b, a.cross(&b)])))
    }

    pub(super) fn target(&mut self, var: Variable, value: &ast::Value) -> Option<Target> {
        match var.kind() {
            ValueKind::Position => match value {
                ast::Value::Vector(v) => {
                    self.vector3(v, Dimension::Length, "Pw").map(Target::Position)
                }
                other => {
                    self.error(other.span(), "Pw is a position: a vector like [0.3, -0.1, 0.05]");
                    None
                }
            },
            ValueKind::Rotation => {
                let keys = var.body_axes().map_or(["f", "p"], |axes| axes.map(BodyAxis::name));
                self.rotation(value, keys, var.symbol()).map(Target::Rotation)
            }
            ValueKind::Angle => match value {
                ast::Value::Quantity(q) => self.quantity(q, Dimension::Angle).map(Target::Angle),
                other => {
                    self.error(other.span(), format!("{} is an angle like 30 deg", var.symbol()));
                    None
                }
            },
        }
    }

    pub(super) fn targets(
        &mut self,
        vars: &[Variable],
        values: &[ast::Value],
        span: Span,
    ) -> Option<Vec<Target>> {
        if vars.len() != values.len() {
            self.error(
                span,
                format!(
                    "{} variable{} ({}) but {} value{}",
                    vars.len(),
                    if vars.len() == 1 { "" } else { "s" },
                    list(vars),
                    values.len(),
                    if values.len() == 1 { "" } else { "s" }
                ),
            );
            return None;
        }
        let out: Vec<Option<Target>> =
            vars.iter().zip(values).map(|(v, x)| self.target(*v, x)).collect();
        out.into_iter().collect()
    }

    /// Checks only that every unit is known (when the variables are not,
    /// so that their values cannot be typed).
    pub(super) fn units_of(&mut self, value: &ast::Value) {
        let units: Vec<&Option<Name>> = match value {
            ast::Value::Quantity(q) => vec![&q.unit],
            ast::Value::Vector(v) => vec![&v.unit],
            ast::Value::Rpy { unit, .. } => vec![unit],
            ast::Value::Quat { .. } => vec![],
            ast::Value::Axes { pairs, .. } => pairs.iter().map(|(_, v)| &v.unit).collect(),
        };
        for unit in units.into_iter().flatten() {
            if !UNITS.iter().any(|(n, ..)| *n == unit.text) {
                self.unknown_unit(unit, None);
            }
        }
    }

    pub(super) fn axis(&mut self, name: &Name) -> Option<Axis> {
        let (sign, bare) = match name.text.strip_prefix('-') {
            Some(rest) => (-1.0, rest),
            None => (1.0, name.text.as_str()),
        };
        let axis = match bare {
            "x" => Axis::Base(Vector3::x() * sign),
            "y" => Axis::Base(Vector3::y() * sign),
            "z" => Axis::Base(Vector3::z() * sign),
            "r" => Axis::Body(BodyAxis::R, sign),
            "l" => Axis::Body(BodyAxis::L, sign),
            "f" => Axis::Body(BodyAxis::F, sign),
            "p" => Axis::Body(BodyAxis::P, sign),
            _ => {
                let help = did_you_mean(&name.text, AXES).map(|s| format!("did you mean `{s}`?"));
                self.error_with_help(
                    name.span,
                    format!("unknown axis `{}`: axes are x, y, z of {{b}} (or -x, -y, -z) and r, l, f, p of the arm", name.text),
                    help,
                );
                return None;
            }
        };
        Some(axis)
    }
}

/// The workspace bound a value of `dimension` exceeds, as a message.
pub(super) fn beyond_bound(v: Real, dimension: Dimension) -> Option<String> {
    match dimension {
        Dimension::Length if v.abs() > MAX_LENGTH => {
            Some(format!("{v:e} m is beyond the workspace bound of {MAX_LENGTH} m"))
        }
        Dimension::Angle if v.abs() > MAX_ANGLE => {
            Some(format!("{v:e} rad is more than the bound of 100 turns"))
        }
        _ => None,
    }
}
