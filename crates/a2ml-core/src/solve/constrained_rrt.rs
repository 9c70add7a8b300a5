//! RRT-Connect in the constrained space of a pattern-3 segment (docs/design.md §5, paper §5.3.2
//! and §6.2): the global solver for a segment whose path constraint must hold exactly while
//! the arm finds its way round obstacles to the goals of the other variables.
//!
//! The search runs in the segment's *chart*: one coordinate σ for the path (the fraction of
//! the path's distance, shared by every path component, as they share one time profile in the
//! QP) and the goal components as free values (a position, a rotation, an angle). Every chart
//! point is a state of the segment's space that satisfies the path constraint by
//! construction, and analytic IK maps it to joints. Along an edge the IK solution is tracked
//! on one branch: each point takes the solution nearest to the previous one, and a step whose
//! joints jump (a branch switch, or a singularity the arm cannot follow) is refused. So the
//! path constraint holds at every node, every checked point and every output sample, to the
//! accuracy of the IK.
//!
//! Samples draw σ uniformly and the free values from the state of a uniform joint-space
//! sample (so rotations and positions the arm can hold come often); a free swivel angle is
//! drawn from the swivel intervals in which the sampled wrist pose is reachable within the
//! joint limits. A wrist line may be followed past its end (up to 99 % of the
//! arm's reach) and back: the arm then straightens and its elbow swings on a smaller circle,
//! as in paper fig. 7(b).
//!
//! Edges are tracked in steps, each step the chord in joint space between two IK solutions:
//! the collision model's conservative advancement ([`crate::collision::advancement`]) must
//! show that the chord keeps the clearance plus twice the IK curve's deviation from it at the
//! step's middle (the deviation were the curve quadratic), or the step is halved. A step whose
//! joints jump by more than [`MAX_JUMP`], or move faster than [`MAX_GAIN`] per unit of chart
//! length (a singularity or another IK branch), ends the edge. Where two IK solutions of one
//! chart point differ by a self-motion at a singularity (the wrist's first and last axes
//! aligned), the path turns the joints between them, which does not move the state. The
//! tests re-check every path densely and independently.

use std::time::Instant;

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use super::monitor::Monitor;
use super::qp::SegmentProblem;
use super::report::Tolerance;
use super::rrt::{
    Extension, LIMIT_FRACTION, REPORT_EVERY, RrtError, RrtOptions, RrtStats, TimedPath,
    closest_pair, nearest,
};
use crate::collision::{CollisionModel, CollisionScene, advancement, clearance, motion_bound};
use crate::decompose::{ArmState, goal_error};
use crate::kinematics::{CpsaState, HatState, ik_cpsa, ik_hat, swivel_intervals};
use crate::language::{Space, Target, Variable};
use crate::math::{JointVector, PI, Real, Rotation3, rotation_distance, rotation_log, wrap_angle};
use crate::profile::{BellProfile, Reference, Role};
use crate::robot::Robot;
use crate::trajectory::{Limits, Trajectory, TrajectoryError, peaks, sample_times};

/// Largest change of any joint between two consecutive IK solutions along an edge (rad): a
/// larger one is a switch of IK branch, which the arm cannot follow.
const MAX_JUMP: Real = 0.25;
/// Largest joint motion per unit of chart length (rad): faster joints mean the IK is near a
/// singularity, or has switched branch, and the edge ends there.
const MAX_GAIN: Real = 10.0;
/// Edge fractions below this end the tracking: the joints do not converge as the step
/// shrinks, so the IK jumps.
const MIN_STEP: Real = 1e-7;
/// Two IK solutions of one chart point closer than this (rad, max norm) are the same solution,
/// or, at a singularity, joined by a self-motion that leaves the state where it is.
const SAME_BRANCH: Real = 0.1 * MAX_JUMP;

/// A point of a segment's constrained space: the path coordinate σ and the values of the
/// space's three variables (those on the path follow from σ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartPoint {
    /// Fraction of the path's distance travelled (0 at the start, 1 at the path's end).
    pub sigma: Real,
    /// The values of the segment space's variables, in the order of [`Space::variables`].
    pub values: [Target; 3],
}

/// The constrained space of a segment: which components follow the path, and how far along
/// it the search may go.
#[derive(Debug, Clone)]
pub struct Chart {
    space: Space,
    references: [Reference; 3],
    on_path: [bool; 3],
    variables: [Variable; 3],
    /// σ ranges over [0, sigma_max].
    sigma_max: Real,
    /// Chart length of σ = 1 (the path's distance, positions scaled as below).
    path_scale: Real,
    /// Chart length of one metre of wrist motion: moving the wrist by half the arm's reach
    /// counts as much as turning by one radian.
    position_scale: Real,
}

