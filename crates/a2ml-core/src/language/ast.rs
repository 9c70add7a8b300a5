//! The typed syntax tree of an A2ML file, as written: names are strings,
//! numbers carry the unit they were written with, and every node has the
//! byte span of its text. Comments stand apart, in [`File::comments`].
//! Validation turns the tree into a [`super::Task`].

use crate::math::Real;

/// A byte range of the source text.
///
/// Spans take no part in equality, so that two parses of differently
/// formatted text compare equal when they say the same thing.
#[derive(Debug, Clone, Copy, Default, Eq, serde::Serialize, serde::Deserialize)]
pub struct Span {
    /// First byte.
    pub start: usize,
    /// One past the last byte.
    pub end: usize,
}

impl PartialEq for Span {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// A name, keyword argument or string with its span.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Name {
    /// The text (strings without their quotes).
    pub text: String,
    /// Where it was written.
    pub span: Span,
}

/// A number with an optional unit: `0.3 m`, `45 deg`, `2`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Quantity {
    /// The number as written.
    pub value: Real,
    /// The unit as written.
    pub unit: Option<Name>,
    /// The whole quantity.
    pub span: Span,
}

/// A bracketed list of numbers with one optional unit: `[0, 30, 0] deg`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Vector {
    /// The numbers as written.
    pub values: Vec<Real>,
    /// The unit as written.
    pub unit: Option<Name>,
    /// The whole vector.
    pub span: Span,
}

/// A value as written.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Value {
    /// A scalar.
    Quantity(Quantity),
    /// A vector.
    Vector(Vector),
    /// `rpy(roll, pitch, yaw) unit`: about fixed x, y, z.
    Rpy {
        /// Roll, pitch, yaw as written.
        angles: [Real; 3],
        /// The unit as written.
        unit: Option<Name>,
        /// The whole value.
        span: Span,
    },
    /// `quat(w, x, y, z)`.
    Quat {
        /// w, x, y, z as written.
        wxyz: [Real; 4],
        /// The whole value.
        span: Span,
    },
    /// `axes(f: [..], p: [..])` or `axes(r: [..], l: [..])`.
    Axes {
        /// The two named directions.
        pairs: [(Name, Vector); 2],
        /// The whole value.
        span: Span,
    },
}

impl Value {
    /// The span of the value.
    pub fn span(&self) -> Span {
        match self {
            Value::Quantity(q) => q.span,
            Value::Vector(v) => v.span,
            Value::Rpy { span, .. } | Value::Quat { span, .. } | Value::Axes { span, .. } => *span,
        }
    }
}

/// A whole A2ML file.
///
/// Two files are equal when their items are and their comments have the
/// same texts in the same order.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct File {
    /// Top-level items in source order.
    pub items: Vec<Item>,
    /// Every comment in source order; [`super::format()`] puts each back
    /// beside the node it was written with.
    pub comments: Vec<Comment>,
    /// Where the blank lines stand, which the formatter keeps.
    #[serde(skip)]
    pub layout: Layout,
}

/// What a text's layout says that the formatter keeps: its blank lines.
///
/// Layout takes no part in equality, as spans do not.
#[derive(Debug, Clone, Default)]
pub struct Layout {
    /// The first byte of each line holding nothing but whitespace, in order.
    pub blank_lines: Vec<usize>,
}

impl PartialEq for Layout {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// A `#` or `//` comment, which runs to the end of its line.
///
/// Comments compare by text alone: where one sits is layout.
#[derive(Debug, Clone, Eq, serde::Serialize)]
pub struct Comment {
    /// The text from `#` or `//` on, without the line break and trailing
    /// whitespace.
    pub text: String,
    /// Whether it stands alone on its line (else code comes before it).
    pub own_line: bool,
    /// One past the last byte of the code before it, 0 if there is none.
    pub code_before: usize,
    /// The first byte of the code after it (past other comments), the
    /// text's length if there is none.
    pub code_after: usize,
    /// The text.
    pub span: Span,
}

impl PartialEq for Comment {
    fn eq(&self, other: &Self) -> bool {
        self.text == other.text
    }
}

/// The `robot` line: the URDF and, optionally, the chain's base and tip links.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RobotLine {
    /// The URDF path as written.
    pub path: Name,
    /// `base "link"`.
    pub base: Option<Name>,
    /// `tip "link"`.
    pub tip: Option<Name>,
}

