//! The CPSA and HAT representation spaces: states, 7x7 Jacobians and the
//! mapping between them (docs/design.md §3, paper eq. 8, 10-11, appendix B).

use super::error::{KinematicsError, Singularity};
use super::fk::{ArmPose, geometric_jacobian, point_jacobian};
use crate::math::{
    Jacobian3x7, Matrix3, Matrix7, Real, Rotation3, Vector3, projector, rotation_about, skew,
};
use crate::robot::Robot;

/// Below this |Pw × z_b| (m) the swivel reference plane is undefined.
const VERTICAL_TOL: Real = 1e-9;
/// Below this |u × r| the arm plane is undefined.
const STRAIGHT_TOL: Real = 1e-9;

/// A state in CPSA space: wrist position, wrist orientation, swivel angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CpsaState {
    /// Pw = W - S in {b} (m).
    pub pw: Vector3,
    /// Ow, the hand frame's rotation in {b}.
    pub ow: Rotation3,
    /// θsw in (-π, π] (rad).
    pub swivel: Real,
}

/// A state in HAT space: shoulder frame, elbow angle, wrist orientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HatState {
    /// Os = [r, l, r × l] in {b}.
    pub shoulder_frame: Rotation3,
    /// θe = α in [0, π]: the angle at E between S and W (rad).
    pub elbow_angle: Real,
    /// Ow, the hand frame's rotation in {b}.
    pub ow: Rotation3,
}

/// n: unit normal of the vertical plane through S and W, and |Pw × (-z_b)|.
fn vertical_plane_normal(
    pw: &Vector3,
    vertical: &Vector3,
) -> Result<(Vector3, Real), KinematicsError> {
    let m = vertical.cross(pw);
    let norm = m.norm();
    if norm < VERTICAL_TOL {
        return Err(KinematicsError::Singular(Singularity::WristAboveShoulder));
    }
    Ok((m / norm, norm))
}

/// θsw from Pw and the arm-plane normal l: `l = Rot(x, -θsw) n`.
pub fn swivel_angle(
    pw: &Vector3,
    l: &Vector3,
    vertical: &Vector3,
) -> Result<Real, KinematicsError> {
    let (n, _) = vertical_plane_normal(pw, vertical)?;
    let x = pw.normalize();
    Ok((-n.cross(l).dot(&x)).atan2(n.dot(l)))
}

/// The directions of the arm triangle at one pose.
struct Triangle {
    r: Vector3,
    u: Vector3,
    l: Vector3,
    upper: Real,
    fore: Real,
    plane: Real,
}

impl Triangle {
    fn new(pose: &ArmPose) -> Result<Self, KinematicsError> {
        Self::from_points(&pose.shoulder, &pose.elbow, &pose.wrist)
    }

    fn from_points(
        shoulder: &Vector3,
        elbow: &Vector3,
        wrist: &Vector3,
    ) -> Result<Self, KinematicsError> {
        let se = elbow - shoulder;
        let ew = wrist - elbow;
        let (upper, fore) = (se.norm(), ew.norm());
        let (r, u) = (se / upper, ew / fore);
        let v = u.cross(&r);
        let plane = v.norm();
        if plane < STRAIGHT_TOL {
            return Err(KinematicsError::Singular(Singularity::StraightArm));
        }
        Ok(Self { r, u, l: v / plane, upper, fore, plane })
    }

    fn elbow_angle(&self) -> Real {
        // atan2 keeps full precision near 0 and π, where acos loses half.
        self.plane.atan2(-self.r.dot(&self.u))
    }

    fn shoulder_frame(&self) -> Rotation3 {
        Rotation3::from_basis_unchecked(&[self.r, self.l, self.r.cross(&self.l)])
    }
}

/// Rates of the triangle's directions, each a 3x7 map of q'.
struct TriangleRates {
    r: Jacobian3x7,
    u: Jacobian3x7,
    l: Jacobian3x7,
}

