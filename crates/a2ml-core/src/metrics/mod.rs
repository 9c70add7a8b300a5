//! Measures of a planned motion, computed from its samples: how smooth and how human-like it
//! is. Pure functions over plain data, shared by the solvers' reports and the analyses.
//!
//! Entry points: [`smoothness`] (normalised jerk, speed-profile peaks, peak rate ratios).

pub mod smoothness;
