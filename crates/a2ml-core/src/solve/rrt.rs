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

use std::collections::VecDeque;
use std::time::Instant;

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use super::monitor::Monitor;
pub use super::timing::{LIMIT_FRACTION, TimedPath, shortest_bell, time_parameterise};
pub use super::tree::DynamicDomain;
use super::tree::{Growth, Tree, TreeSpace, connect_trees};
use crate::collision::{
    CollisionModel, CollisionScene, Inflation, Pairs, advancement_within, clearance, coverage,
    min_distance, motion_bound, self_motion_bound,
};
use crate::kinematics::arm_pose;
use crate::math::{JointVector, Real};
use crate::robot::Robot;

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
    /// Spacing of the discrete edge checks (m of arm motion), default 20 cm: an edge is first
    /// checked at points this far apart with every shape inflated by the farthest it moves
    /// over half of it (finer where an inflated shape comes within the clearance), which
    /// proves a free edge free or finds a configuration of a blocked one within the
    /// clearance; an edge they leave open is covered at [`RrtOptions::resolution`] instead.
    /// The self pairs are checked apart from the obstacles, once those leave the edge free,
    /// at twice this spacing in their relative motion.
    pub spacing: Real,
    /// Distance kept from obstacles and between non-adjacent links (m), default 0.01.
    pub clearance: Real,
    /// Samples before giving up, default 20,000: what decides that a search failed.
    pub max_samples: usize,
    /// Wall time before giving up (s), default none: a limit the user sets, which makes the
    /// outcome depend on the machine's speed.
    pub max_time: Option<Real>,
    /// Shortcut attempts on the found path, default 200.
    pub shortcuts: usize,
    /// Each node's sampling domain in joint space ([`DynamicDomain`], VAMP's settings by
    /// default); `None` takes every sample, as the plain RRT-Connect does.
    pub dynamic_domain: Option<DynamicDomain>,
    /// Grow the smaller tree while the other has at least twice its nodes, default true;
    /// false: the trees take turns.
    pub balance: bool,
}

impl Default for RrtOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            step: 2.0,
            resolution: 0.005,
            spacing: 0.2,
            clearance: 0.01,
            max_samples: 20_000,
            max_time: None,
            shortcuts: 200,
            dynamic_domain: Some(DynamicDomain::default()),
            balance: true,
        }
    }
}

/// Counters of one search.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct RrtStats {
    /// Random samples drawn.
    pub samples: usize,
    /// Nodes in both trees at the end.
    pub nodes: usize,
    /// Configurations checked for collision.
    pub collision_checks: usize,
    /// Wall time (s); not serialised (it reads back as 0), so that plan files reproduce byte
    /// for byte.
    #[serde(skip)]
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

/// [`rrt_connect`] with the arm's half of the collision model prepared once: `arm` is any
/// [`CollisionModel`] of `robot` (its scene is not used), so that many problems of one robot
/// do not each build its self pairs and their floors again. The same path as [`rrt_connect`].
///
/// # Errors
/// As [`rrt_connect`]; [`RrtError::InvalidOptions`] when `arm` was not prepared for `robot`.
pub fn rrt_connect_with(
    arm: &CollisionModel,
    robot: &Robot,
    scene: &CollisionScene,
    start: &JointVector,
    goals: &[JointVector],
    options: &RrtOptions,
) -> Result<RrtPath, RrtError> {
    check_options(options)?;
    if !arm.fits(robot) {
        return Err(RrtError::InvalidOptions {
            reason: "the collision model was prepared for another robot",
        });
    }
    let model = arm.with_scene(scene);
    search(model, robot, scene, start, goals, options, &mut Monitor::silent())
}

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
    search(CollisionModel::new(robot, scene), robot, scene, start, goals, options, monitor)
}

