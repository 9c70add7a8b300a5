//! From a validated task to movement segments (docs/design.md §4, paper §5.1-5.2).
//!
//! Entry points: [`order`] (the action sequence: a STRIPS plan from `init`
//! to `goal`, or the written order), [`classify`] (an action's type I-VII
//! from its goal and path constraints), [`segment_pattern`] (1, 2 or 3),
//! and the optimisers [`opt1`] and [`opt2`] that reconcile constraints
//! given in different spaces.
//! Actions are referred to by their index in `Task::actions`.

mod build;
mod classify;
mod opt;
mod strips;

pub use build::{
    DecomposeOptions, Decomposition, FittsLaw, OptReport, PlannedAction, PlannedSegment, decompose,
};
pub use classify::{
    ActionType, Classification, Combination, SegmentPattern, classify, segment_pattern,
};
pub use opt::{
    ArmState, OptError, OptOptions, OptSolution, along_path, goal_error, goal_margin, opt1, opt2,
};
pub use strips::{StripsOptions, order, order_with};

use crate::language::Variable;

/// Why a task cannot be decomposed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DecomposeError {
    /// An arm capsule or an obstacle cannot be checked for collisions.
    #[error(transparent)]
    Shape(#[from] crate::collision::ShapeError),
    /// Some goal facts never become true, whatever the order of the actions.
    #[error(
        "task `{task}`: goal {} can never become true: {} not in `init`, and no action \
         that can run adds {}",
        fact_list(facts),
        if facts.len() == 1 { "it is" } else { "they are" },
        if facts.len() == 1 { "it" } else { "them" }
    )]
    UnreachableGoal {
        /// The task.
        task: String,
        /// The goal facts that stay false, in the goal's order.
        facts: Vec<String>,
    },
    /// Each goal fact can become true, but no sequence makes all of them true at the end.
    #[error(
        "task `{task}`: each goal fact can become true, but no order of the actions makes {} \
         true together{}",
        fact_list(goal),
        if *repeat_actions { "" } else { " (each action runs at most once)" }
    )]
    NoOrdering {
        /// The task.
        task: String,
        /// The task's goal facts.
        goal: Vec<String>,
        /// Whether actions could run more than once ([`StripsOptions::repeat_actions`]).
        repeat_actions: bool,
    },
    /// The planner gave up.
    #[error(
        "task `{task}`: the action planner generated {limit} search nodes without reaching the \
         goal; raise `StripsOptions::max_nodes` or simplify the facts"
    )]
    NodeLimit {
        /// The task.
        task: String,
        /// The limit that was reached ([`StripsOptions::max_nodes`]).
        limit: usize,
    },
    /// The action's goal and path constraints fit no row of the table.
    #[error("action `{action}`: {combination}, which fits none of the seven action types")]
    OutOfTable {
        /// The action.
        action: String,
        /// What it constrains.
        combination: Combination,
    },
    /// The task gives no start configuration.
    #[error("task `{task}` has no `start`: give the joint angles or a start state")]
    NoStart {
        /// The task.
        task: String,
    },
    /// The start configuration is outside the joint limits or unreachable.
    #[error("task `{task}`: the start is not a valid configuration: {reason}")]
    InvalidStart {
        /// The task.
        task: String,
        /// Why.
        reason: String,
    },
    /// A `solver MSk ..` entry names a segment the action does not decompose into.
    #[error(
        "action `{action}`: `solver MS{}` names no segment: the action decomposes into {count} \
         segment{} (MS1{})",
        segment + 1,
        if *count == 1 { "" } else { "s" },
        if *count > 1 { format!("..MS{count}") } else { String::new() }
    )]
    NoSuchSegment {
        /// The action.
        action: String,
        /// The segment named (0-based).
        segment: usize,
        /// How many segments the action has.
        count: usize,
        /// Where the entry was written in the task file.
        span: crate::language::ast::Span,
    },
    /// A segment's goal cannot be reached within the joint limits.
    #[error("action `{action}`, segment {}: {reason}", segment + 1)]
    Unreachable {
        /// The action.
        action: String,
        /// Segment index (0-based).
        segment: usize,
        /// Why.
        reason: String,
    },
    /// A path leaves out its size where no optimiser chooses it.
    #[error(
        "action `{action}`: the path on {} has no size, and nothing chooses it here: give the \
         {} (it may be left out only when the path conflicts with a goal, types IV-VII)",
        variable.symbol(),
        if *line { "length" } else { "angle" }
    )]
    MissingPathSize {
        /// The action.
        action: String,
        /// The first variable of the path item without a size.
        variable: Variable,
        /// Whether the item is a `line` (else `about`).
        line: bool,
    },
}

fn fact_list(facts: &[String]) -> String {
    let quoted: Vec<String> = facts.iter().map(|f| format!("`{f}`")).collect();
    let noun = if facts.len() == 1 { "fact" } else { "facts" };
    format!("{noun} {}", quoted.join(", "))
}
