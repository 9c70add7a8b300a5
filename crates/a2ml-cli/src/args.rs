//! The command-line grammar: the top-level [`Cli`] and one [`Commands`]
//! variant per subcommand, each with its arguments in its own module.

use clap::{Parser, Subcommand};

use crate::commands::check::CheckArgs;
use crate::commands::explain::ExplainArgs;
use crate::commands::fmt::FmtArgs;
use crate::commands::map::MapArgs;
use crate::commands::plan::PlanArgs;
use crate::commands::robot::RobotArgs;

/// Plans human-like motions for 7-DoF anthropomorphic arms from A2ML tasks.
#[derive(Debug, Parser)]
#[command(name = "a2ml", version, arg_required_else_help = true)]
#[command(after_help = "\
Examples:
  a2ml robot robots/iiwa14.urdf
  a2ml robot robots/iiwa14.urdf --at 0.3,0.5,-0.2,1.2,0.4,-0.6,0.1
  a2ml robot robots/panda.urdf --at 0,-45,0,-135,0,90,45 --deg --json
  a2ml check examples/*.a2ml
  a2ml fmt --write task.a2ml
  a2ml explain examples/type_iv_forward_bar.a2ml
  a2ml plan examples/construct_path_line.a2ml -o lines.mcap
  a2ml map examples/swivel_map_spheres.a2ml --action pass_spheres -o map.svg

Exit codes: 0 success, 1 I/O error, 2 invalid input, 3 a goal missed (plan
written), 4 planning failed.")]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Commands,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Commands {
    /// Show what a2ml reads from a URDF, and the arm's state at a configuration.
    Robot(RobotArgs),
    /// Check task files: parse and validate each, report every problem.
    Check(CheckArgs),
    /// Print a task file in canonical form, check that it is, or rewrite it.
    Fmt(FmtArgs),
    /// Show how a task decomposes: actions, types, segments, primitives, Opt1/Opt2.
    Explain(ExplainArgs),
    /// Plan a task's motion and write it as MCAP (for Foxglove), CSV or JSON.
    Plan(PlanArgs),
    /// Draw the time × swivel obstacle map of one segment, and its profile, as SVG.
    Map(MapArgs),
}
