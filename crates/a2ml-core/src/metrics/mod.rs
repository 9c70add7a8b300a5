//! Human-likeness of a motion, measured (METHODS.md §3): RULA group A per frame ([`rula`]),
//! the HAMP motion patterns and their similarity indices ([`pattern`]), durations against
//! Fitts' law ([`fitts`]), the bell shape of the wrist speed, and smoothness ([`smoothness`]:
//! normalised jerk, speed peaks).
//!
//! Entry point: [`analyze`] (a robot and a trajectory, fresh or read back from a file, to
//! per-frame and per-segment measures). Conventions and angle definitions: docs/metrics.md.

pub mod fitts;
mod motion;
pub mod pattern;
pub mod rula;
pub mod smoothness;

pub use motion::{
    Analysis, BellShape, FrameMetrics, MetricsOptions, ScoreSummary, Span, SpanMetrics, analyze,
    bell_shape, frame_metrics, span_metrics,
};
