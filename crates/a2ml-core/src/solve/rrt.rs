//! RRT-Connect in joint space (docs/design.md §5, paper §5.3.2): the global solver for goal
//! segments, finding a way round obstacles where the local QP stalls.
//!
//! Two trees grow towards uniform samples within the joint limits, one from the start and one
//! from the goal configurations, each extension straight in joint space by at most
//! [`RrtOptions::step`] and greedily connected to the other tree. An edge is covered by checks
//! that each tell how far either way the arm keeps the clearance
//! ([`crate::collision::advancement`]), so the whole edge keeps `clearance`; the start and the
//! goals need only keep it themselves. The path is then shortcut. Seeded: the same seed gives
//! the same path, and a search that fails is decided by its sample budget, not by the clock
//! (a wall-clock limit is the user's option, reported as [`RrtError::Timeout`]).
//!
//! [`time_parameterise`] times the shortcut path as one rest-to-rest bell per straight edge,
//! within the velocity and acceleration limits: the motion is C² and stays on the edges the
//! checks covered.

use std::time::Instant;

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use super::monitor::Monitor;
use crate::collision::{
    CollisionModel, CollisionScene, advancement_at_least, clearance, min_distance, motion_bound,
};
use crate::kinematics::arm_pose;
use crate::math::{JointVector, Real};
use crate::profile::BellProfile;
use crate::robot::Robot;
use crate::trajectory::{Limits, Trajectory, TrajectoryError, sample_times};

/// Settings of [`rrt_connect`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RrtOptions {
    /// Seed of the sampler.
    pub seed: u64,
    /// Largest joint-space extension per step (rad, Euclidean norm), default 2: long edges
    /// are cheap to check where the arm is clear, and fewer nodes connect sooner.
    pub step: Real,
    /// Resolution of the edge checks (m of arm motion), default 5 mm: a check along an edge
    /// must show the clearance kept over half of it either way (or over the rest of the
    /// stretch it closes), so checks are never closer than that, except next to a start or goal
    /// that itself shows less.
    pub resolution: Real,
    /// Distance kept from obstacles and between non-adjacent links (m), default 0.01.
    pub clearance: Real,
    /// Samples before giving up, default 20,000: what decides that a search failed.
    pub max_samples: usize,
    /// Wall time before giving up (s), default none: a limit the user sets, which makes the
    /// outcome depend on the machine's speed.
    pub max_time: Option<Real>,
    /// Shortcut attempts on the found path, default 200.
    pub shortcuts: usize,
}

impl Default for RrtOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            step: 2.0,
            resolution: 0.005,
            clearance: 0.01,
            max_samples: 20_000,
            max_time: None,
            shortcuts: 200,
        }
    }
}

/// Counters of one search.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct RrtStats {
    /// Random samples drawn.
    pub samples: usize,
    /// Nodes in both trees at the end.
    pub nodes: usize,
    /// Configurations checked for collision.
    pub collision_checks: usize,
    /// Wall time (s); not serialised, so that plan files reproduce byte for byte.
    #[serde(skip_serializing)]
    pub time: Real,
}

impl RrtStats {
    /// The counters of a search started at `started`.
    pub(crate) fn since(started: Instant, samples: usize, nodes: usize, checks: usize) -> Self {
        let time = started.elapsed().as_secs_f64();
        Self { samples, nodes, collision_checks: checks, time }
    }
}

