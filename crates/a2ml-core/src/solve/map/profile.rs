//! The smoothest free swivel profile through a map (METHODS.md §1.3 step 3) and the joints
//! along it (step 4): dynamic programming over (cell, last step), a clamped spline through
//! its nodes, a fine check with exact distances and limits, analytic IK with the branch
//! tracked from the start.

use super::grid::SwivelMap;
use super::spline::ClampedSpline;
use super::{MapError, MapOptions, SwivelTargets, WristMotion};
use crate::collision::{CollisionModel, CollisionScene, clearance};
use crate::kinematics::{CpsaState, arm_pose, cpsa_jacobian, ik_cpsa};
use crate::language::Obstacle;
use crate::math::{JointVector, PI, Real, Vector7, wrap_angle};
use crate::robot::Robot;
use crate::trajectory::Trajectory;

/// A planned swivel profile and the joint trajectory it gives.
#[derive(Debug, Clone, PartialEq)]
pub struct SwivelProfile {
    /// The dynamic programme's nodes: times (s) and swivel angles (rad, unwrapped).
    pub nodes: Vec<(Real, Real)>,
    /// Every how many nodes the smoothing spline kept (1: all of them).
    pub smoothing: usize,
    /// The profile θsw(t) at the trajectory's times (rad, unwrapped).
    pub swivel: Vec<Real>,
    /// Joints and their rates at the verification rate, from 0 to the duration.
    pub trajectory: Trajectory,
    /// The smallest clearance over the trajectory's samples (m; ∞ without pairs).
    pub clearance: Real,
    /// The programme's cost (velocity, acceleration and reference terms).
    pub cost: Real,
}

/// Over how many nodes the exact start and goal angles blend into the grid path.
const FADE_NODES: Real = 8.0;

/// The grid path the dynamic programme found: (map column, unwrapped angle) nodes.
struct GridPath {
    nodes: Vec<(usize, Real)>,
    cost: Real,
}

/// Plans the profile through `map` for `motion` from `start` (the segment's start
/// configuration), meeting `targets`, and checks it at `options.verify_rate` against
/// `obstacles` (positions in {b}) and the joint limits.
///
/// # Errors
/// [`MapError::PathInfeasible`] naming the first column the wrist pose rules out;
/// [`MapError::NoProfile`] naming the first time the free region is cut;
/// [`MapError::Verification`] when even the spline through every node fails the fine check;
/// [`MapError::Start`] when the start's swivel angle is undefined;
/// [`MapError::StartBlocked`] when the start is already closer than the safety distance.
pub fn plan_profile(
    robot: &Robot,
    obstacles: &[Obstacle],
    motion: &WristMotion,
    map: &SwivelMap,
    start: &JointVector,
    targets: &SwivelTargets,
    options: &MapOptions,
) -> Result<SwivelProfile, MapError> {
    if let Some((i, fault)) =
        map.faults.iter().enumerate().find_map(|(i, f)| f.as_ref().map(|f| (i, f)))
    {
        return Err(MapError::PathInfeasible { time: map.times[i], why: fault.describe() });
    }
    if !(options.max_swivel_speed.is_finite() && options.max_swivel_speed > 0.0) {
        return Err(MapError::Options("the swivel speed bound must be positive"));
    }
    if !(options.verify_rate.is_finite() && options.verify_rate > 0.0) {
        return Err(MapError::Options("the verification rate must be positive"));
    }
    let pose = arm_pose(robot, start);
    let start_swivel = crate::kinematics::cpsa_state(robot, &pose).map_err(MapError::Start)?.swivel;
    let model = CollisionModel::new(robot, &CollisionScene::new(obstacles));
    let at_start = clearance(&model, start);
    if at_start < options.safety_distance {
        return Err(MapError::StartBlocked {
            clearance: at_start,
            safety: options.safety_distance,
        });
    }
    let path = search(map, start_swivel, targets, options)?;
    let duration = map.times.last().copied().unwrap_or(0.0);
    let nodes: Vec<(Real, Real)> = path.nodes.iter().map(|&(i, a)| (map.times[i], a)).collect();
    let mut failure = None;
    for smoothing in [8, 4, 2, 1] {
        if smoothing > 1 && smoothing * 2 > nodes.len() {
            continue;
        }
        let kept: Vec<(Real, Real)> = nodes
            .iter()
            .enumerate()
            .filter(|(k, _)| k % smoothing == 0 || *k == nodes.len() - 1)
            .map(|(_, n)| *n)
            .collect();
        let spline = ClampedSpline::at_rest(
            kept.iter().map(|n| n.0).collect(),
            kept.iter().map(|n| n.1).collect(),
        )?;
        match follow(robot, &model, motion, &spline, start, duration, options) {
            Ok((trajectory, swivel, clearance)) => {
                return Ok(SwivelProfile {
                    nodes,
                    smoothing,
                    swivel,
                    trajectory,
                    clearance,
                    cost: path.cost,
                });
            }
            Err(e) => failure = Some(e),
        }
    }
    Err(failure.unwrap_or(MapError::Verification { time: 0.0, why: "no node".to_owned() }))
}

