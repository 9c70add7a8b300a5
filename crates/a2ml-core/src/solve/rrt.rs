//! RRT-Connect in joint space (DESIGN.md §5, paper §5.3.2): the global solver for goal
//! segments, finding a way round obstacles where the local QP stalls.
//!
//! Two trees grow towards uniform samples within the joint limits, one from the start and one
//! from the goal configurations, each extension straight in joint space by at most
//! [`RrtOptions::step`] and greedily connected to the other tree. Edges are checked at
//! steps bounded by the clearance found at the last check (half of it, minus the clearance
//! kept, of arm-point motion), and every check asks for `clearance + resolution`, so the whole
//! edge keeps `clearance`. The path is then shortcut. Seeded: the same seed gives the same
//! path.

use std::time::Instant;

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use crate::collision::{CollisionScene, min_distance};
use crate::kinematics::arm_pose;
use crate::math::{JointVector, Real};
use crate::profile::{BellProfile, JointSample};
use crate::robot::Robot;
use crate::trajectory::{Trajectory, TrajectoryError, sample_times};

/// Settings of [`rrt_connect`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RrtOptions {
    /// Seed of the sampler.
    pub seed: u64,
    /// Largest joint-space extension per step (rad, Euclidean norm), default 0.3.
    pub step: Real,
    /// Margin beyond the clearance that every check asks for (m), default 5 mm: checks along
    /// an edge are never closer than half of it in arm-point motion.
    pub resolution: Real,
    /// Distance kept from obstacles and between non-adjacent links (m), default 0.01.
    pub clearance: Real,
    /// Samples before giving up, default 20,000.
    pub max_samples: usize,
    /// Wall time before giving up (s), default 5.
    pub max_time: Real,
    /// Shortcut attempts on the found path, default 200.
    pub shortcuts: usize,
}

impl Default for RrtOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            step: 0.3,
            resolution: 0.005,
            clearance: 0.01,
            max_samples: 20_000,
            max_time: 5.0,
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
    /// Wall time (s).
    pub time: Real,
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
    #[error("none of the {count} goal configurations is within the limits and clear")]
    NoValidGoal {
        /// Goal configurations given.
        count: usize,
    },
    /// The search ran out of samples or time.
    #[error(
        "no path found in {} samples and {:.2} s; the start tree came within {closest:.3} rad \
         of the goal tree",
        stats.samples,
        stats.time
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
/// sample and time limits.
pub fn rrt_connect(
    robot: &Robot,
    scene: &CollisionScene,
    start: &JointVector,
    goals: &[JointVector],
    options: &RrtOptions,
) -> Result<RrtPath, RrtError> {
    check_options(options)?;
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
        if space.edge_free(start, &g) {
            let stats = space.stats(1, 0, started);
            return Ok(RrtPath { waypoints: vec![*start, g], goal: index, stats });
        }
    }
    while samples < options.max_samples && started.elapsed().as_secs_f64() < options.max_time {
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
    let closest = from_start
        .nodes
        .iter()
        .flat_map(|a| from_goal.nodes.iter().map(move |b| (a.q - b.q).norm()))
        .fold(Real::INFINITY, Real::min);
    let nodes = from_start.nodes.len() + from_goal.nodes.len();
    Err(RrtError::NoPath { closest, stats: space.stats(samples, nodes, started) })
}

