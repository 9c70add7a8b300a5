//! `a2ml plan`: loads a task and its robot, plans it ([`solve::plan`]:
//! decompose, solve every segment, join) and writes the result as MCAP, CSV
//! or JSON through the core's atomic writers. Stdout gets a summary table,
//! one row per segment, and a line of totals; stderr gets the warnings and,
//! on a terminal, a progress bar while planning takes a while.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use clap::Args;
use clap::builder::{PossibleValuesParser, TypedValueParser};

use a2ml_core::Robot;
use a2ml_core::language::{self, SolverChoice, Task, Variable};
use a2ml_core::math::Real;
use a2ml_core::output::{self as files, OutputError, Staged};
use a2ml_core::solve::{
    self, CheckError, Plan, PlanOptions, Progress, SegmentReport, SolveError, Tolerance,
};

use crate::error::CliError;
use crate::output::{self, COARSE, Table, deg, num};
use crate::signals::Temporaries;

/// Decimals for durations (s).
const SECONDS: usize = 3;

/// Arguments of `a2ml plan`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  a2ml plan examples/construct_path_line.a2ml
  a2ml plan task.a2ml -o out.mcap --csv out.csv --json out.json
  a2ml plan task.a2ml --solver qp --rate 250 --seed 7
  a2ml plan tasks/ -o 'out/{stem}.mcap' --parquet 'out/{stem}.parquet' --jobs 2
  a2ml plan 'sweep/*.a2ml' --csv 'out/{stem}.csv'

Without -o, --csv, --json or --parquet the MCAP file goes to <FILE stem>.mcap
in the current folder. An output path may hold {stem}, the task file's name
without its extension: with several tasks each output must, so that every task
writes files of its own. Outputs replace only regular files, never a task or
robot file of the run: a folder, device, FIFO or symbolic link is refused.
Every output is written to a temporary file beside it, and all of a task's are
renamed once every one is complete, so a failed or interrupted run (SIGINT,
SIGTERM, SIGHUP: exit 130, 143, 129) leaves the old files as they were and no
temporary file.

Several tasks (several FILEs, a folder: every *.a2ml in it, or a quoted
pattern) are planned in parallel, --jobs at a time, each exactly as it would
be alone (its own seed); one line per task is printed in the order given, then
the count. A task that fails is reported with its file and the others go on.

Exit codes: 0 success, 1 a file cannot be read or written, 2 the task, an
option or an output path is not valid or the task cannot be decomposed, 3 a goal is missed
beyond tolerance (the files are written all the same), 4 the solver failed
on a segment (nothing is written). With several tasks, the worst of theirs:
1, then 2, then 4, then 3.")]
pub struct PlanArgs {
    /// The task files, folders of task files or quoted patterns (`tasks/*.a2ml`).
    #[arg(value_name = "FILE", required = true)]
    pub files: Vec<PathBuf>,
    /// Write the plan as MCAP, for Foxglove [default: <FILE stem>.mcap, when
    /// no other output is given].
    #[arg(short = 'o', long = "output", value_name = "OUT.mcap")]
    pub output: Option<PathBuf>,
    /// Write the joint trajectory as CSV: t, then <joint>_pos and <joint>_vel.
    #[arg(long, value_name = "OUT.csv")]
    pub csv: Option<PathBuf>,
    /// Write the plan as JSON: trajectory, segment reports, warnings.
    #[arg(long, value_name = "OUT.json")]
    pub json: Option<PathBuf>,
    /// Write one row per sample as Parquet: task, action, segment, t, q, qd, wrist state,
    /// clearance (the same columns for every robot, so a batch loads as one table).
    #[arg(long, value_name = "OUT.parquet")]
    pub parquet: Option<PathBuf>,
    /// How many tasks are planned at once [default: one per core].
    #[arg(short = 'j', long, value_name = "N")]
    pub jobs: Option<std::num::NonZeroUsize>,
    /// Solver for every segment, overriding the task's choices.
    #[arg(long, value_name = "SOLVER", value_parser = solver_parser())]
    pub solver: Option<SolverChoice>,
    /// Output rate (Hz), overriding the task's `settings { rate }`.
    #[arg(long, value_name = "HZ", value_parser = parse_rate, allow_hyphen_values = true)]
    pub rate: Option<Real>,
    /// Seed of the randomised solvers, overriding the task's `settings { seed }`.
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Which chain of the URDF, and where its capsules come from.
    #[command(flatten)]
    pub arm: crate::args::ArmArgs,
    /// The joints' acceleration limits as a multiple of the robot file's, overriding the
    /// task's `settings { acceleration }` (e.g. 0.5).
    #[arg(long, value_name = "SCALE", value_parser = parse_positive)]
    pub acceleration_scale: Option<Real>,
    /// Wall-clock limit of the planning (s) [default: none]: the plan fails with a timeout
    /// when it passes, so the result then depends on the machine's speed.
    #[arg(long, value_name = "SECONDS", value_parser = parse_positive)]
    pub time_limit: Option<Real>,
    /// Plan even when the task or an action starts closer to an obstacle than the safety
    /// distance (or in collision), with a warning.
    #[arg(long)]
    pub allow_close_start: bool,
    #[command(flatten)]
    pub limits: super::LimitArgs,
}

