//! `a2ml.parse`, `a2ml.load` and `a2ml.Task`: the validated task as plain
//! Python data. Variables are spelled as the `Robot` methods name them
//! (`pw`, `ow`, `swivel`, `os`, `elbow`); positions are (3,) arrays,
//! rotations (3, 3) arrays, angles floats, all SI and in {b}.
//!
//! The data are built here by hand rather than through serde (serde_json
//! then `json.loads`, or pythonize): the derived serde forms are Rust-shaped
//! (externally tagged enums such as `{"Position": [..]}`, nalgebra matrices
//! as flat column-major lists, variant names as keys), so a second
//! translation would be needed anyway and numpy arrays would be lost. One
//! function per core type keeps the Python spelling in one place and needs
//! no new dependency.

use std::path::PathBuf;

use a2ml_core::language::{
    self, Action, ActionBody, Axis, Goal, GoalConstraint, Obstacle, PathConstraint, PathFeature,
    PathItem, PositionFrame, Primitive, PrimitiveConstraint, Segment, Settings, Shape,
    SolverChoice, Space, Start, Target, ValueKind, Variable,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};

use crate::{CoreError, os_error, read_angle, read_rotation, read_vector3, to_rotation, to_vector};

type Dict<'py> = Bound<'py, PyDict>;

/// A validated A2ML task, immutable. Keeps its source text and path, from
/// which it pickles.
#[pyclass(frozen, module = "a2ml", name = "Task")]
pub(crate) struct PyTask {
    pub(crate) task: language::Task,
    pub(crate) source: String,
    path: Option<PathBuf>,
}

#[pymethods]
impl PyTask {
    /// Pickles as `parse(source, path)`.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let rebuild = py.import("a2ml._a2ml")?.getattr("parse")?;
        let args = (self.source.as_str(), self.path_text()).into_pyobject(py)?;
        PyTuple::new(py, [rebuild, args.into_any()])
    }

    /// Tasks are equal when they say the same thing (layout and comments
    /// aside).
    fn __eq__(&self, other: &Self) -> bool {
        self.task == other.task
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let quoted = |s: &str| -> PyResult<String> { Ok(PyString::new(py, s).repr()?.to_string()) };
        Ok(format!(
            "Task(name={}, robot={}, actions={})",
            quoted(&self.task.name)?,
            quoted(&self.task.robot.to_string_lossy())?,
            self.task.actions.len()
        ))
    }

    /// The task's name.
    #[getter]
    fn name(&self) -> &str {
        &self.task.name
    }

    /// The robot URDF path, resolved relative to the task file.
    #[getter]
    fn robot(&self) -> String {
        self.task.robot.to_string_lossy().into_owned()
    }

    /// None, `{"joints": (7,)}` or `{"state": {variable: value}}`.
    #[getter]
    fn start<'py>(&self, py: Python<'py>) -> PyResult<Option<Dict<'py>>> {
        self.task.start.as_ref().map(|s| start(py, s)).transpose()
    }

    /// Obstacles: dicts with `name`, `shape` and the shape's fields.
    #[getter]
    fn scene<'py>(&self, py: Python<'py>) -> PyResult<Vec<Dict<'py>>> {
        self.task.scene.iter().map(|o| obstacle(py, o)).collect()
    }

    /// `rate`, `solver`, `seed`, `transition` and `frame`, defaults filled in.
    #[getter]
    fn settings<'py>(&self, py: Python<'py>) -> PyResult<Dict<'py>> {
        settings(py, &self.task.settings)
    }

    /// STRIPS initial facts, or None when the actions run in written order.
    #[getter]
    fn init(&self) -> Option<Vec<String>> {
        self.task.init.clone()
    }

    /// STRIPS goal facts, or None.
    #[getter]
    fn goal(&self) -> Option<Vec<String>> {
        self.task.goal.clone()
    }

    /// The actions in written order, as dicts.
    #[getter]
    fn actions<'py>(&self, py: Python<'py>) -> PyResult<Vec<Dict<'py>>> {
        self.task.actions.iter().map(|a| action(py, a)).collect()
    }

    /// The text the task was parsed from.
    #[getter]
    fn source(&self) -> &str {
        &self.source
    }

    /// The file the task was read from (or named when parsed), if any.
    #[getter]
    fn path(&self) -> Option<String> {
        self.path_text()
    }

    /// A new task, this one with the goal values of `action` replaced: keyword arguments
    /// named by the variables' spellings (`pw`: (3,) position in m; `ow`, `shoulder_frame`:
    /// (3, 3) rotations; `swivel`, `elbow`: angles in rad), in the task's frame. Only a goal
    /// the action states can change. The new task is the old text with those values, printed
    /// canonically, validated; it pickles and is attached to outputs as any task.
    #[pyo3(signature = (action, **goal))]
    fn with_goal(
        &self,
        py: Python<'_>,
        action: &str,
        goal: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<PyTask> {
        let mut goals = Vec::new();
        for (name, value) in goal.into_iter().flat_map(|d| d.iter()) {
            let name: String = name.extract()?;
            let variable = variable_from_name(&name).ok_or_else(|| {
                PyTypeError::new_err(format!(
                    "with_goal() got an unexpected keyword argument '{name}' \
                     (variables: {})",
                    a2ml_core::spelling::spellings::<Variable>().join(", ")
                ))
            })?;
            let target = match variable.kind() {
                ValueKind::Position => Target::Position(read_vector3(&value, &name)?),
                ValueKind::Rotation => Target::Rotation(read_rotation(&value, &name)?),
                ValueKind::Angle => Target::Angle(read_angle(value.extract()?, &name)?),
            };
            goals.push((variable, target));
        }
        let path = self.path.as_deref();
        let text =
            language::with_goal(&self.source, path, action, &goals).map_err(|e| match e {
                language::EditError::Syntax(d) => CoreError::from(d).into(),
                other => PyValueError::new_err(other.to_string()),
            })?;
        parse(py, text, self.path.clone())
    }

    /// Every field above except `source` and `path`, as one dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Dict<'py>> {
        let d = PyDict::new(py);
        d.set_item("name", self.name())?;
        d.set_item("robot", self.robot())?;
        d.set_item("start", self.start(py)?)?;
        d.set_item("scene", self.scene(py)?)?;
        d.set_item("settings", self.settings(py)?)?;
        d.set_item("init", self.init())?;
        d.set_item("goal", self.goal())?;
        d.set_item("actions", self.actions(py)?)?;
        Ok(d)
    }
}

