//! `a2ml.Robot`: a URDF's arm, its forward kinematics, Jacobians, states and IK.

use std::path::PathBuf;

use a2ml_core::kinematics::{self, CpsaState, HatState};
use a2ml_core::math::{DOF, JointVector, Real};
use a2ml_core::robot::RobotOptions;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple, PyType};

use crate::batch;
use crate::convert::{
    Matrix, Vector, read_angle, read_joints, read_rotation, read_vector3, to_matrix, to_rotation,
    to_solutions, to_vector,
};
use crate::errors::CoreError;

/// A 7-DoF anthropomorphic arm read from a URDF; immutable.
///
/// Pickles as its URDF text (kept by the core model) and the chain options.
#[pyclass(frozen, module = "a2ml", name = "Robot")]
pub(crate) struct PyRobot {
    pub(crate) robot: a2ml_core::Robot,
    /// The batched FK kernel of `robot`, built once for every batched call.
    pub(crate) chain: kinematics::BatchedChain,
    /// The arm's half of the collision model (its shapes, self pairs and their floors, a
    /// millisecond or more to build for a detailed arm), built at the first planning call and
    /// shared by every later one.
    arm: std::sync::OnceLock<a2ml_core::collision::CollisionModel>,
    base: Option<String>,
    tip: Option<String>,
}

impl PyRobot {
    /// A task's robot, loaded with its `base` and `tip` (which it keeps, to pickle), releasing
    /// the GIL.
    pub(crate) fn of_task(py: Python<'_>, task: &a2ml_core::language::Task) -> PyResult<Self> {
        let robot = py.detach(|| task.load_robot(&RobotOptions::default()));
        let (base, tip) = (task.robot_base.clone(), task.robot_tip.clone());
        Ok(Self::new(robot.map_err(CoreError::from)?, base, tip))
    }

    fn new(robot: a2ml_core::Robot, base: Option<String>, tip: Option<String>) -> Self {
        let chain = kinematics::BatchedChain::new(&robot);
        Self { robot, chain, arm: std::sync::OnceLock::new(), base, tip }
    }

    /// The arm's collision model ([`PyRobot::arm`]), built on first use.
    pub(crate) fn arm_model(&self) -> &a2ml_core::collision::CollisionModel {
        self.arm.get_or_init(|| {
            let empty = a2ml_core::collision::CollisionScene::new(&[]);
            a2ml_core::collision::CollisionModel::new(&self.robot, &empty)
        })
    }

    fn options(base: &Option<String>, tip: &Option<String>) -> RobotOptions {
        RobotOptions { base: base.clone(), tip: tip.clone(), ..RobotOptions::default() }
    }

    fn pose(&self, q: &Bound<'_, PyAny>) -> PyResult<kinematics::ArmPose> {
        Ok(kinematics::arm_pose(&self.robot, &read_joints(q, "q")?))
    }

    fn near(q_near: Option<&Bound<'_, PyAny>>) -> PyResult<Option<JointVector>> {
        q_near.map(|q| read_joints(q, "q_near")).transpose()
    }
}

#[pymethods]
impl PyRobot {
    /// Reads a URDF file; `base` and `tip` pick the chain when it is ambiguous.
    #[classmethod]
    #[pyo3(signature = (path, base=None, tip=None))]
    fn from_urdf(
        _cls: &Bound<'_, PyType>,
        path: PathBuf,
        base: Option<String>,
        tip: Option<String>,
    ) -> PyResult<Self> {
        let robot = a2ml_core::Robot::from_urdf_file_with(&path, &Self::options(&base, &tip))
            .map_err(CoreError::from)?;
        Ok(Self::new(robot, base, tip))
    }

    /// Reads a URDF document given as a string.
    #[classmethod]
    #[pyo3(signature = (text, base=None, tip=None))]
    fn from_urdf_string(
        _cls: &Bound<'_, PyType>,
        text: String,
        base: Option<String>,
        tip: Option<String>,
    ) -> PyResult<Self> {
        let robot = a2ml_core::Robot::from_urdf_str(&text, &Self::options(&base, &tip))
            .map_err(CoreError::from)?;
        Ok(Self::new(robot, base, tip))
    }