/// A positive, finite number.
///
/// # Errors
/// A message saying what the number must be.
fn parse_positive(text: &str) -> Result<Real, String> {
    match text.trim().parse::<Real>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        Ok(_) => Err("it must be positive and finite".to_owned()),
        Err(_) => Err("not a number".to_owned()),
    }
}

/// `--solver`: one of [`SolverChoice::NAMES`], listed in `--help`.
pub(crate) fn solver_parser() -> impl TypedValueParser<Value = SolverChoice> {
    PossibleValuesParser::new(SolverChoice::NAMES.map(|(name, _)| name)).map(|name| {
        SolverChoice::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map_or(SolverChoice::Auto, |(_, solver)| *solver)
    })
}

/// `--rate`: a positive, finite number of samples per second.
///
/// # Errors
/// A message saying what the rate must be.
fn parse_rate(text: &str) -> Result<Real, String> {
    match text.trim().parse::<Real>() {
        Ok(rate) if rate.is_finite() && rate > 0.0 => Ok(rate),
        Ok(_) => Err("the rate must be positive and finite (Hz)".to_owned()),
        Err(_) => Err("not a number (Hz)".to_owned()),
    }
}

/// The kinds of file `a2ml plan` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Format {
    Mcap,
    Csv,
    Json,
    Parquet,
}

/// Runs `a2ml plan`: one task file as below, or many through [`crate::batch`].
///
/// # Errors
/// [`CliError::Io`] when the task or robot cannot be read or an output not
/// written; [`CliError::Input`] for an invalid task (diagnostics on stderr
/// first), an unusable robot, a task that does not decompose or a solver that
/// does not exist yet; [`CliError::Planning`] when a segment's solve fails;
/// [`CliError::Missed`] when the plan, written all the same, misses a goal.
pub fn run(args: &PlanArgs, temporaries: &Temporaries) -> Result<(), CliError> {
    let files = crate::batch::task_files(&args.files)?;
    match (args.files.as_slice(), files.as_slice()) {
        ([given], [file]) if given == file && !given.is_dir() => run_one(args, file, temporaries),
        _ => crate::batch::run(args, &files, temporaries),
    }
}

/// Plans one task file with its summary table and progress bar.
fn run_one(args: &PlanArgs, file: &Path, temporaries: &Temporaries) -> Result<(), CliError> {
    let outputs = outputs(args, file);
    check_outputs(&outputs)?;
    let planning = Planning::load(args, file, &outputs, &[])?;

    let started = Instant::now();
    let mut bar = crate::progress::PlanBar::new(started);
    let result = planning.plan(&mut |p| bar.update(p));
    bar.clear();
    let plan = result?;
    let planning_time = started.elapsed();

    for warning in &plan.warnings {
        output::warn(&warning.to_string());
    }
    let tolerance = planning.options.tolerance;
    output::print(&summary(file, &planning.robot, &plan, &tolerance, planning_time))?;
    planning.write(temporaries, &outputs, &plan)?;
    for (_, path) in &outputs {
        output::print(&format!("wrote  {}\n", path.display()))?;
    }
    verdict(&plan)
}