/// The search of [`rrt_connect_monitored`] with `model` prepared for `robot` and `scene`.
fn search(
    model: CollisionModel,
    robot: &Robot,
    scene: &CollisionScene,
    start: &JointVector,
    goals: &[JointVector],
    options: &RrtOptions,
    monitor: &mut Monitor,
) -> Result<RrtPath, RrtError> {
    let mut monitor = monitor.within(options.max_time);
    let mut space = JointSpace::new(robot, scene, options, model);
    if let Some(reason) = space.invalid(start) {
        return Err(RrtError::InvalidStart { reason });
    }
    let valid_goals: Vec<(usize, JointVector)> =
        goals.iter().copied().enumerate().filter(|(_, g)| space.invalid(g).is_none()).collect();
    if valid_goals.is_empty() {
        return Err(RrtError::NoValidGoal { count: goals.len() });
    }
    // An edge straight from the start to a goal needs no tree.
    for &(index, g) in &valid_goals {
        if space.edge_free(start, &g, false) {
            let stats = space.stats(1, 0);
            return Ok(RrtPath { waypoints: vec![*start, g], goal: index, stats });
        }
    }
    let from_start = Tree::of_roots([Node { q: *start, goal: None }]);
    let from_goal =
        Tree::of_roots(valid_goals.iter().map(|&(index, q)| Node { q, goal: Some(index) }));
    let mut rng = StdRng::seed_from_u64(options.seed);
    let connected = connect_trees(
        &mut space,
        from_start,
        from_goal,
        &mut rng,
        options.max_samples,
        Growth { domain: options.dynamic_domain, balance: options.balance },
        &mut monitor,
    )?;
    let goal = connected.path.last().and_then(|n| n.goal).unwrap_or(0);
    let waypoints = connected.path.into_iter().map(|n| n.q).collect();
    let waypoints = shortcut(waypoints, &mut space, &mut rng, options.shortcuts);
    Ok(RrtPath { waypoints, goal, stats: space.stats(connected.samples, connected.nodes) })
}

pub(crate) fn check_options(o: &RrtOptions) -> Result<(), RrtError> {
    let positive = |x: Real| x.is_finite() && x > 0.0;
    let checks = [
        (positive(o.step), "the step must be positive"),
        (positive(o.resolution), "the resolution must be positive"),
        (positive(o.spacing), "the check spacing must be positive"),
        (o.clearance.is_finite() && o.clearance >= 0.0, "negative clearance"),
        (o.max_samples > 0, "no samples allowed"),
        (o.max_time.is_none_or(positive), "the time limit must be positive"),
        (
            o.dynamic_domain.is_none_or(|d| {
                positive(d.radius)
                    && positive(d.min_radius)
                    && d.min_radius <= d.radius
                    && (0.0..1.0).contains(&d.alpha)
            }),
            "the dynamic domain needs radii with 0 < min_radius <= radius and 0 <= alpha < 1",
        ),
    ];
    match checks.iter().find(|(ok, _)| !ok) {
        Some((_, reason)) => Err(RrtError::InvalidOptions { reason }),
        None => Ok(()),
    }
}

/// The configuration space: limits, collision checks and their count.
struct JointSpace<'a> {
    robot: &'a Robot,
    scene: &'a CollisionScene,
    options: &'a RrtOptions,
    model: CollisionModel,
    /// Uncovered stretches of the edge being checked (reused, to allocate once).
    gaps: Vec<Gap>,
    /// The shapes' inflation for the discrete checks of the edge being checked, scaled to
    /// each check's stretch ([`Inflation::set_share`]; reused, to allocate once).
    inflation: Inflation,
    /// Stretches (first, last check point) of the discrete checks still to split, and the
    /// checks of what a check left uncovered (parameter, half-width, depth) still to make
    /// (reused).
    stretches: VecDeque<(usize, usize)>,
    rests: VecDeque<(Real, Real, usize)>,
    checks: usize,
    /// When the search started, for its wall time.
    started: Instant,
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

