//! Inverse kinematics from CPSA and HAT states to joints (docs/design.md §3).
//!
//! Arms whose shoulder axes meet in a point and whose wrist axes meet in a
//! point are solved in closed form, elbow offsets allowed: the triangle
//! S-E-W is rigid but for its angle at E, so |Pw| fixes q4 (Paden-Kahan
//! subproblem 3), the shoulder's three axes realise the triangle's pose
//! (subproblems 2 then 1) and the wrist's three axes realise Ow. Axes that
//! meet only within `MEET_TOL_RELATIVE` of the arm's length are solved as if
//! they met, then polished by Newton on the real chain. Other arms use
//! Levenberg-Marquardt on the square 7x7 task Jacobian, started from the
//! closed-form branches of the arm with its shoulder (and wrist) axes moved
//! through S (and W): the nearest spherical approximation. Every search has
//! an iteration budget, and callers may add a deadline.

use super::error::{KinematicsError, Singularity};
use super::fk::arm_pose;
use super::spaces::{
    CpsaState, HatState, cpsa_jacobian, cpsa_state, cpsa_to_hat, hat_jacobian, hat_points,
    hat_state,
};
use crate::math::{
    DOF, Few, JointVector, Matrix3, Matrix7, PI, Real, Rotation3, Vector3, Vector7, reject,
    rotation_about, rotation_from_sin_cos, rotation_log, solve_trig, wrap_angle,
};
use crate::robot::{ArmStructure, Robot};

/// Settings of the numerical IK (arms without a closed form, and the polish
/// of near-analytic ones).
#[derive(Debug, Clone)]
pub struct IkOptions {
    /// Starting points tried: `q_near` first, then the closed-form guesses,
    /// then a Halton sequence over the limits.
    pub max_starts: usize,
    /// Levenberg-Marquardt iterations per start.
    pub max_iterations: usize,
    /// Levenberg-Marquardt iterations over all starts of one call: the bound
    /// on its cost (each is one FK and one Jacobian).
    pub max_total_iterations: usize,
    /// Wall-clock time after which the search gives up, for callers with a
    /// time limit; `None` (the default) keeps IK deterministic.
    pub deadline: Option<std::time::Instant>,
    /// Convergence threshold on the task-space residual norm.
    pub tolerance: Real,
    /// Slack allowed on joint limits (rad).
    pub limit_tolerance: Real,
}

impl Default for IkOptions {
    fn default() -> Self {
        Self {
            max_starts: 64,
            max_iterations: 200,
            max_total_iterations: 3000,
            deadline: None,
            tolerance: 1e-12,
            limit_tolerance: 1e-9,
        }
    }
}

/// Residual norm below which a search has converged: the requested
/// tolerance, or what rounding allows on a metre-sized arm.
fn converged(options: &IkOptions) -> Real {
    options.tolerance.max(1e-10)
}

/// Joint solutions reaching a CPSA state: every branch within the limits,
/// nearest to `q_near` (default: the middle of the ranges) first. Newton
/// arms return the one solution found from `q_near`.
///
/// # Errors
/// [`KinematicsError::Unreachable`], [`KinematicsError::Singular`],
/// [`KinematicsError::JointOutOfLimits`] (no branch within limits),
/// [`KinematicsError::NoConvergence`] (Newton arms).
pub fn ik_cpsa(
    robot: &Robot,
    target: &CpsaState,
    q_near: Option<&JointVector>,
) -> Result<Vec<JointVector>, KinematicsError> {
    ik_cpsa_with(robot, target, q_near, &IkOptions::default())
}

/// [`ik_cpsa`] with explicit options.
///
/// # Errors
/// As [`ik_cpsa`].
pub fn ik_cpsa_with(
    robot: &Robot,
    target: &CpsaState,
    q_near: Option<&JointVector>,
    options: &IkOptions,
) -> Result<Vec<JointVector>, KinematicsError> {
    if !(target.pw.iter().all(|v| v.is_finite()) && target.swivel.is_finite()) {
        return Err(KinematicsError::NonFinite { what: "CPSA state" });
    }
    let near = q_near.copied().unwrap_or_else(|| robot.middle());
    let residual = |q: &JointVector| {
        let pose = arm_pose(robot, q);
        let state = cpsa_state(robot, &pose)?;
        let mut e = Vector7::zeros();
        e.fixed_rows_mut::<3>(0).copy_from(&(target.pw - state.pw));
        e.fixed_rows_mut::<3>(3).copy_from(&rotation_log(&(target.ow * state.ow.inverse())));
        e[6] = wrap_angle(target.swivel - state.swivel);
        Ok((e, cpsa_jacobian(robot, &pose)?))
    };
    if robot.has_analytic_ik() {
        let hat = cpsa_to_hat(robot, target)?;
        let (elbow, wrist) = hat_points(robot, &hat);
        let branches = analytic_branches(robot, &elbow, &wrist, &target.ow, &near)?;
        return polished(robot, branches, &near, options, residual);
    }
    // The real reach of an arm with offsets is not the annulus of lu and lf:
    // only the guesses use it, with the wrist target pulled into it.
    let guesses = || {
        let (lu, lf) = (robot.upper_arm_length(), robot.forearm_length());
        let d = target.pw.norm();
        let inside = d.clamp((lu - lf).abs() * (1.0 + 1e-9), (lu + lf) * (1.0 - 1e-9));
        let pulled = CpsaState { pw: target.pw * (inside / d.max(Real::MIN_POSITIVE)), ..*target };
        cpsa_to_hat(robot, &pulled).map_or_else(
            |_| Vec::new(),
            |hat| {
                let (elbow, wrist) = hat_points(robot, &hat);
                decoupled_guesses(robot, &elbow, &wrist, &target.ow, &near)
            },
        )
    };
    newton(robot, &near, q_near.is_some(), guesses, options, residual)
}

