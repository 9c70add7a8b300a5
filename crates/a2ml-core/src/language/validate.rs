//! Syntax tree to [`Task`]: units to SI, every variable checked against its
//! space, segments checked for coverage, names resolved. Collects every
//! problem rather than stopping at the first.

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use super::ast::{self, Name, Span};
use super::bounds::{self, Limits, MAX_ANGLE, MAX_LENGTH};
use super::diagnostic::Diagnostic;
use super::task::*;
use crate::math::{DOF, JointVector, Matrix3, PI, Real, Rotation3, UnitQuaternion, Vector3};
use crate::names::did_you_mean;

/// Physical dimension of a quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Dimension {
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

const UNITS: [(&str, Dimension, Real); 10] = [
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

const AXES: [&str; 14] =
    ["x", "y", "z", "-x", "-y", "-z", "r", "l", "f", "p", "-r", "-l", "-f", "-p"];
const SHAPES: [&str; 4] = ["box", "sphere", "capsule", "cylinder"];
const SETTINGS: [&str; 6] = ["rate", "solver", "seed", "transition", "frame", "acceleration"];

/// A group of an explicit segment: names as written, variables, constraint.
type Group = (Vec<Name>, Vec<Variable>, Option<PrimitiveConstraint>);

struct Checker<'a> {
    errors: Vec<Diagnostic>,
    base_dir: Option<&'a Path>,
    /// The text the spans point into (the seed is read from it: every u64, exactly).
    source: &'a str,
    limits: &'a Limits,
    /// Every duration written, in file order, for the sample limit.
    durations: Vec<(Span, Real)>,
    /// Where the rate is written.
    rate_span: Span,
    /// Every obstacle name the scene declares, shapes valid or not, so that
    /// a bad shape is not reported again at each `contact` naming it.
    obstacles: Vec<String>,
}

fn variable_names() -> impl Iterator<Item = &'static str> {
    Variable::ALL.into_iter().flat_map(|v| [v.symbol(), v.ascii()])
}

fn list(vars: &[Variable]) -> String {
    vars.iter().map(|v| v.symbol()).collect::<Vec<_>>().join(", ")
}