impl Chart {
    /// The chart of `problem`: its path components (role [`Role::Path`]) share σ, its goal
    /// components are free.
    pub fn new(robot: &Robot, problem: &SegmentProblem) -> Self {
        let references = problem.components.map(|c| c.reference);
        let on_path = problem.components.map(|c| c.role == Role::Path);
        let variables = problem.components.map(|c| c.variable);
        let reach = robot.upper_arm_length() + robot.forearm_length();
        let position_scale = 2.0 / reach;
        let moving: Vec<&Reference> = references
            .iter()
            .zip(on_path)
            .filter(|(r, path)| *path && r.bell().distance() > 0.0)
            .map(|(r, _)| r)
            .collect();
        let path_scale = moving
            .iter()
            .map(|r| match r {
                Reference::Position(_) => r.bell().distance() * position_scale,
                _ => r.bell().distance(),
            })
            .map(|l| l * l)
            .sum::<Real>()
            .sqrt();
        let sigma_max = match moving.as_slice() {
            [] => 0.0,
            [Reference::Position(p)] => match p.path() {
                crate::profile::PositionPath::Line { direction } => {
                    // Past the end, up to 99 % of the reach: |Pw0 + d D σ| = 0.99 R.
                    let (p0, distance) = (p.start(), p.bell().distance());
                    let (b, c) = (p0.dot(&direction), p0.norm_squared() - (0.99 * reach).powi(2));
                    let s = -b + (b * b - c).max(0.0).sqrt();
                    (s / distance).max(1.0)
                }
                _ => 1.0,
            },
            _ => 1.0,
        };
        Self {
            space: problem.space,
            references,
            on_path,
            variables,
            sigma_max,
            path_scale: if path_scale > 0.0 { path_scale } else { 1.0 },
            position_scale,
        }
    }

    /// The largest σ the search may reach: 1, or more for a wrist line it may follow past its
    /// end.
    pub fn sigma_max(&self) -> Real {
        self.sigma_max
    }

    /// The point at `sigma` with the free components at `free` (path components ignored).
    fn at(&self, sigma: Real, free: &[Target; 3]) -> ChartPoint {
        let values = std::array::from_fn(|k| {
            if self.on_path[k] { self.references[k].at_fraction(sigma) } else { free[k] }
        });
        ChartPoint { sigma, values }
    }

    /// Where the segment starts: its references' start values.
    pub fn start(&self) -> ChartPoint {
        self.at(0.0, &self.references.map(|r| r.start()))
    }

    /// Where the segment ends: the path's end and the goal components' goals.
    pub fn goal(&self) -> ChartPoint {
        self.at(1.0, &self.references.map(|r| r.end()))
    }

    /// The chart distance between two points: σ scaled by the path's length, positions by
    /// [`Chart::position_scale`], rotations as geodesic angles, angles (swivel wrapped).
    pub fn distance(&self, a: &ChartPoint, b: &ChartPoint) -> Real {
        let sigma = (a.sigma - b.sigma) * self.path_scale;
        let free: Real = (0..3)
            .filter(|&k| !self.on_path[k])
            .map(|k| self.component_distance(k, &a.values[k], &b.values[k]).powi(2))
            .sum();
        (sigma * sigma + free).sqrt()
    }

    fn component_distance(&self, k: usize, a: &Target, b: &Target) -> Real {
        match (a, b) {
            (Target::Position(a), Target::Position(b)) => (a - b).norm() * self.position_scale,
            (Target::Rotation(a), Target::Rotation(b)) => rotation_distance(a, b),
            (Target::Angle(a), Target::Angle(b)) if self.variables[k] == Variable::Swivel => {
                wrap_angle(b - a).abs()
            }
            (Target::Angle(a), Target::Angle(b)) => (b - a).abs(),
            _ => Real::INFINITY,
        }
    }

    /// The point a fraction `tau` of the way from `a` to `b`: σ, positions and θe linearly,
    /// rotations along the geodesic, the swivel angle the shorter way round.
    pub fn interpolate(&self, a: &ChartPoint, b: &ChartPoint, tau: Real) -> ChartPoint {
        let free = std::array::from_fn(|k| match (a.values[k], b.values[k]) {
            (Target::Position(p), Target::Position(q)) => Target::Position(p + (q - p) * tau),
            (Target::Rotation(r), Target::Rotation(s)) => {
                Target::Rotation(r * Rotation3::new(rotation_log(&(r.inverse() * s)) * tau))
            }
            (Target::Angle(x), Target::Angle(y)) if self.variables[k] == Variable::Swivel => {
                Target::Angle(wrap_angle(x + wrap_angle(y - x) * tau))
            }
            (Target::Angle(x), Target::Angle(y)) => Target::Angle(x + (y - x) * tau),
            (value, _) => value,
        });
        self.at(a.sigma + (b.sigma - a.sigma) * tau, &free)
    }