/// Joint solutions reaching a HAT state; as [`ik_cpsa`].
///
/// # Errors
/// As [`ik_cpsa`].
pub fn ik_hat(
    robot: &Robot,
    target: &HatState,
    q_near: Option<&JointVector>,
) -> Result<Vec<JointVector>, KinematicsError> {
    ik_hat_with(robot, target, q_near, &IkOptions::default())
}

/// [`ik_hat`] with explicit options.
///
/// # Errors
/// As [`ik_cpsa`].
pub fn ik_hat_with(
    robot: &Robot,
    target: &HatState,
    q_near: Option<&JointVector>,
    options: &IkOptions,
) -> Result<Vec<JointVector>, KinematicsError> {
    if !(target.elbow_angle.is_finite()
        && target.shoulder_frame.matrix().iter().all(|v| v.is_finite()))
    {
        return Err(KinematicsError::NonFinite { what: "HAT state" });
    }
    let near = q_near.copied().unwrap_or_else(|| robot.middle());
    let residual = |q: &JointVector| {
        let pose = arm_pose(robot, q);
        let state = hat_state(&pose)?;
        let mut e = Vector7::zeros();
        e.fixed_rows_mut::<3>(0)
            .copy_from(&rotation_log(&(target.shoulder_frame * state.shoulder_frame.inverse())));
        e[3] = target.elbow_angle - state.elbow_angle;
        e.fixed_rows_mut::<3>(4).copy_from(&rotation_log(&(target.ow * state.ow.inverse())));
        Ok((e, hat_jacobian(&pose)?))
    };
    let (elbow, wrist) = hat_points(robot, target);
    if robot.has_analytic_ik() {
        let branches = analytic_branches(robot, &elbow, &wrist, &target.ow, &near)?;
        return polished(robot, branches, &near, options, residual);
    }
    let guesses = || decoupled_guesses(robot, &elbow, &wrist, &target.ow, &near);
    newton(robot, &near, q_near.is_some(), guesses, options, residual)
}

/// The analytic branches within limits, nearest first; on an arm whose axes
/// meet only within tolerance, each polished by Newton on the real chain and
/// kept if it converges there.
fn polished<F>(
    robot: &Robot,
    branches: Vec<JointVector>,
    near: &JointVector,
    options: &IkOptions,
    residual: F,
) -> Result<Vec<JointVector>, KinematicsError>
where
    F: Fn(&JointVector) -> Result<(Vector7, Matrix7), KinematicsError>,
{
    let inside = select(robot, branches, near, options.limit_tolerance)?;
    if robot.structure.idealisation <= 1e-9 {
        return Ok(inside);
    }
    let mut budget = Budget::new(options);
    let mut best = Real::INFINITY;
    let mut out: Vec<JointVector> = Vec::with_capacity(inside.len());
    for start in inside {
        let (q, e) = descend(robot, start, &residual, options, &mut budget);
        best = best.min(e);
        if e < converged(options) && !out.iter().any(|p| (p - q).amax() < 1e-9) {
            out.push(q);
        }
    }
    if out.is_empty() {
        return Err(KinematicsError::NoConvergence { residual: best, starts: budget.starts });
    }
    out.sort_by(|a, b| (a - near).norm().total_cmp(&(b - near).norm()));
    Ok(out)
}

/// An angle with its sine and cosine, so that rotating by it needs no
/// further trigonometry.
#[derive(Clone, Copy)]
struct Turn {
    angle: Real,
    sin: Real,
    cos: Real,
}

impl Turn {
    /// No turn: what `Turn::of(0.0)` gives, without calling the trigonometry.
    const ZERO: Self = Self { angle: 0.0, sin: 0.0, cos: 1.0 };

    fn of(angle: Real) -> Self {
        let (sin, cos) = angle.sin_cos();
        Self { angle, sin, cos }
    }

    /// `Rot(axis, ±angle) v` by Rodrigues' formula.
    fn apply(&self, axis: &Vector3, v: &Vector3, inverse: bool) -> Vector3 {
        let sin = if inverse { -self.sin } else { self.sin };
        v * self.cos + axis.cross(v) * sin + axis * (axis.dot(v) * (1.0 - self.cos))
    }
}

