//! Reading a written plan back: the joint trajectory of an MCAP recording (with the URDF and
//! task attached to it, the segment records, the references, the distances and the reference
//! wrist path) or of a CSV table. The MCAP is read through the mcap crate's reader, so chunk
//! compression does not matter; what is read are the `/joint_states`, `/a2ml/segments`,
//! `/a2ml/reference`, `/a2ml/distances` and `/wrist_path` topics, the `.urdf` / `.a2ml`
//! attachments and the metadata.

use std::path::Path;

use serde::Deserialize;
use serde_json::Value;

use super::topics;
use crate::decompose::ActionType;
use crate::language::{Obstacle, Shape, SolverChoice, Variable};
use crate::math::{DOF, JointVector, Real, Rotation3, UnitQuaternion, Vector3};
use crate::solve::{Plan, ReferenceSample, ReferenceState, SegmentReport};
use crate::trajectory::{CapsuleDistances, Trajectory, TrajectoryError};

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

/// One segment's record in a recording: which action and segment, when, how it was solved
/// and where its references end.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedSegment {
    /// The action's name.
    pub action: String,
    /// The action's index in the task.
    pub action_index: usize,
    /// The segment's index within its action (0-based).
    pub segment: usize,
    /// The action's type (`None` for explicit segments).
    pub action_type: Option<ActionType>,
    /// The solver that produced the motion.
    pub solver: Option<SolverChoice>,
    /// The variables of the segment's featured primitive.
    pub focus: Vec<Variable>,
    /// Start (s).
    pub start: Real,
    /// End (s).
    pub end: Real,
    /// The references at the segment's end (empty in a recording without them).
    pub reference_end: ReferenceState,
}

impl RecordedSegment {
    /// The record of a segment report and its references' end.
    pub fn of(report: &SegmentReport, reference_end: ReferenceState) -> Self {
        Self {
            action: report.action.clone(),
            action_index: report.action_index,
            segment: report.segment,
            action_type: report.action_type,
            solver: Some(report.solver),
            focus: report.focus.clone(),
            start: report.start,
            end: report.end,
            reference_end,
        }
    }
}

/// A plan read back from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedPlan {
    /// The task's name, from the recording's metadata.
    pub task: Option<String>,
    /// The joint names, in the order of q.
    pub joint_names: Vec<String>,
    /// Time (s), q (rad), q' (rad/s) per sample.
    pub trajectory: Trajectory,
    /// The segment records (none in a CSV table).
    pub segments: Vec<RecordedSegment>,
    /// The running segment's references per sample (none in a CSV table).
    pub references: Vec<ReferenceSample>,
    /// Every capsule-obstacle distance per sample (none in a CSV table).
    pub distances: Vec<CapsuleDistances>,
    /// The reference wrist path in {b} (m).
    pub wrist_reference: Vec<Vector3>,
    /// The task's obstacles in {b}, as the scene channel draws them.
    pub obstacles: Vec<Obstacle>,
    /// The safety distance the solvers kept (m), from the metadata.
    pub safety_distance: Option<Real>,
    /// The URDF attached to the recording.
    pub urdf: Option<String>,
    /// The task source attached to the recording.
    pub task_source: Option<String>,
}

