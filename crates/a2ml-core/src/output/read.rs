//! Reading a written plan back: the joint trajectory of an MCAP recording (with the URDF and
//! task attached to it, and the segment records) or of a CSV table. The MCAP is read through
//! the mcap crate's reader, so chunk compression does not matter; what is read are the
//! `/joint_states` and `/a2ml/segments` topics and the `.urdf` / `.a2ml` attachments.

use std::path::Path;

use serde::Deserialize;

use super::topics;
use crate::math::{DOF, JointVector, Real};
use crate::trajectory::{Trajectory, TrajectoryError};

/// Why a plan cannot be read back.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReadError {
    /// The file cannot be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// The path as given.
        path: String,
        /// The OS message.
        message: String,
    },
    /// The MCAP container is malformed (or compressed in a way this build cannot read).
    #[error("{path}: not a readable MCAP file: {message}")]
    Mcap {
        /// The path as given.
        path: String,
        /// The reader's message.
        message: String,
    },
    /// A message of a known topic does not hold what its schema says.
    #[error("{path}: message {index} on {topic}: {message}")]
    Message {
        /// The path as given.
        path: String,
        /// The topic.
        topic: &'static str,
        /// Index of the message on its topic (0-based).
        index: usize,
        /// What is wrong.
        message: String,
    },
    /// The recording has no joint state.
    #[error("{path}: no message on {}: not an a2ml plan", topics::JOINT_STATES)]
    NoJointStates {
        /// The path as given.
        path: String,
    },
    /// A CSV line is malformed.
    #[error("{path}:{line}: {message}")]
    Csv {
        /// The path as given.
        path: String,
        /// Line number (1-based).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The samples do not make a trajectory (times not increasing, non-finite values).
    #[error("{path}: {source}")]
    Trajectory {
        /// The path as given.
        path: String,
        /// Why.
        source: TrajectoryError,
    },
    /// The plan's joints are not the robot's.
    #[error("the plan's joints {found:?} are not the robot's {expected:?}")]
    Joints {
        /// The robot's joint names.
        expected: Vec<String>,
        /// The plan's.
        found: Vec<String>,
    },
}

/// One segment's record in a recording: which action and segment, and when.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
pub struct RecordedSegment {
    /// The action's name.
    pub action: String,
    /// The segment's index within its action (0-based).
    pub segment: usize,
    /// Start (s).
    pub start: Real,
    /// End (s).
    pub end: Real,
}

/// A plan read back from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedPlan {
    /// The joint names, in the order of q.
    pub joint_names: Vec<String>,
    /// Time (s), q (rad), q' (rad/s) per sample.
    pub trajectory: Trajectory,
    /// The segment records (none in a CSV table).
    pub segments: Vec<RecordedSegment>,
    /// The URDF attached to the recording.
    pub urdf: Option<String>,
    /// The task source attached to the recording.
    pub task_source: Option<String>,
}

