//! The plan as one JSON document.

use std::io::Write;
use std::path::Path;

use serde::Serialize;

use super::atomic::Failure;
use crate::language::Task;
use crate::robot::Robot;
use crate::solve::Plan;

/// The document: what produced the plan, then the plan's own fields.
#[derive(Serialize)]
struct PlanFile<'a> {
    a2ml_version: &'static str,
    robot: &'a str,
    urdf: &'a Path,
    #[serde(flatten)]
    plan: &'a Plan,
}

pub(super) fn write(
    out: &mut impl Write,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
) -> Result<(), Failure> {
    let file = PlanFile {
        a2ml_version: env!("CARGO_PKG_VERSION"),
        robot: &robot.name,
        urdf: &task.robot,
        plan,
    };
    serde_json::to_writer_pretty(&mut *out, &file)?;
    writeln!(out)?;
    Ok(())
}