/// Why no path was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RrtError {
    /// The settings are out of range.
    #[error("invalid RRT settings: {reason}")]
    InvalidOptions {
        /// What is wrong.
        reason: &'static str,
    },
    /// The start is outside the limits or too close to an obstacle.
    #[error("the start configuration is {reason}")]
    InvalidStart {
        /// Why.
        reason: String,
    },
    /// No goal configuration is within the limits and clear.
    #[error(
        "{}",
        if *count == 0 {
            "the goal state has no IK solution within the joint limits".to_owned()
        } else {
            format!("none of the {count} goal configurations is within the limits and clear")
        }
    )]
    NoValidGoal {
        /// Goal configurations given.
        count: usize,
    },
    /// The IK cannot follow a constrained path between its checked points.
    #[error("the IK loses the path's branch at arc length {at:.4}")]
    Tracking {
        /// Chart arc length where it happens.
        at: Real,
    },
    /// A path cannot be timed.
    #[error("timing the path: {reason}")]
    Timing {
        /// Why.
        reason: String,
    },
    /// The wall-clock limit set by the user passed before a path was found.
    #[error("timeout: the time limit passed after {} samples", stats.samples)]
    Timeout {
        /// The search's counters.
        stats: RrtStats,
    },
    /// The search used its sample budget.
    #[error(
        "no path found in {} samples; the start tree came within {closest:.3} rad of the goal \
         tree",
        stats.samples
    )]
    NoPath {
        /// Joint-space distance between the closest nodes of the two trees (rad).
        closest: Real,
        /// The search's counters.
        stats: RrtStats,
    },
}

/// A collision-free joint-space path.
#[derive(Debug, Clone, PartialEq)]
pub struct RrtPath {
    /// Waypoints from the start to a goal, joined by straight segments in joint space.
    pub waypoints: Vec<JointVector>,
    /// The goal configuration reached (index into the goals given).
    pub goal: usize,
    /// The search's counters.
    pub stats: RrtStats,
}

/// Plans from `start` to any of `goals` (in order of preference: ties in the search go to the
/// earlier) among the obstacles of `scene`.
///
/// # Errors
/// [`RrtError`]: invalid settings, an invalid start, no valid goal, or no path within the
/// sample budget ([`RrtError::Timeout`] when the time limit passes first).
pub fn rrt_connect(
    robot: &Robot,
    scene: &CollisionScene,
    start: &JointVector,
    goals: &[JointVector],
    options: &RrtOptions,
) -> Result<RrtPath, RrtError> {
    rrt_connect_monitored(robot, scene, start, goals, options, &mut Monitor::silent())
}

/// Samples between two progress reports and deadline checks.
pub(crate) const REPORT_EVERY: usize = 64;

/// [`rrt_connect`], reporting the fraction of the sample budget used to `monitor` and
/// stopping at its deadline.
///
/// # Errors
/// As [`rrt_connect`].
pub fn rrt_connect_monitored(
    robot: &Robot,
    scene: &CollisionScene,
    start: &JointVector,
    goals: &[JointVector],
    options: &RrtOptions,
    monitor: &mut Monitor,
) -> Result<RrtPath, RrtError> {
    check_options(options)?;
    let mut monitor = monitor.within(options.max_time);
    let started = Instant::now();
    let mut space = Space::new(robot, scene, options);
    if let Some(reason) = space.invalid(start) {
        return Err(RrtError::InvalidStart { reason });
    }
    let valid_goals: Vec<(usize, JointVector)> =
        goals.iter().copied().enumerate().filter(|(_, g)| space.invalid(g).is_none()).collect();
    if valid_goals.is_empty() {
        return Err(RrtError::NoValidGoal { count: goals.len() });
    }
    let mut from_start = Tree::new(*start, None);
    let mut from_goal = Tree::new(valid_goals[0].1, Some(valid_goals[0].0));
    for &(index, g) in &valid_goals[1..] {
        from_goal.nodes.push(Node { q: g, parent: None, goal: Some(index) });
    }
    let mut rng = StdRng::seed_from_u64(options.seed);
    let (lower, upper) = (robot.lower(), robot.upper());
    let mut samples = 0;
    let mut swapped = false;
    // An edge straight from the start to a goal needs no tree.
    for &(index, g) in &valid_goals {
        if space.edge_free(start, &g, false) {
            let stats = space.stats(1, 0, started);
            return Ok(RrtPath { waypoints: vec![*start, g], goal: index, stats });
        }
    }
    while samples < options.max_samples {
        if samples % REPORT_EVERY == 0 {
            if monitor.expired() {
                let nodes = from_start.nodes.len() + from_goal.nodes.len();
                return Err(RrtError::Timeout { stats: space.stats(samples, nodes, started) });
            }
            monitor.report(samples as Real / options.max_samples as Real);
        }
        samples += 1;
        let sample = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
        let (grow, other) = if swapped {
            (&mut from_goal, &mut from_start)
        } else {
            (&mut from_start, &mut from_goal)
        };
        if let Some(new) = grow.extend(&sample, &mut space) {
            let q = grow.nodes[new].q;
            if let Some(reached) = other.connect(&q, &mut space) {
                let (a, b) = if swapped { (reached, new) } else { (new, reached) };
                let (s_tree, g_tree) = if swapped { (&*other, &*grow) } else { (&*grow, &*other) };
                let mut waypoints = s_tree.path_to_root(a);
                waypoints.reverse();
                let tail = g_tree.path_to_root(b);
                let goal = g_tree.root_goal(b);
                waypoints.extend(tail);
                let waypoints = shortcut(waypoints, &mut space, &mut rng, options.shortcuts);
                let nodes = from_start.nodes.len() + from_goal.nodes.len();
                return Ok(RrtPath {
                    waypoints,
                    goal,
                    stats: space.stats(samples, nodes, started),
                });
            }
        }
        swapped = !swapped;
    }
    let closest =
        closest_pair(from_start.nodes.iter().map(|n| &n.q), from_goal.nodes.iter().map(|n| &n.q));
    let nodes = from_start.nodes.len() + from_goal.nodes.len();
    Err(RrtError::NoPath { closest, stats: space.stats(samples, nodes, started) })
}