/// One task, read and ready to plan: what `a2ml plan` does for each task file.
pub(crate) struct Planning<'a> {
    /// The task file.
    pub file: &'a Path,
    /// The validated task, `--seed` applied.
    pub task: Task,
    /// The task file's text (MCAP attaches it).
    pub source: String,
    /// The task's robot, with its base and tip.
    pub robot: Robot,
    /// The command line's planning options.
    pub options: PlanOptions,
}

impl<'a> Planning<'a> {
    /// Reads the task and its robot; refuses an output that is the task, its robot or one of
    /// `inputs` (the other tasks of a batch).
    ///
    /// # Errors
    /// As [`run`], before planning.
    pub fn load(
        args: &PlanArgs,
        file: &'a Path,
        outputs: &[(Format, PathBuf)],
        inputs: &[PathBuf],
    ) -> Result<Self, CliError> {
        let limits = args.limits.limits();
        let (mut task, source) = super::load_task(file, &limits)?;
        if let Some(seed) = args.seed {
            task.settings.seed = seed;
        }
        for (_, path) in outputs {
            let mut read: Vec<&Path> = vec![file, &task.robot];
            read.extend(inputs.iter().map(PathBuf::as_path));
            output::check_not_an_input(path, &read)?;
        }
        let robot = task.load_robot(&args.arm.options()?)?;
        let options = PlanOptions {
            solver: args.solver,
            rate: args.rate,
            acceleration_scale: args.acceleration_scale,
            time_limit: args.time_limit,
            limits,
            allow_close_start: args.allow_close_start,
            ..PlanOptions::default()
        };
        Ok(Self { file, task, source, robot, options })
    }

    /// Plans the task, reporting progress to `progress`.
    ///
    /// # Errors
    /// As [`solve_error`]; a start too close to an obstacle is shown in the task's text first.
    pub fn plan(&self, progress: &mut dyn FnMut(&Progress)) -> Result<Plan, CliError> {
        solve::plan_with_progress(&self.robot, &self.task, &self.options, progress).map_err(|e| {
            if let SolveError::Check(CheckError::StartTooClose { action_index, order, .. }) = &e {
                report_start(self.file, &self.source, *action_index, *order, &e.to_string());
            }
            solve_error(self.file, e)
        })
    }

    /// Writes every output: each to its temporary file first, then all renamed, so a run that
    /// fails on one output leaves the others as they were.
    ///
    /// # Errors
    /// [`CliError::Io`] (or [`CliError::Input`] for a path that is not a regular file).
    pub fn write(
        &self,
        temporaries: &Temporaries,
        outputs: &[(Format, PathBuf)],
        plan: &Plan,
    ) -> Result<(), CliError> {
        let mut staged = Vec::with_capacity(outputs.len());
        for (format, path) in outputs {
            let mut file = temporaries.stage(path).map_err(output_error)?;
            self.fill(*format, &mut file, plan).map_err(output_error)?;
            staged.push(file);
        }
        temporaries.commit_all(staged).map_err(output_error)
    }

    fn fill(&self, format: Format, staged: &mut Staged, plan: &Plan) -> Result<(), OutputError> {
        let (robot, task) = (&self.robot, &self.task);
        match format {
            Format::Mcap => files::fill_mcap(staged, robot, task, &self.source, plan),
            Format::Csv => files::fill_csv(staged, robot, plan),
            Format::Json => files::fill_json(staged, robot, task, plan),
            Format::Parquet => files::fill_parquet(staged, robot, task, plan, &task_id(self.file)),
        }
    }
}

/// A task's name in a batch's tables: its file's stem.
fn task_id(file: &Path) -> String {
    file.file_stem().map_or_else(|| "plan".to_owned(), |s| s.to_string_lossy().into_owned())
}

/// Refuses, before planning, an output that cannot be written or is given twice.
///
/// # Errors
/// As [`output::check_output`]; [`CliError::Input`] for a path given twice.
pub(crate) fn check_outputs(outputs: &[(Format, PathBuf)]) -> Result<(), CliError> {
    for (k, (_, path)) in outputs.iter().enumerate() {
        output::check_output(path)?;
        if outputs[..k].iter().any(|(_, earlier)| earlier == path) {
            return Err(CliError::Input(format!(
                "{} is given as two outputs; each output needs a file of its own",
                path.display()
            )));
        }
    }
    Ok(())
}