    /// How far `state` is from the path, per component (0 for goal components): the errors
    /// at the σ in [0, [`Chart::sigma_max`]] that minimises the largest of them, each in units
    /// of its tolerance. This is the distance from the path's locus, whatever the timing: a
    /// solver that lags behind its reference but stays on the line has not left it.
    pub fn deviation(&self, state: &ArmState, tolerance: &Tolerance) -> [Real; 3] {
        let errors = |sigma: Real| -> [Real; 3] {
            std::array::from_fn(|k| {
                if !self.on_path[k] {
                    return 0.0;
                }
                let v = self.variables[k];
                goal_error(state, &[(v, self.references[k].at_fraction(sigma))])
            })
        };
        let worst = |sigma: Real| -> Real {
            let e = errors(sigma);
            (0..3).map(|k| e[k] / tolerance.of(self.variables[k])).fold(0.0, Real::max)
        };
        if self.sigma_max <= 0.0 {
            return errors(0.0);
        }
        let best_of = |candidates: &[Real]| -> [Real; 3] {
            let sigma = candidates.iter().copied().min_by(|a, b| worst(*a).total_cmp(&worst(*b)));
            errors(sigma.unwrap_or(0.0))
        };
        // One moving path component (the usual case): the σ nearest in closed form; the other
        // path components are holds, the same at every σ.
        let moving: Vec<usize> = (0..3)
            .filter(|&k| self.on_path[k] && self.references[k].bell().distance() > 0.0)
            .collect();
        if let [k] = moving[..] {
            let value = state.value(self.variables[k]);
            if let Some(sigma) = self.references[k].nearest_fraction(&value) {
                // Angles come back in (-π, π]: a turn by more than π may be nearer a turn on.
                let turn = 2.0 * PI / self.references[k].bell().distance();
                let clamped = |s: Real| s.clamp(0.0, self.sigma_max);
                let candidates = [sigma - turn, sigma, sigma + turn].map(clamped);
                return best_of(&[
                    candidates[0],
                    candidates[1],
                    candidates[2],
                    0.0,
                    self.sigma_max,
                ]);
            }
        }
        // A scan, then golden-section search in the best bracket: the worst error along the
        // path is unimodal near its minimum, not necessarily over the whole path. Each point
        // is evaluated once: the grid's values are kept, and each golden step reuses one.
        const SCAN: usize = 64;
        let h = self.sigma_max / SCAN as Real;
        let best = (0..=SCAN)
            .map(|i| {
                let sigma = i as Real * h;
                (sigma, worst(sigma))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(0.0, |(sigma, _)| sigma);
        let (mut lo, mut hi) = ((best - h).max(0.0), (best + h).min(self.sigma_max));
        let ratio = 0.5 * (5.0_f64.sqrt() - 1.0);
        let (mut a, mut b) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
        let (mut wa, mut wb) = (worst(a), worst(b));
        for _ in 0..40 {
            if wa <= wb {
                (hi, b, wb) = (b, a, wa);
                a = hi - ratio * (hi - lo);
                wa = worst(a);
            } else {
                (lo, a, wa) = (a, b, wb);
                b = lo + ratio * (hi - lo);
                wb = worst(b);
            }
        }
        best_of(&[best, 0.5 * (lo + hi)])
    }

    /// The IK solutions of `x` within the joint limits, the one nearest to `near` first.
    pub fn ik(&self, robot: &Robot, x: &ChartPoint, near: &JointVector) -> Vec<JointVector> {
        let solutions = match (self.space, x.values) {
            (Space::Cpsa, [Target::Position(pw), Target::Rotation(ow), Target::Angle(swivel)]) => {
                ik_cpsa(robot, &CpsaState { pw, ow, swivel }, Some(near))
            }
            (Space::Hat, [Target::Rotation(os), Target::Angle(elbow), Target::Rotation(ow)]) => {
                let hat = HatState { shoulder_frame: os, elbow_angle: elbow, ow };
                ik_hat(robot, &hat, Some(near))
            }
            _ => return Vec::new(),
        };
        solutions.unwrap_or_default()
    }

    /// The IK solution of `x` nearest to `near`, within the joint limits.
    pub fn ik_near(
        &self,
        robot: &Robot,
        x: &ChartPoint,
        near: &JointVector,
    ) -> Option<JointVector> {
        self.ik(robot, x, near).into_iter().next()
    }

    /// A random point: σ uniform, the free values from the state of a uniform joint-space
    /// sample, a free swivel angle uniform over the intervals where the wrist pose is
    /// reachable; with its IK solution nearest that joint-space sample, which tells the
    /// trees which IK branch the point is wanted on. `None` when the sample's state is
    /// singular, no swivel angle works or the point has no IK solution.
    fn sample(&self, robot: &Robot, rng: &mut StdRng) -> Option<(ChartPoint, JointVector)> {
        let (lower, upper) = (robot.lower(), robot.upper());
        let q = JointVector::from_fn(|i, _| rng.random_range(lower[i]..=upper[i]));
        let x = self.sample_near(robot, &q, rng)?;
        let hint = self.ik_near(robot, &x, &q)?;
        Some((x, hint))
    }

    fn sample_near(&self, robot: &Robot, q: &JointVector, rng: &mut StdRng) -> Option<ChartPoint> {
        let sigma = if self.sigma_max > 0.0 { rng.random_range(0.0..=self.sigma_max) } else { 0.0 };
        let state = ArmState::at(robot, q).ok()?;
        let mut x = self.at(sigma, &state.space_values(self.space));
        let swivel = self.variables.iter().position(|v| *v == Variable::Swivel);
        if let (Some(k), Space::Cpsa, true) = (swivel, self.space, robot.has_analytic_ik()) {
            if self.on_path[k] {
                return Some(x);
            }
            let (Target::Position(pw), Target::Rotation(ow)) = (x.values[0], x.values[1]) else {
                return None;
            };
            let intervals = swivel_intervals(robot, &pw, &ow).ok()?;
            let total: Real = intervals.iter().map(|i| i.upper - i.lower).sum();
            if total <= 0.0 {
                return None;
            }
            let mut u = rng.random_range(0.0..total);
            for i in &intervals {
                let width = i.upper - i.lower;
                if u <= width {
                    x.values[k] = Target::Angle(i.lower + u);
                    break;
                }
                u -= width;
            }
        }
        Some(x)
    }
}

/// A path through a segment's constrained space.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstrainedPath {
    /// Chart points from the start to the goal, joined by [`Chart::interpolate`].
    pub waypoints: Vec<ChartPoint>,
    /// The IK solution tracked at each waypoint.
    pub configurations: Vec<JointVector>,
    /// Per edge, the IK solutions at its checked points: (fraction of the edge, joints).
    pub tracks: Vec<Vec<(Real, JointVector)>>,
    /// The search's counters.
    pub stats: RrtStats,
}

/// Plans `problem`'s segment from `start` (a configuration at the chart's start) to the
/// chart's goal, keeping the path constraint exactly and the clearance of `options`.
///
/// A start closer to an obstacle than `clearance` (as the QP can leave one at the safety
/// distance) is accepted: the clearance kept is then half a millimetre less than the
/// start's.
///
/// # Errors
/// [`RrtError`]: invalid settings, a start in collision or outside the limits, no goal
/// configuration clear of obstacles, or no path within the sample budget
/// ([`RrtError::Timeout`] when the time limit passes first).
pub fn constrained_rrt(
    robot: &Robot,
    scene: &CollisionScene,
    chart: &Chart,
    start: &JointVector,
    options: &RrtOptions,
) -> Result<ConstrainedPath, RrtError> {
    constrained_rrt_monitored(robot, scene, chart, start, options, &mut Monitor::silent())
}

/// [`constrained_rrt`], reporting the fraction of the sample budget used to `monitor` and
/// stopping at its deadline.
///
/// # Errors
/// As [`constrained_rrt`].
pub fn constrained_rrt_monitored(
    robot: &Robot,
    scene: &CollisionScene,
    chart: &Chart,
    start: &JointVector,
    options: &RrtOptions,
    monitor: &mut Monitor,
) -> Result<ConstrainedPath, RrtError> {
    super::rrt::check_options(options)?;
    let mut monitor = monitor.within(options.max_time);
    let started = Instant::now();
    if let Some((i, v)) = robot.limit_violation(start, 0.0) {
        let joint = &robot.joints[i].name;
        let reason = format!("outside the limits: joint `{joint}` at {v:.4} rad");
        return Err(RrtError::InvalidStart { reason });
    }
    let mut search = Search::new(robot, scene, chart, options, start)?;
    let start_node =
        Node { x: chart.start(), q: *start, clearance: search.start_clearance, parent: None };
    let goal_x = chart.goal();
    // Every IK branch of the goal, the one nearest the start first.
    let goals = chart.ik(robot, &goal_x, start);
    let mut from_goal = Tree { nodes: Vec::new() };
    for q in &goals {
        if let Some(clearance) = search.valid(q) {
            from_goal.nodes.push(Node { x: goal_x, q: *q, clearance, parent: None });
        }
    }
    if from_goal.nodes.is_empty() {
        return Err(RrtError::NoValidGoal { count: goals.len() });
    }
    let mut from_start = Tree { nodes: vec![start_node] };
    let mut rng = StdRng::seed_from_u64(options.seed);
    let mut samples = 0;
    let mut swapped = false;
    // The straight edge in the chart first: the QP's own route, if it is clear.
    for g in 0..from_goal.nodes.len() {
        if let Some(path) = search.join(&from_start, 0, &from_goal, g) {
            return Ok(search.finish(path, &mut rng, samples, 2, started));
        }
    }
    while samples < options.max_samples {
        if samples % REPORT_EVERY == 0 {
            if monitor.expired() {
                let nodes = from_start.nodes.len() + from_goal.nodes.len();
                return Err(RrtError::Timeout { stats: search.stats(samples, nodes, started) });
            }
            monitor.report(samples as Real / options.max_samples as Real);
        }
        samples += 1;
        let Some((sample, hint)) = chart.sample(robot, &mut rng) else { continue };
        let (grow, other) = if swapped {
            (&mut from_goal, &mut from_start)
        } else {
            (&mut from_start, &mut from_goal)
        };
        let near = grow.nearest(&hint);
        if let Some(new) = grow.step(near, &sample, &mut search).node() {
            let x = grow.nodes[new].x;
            let q = grow.nodes[new].q;
            if let Some(reached) = other.connect(&x, &q, &mut search) {
                let (s, g) = if swapped { (reached, new) } else { (new, reached) };
                let (s_tree, g_tree) = if swapped { (&*other, &*grow) } else { (&*grow, &*other) };
                let mut nodes: Vec<&Node> = s_tree.to_root(s);
                nodes.reverse();
                // Both trees' nodes at the meeting point stay: they may differ by a
                // self-motion.
                nodes.extend(g_tree.to_root(g));
                let path = nodes.iter().map(|n| (n.x, n.q)).collect();
                let count = from_start.nodes.len() + from_goal.nodes.len();
                return Ok(search.finish(path, &mut rng, samples, count, started));
            }
        }
        swapped = !swapped;
    }
    let closest =
        closest_pair(from_start.nodes.iter().map(|n| &n.q), from_goal.nodes.iter().map(|n| &n.q));
    let nodes = from_start.nodes.len() + from_goal.nodes.len();
    Err(RrtError::NoPath { closest, stats: search.stats(samples, nodes, started) })
}

/// The chart, collision checks and their count.
struct Search<'a> {
    robot: &'a Robot,
    model: CollisionModel,
    chart: &'a Chart,
    options: &'a RrtOptions,
    /// The clearance every edge keeps (m).
    kept: Real,
    /// The start's clearance (m).
    start_clearance: Real,
    checks: usize,
}

