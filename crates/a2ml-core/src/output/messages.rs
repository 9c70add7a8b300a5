//! The messages of the MCAP channels as serde types, and the pure functions that build them
//! from the plan's samples. Field names and layouts follow the schemas in `schemas.rs`.

use serde::Serialize;

use crate::kinematics::{CpsaState, HatState};
use crate::language::{Obstacle, Shape};
use crate::math::{Isometry, JointVector, Real, Rotation3, UnitQuaternion, Vector3};
use crate::robot::{LinkRole, Robot};
use crate::solve::{ReferenceState, SegmentReport};
use crate::trajectory::CapsuleDistances;

/// The frame every position is given in: {b}, origin at the shoulder centre.
pub(super) const BASE_FRAME: &str = "b";

const NANOS_PER_SECOND: u64 = 1_000_000_000;
/// Line width of the wrist paths (m).
const PATH_THICKNESS: Real = 0.004;
const OBSTACLE_COLOR: Color = Color { r: 0.85, g: 0.35, b: 0.3, a: 0.6 };
const PLANNED_PATH_COLOR: Color = Color { r: 0.1, g: 0.5, b: 0.95, a: 1.0 };
const REFERENCE_PATH_COLOR: Color = Color { r: 0.95, g: 0.6, b: 0.1, a: 1.0 };

/// A time as Foxglove writes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub(super) struct Time {
    sec: u64,
    nsec: u64,
}

impl Time {
    /// From nanoseconds.
    pub fn from_nanos(nanos: u64) -> Self {
        Self { sec: nanos / NANOS_PER_SECOND, nsec: nanos % NANOS_PER_SECOND }
    }