/// The columns the programme steps between: every `stride`-th, and the last.
fn stride_columns(count: usize, stride: usize) -> Vec<usize> {
    let mut columns: Vec<usize> = (0..count).step_by(stride).collect();
    if columns.last() != Some(&(count - 1)) {
        columns.push(count - 1);
    }
    columns
}

/// Dynamic programming over states (angle cell, last step in cells) at the stride columns:
/// a step of d cells over τ seconds must stay within the speed bound and cross only free
/// cells (rounded straight line through the columns in between); its cost is
/// (w_v v² + w_a a² + w_r wrap(θ − θ_ref)²) τ, the arm at rest before the start and after
/// the end.
fn search(
    map: &SwivelMap,
    start_swivel: Real,
    targets: &SwivelTargets,
    options: &MapOptions,
) -> Result<GridPath, MapError> {
    let n = map.angles.len();
    let nt = map.times.len();
    let step = map.angle_step();
    let dt = map.times[1] - map.times[0];
    let speed = options.max_swivel_speed;
    let stride = if dt > 0.0 { ((step / (speed * dt)).ceil() as usize).max(1) } else { 1 };
    let columns = stride_columns(nt, stride);
    let reach = |tau: Real| ((speed * tau / step) + 1e-9).floor() as isize;
    let m = reach(dt * stride as Real).max(1);
    let width = (2 * m + 1) as usize;
    let j0 = map.angle_index(start_swivel);
    let end_cell = targets.end.map(|e| map.angle_index(e));
    let reference = |i: usize| targets.reference.get(i).copied();
    let (wv, wa, wr) =
        (options.velocity_weight, options.acceleration_weight, options.reference_weight);
    let mut cost = vec![Real::INFINITY; n * width];
    cost[j0 * width + m as usize] = 0.0;
    // back[s][state]: the previous step's index, for the stride ending at columns[s + 1].
    let mut back: Vec<Vec<u16>> = Vec::with_capacity(columns.len());
    let mut previous_tau = dt * stride as Real;
    for w in columns.windows(2) {
        let (a, b) = (w[0], w[1]);
        let tau = map.times[b] - map.times[a];
        let reach_ab = reach(tau).min(m);
        // first_blocked[j][d]: the first column the step from cell j by d hits, or none.
        let blocked = |j: usize, d: isize| -> Option<usize> {
            (a + 1..=b).find(|&c| {
                let offset = (d as Real * (c - a) as Real / (b - a) as Real).round() as isize;
                let jj = (j as isize + offset).rem_euclid(n as isize) as usize;
                !map.is_free(c, jj)
            })
        };
        let mut next = vec![Real::INFINITY; n * width];
        let mut from = vec![u16::MAX; n * width];
        let mut furthest = a;
        for j in 0..n {
            let row = &cost[j * width..(j + 1) * width];
            if row.iter().all(|c| !c.is_finite()) {
                continue;
            }
            for d in -reach_ab..=reach_ab {
                if let Some(c) = blocked(j, d) {
                    furthest = furthest.max(c - 1);
                    continue;
                }
                furthest = b;
                let jj = (j as isize + d).rem_euclid(n as isize) as usize;
                let v = d as Real * step / tau;
                let theta = map.angles[jj];
                let off_reference = reference(b).map_or(0.0, |r| wrap_angle(theta - r).powi(2));
                let base = (wv * v * v + wr * off_reference) * tau;
                for (di, &c) in row.iter().enumerate() {
                    if !c.is_finite() {
                        continue;
                    }
                    let v_before = (di as isize - m) as Real * step / previous_tau;
                    let accel = (v - v_before) / (0.5 * (tau + previous_tau));
                    let total = c + base + wa * accel * accel * tau;
                    let state = jj * width + (d + m) as usize;
                    if total < next[state] {
                        next[state] = total;
                        from[state] = di as u16;
                    }
                }
            }
        }
        if next.iter().all(|c| !c.is_finite()) {
            // `furthest` is the last column some step reached; the next is where it is cut.
            let cut = (furthest + 1).min(b);
            return Err(MapError::NoProfile { time: map.times[cut], speed });
        }
        cost = next;
        back.push(from);
        previous_tau = tau;
    }
    // Come to rest after the end.
    let mut best: Option<(Real, usize)> = None;
    for j in 0..n {
        if end_cell.is_some_and(|e| e != j) {
            continue;
        }
        for di in 0..width {
            let c = cost[j * width + di];
            let v = (di as isize - m) as Real * step / previous_tau;
            let total = c + wa * (v / previous_tau).powi(2) * previous_tau;
            if total.is_finite() && best.is_none_or(|(b, _)| total < b) {
                best = Some((total, j * width + di));
            }
        }
    }
    let Some((total, mut state)) = best else {
        return Err(MapError::NoProfile { time: map.times[nt - 1], speed });
    };
    // Walk back, then unwrap from the exact start angle.
    let mut steps = Vec::with_capacity(back.len());
    for from in back.iter().rev() {
        let d = (state % width) as isize - m;
        steps.push(d);
        let j = state / width;
        let jp = (j as isize - d).rem_euclid(n as isize) as usize;
        state = jp * width + from[state] as usize;
    }
    steps.reverse();
    let mut angle = map.angles[j0];
    let mut nodes = vec![(0, angle)];
    for (s, d) in steps.iter().enumerate() {
        angle += *d as Real * step;
        nodes.push((columns[s + 1], angle));
    }
    // The cells' centres are within half a cell of the exact start (and goal); the offset
    // fades over a few nodes rather than jumping at the first.
    let start_offset = wrap_angle(start_swivel - nodes[0].1);
    let end_offset = targets.end.map_or(0.0, |end| wrap_angle(end - angle));
    let count = nodes.len();
    for (k, node) in nodes.iter_mut().enumerate() {
        let fade = |from_end: usize| (1.0 - from_end as Real / FADE_NODES).max(0.0);
        node.1 += start_offset * fade(k) + end_offset * fade(count - 1 - k);
    }
    Ok(GridPath { nodes, cost: total })
}