impl<'a> Search<'a> {
    fn new(
        robot: &'a Robot,
        scene: &'a CollisionScene,
        chart: &'a Chart,
        options: &'a RrtOptions,
        start: &JointVector,
    ) -> Result<Self, RrtError> {
        let mut search = Self {
            robot,
            model: CollisionModel::new(robot, scene),
            chart,
            options,
            kept: options.clearance,
            start_clearance: 0.0,
            checks: 0,
        };
        let d = search.clearance(start);
        // The QP leaves the arm at the safety distance; half a millimetre less is kept then.
        const SLACK: Real = 5e-4;
        if d < SLACK {
            let reason = format!("{:.1} mm from an obstacle or the arm itself", d * 1e3);
            return Err(RrtError::InvalidStart { reason });
        }
        search.kept = options.clearance.min(d - SLACK);
        search.start_clearance = d;
        Ok(search)
    }

    fn clearance(&mut self, q: &JointVector) -> Real {
        self.checks += 1;
        clearance(&self.model, q)
    }

    /// The clearance of `q` if it is within the limits and clear enough for a node.
    fn valid(&mut self, q: &JointVector) -> Option<Real> {
        if !self.robot.within_limits(q, 0.0) {
            return None;
        }
        let d = self.clearance(q);
        (d >= self.kept).then_some(d)
    }