impl<'a> JointSpace<'a> {
    fn new(
        robot: &'a Robot,
        scene: &'a CollisionScene,
        options: &'a RrtOptions,
        model: CollisionModel,
    ) -> Self {
        let started = Instant::now();
        Self {
            robot,
            scene,
            options,
            inflation: Inflation::none(&model),
            model,
            gaps: Vec::new(),
            stretches: VecDeque::new(),
            rests: VecDeque::new(),
            checks: 0,
            started,
        }
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

    /// How far (in units of `dq`, up to `enough`) the arm at `q` may move along `dq`, either
    /// way, keeping the clearance, if at least `least`.
    fn advancement(
        &mut self,
        q: &JointVector,
        dq: &JointVector,
        least: Real,
        enough: Real,
    ) -> Option<Real> {
        self.checks += 1;
        advancement_within(&self.model, q, dq, self.options.clearance, least, enough)
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
    ///
    /// The discrete checks of [`JointSpace::discrete_edge`] decide most edges; only those they
    /// leave open are covered this way.
    fn edge_free(&mut self, a: &JointVector, b: &JointVector, new: bool) -> bool {
        let dq = b - a;
        let travel = motion_bound(&self.model, &dq);
        if travel == 0.0 {
            return true;
        }
        // The obstacles first (they block most edges), then the self pairs over their own
        // relative motion, which is smaller, and [`SELF_SPACING`] apart in it: fewer checks.
        let discrete = match self.discrete_edge(a, b, &dq, travel, Pairs::Obstacles) {
            Some(true) => match self_motion_bound(&self.model, &dq) {
                0.0 => Some(true),
                travel => self.discrete_edge(a, b, &dq, travel, Pairs::SelfPairs),
            },
            decided => decided,
        };
        if let Some(free) = discrete {
            return free;
        }
        // Half the resolution of arm motion, in units of the edge.
        let floor = 0.5 * self.options.resolution / travel;
        let Some(at_b) = self.advancement(b, &dq, if new { floor } else { 0.0 }, 1.0) else {
            return false;
        };
        let Some(at_a) = self.advancement(a, &dq, 0.0, 1.0) else {
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
            let Some(covered) = self.advancement(&(a + dq * middle), &dq, half.min(splits), half)
            else {
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
}

impl JointSpace<'_> {
    /// Whether `pairs` keep the clearance along the edge a -> b (motion `dq`, no shape of them
    /// moving farther than `travel`: relative to the other, for a self pair), from discrete
    /// checks; `None` when they do not tell.
    ///
    /// A check at the edge's parameter t with every shape inflated by the farthest it moves
    /// over h units of `dq` ([`Inflation::along`]: a capsule's levers times h|dq|, a self pair's
    /// relative motion likewise) covers [t − h, t + h]: a distance between two sets changes by
    /// no more than the farthest a point of either moves, so where the inflated shapes keep the
    /// clearance at t, the shapes themselves keep it over that stretch. The edge is first
    /// checked at n + 1 evenly spaced points, n = ⌈travel / spacing⌉, each covering 1/(2n)
    /// either way (no point of the arm moves farther than spacing/2 over it), which together
    /// cover the edge. A point whose shapes keep the clearance under only a share c of their
    /// inflation ([`coverage`]) covers [t − ch, t + ch], and what is left either side is
    /// checked at its middle with the inflation over its half-width, down to [`REFINEMENTS`]
    /// levels; a point that does not keep the clearance even uninflated is a configuration of
    /// the edge within it, and the edge is blocked. So `Some(true)` only when the checks cover
    /// the whole edge.
    ///
    /// The points between are checked first, in bisection order (the middle first: on the
    /// MotionBenchMaker scenes a blocked edge is more often blocked there than at its new end;
    /// in the cage, of the blocked edges, 29 % were found at b and 50 % at the middle checked
    /// after it), then the new end b, then a (where the edge leaves the tree: clear itself, so
    /// only what its check covers is in question), and the rests last, so that a blocked
    /// edge is found after few checks.
    fn discrete_edge(
        &mut self,
        a: &JointVector,
        b: &JointVector,
        dq: &JointVector,
        travel: Real,
        pairs: Pairs,
    ) -> Option<bool> {
        let spacing = match pairs {
            Pairs::SelfPairs => SELF_SPACING * self.options.spacing,
            Pairs::All | Pairs::Obstacles => self.options.spacing,
        };
        let n = (travel / spacing).ceil().max(1.0);
        let half = 0.5 / n;
        let n = n as usize;
        self.inflation.set_along_of(&self.model, dq, half, pairs);
        self.stretches.clear();
        self.stretches.push_back((0, n));
        self.rests.clear();
        let (mut end_b, mut end_a) = (true, true);
        loop {
            let (t, h, level) = if let Some((first, last)) = self.stretches.pop_front() {
                if last - first < 2 {
                    continue;
                }
                let middle = first + (last - first) / 2;
                self.stretches.push_back((first, middle));
                self.stretches.push_back((middle, last));
                (middle as Real / n as Real, half, 0)
            } else if std::mem::take(&mut end_b) {
                (1.0, half, 0)
            } else if std::mem::take(&mut end_a) {
                (0.0, half, 0)
            } else if let Some(rest) = self.rests.pop_front() {
                rest
            } else {
                return Some(true);
            };
            self.inflation.set_share(h / half);
            let q = if t == 1.0 { *b } else { a + dq * t };
            // One pass tells both how much of [t − h, t + h] the shapes keep the clearance
            // over and, where not all of it, whether they keep it at t.
            self.checks += 1;
            let covered =
                match coverage(&self.model, &q, self.options.clearance, &self.inflation, pairs) {
                    None => return Some(false),
                    Some(share) if share >= 1.0 => continue,
                    Some(share) => share * h,
                };
            if level == REFINEMENTS {
                return None;
            }
            // What is left of [t − h, t + h] either side of [t − covered, t + covered], by
            // the middle of each; at an end, the one outside the edge is not.
            let rest = 0.5 * (h - covered);
            for t in [t - covered - rest, t + covered + rest] {
                if (0.0..=1.0).contains(&t) {
                    self.rests.push_back((t, rest, level + 1));
                }
            }
        }
    }
}

/// The discrete checks of the self pairs are this many times [`RrtOptions::spacing`] apart in
/// the pairs' relative motion: the pairs are seldom near (on the MotionBenchMaker scenes, fewer
/// checks in all than at the obstacles' spacing, or at four times it).
const SELF_SPACING: Real = 2.0;

/// How many levels deep the rests of the discrete checks' stretches are checked where the
/// inflated shapes come within the clearance, before the edge is left to the covering checks
/// (on the MotionBenchMaker scenes, 3 levels cost more checks and 10 no fewer).
const REFINEMENTS: usize = 6;

/// A node of a joint-space tree: its configuration, and for a goal tree's root which goal it
/// is.
#[derive(Debug, Clone, Copy)]
struct Node {
    q: JointVector,
    goal: Option<usize>,
}

impl TreeSpace for JointSpace<'_> {
    type Node = Node;
    type Target = JointVector;

    fn sample(&mut self, rng: &mut StdRng) -> Option<JointVector> {
        let (lower, upper) = (self.robot.lower(), self.robot.upper());
        Some(JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i])))
    }