impl PyTask {
    fn path_text(&self) -> Option<String> {
        self.path.as_ref().map(|p| p.to_string_lossy().into_owned())
    }
}

/// Parses and validates an A2ML task; `path` names the file in messages and
/// anchors a relative robot path (else the working directory does).
#[pyfunction]
#[pyo3(signature = (text, path=None))]
pub(crate) fn parse(py: Python<'_>, text: String, path: Option<PathBuf>) -> PyResult<PyTask> {
    let task = py.detach(|| language::parse(&text, path.as_deref())).map_err(CoreError::from)?;
    Ok(PyTask { task, source: text, path })
}

/// Reads, parses and validates an A2ML task file.
#[pyfunction]
pub(crate) fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyTask> {
    // The file is read here, not by `language::load`, to keep the OS error
    // (errno) that picks FileNotFoundError, PermissionError, ...
    let (source, parsed) = py
        .detach(|| {
            let text = std::fs::read_to_string(&path)?;
            let parsed = language::parse(&text, Some(&path));
            Ok((text, parsed))
        })
        .map_err(|e| os_error(py, &e, &path))?;
    let task = parsed.map_err(CoreError::from)?;
    Ok(PyTask { task, source, path: Some(path) })
}

/// The Python spelling of a variable: its one spelling ([`Variable::as_str`]).
pub(crate) fn variable_name(v: Variable) -> &'static str {
    v.as_str()
}

pub(crate) fn variable_names(vs: &[Variable]) -> Vec<&'static str> {
    vs.iter().copied().map(variable_name).collect()
}