/// A top-level item.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Item {
    /// `robot "path.urdf" base "link" tip "link"`.
    Robot(RobotLine),
    /// `start ...`.
    Start(Start),
    /// `scene { ... }`.
    Scene(Scene),
    /// `settings { ... }`.
    Settings(Settings),
    /// `task name { ... }`.
    Task(Task),
}

/// The start configuration.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Start {
    /// Joint angles.
    Joints(Vector),
    /// A state in CPSA or HAT space: `Pw [..] Ow rpy(..) θsw 30 deg`.
    State {
        /// Variable-value pairs.
        entries: Vec<(Name, Value)>,
        /// The whole list.
        span: Span,
    },
}

/// The obstacles.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Scene {
    /// Obstacles in source order.
    pub obstacles: Vec<Obstacle>,
    /// The whole block, from `scene` to the closing brace.
    pub span: Span,
    /// The braces and what is between them.
    pub braces: Span,
}

/// `name = shape`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Obstacle {
    /// Obstacle name.
    pub name: Name,
    /// Its shape.
    pub shape: Shape,
    /// The whole declaration.
    pub span: Span,
}

/// An obstacle's shape as written.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Shape {
    /// `box at [..] size [..]`: centre and full edge lengths, optionally rotated.
    Box {
        /// Centre.
        at: Vector,
        /// Edge lengths.
        size: Vector,
        /// `rotation ..` or `axis [..]`; axis-aligned without.
        orientation: Option<Orientation>,
    },
    /// `sphere at [..] radius r`.
    Sphere {
        /// Centre.
        at: Vector,
        /// Radius.
        radius: Quantity,
    },
    /// `capsule from [..] to [..] radius r`.
    Capsule {
        /// Segment start.
        from: Vector,
        /// Segment end.
        to: Vector,
        /// Radius.
        radius: Quantity,
    },
    /// `capsule at [..] radius r height h`: the segment of length h centred at `at` along the
    /// local z, vertical without an orientation.
    CapsuleAt {
        /// Centre.
        at: Vector,
        /// Radius.
        radius: Quantity,
        /// Length of the segment, the caps excluded.
        height: Quantity,
        /// `rotation ..` or `axis [..]`.
        orientation: Option<Orientation>,
    },
    /// `cylinder at [..] radius r height h`: centred at `at` along the local z, vertical
    /// without an orientation.
    Cylinder {
        /// Centre.
        at: Vector,
        /// Radius.
        radius: Quantity,
        /// Height.
        height: Quantity,
        /// `rotation ..` or `axis [..]`.
        orientation: Option<Orientation>,
    },
    /// A shape keyword the grammar does not know.
    Unknown(Name),
}

/// How a shape is turned about its centre.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Orientation {
    /// `rotation rpy(..)`, `quat(..)` or `axes(x: .., z: ..)`: the shape's frame in the scene's.
    Rotation(Value),
    /// `axis [..]`: where the shape's local z points (the shortest turn from z).
    Axis(Vector),
}

/// `settings { name value ... }`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Settings {
    /// Entries in source order.
    pub entries: Vec<Setting>,
    /// The whole block, from `settings` to the closing brace.
    pub span: Span,
    /// The braces and what is between them.
    pub braces: Span,
}

/// One setting.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Setting {
    /// Setting name.
    pub name: Name,
    /// Its value.
    pub value: SettingValue,
    /// The whole entry.
    pub span: Span,
}

/// A setting's value.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum SettingValue {
    /// A number with a unit.
    Quantity(Quantity),
    /// A word.
    Word(Name),
}

/// Names in braces, `{ a, b }`: STRIPS facts, or the obstacles of a
/// `contact` statement.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Facts {
    /// The names.
    pub names: Vec<Name>,
    /// The braces.
    pub span: Span,
}

/// `task name { init goal actions }`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Task {
    /// Task name.
    pub name: Name,
    /// `init { .. }` statements.
    pub init: Vec<Facts>,
    /// `goal { .. }` statements.
    pub goal: Vec<Facts>,
    /// Actions in source order.
    pub actions: Vec<Action>,
    /// The task's name.
    pub span: Span,
    /// The braces and what is between them.
    pub braces: Span,
}

