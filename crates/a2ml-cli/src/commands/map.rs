//! `a2ml map`: the time × swivel obstacle map of one segment of a task
//! ([`a2ml_core::solve::map::segment_map`]) drawn as an SVG figure, with the profile the
//! `map` solver would choose. Stdout gets a short summary; a segment without
//! a profile is a warning, since the figure shows why.

use std::path::{Path, PathBuf};

use clap::Args;

use a2ml_core::RobotOptions;
use a2ml_core::decompose::DecomposeOptions;
use a2ml_core::output::{swivel_map_svg, write_text};
use a2ml_core::solve::SolveError;
use a2ml_core::solve::map::{Cell, MapError, MapOptions, MapSummary, SegmentMapError, segment_map};
use a2ml_core::solve::qp::QpOptions;

use crate::error::CliError;
use crate::output;

/// Arguments of `a2ml map`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  a2ml map examples/swivel_map_spheres.a2ml --action pass_spheres -o map.svg
  a2ml map task.a2ml --action push --segment 2 --time-steps 400 --angle-steps 720

The map is built from the decomposition's start configuration of the
segment. Exit codes: 0 the figure is written (also when the segment has no
free profile: a warning says where the free region is cut), 1 a file cannot
be read or written, 2 the task, the action, the segment or an option is not
valid (a HAT segment, an arm without analytic IK), 4 the map cannot be built.")]
pub struct MapArgs {
    /// The task file.
    #[arg(value_name = "FILE")]
    pub file: PathBuf,
    /// The action whose segment to map.
    #[arg(long, value_name = "NAME")]
    pub action: String,
    /// The segment of the action, counted from 1.
    #[arg(long, value_name = "K", default_value_t = 1)]
    pub segment: usize,
    /// The SVG figure [default: <FILE stem>.map.svg].
    #[arg(short = 'o', long = "output", value_name = "OUT.svg")]
    pub output: Option<PathBuf>,
    /// Time samples over the segment, ends included.
    #[arg(long, value_name = "N", default_value_t = 200)]
    pub time_steps: usize,
    /// Swivel-angle cells over the full turn.
    #[arg(long, value_name = "N", default_value_t = 360)]
    pub angle_steps: usize,
}

/// Runs `a2ml map`.
///
/// # Errors
/// [`CliError::Io`] when the task or robot cannot be read or the figure not
/// written; [`CliError::Input`] for an invalid task, action, segment or grid;
/// [`CliError::Planning`] when the map cannot be built.
pub fn run(args: &MapArgs) -> Result<(), CliError> {
    let (task, _) = super::load_task(&args.file, &a2ml_core::language::Limits::default())?;
    let robot = task.load_robot(&RobotOptions::default())?;
    if args.segment == 0 {
        return Err(CliError::Input("--segment counts from 1".to_owned()));
    }
    let options = MapOptions {
        time_steps: args.time_steps,
        angle_steps: args.angle_steps,
        safety_distance: QpOptions::default().safety_distance,
        ..MapOptions::default()
    };
    let k = args.segment - 1;
    let segment =
        segment_map(&robot, &task, &args.action, k, &DecomposeOptions::default(), &options)
            .map_err(|e| map_error(&args.file, e))?;
    let title = format!("{} — action {}, segment {}", task.name, args.action, args.segment);
    let summary = MapSummary::new(&segment.map, segment.profile.as_ref().ok());
    let svg = swivel_map_svg(&summary, &title)
        .map_err(|e| CliError::Planning(format!("cannot draw the map: {e}")))?;
    let path = args.output.clone().unwrap_or_else(|| default_output(&args.file));
    write_text(&path, &svg).map_err(|e| CliError::Io(e.to_string()))?;
    let map = &segment.map;
    let free = map.cells.iter().filter(|c| **c == Cell::Free).count();
    let mut text = format!(
        "map    {} × {} cells over {:.3} s, {:.1} % free\n",
        map.times.len(),
        map.angles.len(),
        map.times.last().copied().unwrap_or(0.0),
        100.0 * free as f64 / map.cells.len().max(1) as f64
    );
    match &segment.profile {
        Ok(profile) => text.push_str(&format!(
            "profile  θsw {:.1}° → {:.1}°, clearance {:.1} mm\n",
            profile.swivel.first().copied().unwrap_or(0.0).to_degrees(),
            profile.swivel.last().copied().unwrap_or(0.0).to_degrees(),
            profile.clearance * 1e3
        )),
        Err(e) => output::warn(&format!("{}: no profile: {e}", args.file.display())),
    }
    text.push_str(&format!("wrote  {}\n", path.display()));
    output::print(&text)
}

/// `<stem>.map.svg` in the current folder.
fn default_output(file: &Path) -> PathBuf {
    let stem = file.file_stem().map_or_else(|| "task".into(), |s| s.to_string_lossy());
    PathBuf::from(format!("{stem}.map.svg"))
}

/// The exit code of each way the map fails: the input (2) or the map itself (4).
fn map_error(file: &Path, error: SegmentMapError) -> CliError {
    let message = format!("{}: {error}", file.display());
    match error {
        SegmentMapError::NoAction { .. }
        | SegmentMapError::NoSegment { .. }
        | SegmentMapError::Solve(SolveError::Decompose(_))
        | SegmentMapError::Map {
            source: MapError::NotWristSegment | MapError::NotAnalytic | MapError::Options(_),
            ..
        } => CliError::Input(message),
        _ => CliError::Planning(message),
    }
}
