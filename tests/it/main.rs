//! Integration tests of the a2ml library, one module per area.

mod common;
mod errors;
mod ik;
mod jacobians;
mod language;
mod robots;
mod swivel;