/// The joint-space distance between the closest configurations of two trees (rad).
pub(crate) fn closest_pair<'a>(
    a: impl Iterator<Item = &'a JointVector>,
    b: impl Iterator<Item = &'a JointVector> + Clone,
) -> Real {
    a.flat_map(|p| b.clone().map(move |q| (p - q).norm())).fold(Real::INFINITY, Real::min)
}

pub(crate) fn check_options(o: &RrtOptions) -> Result<(), RrtError> {
    let positive = |x: Real| x.is_finite() && x > 0.0;
    let checks = [
        (positive(o.step), "the step must be positive"),
        (positive(o.resolution), "the resolution must be positive"),
        (o.clearance.is_finite() && o.clearance >= 0.0, "negative clearance"),
        (o.max_samples > 0, "no samples allowed"),
        (o.max_time.is_none_or(positive), "the time limit must be positive"),
    ];
    match checks.iter().find(|(ok, _)| !ok) {
        Some((_, reason)) => Err(RrtError::InvalidOptions { reason }),
        None => Ok(()),
    }
}

/// The configuration space: limits, collision checks and their count.
struct Space<'a> {
    robot: &'a Robot,
    scene: &'a CollisionScene,
    options: &'a RrtOptions,
    model: CollisionModel,
    /// Uncovered stretches of the edge being checked (reused, to allocate once).
    gaps: Vec<Gap>,
    checks: usize,
}

/// A stretch (from, to) of an edge's parameter not yet known to keep the clearance, and whether
/// it reaches an end whose own check shows the clearance kept over less than half the
/// resolution (a tight end).
#[derive(Debug, Clone, Copy)]
struct Gap {
    from: Real,
    to: Real,
    tight_a: bool,
    tight_b: bool,
}

impl<'a> Space<'a> {
    fn new(robot: &'a Robot, scene: &'a CollisionScene, options: &'a RrtOptions) -> Self {
        let model = CollisionModel::new(robot, scene);
        Self { robot, scene, options, model, gaps: Vec::new(), checks: 0 }
    }

    /// Why `q` is not a valid end (within the limits, `clearance` from the scene), if it is not.
    fn invalid(&mut self, q: &JointVector) -> Option<String> {
        if let Some((i, v)) = self.robot.limit_violation(q, 0.0) {
            return Some(format!(
                "outside the limits: joint `{}` at {v:.4} rad",
                self.robot.joints[i].name
            ));
        }
        self.checks += 1;
        if clearance(&self.model, q) >= self.options.clearance {
            return None;
        }
        let (d, link, obstacle) = min_distance(self.robot, &arm_pose(self.robot, q), self.scene)?;
        Some(format!("{:.1} mm from `{obstacle}` (link `{link}`)", d * 1e3))
    }

