//! `a2ml.rrt_connect` and `a2ml.scene_clearance`: the joint-space RRT-Connect and the
//! clearance of one configuration among obstacles given as plain dicts in the URDF root frame
//! (as MoveIt scenes and MotionBenchMaker problems give them), or as `a2ml.Obstacles`, the
//! same dicts converted and checked once for many calls; for benchmarks against other
//! planners (benches/compare/rrt.py). Only conversions here; the planner is the core's, with
//! the arm's half of its collision model built once per `Robot`.

use std::borrow::Cow;

use numpy::PyArray2;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyDictMethods};

use a2ml_core::collision::{CollisionScene, check_shapes, min_distance};
use a2ml_core::kinematics::arm_pose;
use a2ml_core::language::{Obstacle, Shape};
use a2ml_core::math::{JointVector, Matrix3, Real, Rotation3, Vector3};
use a2ml_core::solve::rrt::{RrtOptions, rrt_connect_with};

use crate::convert::{read_array, read_joints, read_vector3};
use crate::errors::PlanError;
use crate::robot::PyRobot;

/// One obstacle dict: `type` ("box", "sphere", "cylinder"), `position` (root frame, m),
/// `orientation_quat_xyzw` (optional), and `half_extents`, `radius`, `length` as the type
/// needs; moved into {b} by `root_to_b`.
fn obstacle(index: usize, item: &Bound<'_, PyAny>, root_to_b: &Vector3) -> PyResult<Obstacle> {
    let dict = item
        .cast::<PyDict>()
        .map_err(|_| PyTypeError::new_err(format!("obstacles[{index}] must be a dict")))?;
    let field = |key: &str| -> PyResult<Bound<'_, PyAny>> {
        dict.get_item(key)?
            .ok_or_else(|| PyValueError::new_err(format!("obstacles[{index}] has no `{key}`")))
    };
    let number = |key: &str| -> PyResult<Real> {
        let value: Real = field(key)?.extract()?;
        if value.is_finite() && value > 0.0 {
            Ok(value)
        } else {
            Err(PyValueError::new_err(format!("obstacles[{index}].{key} must be positive")))
        }
    };
    let name = match dict.get_item("name")? {
        Some(n) => n.extract::<String>()?,
        None => format!("obstacle{index}"),
    };
    let center = read_vector3(&field("position")?, "position")? + root_to_b;
    let rotation = match dict.get_item("orientation_quat_xyzw")? {
        Some(q) => {
            let q = read_array(&q, "orientation_quat_xyzw", &[4])?;
            let norm = q.iter().map(|c| c * c).sum::<Real>().sqrt();
            if norm < 1e-9 {
                return Err(PyValueError::new_err(format!(
                    "obstacles[{index}].orientation_quat_xyzw is zero"
                )));
            }
            let (x, y, z, w) = (q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm);
            Rotation3::from_matrix_unchecked(Matrix3::new(
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - z * w),
                2.0 * (x * z + y * w),
                2.0 * (x * y + z * w),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - x * w),
                2.0 * (x * z - y * w),
                2.0 * (y * z + x * w),
                1.0 - 2.0 * (x * x + y * y),
            ))
        }
        None => Rotation3::identity(),
    };
    let kind: String = field("type")?.extract()?;
    let shape = match kind.as_str() {
        "box" => Shape::Box {
            center,
            size: read_vector3(&field("half_extents")?, "half_extents")? * 2.0,
            rotation,
        },
        "sphere" => Shape::Sphere { center, radius: number("radius")? },
        "cylinder" => Shape::Cylinder {
            center,
            radius: number("radius")?,
            height: number("length")?,
            rotation,
        },
        other => {
            return Err(PyValueError::new_err(format!(
                "obstacles[{index}].type `{other}`: expected box, sphere or cylinder"
            )));
        }
    };
    Ok(Obstacle { name, shape })
}

/// The obstacles in {b}, each shape (and the robot's capsules) checked as planning checks it.
fn scene(robot: &PyRobot, obstacles: &Bound<'_, PyAny>) -> PyResult<CollisionScene> {
    let root_to_b = root_to_b(robot);
    let list: Vec<Obstacle> = obstacles
        .try_iter()?
        .enumerate()
        .map(|(i, item)| obstacle(i, &item?, &root_to_b))
        .collect::<PyResult<_>>()?;
    checked(robot, &list)?;
    Ok(CollisionScene::new(&list))
}

