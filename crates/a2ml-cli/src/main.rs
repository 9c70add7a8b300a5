//! The `a2ml` command line.
fn main() {}
