//! The task level (paper §5.1): which actions run, in which order.
//!
//! A forward A* search over STRIPS states from `init` to `goal`, with
//! s' = (s − del) ∪ add applicable when pre ⊆ s. States are bitsets over
//! the task's facts. The heuristic ⌈unmet goal facts / k⌉, k the most goal
//! facts one action adds, is consistent, so the plan is a shortest one; the
//! queue orders nodes by f, then by their action sequence, so among the
//! shortest plans the one first in written order wins (lexicographically
//! smallest indices), and the same task always gives the same plan.
//!
//! Each action runs at most once by default. The paper's §5.1 planner may
//! repeat an action, but an A2ML action is one concrete motion (its goals
//! are absolute poses, its names unique) and the task's actions form a set
//! the planner orders; [`StripsOptions::repeat_actions`] lifts the limit.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap, HashSet};

use super::DecomposeError;
use crate::language::Task;

/// Settings of the action planner.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StripsOptions {
    /// Most search nodes generated before giving up with
    /// [`DecomposeError::NodeLimit`]; default 100 000.
    pub max_nodes: usize,
    /// Whether an action may run more than once; default false.
    pub repeat_actions: bool,
}

impl Default for StripsOptions {
    fn default() -> Self {
        Self { max_nodes: 100_000, repeat_actions: false }
    }
}

/// The order in which the task's actions run, as indices into
/// `task.actions`: a STRIPS plan from `init` to `goal` when the task has a
/// goal, else every action in the written order. Default options.
///
/// # Errors
/// See [`order_with`].
pub fn order(task: &Task) -> Result<Vec<usize>, DecomposeError> {
    order_with(task, &StripsOptions::default())
}

/// [`order`] with explicit options. A task with a goal but no `init` starts
/// from no facts; a goal already true in `init` gives an empty plan.
///
/// # Errors
/// [`DecomposeError::UnreachableGoal`] naming the goal facts that no
/// runnable action adds, [`DecomposeError::NoOrdering`] when each goal fact
/// is reachable but no sequence reaches all of them,
/// [`DecomposeError::NodeLimit`] when the search exceeds `max_nodes`.
pub fn order_with(task: &Task, options: &StripsOptions) -> Result<Vec<usize>, DecomposeError> {
    let Some(goal) = &task.goal else {
        return Ok((0..task.actions.len()).collect());
    };
    let init = task.init.as_deref().unwrap_or_default();
    let problem = Problem::new(task, init, goal);

    let reachable = problem.relaxed_reachable();
    let unreachable: Vec<String> = goal
        .iter()
        .filter(|f| !reachable.contains(problem.facts.index[f.as_str()]))
        .cloned()
        .collect();
    if !unreachable.is_empty() {
        return Err(DecomposeError::UnreachableGoal {
            task: task.name.clone(),
            facts: unreachable,
        });
    }
    match problem.search(options) {
        Search::Plan(plan) => Ok(plan),
        Search::Exhausted => Err(DecomposeError::NoOrdering {
            task: task.name.clone(),
            goal: goal.clone(),
            repeat_actions: options.repeat_actions,
        }),
        Search::NodeLimit => {
            Err(DecomposeError::NodeLimit { task: task.name.clone(), limit: options.max_nodes })
        }
    }
}

/// A set of small integers (facts or actions).
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
struct Bits(Vec<u64>);

impl Bits {
    fn empty(len: usize) -> Self {
        Self(vec![0; len.div_ceil(64)])
    }

    fn insert(&mut self, i: usize) {
        self.0[i / 64] |= 1 << (i % 64);
    }

    fn contains(&self, i: usize) -> bool {
        self.0[i / 64] & (1 << (i % 64)) != 0
    }

    fn is_subset(&self, of: &Bits) -> bool {
        self.0.iter().zip(&of.0).all(|(a, b)| a & !b == 0)
    }

    fn union_with(&mut self, other: &Bits) {
        self.0.iter_mut().zip(&other.0).for_each(|(a, b)| *a |= b);
    }

    /// |self ∩ other|.
    fn count_common(&self, other: &Bits) -> usize {
        self.0.iter().zip(&other.0).map(|(a, b)| (a & b).count_ones() as usize).sum()
    }

    /// (self − del) ∪ add.
    fn apply(&self, del: &Bits, add: &Bits) -> Bits {
        Bits(self.0.iter().zip(&del.0).zip(&add.0).map(|((s, d), a)| (s & !d) | a).collect())
    }
}