    /// How far (in units of `dq`) the arm at `q` may move along `dq`, either way, keeping the
    /// clearance, if at least `least`.
    fn advancement(&mut self, q: &JointVector, dq: &JointVector, least: Real) -> Option<Real> {
        self.checks += 1;
        advancement_at_least(&self.model, q, dq, self.options.clearance, least)
    }

    /// Whether the straight edge a -> b keeps the clearance, `b` being a new configuration
    /// (checked first, as the likelier to collide) or a node.
    ///
    /// A check at a point of the edge tells how far either way along it the arm keeps the
    /// clearance ([`advancement`]), so the edge is covered by checks placed in the middle of
    /// what is still uncovered. Each check must show the clearance kept over half the
    /// resolution of arm motion either way, or over the rest of its stretch, or lie in a
    /// stretch reaching an end that shows less (a start left near the clearance: such
    /// stretches are split finer until covered, down to a millionth of that). The ends must
    /// keep the clearance, a new `b` over half the resolution too, so that the edges leaving it
    /// are not that fine. So the whole edge keeps `clearance`.
    fn edge_free(&mut self, a: &JointVector, b: &JointVector, new: bool) -> bool {
        let dq = b - a;
        let travel = motion_bound(&self.model, &dq);
        if travel == 0.0 {
            return true;
        }
        // Half the resolution of arm motion, in units of the edge.
        let floor = 0.5 * self.options.resolution / travel;
        let Some(at_b) = self.advancement(b, &dq, if new { floor } else { 0.0 }) else {
            return false;
        };
        let Some(at_a) = self.advancement(a, &dq, 0.0) else {
            return false;
        };
        // Next to a tight end, stretches are split until covered, down to this.
        let finest = floor * 1e-6;
        self.gaps.clear();
        self.gaps.push(Gap {
            from: at_a,
            to: 1.0 - at_b,
            tight_a: at_a < floor,
            tight_b: at_b < floor,
        });
        while let Some(gap) = self.gaps.pop() {
            if gap.from >= gap.to {
                continue;
            }
            let (middle, half) = (0.5 * (gap.from + gap.to), 0.5 * (gap.to - gap.from));
            // Enough to close the stretch, or to split it.
            let splits = if (gap.tight_a || gap.tight_b) && half > finest { 0.0 } else { floor };
            let Some(covered) = self.advancement(&(a + dq * middle), &dq, half.min(splits)) else {
                return false;
            };
            if covered >= half {
                continue;
            }
            // Towards b last: a stretch next to a tends to be checked first.
            self.gaps.push(Gap { from: middle + covered, tight_a: false, ..gap });
            self.gaps.push(Gap { to: middle - covered, tight_b: false, ..gap });
        }
        true
    }

    fn stats(&self, samples: usize, nodes: usize, started: Instant) -> RrtStats {
        RrtStats::since(started, samples, nodes, self.checks)
    }
}

struct Node {
    q: JointVector,
    parent: Option<usize>,
    /// For a goal tree's root: which goal it is.
    goal: Option<usize>,
}

struct Tree {
    nodes: Vec<Node>,
}

/// The outcome of one step of a tree towards a target.
pub(crate) enum Extension {
    /// The target was reached: the new node.
    Reached(usize),
    /// A step towards it was taken: the new node.
    Advanced(usize),
    /// The step was blocked.
    Trapped,
}

impl Extension {
    /// The new node, if any.
    pub(crate) fn node(self) -> Option<usize> {
        match self {
            Extension::Reached(i) | Extension::Advanced(i) => Some(i),
            Extension::Trapped => None,
        }
    }
}