/// The variable spelled `name`.
pub(crate) fn variable_from_name(name: &str) -> Option<Variable> {
    name.parse().ok()
}

pub(crate) fn space_name(s: Space) -> &'static str {
    s.as_str()
}

/// (3,) array (m), (3, 3) array or float (rad).
fn target<'py>(py: Python<'py>, t: &Target) -> PyResult<Bound<'py, PyAny>> {
    Ok(match t {
        Target::Position(p) => to_vector(py, p.as_slice()).into_any(),
        Target::Rotation(r) => to_rotation(py, r).into_any(),
        Target::Angle(a) => a.into_pyobject(py)?.into_any(),
    })
}

/// `{variable: value}` in written order.
fn targets<'py, 'a>(
    py: Python<'py>,
    pairs: impl IntoIterator<Item = (Variable, &'a Target)>,
) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    for (v, t) in pairs {
        d.set_item(variable_name(v), target(py, t)?)?;
    }
    Ok(d)
}

fn goal<'py>(py: Python<'py>, g: &Goal) -> PyResult<Dict<'py>> {
    targets(py, g.targets.iter().map(|(v, t)| (*v, t)))
}

fn goal_constraint<'py>(py: Python<'py>, gc: &GoalConstraint) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    d.set_item("primary", goal(py, &gc.primary)?)?;
    d.set_item("secondary", gc.secondary.as_ref().map(|g| goal(py, g)).transpose()?)?;
    Ok(d)
}

fn start<'py>(py: Python<'py>, s: &Start) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    match s {
        Start::Joints(q) => d.set_item("joints", to_vector(py, q.as_slice()))?,
        Start::State(pairs) => {
            d.set_item("state", targets(py, pairs.iter().map(|(v, t)| (*v, t)))?)?;
        }
    }
    Ok(d)
}

fn obstacle<'py>(py: Python<'py>, o: &Obstacle) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    d.set_item("name", &o.name)?;
    match &o.shape {
        Shape::Box { center, size, rotation } => {
            d.set_item("shape", "box")?;
            d.set_item("center", to_vector(py, center.as_slice()))?;
            d.set_item("size", to_vector(py, size.as_slice()))?;
            d.set_item("rotation", to_rotation(py, rotation))?;
        }
        Shape::Sphere { center, radius } => {
            d.set_item("shape", "sphere")?;
            d.set_item("center", to_vector(py, center.as_slice()))?;
            d.set_item("radius", radius)?;
        }
        Shape::Capsule { a, b, radius } => {
            d.set_item("shape", "capsule")?;
            d.set_item("a", to_vector(py, a.as_slice()))?;
            d.set_item("b", to_vector(py, b.as_slice()))?;
            d.set_item("radius", radius)?;
        }
        Shape::Cylinder { center, radius, height, rotation } => {
            d.set_item("shape", "cylinder")?;
            d.set_item("center", to_vector(py, center.as_slice()))?;
            d.set_item("radius", radius)?;
            d.set_item("height", height)?;
            d.set_item("rotation", to_rotation(py, rotation))?;
        }
    }
    Ok(d)
}

fn settings<'py>(py: Python<'py>, s: &Settings) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    d.set_item("rate", s.rate)?;
    d.set_item("solver", s.solver.as_str())?;
    d.set_item("seed", s.seed)?;
    d.set_item("transition", s.transition)?;
    d.set_item(
        "frame",
        match s.frame {
            PositionFrame::Base => "base",
            PositionFrame::Root => "root",
        },
    )?;
    Ok(d)
}

/// A base axis as its (3,) unit direction; a body axis as `"r"`, `"-f"`, ...
fn axis<'py>(py: Python<'py>, a: &Axis) -> PyResult<Bound<'py, PyAny>> {
    Ok(match a {
        Axis::Base(direction) => to_vector(py, direction.as_slice()).into_any(),
        Axis::Body(body, sign) => {
            let name = body.name();
            let signed = if *sign < 0.0 { format!("-{name}") } else { name.to_owned() };
            PyString::new(py, &signed).into_any()
        }
    })
}

