//! Integration tests of the a2ml library, one module per area.

mod collision;
mod common;
mod constrained_rrt;
mod decompose;
mod errors;
mod ik;
mod jacobians;
mod language;
mod opt;
mod output;
mod plan;
mod profile;
mod push_box;
mod repository;
mod robots;
mod rrt;
mod segments;
mod swivel;
mod visuals;