impl Checker<'_> {
    fn error(&mut self, span: Span, message: impl Into<String>) {
        self.errors.push(Diagnostic::new(span, message));
    }

    fn error_with_help(&mut self, span: Span, message: impl Into<String>, help: Option<String>) {
        let mut d = Diagnostic::new(span, message);
        d.help = help;
        self.errors.push(d);
    }

    /// The factor of a written unit for `dimension`; errors name the problem.
    fn unit_factor(&mut self, unit: &Option<Name>, dimension: Dimension) -> Option<Real> {
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
    fn unknown_unit(&mut self, unit: &Name, dimension: Option<Dimension>) {
        let names = |d: Option<Dimension>| {
            UNITS.iter().filter(move |(_, u, _)| d.is_none_or(|d| *u == d)).map(|(n, ..)| *n)
        };
        let help = dimension
            .and_then(|d| did_you_mean(&unit.text, names(Some(d))))
            .or_else(|| did_you_mean(&unit.text, names(None)))
            .map(|s| format!("did you mean `{s}`?"));
        self.error_with_help(unit.span, format!("unknown unit `{}`", unit.text), help);
    }

    fn quantity(&mut self, q: &ast::Quantity, dimension: Dimension) -> Option<Real> {
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
    fn duration(&mut self, q: &ast::Quantity, what: &str) -> Option<Real> {
        let v = self.positive(q, Dimension::Time, what)?;
        self.durations.push((q.span, v));
        Some(v)
    }

    fn positive(&mut self, q: &ast::Quantity, dimension: Dimension, what: &str) -> Option<Real> {
        let v = self.quantity(q, dimension)?;
        if v <= 0.0 {
            self.error(q.span, format!("{what} must be positive"));
            return None;
        }
        Some(v)
    }

    fn numbers(
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

    fn vector3(&mut self, v: &ast::Vector, dimension: Dimension, what: &str) -> Option<Vector3> {
        self.numbers(v, dimension, 3, what).map(|n| Vector3::new(n[0], n[1], n[2]))
    }

    fn direction(&mut self, v: &ast::Vector, what: &str) -> Option<Vector3> {
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

    fn variable(&mut self, name: &Name) -> Option<Variable> {
        let v = Variable::from_name(&name.text);
        if v.is_none() {
            let help = did_you_mean(&name.text, variable_names())
                .map(|s| format!("did you mean `{s}`?"))
                .or_else(|| Some("the state variables are Pw, Ow, θsw (sw), Os and θe (e)".into()));
            self.error_with_help(
                name.span,
                format!("unknown state variable `{}`", name.text),
                help,
            );
        }
        v
    }

    /// Variables of one term, distinct and of one space.
    fn variables(&mut self, names: &[Name]) -> Option<(Vec<Variable>, Option<Space>)> {
        let mut vars = Vec::new();
        let mut ok = true;
        for n in names {
            match self.variable(n) {
                Some(v) if vars.contains(&v) => {
                    self.error(n.span, format!("{} is named twice", v.symbol()));
                    ok = false;
                }
                Some(v) => vars.push(v),
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        let space = self.space_of(names, &vars)?;
        Some((vars, space))
    }

    /// The one space of `vars` (None when only Ow); an error if mixed.
    fn space_of(&mut self, names: &[Name], vars: &[Variable]) -> Option<Option<Space>> {
        let mut space: Option<(Space, Variable)> = None;
        for (n, v) in names.iter().zip(vars) {
            if let Some(s) = v.space() {
                match space {
                    Some((t, first)) if t != s => {
                        self.error(
                            n.span,
                            format!(
                                "{} belongs to {} space, but {} belongs to {} space; \
                                 one constraint covers one space",
                                v.symbol(),
                                s.name(),
                                first.symbol(),
                                t.name()
                            ),
                        );
                        return None;
                    }
                    None => space = Some((s, *v)),
                    _ => {}
                }
            }
        }
        Some(space.map(|(s, _)| s))
    }

    /// A segment's space, from its first variable that fixes one; a variable
    /// of the other space is named against the segment's variables.
    fn segment_space(&mut self, names: &[Name], vars: &[Variable]) -> Option<Option<Space>> {
        let mut space: Option<Space> = None;
        for (n, v) in names.iter().zip(vars) {
            match (space, v.space()) {
                (None, s) => space = s,
                (Some(t), Some(s)) if s != t => {
                    self.error(
                        n.span,
                        format!(
                            "{} belongs to {} space, but this segment is in {} space ({})",
                            v.symbol(),
                            s.name(),
                            t.name(),
                            list(&t.variables())
                        ),
                    );
                    return None;
                }
                _ => {}
            }
        }
        Some(space)
    }

    fn rotation(&mut self, value: &ast::Value, keys: [&str; 2], what: &str) -> Option<Rotation3> {
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
    fn axes(
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

    fn target(&mut self, var: Variable, value: &ast::Value) -> Option<Target> {
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
                let keys = if var == Variable::Os { ["r", "l"] } else { ["f", "p"] };
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

    fn targets(
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
    fn units_of(&mut self, value: &ast::Value) {
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

    fn goal_term(&mut self, term: &ast::GoalTerm) -> Option<Goal> {
        let Some((vars, space)) = self.variables(&term.variables) else {
            term.values.iter().for_each(|v| self.units_of(v));
            return None;
        };
        let targets = self.targets(&vars, &term.values, term.span)?;
        Some(Goal { targets: vars.into_iter().zip(targets).collect(), space, span: term.span })
    }

    fn goal(&mut self, goal: &ast::Goal) -> Option<GoalConstraint> {
        let terms: Vec<Option<Goal>> = goal.terms.iter().map(|t| self.goal_term(t)).collect();
        let mut terms = terms.into_iter().collect::<Option<Vec<Goal>>>()?.into_iter();
        let primary = terms.next()?;
        let secondary = terms.next();
        if let Some(second) = &secondary {
            if let (Some(a), Some(b)) = (primary.space, second.space) {
                if a == b {
                    self.error(
                        second.span,
                        format!(
                            "both goals are in {} space; `>` orders goals of different spaces \
                             (write one goal `{}` for goals of one space)",
                            a.name(),
                            "V1 V2 = (v1, v2)"
                        ),
                    );
                    return None;
                }
            }
            if let Some((v, _)) =
                second.targets.iter().find(|(v, _)| primary.targets.iter().any(|(p, _)| p == v))
            {
                self.error(second.span, format!("{} appears in both goals", v.symbol()));
                return None;
            }
        }
        Some(GoalConstraint { primary, secondary })
    }

    fn axis(&mut self, name: &Name) -> Option<Axis> {
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

    /// A feature for `vars`, checking that each variable can keep it.
    fn feature(
        &mut self,
        vars: &[Variable],
        names: &[Name],
        feature: &ast::Feature,
    ) -> Option<PathFeature> {
        let (allowed, what): (&[Variable], &str) = match feature {
            ast::Feature::Line { .. } => (&[Variable::Pw], "`line` moves Pw"),
            ast::Feature::About { .. } => {
                (&[Variable::Pw, Variable::Ow, Variable::Os], "`about` turns Pw, Ow or Os")
            }
            ast::Feature::By { .. } => {
                (&[Variable::Swivel, Variable::Elbow], "`by` changes θsw or θe")
            }
            ast::Feature::Hold => (&Variable::ALL, ""),
        };
        for (v, n) in vars.iter().zip(names) {
            if !allowed.contains(v) {
                self.error(n.span, format!("{what}, not {}", v.symbol()));
                return None;
            }
        }
        Some(match feature {
            ast::Feature::Line { direction, size } => PathFeature::Line {
                direction: self.direction(direction, "the line direction")?,
                length: match size {
                    Some(q) => Some(self.positive(q, Dimension::Length, "the line length")?),
                    None => None,
                },
            },
            ast::Feature::About { axis, size } => PathFeature::About {
                axis: self.axis(axis)?,
                angle: match size {
                    Some(q) => {
                        Some(self.positive(q, Dimension::Angle, "the angle about an axis")?)
                    }
                    None => None,
                },
            },
            ast::Feature::By { size } => {
                let angle = self.quantity(size, Dimension::Angle)?;
                if angle == 0.0 {
                    self.error(size.span, "`by` needs a non-zero angle (use `hold` to keep it)");
                    return None;
                }
                PathFeature::By { angle }
            }
            ast::Feature::Hold => PathFeature::Hold,
        })
    }

    fn path(&mut self, path: &ast::Path) -> Option<PathConstraint> {
        let mut items = Vec::new();
        let mut all_vars: Vec<Variable> = Vec::new();
        let mut all_names: Vec<Name> = Vec::new();
        let mut ok = true;
        for item in &path.items {
            let Some((vars, _)) = self.variables(&item.variables) else {
                ok = false;
                continue;
            };
            for (v, n) in vars.iter().zip(&item.variables) {
                if all_vars.contains(v) {
                    self.error(n.span, format!("{} is constrained twice in this path", v.symbol()));
                    ok = false;
                }
            }
            all_vars.extend(&vars);
            all_names.extend(item.variables.iter().cloned());
            match self.feature(&vars, &item.variables, &item.feature) {
                Some(feature) => items.push(PathItem { variables: vars, feature }),
                None => ok = false,
            }
        }
        let hard = match &path.hardness {
            None => Some(true),
            Some(h) if h.text == "hard" => Some(true),
            Some(h) if h.text == "soft" => Some(false),
            Some(h) => {
                let help =
                    did_you_mean(&h.text, ["hard", "soft"]).map(|s| format!("did you mean `{s}`?"));
                self.error_with_help(
                    h.span,
                    format!("expected `hard` or `soft`, found `{}`", h.text),
                    help,
                );
                None
            }
        };
        let space = if ok { self.space_of(&all_names, &all_vars)? } else { None };
        let hard = hard?;
        ok.then_some(PathConstraint { items, space, hard, span: path.span })
    }

    /// What a path means next to the goal: without one, nothing can size an
    /// open path or be given way to by a soft one; with one, a variable
    /// cannot be both held to a hard path and sent to a goal.
    fn path_against_goal(
        &mut self,
        ast_path: &ast::Path,
        path: &PathConstraint,
        goal: Option<&GoalConstraint>,
        no_goal: bool,
    ) {
        if no_goal {
            for (item, ast_item) in path.items.iter().zip(&ast_path.items) {
                if matches!(
                    item.feature,
                    PathFeature::Line { length: None, .. } | PathFeature::About { angle: None, .. }
                ) {
                    self.error(
                        ast_item.span,
                        "without a goal nothing can compute this path's size: give it (e.g. `0.1 m`, `30 deg`)",
                    );
                }
            }
            if let (false, Some(h)) = (path.hard, &ast_path.hardness) {
                self.error(h.span, "a soft path gives way to a goal, but this action has none");
            }
        }
        // A soft path may give way to a goal on the same variable (types V, VII).
        let Some(goal) = goal.filter(|_| path.hard) else { return };
        let goal_vars: Vec<Variable> = goal
            .primary
            .targets
            .iter()
            .chain(goal.secondary.iter().flat_map(|g| &g.targets))
            .map(|(v, _)| *v)
            .collect();
        for (item, ast_item) in path.items.iter().zip(&ast_path.items) {
            for (v, n) in item.variables.iter().zip(&ast_item.variables) {
                if goal_vars.contains(v) {
                    self.error(
                        n.span,
                        format!(
                            "{} has both a goal and a path constraint in this action",
                            v.symbol()
                        ),
                    );
                }
            }
        }
    }

    /// An action's `solver` statement: the solver of its segments and those
    /// of single segments, `MS1` the first. `segments` is the number of an
    /// explicit action's segments; an action decomposed has its segments
    /// checked by the decomposition.
    fn solver_statement(
        &mut self,
        statement: &ast::SolverStatement,
        action: &str,
        segments: Option<usize>,
    ) -> (Option<SolverChoice>, Vec<SegmentSolver>) {
        let mut whole = None;
        let mut seen_whole = false;
        let mut single: Vec<SegmentSolver> = Vec::new();
        for entry in &statement.entries {
            let solver = self.solver(&entry.solver);
            let Some(segment) = &entry.segment else {
                if seen_whole {
                    self.error(
                        entry.span,
                        "one solver for the whole action; name the segment of the others (`MS2 rrt`)",
                    );
                }
                seen_whole = true;
                whole = whole.or(solver);
                continue;
            };
            let index = segment
                .text
                .strip_prefix("MS")
                .and_then(|k| k.parse::<usize>().ok())
                .filter(|&k| k >= 1 && !segment.text[2..].starts_with('0'));
            let Some(k) = index else {
                self.error(
                    segment.span,
                    format!(
                        "`{}` is not a segment: segments are named MS1, MS2, ... in their action",
                        segment.text
                    ),
                );
                continue;
            };
            if let Some(count) = segments.filter(|&count| k > count) {
                let names: Vec<String> = (1..=count).map(|i| format!("MS{i}")).collect();
                self.error(
                    segment.span,
                    format!(
                        "action `{action}` has {count} segment{} ({}): there is no {}",
                        if count == 1 { "" } else { "s" },
                        names.join(", "),
                        segment.text
                    ),
                );
            } else if single.iter().any(|s| s.segment == k - 1) {
                self.error(segment.span, format!("{} has a solver already", segment.text));
            } else if let Some(solver) = solver {
                single.push(SegmentSolver { segment: k - 1, solver, span: entry.span });
            }
        }
        (whole, single)
    }

    fn solver(&mut self, name: &Name) -> Option<SolverChoice> {
        let found = SolverChoice::NAMES.iter().find(|(n, _)| *n == name.text).map(|(_, s)| *s);
        if found.is_none() {
            let help = did_you_mean(&name.text, SolverChoice::NAMES.iter().map(|(n, _)| *n))
                .map(|s| format!("did you mean `{s}`?"));
            self.error_with_help(
                name.span,
                format!(
                    "unknown solver `{}` (auto, qp, rrt, map, gpm, clik, pmp, hamp)",
                    name.text
                ),
                help,
            );
        }
        found
    }

    /// A segment's primitives. `-Pa` binds to the group just before it
    /// (paper eq. 4: MP− = complete primitive −Pa MP), so the complement
    /// may come first or last; a bare group is allowed right before `-Pa`
    /// and holds its remaining variables.
    fn segment(&mut self, segment: &ast::Segment) -> Option<Segment> {
        // (names, variables, constraint) per group, after removals.
        let mut groups: Vec<Group> = Vec::new();
        let mut ok = true;
        let prims = &segment.primitives;
        for (k, (combine, p)) in prims.iter().enumerate() {
            let Some((vars, _)) = self.variables(&p.variables) else {
                ok = false;
                continue;
            };
            let next_removes = prims.get(k + 1).is_some_and(|(c, _)| *c == ast::Combine::Remove);
            match (combine, &p.constraint) {
                (ast::Combine::Add, None) if !next_removes => {
                    self.error(
                        p.span,
                        "a primitive needs `.goal(..)`, `.path(..)` or `.hold` \
                         (a bare group may only stand before `-Pa`)",
                    );
                    ok = false;
                }
                (ast::Combine::Add, None) => {
                    groups.push((p.variables.clone(), vars, Some(PrimitiveConstraint::Hold)));
                }
                (ast::Combine::Add, Some(c)) => {
                    let constraint = match c {
                        ast::PrimitiveConstraint::Goal(values) => {
                            self.targets(&vars, values, p.span).map(PrimitiveConstraint::Goal)
                        }
                        ast::PrimitiveConstraint::Path(f) => {
                            let feature = self.feature(&vars, &p.variables, f);
                            if let Some(
                                PathFeature::Line { length: None, .. }
                                | PathFeature::About { angle: None, .. },
                            ) = feature
                            {
                                self.error(
                                    p.span,
                                    "a path in an explicit segment needs its size: nothing computes it here",
                                );
                                ok = false;
                            }
                            feature.map(PrimitiveConstraint::Path)
                        }
                        ast::PrimitiveConstraint::Hold => Some(PrimitiveConstraint::Hold),
                    };
                    ok &= constraint.is_some();
                    groups.push((p.variables.clone(), vars, constraint));
                }
                (ast::Combine::Remove, Some(_)) => {
                    self.error(p.span, "`-Pa` removes variables: write them without a constraint");
                    ok = false;
                }
                (ast::Combine::Remove, None) => {
                    let Some((names, group, constraint)) = groups.last_mut() else {
                        self.error(p.span, "`-Pa` needs a group before it to remove from");
                        ok = false;
                        continue;
                    };
                    for (v, n) in vars.iter().zip(&p.variables) {
                        let Some(i) = group.iter().position(|s| s == v) else {
                            self.error(
                                n.span,
                                format!(
                                    "{} is not in the group before `-Pa`, so it cannot be removed",
                                    v.symbol()
                                ),
                            );
                            ok = false;
                            continue;
                        };
                        group.remove(i);
                        names.remove(i);
                        if let Some(PrimitiveConstraint::Goal(t)) = constraint {
                            t.remove(i);
                        }
                    }
                }
            }
        }
        if !ok {
            return None;
        }
        let mut primitives: Vec<Primitive> = Vec::new();
        let mut names: Vec<Name> = Vec::new();
        let mut vars_seen: Vec<Variable> = Vec::new();
        for (group_names, vars, constraint) in groups {
            for (v, n) in vars.iter().zip(&group_names) {
                if vars_seen.contains(v) {
                    self.error(n.span, format!("{} is already driven in this segment", v.symbol()));
                    ok = false;
                }
            }
            vars_seen.extend(&vars);
            names.extend(group_names);
            if let (Some(constraint), false) = (constraint, vars.is_empty()) {
                primitives.push(Primitive { variables: vars, constraint });
            }
        }
        if !ok {
            return None;
        }
        let space = match self.segment_space(&names, &vars_seen)? {
            Some(s) => s,
            None => {
                self.error(
                    segment.span,
                    "a segment covers a whole space: Pw, Ow, θsw (CPSA) or Os, θe, Ow (HAT)",
                );
                return None;
            }
        };
        let missing: Vec<Variable> =
            space.variables().into_iter().filter(|v| !vars_seen.contains(v)).collect();
        if !missing.is_empty() {
            self.error(
                segment.span,
                format!(
                    "this {} segment does not drive {}: a segment covers {} exactly once",
                    space.name(),
                    list(&missing),
                    list(&space.variables())
                ),
            );
            return None;
        }
        let duration = match &segment.duration {
            Some(q) => Some(self.duration(q, "a segment's duration")?),
            None => None,
        };
        Some(Segment { space, duration, primitives })
    }

    fn facts(&mut self, lists: &[ast::Facts], what: &str) -> Vec<String> {
        if let Some(extra) = lists.get(1) {
            self.error(extra.span, format!("`{what}` is given twice"));
        }
        let mut out: Vec<String> = Vec::new();
        for n in lists.iter().flat_map(|f| &f.names) {
            if out.contains(&n.text) {
                self.error(n.span, format!("fact `{}` is listed twice", n.text));
            } else {
                out.push(n.text.clone());
            }
        }
        out
    }

    /// The obstacles of an action's `contact`: declared in the scene, each
    /// named once.
    fn contact(&mut self, lists: &[ast::Facts]) -> Vec<String> {
        if let Some(extra) = lists.get(1) {
            self.error(extra.span, "`contact` is given twice; list every obstacle in one");
        }
        let mut out: Vec<String> = Vec::new();
        for n in lists.iter().flat_map(|f| &f.names) {
            if out.contains(&n.text) {
                self.error(n.span, format!("obstacle `{}` is listed twice", n.text));
                continue;
            }
            if !self.obstacles.contains(&n.text) {
                let declared = self.obstacles.iter().map(String::as_str);
                let help = did_you_mean(&n.text, declared)
                    .map(|s| format!("did you mean `{s}`?"))
                    .unwrap_or_else(|| match self.obstacles.as_slice() {
                        [] => "the file declares no obstacles".to_owned(),
                        names => format!("the scene declares {}", names.join(", ")),
                    });
                self.error_with_help(
                    n.span,
                    format!(
                        "unknown obstacle `{}`: `contact` names obstacles of the scene",
                        n.text
                    ),
                    Some(help),
                );
            }
            out.push(n.text.clone());
        }
        out
    }

    fn action(&mut self, a: &ast::Action) -> Option<Action> {
        let pre = self.facts(&a.pre, "pre");
        let add = self.facts(&a.add, "add");
        let del = self.facts(&a.del, "del");
        let contact = self.contact(&a.contact);
        if let Some(extra) = a.solver.get(1) {
            self.error(extra.span, "`solver` is given twice");
        }
        let segments = match &a.body {
            ast::ActionBody::Explicit { segments } => Some(segments.len()),
            ast::ActionBody::Constraints { .. } => None,
        };
        let (solver, segment_solvers) = match a.solver.first() {
            Some(statement) => self.solver_statement(statement, &a.name.text, segments),
            None => (None, Vec::new()),
        };
        let body = match &a.body {
            ast::ActionBody::Constraints { goals, paths, durations } => {
                for g in goals.iter().skip(1) {
                    self.error(g.span, "an action has one `goal`; order two goals with `>` in it");
                }
                for p in paths.iter().skip(1) {
                    self.error(
                        p.span,
                        "an action has one `path`; list several variables in it with `,`",
                    );
                }
                for d in durations.iter().skip(1) {
                    self.error(d.span, "`duration` is given twice");
                }
                if goals.is_empty() && paths.is_empty() {
                    self.error(
                        a.name.span,
                        format!("action `{}` has neither a goal nor a path", a.name.text),
                    );
                }
                let goal = goals.first().map(|g| self.goal(g));
                let path = paths.first().map(|p| self.path(p));
                if let (Some(ast_path), Some(Some(pc))) = (paths.first(), &path) {
                    self.path_against_goal(
                        ast_path,
                        pc,
                        goal.as_ref().and_then(|g| g.as_ref()),
                        goals.is_empty(),
                    );
                }
                let duration = durations.first().map(|d| self.duration(d, "the duration"));
                ActionBody::Constraints {
                    goal: goal.flatten(),
                    path: path.flatten(),
                    duration: duration.flatten(),
                }
            }
            ast::ActionBody::Explicit { segments } => {
                let segs: Vec<Option<Segment>> = segments.iter().map(|s| self.segment(s)).collect();
                ActionBody::Explicit(segs.into_iter().flatten().collect())
            }
        };
        Some(Action {
            name: a.name.text.clone(),
            description: a.description.as_ref().map(|d| d.text.clone()),
            pre,
            add,
            del,
            contact,
            solver,
            segment_solvers,
            body,
            span: a.name.span,
        })
    }

    fn start(&mut self, start: &ast::Start) -> Option<Start> {
        match start {
            ast::Start::Joints(v) => {
                let q = self.numbers(v, Dimension::Angle, DOF, "the start configuration")?;
                Some(Start::Joints(JointVector::from_column_slice(&q)))
            }
            ast::Start::State { entries, span } => {
                let names: Vec<Name> = entries.iter().map(|(n, _)| n.clone()).collect();
                let (vars, space) = self.variables(&names)?;
                let targets: Vec<Option<Target>> =
                    vars.iter().zip(entries).map(|(v, (_, x))| self.target(*v, x)).collect();
                let targets: Vec<Target> = targets.into_iter().collect::<Option<_>>()?;
                let space = space.unwrap_or(Space::Cpsa);
                let missing: Vec<Variable> =
                    space.variables().into_iter().filter(|v| !vars.contains(v)).collect();
                if !missing.is_empty() {
                    self.error(
                        *span,
                        format!(
                            "a start state in {} space also needs {}",
                            space.name(),
                            list(&missing)
                        ),
                    );
                    return None;
                }
                Some(Start::State(vars.into_iter().zip(targets).collect()))
            }
        }
    }

    fn scene(&mut self, scene: &ast::Scene) -> Vec<Obstacle> {
        let mut seen: HashMap<&str, Span> = HashMap::new();
        let mut out = Vec::new();
        for o in &scene.obstacles {
            if seen.insert(&o.name.text, o.name.span).is_some() {
                self.error(o.name.span, format!("obstacle `{}` is declared twice", o.name.text));
                continue;
            }
            let shape = match &o.shape {
                ast::Shape::Box { at, size, orientation } => (|| {
                    let center = self.vector3(at, Dimension::Length, "the centre");
                    let size = self.vector3(size, Dimension::Length, "the size");
                    let rotation = self.orientation(orientation.as_ref());
                    let (center, size, rotation) = (center?, size?, rotation?);
                    if size.iter().any(|s| *s <= 0.0) {
                        self.error(o.span, "a box's size must be positive in x, y and z");
                        return None;
                    }
                    Some(Shape::Box { center, size, rotation })
                })(),
                ast::Shape::Sphere { at, radius } => (|| {
                    Some(Shape::Sphere {
                        center: self.vector3(at, Dimension::Length, "the centre")?,
                        radius: self.positive(radius, Dimension::Length, "the radius")?,
                    })
                })(),
                ast::Shape::Capsule { from, to, radius } => (|| {
                    Some(Shape::Capsule {
                        a: self.vector3(from, Dimension::Length, "the start")?,
                        b: self.vector3(to, Dimension::Length, "the end")?,
                        radius: self.positive(radius, Dimension::Length, "the radius")?,
                    })
                })(),
                ast::Shape::CapsuleAt { at, radius, height, orientation } => (|| {
                    let center = self.vector3(at, Dimension::Length, "the centre");
                    let radius = self.positive(radius, Dimension::Length, "the radius");
                    let height = self.positive(height, Dimension::Length, "the height");
                    let rotation = self.orientation(orientation.as_ref());
                    let half = rotation? * Vector3::z() * (0.5 * height?);
                    let center = center?;
                    Some(Shape::Capsule { a: center - half, b: center + half, radius: radius? })
                })(),
                ast::Shape::Cylinder { at, radius, height, orientation } => (|| {
                    let center = self.vector3(at, Dimension::Length, "the centre");
                    let radius = self.positive(radius, Dimension::Length, "the radius");
                    let height = self.positive(height, Dimension::Length, "the height");
                    let rotation = self.orientation(orientation.as_ref());
                    Some(Shape::Cylinder {
                        center: center?,
                        radius: radius?,
                        height: height?,
                        rotation: rotation?,
                    })
                })(),
                ast::Shape::Unknown(name) => {
                    let help =
                        did_you_mean(&name.text, SHAPES).map(|s| format!("did you mean `{s}`?"));
                    self.error_with_help(
                        name.span,
                        format!("unknown shape `{}` (box, sphere, capsule, cylinder)", name.text),
                        help,
                    );
                    None
                }
            };
            if let Some(shape) = shape {
                out.push(Obstacle { name: o.name.text.clone(), shape });
            }
        }
        out
    }

    /// A shape's rotation: the identity without an orientation; for an `axis`, the shortest
    /// turn taking z onto it (half a turn about x for -z).
    fn orientation(&mut self, orientation: Option<&ast::Orientation>) -> Option<Rotation3> {
        match orientation {
            None => Some(Rotation3::identity()),
            Some(ast::Orientation::Rotation(value)) => {
                self.rotation(value, ["x", "y"], "the shape's orientation")
            }
            Some(ast::Orientation::Axis(vector)) => {
                let axis = self.direction(vector, "the axis")?;
                Some(
                    Rotation3::rotation_between(&Vector3::z(), &axis)
                        .unwrap_or_else(|| Rotation3::from_axis_angle(&Vector3::x_axis(), PI)),
                )
            }
        }
    }

    fn settings(&mut self, settings: &ast::Settings) -> Settings {
        let mut out = Settings::default();
        let mut seen: BTreeSet<&str> = BTreeSet::new();
        for s in &settings.entries {
            if !seen.insert(&s.name.text) && SETTINGS.contains(&s.name.text.as_str()) {
                self.error(s.name.span, format!("setting `{}` is given twice", s.name.text));
                continue;
            }
            match (s.name.text.as_str(), &s.value) {
                ("rate", ast::SettingValue::Quantity(q)) => {
                    if let Some(v) = self.positive(q, Dimension::Frequency, "the rate") {
                        out.rate = v;
                        self.rate_span = q.span;
                    }
                }
                ("solver", ast::SettingValue::Word(w)) => {
                    if let Some(v) = self.solver(w) {
                        out.solver = v;
                    }
                }
                ("seed", ast::SettingValue::Quantity(q)) => {
                    // Read from the text: a number above 2^53 is not exact as a float.
                    let written = self.source.get(q.span.start..q.span.end).unwrap_or("");
                    let exact_float = q.value >= 0.0 && q.value.fract() == 0.0 && q.value < 9.0e15;
                    match (q.unit.is_some(), written.parse::<u64>()) {
                        (false, Ok(seed)) => out.seed = seed,
                        // `7.0` or `1e3`: whole, and exact as a float.
                        (false, Err(_)) if exact_float => out.seed = q.value as u64,
                        _ => self.error(
                            q.span,
                            format!("the seed is a whole number from 0 to {}", u64::MAX),
                        ),
                    }
                }
                ("transition", ast::SettingValue::Quantity(q)) => {
                    if let Some(v) = self.quantity(q, Dimension::Fraction) {
                        if (0.0..1.0).contains(&v) {
                            out.transition = v;
                        } else {
                            let help = (q.unit.is_none() && q.value < 100.0).then(|| {
                                format!("a bare number is a fraction: write `{} %`", q.value)
                            });
                            self.error_with_help(
                                q.span,
                                "the transition overlap is between 0 and 100 %",
                                help,
                            );
                        }
                    }
                }
                ("acceleration", ast::SettingValue::Quantity(q)) => {
                    if let Some(v) = self.quantity(q, Dimension::Fraction) {
                        if v > 0.0 && v <= 10.0 {
                            out.acceleration = v;
                        } else {
                            self.error(
                                q.span,
                                "the acceleration scale is above 0 and at most 1000 %",
                            );
                        }
                    }
                }
                ("frame", ast::SettingValue::Word(w)) => match w.text.as_str() {
                    "base" => out.frame = PositionFrame::Base,
                    "root" => out.frame = PositionFrame::Root,
                    _ => self
                        .error(w.span, format!("the frame is `base` or `root`, not `{}`", w.text)),
                },
                (
                    name @ ("rate" | "solver" | "seed" | "transition" | "frame" | "acceleration"),
                    value,
                ) => {
                    let span = match value {
                        ast::SettingValue::Quantity(q) => q.span,
                        ast::SettingValue::Word(w) => w.span,
                    };
                    let expected = match name {
                        "rate" => "a rate like 100 Hz",
                        "solver" => "a solver name like qp",
                        "seed" => "a whole number",
                        "transition" | "acceleration" => "a percentage like 20 %",
                        _ => "`base` or `root`",
                    };
                    self.error(span, format!("`{name}` takes {expected}"));
                }
                (other, _) => {
                    let help =
                        did_you_mean(other, SETTINGS).map(|s| format!("did you mean `{s}`?"));
                    self.error_with_help(
                        s.name.span,
                        format!(
                            "unknown setting `{other}` (rate, solver, seed, transition, frame, \
                             acceleration)"
                        ),
                        help,
                    );
                }
            }
        }
        out
    }

    fn robot(&mut self, name: &Name) -> Option<PathBuf> {
        let written = Path::new(&name.text);
        let resolved = match self.base_dir {
            Some(dir) if written.is_relative() => dir.join(written),
            _ => written.to_path_buf(),
        };
        if !resolved.is_file() {
            self.error(name.span, format!("robot file not found: {}", resolved.display()));
            return None;
        }
        Some(resolved)
    }

    /// The actions and their written segments against [`Limits::max_segments`] (each action
    /// is at least one segment): an error at the action that crosses the limit.
    fn segment_limit(&mut self, task: &ast::Task) {
        let mut segments = 0usize;
        for a in &task.actions {
            segments = segments.saturating_add(match &a.body {
                ast::ActionBody::Explicit { segments, .. } => segments.len().max(1),
                _ => 1,
            });
            if segments > self.limits.max_segments {
                self.error(
                    a.name.span,
                    format!(
                        "the task has more than {} segments by this action (raise the limit \
                         with --max-segments)",
                        self.limits.max_segments
                    ),
                );
                return;
            }
        }
    }

    /// STRIPS: every fact an action needs or deletes, and every goal fact,
    /// is in `init` or added by some action.
    fn strips(&mut self, task: &ast::Task, init: &[String]) {
        let mut known: Vec<&str> = init.iter().map(String::as_str).collect();
        for a in &task.actions {
            known.extend(a.add.iter().flat_map(|f| &f.names).map(|n| n.text.as_str()));
        }
        let needed = task
            .actions
            .iter()
            .flat_map(|a| a.pre.iter().chain(&a.del))
            .chain(&task.goal)
            .flat_map(|f| &f.names);
        for n in needed {
            if !known.contains(&n.text.as_str()) {
                let help = did_you_mean(&n.text, known.iter().copied())
                    .map(|s| format!("did you mean `{s}`?"));
                self.error_with_help(
                    n.span,
                    format!(
                        "fact `{}` is never true: it is not in `init` and no action adds it",
                        n.text
                    ),
                    help,
                );
            }
        }
    }
}

/// The workspace bound a value of `dimension` exceeds, as a message.
fn beyond_bound(v: Real, dimension: Dimension) -> Option<String> {
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

/// Validates a parsed file. `base_dir` is the task file's folder, against
/// which the robot path is resolved.
pub(super) fn validate(
    file: &ast::File,
    source: &str,
    base_dir: Option<&Path>,
    limits: &Limits,
) -> Result<Task, Vec<Diagnostic>> {
    let mut c = Checker {
        errors: Vec::new(),
        base_dir,
        source,
        limits,
        durations: Vec::new(),
        rate_span: Span::default(),
        obstacles: Vec::new(),
    };
    let mut robot: Option<PathBuf> = None;
    let mut robot_chain: (Option<Name>, Option<Name>) = (None, None);
    let (mut seen_robot, mut start, mut scene, mut settings) = (false, None, Vec::new(), None);
    let mut tasks: Vec<&ast::Task> = Vec::new();
    let mut seen_start = false;
    let mut seen_scene = false;
    for item in &file.items {
        match item {
            ast::Item::Robot(line) => {
                if seen_robot {
                    c.error(line.path.span, "a file names one `robot`");
                }
                seen_robot = true;
                robot = c.robot(&line.path).or(robot);
                for link in [&line.base, &line.tip].into_iter().flatten() {
                    if link.text.trim().is_empty() {
                        c.error(link.span, "a link name cannot be empty");
                    }
                }
                robot_chain = (line.base.clone(), line.tip.clone());
            }
            ast::Item::Start(s) => {
                if seen_start {
                    let span = match s {
                        ast::Start::Joints(v) => v.span,
                        ast::Start::State { span, .. } => *span,
                    };
                    c.error(span, "a file has one `start`");
                }
                seen_start = true;
                start = c.start(s);
            }
            ast::Item::Scene(s) => {
                if seen_scene {
                    c.error(s.span, "a file has one `scene`");
                }
                seen_scene = true;
                c.obstacles.extend(s.obstacles.iter().map(|o| o.name.text.clone()));
                scene.extend(c.scene(s));
            }
            ast::Item::Settings(s) => {
                if settings.is_some() {
                    c.error(s.span, "a file has one `settings`");
                }
                settings = Some(c.settings(s));
            }
            ast::Item::Task(t) => tasks.push(t),
        }
    }
    if !seen_robot {
        c.error(Span::default(), "the file names no robot: add `robot \"path/to/arm.urdf\"`");
    }
    for extra in tasks.iter().skip(1) {
        c.error(extra.name.span, "a file holds one `task`");
    }
    let Some(task) = tasks.first() else {
        c.error(Span { start: 0, end: 0 }, "the file has no `task`");
        return Err(c.errors);
    };
    let mut action_names: HashMap<&str, Span> = HashMap::new();
    for a in &task.actions {
        if action_names.insert(&a.name.text, a.name.span).is_some() {
            c.error(a.name.span, format!("action `{}` is declared twice", a.name.text));
        }
    }
    let actions: Vec<Action> = task.actions.iter().filter_map(|a| c.action(a)).collect();
    c.segment_limit(task);
    let rate = settings.as_ref().map_or(Settings::default().rate, |s| s.rate);
    if let Some(d) = bounds::check_samples(&c.durations, (c.rate_span, rate), c.limits) {
        c.errors.push(d);
    }
    let init = c.facts(&task.init, "init");
    let goal = c.facts(&task.goal, "goal");
    let planned = !task.init.is_empty() || !task.goal.is_empty();
    if planned {
        if task.init.is_empty() {
            c.error(task.goal[0].span, "a task with a `goal { .. }` also needs `init { .. }`");
        }
        if task.goal.is_empty() {
            c.error(task.init[0].span, "a task with `init { .. }` also needs a `goal { .. }`");
        }
        c.strips(task, &init);
    }
    c.errors.sort_by_key(|d| (d.span.start, d.span.end));
    if !c.errors.is_empty() {
        return Err(c.errors);
    }
    Ok(Task {
        name: task.name.text.clone(),
        robot: robot.unwrap_or_default(),
        robot_base: robot_chain.0.map(|n| n.text),
        robot_tip: robot_chain.1.map(|n| n.text),
        start,
        scene,
        settings: settings.unwrap_or_default(),
        init: planned.then_some(init),
        goal: planned.then_some(goal),
        actions,
    })
}