    /// Follows the edge from `(a, qa)` to `b` on one IK branch; the configuration and
    /// clearance at `b` when the whole edge is within the limits, keeps the clearance and
    /// never jumps.
    fn track(
        &mut self,
        a: &ChartPoint,
        qa: &JointVector,
        b: &ChartPoint,
    ) -> Option<(JointVector, Real)> {
        self.track_recorded(a, qa, b, &mut Vec::new())
    }

    /// [`Search::track`], pushing every checked point (edge fraction, configuration) onto
    /// `record`.
    fn track_recorded(
        &mut self,
        a: &ChartPoint,
        qa: &JointVector,
        b: &ChartPoint,
        record: &mut Vec<(Real, JointVector)>,
    ) -> Option<(JointVector, Real)> {
        let (mut tau, mut q) = (0.0, *qa);
        record.push((tau, q));
        let length = self.chart.distance(a, b);
        let mut step: Real = 1.0;
        while tau < 1.0 {
            let mut trial = step.min(1.0 - tau);
            let next = loop {
                let last = trial >= 1.0 - tau;
                let x = if last { *b } else { self.chart.interpolate(a, b, tau + trial) };
                let candidate = self.chart.ik_near(self.robot, &x, &q)?;
                let delta = candidate - q;
                let jump = delta.amax();
                // Interpolation is uniform in chart length, so this step is trial × length
                // long: joints faster than that allows mean a singularity or another branch.
                if jump > MAX_GAIN * trial * length + 1e-9 {
                    return None;
                }
                let shrink = if jump > MAX_JUMP {
                    MAX_JUMP / jump
                } else {
                    // The IK curve leaves the chord by about its deviation at the middle
                    // (exactly, were it quadratic): the chord must keep that much more.
                    let middle = self.chart.interpolate(a, b, tau + 0.5 * trial.min(1.0 - tau));
                    let bend = self.chart.ik_near(self.robot, &middle, &q)? - (q + candidate) * 0.5;
                    let needed = self.kept + 2.0 * motion_bound(&self.model, &bend);
                    self.checks += 1;
                    let reach = if jump == 0.0 {
                        // No motion: the chord is the point, as clear as the search found it.
                        if clearance(&self.model, &q) >= needed { 1.0 } else { 0.0 }
                    } else {
                        advancement(&self.model, &q, &delta, needed)
                    };
                    if reach >= 1.0 {
                        break candidate;
                    }
                    if reach <= 0.0 {
                        return None;
                    }
                    reach
                };
                trial *= (0.9 * shrink).clamp(0.05, 0.5);
                if trial < MIN_STEP {
                    return None;
                }
            };
            // The last step lands on b exactly, whatever the rounding.
            tau = if trial >= 1.0 - tau { 1.0 } else { tau + trial };
            q = next;
            record.push((tau, q));
            step = 2.0 * trial;
        }
        Some((q, self.clearance(&q)))
    }