impl RecordedPlan {
    /// A plan as it reads back from its MCAP recording, but for what the plan does not hold:
    /// the scene (empty here) and the attachments.
    pub fn of(plan: &Plan) -> Self {
        let ends = |i: usize| plan.reference_ends.get(i).copied().unwrap_or_default();
        Self {
            task: Some(plan.task.clone()),
            joint_names: plan.joint_names.clone(),
            trajectory: plan.trajectory.clone(),
            segments: plan
                .segments
                .iter()
                .enumerate()
                .map(|(i, s)| RecordedSegment::of(s, ends(i)))
                .collect(),
            references: plan.references.clone(),
            distances: plan.distances.clone(),
            wrist_reference: plan.wrist_reference.iter().map(|(_, p)| *p).collect(),
            obstacles: Vec::new(),
            safety_distance: Some(plan.safety_distance),
            urdf: None,
            task_source: None,
        }
    }

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
    /// The exact plan time (s); recordings without it give the log time only.
    time: Option<Real>,
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
    let mut metadata = std::collections::BTreeMap::new();
    for record in mcap::read::LinearReader::new(bytes).map_err(mcap_error)? {
        match record.map_err(mcap_error)? {
            mcap::records::Record::Attachment { header, data, .. } => {
                let text = String::from_utf8_lossy(&data).into_owned();
                if header.name.ends_with(".urdf") {
                    urdf = Some(text);
                } else if header.name.ends_with(".a2ml") {
                    task_source = Some(text);
                }
            }
            mcap::records::Record::Metadata(m) if m.name == "a2ml" => metadata = m.metadata,
            _ => {}
        }
    }
    let (mut times, mut positions, mut velocities) = (Vec::new(), Vec::new(), Vec::new());
    let mut joint_names: Option<Vec<String>> = None;
    let mut segments = Vec::new();
    let mut references = Vec::new();
    let mut distances: Vec<CapsuleDistances> = Vec::new();
    let mut wrist_reference = Vec::new();
    let mut obstacles = Vec::new();
    for message in mcap::MessageStream::new(bytes).map_err(mcap_error)? {
        let message = message.map_err(mcap_error)?;
        let topic = message.channel.topic.as_str();
        let value = || -> Result<Value, String> {
            serde_json::from_slice(&message.data).map_err(|e| e.to_string())
        };
        match topic {
            topics::JOINT_STATES => {
                let index = times.len();
                let err = |m: String| message_error(topics::JOINT_STATES, index, m);
                let state: JointStateMessage =
                    serde_json::from_slice(&message.data).map_err(|e| err(e.to_string()))?;
                positions.push(joint_vector(&state.position).map_err(err)?);
                velocities.push(joint_vector(&state.velocity).map_err(err)?);
                times.push(state.time.unwrap_or(message.log_time as Real / 1e9));
                if joint_names.is_none() {
                    joint_names = Some(state.name);
                }
            }
            topics::SEGMENTS => {
                let err = |m: String| message_error(topics::SEGMENTS, segments.len(), m);
                segments.push(value().and_then(|v| segment_record(&v)).map_err(err)?);
            }
            topics::REFERENCE => {
                let err = |m: String| message_error(topics::REFERENCE, references.len(), m);
                references.push(value().and_then(|v| reference_sample(&v)).map_err(err)?);
            }
            topics::DISTANCES => {
                let index = distances.first().map_or(0, |d| d.distance.len());
                let err = |m: String| message_error(topics::DISTANCES, index, m);
                value().and_then(|v| add_distances(&mut distances, &v)).map_err(err)?;
            }
            topics::WRIST_PATH => {
                let err = |m: String| message_error(topics::WRIST_PATH, 0, m);
                wrist_reference = value().and_then(|v| reference_path(&v)).map_err(err)?;
            }
            topics::SCENE => {
                let err = |m: String| message_error(topics::SCENE, 0, m);
                obstacles = value().and_then(|v| scene_obstacles(&v)).map_err(err)?;
            }
            _ => {}
        }
    }
    let Some(joint_names) = joint_names else {
        return Err(ReadError::NoJointStates { path: path.to_owned() });
    };
    let trajectory = Trajectory::new(times, positions, velocities)
        .map_err(|source| ReadError::Trajectory { path: path.to_owned(), source })?;
    Ok(RecordedPlan {
        task: metadata.get("task").cloned(),
        joint_names,
        trajectory,
        segments,
        references,
        distances,
        wrist_reference,
        obstacles,
        safety_distance: metadata.get("safety_distance_m").and_then(|d| d.parse().ok()),
        urdf,
        task_source,
    })
}