/// The facts of a task, numbered in order of first mention.
struct Facts<'a> {
    index: HashMap<&'a str, usize>,
}

impl<'a> Facts<'a> {
    fn set(&mut self, names: &'a [String]) -> Vec<usize> {
        names
            .iter()
            .map(|n| {
                let next = self.index.len();
                *self.index.entry(n.as_str()).or_insert(next)
            })
            .collect()
    }
}

struct Step {
    pre: Bits,
    add: Bits,
    del: Bits,
}

struct Problem<'a> {
    facts: Facts<'a>,
    init: Bits,
    goal: Bits,
    steps: Vec<Step>,
}

enum Search {
    Plan(Vec<usize>),
    Exhausted,
    NodeLimit,
}

/// A queue entry; ordered by f, then by the action sequence.
type Entry = Reverse<(usize, Vec<usize>, Bits, Bits)>;

impl<'a> Problem<'a> {
    fn new(task: &'a Task, init: &'a [String], goal: &'a [String]) -> Self {
        let mut facts = Facts { index: HashMap::new() };
        let init = facts.set(init);
        let goal = facts.set(goal);
        let steps: Vec<[Vec<usize>; 3]> = task
            .actions
            .iter()
            .map(|a| [facts.set(&a.pre), facts.set(&a.add), facts.set(&a.del)])
            .collect();
        let n = facts.index.len();
        let bits = |members: &[usize]| {
            let mut b = Bits::empty(n);
            members.iter().for_each(|&i| b.insert(i));
            b
        };
        Problem {
            init: bits(&init),
            goal: bits(&goal),
            steps: steps
                .iter()
                .map(|[pre, add, del]| Step { pre: bits(pre), add: bits(add), del: bits(del) })
                .collect(),
            facts,
        }
    }

    /// Every fact some sequence could make true if nothing were deleted: a
    /// superset of what is reachable, so a goal fact outside it is lost.
    fn relaxed_reachable(&self) -> Bits {
        let mut reached = self.init.clone();
        let mut fired = vec![false; self.steps.len()];
        let mut changed = true;
        while changed {
            changed = false;
            for (step, fired) in self.steps.iter().zip(&mut fired) {
                if !*fired && step.pre.is_subset(&reached) {
                    reached.union_with(&step.add);
                    *fired = true;
                    changed = true;
                }
            }
        }
        reached
    }