impl TriangleRates {
    fn new(t: &Triangle, pose: &ArmPose, wrist_jacobian: &Jacobian3x7) -> Self {
        let elbow = point_jacobian(pose, 3, &pose.elbow);
        // S is fixed in {b} (its origin), so r' follows from E' alone.
        let r = projector(&t.r) * elbow / t.upper;
        let u = projector(&t.u) * (wrist_jacobian - elbow) / t.fore;
        let v = skew(&t.u) * r - skew(&t.r) * u;
        let l = projector(&t.l) * v / t.plane;
        Self { r, u, l }
    }
}

/// The CPSA state at a pose.
///
/// # Errors
/// [`Singularity::StraightArm`], [`Singularity::WristAboveShoulder`].
pub fn cpsa_state(robot: &Robot, pose: &ArmPose) -> Result<CpsaState, KinematicsError> {
    cpsa_from_points(robot, &pose.elbow, &pose.wrist, pose.hand)
}

/// The CPSA state of an arm with E and W (in {b}, S at the origin) and hand rotation Ow.
pub(crate) fn cpsa_from_points(
    robot: &Robot,
    elbow: &Vector3,
    wrist: &Vector3,
    ow: Rotation3,
) -> Result<CpsaState, KinematicsError> {
    let t = Triangle::from_points(&Vector3::zeros(), elbow, wrist)?;
    Ok(CpsaState { pw: *wrist, ow, swivel: swivel_angle(wrist, &t.l, &robot.vertical)? })
}

/// The HAT state at a pose.
///
/// # Errors
/// [`Singularity::StraightArm`].
pub fn hat_state(pose: &ArmPose) -> Result<HatState, KinematicsError> {
    let t = Triangle::new(pose)?;
    Ok(HatState { shoulder_frame: t.shoulder_frame(), elbow_angle: t.elbow_angle(), ow: pose.hand })
}

/// J_cs (7x7): q' to [Pw', ω_w, θsw'].
///
/// # Errors
/// As [`cpsa_state`].
pub fn cpsa_jacobian(robot: &Robot, pose: &ArmPose) -> Result<Matrix7, KinematicsError> {
    let t = Triangle::new(pose)?;
    let jge = geometric_jacobian(pose);
    let jw: Jacobian3x7 = jge.fixed_rows::<3>(0).into();
    let rates = TriangleRates::new(&t, pose, &jw);

    let pw = pose.wrist - pose.shoulder;
    let (n, m_norm) = vertical_plane_normal(&pw, &robot.vertical)?;
    let x = pw.normalize();
    let x_rate = projector(&x) * jw / pw.norm();
    let n_rate = projector(&n) * skew(&robot.vertical) * jw / m_norm;
    // θsw = atan2(a, b), a = -(n × l)·x, b = n·l.
    let a = -n.cross(&t.l).dot(&x);
    let b = n.dot(&t.l);
    let a_rate = -(t.l.cross(&x).transpose() * n_rate
        + x.cross(&n).transpose() * rates.l
        + n.cross(&t.l).transpose() * x_rate);
    let b_rate = t.l.transpose() * n_rate + n.transpose() * rates.l;
    let swivel_rate = (a_rate * b - b_rate * a) / (a * a + b * b);

    let mut j = Matrix7::zeros();
    j.fixed_view_mut::<6, 7>(0, 0).copy_from(&jge);
    j.fixed_view_mut::<1, 7>(6, 0).copy_from(&swivel_rate);
    Ok(j)
}

/// J_tr (7x7): q' to [ω_s, θe', ω_w].
///
/// # Errors
/// As [`hat_state`].
pub fn hat_jacobian(pose: &ArmPose) -> Result<Matrix7, KinematicsError> {
    let t = Triangle::new(pose)?;
    let jge = geometric_jacobian(pose);
    let jw: Jacobian3x7 = jge.fixed_rows::<3>(0).into();
    let rates = TriangleRates::new(&t, pose, &jw);
    let k = t.r.cross(&t.l);
    let k_rate = skew(&t.r) * rates.l - skew(&t.l) * rates.r;
    // For an orthonormal frame [e_i], ω = ½ Σ e_i × e_i'.
    let shoulder_rate = 0.5 * (skew(&t.r) * rates.r + skew(&t.l) * rates.l + skew(&k) * k_rate);
    // cos α = -r·u, so α' = (r'·u + r·u') / sin α.
    let alpha = t.elbow_angle();
    let elbow_rate = (t.u.transpose() * rates.r + t.r.transpose() * rates.u) / alpha.sin();

    let mut j = Matrix7::zeros();
    j.fixed_view_mut::<3, 7>(0, 0).copy_from(&shoulder_rate);
    j.fixed_view_mut::<1, 7>(3, 0).copy_from(&elbow_rate);
    j.fixed_view_mut::<3, 7>(4, 0).copy_from(&jge.fixed_rows::<3>(3));
    Ok(j)
}

