//! `a2ml.swivel_map`: the time × swivel obstacle map (METHODS.md §1) of a task's segment, or
//! of a wrist path through points on a robot, as numpy arrays plus the planned profile.
//!
//! Labels are int8: 0 free, 1 joint limits, 2 self-collision, 3 + k obstacle k. Angles are
//! cell centres in rad over [−π, π); times in s from the segment's start.

use a2ml_core::decompose::DecomposeOptions;
use a2ml_core::kinematics::arm_pose;
use a2ml_core::language::{Obstacle, Shape};
use a2ml_core::math::{DOF, JointVector, Real, Vector3};
use a2ml_core::solve::map::{
    Cell, MapError, MapOptions, SwivelMap, SwivelProfile, SwivelTargets, WristMotion, build_map,
    plan_profile, segment_map,
};
use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::language::{self, PyTask};
use crate::{PyRobot, read_array, to_vector};

/// The map of segment `segment` (from 1) of `action` of a task (a `Task` or a path), or of
/// the wrist path from `start`'s wrist through `points` in `duration` s on a `Robot` (Ow
/// held, spheres `(name, centre, radius)` in {b}); a dict of arrays, releasing the GIL.
#[pyfunction]
#[pyo3(signature = (
    task_or_robot, action=None, segment=1, *, start=None, points=None, duration=None,
    spheres=None, time_steps=200, angle_steps=360, safety_distance=0.01
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn swivel_map<'py>(
    py: Python<'py>,
    task_or_robot: &Bound<'py, PyAny>,
    action: Option<&str>,
    segment: usize,
    start: Option<&Bound<'py, PyAny>>,
    points: Option<&Bound<'py, PyAny>>,
    duration: Option<Real>,
    spheres: Option<Vec<(String, Vec<Real>, Real)>>,
    time_steps: usize,
    angle_steps: usize,
    safety_distance: Real,
) -> PyResult<Bound<'py, PyDict>> {
    let options = MapOptions { time_steps, angle_steps, safety_distance, ..MapOptions::default() };
    if let Ok(robot) = task_or_robot.cast::<PyRobot>() {
        let robot = &robot.get().robot;
        let start = start.ok_or_else(|| PyValueError::new_err("a robot's map needs `start`"))?;
        let q = JointVector::from_vec(read_array(start, "start", &[DOF])?);
        let points = points.ok_or_else(|| PyValueError::new_err("a robot's map needs `points`"))?;
        let flat: Vec<Real> = points
            .extract::<Vec<Vec<Real>>>()
            .map_err(|_| {
                PyTypeError::new_err("points must be a sequence of [x, y, z] positions (m)")
            })?
            .into_iter()
            .map(|p| {
                if p.len() == 3 {
                    Ok(p)
                } else {
                    Err(PyValueError::new_err("each point must have 3 coordinates"))
                }
            })
            .collect::<PyResult<Vec<_>>>()?
            .concat();
        let duration =
            duration.ok_or_else(|| PyValueError::new_err("a robot's map needs `duration`"))?;
        let obstacles = spheres
            .unwrap_or_default()
            .into_iter()
            .map(|(name, c, radius)| match c.as_slice() {
                [x, y, z] if radius > 0.0 => Ok(Obstacle {
                    name,
                    shape: Shape::Sphere { center: Vector3::new(*x, *y, *z), radius },
                }),
                _ => {
                    Err(PyValueError::new_err("each sphere is (name, [x, y, z], radius > 0) in m"))
                }
            })
            .collect::<PyResult<Vec<_>>>()?;
        let result = py.detach(|| {
            let pose = arm_pose(robot, &q);
            let mut path = vec![pose.wrist - pose.shoulder];
            path.extend(flat.chunks(3).map(|p| Vector3::new(p[0], p[1], p[2])));
            let motion = WristMotion::through(&path, duration, pose.hand)?;
            let map = build_map(robot, &obstacles, &motion, &q, &options)?;
            let profile = plan_profile(
                robot,
                &obstacles,
                &motion,
                &map,
                &q,
                &SwivelTargets::default(),
                &options,
            );
            Ok::<_, MapError>((map, profile))
        });
        let (map, profile) = result.map_err(|e| PyValueError::new_err(e.to_string()))?;
        return to_dict(py, &map, &profile);
    }
    let task = match task_or_robot.cast::<PyTask>() {
        Ok(task) => task.get().task.clone(),
        Err(_) => {
            let path = task_or_robot.extract::<std::path::PathBuf>().map_err(|_| {
                PyTypeError::new_err("task_or_robot must be an a2ml.Task, a path or an a2ml.Robot")
            })?;
            language::load(py, path)?.task
        }
    };
    let action = action.ok_or_else(|| PyValueError::new_err("a task's map needs `action`"))?;
    if segment == 0 {
        return Err(PyValueError::new_err("segment counts from 1"));
    }
    let result = py.detach(|| {
        let robot =
            task.load_robot(&a2ml_core::RobotOptions::default()).map_err(|e| e.to_string())?;
        segment_map(&robot, &task, action, segment - 1, &DecomposeOptions::default(), &options)
            .map_err(|e| e.to_string())
    });
    let found = result.map_err(PyValueError::new_err)?;
    to_dict(py, &found.map, &found.profile)
}

fn label(cell: Cell) -> i8 {
    match cell {
        Cell::Free => 0,
        Cell::Limits => 1,
        Cell::SelfCollision => 2,
        Cell::Obstacle(k) => 3 + k.min(124) as i8,
    }
}

/// `t`, `swivel`, `labels` (N_t, N_θ), `obstacles`, `faults`, then `profile` (a dict of
/// `t`, `swivel`, `q`, `qd`, `clearance`) or None with `error`.
fn to_dict<'py>(
    py: Python<'py>,
    map: &SwivelMap,
    profile: &Result<SwivelProfile, MapError>,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("t", to_vector(py, &map.times))?;
    out.set_item("swivel", to_vector(py, &map.angles))?;
    let n = map.angles.len();
    let labels = Array2::from_shape_fn((map.times.len(), n), |(i, j)| label(map.cell(i, j)));
    out.set_item("labels", labels.into_pyarray(py))?;
    out.set_item("obstacles", map.obstacles.clone())?;
    let faults: Vec<Option<String>> =
        map.faults.iter().map(|f| f.as_ref().map(|f| f.describe())).collect();
    out.set_item("faults", faults)?;
    match profile {
        Ok(p) => {
            let rows = |v: &[JointVector]| {
                Array2::from_shape_fn((v.len(), DOF), |(i, j)| v[i][j]).into_pyarray(py)
            };
            let d = PyDict::new(py);
            d.set_item("t", to_vector(py, p.trajectory.times()))?;
            d.set_item("swivel", to_vector(py, &p.swivel))?;
            d.set_item("q", rows(p.trajectory.positions()))?;
            d.set_item("qd", rows(p.trajectory.velocities()))?;
            d.set_item("clearance", p.clearance)?;
            out.set_item("profile", d)?;
            out.set_item("error", py.None())?;
        }
        Err(e) => {
            out.set_item("profile", py.None())?;
            out.set_item("error", e.to_string())?;
        }
    }
    Ok(out)
}
