//! Solving the segments of a decomposed task (docs/design.md §5) and the plan they make.
//!
//! Entry points: [`plan`] (a task to a [`Plan`]: trajectory and one [`SegmentReport`] per
//! segment), [`qp::solve_segment`] (one segment with the velocity QP) and
//! [`rrt::rrt_connect`] (a collision-free joint-space path) and
//! [`constrained_rrt::constrained_rrt`] (one that keeps a segment's path constraint exactly);
//! [`hamp::plan_handover`] plans a handover the HAMP way (METHODS.md §3.4);
//! the baselines [`gpm`], [`clik`] and [`pmp`], each a resolver of the velocity loop in
//! [`control`].
//! Their long loops report progress and check the user's wall-clock limit through a
//! [`monitor::Monitor`]; without a limit, results never depend on the clock.

mod assembly;
pub mod chart;
mod checks;
pub mod clik;
pub mod compare;
pub mod constrained_rrt;
pub mod control;
pub mod gpm;
pub mod hamp;
pub mod judge;
pub mod map;
pub mod monitor;
pub(crate) mod plan;
pub mod pmp;
pub mod problem;
pub mod qp;
mod references;
mod report;
pub mod rrt;
pub mod timing;
mod tree;

pub use checks::CheckError;
pub use monitor::Monitor;
pub use plan::{PlanOptions, Progress, SolveError, plan, plan_with_progress};
pub use report::{
    Fallback, Plan, QpStats, ReferenceSample, ReferenceState, SegmentReport, SegmentSwivelMap,
    Tolerance, VariableError, Warning, WarningKind,
};
