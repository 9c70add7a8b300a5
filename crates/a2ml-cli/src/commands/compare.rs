//! `a2ml compare`: plans one task with several solvers ([`a2ml_core::solve::compare`]) and prints one
//! table, a row per solver and segment: goal errors, path kept, the worst joint-limit margin
//! and its joint, the smallest clearance and its link, the peak joint speed against the
//! limits, the duration and the planning time. `--json` prints the records instead; `-o DIR`
//! writes each solver's plan there as MCAP and CSV.

use std::path::PathBuf;

use clap::Args;

use a2ml_core::RobotOptions;
use a2ml_core::language::{Measure, SolverChoice, Variable};
use a2ml_core::output as files;
use a2ml_core::solve::compare::{ComparisonRecord, compare, records};
use a2ml_core::solve::{PlanOptions, Tolerance};

use crate::error::CliError;
use crate::output::{self, Table, deg, num};

/// Arguments of `a2ml compare`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  a2ml compare examples/baseline_gpm.a2ml
  a2ml compare task.a2ml --solvers qp,gpm --json
  a2ml compare task.a2ml -o plans/

A baseline that leaves its joint limits or hits an obstacle is shown doing so
(a negative margin or clearance): that is what the comparison is for. A solver
that fails on the task gets one row with its error.

Exit codes: 0 success, 1 a file cannot be read or written, 2 the task or an
option is not valid.")]
pub struct CompareArgs {
    /// The task file.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// The solvers, comma-separated.
    #[arg(long, value_name = "LIST", value_delimiter = ',', default_value = "auto,gpm,clik,pmp",
          value_parser = super::plan::solver_parser())]
    pub solvers: Vec<SolverChoice>,
    /// Print the records as JSON.
    #[arg(long)]
    pub json: bool,
    /// Write each solver's plan to DIR/<stem>_<solver>.mcap and .csv.
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    pub output: Option<PathBuf>,
}

/// Runs `a2ml compare`.
///
/// # Errors
/// [`CliError::Io`] when the task, robot or an output cannot be read or written;
/// [`CliError::Input`] for an invalid task or robot.
pub fn run(args: &CompareArgs) -> Result<(), CliError> {
    if let Some(dir) = &args.output {
        if !dir.is_dir() {
            return Err(CliError::Io(format!("there is no folder {}", dir.display())));
        }
    }
    let (task, source) = super::load_task(&args.file, &a2ml_core::language::Limits::default())?;
    let robot = task.load_robot(&RobotOptions::default())?;
    let options = PlanOptions::default();
    let attempts = compare(&robot, &task, &args.solvers, &options);
    let rows: Vec<ComparisonRecord> = attempts.iter().flat_map(|a| records(&robot, a)).collect();
    output::emit(&rows, args.json, &[], || table(&rows, &options.tolerance))?;
    if let Some(dir) = &args.output {
        let stem = args.file.file_stem().map_or_else(|| "plan".into(), |s| s.to_string_lossy());
        for attempt in &attempts {
            let Ok(plan) = &attempt.outcome else { continue };
            let name = format!("{stem}_{}", attempt.solver.name());
            let mcap = dir.join(format!("{name}.mcap"));
            let csv = dir.join(format!("{name}.csv"));
            let failed = |e: files::OutputError| CliError::Io(e.to_string());
            files::write_mcap(&mcap, &robot, &task, &source, plan).map_err(failed)?;
            files::write_csv(&csv, &robot, plan).map_err(failed)?;
            if !args.json {
                output::print(&format!("wrote  {}\nwrote  {}\n", mcap.display(), csv.display()))?;
            }
        }
    }
    Ok(())
}

/// The text table: one row per record.
fn table(rows: &[ComparisonRecord], tolerance: &Tolerance) -> String {
    let mut t = Table::with_header([
        "solver",
        "segment",
        "by",
        "reached",
        "goal errors",
        "path",
        "limit margin°",
        "joint",
        "clearance mm",
        "link",
        "speed ×",
        "time s",
        "planned s",
    ])
    .left_columns(3)
    .left_aligned([4, 7, 9]);
    for r in rows {
        let segment = match (&r.action, r.segment) {
            (Some(a), Some(k)) => format!("{a}/{}", k + 1),
            _ => "-".to_owned(),
        };
        if let Some(error) = &r.error {
            t.note(format!("{}  {segment}", r.solver), format!("failed: {error}"));
            continue;
        }
        let errors: Vec<String> = r
            .errors
            .iter()
            .map(|(v, e)| {
                // The records name each variable by its one spelling.
                let measure = v.parse().map_or(Measure::Angle, Variable::measure);
                let decimals = match measure {
                    Measure::Length => 1,
                    Measure::Angle => 2,
                };
                format!("{v} {}{}", num(measure.shown(*e), decimals), measure.shown_unit())
            })
            .collect();
        let path = match r.path_kept {
            Some(true) => "kept",
            Some(false) => "LEFT",
            None => "-",
        };
        let opt = |x: Option<f64>, f: &dyn Fn(f64) -> String| x.map_or_else(|| "-".to_owned(), f);
        t.row(
            r.solver.clone(),
            [
                segment,
                r.solved_by.clone().unwrap_or_default(),
                output::yes_no(r.reached.unwrap_or(false)),
                errors.join(", "),
                path.to_owned(),
                opt(r.limit_margin, &|m| num(deg(m), 1)),
                r.limit_joint.clone().unwrap_or_else(|| "-".to_owned()),
                opt(r.clearance, &|c| num(c * 1e3, 1)),
                r.clearance_link.clone().unwrap_or_else(|| "-".to_owned()),
                opt(r.peak_speed_ratio, &|s| num(s, 2)),
                opt(r.duration, &|d| num(d, 3)),
                num(r.planning_time, 3),
            ],
        );
    }
    let mut out = String::new();
    t.render(&mut out);
    out.push_str(&format!(
        "  reached: within {} mm and {}°; a negative margin or clearance is a violation\n",
        num(Measure::Length.shown(tolerance.position), 1),
        num(Measure::Angle.shown(tolerance.angle), 1)
    ));
    out
}
