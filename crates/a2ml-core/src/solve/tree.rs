//! The RRT-Connect tree loop both RRTs share (paper §5.3.2): two trees, one from the start and
//! one from the goals, take turns extending towards a random sample and connecting the other
//! tree to the new node; the first connection is the path.
//!
//! What a node is, how a sample is drawn and how an edge is steered and checked belong to the
//! space ([`TreeSpace`]): joint space for goal segments ([`super::rrt`]), the segment's chart
//! for segments with a path ([`super::constrained_rrt`]). Nearest neighbours are found in
//! joint space in both, which tells IK branches of one chart point apart. Seeded and decided
//! by the sample budget; the monitor's deadline is the user's option.

use rand::rngs::StdRng;

use super::monitor::Monitor;
use super::rrt::{RrtError, RrtStats};
use crate::math::{JointVector, Real};

/// Samples between two progress reports and deadline checks.
pub(crate) const REPORT_EVERY: usize = 64;

/// A space the trees grow in.
pub(crate) trait TreeSpace {
    /// A node of a tree: a configuration and what the space keeps with it.
    type Node: Clone;
    /// What a tree grows towards: a sample, or a node of the other tree.
    type Target;

    /// A random target; `None` when the draw gives none (the sample still counts).
    fn sample(&mut self, rng: &mut StdRng) -> Option<Self::Target>;

    /// A node as a target for the other tree.
    fn target(&self, node: &Self::Node) -> Self::Target;

    /// The node's configuration.
    fn joints(node: &Self::Node) -> &JointVector;

    /// The configuration nearest neighbours are measured to.
    fn target_joints(target: &Self::Target) -> &JointVector;

    /// The node one step from `from` towards `target`, and whether it is the target itself;
    /// `None` when the step is blocked. `new_target`: the target is a fresh sample rather
    /// than a node of the other tree.
    fn steer(
        &mut self,
        from: &Self::Node,
        target: &Self::Target,
        new_target: bool,
    ) -> Option<(Self::Node, bool)>;

    /// Whether `arrival`, steered all the way to a node of the other tree, meets it (the same
    /// IK branch, say).
    fn meets(&mut self, arrival: &Self::Node, target: &Self::Target) -> bool {
        let _ = (arrival, target);
        true
    }

    /// The search's counters after `samples` samples with `nodes` nodes in the trees.
    fn stats(&self, samples: usize, nodes: usize) -> RrtStats;
}

/// A tree: nodes and each one's parent (`None` for a root; a goal tree may have several).
pub(crate) struct Tree<N> {
    nodes: Vec<N>,
    parents: Vec<Option<usize>>,
}

impl<N: Clone> Tree<N> {
    /// A tree of the given roots.
    pub(crate) fn of_roots(roots: impl IntoIterator<Item = N>) -> Self {
        let nodes: Vec<N> = roots.into_iter().collect();
        let parents = vec![None; nodes.len()];
        Self { nodes, parents }
    }

    fn add(&mut self, node: N, parent: usize) -> usize {
        self.nodes.push(node);
        self.parents.push(Some(parent));
        self.nodes.len() - 1
    }

