//! The MCAP recording: channels, attachments, metadata and the messages in time order. The
//! mcap crate enters here only.

use std::collections::BTreeMap;
use std::io::{Seek, Write};

use mcap::records::{MessageHeader, Metadata};
use mcap::{Attachment, Compression, McapError, WriteOptions, Writer};
use serde::Serialize;

use super::atomic::Failure;
use super::messages::{self, JointLimits, ReferenceSeries, StateSeries, Time};
use super::schemas::{self, Schema};
use super::topics;
use crate::kinematics::{arm_pose, cpsa_state, hat_state, link_poses};
use crate::language::Task;
use crate::math::{Real, Vector3};
use crate::robot::Robot;
use crate::solve::{Plan, ReferenceState, SegmentReport};

const JSON: &str = "json";
const JSON_SCHEMA: &str = "jsonschema";

impl From<McapError> for Failure {
    fn from(e: McapError) -> Self {
        match e {
            McapError::Io(e) => Self::Io(e),
            other => Self::Mcap(other.to_string()),
        }
    }
}

/// Plan time to MCAP time: nanoseconds from the plan's time 0 (or from its first sample, if
/// that is earlier, since MCAP times are unsigned).
#[derive(Debug, Clone, Copy)]
struct Clock {
    origin: Real,
}

impl Clock {
    fn of(plan: &Plan) -> Self {
        Self { origin: plan.trajectory.start().min(0.0) }
    }

    fn nanos(self, t: Real) -> u64 {
        // `as` saturates: a time before the origin is 0.
        ((t - self.origin) * 1e9).round() as u64
    }
}

/// A channel and the sequence number of its next message.
struct Topic {
    id: u16,
    sequence: u32,
}

struct Topics {
    joint_states: Topic,
    tf: Topic,
    scene: Topic,
    arm_capsules: Topic,
    wrist_path: Topic,
    state: Topic,
    reference: Topic,
    distances: Topic,
    segments: Topic,
    robot_description: Topic,
}

fn add_topic<W: Write + Seek>(
    writer: &mut Writer<W>,
    topic: &str,
    schema: &Schema,
) -> Result<Topic, Failure> {
    let data = serde_json::to_vec(&schema.body)?;
    let schema_id = writer.add_schema(schema.name, JSON_SCHEMA, &data)?;
    let id = writer.add_channel(schema_id, topic, JSON, &BTreeMap::new())?;
    Ok(Topic { id, sequence: 0 })
}

fn add_topics<W: Write + Seek>(writer: &mut Writer<W>) -> Result<Topics, Failure> {
    let scene = schemas::scene_update();
    Ok(Topics {
        joint_states: add_topic(writer, topics::JOINT_STATES, &schemas::joint_state())?,
        tf: add_topic(writer, topics::TF, &schemas::frame_transforms())?,
        scene: add_topic(writer, topics::SCENE, &scene)?,
        arm_capsules: add_topic(writer, topics::ARM_CAPSULES, &scene)?,
        wrist_path: add_topic(writer, topics::WRIST_PATH, &scene)?,
        state: add_topic(writer, topics::STATE, &schemas::state())?,
        reference: add_topic(writer, topics::REFERENCE, &schemas::reference())?,
        distances: add_topic(writer, topics::DISTANCES, &schemas::distances())?,
        segments: add_topic(writer, topics::SEGMENTS, &schemas::segment())?,
        robot_description: add_topic(
            writer,
            topics::ROBOT_DESCRIPTION,
            &schemas::robot_description(),
        )?,
    })
}

/// Writes one JSON message with log time = publish time = `nanos`.
fn publish<W: Write + Seek>(
    writer: &mut Writer<W>,
    topic: &mut Topic,
    nanos: u64,
    message: &impl Serialize,
) -> Result<(), Failure> {
    let data = serde_json::to_vec(message)?;
    let header = MessageHeader {
        channel_id: topic.id,
        sequence: topic.sequence,
        log_time: nanos,
        publish_time: nanos,
    };
    topic.sequence = topic.sequence.wrapping_add(1);
    writer.write_to_known_channel(&header, &data)?;
    Ok(())
}

fn attach<W: Write + Seek>(
    writer: &mut Writer<W>,
    name: String,
    media_type: &str,
    data: &[u8],
) -> Result<(), Failure> {
    let attachment = Attachment {
        log_time: 0,
        create_time: 0,
        name,
        media_type: media_type.to_owned(),
        data: data.into(),
    };
    writer.attach(&attachment)?;
    Ok(())
}

fn metadata(robot: &Robot, task: &Task, plan: &Plan) -> Metadata {
    let mut entries = BTreeMap::from([
        ("task".to_owned(), task.name.clone()),
        ("robot".to_owned(), robot.name.clone()),
        ("a2ml_version".to_owned(), env!("CARGO_PKG_VERSION").to_owned()),
        ("rate_hz".to_owned(), plan.rate.to_string()),
        ("reached".to_owned(), plan.reached().to_string()),
        ("safety_distance_m".to_owned(), plan.safety_distance.to_string()),
    ]);
    if !plan.warnings.is_empty() {
        let lines: Vec<String> = plan.warnings.iter().map(ToString::to_string).collect();
        entries.insert("warnings".to_owned(), lines.join("\n"));
    }
    Metadata { name: "a2ml".to_owned(), metadata: entries }
}