    fn search(&self, options: &StripsOptions) -> Search {
        let goal_count = self.goal.count_common(&self.goal);
        // An action makes at most `k` goal facts true, so ⌈unmet / k⌉ more
        // actions are needed at least, and one action lowers the bound by at
        // most one: admissible and consistent.
        let k = self.steps.iter().map(|s| s.add.count_common(&self.goal)).max().unwrap_or(0);
        let h = |facts: &Bits| {
            let unmet = goal_count - facts.count_common(&self.goal);
            if k == 0 { 0 } else { unmet.div_ceil(k) }
        };
        // Without repeats the state is (facts, actions used); with them the
        // used set stays empty.
        let no_actions = Bits::empty(self.steps.len());
        let mut open: BinaryHeap<Entry> = BinaryHeap::new();
        let mut closed: HashSet<(Bits, Bits)> = HashSet::new();
        open.push(Reverse((h(&self.init), Vec::new(), self.init.clone(), no_actions)));
        let mut generated = 1;
        while let Some(Reverse((_, plan, facts, used))) = open.pop() {
            if self.goal.is_subset(&facts) {
                return Search::Plan(plan);
            }
            if !closed.insert((facts.clone(), used.clone())) {
                continue;
            }
            for (i, step) in self.steps.iter().enumerate() {
                if (!options.repeat_actions && used.contains(i)) || !step.pre.is_subset(&facts) {
                    continue;
                }
                let next = facts.apply(&step.del, &step.add);
                let mut next_used = used.clone();
                if !options.repeat_actions {
                    next_used.insert(i);
                }
                let state = (next, next_used);
                if closed.contains(&state) {
                    continue;
                }
                if generated >= options.max_nodes {
                    return Search::NodeLimit;
                }
                generated += 1;
                let mut next_plan = plan.clone();
                next_plan.push(i);
                let f = next_plan.len() + h(&state.0);
                open.push(Reverse((f, next_plan, state.0, state.1)));
            }
        }
        Search::Exhausted
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::language::{Action, ActionBody, ast::Span};

    type Spec<'a> = (&'a str, &'a [&'a str], &'a [&'a str], &'a [&'a str]);

    fn strings(names: &[&str]) -> Vec<String> {
        names.iter().map(|s| (*s).to_owned()).collect()
    }

    /// A task with facts only: actions (name, pre, add, del).
    fn task(init: &[&str], goal: Option<&[&str]>, actions: &[Spec]) -> Task {
        Task {
            name: "t".into(),
            robot: Default::default(),
            robot_base: None,
            robot_tip: None,
            start: None,
            scene: Vec::new(),
            settings: Default::default(),
            init: Some(strings(init)),
            goal: goal.map(strings),
            actions: actions
                .iter()
                .map(|(name, pre, add, del)| Action {
                    name: (*name).into(),
                    description: None,
                    pre: strings(pre),
                    add: strings(add),
                    del: strings(del),
                    contact: Vec::new(),
                    solver: None,
                    segment_solvers: Vec::new(),
                    body: ActionBody::Constraints { goal: None, path: None, duration: None },
                    span: Span::default(),
                })
                .collect(),
        }
    }

    #[test]
    fn without_goal_the_written_order_stands() {
        let t = task(&[], None, &[("b", &["x"], &[], &[]), ("a", &[], &[], &[])]);
        assert_eq!(order(&t), Ok(vec![0, 1]));
    }

    #[test]
    fn a_goal_true_at_the_start_needs_no_action() {
        let t = task(&["done"], Some(&["done"]), &[("a", &[], &["x"], &[])]);
        assert_eq!(order(&t), Ok(vec![]));
    }

    #[test]
    fn the_chain_is_found_whatever_the_written_order() {
        let t = task(
            &["p"],
            Some(&["s"]),
            &[("c", &["r"], &["s"], &[]), ("a", &["p"], &["q"], &[]), ("b", &["q"], &["r"], &[])],
        );
        assert_eq!(order(&t), Ok(vec![1, 2, 0]));
    }

    #[test]
    fn deletes_force_the_order() {
        // `first` written first would lose `a` to `second`.
        let t = task(
            &[],
            Some(&["a", "b"]),
            &[("first", &[], &["a"], &[]), ("second", &[], &["b"], &["a"])],
        );
        assert_eq!(order(&t), Ok(vec![1, 0]));
    }

    #[test]
    fn ties_go_to_the_written_order() {
        let t = task(
            &[],
            Some(&["a", "b"]),
            &[("x", &[], &["b"], &[]), ("y", &[], &["a"], &[]), ("z", &[], &["a", "b"], &[])],
        );
        assert_eq!(order(&t), Ok(vec![2]));
        let t = task(&[], Some(&["a", "b"]), &[("x", &[], &["b"], &[]), ("y", &[], &["a"], &[])]);
        assert_eq!(order(&t), Ok(vec![0, 1]));
    }

    #[test]
    fn a_fact_behind_a_cycle_is_unreachable() {
        let t = task(
            &["outside"],
            Some(&["inside", "outside"]),
            &[
                ("enter", &["door_open"], &["inside"], &["outside"]),
                ("open", &["key"], &["door_open"], &[]),
                ("take_key", &["inside"], &["key"], &[]),
            ],
        );
        assert_eq!(
            order(&t),
            Err(DecomposeError::UnreachableGoal { task: "t".into(), facts: vec!["inside".into()] })
        );
    }

    #[test]
    fn a_fact_no_action_adds_is_unreachable() {
        let t = task(&[], Some(&["nowhere"]), &[]);
        let err = order(&t).expect_err("unreachable");
        assert_eq!(
            err.to_string(),
            "task `t`: goal fact `nowhere` can never become true: it is not in `init`, and no \
             action that can run adds it"
        );
    }

    #[test]
    fn facts_that_undo_each_other_have_no_ordering() {
        let t =
            task(&[], Some(&["a", "b"]), &[("x", &[], &["a"], &["b"]), ("y", &[], &["b"], &["a"])]);
        let err = order(&t).expect_err("no ordering");
        assert!(matches!(err, DecomposeError::NoOrdering { .. }), "{err}");
        assert!(err.to_string().contains("makes facts `a`, `b` true together"), "{err}");
    }

    #[test]
    fn repeats_when_allowed() {
        let t = task(
            &["dirty"],
            Some(&["clean", "spilled"]),
            &[
                ("wipe", &["dirty"], &["clean"], &["dirty"]),
                ("spill", &["clean"], &["dirty", "spilled"], &["clean"]),
            ],
        );
        assert!(matches!(order(&t), Err(DecomposeError::NoOrdering { .. })));
        let options = StripsOptions { repeat_actions: true, ..Default::default() };
        assert_eq!(order_with(&t, &options), Ok(vec![0, 1, 0]));
    }

    #[test]
    fn the_node_limit_is_an_error_naming_it() {
        let names: Vec<String> = (0..12).map(|i| format!("f{i}")).collect();
        let goal: Vec<&str> = names.iter().map(String::as_str).collect();
        let mut actions: Vec<Spec> = Vec::new();
        for name in &goal {
            actions.push(("a", &[], std::slice::from_ref(name), &[]));
        }
        // Twelve independent actions, and one that undoes them all: no plan,
        // and 2^13 states to rule out.
        actions.push(("never", &["f0"], &["g"], &goal));
        let mut goal_facts = goal.clone();
        goal_facts.push("g");
        let t = task(&[], Some(&goal_facts), &actions);
        let options = StripsOptions { max_nodes: 500, ..Default::default() };
        let err = order_with(&t, &options).expect_err("limit");
        assert_eq!(err, DecomposeError::NodeLimit { task: "t".into(), limit: 500 });
        assert!(err.to_string().contains("500 search nodes"), "{err}");
    }

    /// Tiny deterministic generator for the brute-force comparison.
    struct XorShift(u64);

    impl XorShift {
        fn below(&mut self, n: u64) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0 % n
        }

        fn facts(&mut self, universe: &[&'static str], p: u64) -> Vec<&'static str> {
            universe.iter().copied().filter(|_| self.below(100) < p).collect()
        }
    }

    /// Sequences of distinct actions, shortest first, in lexicographic
    /// order: the first valid one is the plan the planner must return.
    fn brute_force(t: &Task) -> Option<Vec<usize>> {
        let goal = t.goal.as_ref()?;
        let holds = |plan: &[usize]| {
            let mut s: Vec<&String> = t.init.iter().flatten().collect();
            for &i in plan {
                let a = &t.actions[i];
                if !a.pre.iter().all(|p| s.contains(&p)) {
                    return false;
                }
                s.retain(|f| !a.del.contains(f));
                s.extend(a.add.iter().filter(|f| !s.contains(f)).collect::<Vec<_>>());
            }
            goal.iter().all(|g| s.contains(&g))
        };
        let n = t.actions.len();
        let mut layer: Vec<Vec<usize>> = vec![Vec::new()];
        for _ in 0..=n {
            if let Some(plan) = layer.iter().find(|p| holds(p)) {
                return Some(plan.clone());
            }
            layer = layer
                .iter()
                .flat_map(|p| {
                    (0..n).filter(|i| !p.contains(i)).map(|i| [p.as_slice(), &[i]].concat())
                })
                .collect();
        }
        None
    }

    #[test]
    fn agrees_with_brute_force_on_random_tasks() {
        const UNIVERSE: [&str; 6] = ["a", "b", "c", "d", "e", "f"];
        let mut rng = XorShift(0x9e37_79b9_7f4a_7c15);
        let mut solved = 0;
        for _ in 0..400 {
            let init = rng.facts(&UNIVERSE, 30);
            let goal = rng.facts(&UNIVERSE, 35);
            let count = 1 + rng.below(5) as usize;
            let specs: Vec<[Vec<&str>; 3]> = (0..count)
                .map(|_| {
                    [rng.facts(&UNIVERSE, 20), rng.facts(&UNIVERSE, 30), rng.facts(&UNIVERSE, 20)]
                })
                .collect();
            let actions: Vec<Spec> = specs
                .iter()
                .map(|[p, a, d]| ("x", p.as_slice(), a.as_slice(), d.as_slice()))
                .collect();
            let t = task(&init, Some(&goal), &actions);
            let expected = brute_force(&t);
            match (order(&t), expected) {
                (Ok(plan), Some(expected)) => {
                    assert_eq!(plan, expected, "{init:?} -> {goal:?} by {specs:?}");
                    solved += 1;
                }
                (Err(_), None) => {}
                (got, expected) => {
                    panic!("{init:?} -> {goal:?} by {specs:?}: {got:?} vs {expected:?}")
                }
            }
        }
        assert!(solved > 100, "only {solved} solvable tasks drawn");
    }
}
