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

/// How the trees grow, besides the space: the dynamic domain of each node and the balance
/// between the two trees (the settings VAMP's RRTC and OMPL's dynamic-domain RRT use).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Growth {
    /// Each node's sampling domain: `None` for the plain RRT-Connect.
    pub domain: Option<DynamicDomain>,
    /// Grow the smaller tree while the other has at least twice its nodes, instead of
    /// strictly taking turns.
    pub balance: bool,
}

impl Growth {
    /// RRT-Connect as in the paper: every sample taken, the trees taking turns.
    pub(crate) const PLAIN: Self = Self { domain: None, balance: false };
}

/// The dynamic domain (Yershova et al., ICRA 2005): a sample farther from its nearest node
/// than the node's radius is passed over, so that nodes next to obstacles (whose extensions
/// fail) draw only the samples near them, where a way round is likelier. A node's radius is
/// unbounded until an extension from it fails, then `radius`, shrunk by `alpha` at each
/// further failure (to no less than `min_radius`) and grown by it at each success (rad).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DynamicDomain {
    /// A node's radius after its first failed extension (rad).
    pub radius: Real,
    /// The relative change of a bounded radius at each extension.
    pub alpha: Real,
    /// The smallest radius (rad).
    pub min_radius: Real,
}

impl Default for DynamicDomain {
    /// VAMP's RRTC settings: 4 rad, 1e-4, 1 rad.
    fn default() -> Self {
        Self { radius: 4.0, alpha: 1e-4, min_radius: 1.0 }
    }
}

impl DynamicDomain {
    /// The radius of a node whose extension failed.
    fn failed(&self, radius: Real) -> Real {
        if radius.is_finite() {
            (radius * (1.0 - self.alpha)).max(self.min_radius)
        } else {
            self.radius
        }
    }

    /// The radius of a node whose extension succeeded.
    fn succeeded(&self, radius: Real) -> Real {
        if radius.is_finite() { radius * (1.0 + self.alpha) } else { radius }
    }
}

/// A tree: nodes and each one's parent (`None` for a root; a goal tree may have several), and
/// each one's dynamic-domain radius (∞ until an extension from it fails).
pub(crate) struct Tree<N> {
    nodes: Vec<N>,
    parents: Vec<Option<usize>>,
    radii: Vec<Real>,
}

impl<N: Clone> Tree<N> {
    /// A tree of the given roots.
    pub(crate) fn of_roots(roots: impl IntoIterator<Item = N>) -> Self {
        let nodes: Vec<N> = roots.into_iter().collect();
        let parents = vec![None; nodes.len()];
        let radii = vec![Real::INFINITY; nodes.len()];
        Self { nodes, parents, radii }
    }

    fn add(&mut self, node: N, parent: usize) -> usize {
        self.nodes.push(node);
        self.parents.push(Some(parent));
        self.radii.push(Real::INFINITY);
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

/// The index of the configuration nearest to `q` (Euclidean in joint space) and its squared
/// distance; (0, ∞) for none.
pub(crate) fn nearest<'a>(
    configurations: impl Iterator<Item = &'a JointVector>,
    q: &JointVector,
) -> (usize, Real) {
    let mut best = (0, Real::INFINITY);
    for (i, c) in configurations.enumerate() {
        let d = (c - q).norm_squared();
        if d < best.1 {
            best = (i, d);
        }
    }
    best
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

fn nearest_node<S: TreeSpace>(tree: &Tree<S::Node>, target: &S::Target) -> (usize, Real) {
    nearest(tree.nodes.iter().map(S::joints), S::target_joints(target))
}

/// What a sample did to a tree.
enum Grown {
    /// Outside the dynamic domain of its nearest node: no step tried.
    PassedOver,
    /// The step towards it was blocked.
    Trapped,
    /// The new node.
    New(usize),
}

/// One step from the nearest node towards a sample. With a dynamic domain, a sample outside
/// the nearest node's is passed over, and the node's radius follows the step's outcome.
fn extend<S: TreeSpace>(
    space: &mut S,
    tree: &mut Tree<S::Node>,
    target: &S::Target,
    domain: Option<&DynamicDomain>,
) -> Grown {
    let (near, squared) = nearest_node::<S>(tree, target);
    let radius = tree.radii[near];
    if domain.is_some() && squared > radius * radius {
        return Grown::PassedOver;
    }
    let extension = step(space, tree, near, target, true);
    if let Some(domain) = domain {
        tree.radii[near] = match extension {
            Extension::Trapped => domain.failed(radius),
            _ => domain.succeeded(radius),
        };
    }
    match extension {
        Extension::Reached(i) | Extension::Advanced(i) => Grown::New(i),
        Extension::Trapped => Grown::Trapped,
    }
}

/// Draws per sample of the budget at most: samples a dynamic domain passes over do not count
/// against the budget (they cost no collision check), but their number is bounded too, so that
/// a search whose domains have all shrunk still ends.
const DRAWS_PER_SAMPLE: usize = 64;

/// Steps from the nearest node towards a node of the other tree until it is reached and met
/// (the node reached) or a step is blocked.
fn connect<S: TreeSpace>(
    space: &mut S,
    tree: &mut Tree<S::Node>,
    target: &S::Target,
) -> Option<usize> {
    let (mut from, _) = nearest_node::<S>(tree, target);
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
    /// Samples tried (those a dynamic domain passed over not counted).
    pub samples: usize,
    /// Nodes in both trees.
    pub nodes: usize,
}

/// RRT-Connect from the trees `from_start` and `from_goal` (non-empty): at most
/// `max_samples` samples tried (and [`DRAWS_PER_SAMPLE`] times that drawn), the trees swapping
/// roles after each (the smaller one growing while
/// the other has at least twice its nodes, with [`Growth::balance`]), reporting the share of
/// the budget used to `monitor` and stopping at its deadline.
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
    growth: Growth,
    monitor: &mut Monitor,
) -> Result<Connected<S::Node>, RrtError> {
    let (mut samples, mut draws) = (0, 0);
    let most_draws = max_samples.saturating_mul(DRAWS_PER_SAMPLE);
    let mut swapped = false;
    while samples < max_samples && draws < most_draws {
        if draws % REPORT_EVERY == 0 {
            if monitor.expired() {
                let nodes = from_start.nodes.len() + from_goal.nodes.len();
                return Err(RrtError::Timeout { stats: space.stats(samples, nodes) });
            }
            monitor.report(samples as Real / max_samples as Real);
        }
        draws += 1;
        samples += 1;
        let Some(sample) = space.sample(rng) else { continue };
        let (grow, other) = if swapped {
            (&mut from_goal, &mut from_start)
        } else {
            (&mut from_start, &mut from_goal)
        };
        let grown = extend(space, grow, &sample, growth.domain.as_ref());
        if let Grown::PassedOver = grown {
            samples -= 1;
        }
        if let Grown::New(new) = grown {
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
        // Balanced: the tree that just grew keeps growing while the other has at least
        // twice its nodes.
        let (grown, waiting) = (grow.nodes.len(), other.nodes.len());
        if !(growth.balance && waiting >= 2 * grown) {
            swapped = !swapped;
        }
    }
    let closest =
        closest_pair(from_start.nodes.iter().map(S::joints), from_goal.nodes.iter().map(S::joints));
    let nodes = from_start.nodes.len() + from_goal.nodes.len();
    Err(RrtError::NoPath { closest, stats: space.stats(samples, nodes) })
}
