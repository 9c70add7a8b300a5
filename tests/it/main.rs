//! Integration tests of the a2ml library, one module per area.

mod baselines;
mod collision;
mod common;
mod constrained_rrt;
mod decompose;
mod errors;
mod hamp;
mod hostile;
mod ik;
mod jacobians;
mod language;
mod metrics;
mod map;
mod opt;
mod output;
mod plan;
mod plot;
mod profile;
mod push_box;
mod repository;
mod robots;
mod rrt;
mod segments;
mod smoothness;
mod swivel;
mod visuals;