/// The angle between sides `a` and `b` of a triangle whose third side is
/// `c`: atan2 of Heron's area over the law of cosines, accurate at 0 and π.
fn triangle_angle(a: Real, b: Real, c: Real) -> Real {
    let heron = (a + b + c) * (-a + b + c) * (a - b + c) * (a + b - c);
    (0.5 * heron.max(0.0).sqrt()).atan2(0.5 * (a * a + b * b - c * c))
}

/// CPSA -> HAT for an arm with lengths lu, lf (paper eq. 10-11).
///
/// # Errors
/// [`KinematicsError::Unreachable`] outside |lu - lf| ≤ |Pw| ≤ lu + lf;
/// [`Singularity::WristAboveShoulder`]; non-finite input.
pub fn cpsa_to_hat(robot: &Robot, cpsa: &CpsaState) -> Result<HatState, KinematicsError> {
    let (lu, lf) = (robot.upper_arm_length(), robot.forearm_length());
    if !(cpsa.pw.iter().all(|v| v.is_finite()) && cpsa.swivel.is_finite()) {
        return Err(KinematicsError::NonFinite { what: "CPSA state" });
    }
    let d = cpsa.pw.norm();
    let (min, max) = ((lu - lf).abs(), lu + lf);
    if d < min - 1e-12 || d > max + 1e-12 || d == 0.0 {
        return Err(KinematicsError::Unreachable { distance: d, min, max });
    }
    let x = cpsa.pw / d;
    let (n, _) = vertical_plane_normal(&cpsa.pw, &robot.vertical)?;
    let tr0 = Matrix3::from_columns(&[x, n.cross(&x), n]);
    let tr = tr0 * rotation_about(&Vector3::x(), -cpsa.swivel);
    let beta = triangle_angle(lu, d, lf);
    let r = tr * Vector3::new(beta.cos(), beta.sin(), 0.0);
    let l: Vector3 = tr.column(2).into();
    let alpha = triangle_angle(lu, lf, d);
    Ok(HatState {
        shoulder_frame: Rotation3::from_basis_unchecked(&[r, l, r.cross(&l)]),
        elbow_angle: alpha,
        ow: cpsa.ow,
    })
}

/// E and W (in {b}) of the HAT triangle with lengths lu, lf.
pub(crate) fn hat_points(robot: &Robot, hat: &HatState) -> (Vector3, Vector3) {
    let os = hat.shoulder_frame.matrix();
    let r: Vector3 = os.column(0).into();
    let l: Vector3 = os.column(1).into();
    let elbow = robot.upper_arm_length() * r;
    let u = rotation_about(&l, hat.elbow_angle) * (-r);
    (elbow, elbow + robot.forearm_length() * u)
}

/// HAT -> CPSA: E = lu r, u = Rot(l, α)(-r), W = E + lf u.
///
/// # Errors
/// [`Singularity::WristAboveShoulder`]; non-finite input.
pub fn hat_to_cpsa(robot: &Robot, hat: &HatState) -> Result<CpsaState, KinematicsError> {
    if !(hat.elbow_angle.is_finite() && hat.shoulder_frame.matrix().iter().all(|v| v.is_finite())) {
        return Err(KinematicsError::NonFinite { what: "HAT state" });
    }
    let (_, wrist) = hat_points(robot, hat);
    let l: Vector3 = hat.shoulder_frame.matrix().column(1).into();
    Ok(CpsaState { pw: wrist, ow: hat.ow, swivel: swivel_angle(&wrist, &l, &robot.vertical)? })
}