/// Subproblem 1: the turn about unit `w` (through the origin) taking `u`
/// towards `v`; `None` when either lies on the axis.
fn rotation_turn(w: &Vector3, u: &Vector3, v: &Vector3) -> Option<Turn> {
    let (up, vp) = (reject(u, w), reject(v, w));
    let (s, c) = (w.dot(&up.cross(&vp)), up.dot(&vp));
    // Products of vectors of at most unit length: no overflow, and sqrt is several times
    // faster than hypot, which IK calls thousands of times per optimisation.
    let h = (s * s + c * c).sqrt();
    if up.norm_squared() < 1e-24 || vp.norm_squared() < 1e-24 || h == 0.0 {
        return None;
    }
    Some(Turn { angle: s.atan2(c), sin: s / h, cos: c / h })
}

/// At most two solutions of a three-axis decomposition.
#[derive(Clone, Copy)]
pub(crate) struct Solutions {
    items: [[Real; 3]; 2],
    len: usize,
}

impl Solutions {
    const NONE: Self = Self { items: [[0.0; 3]; 2], len: 0 };

    pub(crate) fn as_slice(&self) -> &[[Real; 3]] {
        &self.items[..self.len]
    }

    fn push(&mut self, s: [Real; 3]) {
        self.items[self.len] = s;
        self.len += 1;
    }
}

/// Every (a, b, c) with `R = Rot(wa, a) Rot(wb, b) Rot(wc, c)`; where the
/// first and last axes align (gimbal), `a` is taken from `near_a`.
pub(crate) fn decompose(
    r: &Matrix3,
    wa: &Vector3,
    wb: &Vector3,
    wc: &Vector3,
    near_a: Real,
) -> Result<Solutions, KinematicsError> {
    let split = Split::new(r, wa, wb, wc, near_a)?;
    let mut out = Solutions::NONE;
    for i in 0..split.len {
        out.push(split.solution(i));
    }
    Ok(out)
}

/// A three-axis decomposition in two stages: each solution's middle angle first (which
/// bounds its distance from a configuration), its outer angles when asked. The same
/// arithmetic as [`decompose`], which runs both stages.
pub(crate) struct Split<'a> {
    wa: &'a Vector3,
    wb: &'a Vector3,
    wc: &'a Vector3,
    /// R wc.
    w: Vector3,
    /// A direction orthogonal to wc, and R times it.
    probe: Vector3,
    r_probe: Vector3,
    near_a: Real,
    /// Per solution, Rot(wb, b) wc and the middle turn b.
    middles: [(Vector3, Turn); 2],
    pub(crate) len: usize,
}

impl<'a> Split<'a> {
    pub(crate) fn new(
        r: &Matrix3,
        wa: &'a Vector3,
        wb: &'a Vector3,
        wc: &'a Vector3,
        near_a: Real,
    ) -> Result<Self, KinematicsError> {
        // Subproblem 2 on wc: Rot(wb, b) wc = Rot(wa, -a) (R wc) = c.
        let (v, w) = (*wc, r * wc);
        let k = wa.dot(wb);
        let cross = wa.cross(wb);
        if cross.norm() < 1e-9 {
            return Err(KinematicsError::Singular(Singularity::ParallelAxes));
        }
        // Any direction orthogonal to wc shows the last angle.
        let probe = wc.cross(&if wc.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() });
        let zero = (Vector3::zeros(), Turn::ZERO);
        let mut split =
            Self { wa, wb, wc, w, probe, r_probe: r * probe, near_a, middles: [zero; 2], len: 0 };
        let alpha = (wa.dot(&w) - k * wb.dot(&v)) / (1.0 - k * k);
        let beta = (wb.dot(&v) - k * wa.dot(&w)) / (1.0 - k * k);
        let gamma_sq = (v.norm_squared() - alpha * alpha - beta * beta - 2.0 * alpha * beta * k)
            / cross.norm_squared();
        if gamma_sq < -1e-9 {
            // The rotation is outside what these three axes can produce.
            return Ok(split);
        }
        let gamma = gamma_sq.max(0.0).sqrt();
        let gammas: &[Real] = if gamma < 1e-12 { &[0.0] } else { &[gamma, -gamma] };
        for &g in gammas {
            let c = alpha * wa + beta * wb + g * cross;
            let b = rotation_turn(wb, &v, &c).unwrap_or(Turn::ZERO);
            split.middles[split.len] = (c, b);
            split.len += 1;
        }
        Ok(split)
    }

    /// The middle angle of solution `i`.
    pub(crate) fn middle(&self, i: usize) -> Real {
        self.middles[i].1.angle
    }

    /// Solution `i`: (a, b, c).
    pub(crate) fn solution(&self, i: usize) -> [Real; 3] {
        let (c, b) = &self.middles[i];
        let a = rotation_turn(self.wa, c, &self.w).unwrap_or_else(|| Turn::of(self.near_a));
        // Rot(wc, c) probe = Rot(wb, -b) Rot(wa, -a) R probe.
        let turned = b.apply(self.wb, &a.apply(self.wa, &self.r_probe, true), true);
        let c_angle = rotation_turn(self.wc, &self.probe, &turned).map_or(0.0, |t| t.angle);
        [a.angle, b.angle, c_angle]
    }
}

