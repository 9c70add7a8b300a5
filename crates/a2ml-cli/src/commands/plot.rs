//! `a2ml plot`: plans a task file (as `a2ml plan` does), or reads a plan's MCAP recording, and
//! draws the plan as an SVG or PNG picture (by the output's extension) through the core's
//! [`output::plot`](a2ml_core::output::plot): one kind of chart, or every kind on one page.

use std::path::{Path, PathBuf};

use clap::Args;
use clap::builder::{PossibleValuesParser, TypedValueParser};

use a2ml_core::language::Task;
use a2ml_core::output::plot::{MAX_WIDTH, PlotData, PlotKind, write_plot, write_plot_data};
use a2ml_core::output::{RecordedPlan, read_mcap};
use a2ml_core::solve::{self, Plan, PlanOptions};
use a2ml_core::{Robot, RobotOptions};

use crate::error::CliError;
use crate::output;

/// Arguments of `a2ml plot`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  a2ml plot examples/type_iv_forward_bar.a2ml -o forward_bar.svg
  a2ml plot task.a2ml -o joints.svg --kind joints
  a2ml plot task.a2ml -o joints.png --kind joints --width 1600
  a2ml plot plan.mcap -o plan.svg      (a plan written by `a2ml plan --mcap`)

An output ending in .png is a PNG image (its text in the font the library
embeds, no system font read); any other is an SVG document.

Kinds: joints (positions, limits shaded, segment boundaries numbered),
velocities (and accelerations, against the speed limits), featured (each
segment's featured variables against their reference and goal), distances
(each arm capsule to each obstacle, with the safety distance), wrist (the
wrist path in three orthographic views), all (every kind on one page).

Exit codes: 0 success, 1 a file cannot be read or written, 2 the task or an
option is not valid, 3 a goal is missed beyond tolerance (the picture is
written all the same), 4 the solver failed (nothing is written).
An .mcap plan is drawn from its recording: its robot and task are the ones
attached to it.")]
pub struct PlotArgs {
    /// The task file (it is planned first), or a plan's .mcap recording.
    #[arg(value_name = "TASK.a2ml|PLAN.mcap")]
    pub file: PathBuf,
    /// The picture to write: PNG for a .png name, else SVG.
    #[arg(short = 'o', long = "output", value_name = "OUT.svg|OUT.png")]
    pub output: PathBuf,
    /// The picture's width in pixels, its height in proportion [default: as drawn].
    #[arg(long, value_name = "PX")]
    pub width: Option<u32>,
    /// What to draw.
    #[arg(long, value_name = "KIND", default_value = "all", value_parser = kind_parser())]
    pub kind: PlotKind,
    /// Seed of the randomised solvers, overriding the task's `settings { seed }`.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
}

/// `--kind`: one of [`PlotKind::NAMES`], listed in `--help`.
fn kind_parser() -> impl TypedValueParser<Value = PlotKind> {
    PossibleValuesParser::new(PlotKind::NAMES.map(|(name, _)| name))
        .map(|name| PlotKind::from_name(&name).unwrap_or(PlotKind::All))
}

/// A task file, its robot and its plan.
pub struct Planned {
    /// The robot.
    pub robot: Robot,
    /// The validated task.
    pub task: Task,
    /// The task file's text.
    pub source: String,
    /// The plan.
    pub plan: Plan,
}

/// Loads and plans the task file with the default options (and `seed`, if given), the
/// warnings going to stderr.
///
/// # Errors
/// As `a2ml plan`: [`CliError::Io`], [`CliError::Input`] or [`CliError::Planning`].
pub fn plan_file(file: &Path, seed: Option<u64>) -> Result<Planned, CliError> {
    let (mut task, source) = super::load_task(file, &a2ml_core::language::Limits::default())?;
    if let Some(seed) = seed {
        task.settings.seed = seed;
    }
    let robot = task.load_robot(&RobotOptions::default())?;
    let plan = solve::plan(&robot, &task, &PlanOptions::default())
        .map_err(|e| super::plan::solve_error(file, e))?;
    for warning in &plan.warnings {
        output::warn(&warning.to_string());
    }
    Ok(Planned { robot, task, source, plan })
}

/// [`CliError::Missed`] when the plan misses a goal or leaves a hard path: `what` was
/// written all the same.
///
/// # Errors
/// As said.
pub fn missed(plan: &Plan, what: &str) -> Result<(), CliError> {
    let failed = plan.segments.iter().filter(|s| !s.reached || !s.path_kept).count();
    if failed == 0 {
        return Ok(());
    }
    Err(CliError::Missed(format!(
        "{failed} of {} missed a goal or left a hard path; {what} was written all the same",
        output::count(plan.segments.len(), "segment")
    )))
}

/// Runs `a2ml plot`.
///
/// # Errors
/// As [`plan_file`]; [`CliError::Io`] when the picture cannot be written;
/// [`CliError::Missed`] when the plan, drawn all the same, misses a goal.
pub fn run(args: &PlotArgs) -> Result<(), CliError> {
    super::plan::check_folder(&args.output)?;
    if is_recording(&args.file) {
        return plot_recording(args);
    }
    check_width(args.width)?;
    let planned = plan_file(&args.file, args.seed)?;
    write_plot(&args.output, &planned.robot, &planned.task, &planned.plan, args.kind, args.width)
        .map_err(|e| CliError::Io(e.to_string()))?;
    output::print(&format!("wrote  {}\n", args.output.display()))?;
    missed(&planned.plan, "the picture")
}

/// [`CliError::Input`] for a `--width` no picture can have, before anything is planned.
fn check_width(width: Option<u32>) -> Result<(), CliError> {
    match width {
        Some(w) if w == 0 || w > MAX_WIDTH => {
            Err(CliError::Input(format!("--width is 1 to {MAX_WIDTH} pixels, not {w}")))
        }
        _ => Ok(()),
    }
}

/// Whether `file` is an MCAP recording (by its extension).
fn is_recording(file: &Path) -> bool {
    file.extension().is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
}

/// The robot of a recording, from its attached URDF.
///
/// # Errors
/// [`CliError::Input`] when the URDF is missing, invalid or not the plan's joints.
pub fn recorded_robot(file: &Path, recorded: &RecordedPlan) -> Result<Robot, CliError> {
    let urdf = recorded.urdf.as_deref().ok_or_else(|| {
        CliError::Input(format!("{}: no URDF attached: not a plan written by a2ml", file.display()))
    })?;
    let robot = Robot::from_urdf_str(urdf, &RobotOptions::default())
        .map_err(|e| CliError::Input(format!("{}: the attached URDF: {e}", file.display())))?;
    recorded.check_joints(&robot.joint_names())?;
    Ok(robot)
}

/// `a2ml plot PLAN.mcap`: draws the recorded plan, exit code 3 when a segment missed.
fn plot_recording(args: &PlotArgs) -> Result<(), CliError> {
    check_width(args.width)?;
    let recorded = read_mcap(&args.file)?;
    let robot = recorded_robot(&args.file, &recorded)?;
    let data = PlotData::recorded(&robot, &recorded.obstacles, &recorded);
    write_plot_data(&args.output, &data, args.kind, args.width)
        .map_err(|e| CliError::Io(e.to_string()))?;
    output::print(&format!("wrote  {}\n", args.output.display()))
}