    const ZERO: Time = Time { sec: 0, nsec: 0 };
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
struct Xyz {
    x: Real,
    y: Real,
    z: Real,
}

impl From<&Vector3> for Xyz {
    fn from(v: &Vector3) -> Self {
        Self { x: v.x, y: v.y, z: v.z }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
struct Quaternion {
    x: Real,
    y: Real,
    z: Real,
    w: Real,
}

impl From<&UnitQuaternion> for Quaternion {
    fn from(q: &UnitQuaternion) -> Self {
        Self { x: q.i, y: q.j, z: q.k, w: q.w }
    }
}

impl From<&Rotation3> for Quaternion {
    fn from(r: &Rotation3) -> Self {
        Self::from(&UnitQuaternion::from_rotation_matrix(r))
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
struct Pose {
    position: Xyz,
    orientation: Quaternion,
}

impl Pose {
    fn at(position: &Vector3) -> Self {
        Self::new(position, &UnitQuaternion::identity())
    }

    fn new(position: &Vector3, orientation: &UnitQuaternion) -> Self {
        Self { position: position.into(), orientation: orientation.into() }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
struct Color {
    r: Real,
    g: Real,
    b: Real,
    a: Real,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
struct KeyValue {
    key: &'static str,
    value: String,
}

/// `a2ml.JointState`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(super) struct JointState<'a> {
    timestamp: Time,
    time: Real,
    name: &'a [String],
    position: &'a [Real],
    velocity: &'a [Real],
    lower: &'a [Real],
    upper: &'a [Real],
}

/// The joint position limits (rad), repeated in every joint state so that a plot draws them
/// beside the positions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct JointLimits<'a> {
    /// Lower limits, in the order of q.
    pub lower: &'a JointVector,
    /// Upper limits.
    pub upper: &'a JointVector,
}

/// The joint state of one sample.
pub(super) fn joint_state<'a>(
    (time, t): (Time, Real),
    names: &'a [String],
    q: &'a JointVector,
    qd: &'a JointVector,
    limits: JointLimits<'a>,
) -> JointState<'a> {
    JointState {
        timestamp: time,
        time: t,
        name: names,
        position: q.as_slice(),
        velocity: qd.as_slice(),
        lower: limits.lower.as_slice(),
        upper: limits.upper.as_slice(),
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
struct FrameTransform<'a> {
    timestamp: Time,
    parent_frame_id: &'a str,
    child_frame_id: &'a str,
    translation: Xyz,
    rotation: Quaternion,
}

/// `foxglove.FrameTransforms`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(super) struct FrameTransforms<'a> {
    transforms: Vec<FrameTransform<'a>>,
}

/// The links of a chain as a tree of transforms, as a URDF viewer expects them: the first
/// link from frame "b", every other one from the link before it. `links` are the links' names
/// and poses in {b}, base to tip.
pub(super) fn frame_transforms<'a>(
    time: Time,
    links: impl IntoIterator<Item = (&'a str, Isometry)>,
) -> FrameTransforms<'a> {
    let mut parent: (&str, Isometry) = (BASE_FRAME, Isometry::identity());
    let transforms = links
        .into_iter()
        .map(|(name, b_from_link)| {
            let parent_from_link = parent.1.inv_mul(&b_from_link);
            let transform = FrameTransform {
                timestamp: time,
                parent_frame_id: parent.0,
                child_frame_id: name,
                translation: (&parent_from_link.translation.vector).into(),
                rotation: (&parent_from_link.rotation).into(),
            };
            parent = (name, b_from_link);
            transform
        })
        .collect();
    FrameTransforms { transforms }
}

/// Cube and sphere: a pose, the full extent along each axis, a colour.
#[derive(Debug, Clone, PartialEq, Serialize)]
struct Solid {
    pose: Pose,
    size: Xyz,
    color: Color,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
struct Cylinder {
    pose: Pose,
    size: Xyz,
    bottom_scale: Real,
    top_scale: Real,
    color: Color,
}

/// Foxglove's `LineType::LINE_STRIP`.
const LINE_STRIP: u32 = 0;

#[derive(Debug, Clone, PartialEq, Serialize)]
struct Line {
    #[serde(rename = "type")]
    kind: u32,
    pose: Pose,
    thickness: Real,
    scale_invariant: bool,
    points: Vec<Xyz>,
    color: Color,
    colors: Vec<Color>,
    indices: Vec<u32>,
}

/// Primitives a2ml does not draw; Foxglove's schema still requires their arrays.
type Unused = [(); 0];

/// `foxglove.SceneEntity`, kept until replaced.
#[derive(Debug, Clone, PartialEq, Serialize)]
struct SceneEntity {
    timestamp: Time,
    frame_id: String,
    id: String,
    lifetime: Time,
    frame_locked: bool,
    metadata: Vec<KeyValue>,
    arrows: Unused,
    cubes: Vec<Solid>,
    spheres: Vec<Solid>,
    cylinders: Vec<Cylinder>,
    lines: Vec<Line>,
    triangles: Unused,
    texts: Unused,
    models: Unused,
}

impl SceneEntity {
    /// An empty entity in frame "b".
    fn new(time: Time, id: String, metadata: Vec<KeyValue>) -> Self {
        Self {
            timestamp: time,
            frame_id: BASE_FRAME.to_owned(),
            id,
            lifetime: Time::ZERO,
            frame_locked: false,
            metadata,
            arrows: [],
            cubes: Vec::new(),
            spheres: Vec::new(),
            cylinders: Vec::new(),
            lines: Vec::new(),
            triangles: [],
            texts: [],
            models: [],
        }
    }
}

/// `foxglove.SceneUpdate` (a2ml never deletes: entities are replaced by id).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(super) struct SceneUpdate {
    deletions: Unused,
    entities: Vec<SceneEntity>,
}

fn ball(center: &Vector3, radius: Real, color: Color) -> Solid {
    let d = 2.0 * radius;
    Solid { pose: Pose::at(center), size: Xyz { x: d, y: d, z: d }, color }
}

/// A cylinder of `radius` around the axis from `a` to `b` (Foxglove's cylinders lie along z).
fn cylinder_between(a: &Vector3, b: &Vector3, radius: Real, color: Color) -> Cylinder {
    let axis = b - a;
    let z_to_axis = UnitQuaternion::rotation_between(&Vector3::z(), &axis).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    });
    let d = 2.0 * radius;
    Cylinder {
        pose: Pose::new(&(0.5 * (a + b)), &z_to_axis),
        size: Xyz { x: d, y: d, z: axis.norm() },
        bottom_scale: 1.0,
        top_scale: 1.0,
        color,
    }
}

/// Draws a capsule into `entity`: a cylinder (unless the capsule is a ball) and its two caps.
fn add_capsule(entity: &mut SceneEntity, a: &Vector3, b: &Vector3, radius: Real, color: Color) {
    if (b - a).norm() > 0.0 {
        entity.cylinders.push(cylinder_between(a, b, radius, color));
    }
    entity.spheres.extend([ball(a, radius, color), ball(b, radius, color)]);
}

fn shape_name(shape: &Shape) -> &'static str {
    match shape {
        Shape::Box { .. } => "box",
        Shape::Sphere { .. } => "sphere",
        Shape::Capsule { .. } => "capsule",
        Shape::Cylinder { .. } => "cylinder",
    }
}