    /// Whether `arrival` (clearance `clearance`), tracked to a chart point, meets `node` at the
    /// same point: the same IK solution, or one a short self-motion away that keeps the
    /// clearance (two bodies approach at most twice as fast as one point moves).
    fn meets(&self, arrival: &JointVector, clearance: Real, node: &JointVector) -> bool {
        let delta = node - arrival;
        delta.amax() <= SAME_BRANCH
            && (delta.amax() == 0.0 && clearance >= self.kept
                || advancement(&self.model, arrival, &delta, self.kept) >= 1.0)
    }

    /// The edge from node `i` of `a` to node `j` of `b`, tracked to the same branch: the
    /// two-point path when it is free.
    fn join(
        &mut self,
        a: &Tree,
        i: usize,
        b: &Tree,
        j: usize,
    ) -> Option<Vec<(ChartPoint, JointVector)>> {
        let (from, to) = (&a.nodes[i], &b.nodes[j]);
        let (q, d) = self.track(&from.x, &from.q, &to.x)?;
        self.meets(&q, d, &to.q).then(|| vec![(from.x, from.q), (to.x, q), (to.x, to.q)])
    }

    /// Shortcuts the path and packs the result.
    fn finish(
        &mut self,
        mut path: Vec<(ChartPoint, JointVector)>,
        rng: &mut StdRng,
        samples: usize,
        nodes: usize,
        started: Instant,
    ) -> ConstrainedPath {
        for _ in 0..self.options.shortcuts {
            if path.len() < 3 {
                break;
            }
            let i = rng.random_range(0..path.len() - 2);
            let j = rng.random_range(i + 2..path.len());
            let ((xi, qi), (xj, qj)) = (path[i], path[j]);
            if let Some((q, d)) = self.track(&xi, &qi, &xj) {
                if self.meets(&q, d, &qj) {
                    // The arrival stays, for the self-motion onto qj if there is one.
                    path.splice(i + 1..j, [(xj, q)]);
                }
            }
        }
        // The IK solutions along each edge, as checked: timing follows them, so that it
        // stays on the branch the checks saw. An edge of the goal tree was grown from its
        // far end; it is tracked that way again when it does not track forwards.
        let mut tracks = Vec::with_capacity(path.len().saturating_sub(1));
        for w in path.windows(2) {
            let ((a, qa), (b, qb)) = (w[0], w[1]);
            let mut track = Vec::new();
            match self.track_recorded(&a, &qa, &b, &mut track) {
                Some((q, d)) if self.meets(&q, d, &qb) => {}
                _ => {
                    track.clear();
                    if let Some((q, d)) = self.track_recorded(&b, &qb, &a, &mut track) {
                        if self.meets(&q, d, &qa) {
                            track.reverse();
                            for (t, _) in &mut track {
                                *t = 1.0 - *t;
                            }
                            // The far end is the edge's own start, a self-motion away at most.
                            if let Some(first) = track.first_mut() {
                                first.1 = qa;
                            }
                        }
                    }
                }
            }
            tracks.push(track);
        }
        let stats = self.stats(samples, nodes, started);
        let (waypoints, configurations) = path.into_iter().unzip();
        ConstrainedPath { waypoints, configurations, tracks, stats }
    }

    fn stats(&self, samples: usize, nodes: usize, started: Instant) -> RrtStats {
        RrtStats::since(started, samples, nodes, self.checks)
    }
}

struct Node {
    x: ChartPoint,
    q: JointVector,
    clearance: Real,
    parent: Option<usize>,
}

struct Tree {
    nodes: Vec<Node>,
}

impl Tree {
    /// The node nearest to `q` in joint space. The chart alone cannot tell IK branches
    /// apart: two nodes at one chart point on different branches are far apart in joints, and
    /// no edge joins them without a jump.
    fn nearest(&self, q: &JointVector) -> usize {
        nearest(self.nodes.iter().map(|n| &n.q), q)
    }

    /// One step of at most `step` (chart length) from node `near` towards `target`.
    fn step(&mut self, near: usize, target: &ChartPoint, search: &mut Search) -> Extension {
        let from = &self.nodes[near];
        let distance = search.chart.distance(&from.x, target);
        let reached = distance <= search.options.step;
        let to = if reached {
            *target
        } else {
            search.chart.interpolate(&from.x, target, search.options.step / distance)
        };
        let (x, q0) = (from.x, from.q);
        let Some((q, clearance)) = search.track(&x, &q0, &to) else {
            return Extension::Trapped;
        };
        self.nodes.push(Node { x: to, q, clearance, parent: Some(near) });
        let new = self.nodes.len() - 1;
        if reached { Extension::Reached(new) } else { Extension::Advanced(new) }
    }

    /// Steps towards the node `(x, q)` of the other tree until reaching it on the same IK
    /// branch (the node reached) or being blocked.
    fn connect(&mut self, x: &ChartPoint, q: &JointVector, search: &mut Search) -> Option<usize> {
        let mut from = self.nearest(q);
        loop {
            match self.step(from, x, search) {
                Extension::Reached(i) => {
                    let n = &self.nodes[i];
                    return search.meets(&n.q, n.clearance, q).then_some(i);
                }
                Extension::Advanced(i) => from = i,
                Extension::Trapped => return None,
            }
        }
    }

