//! Solving the segments of a decomposed task (docs/design.md §5) and the plan they make.
//!
//! Entry points: [`plan`] (a task to a [`Plan`]: trajectory and one [`SegmentReport`] per
//! segment), [`qp::solve_segment`] (one segment with the velocity QP) and
//! [`rrt::rrt_connect`] (a collision-free joint-space path) and
//! [`constrained_rrt::constrained_rrt`] (one that keeps a segment's path constraint exactly).

pub mod constrained_rrt;
mod plan;
pub mod qp;
mod report;
pub mod rrt;

pub use plan::{PlanOptions, Progress, SolveError, plan, plan_with_progress};
pub use report::{Fallback, Plan, QpStats, SegmentReport, Tolerance, VariableError};
