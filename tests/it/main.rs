//! Integration tests of the a2ml library, one module per area.

mod common;
mod decompose;
mod errors;
mod ik;
mod jacobians;
mod language;
mod profile;
mod robots;
mod swivel;