fn obstacle_entity(time: Time, obstacle: &Obstacle) -> SceneEntity {
    let metadata = vec![
        KeyValue { key: "name", value: obstacle.name.clone() },
        KeyValue { key: "shape", value: shape_name(&obstacle.shape).to_owned() },
    ];
    let mut entity = SceneEntity::new(time, format!("obstacle/{}", obstacle.name), metadata);
    let color = OBSTACLE_COLOR;
    match &obstacle.shape {
        Shape::Box { center, size, rotation } => {
            let pose = Pose::new(center, &UnitQuaternion::from_rotation_matrix(rotation));
            entity.cubes.push(Solid { pose, size: size.into(), color });
        }
        Shape::Sphere { center, radius } => entity.spheres.push(ball(center, *radius, color)),
        Shape::Capsule { a, b, radius } => add_capsule(&mut entity, a, b, *radius, color),
        Shape::Cylinder { center, radius, height, rotation } => {
            let d = 2.0 * radius;
            entity.cylinders.push(Cylinder {
                pose: Pose::new(center, &UnitQuaternion::from_rotation_matrix(rotation)),
                size: Xyz { x: d, y: d, z: *height },
                bottom_scale: 1.0,
                top_scale: 1.0,
                color,
            });
        }
    }
    entity
}

/// The obstacles (positions in {b}), one entity each.
pub(super) fn obstacles(time: Time, scene: &[Obstacle]) -> SceneUpdate {
    SceneUpdate {
        deletions: [],
        entities: scene.iter().map(|o| obstacle_entity(time, o)).collect(),
    }
}

fn role_color(role: LinkRole) -> Color {
    let (r, g, b) = match role {
        LinkRole::Base => (0.6, 0.6, 0.6),
        LinkRole::UpperArm => (0.25, 0.45, 0.9),
        LinkRole::Forearm => (0.2, 0.75, 0.45),
        LinkRole::Hand => (0.95, 0.7, 0.2),
    };
    Color { r, g, b, a: 0.5 }
}

/// The arm's capsules, one entity each, in the frame of the link that carries it and locked
/// to it: sent once, they move with that link's `/tf` transforms.
pub(super) fn arm_capsules(time: Time, robot: &Robot) -> SceneUpdate {
    let entities = robot
        .capsules
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let metadata = vec![
                KeyValue { key: "name", value: c.name.clone() },
                KeyValue { key: "role", value: c.role.as_str().to_owned() },
            ];
            let mut entity = SceneEntity::new(time, format!("capsule/{i}/{}", c.name), metadata);
            // The capsule's ends are given in its moving frame; the entity is drawn in its link.
            let link_from_frame = robot
                .links
                .iter()
                .find(|l| l.name == c.link)
                .map_or_else(Isometry::identity, |l| l.frame_from_link.inverse());
            let (a, b) = (
                link_from_frame.transform_point(&c.a.into()).coords,
                link_from_frame.transform_point(&c.b.into()).coords,
            );
            entity.frame_id.clone_from(&c.link);
            entity.frame_locked = true;
            add_capsule(&mut entity, &a, &b, c.radius, role_color(c.role));
            entity
        })
        .collect();
    SceneUpdate { deletions: [], entities }
}