    /// The nodes from `i` up to the root.
    fn to_root(&self, mut i: usize) -> Vec<&Node> {
        let mut out = vec![&self.nodes[i]];
        while let Some(p) = self.nodes[i].parent {
            out.push(&self.nodes[p]);
            i = p;
        }
        out
    }
}

/// A chart edge and the configurations checked along it (edge fraction, joints).
struct Edge {
    a: ChartPoint,
    b: ChartPoint,
    track: Vec<(Real, JointVector)>,
}

/// One stretch of a timed constrained path.
enum Piece {
    /// Along a chart edge, by IK near the configurations checked along it.
    Edge(Box<Edge>),
    /// A self-motion at one chart point: two IK solutions of the same state at a
    /// singularity (the wrist's first and last axes aligned, say), joined straight in joint
    /// space, which does not move the state.
    SelfMotion { a: JointVector, b: JointVector },
}

impl Piece {
    fn length(&self, chart: &Chart) -> Real {
        match self {
            Piece::Edge(e) => chart.distance(&e.a, &e.b),
            Piece::SelfMotion { a, b } => (b - a).norm(),
        }
    }
}

/// The pieces of `path`: its edges, and a self-motion wherever an edge leaves a singular
/// configuration on another IK solution of the same state than the one recorded (at a
/// singularity the solutions form a continuum, and the one the motion departs on is the limit
/// of those just after), or reaches its end on another one than the next edge starts from.
fn pieces(robot: &Robot, chart: &Chart, path: &ConstrainedPath) -> Result<Vec<Piece>, RrtError> {
    let mut out = Vec::new();
    let mut travelled = 0.0;
    let edges = path.waypoints.windows(2).zip(path.configurations.windows(2)).zip(&path.tracks);
    for ((w, c), track) in edges {
        let (a, b) = (w[0], w[1]);
        let lost = || RrtError::Tracking { at: travelled };
        // Far enough along for the IK to see the direction of departure, near enough for
        // that direction not to have turned.
        let probe = chart.interpolate(&a, &b, 1e-6);
        let after = chart.ik_near(robot, &probe, &c[0]).ok_or_else(lost)?;
        let departure = chart.ik_near(robot, &a, &after).ok_or_else(lost)?;
        if (departure - c[0]).amax() > 0.0 {
            out.push(Piece::SelfMotion { a: c[0], b: departure });
        }
        let mut track = track.clone();
        if track.last().is_none_or(|(t, _)| *t < 1.0) {
            return Err(lost());
        }
        let arrival = track.last().map_or(departure, |(_, q)| *q);
        if let Some(first) = track.first_mut() {
            first.1 = departure;
        }
        out.push(Piece::Edge(Box::new(Edge { a, b, track })));
        if (c[1] - arrival).amax() > 0.0 {
            out.push(Piece::SelfMotion { a: arrival, b: c[1] });
        }
        travelled += chart.distance(&a, &b);
    }
    Ok(out)
}

/// The IK solution at fraction `tau` of an edge, nearest the checked configurations around it;
/// `None` when it is not within [`MAX_JUMP`] of them (the IK has left their branch). Passing
/// close by a wrist or shoulder singularity, the solution can sweep away from the chord
/// between two checks faster than the checks' spacing assumed; the sweep turns the links
/// next to the aligned axes about those axes.
fn on_track(
    robot: &Robot,
    chart: &Chart,
    (a, b): (&ChartPoint, &ChartPoint),
    track: &[(Real, JointVector)],
    tau: Real,
) -> Option<JointVector> {
    let k = track.partition_point(|(t, _)| *t <= tau).clamp(1, track.len().max(1)) - 1;
    let near = match (track.get(k), track.get(k + 1)) {
        (Some((t0, q0)), Some((t1, q1))) if t1 > t0 => q0 + (q1 - q0) * ((tau - t0) / (t1 - t0)),
        (Some((_, q0)), _) => *q0,
        _ => return None,
    };
    let q = chart.ik_near(robot, &chart.interpolate(a, b, tau), &near)?;
    if (q - near).amax() <= SAME_BRANCH {
        return Some(q);
    }
    // Far from the chord (close by a singularity): follow the IK from the checked point
    // before, in steps that change no joint by much.
    let (mut t, mut q) = *track.get(k)?;
    let mut step = tau - t;
    while t < tau {
        let trial = step.min(tau - t);
        let at = if trial >= tau - t { tau } else { t + trial };
        let next = chart.ik_near(robot, &chart.interpolate(a, b, at), &q)?;
        if (next - q).amax() <= SAME_BRANCH {
            (t, q) = (at, next);
            step = 2.0 * trial;
        } else if trial > MIN_STEP {
            step = 0.5 * trial;
        } else {
            return None;
        }
    }
    Some(q)
}