/// [`check_shapes`] of `robot`'s capsules and `obstacles`, as a ValueError.
fn checked(robot: &PyRobot, obstacles: &[Obstacle]) -> PyResult<()> {
    check_shapes(&robot.robot, obstacles).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Obstacle dicts converted into a robot's base frame {b} and checked once, for many planning
/// calls on one scene: `a2ml.Obstacles(robot, obstacles)`. Usable with any robot whose URDF
/// root is where `robot`'s is relative to {b}.
#[pyclass(frozen, module = "a2ml", name = "Obstacles")]
pub(crate) struct PyObstacles {
    scene: CollisionScene,
    /// {b} from the URDF root (a translation) of the robot they were converted for.
    root_to_b: Vector3,
}

#[pymethods]
impl PyObstacles {
    #[new]
    fn py_new(robot: &PyRobot, obstacles: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self { scene: scene(robot, obstacles)?, root_to_b: root_to_b(robot) })
    }

    fn __len__(&self) -> usize {
        self.scene.len()
    }

    fn __repr__(&self) -> String {
        format!("Obstacles({} obstacles)", self.scene.len())
    }
}

fn root_to_b(robot: &PyRobot) -> Vector3 {
    robot.robot.b_from_base_link.translation.vector
}

/// The scene of `obstacles`: an `a2ml.Obstacles` as it is (refused when converted for a robot
/// whose root is elsewhere relative to {b}; the obstacles were checked when converted, this
/// robot's capsules are checked now, as they may be another robot's), else an iterable of
/// dicts converted now.
fn scene_of<'a>(
    robot: &PyRobot,
    obstacles: &'a Bound<'_, PyAny>,
) -> PyResult<Cow<'a, CollisionScene>> {
    if let Ok(prepared) = obstacles.cast::<PyObstacles>() {
        let prepared = prepared.get();
        if prepared.root_to_b != root_to_b(robot) {
            return Err(PyValueError::new_err(
                "these Obstacles were converted for a robot whose URDF root is elsewhere \
                 relative to its base frame; convert them again for this robot",
            ));
        }
        checked(robot, &[])?;
        return Ok(Cow::Borrowed(&prepared.scene));
    }
    Ok(Cow::Owned(scene(robot, obstacles)?))
}

/// Joint-space RRT-Connect from `start` to any of `goals` among `obstacles` (dicts in the
/// URDF root frame, or `a2ml.Obstacles`). Returns a dict: `waypoints` ((N, 7) array), `goal`
/// (index), `samples`, `nodes`, `collision_checks` (no wall time: callers time the call
/// themselves). Raises `PlanError` when no path is found. The robot's arm model is built at
/// its first call, without the GIL.
#[pyfunction]
#[pyo3(signature = (robot, obstacles, start, goals, *, seed = 0, clearance = 0.01,
    max_samples = 20_000, step = 2.0, resolution = 0.005, shortcuts = 200))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn rrt_connect<'py>(
    py: Python<'py>,
    robot: &PyRobot,
    obstacles: &Bound<'py, PyAny>,
    start: &Bound<'py, PyAny>,
    goals: &Bound<'py, PyAny>,
    seed: u64,
    clearance: Real,
    max_samples: usize,
    step: Real,
    resolution: Real,
    shortcuts: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let scene = scene_of(robot, obstacles)?;
    let start = read_joints(start, "start")?;
    let goals: Vec<JointVector> =
        goals.try_iter()?.map(|g| read_joints(&g?, "goal")).collect::<PyResult<_>>()?;
    let options = RrtOptions {
        seed,
        step,
        resolution,
        clearance,
        max_samples,
        shortcuts,
        ..RrtOptions::default()
    };
    let path = py
        .detach(|| {
            rrt_connect_with(robot.arm_model(), &robot.robot, &scene, &start, &goals, &options)
        })
        .map_err(|e| PlanError::new_err(e.to_string()))?;
    let rows: Vec<Vec<Real>> = path.waypoints.iter().map(|q| q.iter().copied().collect()).collect();
    let out = PyDict::new(py);
    out.set_item("waypoints", PyArray2::from_vec2(py, &rows)?)?;
    out.set_item("goal", path.goal)?;
    out.set_item("samples", path.stats.samples)?;
    out.set_item("nodes", path.stats.nodes)?;
    out.set_item("collision_checks", path.stats.collision_checks)?;
    Ok(out)
}

/// The smallest signed distance (m) between the arm at `q` and `obstacles` (dicts in the URDF
/// root frame, or `a2ml.Obstacles`) or between its self-collision pairs; `inf` when there is
/// no pair.
#[pyfunction]
pub(crate) fn scene_clearance(
    robot: &PyRobot,
    obstacles: &Bound<'_, PyAny>,
    q: &Bound<'_, PyAny>,
) -> PyResult<Real> {
    let scene = scene_of(robot, obstacles)?;
    let q = read_joints(q, "q")?;
    let pose = arm_pose(&robot.robot, &q);
    Ok(min_distance(&robot.robot, &pose, &scene).map_or(Real::INFINITY, |(d, _, _)| d))
}

/// Adds [`PyObstacles`], [`rrt_connect`] and [`scene_clearance`] to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyObstacles>()?;
    m.add_function(wrap_pyfunction!(rrt_connect, m)?)?;
    m.add_function(wrap_pyfunction!(scene_clearance, m)?)
}
