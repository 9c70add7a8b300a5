//! `a2ml analyze`: reads a written plan back (MCAP with its attached URDF, or CSV with
//! `--robot`) and prints its human-likeness measures ([`metrics::analyze`]): one row per
//! segment and one for the whole motion, or the same as JSON.

use std::path::{Path, PathBuf};

use clap::Args;
use serde::Serialize;

use a2ml_core::metrics::{self, MetricsOptions, Span, SpanMetrics};
use a2ml_core::output::{self as files, ReadError, RecordedPlan};
use a2ml_core::{Robot, RobotOptions};

use crate::error::CliError;
use crate::output::{self, Table, num};

/// Arguments of `a2ml analyze`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  a2ml analyze plan.mcap
  a2ml analyze plan.csv --robot robots/coman_right_arm.urdf --json

An MCAP file written by `a2ml plan` carries its URDF, so --robot is needed
only for CSV (or to score the plan on another model of the same joints).
Patterns: Φ swivel, P wrist position, O hand orientation moving (docs/metrics.md).

Exit codes: 0 success, 1 a file cannot be read, 2 the file or the robot is
not valid, or they do not match.")]
pub struct AnalyzeArgs {
    /// The plan: an .mcap or .csv file written by `a2ml plan`.
    #[arg(value_name = "PLAN")]
    pub file: PathBuf,
    /// The robot's URDF (required for CSV; for MCAP, instead of the attached one).
    #[arg(long, value_name = "URDF")]
    pub robot: Option<PathBuf>,
    /// Print the measures as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The JSON of `a2ml analyze --json`.
#[derive(Debug, Serialize)]
struct Report<'a> {
    /// The file analysed.
    file: String,
    /// The robot's name.
    robot: &'a str,
    /// The whole motion.
    whole: &'a SpanMetrics,
    /// Each segment (none for CSV).
    segments: &'a [SpanMetrics],
    /// Samples where the swivel angle or the arm plane is undefined.
    singular_frames: usize,
    /// Nothing to say, or that the file has no segment records.
    warnings: Vec<String>,
}

impl From<ReadError> for CliError {
    fn from(error: ReadError) -> Self {
        match error {
            ReadError::Io { .. } => Self::Io(error.to_string()),
            other => Self::Input(other.to_string()),
        }
    }
}

fn read(path: &Path) -> Result<RecordedPlan, CliError> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("mcap") => Ok(files::read_mcap(path)?),
        Some("csv") => Ok(files::read_csv(path)?),
        _ => Err(CliError::Input(format!(
            "{}: give a plan written by `a2ml plan`: an .mcap or a .csv file",
            path.display()
        ))),
    }
}

fn robot_of(args: &AnalyzeArgs, recorded: &RecordedPlan) -> Result<Robot, CliError> {
    match (&args.robot, &recorded.urdf) {
        (Some(path), _) => Ok(Robot::from_urdf_file(path)?),
        (None, Some(urdf)) => Robot::from_urdf_str(urdf, &RobotOptions::default()).map_err(|e| {
            CliError::Input(format!("{}: the attached URDF: {e}", args.file.display()))
        }),
        (None, None) => Err(CliError::Input(format!(
            "{}: no URDF attached: give the robot with --robot URDF",
            args.file.display()
        ))),
    }
}

/// Runs `a2ml analyze`.
///
/// # Errors
/// [`CliError::Io`] when the file cannot be read; [`CliError::Input`] when it is not a plan,
/// the robot is missing or invalid, or its joints are not the plan's.
pub fn run(args: &AnalyzeArgs) -> Result<(), CliError> {
    let recorded = read(&args.file)?;
    let robot = robot_of(args, &recorded)?;
    recorded.check_joints(&robot.joint_names())?;
    let spans = Span::of_recorded(&recorded);
    let analysis =
        metrics::analyze(&robot, &recorded.trajectory, &spans, &MetricsOptions::default());
    let mut warnings = Vec::new();
    if spans.is_empty() {
        warnings.push("the file has no segment records: the whole motion only".to_owned());
    }
    let report = Report {
        file: args.file.display().to_string(),
        robot: &robot.name,
        whole: &analysis.whole,
        segments: &analysis.segments,
        singular_frames: analysis.frames.singular_frames,
        warnings,
    };
    output::emit(&report, args.json, &report.warnings, || text(&report))
}

fn summary(s: Option<metrics::ScoreSummary>) -> [String; 2] {
    s.map_or(["-".to_owned(), "-".to_owned()], |s| [num(s.mean, 2), s.max.to_string()])
}

fn row(table: &mut Table, m: &SpanMetrics) {
    let [rula_mean, rula_max] = summary(m.rula);
    let [sum_mean, sum_max] = summary(m.rula_sum);
    let p = &m.patterns;
    let hamp =
        |h: &metrics::pattern::Hamp| if h.is_empty() { "-".to_owned() } else { h.to_string() };
    table.row(
        m.span.label.clone(),
        [
            num(m.span.start, 3),
            num(m.fitts.duration, 3),
            num(m.fitts.fitts, 3),
            num(m.fitts.ratio, 2),
            hamp(&p.phase1.hamp),
            hamp(&p.phase2.hamp),
            num(p.swivel_ratio, 2),
            rula_mean,
            rula_max,
            sum_mean,
            sum_max,
            num(m.wrist_speed.peak_time_ratio, 2),
            num(m.wrist_speed.symmetry, 2),
            m.speed_peaks.to_string(),
            num(m.wrist_jerk, 1),
        ],
    );
}

fn text(report: &Report<'_>) -> String {
    let mut table = Table::with_header([
        "span",
        "start (s)",
        "T (s)",
        "Fitts (s)",
        "×Fitts",
        "HAMP 1",
        "HAMP 2",
        "R_Φ",
        "RULA A",
        "max",
        "UA+LA+W",
        "max",
        "peak t/T",
        "symmetry",
        "peaks",
        "NJ wrist",
    ])
    .left_aligned([5, 6]);
    for segment in report.segments {
        row(&mut table, segment);
    }
    row(&mut table, report.whole);
    let mut out = format!("{} on {}\n", report.file, report.robot);
    table.render(&mut out);
    if report.singular_frames > 0 {
        out.push_str(&format!(
            "  {} singular (swivel or arm plane undefined; not scored)\n",
            output::count(report.singular_frames, "sample")
        ));
    }
    out
}
