//! Writing a [`Plan`] to files (docs/design.md §6): an MCAP recording for Foxglove, a CSV table
//! of the joint trajectory, the plan as JSON, a Parquet table of the samples, SVG and PNG pictures ([`plot`]) and an HTML report
//! ([`report`]).
//!
//! Entry points: [`write_mcap`], [`write_csv`], [`write_json`], [`write_parquet`], [`plot::write_plot`],
//! [`report::write_report`]. Every writer goes through a
//! temporary file beside the target, renamed on success and removed on failure, so a failed
//! run never leaves a partial file; several outputs can be [`Staged`] first and committed
//! together ([`fill_mcap`], [`fill_csv`], [`fill_json`]). Only regular files are replaced. Positions are in {b}, times in the plan's seconds (MCAP:
//! nanoseconds from the plan's time 0). mcap enters the crate here only.

mod atomic;
mod csv;
mod json;
mod mcap_file;
mod messages;
mod parquet;
pub mod plot;
mod read;
pub mod report;
mod schemas;
mod swivel_map;

#[cfg(test)]
mod tests;

use std::path::Path;

pub use atomic::{Staged, refused_kind};
pub use read::{
    ReadError, RecordedPlan, RecordedSegment, read_csv, read_csv_str, read_mcap, read_mcap_bytes,
};
pub use swivel_map::swivel_map_svg;

use crate::language::Task;
use crate::robot::Robot;
use crate::solve::Plan;

/// The MCAP channels [`write_mcap`] writes, all JSON-encoded with a JSON Schema.
pub mod topics {
    /// `a2ml.JointState` per sample: timestamp, joint names, positions (rad), velocities
    /// (rad/s) and the position limits (rad), so that a plot shows each joint against them.
    pub const JOINT_STATES: &str = "/joint_states";
    /// `foxglove.FrameTransforms` per sample: the chain's links as a tree, the first link from
    /// frame "b" and every other one from the link before it (as the URDF nests them).
    pub const TF: &str = "/tf";
    /// `foxglove.SceneUpdate` once at the start: the obstacles, in frame "b".
    pub const SCENE: &str = "/scene";
    /// `foxglove.SceneUpdate` once at the start: the arm's capsules, each in its link's frame
    /// and locked to it, so that `/tf` moves them.
    pub const ARM_CAPSULES: &str = "/arm_capsules";
    /// `foxglove.SceneUpdate` once: the planned and the reference wrist path Pw.
    pub const WRIST_PATH: &str = "/wrist_path";
    /// `a2ml.State` per sample: the CPSA and HAT states (null where singular).
    pub const STATE: &str = "/a2ml/state";
    /// `a2ml.Reference` per sample: what the running segment asks for (its references in
    /// both spaces, [`crate::solve::Plan::references`]).
    pub const REFERENCE: &str = "/a2ml/reference";
    /// `a2ml.Distances` per sample, when the scene has obstacles: each moving arm capsule's
    /// signed distance to each obstacle ([`crate::solve::Plan::distances`]).
    pub const DISTANCES: &str = "/a2ml/distances";
    /// `a2ml.Segment` at each segment's start: its [`crate::solve::SegmentReport`] and its
    /// references' ends.
    pub const SEGMENTS: &str = "/a2ml/segments";
    /// `std_msgs/String` once at the start: the robot's URDF in `data`, which Foxglove's 3D
    /// panel draws (its visuals) on the `/tf` frames.
    pub const ROBOT_DESCRIPTION: &str = "/robot_description";
}

/// Why an output file could not be written. No partial file is left behind in any case.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OutputError {
    /// The file system refused: a missing folder, no permission, a full disk.
    #[error("cannot write {path}: {message}")]
    Io {
        /// The path as given.
        path: String,
        /// The OS message.
        message: String,
    },
    /// The path is a folder, device, FIFO, socket or symbolic link, which an output never
    /// replaces.
    #[error("cannot write {path}: it is {kind}, and outputs replace only regular files")]
    NotRegularFile {
        /// The path as given.
        path: String,
        /// What is there: "a folder", "a device", "a FIFO", "a socket", "a symbolic link".
        kind: &'static str,
    },
    /// The MCAP writer failed to encode a record.
    #[error("cannot encode the MCAP file {path}: {message}")]
    Mcap {
        /// The path as given.
        path: String,
        /// The writer's message.
        message: String,
    },
    /// A picture could not be drawn (see [`plot::PlotError`]).
    #[error("cannot draw {path}: {message}")]
    Plot {
        /// The path as given.
        path: String,
        /// The plotting backend's message.
        message: String,
    },
    /// The Parquet writer failed to encode the table.
    #[error("cannot encode the Parquet file {path}: {message}")]
    Parquet {
        /// The path as given.
        path: String,
        /// The writer's message.
        message: String,
    },
    /// A value could not be encoded as JSON.
    #[error("cannot encode JSON for {path}: {message}")]
    Json {
        /// The path as given.
        path: String,
        /// The encoder's message.
        message: String,
    },
}