/// The index of the configuration nearest to `q` (Euclidean in joint space); 0 for none.
pub(crate) fn nearest<'a>(
    configurations: impl Iterator<Item = &'a JointVector>,
    q: &JointVector,
) -> usize {
    let mut best = (0, Real::INFINITY);
    for (i, c) in configurations.enumerate() {
        let d = (c - q).norm_squared();
        if d < best.1 {
            best = (i, d);
        }
    }
    best.0
}

impl Tree {
    fn new(root: JointVector, goal: Option<usize>) -> Self {
        Self { nodes: vec![Node { q: root, parent: None, goal }] }
    }

    fn nearest(&self, q: &JointVector) -> usize {
        nearest(self.nodes.iter().map(|n| &n.q), q)
    }

    /// One step from the nearest node towards `target`, a new configuration or a node of the
    /// other tree.
    fn step(&mut self, target: &JointVector, new_target: bool, space: &mut Space) -> Extension {
        let near = self.nearest(target);
        let from = self.nodes[near].q;
        let delta = target - from;
        let distance = delta.norm();
        let (to, reached) = if distance <= space.options.step {
            (*target, true)
        } else {
            (from + delta * (space.options.step / distance), false)
        };
        if !space.edge_free(&from, &to, new_target || !reached) {
            return Extension::Trapped;
        }
        self.nodes.push(Node { q: to, parent: Some(near), goal: None });
        let new = self.nodes.len() - 1;
        if reached { Extension::Reached(new) } else { Extension::Advanced(new) }
    }

    fn extend(&mut self, target: &JointVector, space: &mut Space) -> Option<usize> {
        self.step(target, true, space).node()
    }

    /// Steps towards `target` until it is reached (its node) or blocked.
    fn connect(&mut self, target: &JointVector, space: &mut Space) -> Option<usize> {
        loop {
            match self.step(target, false, space) {
                Extension::Reached(i) => return Some(i),
                Extension::Advanced(_) => continue,
                Extension::Trapped => return None,
            }
        }
    }

    /// Configurations from node `i` up to the root.
    fn path_to_root(&self, mut i: usize) -> Vec<JointVector> {
        let mut out = vec![self.nodes[i].q];
        while let Some(p) = self.nodes[i].parent {
            out.push(self.nodes[p].q);
            i = p;
        }
        out
    }

    fn root_goal(&self, mut i: usize) -> usize {
        while let Some(p) = self.nodes[i].parent {
            i = p;
        }
        self.nodes[i].goal.unwrap_or(0)
    }
}

/// Random shortcuts: two waypoints joined straight when the edge is free. A pair found blocked
/// is not checked again until the path changes (the answer would be the same), and the search
/// ends once every pair is.
fn shortcut(
    mut path: Vec<JointVector>,
    space: &mut Space,
    rng: &mut StdRng,
    attempts: usize,
) -> Vec<JointVector> {
    let mut blocked: Vec<(usize, usize)> = Vec::new();
    for _ in 0..attempts {
        let n = path.len();
        if n < 3 || blocked.len() == (n - 1) * (n - 2) / 2 {
            break;
        }
        let i = rng.random_range(0..n - 2);
        let j = rng.random_range(i + 2..n);
        if blocked.contains(&(i, j)) {
            continue;
        }
        if space.edge_free(&path[i], &path[j], false) {
            path.drain(i + 1..j);
            blocked.clear();
        } else {
            blocked.push((i, j));
        }
    }
    path
}

/// A path timed with bell-shaped speeds (paper eq. 9).
#[derive(Debug, Clone, PartialEq)]
pub struct TimedPath {
    /// Samples at the rate asked for, plus the end.
    pub trajectory: Trajectory,
    /// The duration used (s).
    pub duration: Real,
    /// Whether the duration asked for was stretched to keep every joint within its speed and
    /// acceleration limits.
    pub stretched: bool,
}

/// The share of a limit that planned timing uses; the rest absorbs the interpolation of the
/// output between samples.
pub const LIMIT_FRACTION: Real = 0.95;