/// The joints along (Pw(t), Ow(t), θsw(t)) at the verification rate, each by analytic IK
/// within the limits on the branch nearest the previous sample, with q' from the CPSA
/// Jacobian; the samples checked for clearance, speed and acceleration.
fn follow(
    robot: &Robot,
    model: &CollisionModel,
    motion: &WristMotion,
    spline: &ClampedSpline<Real>,
    start: &JointVector,
    duration: Real,
    options: &MapOptions,
) -> Result<(Trajectory, Vec<Real>, Real), MapError> {
    let samples = ((duration * options.verify_rate).ceil() as usize).max(1);
    let dt = duration / samples as Real;
    let speed = robot.velocity_limits();
    let (mut times, mut positions, mut velocities, mut swivel) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut near = *start;
    let mut worst = Real::INFINITY;
    for k in 0..=samples {
        let t = (k as Real * dt).min(duration);
        let fail = |why: String| MapError::Verification { time: t, why };
        let (theta, theta_rate, _) = spline.sample(t);
        let wrist = motion.at(t);
        let target = CpsaState { pw: wrist.pw, ow: wrist.ow, swivel: wrap_angle(theta) };
        let q = ik_cpsa(robot, &target, Some(&near))
            .map_err(|e| fail(e.to_string()))?
            .into_iter()
            .map(|b| unwrapped_toward(robot, b, &near))
            .min_by(|a, b| (a - near).norm().total_cmp(&(b - near).norm()))
            .ok_or_else(|| fail("no IK branch".to_owned()))?;
        if k > 0 && (q - near).amax() > 0.2 {
            let joint = (q - near).iamax();
            return Err(fail(format!(
                "the IK branch jumps by {:.3} rad at joint {} between samples (a joint limit or \
                 a singularity on the way)",
                (q - near).amax(),
                joint + 1
            )));
        }
        let distance = clearance(model, &q);
        if distance < options.safety_distance {
            return Err(fail(format!(
                "clearance {:.2} mm below the safety distance {:.2} mm",
                distance * 1e3,
                options.safety_distance * 1e3
            )));
        }
        worst = worst.min(distance);
        let jacobian =
            cpsa_jacobian(robot, &arm_pose(robot, &q)).map_err(|e| fail(e.to_string()))?;
        let mut rate = Vector7::zeros();
        rate.fixed_rows_mut::<3>(0).copy_from(&wrist.velocity);
        rate.fixed_rows_mut::<3>(3).copy_from(&wrist.angular_velocity);
        rate[6] = theta_rate;
        let qd: JointVector = jacobian
            .lu()
            .solve(&rate)
            .ok_or_else(|| fail("the CPSA Jacobian is singular".to_owned()))?;
        if let Some(i) = (0..7).find(|&i| qd[i].abs() > speed[i]) {
            return Err(fail(format!(
                "joint {} at {:.3} rad/s exceeds its speed limit {:.3} rad/s",
                i + 1,
                qd[i],
                speed[i]
            )));
        }
        if let (Some(limits), Some(before)) = (&options.acceleration_limits, velocities.last()) {
            let accel: JointVector = (qd - before) / dt;
            if let Some(i) = (0..7).find(|&i| accel[i].abs() > limits[i]) {
                return Err(fail(format!(
                    "joint {} accelerates at {:.3} rad/s², beyond {:.3} rad/s²",
                    i + 1,
                    accel[i],
                    limits[i]
                )));
            }
        }
        times.push(t);
        positions.push(q);
        velocities.push(qd);
        swivel.push(theta);
        near = q;
    }
    let trajectory = Trajectory::new(times, positions, velocities)
        .map_err(|e| MapError::Verification { time: 0.0, why: e.to_string() })?;
    Ok((trajectory, swivel, worst))
}

/// Each joint of `q` moved by ±2π towards `near` where that keeps it within its limits, so
/// a joint whose range spans more than a turn is followed continuously.
fn unwrapped_toward(robot: &Robot, mut q: JointVector, near: &JointVector) -> JointVector {
    for (i, joint) in robot.joints.iter().enumerate() {
        let candidates = [q[i], q[i] - 2.0 * PI, q[i] + 2.0 * PI];
        q[i] = candidates
            .into_iter()
            .filter(|v| joint.limits.contains(*v, 1e-9))
            .min_by(|a, b| (a - near[i]).abs().total_cmp(&(b - near[i]).abs()))
            .unwrap_or(q[i]);
    }
    q
}