    /// The nodes from `i` up to its root.
    fn path_to_root(&self, mut i: usize) -> Vec<N> {
        let mut out = vec![self.nodes[i].clone()];
        while let Some(p) = self.parents[i] {
            out.push(self.nodes[p].clone());
            i = p;
        }
        out
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

/// The joint-space distance between the closest configurations of two trees (rad).
fn closest_pair<'a>(
    a: impl Iterator<Item = &'a JointVector>,
    b: impl Iterator<Item = &'a JointVector> + Clone,
) -> Real {
    a.flat_map(|p| b.clone().map(move |q| (p - q).norm())).fold(Real::INFINITY, Real::min)
}

/// The outcome of one step of a tree towards a target.
enum Extension {
    /// The target was reached: the new node.
    Reached(usize),
    /// A step towards it was taken: the new node.
    Advanced(usize),
    /// The step was blocked.
    Trapped,
}

fn step<S: TreeSpace>(
    space: &mut S,
    tree: &mut Tree<S::Node>,
    near: usize,
    target: &S::Target,
    new_target: bool,
) -> Extension {
    match space.steer(&tree.nodes[near], target, new_target) {
        None => Extension::Trapped,
        Some((node, reached)) => {
            let new = tree.add(node, near);
            if reached { Extension::Reached(new) } else { Extension::Advanced(new) }
        }
    }
}

fn nearest_node<S: TreeSpace>(tree: &Tree<S::Node>, target: &S::Target) -> usize {
    nearest(tree.nodes.iter().map(S::joints), S::target_joints(target))
}

/// One step from the nearest node towards a sample: the new node, if any.
fn extend<S: TreeSpace>(
    space: &mut S,
    tree: &mut Tree<S::Node>,
    target: &S::Target,
) -> Option<usize> {
    let near = nearest_node::<S>(tree, target);
    match step(space, tree, near, target, true) {
        Extension::Reached(i) | Extension::Advanced(i) => Some(i),
        Extension::Trapped => None,
    }
}

/// Steps from the nearest node towards a node of the other tree until it is reached and met
/// (the node reached) or a step is blocked.
fn connect<S: TreeSpace>(
    space: &mut S,
    tree: &mut Tree<S::Node>,
    target: &S::Target,
) -> Option<usize> {
    let mut from = nearest_node::<S>(tree, target);
    loop {
        match step(space, tree, from, target, false) {
            Extension::Reached(i) => return space.meets(&tree.nodes[i], target).then_some(i),
            Extension::Advanced(i) => from = i,
            Extension::Trapped => return None,
        }
    }
}

/// Two trees connected.
pub(crate) struct Connected<N> {
    /// The nodes from the start's root to a goal root; both trees' nodes at the meeting point
    /// stay (they may differ by a self-motion).
    pub path: Vec<N>,
    /// Samples drawn.
    pub samples: usize,
    /// Nodes in both trees.
    pub nodes: usize,
}

/// RRT-Connect from the trees `from_start` and `from_goal` (non-empty): at most
/// `max_samples` samples, the trees swapping roles after each, reporting the share of the
/// budget used to `monitor` and stopping at its deadline.
///
/// # Errors
/// [`RrtError::Timeout`] when the deadline passes, [`RrtError::NoPath`] when the budget is
/// used up.
pub(crate) fn connect_trees<S: TreeSpace>(
    space: &mut S,
    mut from_start: Tree<S::Node>,
    mut from_goal: Tree<S::Node>,
    rng: &mut StdRng,
    max_samples: usize,
    monitor: &mut Monitor,
) -> Result<Connected<S::Node>, RrtError> {
    let mut samples = 0;
    let mut swapped = false;
    while samples < max_samples {
        if samples % REPORT_EVERY == 0 {
            if monitor.expired() {
                let nodes = from_start.nodes.len() + from_goal.nodes.len();
                return Err(RrtError::Timeout { stats: space.stats(samples, nodes) });
            }
            monitor.report(samples as Real / max_samples as Real);
        }
        samples += 1;
        let Some(sample) = space.sample(rng) else { continue };
        let (grow, other) = if swapped {
            (&mut from_goal, &mut from_start)
        } else {
            (&mut from_start, &mut from_goal)
        };
        if let Some(new) = extend(space, grow, &sample) {
            let target = space.target(&grow.nodes[new]);
            if let Some(reached) = connect(space, other, &target) {
                let (s, g) = if swapped { (reached, new) } else { (new, reached) };
                let (s_tree, g_tree) = if swapped { (&*other, &*grow) } else { (&*grow, &*other) };
                let mut path = s_tree.path_to_root(s);
                path.reverse();
                path.extend(g_tree.path_to_root(g));
                let nodes = from_start.nodes.len() + from_goal.nodes.len();
                return Ok(Connected { path, samples, nodes });
            }
        }
        swapped = !swapped;
    }
    let closest =
        closest_pair(from_start.nodes.iter().map(S::joints), from_goal.nodes.iter().map(S::joints));
    let nodes = from_start.nodes.len() + from_goal.nodes.len();
    Err(RrtError::NoPath { closest, stats: space.stats(samples, nodes) })
}