    /// Pickles as `Robot.from_urdf_string(urdf, base, tip)`.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let this = slf.get();
        let rebuild = slf.get_type().getattr("from_urdf_string")?;
        let args = (this.robot.urdf.as_str(), this.base.as_deref(), this.tip.as_deref())
            .into_pyobject(py)?;
        PyTuple::new(py, [rebuild, args.into_any()])
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let quoted = |s: &str| -> PyResult<String> { Ok(PyString::new(py, s).repr()?.to_string()) };
        Ok(format!(
            "Robot(name={}, base_link={}, tip_link={})",
            quoted(&self.robot.name)?,
            quoted(&self.robot.base_link)?,
            quoted(&self.robot.tip_link)?
        ))
    }

    /// URDF robot name.
    #[getter]
    fn name(&self) -> &str {
        &self.robot.name
    }

    /// Number of joints (always 7).
    #[getter]
    fn dof(&self) -> usize {
        DOF
    }

    /// Joint names, base to tip.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.robot.joint_names().into_iter().map(str::to_owned).collect()
    }

    /// Lower position limits (rad), shape (7,).
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> Vector<'py> {
        to_vector(py, self.robot.lower().as_slice())
    }

    /// Upper position limits (rad), shape (7,).
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> Vector<'py> {
        to_vector(py, self.robot.upper().as_slice())
    }

    /// Velocity limits (rad/s), shape (7,).
    #[getter]
    fn velocity_limits<'py>(&self, py: Python<'py>) -> Vector<'py> {
        to_vector(py, self.robot.velocity_limits().as_slice())
    }

    /// Spherical shoulder and wrist and no elbow offset.
    #[getter]
    fn is_srs(&self) -> bool {
        self.robot.structure.is_srs
    }

    /// Whether IK is closed-form (else damped Newton).
    #[getter]
    fn has_analytic_ik(&self) -> bool {
        self.robot.has_analytic_ik()
    }

    /// lu = |E - S| (m).
    #[getter]
    fn upper_arm_length(&self) -> Real {
        self.robot.upper_arm_length()
    }

    /// lf = |W - E| at the zero configuration (m).
    #[getter]
    fn forearm_length(&self) -> Real {
        self.robot.forearm_length()
    }

    /// Base link of the chain.
    #[getter]
    fn base_link(&self) -> &str {
        &self.robot.base_link
    }

    /// Tip link of the chain.
    #[getter]
    fn tip_link(&self) -> &str {
        &self.robot.tip_link
    }

    /// The hand frame {W} in {b} as a 4x4 homogeneous matrix.
    #[pyo3(signature = (q, out=None))]
    fn fk<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<batch::Array<'py>> {
        self.frame_into(py, q, out)
    }

    /// Shoulder, elbow and wrist centres in {b}.
    fn centers<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
        let pose = self.pose(q)?;
        let dict = PyDict::new(py);
        dict.set_item("shoulder", to_vector(py, pose.shoulder.as_slice()))?;
        dict.set_item("elbow", to_vector(py, pose.elbow.as_slice()))?;
        dict.set_item("wrist", to_vector(py, pose.wrist.as_slice()))?;
        Ok(dict)
    }

    /// J_ge (6x7): linear velocity of W, angular velocity of the hand.
    #[pyo3(signature = (q, out=None))]
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<batch::Array<'py>> {
        self.jacobian_into(py, q, out)
    }

    /// The CPSA state (pw, ow, swivel).
    fn cpsa<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<(Vector<'py>, Matrix<'py>, Real)> {
        let s = kinematics::cpsa_state(&self.robot, &self.pose(q)?).map_err(CoreError::from)?;
        Ok((to_vector(py, s.pw.as_slice()), to_rotation(py, &s.ow), s.swivel))
    }

    /// The HAT state (os, elbow, ow).
    fn hat<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<(Matrix<'py>, Real, Matrix<'py>)> {
        let s = kinematics::hat_state(&self.pose(q)?).map_err(CoreError::from)?;
        Ok((to_rotation(py, &s.shoulder_frame), s.elbow_angle, to_rotation(py, &s.ow)))
    }

    /// J_cs (7x7): q' to [Pw', ω_w, θsw'].
    fn cpsa_jacobian<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Matrix<'py>> {
        let j = kinematics::cpsa_jacobian(&self.robot, &self.pose(q)?).map_err(CoreError::from)?;
        Ok(to_matrix(py, &j, DOF, DOF))
    }

    /// J_tr (7x7): q' to [ω_s, θe', ω_w].
    fn hat_jacobian<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Matrix<'py>> {
        let j = kinematics::hat_jacobian(&self.pose(q)?).map_err(CoreError::from)?;
        Ok(to_matrix(py, &j, DOF, DOF))
    }

    /// Joints reaching a CPSA state: the in-limit solution nearest `q_near`,
    /// or all of them (nearest first) with `all_branches`.
    #[pyo3(signature = (pw, ow, swivel, q_near=None, all_branches=false))]
    fn ik_cpsa<'py>(
        &self,
        py: Python<'py>,
        pw: &Bound<'py, PyAny>,
        ow: &Bound<'py, PyAny>,
        swivel: Real,
        q_near: Option<&Bound<'py, PyAny>>,
        all_branches: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let target = CpsaState {
            pw: read_vector3(pw, "pw")?,
            ow: read_rotation(ow, "ow")?,
            swivel: read_angle(swivel, "swivel")?,
        };
        let near = Self::near(q_near)?;
        let solutions = py
            .detach(|| kinematics::ik_cpsa(&self.robot, &target, near.as_ref()))
            .map_err(CoreError::from)?;
        Ok(to_solutions(py, &solutions, all_branches))
    }

    /// Joints reaching a HAT state; as `ik_cpsa`.
    #[pyo3(signature = (os, elbow, ow, q_near=None, all_branches=false))]
    fn ik_hat<'py>(
        &self,
        py: Python<'py>,
        os: &Bound<'py, PyAny>,
        elbow: Real,
        ow: &Bound<'py, PyAny>,
        q_near: Option<&Bound<'py, PyAny>>,
        all_branches: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let target = HatState {
            shoulder_frame: read_rotation(os, "os")?,
            elbow_angle: read_angle(elbow, "elbow")?,
            ow: read_rotation(ow, "ow")?,
        };
        let near = Self::near(q_near)?;
        let solutions = py
            .detach(|| kinematics::ik_hat(&self.robot, &target, near.as_ref()))
            .map_err(CoreError::from)?;
        Ok(to_solutions(py, &solutions, all_branches))
    }

    /// The swivel angles at which (pw, ow) is reachable within the joint
    /// limits, as sorted disjoint (lower, upper) intervals of [-π, π].
    fn swivel_intervals(
        &self,
        py: Python<'_>,
        pw: &Bound<'_, PyAny>,
        ow: &Bound<'_, PyAny>,
    ) -> PyResult<Vec<(Real, Real)>> {
        let (pw, ow) = (read_vector3(pw, "pw")?, read_rotation(ow, "ow")?);
        let intervals = py
            .detach(|| kinematics::swivel_intervals(&self.robot, &pw, &ow))
            .map_err(CoreError::from)?;
        Ok(intervals.into_iter().map(|i| (i.lower, i.upper)).collect())
    }
}