/// `{"kind": "line" | "about" | "by" | "arc" | "hold", ...}`.
fn feature<'py>(py: Python<'py>, f: &PathFeature) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    match f {
        PathFeature::Line { direction, length } => {
            d.set_item("kind", "line")?;
            d.set_item("direction", to_vector(py, direction.as_slice()))?;
            d.set_item("length", length)?;
        }
        PathFeature::About { axis: a, angle } => {
            d.set_item("kind", "about")?;
            d.set_item("axis", axis(py, a)?)?;
            d.set_item("angle", angle)?;
        }
        PathFeature::By { angle } => {
            d.set_item("kind", "by")?;
            d.set_item("angle", angle)?;
        }
        PathFeature::Arc { through, to } => {
            d.set_item("kind", "arc")?;
            d.set_item("through", to_vector(py, through.as_slice()))?;
            d.set_item("to", to.map(|to| to_vector(py, to.as_slice())))?;
        }
        PathFeature::Hold => d.set_item("kind", "hold")?,
    }
    Ok(d)
}

fn path_item<'py>(py: Python<'py>, item: &PathItem) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    d.set_item("variables", variable_names(&item.variables))?;
    d.set_item("feature", feature(py, &item.feature)?)?;
    Ok(d)
}

fn path_constraint<'py>(py: Python<'py>, pc: &PathConstraint) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    let items: Vec<Dict<'py>> =
        pc.items.iter().map(|i| path_item(py, i)).collect::<PyResult<_>>()?;
    d.set_item("items", items)?;
    d.set_item("space", pc.space.map(space_name))?;
    d.set_item("hard", pc.hard)?;
    Ok(d)
}

/// `{"variables": [...], "kind": "goal" | "path" | "hold"}` plus `goal`
/// (`{variable: value}`) or `feature`.
pub(crate) fn primitive<'py>(py: Python<'py>, p: &Primitive) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    d.set_item("variables", variable_names(&p.variables))?;
    match &p.constraint {
        PrimitiveConstraint::Goal(values) => {
            d.set_item("kind", "goal")?;
            d.set_item("goal", targets(py, p.variables.iter().copied().zip(values))?)?;
        }
        PrimitiveConstraint::Path(f) => {
            d.set_item("kind", "path")?;
            d.set_item("feature", feature(py, f)?)?;
        }
        PrimitiveConstraint::Hold => d.set_item("kind", "hold")?,
    }
    Ok(d)
}

fn segment<'py>(py: Python<'py>, s: &Segment) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    d.set_item("space", space_name(s.space))?;
    d.set_item("duration", s.duration)?;
    let primitives: Vec<Dict<'py>> =
        s.primitives.iter().map(|p| primitive(py, p)).collect::<PyResult<_>>()?;
    d.set_item("primitives", primitives)?;
    Ok(d)
}

/// The STRIPS part, `contact`, `solver` and `kind`, then for `"constraints"`
/// the keys `goal`, `path` and `duration`, for `"explicit"` the key `segments`.
fn action<'py>(py: Python<'py>, a: &Action) -> PyResult<Dict<'py>> {
    let d = PyDict::new(py);
    d.set_item("name", &a.name)?;
    d.set_item("description", a.description.as_deref())?;
    d.set_item("pre", &a.pre)?;
    d.set_item("add", &a.add)?;
    d.set_item("del", &a.del)?;
    d.set_item("contact", &a.contact)?;
    d.set_item("solver", a.solver.map(SolverChoice::as_str))?;
    match &a.body {
        ActionBody::Constraints { goal, path, duration } => {
            d.set_item("kind", "constraints")?;
            d.set_item("goal", goal.as_ref().map(|g| goal_constraint(py, g)).transpose()?)?;
            d.set_item("path", path.as_ref().map(|p| path_constraint(py, p)).transpose()?)?;
            d.set_item("duration", duration)?;
        }
        ActionBody::Explicit(segments) => {
            d.set_item("kind", "explicit")?;
            let segments: Vec<Dict<'py>> =
                segments.iter().map(|s| segment(py, s)).collect::<PyResult<_>>()?;
            d.set_item("segments", segments)?;
        }
    }
    Ok(d)
}