/// The value among `candidates` that serialises as `value` (so that the spellings are the
/// writer's, whatever they are).
/// The enum value a JSON string spells ([`crate::spelling`]).
fn spelled<T: crate::spelling::Spelled>(value: &Value) -> Option<T> {
    value.as_str().and_then(|text| crate::spelling::parse(text).ok())
}

fn field<'v>(value: &'v Value, name: &str) -> Result<&'v Value, String> {
    value.get(name).ok_or_else(|| format!("no `{name}`"))
}

fn number(value: &Value, name: &str) -> Result<Real, String> {
    field(value, name)?.as_f64().ok_or_else(|| format!("`{name}` is not a number"))
}

fn index(value: &Value, name: &str) -> Result<usize, String> {
    field(value, name)?
        .as_u64()
        .and_then(|i| usize::try_from(i).ok())
        .ok_or_else(|| format!("`{name}` is not an index"))
}

fn text(value: &Value, name: &str) -> Result<String, String> {
    Ok(field(value, name)?.as_str().ok_or_else(|| format!("`{name}` is not text"))?.to_owned())
}

fn xyz(value: &Value) -> Option<Vector3> {
    Some(Vector3::new(value["x"].as_f64()?, value["y"].as_f64()?, value["z"].as_f64()?))
}

fn quaternion(value: &Value) -> Option<UnitQuaternion> {
    let [x, y, z, w] = ["x", "y", "z", "w"].map(|k| value[k].as_f64());
    Some(UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(w?, x?, y?, z?)))
}

/// A reference state's fields, each absent where the message leaves it out.
fn reference_state(value: &Value) -> ReferenceState {
    ReferenceState {
        pw: value.get("pw").and_then(xyz),
        ow: value.get("ow").and_then(quaternion),
        swivel: value.get("swivel").and_then(Value::as_f64),
        shoulder_frame: value.get("shoulder_frame").and_then(quaternion),
        elbow_angle: value.get("elbow_angle").and_then(Value::as_f64),
    }
}

fn reference_sample(value: &Value) -> Result<ReferenceSample, String> {
    Ok(ReferenceSample { segment: index(value, "segment")?, state: reference_state(value) })
}

fn segment_record(value: &Value) -> Result<RecordedSegment, String> {
    let focus = field(value, "focus")?
        .as_array()
        .ok_or("`focus` is not a list")?
        .iter()
        .map(|v| spelled::<Variable>(v).ok_or_else(|| format!("unknown variable {v}")))
        .collect::<Result<_, _>>()?;
    Ok(RecordedSegment {
        action: text(value, "action")?,
        action_index: index(value, "action_index")?,
        segment: index(value, "segment")?,
        action_type: value.get("action_type").and_then(spelled::<ActionType>),
        solver: spelled::<SolverChoice>(field(value, "solver")?),
        focus,
        start: number(value, "start")?,
        end: number(value, "end")?,
        reference_end: value.get("reference_end").map(reference_state).unwrap_or_default(),
    })
}

/// Appends one sample's distances, pair by pair (the pairs are the first message's).
fn add_distances(series: &mut Vec<CapsuleDistances>, value: &Value) -> Result<(), String> {
    let pairs = field(value, "distances")?.as_array().ok_or("`distances` is not a list")?;
    if series.is_empty() {
        for pair in pairs {
            series.push(CapsuleDistances {
                capsule: text(pair, "capsule")?,
                capsule_index: index(pair, "capsule_index")?,
                obstacle: text(pair, "obstacle")?,
                distance: Vec::new(),
            });
        }
    }
    if pairs.len() != series.len() {
        return Err(format!("{} pairs, the first sample has {}", pairs.len(), series.len()));
    }
    for (s, pair) in series.iter_mut().zip(pairs) {
        s.distance.push(pair.get("distance").and_then(Value::as_f64));
    }
    Ok(())
}