/// The rotation taking the pair (a0, b0) onto (a1, b1), which must have the
/// same lengths and angle; `None` when they are parallel.
fn align(a0: &Vector3, b0: &Vector3, a1: &Vector3, b1: &Vector3) -> Option<Matrix3> {
    let frame = |a: &Vector3, b: &Vector3| {
        let x = a.normalize();
        let z = a.cross(b);
        let zn = z.norm();
        (zn > 1e-9 * a.norm() * b.norm()).then(|| {
            let z = z / zn;
            Matrix3::from_columns(&[x, z.cross(&x), z])
        })
    };
    Some(frame(a1, b1)? * frame(a0, b0)?.transpose())
}

/// Every analytic branch reaching elbow E and wrist W (in {b}) with hand
/// orientation Ow, angles moved by 2π into their ranges where possible.
pub(crate) fn analytic_branches(
    robot: &Robot,
    elbow: &Vector3,
    wrist: &Vector3,
    ow: &Rotation3,
    near: &JointVector,
) -> Result<Vec<JointVector>, KinematicsError> {
    let s = &robot.structure;
    branches_with_wrist(robot, s, &s.wrist_zero, elbow, wrist, ow, near)
}

/// Every q4 that gives the triangle S-E-W the target's shape, with the
/// rotation R1 R2 R3 that then places it on the target E and W, and R1 R2 R3 R4.
pub(crate) fn triangle_placements(
    robot: &Robot,
    wrist_zero: &Vector3,
    elbow: &Vector3,
    wrist: &Vector3,
) -> Result<Few<(Real, Matrix3, Matrix3), 2>, KinematicsError> {
    let placements = placements_of(&robot.structure, wrist_zero, elbow, wrist)?;
    let mut out = Few::new((0.0, Matrix3::zeros(), Matrix3::zeros()));
    for (q4, r123) in placements {
        let r1234 = r123 * rotation_from_sin_cos(&robot.structure.axes_zero[3], q4.sin, q4.cos);
        out.push((q4.angle, r123, r1234));
    }
    Ok(out)
}

/// [`triangle_placements`] for the arm structure `s`.
fn placements_of(
    s: &ArmStructure,
    wrist_zero: &Vector3,
    elbow: &Vector3,
    wrist: &Vector3,
) -> Result<Few<(Turn, Matrix3), 2>, KinematicsError> {
    let (w, p) = (&s.axes_zero, &s.axis_points_zero);
    let d = wrist.norm();

    // q4: |p4 + Rot(w4, q4)(W0 - p4)| = |W|  (subproblem 3 about S = origin).
    let v = wrist_zero - p[3];
    let v_par = w[3] * w[3].dot(&v);
    let v_perp = v - v_par;
    let w_perp = w[3].cross(&v_perp);
    let c0 = p[3] + v_par;
    let q4s = solve_trig(
        2.0 * c0.dot(&v_perp),
        2.0 * c0.dot(&w_perp),
        d * d - c0.norm_squared() - v_perp.norm_squared(),
    );
    if q4s.is_empty() {
        let (lu, lf) = (s.upper_arm_length, s.forearm_length);
        return Err(KinematicsError::Unreachable {
            distance: d,
            min: (lu - lf).abs(),
            max: lu + lf,
        });
    }
    let mut placements = Few::new((Turn::ZERO, Matrix3::zeros()));
    for q4 in q4s {
        let turn = Turn::of(q4);
        let wrist_moved = c0 + turn.cos * v_perp + turn.sin * w_perp;
        let r123 = align(&s.elbow_zero, &wrist_moved, elbow, wrist)
            .ok_or(KinematicsError::Singular(Singularity::StraightArm))?;
        placements.push((turn, r123));
    }
    Ok(placements)
}

/// [`analytic_branches`] for a wrist centre that sits at `wrist_zero` when
/// joints 1-4 are at zero (exact when joints 5-7 do not move W).
fn branches_with_wrist(
    robot: &Robot,
    s: &ArmStructure,
    wrist_zero: &Vector3,
    elbow: &Vector3,
    wrist: &Vector3,
    ow: &Rotation3,
    near: &JointVector,
) -> Result<Vec<JointVector>, KinematicsError> {
    let mut out = Vec::with_capacity(8);
    for (q4, r123) in placements_of(s, wrist_zero, elbow, wrist)? {
        elbow_branches(robot, s, q4, &r123, ow, near, &mut out)?;
    }
    Ok(out)
}