/// One action.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Action {
    /// Action name.
    pub name: Name,
    /// Optional description string.
    pub description: Option<Name>,
    /// `pre`, `add`, `del` statements.
    pub pre: Vec<Facts>,
    /// Facts the action makes true.
    pub add: Vec<Facts>,
    /// Facts the action makes false.
    pub del: Vec<Facts>,
    /// `contact` statements: obstacles the arm may touch.
    pub contact: Vec<Facts>,
    /// `solver` statements.
    pub solver: Vec<SolverStatement>,
    /// Constraints or explicit segments.
    pub body: ActionBody,
    /// `+Se` is written before it (actions run in sequence either way).
    pub sequential: bool,
    /// The action's name.
    pub span: Span,
    /// The braces and what is between them.
    pub braces: Span,
}

/// `solver qp` or `solver MS1 rrt, MS2 qp`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SolverStatement {
    /// The entries in written order.
    pub entries: Vec<SolverEntry>,
    /// The `solver` keyword.
    pub span: Span,
}

/// One entry of a `solver` statement: `rrt`, or `MS1 rrt` for one segment.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SolverEntry {
    /// The segment, `MS1` for the action's first; none for the whole action.
    pub segment: Option<Name>,
    /// The solver's name.
    pub solver: Name,
    /// The whole entry.
    pub span: Span,
}

/// The two forms of an action.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum ActionBody {
    /// Goal and path constraints, decomposed automatically.
    Constraints {
        /// `goal` statements.
        goals: Vec<Goal>,
        /// `path` statements.
        paths: Vec<Path>,
        /// `duration` statements.
        durations: Vec<Quantity>,
    },
    /// Segments of primitives, as in paper eq. 4.
    Explicit {
        /// Segments joined with `+Tr`.
        segments: Vec<Segment>,
    },
}

/// `goal A = a > B = b`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Goal {
    /// One term, or two in priority order (higher first).
    pub terms: Vec<GoalTerm>,
    /// The `goal` keyword.
    pub span: Span,
}

/// `V1 V2 = (v1, v2)`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct GoalTerm {
    /// Variables.
    pub variables: Vec<Name>,
    /// One value per variable.
    pub values: Vec<Value>,
    /// The whole term.
    pub span: Span,
}

/// `path item, item : hard`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Path {
    /// The constrained variables and their features.
    pub items: Vec<PathItem>,
    /// `hard` (default) or `soft`.
    pub hardness: Option<Name>,
    /// The `path` keyword.
    pub span: Span,
}

/// `V feature`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PathItem {
    /// Variables.
    pub variables: Vec<Name>,
    /// What they keep.
    pub feature: Feature,
    /// The whole item.
    pub span: Span,
}

/// A path feature P with its size S.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum Feature {
    /// `line [dir] length`.
    Line {
        /// Direction in {b}.
        direction: Vector,
        /// Distance along it, if given.
        size: Option<Quantity>,
    },
    /// `about axis angle`.
    About {
        /// Axis name: x y z -x -y -z r l f p (and negations).
        axis: Name,
        /// Angle about it, if given.
        size: Option<Quantity>,
    },
    /// `by angle`.
    By {
        /// Signed angle.
        size: Quantity,
    },
    /// `arc through [x, y, z]`.
    Arc {
        /// The point the arc passes through.
        through: Vector,
    },
    /// `hold`.
    Hold,
}

/// `segment T { P +Pa P -Pa P }`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Segment {
    /// Duration, if given.
    pub duration: Option<Quantity>,
    /// Primitives, each with the operator before it (`+Pa` for the first).
    pub primitives: Vec<(Combine, Primitive)>,
    /// The `segment` keyword.
    pub span: Span,
    /// The braces and what is between them.
    pub braces: Span,
}

/// How a primitive joins the ones before it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Combine {
    /// `+Pa`: in parallel.
    Add,
    /// `-Pa`: removed (paper's MP−).
    Remove,
}

/// `V.goal(..)`, `(V W).path(..)`, `V.hold`, or bare `V` after `-Pa`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Primitive {
    /// Variables.
    pub variables: Vec<Name>,
    /// The constraint, if written.
    pub constraint: Option<PrimitiveConstraint>,
    /// The whole primitive.
    pub span: Span,
}

/// A primitive's constraint.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub enum PrimitiveConstraint {
    /// `.goal(values)`.
    Goal(Vec<Value>),
    /// `.path(feature)`.
    Path(Feature),
    /// `.hold`.
    Hold,
}