/// A written plan that misses a goal, leaves a hard path or exceeds a limit is
/// [`CliError::Missed`], naming how many segments did.
///
/// # Errors
/// [`CliError::Missed`].
pub(crate) fn verdict(plan: &Plan) -> Result<(), CliError> {
    let missed = plan.segments.iter().filter(|s| !s.reached).count();
    let off_path = plan.segments.iter().filter(|s| !s.path_kept).count();
    let over = plan.segments.iter().filter(|s| !s.limits_kept).count();
    if missed + off_path + over > 0 {
        let total = output::count(plan.segments.len(), "segment");
        let mut failures = Vec::new();
        if missed > 0 {
            let goal = if missed == 1 { "its goal" } else { "their goals" };
            failures.push(format!("{missed} of {total} missed {goal} beyond tolerance"));
        }
        if off_path > 0 {
            let path = if off_path == 1 { "its hard path" } else { "their hard paths" };
            failures.push(format!("{off_path} of {total} left {path}"));
        }
        if over > 0 {
            failures.push(format!("{over} of {total} exceeded the joint limits"));
        }
        return Err(CliError::Missed(format!(
            "{}; the plan was written all the same",
            failures.join(", ")
        )));
    }
    Ok(())
}

/// The files to write for the task `file`: those asked for, `{stem}` replaced by the file's
/// stem, else `<stem>.mcap` in the current folder.
pub(crate) fn outputs(args: &PlanArgs, file: &Path) -> Vec<(Format, PathBuf)> {
    let asked = [
        (Format::Mcap, &args.output),
        (Format::Csv, &args.csv),
        (Format::Json, &args.json),
        (Format::Parquet, &args.parquet),
    ];
    let stem = task_id(file);
    let named = |pattern: &PathBuf| {
        let text = pattern.to_string_lossy();
        if text.contains(STEM) { PathBuf::from(text.replace(STEM, &stem)) } else { pattern.clone() }
    };
    let mut outputs: Vec<(Format, PathBuf)> =
        asked.iter().filter_map(|(f, p)| p.as_ref().map(|p| (*f, named(p)))).collect();
    if outputs.is_empty() {
        outputs.push((Format::Mcap, PathBuf::from(&stem).with_extension("mcap")));
    }
    outputs
}

/// The placeholder of an output path for the task file's stem.
pub(crate) const STEM: &str = "{stem}";

/// Fails early, before a long plan, when an output's folder does not exist.
///
/// # Errors
/// [`CliError::Io`] naming the output and its folder.
pub(crate) fn check_folder(path: &Path) -> Result<(), CliError> {
    match path.parent() {
        Some(folder) if !folder.as_os_str().is_empty() && !folder.is_dir() => Err(CliError::Io(
            format!("cannot write {}: there is no folder {}", path.display(), folder.display()),
        )),
        _ => Ok(()),
    }
}

/// An output that cannot be written is an I/O failure, whatever the cause:
/// an encoding failure would be a bug, but still a file not written.
/// A path that is not a regular file is invalid input.
fn output_error(error: OutputError) -> CliError {
    match error {
        OutputError::NotRegularFile { .. } => CliError::Input(error.to_string()),
        _ => CliError::Io(error.to_string()),
    }
}

/// The exit code of each way planning fails: the input (2) or the solver (4).
pub(crate) fn solve_error(file: &Path, error: SolveError) -> CliError {
    let message = format!("{}: {error}", file.display());
    match error {
        SolveError::Decompose(_)
        | SolveError::InvalidRate { .. }
        | SolveError::NoArmGeometry { .. }
        | SolveError::InvalidAccelerationScale { .. }
        | SolveError::Check(_)
        | SolveError::UnsupportedSolver { .. } => CliError::Input(message),
        SolveError::Reference { .. }
        | SolveError::Qp { .. }
        | SolveError::Rrt { .. }
        | SolveError::Map { .. }
        | SolveError::Baseline { .. }
        | SolveError::Hamp { .. }
        | SolveError::Trajectory(_) => CliError::Planning(message),
    }
}