/// Pushes the branches of one elbow angle q4 (shoulder rotation `r123`) onto `out`.
fn elbow_branches(
    robot: &Robot,
    s: &ArmStructure,
    q4: Turn,
    r123: &Matrix3,
    ow: &Rotation3,
    near: &JointVector,
    out: &mut Vec<JointVector>,
) -> Result<(), KinematicsError> {
    let w = &s.axes_zero;
    // Whatever the shoulder branch, R1 R2 R3 = r123: the wrist's share of
    // Ow is the same for both, so it is split once per q4.
    let r567 = (r123 * rotation_from_sin_cos(&w[3], q4.sin, q4.cos)).transpose()
        * ow.matrix()
        * s.hand_zero.matrix().transpose();
    let wrists = decompose(&r567, &w[4], &w[5], &w[6], near[4])?;
    let q4 = q4.angle;
    for &[q1, q2, q3] in decompose(r123, &w[0], &w[1], &w[2], near[0])?.as_slice() {
        for [q5, q6, q7] in wrists.as_slice() {
            let q = JointVector::from_column_slice(&[q1, q2, q3, q4, *q5, *q6, *q7]);
            push_shifts(robot, q, out);
        }
    }
    Ok(())
}

/// The first of [`ik_cpsa`]'s solutions (the in-limit branch nearest `near`) without the
/// others: what tracking an IK branch along a path asks for, many times per edge.
///
/// # Errors
/// As [`ik_cpsa`].
pub fn ik_cpsa_nearest(
    robot: &Robot,
    target: &CpsaState,
    near: &JointVector,
) -> Result<JointVector, KinematicsError> {
    if !(target.pw.iter().all(|v| v.is_finite()) && target.swivel.is_finite()) {
        return Err(KinematicsError::NonFinite { what: "CPSA state" });
    }
    if robot.has_analytic_ik() && robot.structure.idealisation <= 1e-9 {
        let hat = cpsa_to_hat(robot, target)?;
        let (elbow, wrist) = hat_points(robot, &hat);
        if let Some(q) = nearest_branch(robot, &elbow, &wrist, &target.ow, near)? {
            return Ok(q);
        }
    }
    first(ik_cpsa(robot, target, Some(near))?)
}

/// The first of [`ik_hat`]'s solutions; as [`ik_cpsa_nearest`].
///
/// # Errors
/// As [`ik_hat`].
pub fn ik_hat_nearest(
    robot: &Robot,
    target: &HatState,
    near: &JointVector,
) -> Result<JointVector, KinematicsError> {
    let finite = target.elbow_angle.is_finite()
        && target.shoulder_frame.matrix().iter().all(|v| v.is_finite());
    if finite && robot.has_analytic_ik() && robot.structure.idealisation <= 1e-9 {
        let (elbow, wrist) = hat_points(robot, target);
        if let Some(q) = nearest_branch(robot, &elbow, &wrist, &target.ow, near)? {
            return Ok(q);
        }
    }
    first(ik_hat(robot, target, Some(near))?)
}

fn first(solutions: Vec<JointVector>) -> Result<JointVector, KinematicsError> {
    // The solvers return at least one solution or an error.
    solutions.into_iter().next().ok_or(KinematicsError::Singular(Singularity::ParallelAxes))
}