    fn target(&self, node: &Node) -> JointVector {
        node.q
    }

    fn joints(node: &Node) -> &JointVector {
        &node.q
    }

    fn target_joints(target: &JointVector) -> &JointVector {
        target
    }

    /// Straight in joint space by at most [`RrtOptions::step`].
    fn steer(
        &mut self,
        from: &Node,
        target: &JointVector,
        new_target: bool,
    ) -> Option<(Node, bool)> {
        let delta = target - from.q;
        let distance = delta.norm();
        let (to, reached) = if distance <= self.options.step {
            (*target, true)
        } else {
            (from.q + delta * (self.options.step / distance), false)
        };
        self.edge_free(&from.q, &to, new_target || !reached)
            .then_some((Node { q: to, goal: None }, reached))
    }

    fn stats(&self, samples: usize, nodes: usize) -> RrtStats {
        RrtStats::since(self.started, samples, nodes, self.checks)
    }
}

/// Random shortcuts: two waypoints joined straight when the edge is free. A pair found blocked
/// is not checked again until the path changes (the answer would be the same), and the search
/// ends once every pair is.
fn shortcut(
    mut path: Vec<JointVector>,
    space: &mut JointSpace,
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

/// The length of a joint-space path (rad, Euclidean per edge).
pub fn path_length(waypoints: &[JointVector]) -> Real {
    waypoints.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}