/// Shows where a start too close to an obstacle is written: the task's `start` for the first
/// action (or the action's name when there is no `start`), else the action.
fn report_start(file: &Path, source: &str, action_index: usize, order: usize, message: &str) {
    let Ok(ast) = language::parse_ast(source, Some(file)) else { return };
    let start = ast.items.iter().find_map(|item| match item {
        language::ast::Item::Start(language::ast::Start::Joints(v)) => Some(v.span),
        language::ast::Item::Start(language::ast::Start::State { span, .. }) => Some(*span),
        _ => None,
    });
    let action = ast.items.iter().find_map(|item| match item {
        language::ast::Item::Task(t) => t.actions.get(action_index).map(|a| a.name.span),
        _ => None,
    });
    let Some(span) = (if order == 0 { start.or(action) } else { action }) else { return };
    let hint = "plan anyway, with a warning, with --allow-close-start";
    let diagnostics = language::Diagnostics {
        path: Some(file.display().to_string()),
        source: source.to_owned(),
        items: vec![language::Diagnostic::new(span, message).with_help(hint)],
        omitted: 0,
    };
    output::report(&diagnostics.to_string());
}

/// The summary: the task, one row per segment, then the totals.
fn summary(
    file: &Path,
    robot: &Robot,
    plan: &Plan,
    tolerance: &Tolerance,
    planning_time: Duration,
) -> String {
    let mut head = Table::new();
    head.title(format!("plan {}", plan.task));
    head.note("file", file.display().to_string());
    head.note("robot", robot.name.clone());
    let mut out = String::new();
    head.render(&mut out);

    let mut table = Table::with_header([
        "action",
        "segment",
        "type",
        "pattern",
        "space",
        "solver",
        "duration (s)",
        "goal error",
        "clearance (mm)",
        "limit margin (°)",
        "status",
    ])
    .left_aligned([2, 3, 4, 5, 7, 10]);
    table.title("segments");
    for s in &plan.segments {
        table.row(
            s.action.clone(),
            [
                (s.segment + 1).to_string(),
                s.action_type.map_or_else(|| "-".to_owned(), |t| t.to_string()),
                s.pattern.to_string(),
                s.space.to_string(),
                s.solver.to_string(),
                num(s.end - s.start, SECONDS),
                goal_error(s, tolerance),
                s.clearance.as_ref().map_or_else(|| "-".to_owned(), |c| num(c.distance * 1e3, 1)),
                num(deg(s.limit_margin), COARSE),
                status(s),
            ],
        );
    }
    table.render(&mut out);

    let steps: usize = plan.segments.iter().map(|s| s.qp.steps).sum();
    let clarabel: usize = plan.segments.iter().map(|s| s.qp.clarabel_steps).sum();
    let share = if steps == 0 { 0.0 } else { 100.0 * clarabel as Real / steps as Real };
    out.push_str(&format!(
        "\ntotal  {} s of motion, {} at {} Hz, planned in {} s, Clarabel in {clarabel} of {} ({}%)\n",
        num(plan.trajectory.duration(), SECONDS),
        output::count(plan.trajectory.len(), "sample"),
        short(plan.rate),
        num(planning_time.as_secs_f64(), 2),
        output::count(steps, "QP step"),
        num(share, 1),
    ));
    out.push_str(&worst_rates(plan));
    out
}

/// The error of the variable furthest from its goal relative to its
/// tolerance, as `pw 0.42 mm` or `swivel 0.31°`; `-` for a segment without one.
fn goal_error(s: &SegmentReport, tolerance: &Tolerance) -> String {
    let limit = |v: Variable| tolerance.of(v);
    let worst = s
        .errors
        .iter()
        .max_by(|a, b| (a.error / limit(a.variable)).total_cmp(&(b.error / limit(b.variable))));
    worst.map_or_else(|| "-".to_owned(), |e| e.variable.error_text(e.error, 2))
}

