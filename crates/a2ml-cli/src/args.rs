//! The command-line grammar: the top-level [`Cli`] and one [`Commands`]
//! variant per subcommand, each with its arguments in its own module.

use clap::{Parser, Subcommand};

use crate::commands::analyze::AnalyzeArgs;
use crate::commands::check::CheckArgs;
use crate::commands::compare::CompareArgs;
use crate::commands::explain::ExplainArgs;
use crate::commands::fmt::FmtArgs;
use crate::commands::map::MapArgs;
use crate::commands::plan::PlanArgs;
use crate::commands::plot::PlotArgs;
use crate::commands::report::ReportArgs;
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
  a2ml analyze lines.mcap
  a2ml plot examples/type_iv_forward_bar.a2ml -o forward_bar.svg
  a2ml report examples/push_box_aside_coman.a2ml -o push_box.html
  a2ml compare examples/baseline_pmp.a2ml --solvers qp,pmp
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
    /// Measure how human-like a written plan is: RULA, motion patterns, Fitts, bell shape.
    Analyze(AnalyzeArgs),
    /// Plan a task and draw it as SVG: joints, velocities, featured variables, clearance, wrist path.
    Plot(PlotArgs),
    /// Plan a task and write one self-contained HTML report: table, plots, motion playback.
    Report(ReportArgs),
    /// Plan one task with several solvers (the baselines among them) and compare the results.
    Compare(CompareArgs),
    /// Draw the time × swivel obstacle map of one segment, and its profile, as SVG.
    Map(MapArgs),
}

/// How `robot`, `explain` and `plan` read the arm from its URDF.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct ArmArgs {
    /// Base link of the arm's chain [default: the task's `robot ... base`,
    /// else the root of the unique 7-joint chain].
    #[arg(long, value_name = "LINK")]
    pub base: Option<String>,
    /// Tip link of the arm's chain [default: the task's `robot ... tip`,
    /// else the last link of the unique 7-joint chain].
    #[arg(long, value_name = "LINK")]
    pub tip: Option<String>,
    /// A folder searched for `package://` meshes (a package, or a folder of
    /// packages); repeatable, searched before A2ML_PACKAGE_PATH and
    /// ROS_PACKAGE_PATH.
    #[arg(long = "package-path", value_name = "DIR")]
    pub package_path: Vec<std::path::PathBuf>,
    /// Radius (m) of the skeleton capsules that cover parts of the arm
    /// without usable URDF geometry; 0 leaves them uncovered [default: 0.06].
    #[arg(long, value_name = "M")]
    pub skeleton_radius: Option<f64>,
    /// An SRDF whose `<disable_collisions>` pairs are not checked for self-collision
    /// [default: the URDF's name with `.srdf`, when that file exists].
    #[arg(long, value_name = "PATH")]
    pub srdf: Option<std::path::PathBuf>,
}

impl ArmArgs {
    /// The robot options: `--base`/`--tip` (a task's own `base`/`tip` come second, in
    /// [`a2ml_core::language::Task::load_robot`]), `--srdf`, and the package path with the
    /// environment's folders after `--package-path`.
    ///
    /// # Errors
    /// A message when the skeleton radius is negative or not finite.
    pub fn options(&self) -> Result<a2ml_core::RobotOptions, crate::error::CliError> {
        let mut options = a2ml_core::RobotOptions {
            base: self.base.clone(),
            tip: self.tip.clone(),
            ..a2ml_core::RobotOptions::default()
        };
        let geometry = &mut options.geometry;
        geometry.package_path = self.package_path.clone();
        geometry.srdf = self.srdf.clone();
        for variable in ["A2ML_PACKAGE_PATH", "ROS_PACKAGE_PATH"] {
            if let Some(value) = std::env::var_os(variable) {
                geometry.package_path.extend(std::env::split_paths(&value));
            }
        }
        match self.skeleton_radius {
            Some(r) if !(r.is_finite() && r >= 0.0) => {
                return Err(crate::error::CliError::Input(format!(
                    "--skeleton-radius {r}: it must be a finite length of 0 m or more"
                )));
            }
            Some(r) => geometry.skeleton_radius = (r > 0.0).then_some(r),
            None => {}
        }
        Ok(options)
    }
}