/// The shortest rest-to-rest bell over `length` along the unit joint direction `u` that keeps
/// every joint within [`LIMIT_FRACTION`] of its limits: the bell's peak speed is 2L/T and its
/// peak acceleration 2πL/T², joint i moving |u_i| times as much.
pub fn shortest_bell(u: &JointVector, length: Real, limits: &Limits) -> Real {
    (0..u.len())
        .map(|i| {
            let d = length * u[i].abs();
            let v = LIMIT_FRACTION * limits.velocity[i];
            let a = LIMIT_FRACTION * limits.acceleration[i];
            (2.0 * d / v).max((2.0 * crate::math::PI * d / a).sqrt())
        })
        .fold(0.0, Real::max)
}

/// Times `waypoints` as one rest-to-rest bell (paper eq. 9) per straight edge: the speed and
/// acceleration vanish at every waypoint, so the motion is C² with no velocity step, and it
/// stays on the edges the collision checks covered. The path takes `duration`, or the sum of
/// the edges' shortest bells within the limits ([`shortest_bell`]) when that is longer.
///
/// # Errors
/// [`TrajectoryError`] for no waypoint, a non-positive rate or duration, or non-finite values.
pub fn time_parameterise(
    limits: &Limits,
    waypoints: &[JointVector],
    duration: Real,
    rate: Real,
) -> Result<TimedPath, TrajectoryError> {
    let first = *waypoints.first().ok_or(TrajectoryError::Empty)?;
    if !(rate.is_finite() && rate > 0.0) {
        return Err(TrajectoryError::InvalidRate { rate_hz: rate });
    }
    let edges: Vec<(JointVector, JointVector, Real)> = waypoints
        .windows(2)
        .filter(|w| (w[1] - w[0]).norm() > 0.0)
        .map(|w| (w[0], (w[1] - w[0]).normalize(), (w[1] - w[0]).norm()))
        .collect();
    // Each edge's share of the duration is in proportion to its shortest bell, so that every
    // edge uses the same share of its limits, and none is stretched unless all are.
    let shortest: Vec<Real> = edges.iter().map(|(_, u, l)| shortest_bell(u, *l, limits)).collect();
    let least: Real = shortest.iter().sum();
    let scale = if least > 0.0 { (duration / least).max(1.0) } else { 1.0 };
    let bells = edges
        .iter()
        .zip(&shortest)
        .map(|((_, _, l), short)| BellProfile::new(short * scale, *l))
        .collect::<Result<Vec<_>, _>>()
        .map_err(TrajectoryError::Join)?;
    let total: Real = bells.iter().map(BellProfile::duration).sum();
    if edges.is_empty() {
        let trajectory = Trajectory::new(vec![0.0], vec![first], vec![JointVector::zeros()])?;
        return Ok(TimedPath { trajectory, duration: 0.0, stretched: false });
    }
    // The rate's grid plus every waypoint's time, where the motion rests.
    let mut times = sample_times(0.0, total, rate);
    let mut start = 0.0;
    for bell in &bells {
        start += bell.duration();
        times.push(start);
    }
    times.sort_by(Real::total_cmp);
    times.dedup_by(|b, a| *b - *a <= 1e-9 / rate);
    let mut samples = Vec::with_capacity(times.len());
    let (mut edge, mut edge_start) = (0, 0.0);
    for &t in &times {
        while edge + 1 < edges.len() && t > edge_start + bells[edge].duration() {
            edge_start += bells[edge].duration();
            edge += 1;
        }
        let (from, u, _) = &edges[edge];
        let local = t - edge_start;
        samples.push((from + u * bells[edge].progress(local), u * bells[edge].speed(local)));
    }
    let (positions, velocities) = samples.into_iter().unzip();
    let trajectory = Trajectory::new(times, positions, velocities)?;
    Ok(TimedPath { trajectory, duration: total, stretched: total > duration * (1.0 + 1e-9) })
}

/// The length of a joint-space path (rad, Euclidean per edge).
pub fn path_length(waypoints: &[JointVector]) -> Real {
    waypoints.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}
