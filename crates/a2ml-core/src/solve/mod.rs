//! Solving the segments of a decomposed task (DESIGN.md §5) and the plan they make.
//!
//! Entry points: [`Plan`] with one [`SegmentReport`] per segment.

mod report;

pub use report::{Plan, QpStats, SegmentReport, Tolerance, VariableError};