/// Writes the plan as an MCAP file for Foxglove: joint states, link transforms, the scene and
/// the arm's capsules, the wrist path, the CPSA and HAT states and one record per segment
/// (the channels are listed in [`topics`]), with the task `source` and the robot's URDF
/// attached.
///
/// # Errors
/// [`OutputError`] when the file cannot be written; the target is then left untouched.
pub fn write_mcap(
    path: &Path,
    robot: &Robot,
    task: &Task,
    source: &str,
    plan: &Plan,
) -> Result<(), OutputError> {
    atomic::write_atomically(path, |out| mcap_file::write(out, robot, task, source, plan))
}

/// [`write_mcap`] into a staged temporary file, to be committed with the run's other outputs.
///
/// # Errors
/// As [`write_mcap`]; the staged file is then useless and is removed when dropped.
pub fn fill_mcap(
    staged: &mut Staged,
    robot: &Robot,
    task: &Task,
    source: &str,
    plan: &Plan,
) -> Result<(), OutputError> {
    staged.fill(|out| mcap_file::write(out, robot, task, source, plan))
}

/// [`write_csv`] into a staged temporary file.
///
/// # Errors
/// As [`write_csv`].
pub fn fill_csv(staged: &mut Staged, robot: &Robot, plan: &Plan) -> Result<(), OutputError> {
    staged.fill(|out| csv::write(out, robot, plan))
}

/// [`write_json`] into a staged temporary file.
///
/// # Errors
/// As [`write_json`].
pub fn fill_json(
    staged: &mut Staged,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
) -> Result<(), OutputError> {
    staged.fill(|out| json::write(out, robot, task, plan))
}

/// Writes the joint trajectory as CSV: `t`, then `<joint>_pos` and `<joint>_vel` per joint,
/// one row per sample (s, rad, rad/s), numbers in their shortest exact form.
///
/// # Errors
/// [`OutputError::Io`] when the file cannot be written; the target is then left untouched.
pub fn write_csv(path: &Path, robot: &Robot, plan: &Plan) -> Result<(), OutputError> {
    atomic::write_atomically(path, |out| csv::write(out, robot, plan))
}

/// Writes the plan as pretty-printed JSON: the [`Plan`]'s fields (joint names, rate,
/// trajectory, segment reports, wrist reference, warnings) with the a2ml version, the robot's
/// name and the task's URDF path.
///
/// # Errors
/// [`OutputError`] when the file cannot be written; the target is then left untouched.
pub fn write_json(path: &Path, robot: &Robot, task: &Task, plan: &Plan) -> Result<(), OutputError> {
    atomic::write_atomically(path, |out| json::write(out, robot, task, plan))
}

/// Writes the plan as a Parquet table, one row per sample: `task` (`task_id`), `action`,
/// `action_index`, `segment`, `t`, `q1`..`q7`, `qd1`..`qd7`, the wrist state `pw_x`..`pw_z`,
/// `ow_w`..`ow_z`, `swivel`, and `clearance` (s, m, rad; {b}); the same columns for every
/// robot, so a batch's files load as one table.
///
/// # Errors
/// [`OutputError`] when the file cannot be written; the target is then left untouched.
pub fn write_parquet(
    path: &Path,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    task_id: &str,
) -> Result<(), OutputError> {
    atomic::write_atomically(path, |out| parquet::write(out, robot, task, plan, task_id))
}

/// [`write_parquet`] into a staged temporary file.
///
/// # Errors
/// As [`write_parquet`].
pub fn fill_parquet(
    staged: &mut Staged,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    task_id: &str,
) -> Result<(), OutputError> {
    staged.fill(|out| parquet::write(out, robot, task, plan, task_id))
}

/// The Parquet table of [`write_parquet`] as the bytes of a file, in memory.
///
/// # Errors
/// [`OutputError::Parquet`] when the table cannot be encoded.
pub fn parquet_bytes(
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    task_id: &str,
) -> Result<Vec<u8>, OutputError> {
    parquet::to_bytes(robot, task, plan, task_id).map_err(|e| e.at(Path::new("<memory>")))
}

/// Writes `text` to `path` through a temporary file (figures, reports).
///
/// # Errors
/// [`OutputError::Io`] when the file cannot be written; the target is then left untouched.
pub fn write_text(path: &Path, text: &str) -> Result<(), OutputError> {
    write_bytes(path, text.as_bytes())
}

/// Writes `bytes` to `path` through a temporary file (PNG images).
///
/// # Errors
/// As [`write_text`].
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    atomic::write_atomically(path, |out| {
        std::io::Write::write_all(out, bytes)?;
        Ok(())
    })
}