/// The obstacles of the scene channel: each entity's shape from its primitives, as
/// `messages::obstacles` draws them.
fn scene_obstacles(value: &Value) -> Result<Vec<Obstacle>, String> {
    let entities = field(value, "entities")?.as_array().ok_or("`entities` is not a list")?;
    entities.iter().map(obstacle).collect()
}

fn obstacle(entity: &Value) -> Result<Obstacle, String> {
    let meta = |key: &str| {
        entity["metadata"]
            .as_array()
            .and_then(|m| m.iter().find(|kv| kv["key"] == key))
            .and_then(|kv| kv["value"].as_str())
            .ok_or_else(|| format!("an obstacle without its {key}"))
    };
    let (name, shape) = (meta("name")?.to_owned(), meta("shape")?);
    let primitive = |kind: &str, i: usize| -> Result<(Vector3, Vector3), String> {
        let p = &entity[kind][i];
        let at = xyz(&p["pose"]["position"]).ok_or_else(|| format!("`{name}`: no {kind} pose"))?;
        let size = xyz(&p["size"]).ok_or_else(|| format!("`{name}`: no {kind} size"))?;
        Ok((at, size))
    };
    // Boxes and cylinders are drawn turned by their rotation; spheres and a capsule's
    // end spheres need none.
    let rotation = |kind: &str| -> Result<Rotation3, String> {
        let q = quaternion(&entity[kind][0]["pose"]["orientation"])
            .ok_or_else(|| format!("`{name}`: no {kind} orientation"))?;
        Ok(UnitQuaternion::new_normalize(q.into_inner()).to_rotation_matrix())
    };
    let shape = match shape {
        "box" => {
            let (center, size) = primitive("cubes", 0)?;
            Shape::Box { center, size, rotation: rotation("cubes")? }
        }
        "sphere" => {
            let (center, size) = primitive("spheres", 0)?;
            Shape::Sphere { center, radius: 0.5 * size.x }
        }
        "capsule" => {
            let ((a, size), (b, _)) = (primitive("spheres", 0)?, primitive("spheres", 1)?);
            Shape::Capsule { a, b, radius: 0.5 * size.x }
        }
        "cylinder" => {
            let (center, size) = primitive("cylinders", 0)?;
            let rotation = rotation("cylinders")?;
            Shape::Cylinder { center, radius: 0.5 * size.x, height: size.z, rotation }
        }
        other => return Err(format!("`{name}`: unknown shape {other}")),
    };
    Ok(Obstacle { name, shape })
}

/// The points of the reference wrist path's line.
fn reference_path(value: &Value) -> Result<Vec<Vector3>, String> {
    let entities = field(value, "entities")?.as_array().ok_or("`entities` is not a list")?;
    let Some(entity) = entities.iter().find(|e| e["id"] == "wrist/reference") else {
        return Ok(Vec::new());
    };
    let points = entity["lines"][0]["points"].as_array().ok_or("the path has no points")?;
    points.iter().map(|p| xyz(p).ok_or_else(|| format!("not a point: {p}"))).collect()
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

/// The joint names of a CSV header: `t`, then `<joint>_pos` × 7, then `<joint>_vel` × 7 (the
/// reference and distance columns after them are not read back).
fn csv_joint_names(header: &str) -> Result<Vec<String>, String> {
    let fields: Vec<String> =
        header.split(',').map(|f| f.trim().trim_matches('"').to_owned()).collect();
    if fields.len() < 1 + 2 * DOF || fields[0] != "t" {
        return Err(format!(
            "the header must start with `t`, {DOF} `<joint>_pos` and {DOF} `<joint>_vel` \
             columns; found {} columns",
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
            .take(1 + 2 * DOF)
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
    Ok(RecordedPlan {
        task: None,
        joint_names,
        trajectory,
        segments: Vec::new(),
        references: Vec::new(),
        distances: Vec::new(),
        wrist_reference: Vec::new(),
        obstacles: Vec::new(),
        safety_distance: None,
        urdf: None,
        task_source: None,
    })
}