/// Times a constrained path at `rate` as one rest-to-rest bell (paper eq. 9) per piece, along
/// its length (chart length for edges, joint-space length for self-motions at singular
/// points): speed and acceleration vanish where pieces meet, so nothing steps there. Every
/// sample on an edge is the IK of a chart point on the path, tracked on the path's branch, so
/// the path constraint holds at every sample. Joint velocities are the IK's derivative along
/// the path times the bell speed. Each piece takes its share of `duration` by length,
/// stretched until its joints keep [`LIMIT_FRACTION`] of their velocity and acceleration
/// limits.
///
/// # Errors
/// [`RrtError::Timing`] for a non-positive rate or duration, or a piece whose timing does not
/// settle within the limits; [`RrtError::Tracking`] when the IK cannot follow the path between
/// its checked points.
pub fn time_constrained(
    robot: &Robot,
    limits: &Limits,
    chart: &Chart,
    path: &ConstrainedPath,
    duration: Real,
    rate: Real,
) -> Result<TimedPath, RrtError> {
    let trajectory_error = |e: TrajectoryError| RrtError::Timing { reason: e.to_string() };
    if !(rate.is_finite() && rate > 0.0) {
        return Err(trajectory_error(TrajectoryError::InvalidRate { rate_hz: rate }));
    }
    let pieces = pieces(robot, chart, path)?;
    let lengths: Vec<Real> = pieces.iter().map(|p| p.length(chart)).collect();
    let length: Real = lengths.iter().sum();
    let within = Limits {
        velocity: limits.velocity * LIMIT_FRACTION,
        acceleration: limits.acceleration * LIMIT_FRACTION,
        ..*limits
    };
    let first = path.configurations[0];
    let (mut times, mut positions, mut velocities) =
        (vec![0.0], vec![first], vec![JointVector::zeros()]);
    let mut stretched = false;
    let mut travelled = 0.0;
    for (piece, &piece_length) in pieces.iter().zip(&lengths) {
        if piece_length <= 0.0 {
            continue;
        }
        let mut piece_duration = duration * piece_length / length;
        let mut timed = None;
        for _ in 0..8 {
            let samples = time_piece(robot, chart, piece, piece_length, piece_duration, rate)
                .map_err(|e| match e {
                    RrtError::Tracking { at } => RrtError::Tracking { at: travelled + at },
                    e => e,
                })?;
            let trajectory =
                Trajectory::new(samples.0, samples.1, samples.2).map_err(trajectory_error)?;
            let stretch = peaks(&trajectory, 0.0, piece_duration).stretch(&within);
            if stretch <= 1.0 {
                timed = Some(trajectory);
                break;
            }
            piece_duration *= stretch * 1.01;
            stretched = true;
        }
        let trajectory = timed.ok_or_else(|| RrtError::Timing {
            reason: "a piece's duration does not settle under the joint limits".into(),
        })?;
        let offset = *times.last().unwrap_or(&0.0);
        // The piece's first sample is where the last one ended, at rest.
        for ((t, q), qd) in trajectory
            .times()
            .iter()
            .zip(trajectory.positions())
            .zip(trajectory.velocities())
            .skip(1)
        {
            times.push(offset + t);
            positions.push(*q);
            velocities.push(*qd);
        }
        travelled += piece_length;
    }
    let total = *times.last().unwrap_or(&0.0);
    let trajectory = Trajectory::new(times, positions, velocities).map_err(trajectory_error)?;
    Ok(TimedPath {
        trajectory,
        duration: total,
        stretched: stretched || total > duration * (1.0 + 1e-9),
    })
}

/// One piece timed by a rest-to-rest bell of `duration` over its `length`: times from 0, q,
/// q'.
fn time_piece(
    robot: &Robot,
    chart: &Chart,
    piece: &Piece,
    length: Real,
    duration: Real,
    rate: Real,
) -> Result<(Vec<Real>, Vec<JointVector>, Vec<JointVector>), RrtError> {
    let bell = BellProfile::new(duration, length)
        .map_err(|e| RrtError::Timing { reason: TrajectoryError::Join(e).to_string() })?;
    let times = sample_times(0.0, duration, rate);
    let mut positions = Vec::with_capacity(times.len());
    let mut velocities = Vec::with_capacity(times.len());
    for &t in &times {
        let s = bell.progress(t);
        let lost = || RrtError::Tracking { at: s };
        let (q, rate_of_change) = match piece {
            Piece::SelfMotion { a, b } => {
                let u = (b - a) / length;
                (a + u * s, u)
            }
            Piece::Edge(edge) => {
                let Edge { a, b, track } = edge.as_ref();
                let tau = (s / length).clamp(0.0, 1.0);
                let at = |t: Real| on_track(robot, chart, (a, b), track, t);
                let q = at(tau).ok_or_else(lost)?;
                // dq/ds by a central difference on the same branch.
                let h = 1e-6;
                let (lo, hi) = ((tau - h).max(0.0), (tau + h).min(1.0));
                let ahead = at(hi).ok_or_else(lost)?;
                let behind = at(lo).ok_or_else(lost)?;
                (q, (ahead - behind) / ((hi - lo) * length))
            }
        };
        positions.push(q);
        velocities.push(rate_of_change * bell.speed(t));
    }
    Ok((times, positions, velocities))
}