fn check_options(o: &RrtOptions) -> Result<(), RrtError> {
    let positive = |x: Real| x.is_finite() && x > 0.0;
    let checks = [
        (positive(o.step), "the step must be positive"),
        (positive(o.resolution), "the resolution must be positive"),
        (o.clearance.is_finite() && o.clearance >= 0.0, "negative clearance"),
        (o.max_samples > 0, "no samples allowed"),
        (positive(o.max_time), "the time limit must be positive"),
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
    /// Per joint, how far any capsule point it moves can be from its axis (m): a point moves
    /// at most Σ levers_i |Δq_i| along a straight joint-space edge.
    levers: JointVector,
    checks: usize,
}

impl<'a> Space<'a> {
    fn new(robot: &'a Robot, scene: &'a CollisionScene, options: &'a RrtOptions) -> Self {
        // Joint j turns frames j+1..7; its axis passes through the origin of frame j+1. A
        // capsule point on frame f is within Σ_{k=j+1}^{f-1} |t_k| (the joint offsets between)
        // plus its own distance from frame f's origin of that axis.
        let offsets: Vec<Real> =
            robot.joints.iter().map(|j| j.parent_from_joint.translation.vector.norm()).collect();
        let levers = JointVector::from_fn(|j, _| {
            robot
                .capsules
                .iter()
                .filter(|c| c.frame > j)
                .map(|c| {
                    let between: Real = offsets[j + 1..c.frame].iter().sum();
                    between + c.a.norm().max(c.b.norm()) + c.radius
                })
                .fold(0.0, Real::max)
        });
        Self { robot, scene, options, levers, checks: 0 }
    }

    /// Why `q` is not a valid configuration, if it is not.
    fn invalid(&mut self, q: &JointVector) -> Option<String> {
        if let Some((i, v)) = self.robot.limit_violation(q, 0.0) {
            return Some(format!(
                "outside the limits: joint `{}` at {v:.4} rad",
                self.robot.joints[i].name
            ));
        }
        self.checks += 1;
        let pose = arm_pose(self.robot, q);
        match min_distance(self.robot, &pose, self.scene) {
            Some((d, link, obstacle)) if d < self.options.clearance + self.options.resolution => {
                Some(format!("{:.1} mm from `{obstacle}` (link `{link}`)", d * 1e3))
            }
            _ => None,
        }
    }

    /// The smallest distance of the arm at `q` from the scene and from itself (∞ with no
    /// pair).
    fn clearance_at(&mut self, q: &JointVector) -> Real {
        self.checks += 1;
        let pose = arm_pose(self.robot, q);
        min_distance(self.robot, &pose, self.scene).map_or(Real::INFINITY, |(d, ..)| d)
    }

    /// Whether the straight edge a -> b keeps the clearance. No arm point moves more than
    /// travel = Σ lever_i |Δq_i| along the whole edge, and two bodies approach at most twice
    /// as fast as one point moves, so from a check at distance d the next check may wait
    /// until the points have moved (d - clearance) / 2: the edge keeps the clearance between
    /// checks, and every check asks for clearance + resolution, so checks are never closer
    /// than half the resolution of arm motion.
    fn edge_free(&mut self, a: &JointVector, b: &JointVector) -> bool {
        let travel = self.levers.dot(&(b - a).abs());
        let (clearance, needed) =
            (self.options.clearance, self.options.clearance + self.options.resolution);
        let mut tau: Real = 0.0;
        loop {
            let d = self.clearance_at(&(a + (b - a) * tau));
            if d < needed {
                return false;
            }
            if tau >= 1.0 || travel == 0.0 {
                return true;
            }
            tau = (tau + 0.5 * (d - clearance) / travel).min(1.0);
        }
    }

    fn stats(&self, samples: usize, nodes: usize, started: Instant) -> RrtStats {
        RrtStats {
            samples,
            nodes,
            collision_checks: self.checks,
            time: started.elapsed().as_secs_f64(),
        }
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

enum Extension {
    Reached(usize),
    Advanced(usize),
    Trapped,
}

impl Tree {
    fn new(root: JointVector, goal: Option<usize>) -> Self {
        Self { nodes: vec![Node { q: root, parent: None, goal }] }
    }

    fn nearest(&self, q: &JointVector) -> usize {
        let mut best = (0, Real::INFINITY);
        for (i, n) in self.nodes.iter().enumerate() {
            let d = (n.q - q).norm_squared();
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    /// One step from the nearest node towards `target`.
    fn step(&mut self, target: &JointVector, space: &mut Space) -> Extension {
        let near = self.nearest(target);
        let from = self.nodes[near].q;
        let delta = target - from;
        let distance = delta.norm();
        let (to, reached) = if distance <= space.options.step {
            (*target, true)
        } else {
            (from + delta * (space.options.step / distance), false)
        };
        if !space.edge_free(&from, &to) {
            return Extension::Trapped;
        }
        self.nodes.push(Node { q: to, parent: Some(near), goal: None });
        let new = self.nodes.len() - 1;
        if reached { Extension::Reached(new) } else { Extension::Advanced(new) }
    }

    fn extend(&mut self, target: &JointVector, space: &mut Space) -> Option<usize> {
        match self.step(target, space) {
            Extension::Reached(i) | Extension::Advanced(i) => Some(i),
            Extension::Trapped => None,
        }
    }

    /// Steps towards `target` until it is reached (its node) or blocked.
    fn connect(&mut self, target: &JointVector, space: &mut Space) -> Option<usize> {
        loop {
            match self.step(target, space) {
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

/// Random shortcuts: two points on the path joined straight when the edge is free.
fn shortcut(
    mut path: Vec<JointVector>,
    space: &mut Space,
    rng: &mut StdRng,
    attempts: usize,
) -> Vec<JointVector> {
    for _ in 0..attempts {
        if path.len() < 3 {
            break;
        }
        let i = rng.random_range(0..path.len() - 2);
        let j = rng.random_range(i + 2..path.len());
        if space.edge_free(&path[i], &path[j]) {
            path.drain(i + 1..j);
        }
    }
    path
}

/// A path timed with the bell profile (paper eq. 9) along its joint-space arc length.
#[derive(Debug, Clone, PartialEq)]
pub struct TimedPath {
    /// Samples at the rate asked for, plus the end.
    pub trajectory: Trajectory,
    /// The duration used (s).
    pub duration: Real,
    /// Whether the duration asked for was stretched to keep every joint within its speed
    /// limit.
    pub stretched: bool,
}

/// Times `waypoints` with a bell-shaped speed along the path's arc length s: ṡ peaks at 2L/T
/// mid-way and is zero at both ends. Joint i moves at u_i ṡ on an edge of unit direction u,
/// so T is stretched to 2L max |u_i| / v_i when `duration` would exceed a speed limit.
///
/// # Errors
/// [`TrajectoryError`] for fewer than one waypoint, a non-positive rate or duration, or
/// non-finite values.
pub fn time_parameterise(
    robot: &Robot,
    waypoints: &[JointVector],
    duration: Real,
    rate: Real,
) -> Result<TimedPath, TrajectoryError> {
    let first = *waypoints.first().ok_or(TrajectoryError::Empty)?;
    if !(rate.is_finite() && rate > 0.0) {
        return Err(TrajectoryError::InvalidRate { rate_hz: rate });
    }
    let edges: Vec<(JointVector, Real)> = waypoints
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| d.norm() > 0.0)
        .map(|d| (d / d.norm(), d.norm()))
        .collect();
    let length: Real = edges.iter().map(|(_, l)| l).sum();
    let speed = robot.velocity_limits();
    let needed = edges
        .iter()
        .flat_map(|(u, _)| (0..u.len()).map(move |i| 2.0 * length * u[i].abs() / speed[i]))
        .fold(0.0, Real::max);
    let stretched = needed > duration;
    let duration = duration.max(needed);
    let bell = BellProfile::new(duration, length).map_err(TrajectoryError::Join)?;
    let at = |t: Real| -> JointSample {
        let (mut s, rate) = (bell.progress(t), bell.speed(t));
        let mut q = first;
        for (u, l) in &edges {
            if s <= *l {
                return (q + u * s, u * rate);
            }
            q += u * *l;
            s -= l;
        }
        (q, JointVector::zeros())
    };
    let trajectory = Trajectory::from_fn(sample_times(0.0, duration, rate), at)?;
    Ok(TimedPath { trajectory, duration, stretched })
}

/// The length of a joint-space path (rad, Euclidean per edge).
pub fn path_length(waypoints: &[JointVector]) -> Real {
    waypoints.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}