/// The branch `select` would put first, computed elbow angle by elbow angle, nearest q4
/// first, skipping an elbow angle whose every branch is farther from `near` (in joint 4
/// alone) than the best found. `None` where that shortcut could differ from `select` (two
/// elbow angles one turn apart or equal, whose branches it would deduplicate across) or finds
/// no branch within the limits: the caller then runs the full solve, errors included.
fn nearest_branch(
    robot: &Robot,
    elbow: &Vector3,
    wrist: &Vector3,
    ow: &Rotation3,
    near: &JointVector,
) -> Result<Option<JointVector>, KinematicsError> {
    let s = &robot.structure;
    let placements = placements_of(s, &s.wrist_zero, elbow, wrist)?;
    // No branch of an elbow angle is nearer than its q4 is to near's (2π shifts included).
    let bound = |q4: Real| wrap_angle(q4 - near[3]).abs() - 1e-9;
    let mut order = [0, 1];
    let order = &mut order[..placements.len()];
    if let [(a, _), (b, _)] = placements[..] {
        let (a, b) = (a.angle, b.angle);
        if wrap_angle(a - b).abs() <= 1e-6 {
            return Ok(None);
        }
        if bound(b) < bound(a) {
            order.swap(0, 1);
        }
    }
    let tolerance = IkOptions::default().limit_tolerance;
    let w = &s.axes_zero;
    // A branch's distance from `near` is at least that of its joints 2, 4 and 6 alone, 2π
    // shifts included: the middle angles come before the outer ones, so a shoulder or wrist
    // solution that cannot be nearest is never finished. The margin keeps every skipped
    // branch, and any near-copy of one that the deduplication below would have dropped,
    // farther than the nearest.
    let apart = |angle: Real, j: usize| (wrap_angle(angle - near[j]).abs() - 2e-9).max(0.0);
    // (distance, elbow angle's index as `select` meets it, (shoulder, wrist, shift) within
    // it, which orders as the branch's index there, joints)
    type Candidate = (Real, usize, (usize, usize, usize), JointVector);
    let mut best: Option<Candidate> = None;
    let mut branches = Vec::with_capacity(8);
    let mut kept: Vec<JointVector> = Vec::with_capacity(8);
    for &mut g in order {
        let (turn, r123) = placements[g];
        let q4 = turn.angle;
        if best.is_some_and(|(d, ..)| bound(q4) > d) {
            continue;
        }
        // Whatever the shoulder branch, R1 R2 R3 = r123: the wrist's share of Ow is the same
        // for both, so it is split once per q4 (as in `elbow_branches`).
        let r567 = (r123 * rotation_from_sin_cos(&w[3], turn.sin, turn.cos)).transpose()
            * ow.matrix()
            * s.hand_zero.matrix().transpose();
        let wrists = Split::new(&r567, &w[4], &w[5], &w[6], near[4])?;
        let shoulders = Split::new(&r123, &w[0], &w[1], &w[2], near[0])?;
        let mut shoulder_done: [Option<[Real; 3]>; 2] = [None; 2];
        let mut wrist_done: [Option<[Real; 3]>; 2] = [None; 2];
        let joints = |sh: [Real; 3], wr: [Real; 3]| {
            JointVector::from_column_slice(&[sh[0], sh[1], sh[2], q4, wr[0], wr[1], wr[2]])
        };
        let lower = |i: usize, j: usize| {
            let (a, b, c) =
                (apart(shoulders.middle(i), 1), apart(q4, 3), apart(wrists.middle(j), 5));
            (a * a + b * b + c * c).sqrt()
        };
        // An upper bound on the nearest distance: the in-limit versions of the pair whose
        // lower bound is least (it or a near-copy of it is among the branches below).
        let mut limit = best.map_or(Real::INFINITY, |(d, ..)| d + 1e-8);
        let pairs = (0..shoulders.len).flat_map(|i| (0..wrists.len).map(move |j| (i, j)));
        if let Some((i, j)) =
            pairs.clone().min_by(|a, b| lower(a.0, a.1).total_cmp(&lower(b.0, b.1)))
        {
            let (sh, wr) = (shoulders.solution(i), wrists.solution(j));
            shoulder_done[i] = Some(sh);
            wrist_done[j] = Some(wr);
            branches.clear();
            push_shifts(robot, joints(sh, wr), &mut branches);
            for q in branches.iter().filter(|q| robot.within_limits(q, tolerance)) {
                limit = limit.min((q - near).norm() + 1e-8);
            }
        }
        kept.clear();
        for (i, j) in pairs {
            if lower(i, j) > limit {
                continue;
            }
            let sh = *shoulder_done[i].get_or_insert_with(|| shoulders.solution(i));
            let wr = *wrist_done[j].get_or_insert_with(|| wrists.solution(j));
            branches.clear();
            push_shifts(robot, joints(sh, wr), &mut branches);
            for (k, q) in branches.iter().enumerate() {
                if !robot.within_limits(q, tolerance) || kept.iter().any(|p| (p - q).amax() < 1e-9)
                {
                    continue;
                }
                kept.push(*q);
                let d = (q - near).norm();
                let at = (i, j, k);
                let better = match best {
                    None => true,
                    // A stable sort by distance keeps the earlier of equal ones.
                    Some((bd, bg, bat, _)) => d < bd || (d == bd && (g, at) < (bg, bat)),
                };
                if better {
                    best = Some((d, g, at, *q));
                    limit = limit.min(d + 1e-8);
                }
            }
        }
    }
    Ok(best.map(|(.., q)| q))
}

/// Pushes every version of `q` whose angles are moved by multiples of 2π
/// into their joint ranges (several where a range spans more than a turn,
/// as on continuous joints); a joint that no shift brings inside keeps the
/// shift nearest its range, so that the branch can still be reported.
/// IK calls this for every branch: it allocates nothing but the pushes.
fn push_shifts(robot: &Robot, q: JointVector, out: &mut Vec<JointVector>) {
    let first = out.len();
    out.push(q);
    for (i, joint) in robot.joints.iter().enumerate() {
        let l = &joint.limits;
        // Most angles are within a turn above the lower limit, where the floor is 0 and the
        // shift leaves them as they are (bit for bit); `floor` is a library call here.
        let turns = (q[i] - l.lower) / (2.0 * PI);
        let base = if (0.0..1.0).contains(&turns) { q[i] } else { q[i] - 2.0 * PI * turns.floor() };
        // base is the smallest shift at or above the lower limit.
        let shift = |k: u32| base + 2.0 * PI * Real::from(k);
        let inside = (0..).take_while(|k| shift(*k) <= l.upper + 1e-9).count() as u32;
        let count = out.len() - first;
        if inside == 0 {
            let excess = |v: Real| (l.lower - v).max(v - l.upper).max(0.0);
            let nearest =
                if excess(base - 2.0 * PI) < excess(base) { base - 2.0 * PI } else { base };
            for q in &mut out[first..first + count] {
                q[i] = nearest;
            }
            continue;
        }
        for k in 0..count {
            for n in 0..inside {
                if n == 0 {
                    out[first + k][i] = shift(0);
                } else {
                    let mut shifted = out[first + k];
                    shifted[i] = shift(n);
                    out.push(shifted);
                }
            }
        }
    }
}