/// `/robot_description`: the URDF text in a `data` field, as ROS publishes it
/// (`std_msgs/String`) and as Foxglove's 3D panel reads it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(super) struct RobotDescription<'a> {
    data: &'a str,
}

/// The robot's URDF document as a message.
pub(super) fn robot_description(robot: &Robot) -> RobotDescription<'_> {
    RobotDescription { data: &robot.urdf }
}

fn path_entity(time: Time, id: &str, points: &[Vector3], color: Color) -> SceneEntity {
    let mut entity = SceneEntity::new(time, format!("wrist/{id}"), Vec::new());
    entity.lines.push(Line {
        kind: LINE_STRIP,
        pose: Pose::at(&Vector3::zeros()),
        thickness: PATH_THICKNESS,
        scale_invariant: false,
        points: points.iter().map(Xyz::from).collect(),
        color,
        colors: Vec::new(),
        indices: Vec::new(),
    });
    entity
}

/// The planned wrist path (FK of every sample) and the reference one, as two line strips.
pub(super) fn wrist_paths(time: Time, planned: &[Vector3], reference: &[Vector3]) -> SceneUpdate {
    let entities = vec![
        path_entity(time, "planned", planned, PLANNED_PATH_COLOR),
        path_entity(time, "reference", reference, REFERENCE_PATH_COLOR),
    ];
    SceneUpdate { deletions: [], entities }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
struct Cpsa {
    pw: Xyz,
    ow: Quaternion,
    swivel: Real,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
struct Hat {
    shoulder_frame: Quaternion,
    elbow_angle: Real,
    ow: Quaternion,
}

/// `a2ml.State`: either space is left out where its state is singular.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(super) struct State {
    timestamp: Time,
    #[serde(skip_serializing_if = "Option::is_none")]
    cpsa: Option<Cpsa>,
    #[serde(skip_serializing_if = "Option::is_none")]
    hat: Option<Hat>,
}

/// Unit quaternions kept on one hemisphere along a series, so that plotted components do not
/// jump between q and -q (the same rotation).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct QuaternionSeries {
    last: Option<UnitQuaternion>,
}

impl QuaternionSeries {
    /// The quaternion of `r`, on the side of the previous one.
    pub fn next(&mut self, r: &Rotation3) -> UnitQuaternion {
        self.next_quaternion(UnitQuaternion::from_rotation_matrix(r))
    }

    /// `q` or `-q`, whichever is on the side of the previous one.
    pub fn next_quaternion(&mut self, q: UnitQuaternion) -> UnitQuaternion {
        let q = match self.last {
            Some(last) if last.coords.dot(&q.coords) < 0.0 => {
                UnitQuaternion::new_unchecked(-q.into_inner())
            }
            _ => q,
        };
        self.last = Some(q);
        q
    }
}

/// The continuity of the three orientations of [`State`] from sample to sample.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct StateSeries {
    cpsa_ow: QuaternionSeries,
    shoulder_frame: QuaternionSeries,
    hat_ow: QuaternionSeries,
}

/// The representation states of one sample.
pub(super) fn state(
    time: Time,
    cpsa: Option<&CpsaState>,
    hat: Option<&HatState>,
    series: &mut StateSeries,
) -> State {
    let cpsa = cpsa.map(|s| Cpsa {
        pw: (&s.pw).into(),
        ow: (&series.cpsa_ow.next(&s.ow)).into(),
        swivel: s.swivel,
    });
    let hat = hat.map(|s| Hat {
        shoulder_frame: (&series.shoulder_frame.next(&s.shoulder_frame)).into(),
        elbow_angle: s.elbow_angle,
        ow: (&series.hat_ow.next(&s.ow)).into(),
    });
    State { timestamp: time, cpsa, hat }
}