impl RecordedPlan {
    /// Checks that the plan's joints are `robot_joints`, in that order.
    ///
    /// # Errors
    /// [`ReadError::Joints`] otherwise.
    pub fn check_joints(&self, robot_joints: &[&str]) -> Result<(), ReadError> {
        if self.joint_names.iter().map(String::as_str).eq(robot_joints.iter().copied()) {
            return Ok(());
        }
        Err(ReadError::Joints {
            expected: robot_joints.iter().map(|s| (*s).to_owned()).collect(),
            found: self.joint_names.clone(),
        })
    }
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, ReadError> {
    std::fs::read(path)
        .map_err(|e| ReadError::Io { path: path.display().to_string(), message: e.to_string() })
}

#[derive(Deserialize)]
struct JointStateMessage {
    name: Vec<String>,
    position: Vec<Real>,
    velocity: Vec<Real>,
}

fn joint_vector(values: &[Real]) -> Result<JointVector, String> {
    if values.len() != DOF {
        return Err(format!("{} values, expected {DOF}", values.len()));
    }
    Ok(JointVector::from_column_slice(values))
}

/// Reads the plan of an MCAP file written by [`super::write_mcap`].
///
/// # Errors
/// [`ReadError`] when the file cannot be read, is not MCAP, or its messages are malformed.
pub fn read_mcap(path: &Path) -> Result<RecordedPlan, ReadError> {
    read_mcap_bytes(&read_bytes(path)?, &path.display().to_string())
}

/// [`read_mcap`] on the bytes of a file; `path` names it in errors.
///
/// # Errors
/// As [`read_mcap`].
pub fn read_mcap_bytes(bytes: &[u8], path: &str) -> Result<RecordedPlan, ReadError> {
    let mcap_error =
        |e: mcap::McapError| ReadError::Mcap { path: path.to_owned(), message: e.to_string() };
    let message_error = |topic, index, message: String| ReadError::Message {
        path: path.to_owned(),
        topic,
        index,
        message,
    };
    let (mut urdf, mut task_source) = (None, None);
    for record in mcap::read::LinearReader::new(bytes).map_err(mcap_error)? {
        if let mcap::records::Record::Attachment { header, data, .. } = record.map_err(mcap_error)? {
            let text = String::from_utf8_lossy(&data).into_owned();
            if header.name.ends_with(".urdf") {
                urdf = Some(text);
            } else if header.name.ends_with(".a2ml") {
                task_source = Some(text);
            }
        }
    }
    let (mut times, mut positions, mut velocities) = (Vec::new(), Vec::new(), Vec::new());
    let mut joint_names: Option<Vec<String>> = None;
    let mut segments = Vec::new();
    for message in mcap::MessageStream::new(bytes).map_err(mcap_error)? {
        let message = message.map_err(mcap_error)?;
        match message.channel.topic.as_str() {
            topics::JOINT_STATES => {
                let index = times.len();
                let err = |m: String| message_error(topics::JOINT_STATES, index, m);
                let state: JointStateMessage =
                    serde_json::from_slice(&message.data).map_err(|e| err(e.to_string()))?;
                positions.push(joint_vector(&state.position).map_err(err)?);
                velocities.push(joint_vector(&state.velocity).map_err(err)?);
                times.push(message.log_time as Real * 1e-9);
                if joint_names.is_none() {
                    joint_names = Some(state.name);
                }
            }
            topics::SEGMENTS => {
                let segment: RecordedSegment = serde_json::from_slice(&message.data)
                    .map_err(|e| message_error(topics::SEGMENTS, segments.len(), e.to_string()))?;
                segments.push(segment);
            }
            _ => {}
        }
    }
    let Some(joint_names) = joint_names else {
        return Err(ReadError::NoJointStates { path: path.to_owned() });
    };
    let trajectory = Trajectory::new(times, positions, velocities)
        .map_err(|source| ReadError::Trajectory { path: path.to_owned(), source })?;
    Ok(RecordedPlan { joint_names, trajectory, segments, urdf, task_source })
}

/// Reads the joint trajectory of a CSV table written by [`super::write_csv`].
///
/// # Errors
/// [`ReadError::Io`], [`ReadError::Csv`] (a located problem), [`ReadError::Trajectory`].
pub fn read_csv(path: &Path) -> Result<RecordedPlan, ReadError> {
    let name = path.display().to_string();
    let text = String::from_utf8(read_bytes(path)?).map_err(|_| ReadError::Csv {
        path: name.clone(),
        line: 1,
        message: "not UTF-8 text".to_owned(),
    })?;
    read_csv_str(&text, &name)
}

/// The joint names of a CSV header: `t`, then `<joint>_pos` × 7, then `<joint>_vel` × 7.
fn csv_joint_names(header: &str) -> Result<Vec<String>, String> {
    let fields: Vec<String> = header.split(',').map(|f| f.trim().trim_matches('"').to_owned()).collect();
    if fields.len() != 1 + 2 * DOF || fields[0] != "t" {
        return Err(format!(
            "the header must be `t`, {DOF} `<joint>_pos` and {DOF} `<joint>_vel` columns; found {} \
             columns",
            fields.len()
        ));
    }
    let mut names = Vec::with_capacity(DOF);
    for k in 0..DOF {
        let (pos, vel) = (&fields[1 + k], &fields[1 + DOF + k]);
        match (pos.strip_suffix("_pos"), vel.strip_suffix("_vel")) {
            (Some(a), Some(b)) if a == b => names.push(a.to_owned()),
            _ => return Err(format!("columns `{pos}` and `{vel}` do not name one joint")),
        }
    }
    Ok(names)
}

/// [`read_csv`] on the text of a table; `path` names it in errors.
///
/// # Errors
/// As [`read_csv`].
pub fn read_csv_str(text: &str, path: &str) -> Result<RecordedPlan, ReadError> {
    let csv_error =
        |line: usize, message: String| ReadError::Csv { path: path.to_owned(), line, message };
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err(csv_error(1, "the table is empty".to_owned()));
    };
    let joint_names = csv_joint_names(header).map_err(|m| csv_error(1, m))?;
    let (mut times, mut positions, mut velocities) = (Vec::new(), Vec::new(), Vec::new());
    for (index, line) in lines {
        let values: Vec<Real> = line
            .split(',')
            .map(|f| f.trim().parse::<Real>())
            .collect::<Result<_, _>>()
            .map_err(|e| csv_error(index + 1, format!("not a number: {e}")))?;
        if values.len() != 1 + 2 * DOF {
            let message = format!("{} values, expected {}", values.len(), 1 + 2 * DOF);
            return Err(csv_error(index + 1, message));
        }
        times.push(values[0]);
        positions.push(JointVector::from_column_slice(&values[1..=DOF]));
        velocities.push(JointVector::from_column_slice(&values[1 + DOF..]));
    }
    let trajectory = Trajectory::new(times, positions, velocities)
        .map_err(|source| ReadError::Trajectory { path: path.to_owned(), source })?;
    Ok(RecordedPlan { joint_names, trajectory, segments: Vec::new(), urdf: None, task_source: None })
}