/// `ok`, `stalled` (stopped making progress short of the goal), `missed`
/// (the time ran out short of it) or `off path` (a hard path left); after
/// `auto` went on from the QP, why: `ok (qp_stalled)`.
fn status(s: &SegmentReport) -> String {
    let outcome = match (s.path_kept, s.reached, s.stalled) {
        _ if !s.limits_kept => "over limits",
        (false, ..) => "off path",
        (true, true, _) => "ok",
        (true, false, true) => "stalled",
        (true, false, false) => "missed",
    };
    match s.fallback {
        Some(why) => format!("{outcome} ({why})"),
        None => outcome.to_owned(),
    }
}

/// The worst joint rates against their limits, and which segment has each.
fn worst_rates(plan: &Plan) -> String {
    let worst = |rate: fn(&SegmentReport) -> Real| {
        plan.segments
            .iter()
            .max_by(|a, b| rate(a).total_cmp(&rate(b)))
            .map(|s| format!("{} in `{}` segment {}", num(rate(s), 2), s.action, s.segment + 1))
    };
    match (worst(|s| s.peak_velocity_ratio), worst(|s| s.peak_acceleration_ratio)) {
        (Some(v), Some(a)) => format!("rates  peak |q'|/limit {v}, peak |q''|/limit {a}\n"),
        _ => String::new(),
    }
}

/// A number without trailing zeros: `100`, `62.5`.
fn short(x: Real) -> String {
    let text = num(x, 3);
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

#[cfg(test)]
mod tests {
    use a2ml_core::decompose::SegmentPattern;
    use a2ml_core::solve::qp::{ClarabelStatus, QpError};

    use super::*;

    #[test]
    fn rates_must_be_positive_and_finite() {
        assert_eq!(parse_rate("250"), Ok(250.0));
        assert!(parse_rate("0").is_err());
        assert!(parse_rate("-5").is_err());
        assert!(parse_rate("inf").is_err());
        assert!(parse_rate("NaN").is_err());
        assert!(parse_rate("fast").is_err());
    }

    #[test]
    fn solver_failures_exit_4_and_input_errors_2() {
        let file = Path::new("task.a2ml");
        let failed = SolveError::Qp {
            action: "reach".to_owned(),
            segment: 1,
            source: QpError::Unsolved { time: 0.25, status: ClarabelStatus::PrimalInfeasible },
        };
        let error = solve_error(file, failed);
        assert_eq!(
            error.to_string(),
            "task.a2ml: action `reach`, segment 2: at t = 0.250 s the QP has no solution \
             (Clarabel: primal_infeasible)"
        );
        assert!(matches!(error, CliError::Planning(_)));
        let unsupported = SolveError::UnsupportedSolver {
            action: "reach".to_owned(),
            solver: SolverChoice::Pmp,
            pattern: SegmentPattern::Goal,
        };
        assert!(matches!(solve_error(file, unsupported), CliError::Input(_)));
    }

    #[test]
    fn rates_print_short() {
        assert_eq!(short(100.0), "100");
        assert_eq!(short(62.5), "62.5");
    }

    #[test]
    fn default_output_is_the_stem_in_the_current_folder() {
        let args = PlanArgs {
            files: vec![PathBuf::from("examples/lines.a2ml")],
            output: None,
            csv: None,
            json: None,
            parquet: None,
            jobs: None,
            solver: None,
            rate: None,
            seed: None,
            arm: crate::args::ArmArgs::default(),
            acceleration_scale: None,
            time_limit: None,
            allow_close_start: false,
            limits: crate::commands::LimitArgs {
                max_samples: 1,
                max_segments: 1,
                max_errors: 1,
                max_input_bytes: 1,
            },
        };
        let file = Path::new("examples/lines.a2ml");
        assert_eq!(outputs(&args, file), vec![(Format::Mcap, PathBuf::from("lines.mcap"))]);
        let args = PlanArgs { csv: Some(PathBuf::from("x.csv")), ..args };
        assert_eq!(outputs(&args, file), vec![(Format::Csv, PathBuf::from("x.csv"))]);
        let args = PlanArgs { parquet: Some(PathBuf::from("out/{stem}-plan.parquet")), ..args };
        assert_eq!(
            outputs(&args, file),
            vec![
                (Format::Csv, PathBuf::from("x.csv")),
                (Format::Parquet, PathBuf::from("out/lines-plan.parquet"))
            ]
        );
    }
}
