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
//! joints jump by more than `MAX_JUMP`, or move faster than `MAX_GAIN` per unit of chart
//! length (a singularity or another IK branch), ends the edge. Where two IK solutions of one
//! chart point differ by a self-motion at a singularity (the wrist's first and last axes
//! aligned), the path turns the joints between them, which does not move the state. The
//! tests re-check every path densely and independently.

use std::time::Instant;

use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

pub use super::chart::{Chart, ChartPoint};
use super::chart::{MAX_GAIN, MAX_JUMP, MIN_STEP, SAME_BRANCH};
use super::monitor::Monitor;
use super::rrt::{RrtError, RrtOptions, RrtStats};
pub use super::timing::time_constrained;
use super::tree::{Growth, Tree, TreeSpace, connect_trees};
use crate::collision::{CollisionModel, CollisionScene, advancement, clearance, motion_bound};
use crate::math::{JointVector, Real};
use crate::robot::Robot;

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
    if let Some((i, v)) = robot.limit_violation(start, 0.0) {
        let joint = &robot.joints[i].name;
        let reason = format!("outside the limits: joint `{joint}` at {v:.4} rad");
        return Err(RrtError::InvalidStart { reason });
    }
    let mut search = Search::new(robot, scene, chart, options, start)?;
    let start_node = Node { x: chart.start(), q: *start, clearance: search.start_clearance };
    let goal_x = chart.goal();
    // Every IK branch of the goal, the one nearest the start first.
    let goals = chart.ik(robot, &goal_x, start);
    let goal_nodes: Vec<Node> = goals
        .iter()
        .filter_map(|q| search.valid(q).map(|clearance| Node { x: goal_x, q: *q, clearance }))
        .collect();
    if goal_nodes.is_empty() {
        return Err(RrtError::NoValidGoal { count: goals.len() });
    }
    let mut rng = StdRng::seed_from_u64(options.seed);
    // The straight edge in the chart first: the QP's own route, if it is clear.
    for goal in &goal_nodes {
        if let Some(path) = search.join(&start_node, goal) {
            return Ok(search.finish(path, &mut rng, 0, 2));
        }
    }
    let from_start = Tree::of_roots([start_node]);
    let from_goal = Tree::of_roots(goal_nodes);
    let connected = connect_trees(
        &mut search,
        from_start,
        from_goal,
        &mut rng,
        options.max_samples,
        // The chart's own growth as the paper's: its snapshots and figures are of it.
        Growth::PLAIN,
        &mut monitor,
    )?;
    let path = connected.path.iter().map(|n| (n.x, n.q)).collect();
    Ok(search.finish(path, &mut rng, connected.samples, connected.nodes))
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
    /// When the search started, for its wall time.
    started: Instant,
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
            started: Instant::now(),
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
            // The last middle point solved (edge fraction, joints): a step halved lands on it,
            // and the same point from the same joints has the same solution.
            let mut solved: Option<(Real, JointVector)> = None;
            let next = loop {
                let last = trial >= 1.0 - tau;
                let candidate = match solved {
                    Some((at, q_at)) if !last && at == tau + trial => q_at,
                    _ => {
                        let x = if last { *b } else { self.chart.interpolate(a, b, tau + trial) };
                        self.chart.ik_near(self.robot, &x, &q)?
                    }
                };
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
                    let at = tau + 0.5 * trial.min(1.0 - tau);
                    let q_middle =
                        self.chart.ik_near(self.robot, &self.chart.interpolate(a, b, at), &q)?;
                    solved = Some((at, q_middle));
                    let bend = q_middle - (q + candidate) * 0.5;
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
    fn meets_at(&self, arrival: &JointVector, clearance: Real, node: &JointVector) -> bool {
        let delta = node - arrival;
        delta.amax() <= SAME_BRANCH
            && (delta.amax() == 0.0 && clearance >= self.kept
                || advancement(&self.model, arrival, &delta, self.kept) >= 1.0)
    }

    /// The edge from node `from` to node `to` (of the other tree), tracked to the same
    /// branch: the two-point path when it is free.
    fn join(&mut self, from: &Node, to: &Node) -> Option<Vec<(ChartPoint, JointVector)>> {
        let (q, d) = self.track(&from.x, &from.q, &to.x)?;
        self.meets_at(&q, d, &to.q).then(|| vec![(from.x, from.q), (to.x, q), (to.x, to.q)])
    }

    /// Shortcuts the path and packs the result.
    fn finish(
        &mut self,
        mut path: Vec<(ChartPoint, JointVector)>,
        rng: &mut StdRng,
        samples: usize,
        nodes: usize,
    ) -> ConstrainedPath {
        // A pair whose attempt failed, or left the path as it was, is not tracked again until
        // the path changes: tracking is deterministic, so the answer would be the same. The
        // random draws stop once every pair is settled (nothing draws after them).
        let mut settled: Vec<(usize, usize)> = Vec::new();
        // Per edge of `path`, the forward track a shortcut made of it (checked points, arrival,
        // its clearance): the same as tracking it again below.
        let mut recorded: Vec<Option<Track>> = vec![None; path.len().saturating_sub(1)];
        for _ in 0..self.options.shortcuts {
            let n = path.len();
            if n < 3 || settled.len() == (n - 1) * (n - 2) / 2 {
                break;
            }
            let i = rng.random_range(0..n - 2);
            let j = rng.random_range(i + 2..n);
            if settled.contains(&(i, j)) {
                continue;
            }
            let ((xi, qi), (xj, qj)) = (path[i], path[j]);
            let mut track = Vec::new();
            let arrival = self
                .track_recorded(&xi, &qi, &xj, &mut track)
                .filter(|(q, d)| self.meets_at(q, *d, &qj));
            match arrival {
                // The arrival stays, for the self-motion onto qj if there is one.
                Some((q, d)) if !(j == i + 2 && path[i + 1] == (xj, q)) => {
                    path.splice(i + 1..j, [(xj, q)]);
                    recorded.splice(i..j, [Some((track, q, d)), None]);
                    settled.clear();
                }
                _ => settled.push((i, j)),
            }
        }
        // The IK solutions along each edge, as checked: timing follows them, so that it
        // stays on the branch the checks saw. An edge of the goal tree was grown from its
        // far end; it is tracked that way again when it does not track forwards.
        let mut tracks = Vec::with_capacity(path.len().saturating_sub(1));
        for (w, known) in path.windows(2).zip(recorded) {
            let ((a, qa), (b, qb)) = (w[0], w[1]);
            let (mut track, forward) = match known {
                Some((track, q, d)) => (track, Some((q, d))),
                None => {
                    let mut track = Vec::new();
                    let forward = self.track_recorded(&a, &qa, &b, &mut track);
                    (track, forward)
                }
            };
            match forward {
                Some((q, d)) if self.meets_at(&q, d, &qb) => {}
                _ => {
                    track.clear();
                    if let Some((q, d)) = self.track_recorded(&b, &qb, &a, &mut track) {
                        if self.meets_at(&q, d, &qa) {
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
        let stats = RrtStats::since(self.started, samples, nodes, self.checks);
        let (waypoints, configurations) = path.into_iter().unzip();
        ConstrainedPath { waypoints, configurations, tracks, stats }
    }
}

/// An edge's forward track: its checked points (edge fraction, joints), the arrival and the
/// arrival's clearance.
type Track = (Vec<(Real, JointVector)>, JointVector, Real);

/// A node of a chart tree: its chart point, the IK solution tracked there and its clearance.
#[derive(Debug, Clone, Copy)]
struct Node {
    x: ChartPoint,
    q: JointVector,
    clearance: Real,
}

/// The trees grow towards (chart point, joints): a sample and the IK solution nearest the
/// joint-space draw it came from, or a node of the other tree.
impl TreeSpace for Search<'_> {
    type Node = Node;
    type Target = (ChartPoint, JointVector);

    fn sample(&mut self, rng: &mut StdRng) -> Option<(ChartPoint, JointVector)> {
        self.chart.sample(self.robot, rng)
    }

    fn target(&self, node: &Node) -> (ChartPoint, JointVector) {
        (node.x, node.q)
    }

    fn joints(node: &Node) -> &JointVector {
        &node.q
    }

    /// The chart alone cannot tell IK branches apart: two nodes at one chart point on
    /// different branches are far apart in joints, and no edge joins them without a jump.
    fn target_joints(target: &(ChartPoint, JointVector)) -> &JointVector {
        &target.1
    }

    /// At most [`RrtOptions::step`] of chart length, tracked on the branch of `from`.
    fn steer(
        &mut self,
        from: &Node,
        (target, _): &(ChartPoint, JointVector),
        _: bool,
    ) -> Option<(Node, bool)> {
        let distance = self.chart.distance(&from.x, target);
        let reached = distance <= self.options.step;
        let to = if reached {
            *target
        } else {
            self.chart.interpolate(&from.x, target, self.options.step / distance)
        };
        let (q, clearance) = self.track(&from.x, &from.q, &to)?;
        Some((Node { x: to, q, clearance }, reached))
    }

    /// On the same IK branch, or a short self-motion away.
    fn meets(&mut self, arrival: &Node, (_, q): &(ChartPoint, JointVector)) -> bool {
        self.meets_at(&arrival.q, arrival.clearance, q)
    }

    fn stats(&self, samples: usize, nodes: usize) -> RrtStats {
        RrtStats::since(self.started, samples, nodes, self.checks)
    }
}