/// The segments with their references' ends, in start order (stable for equal starts).
fn by_start(plan: &Plan) -> Vec<(&SegmentReport, Option<&ReferenceState>)> {
    let mut sorted: Vec<(&SegmentReport, Option<&ReferenceState>)> =
        plan.segments.iter().enumerate().map(|(i, s)| (s, plan.reference_ends.get(i))).collect();
    sorted.sort_by(|a, b| a.0.start.total_cmp(&b.0.start));
    sorted
}

/// Writes the whole recording to `out`.
pub(super) fn write<W: Write + Seek>(
    out: W,
    robot: &Robot,
    task: &Task,
    source: &str,
    plan: &Plan,
) -> Result<(), Failure> {
    // zstd on one thread: the compressed bytes then depend on the plan only, not on the
    // machine's core count.
    let options = WriteOptions::new().compression(Some(Compression::Zstd)).compression_threads(0);
    let mut writer = options.create(out)?;
    attach(&mut writer, format!("{}.a2ml", task.name), "text/plain", source.as_bytes())?;
    attach(&mut writer, format!("{}.urdf", robot.name), "application/xml", robot.urdf.as_bytes())?;
    writer.write_metadata(&metadata(robot, task, plan))?;
    let mut topics = add_topics(&mut writer)?;
    write_static(&mut writer, &mut topics, robot, task, plan)?;
    write_samples(&mut writer, &mut topics, robot, plan)?;
    writer.finish()?;
    Ok(())
}

/// The messages published once, at the first sample: the robot's URDF, the arm's capsules
/// (attached to their links), the obstacles and the wrist paths.
fn write_static<W: Write + Seek>(
    writer: &mut Writer<W>,
    topics: &mut Topics,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
) -> Result<(), Failure> {
    let nanos = Clock::of(plan).nanos(plan.trajectory.start());
    let time = Time::from_nanos(nanos);
    let description = messages::robot_description(robot);
    publish(writer, &mut topics.robot_description, nanos, &description)?;
    publish(writer, &mut topics.arm_capsules, nanos, &messages::arm_capsules(time, robot))?;
    let scene = task.in_base_frame(&robot.structure.shoulder_in_base_link).scene;
    publish(writer, &mut topics.scene, nanos, &messages::obstacles(time, &scene))?;
    let planned: Vec<Vector3> =
        plan.trajectory.positions().iter().map(|q| arm_pose(robot, q).wrist).collect();
    let reference: Vec<Vector3> = plan.wrist_reference.iter().map(|(_, p)| *p).collect();
    let paths = messages::wrist_paths(time, &planned, &reference);
    publish(writer, &mut topics.wrist_path, nanos, &paths)
}

/// The per-sample messages, with each segment's record interleaved at its start time.
fn write_samples<W: Write + Seek>(
    writer: &mut Writer<W>,
    topics: &mut Topics,
    robot: &Robot,
    plan: &Plan,
) -> Result<(), Failure> {
    let clock = Clock::of(plan);
    let trajectory = &plan.trajectory;
    let mut segments = by_start(plan).into_iter().peekable();
    let mut series = StateSeries::default();
    let mut reference_series = ReferenceSeries::default();
    let (lower, upper) = (robot.lower(), robot.upper());
    let limits = JointLimits { lower: &lower, upper: &upper };
    let samples =
        trajectory.times().iter().zip(trajectory.positions()).zip(trajectory.velocities());
    for (k, ((&t, q), qd)) in samples.enumerate() {
        while let Some(segment) = segments.next_if(|s| s.0.start <= t) {
            write_segment(writer, &mut topics.segments, clock, segment)?;
        }
        let nanos = clock.nanos(t);
        let time = Time::from_nanos(nanos);
        let pose = arm_pose(robot, q);
        let joints = messages::joint_state((time, t), &plan.joint_names, q, qd, limits);
        publish(writer, &mut topics.joint_states, nanos, &joints)?;
        let names = robot.links.iter().map(|l| l.name.as_str());
        let tf = messages::frame_transforms(time, names.zip(link_poses(robot, &pose)));
        publish(writer, &mut topics.tf, nanos, &tf)?;
        let (cpsa, hat) = (cpsa_state(robot, &pose).ok(), hat_state(&pose).ok());
        let state = messages::state(time, cpsa.as_ref(), hat.as_ref(), &mut series);
        publish(writer, &mut topics.state, nanos, &state)?;
        if let Some(r) = plan.references.get(k) {
            let message =
                messages::reference_message(time, r.segment, &r.state, &mut reference_series);
            publish(writer, &mut topics.reference, nanos, &message)?;
        }
        if !plan.distances.is_empty() {
            let message = messages::distances(time, &plan.distances, k);
            publish(writer, &mut topics.distances, nanos, &message)?;
        }
    }
    for segment in segments {
        write_segment(writer, &mut topics.segments, clock, segment)?;
    }
    Ok(())
}

fn write_segment<W: Write + Seek>(
    writer: &mut Writer<W>,
    topic: &mut Topic,
    clock: Clock,
    (segment, reference_end): (&SegmentReport, Option<&ReferenceState>),
) -> Result<(), Failure> {
    let nanos = clock.nanos(segment.start);
    let message = messages::segment(Time::from_nanos(nanos), segment, reference_end)?;
    publish(writer, topic, nanos, &message)
}