fn limit_excess(robot: &Robot, q: &JointVector) -> (usize, Real) {
    (0..DOF)
        .map(|i| {
            let l = &robot.joints[i].limits;
            (i, (l.lower - q[i]).max(q[i] - l.upper))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0, 0.0))
}

fn out_of_limits(robot: &Robot, q: &JointVector) -> KinematicsError {
    let (i, excess) = limit_excess(robot, q);
    let l = &robot.joints[i].limits;
    KinematicsError::JointOutOfLimits {
        joint: robot.joints[i].name.clone(),
        value: q[i],
        lower: l.lower,
        upper: l.upper,
        excess,
    }
}

/// The distinct branches within limits, nearest `near` first, kept in `branches`' own
/// storage (IK calls this once per solve).
fn select(
    robot: &Robot,
    mut branches: Vec<JointVector>,
    near: &JointVector,
    tolerance: Real,
) -> Result<Vec<JointVector>, KinematicsError> {
    if !branches.iter().any(|q| robot.within_limits(q, tolerance)) {
        let least = branches
            .iter()
            .min_by(|a, b| limit_excess(robot, a).1.total_cmp(&limit_excess(robot, b).1));
        return Err(match least {
            Some(q) => out_of_limits(robot, q),
            None => KinematicsError::Singular(Singularity::ParallelAxes),
        });
    }
    // In place: the first of each set of equal branches within limits stays, in order.
    let mut kept = 0;
    for k in 0..branches.len() {
        let q = branches[k];
        if robot.within_limits(&q, tolerance)
            && !branches[..kept].iter().any(|p| (p - q).amax() < 1e-9)
        {
            branches[kept] = q;
            kept += 1;
        }
    }
    branches.truncate(kept);
    branches.sort_by(|a, b| (a - near).norm().total_cmp(&(b - near).norm()));
    Ok(branches)
}

/// The k-th point of a Halton sequence, scaled into the joint limits.
fn halton_start(robot: &Robot, k: usize) -> JointVector {
    const BASES: [usize; DOF] = [2, 3, 5, 7, 11, 13, 17];
    JointVector::from_fn(|i, _| {
        let (mut f, mut r, mut n) = (1.0, 0.0, k + 1);
        while n > 0 {
            f /= BASES[i] as Real;
            r += f * (n % BASES[i]) as Real;
            n /= BASES[i];
        }
        let l = &robot.joints[i].limits;
        l.lower + r * (l.upper - l.lower)
    })
}

fn clamp_to_limits(robot: &Robot, q: &mut JointVector) {
    for (i, joint) in robot.joints.iter().enumerate() {
        q[i] = q[i].clamp(joint.limits.lower, joint.limits.upper);
    }
}