/// The five variables of a reference state, each left out where it is undefined.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(super) struct Reference {
    #[serde(skip_serializing_if = "Option::is_none")]
    pw: Option<Xyz>,
    #[serde(skip_serializing_if = "Option::is_none")]
    ow: Option<Quaternion>,
    #[serde(skip_serializing_if = "Option::is_none")]
    swivel: Option<Real>,
    #[serde(skip_serializing_if = "Option::is_none")]
    shoulder_frame: Option<Quaternion>,
    #[serde(skip_serializing_if = "Option::is_none")]
    elbow_angle: Option<Real>,
}

/// The continuity of the two rotations of [`Reference`] from sample to sample.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct ReferenceSeries {
    ow: QuaternionSeries,
    shoulder_frame: QuaternionSeries,
}

/// A reference state as a message, its quaternions continued along `series`.
pub(super) fn reference(state: &ReferenceState, series: &mut ReferenceSeries) -> Reference {
    Reference {
        pw: state.pw.as_ref().map(Xyz::from),
        ow: state.ow.map(|q| (&series.ow.next_quaternion(q)).into()),
        swivel: state.swivel,
        shoulder_frame: state
            .shoulder_frame
            .map(|q| (&series.shoulder_frame.next_quaternion(q)).into()),
        elbow_angle: state.elbow_angle,
    }
}

/// `a2ml.Reference`: what the running segment asks for at one sample.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(super) struct ReferenceMessage {
    timestamp: Time,
    segment: usize,
    #[serde(flatten)]
    reference: Reference,
}

/// The reference of one sample: the segment's index in the plan and its references.
pub(super) fn reference_message(
    time: Time,
    segment: usize,
    state: &ReferenceState,
    series: &mut ReferenceSeries,
) -> ReferenceMessage {
    ReferenceMessage { timestamp: time, segment, reference: reference(state, series) }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
struct PairDistance<'a> {
    capsule: &'a str,
    capsule_index: usize,
    obstacle: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    distance: Option<Real>,
}

/// `a2ml.Distances`: every capsule-obstacle distance of one sample.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(super) struct Distances<'a> {
    timestamp: Time,
    distances: Vec<PairDistance<'a>>,
}

/// The distances of sample `k`; a pair's distance is left out while it is not measured.
pub(super) fn distances(time: Time, series: &[CapsuleDistances], k: usize) -> Distances<'_> {
    let distances = series
        .iter()
        .map(|d| PairDistance {
            capsule: &d.capsule,
            capsule_index: d.capsule_index,
            obstacle: &d.obstacle,
            distance: d.distance.get(k).copied().flatten(),
        })
        .collect();
    Distances { timestamp: time, distances }
}

/// The fields of `a2ml.Segment` that a report may lack; left out of the message then.
pub(super) const SEGMENT_OPTIONAL: [&str; 5] =
    ["action_type", "clearance", "rrt", "fallback", "reference_end"];

/// `a2ml.Segment`: the report with its start time and its references' ends, its absent
/// optional fields left out (Foxglove's schema reader takes one type per field, so "absent"
/// stands for null).
pub(super) fn segment(
    time: Time,
    report: &SegmentReport,
    reference_end: Option<&ReferenceState>,
) -> Result<serde_json::Value, serde_json::Error> {
    let mut fields = serde_json::Map::new();
    fields.insert("timestamp".to_owned(), serde_json::to_value(time)?);
    if let Some(end) = reference_end {
        let end = reference(end, &mut ReferenceSeries::default());
        fields.insert("reference_end".to_owned(), serde_json::to_value(end)?);
    }
    if let serde_json::Value::Object(report) = serde_json::to_value(report)? {
        let present = |(key, value): &(String, serde_json::Value)| {
            !(value.is_null() && SEGMENT_OPTIONAL.contains(&key.as_str()))
        };
        fields.extend(report.into_iter().filter(present));
    }
    Ok(serde_json::Value::Object(fields))
}
