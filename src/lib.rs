#![doc = include_str!("../README.md")]
//! The facade crate: everything lives in [`a2ml_core`], re-exported here.
pub use a2ml_core::*;