/// A damped least-squares step that leaves joints resting on a limit alone
/// when the step would push them further out, so that the free joints do
/// the work instead of the step being clipped away.
fn projected_step(
    robot: &Robot,
    q: &JointVector,
    j: &Matrix7,
    e: &Vector7,
    lambda: Real,
) -> Option<JointVector> {
    let mut jac = *j;
    let mut step = JointVector::zeros();
    for _ in 0..DOF {
        let jt = jac.transpose();
        step = (jt * jac + Matrix7::identity() * lambda).cholesky()?.solve(&(jt * e));
        let mut changed = false;
        for (i, joint) in robot.joints.iter().enumerate() {
            let l = &joint.limits;
            let blocked = (q[i] <= l.lower && step[i] < 0.0) || (q[i] >= l.upper && step[i] > 0.0);
            if blocked && jac.column(i).iter().any(|v| *v != 0.0) {
                jac.column_mut(i).fill(0.0);
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    Some(step)
}

/// The arm with its shoulder axes moved through S, and, when its wrist is
/// nearly spherical, axes 5 and 6 through W: the nearest arm with the
/// closed-form IK, whose branches start Newton on the real one.
fn spherical_approximation(s: &ArmStructure) -> ArmStructure {
    let mut ideal = s.clone();
    for p in &mut ideal.axis_points_zero[..3] {
        *p = Vector3::zeros();
    }
    if s.wrist_residual > 0.0 && s.wrist_residual < 0.35 * s.forearm_length {
        for p in &mut ideal.axis_points_zero[4..] {
            *p = s.wrist_zero;
        }
    }
    ideal
}

/// Starting points for Newton, from the spherical approximation: on an arm
/// whose wrist centre moves with joints 5-6 (the human arm), freeze those
/// joints, solve the rest in closed form, re-freeze at the answer, a few
/// times over, from every branch.
fn decoupled_guesses(
    robot: &Robot,
    elbow: &Vector3,
    wrist: &Vector3,
    ow: &Rotation3,
    near: &JointVector,
) -> Vec<JointVector> {
    let ideal = spherical_approximation(&robot.structure);
    let s = &ideal;
    let (w, p) = (&s.axes_zero, &s.axis_points_zero);
    let about =
        |i: usize, angle: Real, x: &Vector3| p[i] + rotation_about(&w[i], angle) * (x - p[i]);
    let wrist_zero = |q: &JointVector| about(4, q[4], &about(5, q[5], &s.wrist_zero));
    let solve =
        |q: &JointVector| branches_with_wrist(robot, s, &wrist_zero(q), elbow, wrist, ow, q);
    let Ok(branches) = solve(near) else { return Vec::new() };
    let mut guesses: Vec<JointVector> = branches
        .into_iter()
        .map(|mut q| {
            for _ in 0..4 {
                let Some(next) = solve(&q).ok().and_then(|b| {
                    b.into_iter().min_by(|a, c| (a - q).norm().total_cmp(&(c - q).norm()))
                }) else {
                    break;
                };
                q = next;
            }
            q
        })
        .collect();
    // Within limits first, then nearest.
    guesses.sort_by(|a, b| {
        let key = |q: &JointVector| (limit_excess(robot, q).1.max(0.0), (q - near).norm());
        key(a).partial_cmp(&key(b)).unwrap_or(std::cmp::Ordering::Equal)
    });
    guesses
}

/// What one IK call may still spend.
struct Budget {
    iterations: usize,
    deadline: Option<std::time::Instant>,
    starts: usize,
}

impl Budget {
    fn new(options: &IkOptions) -> Self {
        Self { iterations: options.max_total_iterations, deadline: options.deadline, starts: 0 }
    }

    /// Takes one iteration; false when none is left or the deadline passed.
    fn take(&mut self) -> bool {
        if self.iterations == 0 || self.deadline.is_some_and(|d| std::time::Instant::now() >= d) {
            self.iterations = 0;
            return false;
        }
        self.iterations -= 1;
        true
    }
}

/// Levenberg-Marquardt from `start`, kept inside the joint limits: where it
/// ends and its residual norm.
fn descend<F>(
    robot: &Robot,
    mut q: JointVector,
    residual: &F,
    options: &IkOptions,
    budget: &mut Budget,
) -> (JointVector, Real)
where
    F: Fn(&JointVector) -> Result<(Vector7, Matrix7), KinematicsError>,
{
    budget.starts += 1;
    clamp_to_limits(robot, &mut q);
    let Ok((mut e, mut j)) = residual(&q) else { return (q, Real::INFINITY) };
    let mut lambda = 1e-6;
    for _ in 0..options.max_iterations {
        if e.norm() < options.tolerance || !budget.take() {
            break;
        }
        let Some(step) = projected_step(robot, &q, &j, &e, lambda) else {
            lambda *= 10.0;
            continue;
        };
        let mut trial = q + step;
        clamp_to_limits(robot, &mut trial);
        match residual(&trial) {
            Ok((e2, j2)) if e2.norm() < e.norm() => {
                (q, e, j) = (trial, e2, j2);
                lambda = (lambda * 0.1).max(1e-12);
            }
            _ => {
                lambda *= 10.0;
                if lambda > 1e6 {
                    break;
                }
            }
        }
    }
    (q, e.norm())
}

/// Levenberg-Marquardt on a square task Jacobian, kept inside the joint
/// limits, from `near` and the closed-form guesses (in the order the caller
/// prefers), then Halton starts, until one converges or the budget is spent.
fn newton<F, G>(
    robot: &Robot,
    near: &JointVector,
    near_first: bool,
    guesses: G,
    options: &IkOptions,
    residual: F,
) -> Result<Vec<JointVector>, KinematicsError>
where
    F: Fn(&JointVector) -> Result<(Vector7, Matrix7), KinematicsError>,
    G: FnOnce() -> Vec<JointVector>,
{
    if !near.iter().all(|v| v.is_finite()) {
        return Err(KinematicsError::NonFinite { what: "q_near" });
    }
    let mut best = Real::INFINITY;
    let mut budget = Budget::new(options);
    // A caller's q_near is usually close: try it before paying for guesses.
    let near_start = std::iter::once(*near);
    let (before, after) =
        if near_first { (Some(near_start), None) } else { (None, Some(near_start)) };
    let starts = before
        .into_iter()
        .flatten()
        .chain(std::iter::once_with(guesses).flatten())
        .chain(after.into_iter().flatten())
        .chain((1..).map(|k| halton_start(robot, k)))
        .take(options.max_starts);
    for start in starts {
        if budget.iterations == 0 {
            break;
        }
        let (q, e) = descend(robot, start, &residual, options, &mut budget);
        best = best.min(e);
        if e < converged(options) {
            return Ok(vec![q]);
        }
    }
    Err(KinematicsError::NoConvergence { residual: best, starts: budget.starts })
}
