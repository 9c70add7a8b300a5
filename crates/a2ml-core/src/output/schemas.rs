//! The JSON Schemas of the MCAP channels: Foxglove's own (`foxglove.FrameTransforms`,
//! `foxglove.SceneUpdate`, field for field as Foxglove publishes them, descriptions left out)
//! and a2ml's (`a2ml.JointState`, `a2ml.State`, `a2ml.Reference`, `a2ml.Distances`,
//! `a2ml.Segment`).
//!
//! Foxglove reads a JSON Schema into message definitions: every object needs `"type":
//! "object"` and `properties`, a field has one type (no `["object", "null"]`, no `$ref`), and
//! `oneOf` is only for numeric enumerations. A field that may have no value is therefore
//! declared with its one type, left out of `required`, and left out of the message when it
//! has none: every message validates against its schema and Foxglove still reads the schema.

use serde_json::{Value, json};

use super::messages::SEGMENT_OPTIONAL;
use crate::decompose::{ActionType, SegmentPattern};
use crate::language::{SolverChoice, Space, Variable};
use crate::solve::Fallback;
use crate::spelling::{Spelled, spellings};

/// Schema name and body of a channel.
pub(super) struct Schema {
    /// The name Foxglove recognises (`foxglove.SceneUpdate`) or a2ml's own.
    pub name: &'static str,
    /// The JSON Schema.
    pub body: Value,
}

fn object(title: Option<&str>, properties: Value, required: &[&str]) -> Value {
    let mut schema = json!({ "type": "object", "properties": properties, "required": required });
    if let Some(title) = title {
        schema["title"] = json!(title);
    }
    schema
}

fn typed(kind: &str) -> Value {
    json!({ "type": kind })
}

fn described(kind: &str, description: &str) -> Value {
    json!({ "type": kind, "description": description })
}

/// A string field taking the spellings of `T` only.
fn enumerated<T: Spelled>(description: &str) -> Value {
    json!({ "type": "string", "enum": spellings::<T>(), "description": description })
}

fn array(items: Value) -> Value {
    json!({ "type": "array", "items": items })
}

fn time() -> Value {
    json!({
        "type": "object",
        "title": "time",
        "properties": {
            "sec": { "type": "integer", "minimum": 0 },
            "nsec": { "type": "integer", "minimum": 0, "maximum": 999_999_999 }
        }
    })
}

fn duration() -> Value {
    json!({
        "type": "object",
        "title": "duration",
        "properties": {
            "sec": { "type": "integer" },
            "nsec": { "type": "integer", "minimum": 0, "maximum": 999_999_999 }
        }
    })
}

fn xyz(title: &str) -> Value {
    let n = typed("number");
    object(Some(title), json!({ "x": n, "y": n, "z": n }), &["x", "y", "z"])
}

fn vector3() -> Value {
    xyz("foxglove.Vector3")
}

fn point3() -> Value {
    xyz("foxglove.Point3")
}

fn quaternion() -> Value {
    let n = typed("number");
    object(
        Some("foxglove.Quaternion"),
        json!({ "x": n, "y": n, "z": n, "w": n }),
        &["x", "y", "z", "w"],
    )
}

fn color() -> Value {
    let n = typed("number");
    object(Some("foxglove.Color"), json!({ "r": n, "g": n, "b": n, "a": n }), &["r", "g", "b", "a"])
}

fn pose() -> Value {
    object(
        Some("foxglove.Pose"),
        json!({ "position": vector3(), "orientation": quaternion() }),
        &["position", "orientation"],
    )
}

fn indices() -> Value {
    array(json!({ "type": "integer", "minimum": 0 }))
}

/// `foxglove.FrameTransforms`.
pub(super) fn frame_transforms() -> Schema {
    let transform = object(
        Some("foxglove.FrameTransform"),
        json!({
            "timestamp": time(),
            "parent_frame_id": typed("string"),
            "child_frame_id": typed("string"),
            "translation": vector3(),
            "rotation": quaternion(),
        }),
        &["timestamp", "parent_frame_id", "child_frame_id", "translation", "rotation"],
    );
    let body = object(
        Some("foxglove.FrameTransforms"),
        json!({ "transforms": array(transform) }),
        &["transforms"],
    );
    Schema { name: "foxglove.FrameTransforms", body }
}

fn shape_primitive(title: &str, extra: &[(&str, Value)]) -> Value {
    let mut properties = json!({ "pose": pose(), "size": vector3(), "color": color() });
    let mut required = vec!["pose", "size"];
    for (name, schema) in extra {
        properties[*name] = schema.clone();
        required.push(name);
    }
    required.push("color");
    object(Some(title), properties, &required)
}

fn arrow() -> Value {
    let n = typed("number");
    object(
        Some("foxglove.ArrowPrimitive"),
        json!({
            "pose": pose(),
            "shaft_length": n,
            "shaft_diameter": n,
            "head_length": n,
            "head_diameter": n,
            "color": color(),
        }),
        &["pose", "shaft_length", "shaft_diameter", "head_length", "head_diameter", "color"],
    )
}

fn line() -> Value {
    let line_type = json!({
        "title": "foxglove.LineType",
        "oneOf": [
            { "title": "LINE_STRIP", "const": 0 },
            { "title": "LINE_LOOP", "const": 1 },
            { "title": "LINE_LIST", "const": 2 }
        ]
    });
    object(
        Some("foxglove.LinePrimitive"),
        json!({
            "type": line_type,
            "pose": pose(),
            "thickness": typed("number"),
            "scale_invariant": typed("boolean"),
            "points": array(point3()),
            "color": color(),
            "colors": array(color()),
            "indices": indices(),
        }),
        &["type", "pose", "thickness", "scale_invariant", "points", "color", "colors", "indices"],
    )
}

fn triangles() -> Value {
    object(
        Some("foxglove.TriangleListPrimitive"),
        json!({
            "pose": pose(),
            "points": array(point3()),
            "color": color(),
            "colors": array(color()),
            "indices": indices(),
        }),
        &["pose", "points", "color", "colors", "indices"],
    )
}

fn text() -> Value {
    object(
        Some("foxglove.TextPrimitive"),
        json!({
            "pose": pose(),
            "billboard": typed("boolean"),
            "font_size": typed("number"),
            "scale_invariant": typed("boolean"),
            "color": color(),
            "text": typed("string"),
        }),
        &["pose", "billboard", "font_size", "scale_invariant", "color", "text"],
    )
}

fn model() -> Value {
    object(
        Some("foxglove.ModelPrimitive"),
        json!({
            "pose": pose(),
            "scale": vector3(),
            "color": color(),
            "override_color": typed("boolean"),
            "url": typed("string"),
            "media_type": typed("string"),
            "data": { "type": "string", "contentEncoding": "base64" },
        }),
        &["pose", "scale", "color", "override_color", "url", "media_type", "data"],
    )
}

fn scene_entity() -> Value {
    let key_value = object(
        Some("foxglove.KeyValuePair"),
        json!({ "key": typed("string"), "value": typed("string") }),
        &["key", "value"],
    );
    let n = typed("number");
    object(
        Some("foxglove.SceneEntity"),
        json!({
            "timestamp": time(),
            "frame_id": typed("string"),
            "id": typed("string"),
            "lifetime": duration(),
            "frame_locked": typed("boolean"),
            "metadata": array(key_value),
            "arrows": array(arrow()),
            "cubes": array(shape_primitive("foxglove.CubePrimitive", &[])),
            "spheres": array(shape_primitive("foxglove.SpherePrimitive", &[])),
            "cylinders": array(shape_primitive(
                "foxglove.CylinderPrimitive",
                &[("bottom_scale", n.clone()), ("top_scale", n)],
            )),
            "lines": array(line()),
            "triangles": array(triangles()),
            "texts": array(text()),
            "models": array(model()),
        }),
        &[
            "timestamp",
            "frame_id",
            "id",
            "lifetime",
            "frame_locked",
            "metadata",
            "arrows",
            "cubes",
            "spheres",
            "cylinders",
            "lines",
            "triangles",
            "texts",
            "models",
        ],
    )
}

/// `foxglove.SceneUpdate`.
pub(super) fn scene_update() -> Schema {
    let deletion_type = json!({
        "title": "foxglove.SceneEntityDeletionType",
        "oneOf": [
            { "title": "MATCHING_ID", "const": 0 },
            { "title": "ALL", "const": 1 }
        ]
    });
    let deletion = object(
        Some("foxglove.SceneEntityDeletion"),
        json!({ "timestamp": time(), "type": deletion_type, "id": typed("string") }),
        &["timestamp", "type", "id"],
    );
    let body = object(
        Some("foxglove.SceneUpdate"),
        json!({ "deletions": array(deletion), "entities": array(scene_entity()) }),
        &["deletions", "entities"],
    );
    Schema { name: "foxglove.SceneUpdate", body }
}

/// `a2ml.JointState`: the joint trajectory sample, laid out like ROS's sensor_msgs/JointState,
/// with the position limits beside it.
pub(super) fn joint_state() -> Schema {
    let body = object(
        Some("a2ml.JointState"),
        json!({
            "timestamp": time(),
            "time": described("number", "the plan's time (s), exact; timestamp rounds it to ns"),
            "name": array(typed("string")),
            "position": { "type": "array", "items": typed("number"), "description": "rad" },
            "velocity": { "type": "array", "items": typed("number"), "description": "rad/s" },
            "lower": {
                "type": "array",
                "items": typed("number"),
                "description": "lower position limits (rad)"
            },
            "upper": {
                "type": "array",
                "items": typed("number"),
                "description": "upper position limits (rad)"
            },
        }),
        &["timestamp", "time", "name", "position", "velocity", "lower", "upper"],
    );
    Schema { name: "a2ml.JointState", body }
}

/// `a2ml.State`: the CPSA (Pw, Ow, θsw) and HAT (Os, θe, Ow) states in {b}.
pub(super) fn state() -> Schema {
    let cpsa = json!({
        "type": "object",
        "description": "CPSA state; absent where it is singular (the arm straight or folded, \
                        or the wrist on the vertical through S)",
        "properties": {
            "pw": xyz("foxglove.Vector3"),
            "ow": quaternion(),
            "swivel": described("number", "θsw (rad)"),
        },
        "required": ["pw", "ow", "swivel"],
    });
    let hat = json!({
        "type": "object",
        "description": "HAT state; absent where it is singular (the arm straight or folded)",
        "properties": {
            "shoulder_frame": quaternion(),
            "elbow_angle": described("number", "θe (rad)"),
            "ow": quaternion(),
        },
        "required": ["shoulder_frame", "elbow_angle", "ow"],
    });
    let body = object(
        Some("a2ml.State"),
        json!({ "timestamp": time(), "cpsa": cpsa, "hat": hat }),
        &["timestamp"],
    );
    Schema { name: "a2ml.State", body }
}

/// The properties of a reference state: each variable, absent where it is undefined.
fn reference_properties() -> Value {
    json!({
        "pw": xyz("foxglove.Vector3"),
        "ow": quaternion(),
        "swivel": described("number", "θsw (rad)"),
        "shoulder_frame": quaternion(),
        "elbow_angle": described("number", "θe (rad)"),
    })
}

/// `a2ml.Reference`: what the running segment asks for at one sample, in both spaces.
pub(super) fn reference() -> Schema {
    let mut properties = reference_properties();
    properties["timestamp"] = time();
    properties["segment"] = described("integer", "index of the running segment in the plan");
    let mut body = object(Some("a2ml.Reference"), properties, &["timestamp", "segment"]);
    body["description"] = json!(
        "the running segment's references (its own space) and their mapping to the other \
         space; a variable is absent where the mapping is singular"
    );
    Schema { name: "a2ml.Reference", body }
}

/// `a2ml.Distances`: the signed distance of every moving arm capsule to every obstacle.
pub(super) fn distances() -> Schema {
    let s = typed("string");
    let pair = object(
        None,
        json!({
            "capsule": s,
            "capsule_index": described("integer", "the capsule's index in the robot's list"),
            "obstacle": s,
            "distance": described(
                "number",
                "signed distance (m); absent while the action touches the obstacle on purpose"
            ),
        }),
        &["capsule", "capsule_index", "obstacle"],
    );
    let body = object(
        Some("a2ml.Distances"),
        json!({ "timestamp": time(), "distances": array(pair) }),
        &["timestamp", "distances"],
    );
    Schema { name: "a2ml.Distances", body }
}

/// `a2ml.Segment`: a [`crate::solve::SegmentReport`] with the time it starts.
pub(super) fn segment() -> Schema {
    let (n, s, b, i) = (typed("number"), typed("string"), typed("boolean"), typed("integer"));
    let error = object(
        None,
        json!({
            "variable": enumerated::<Variable>("the state variable"),
            "error": described("number", "m or rad"),
            "within": b
        }),
        &["variable", "error", "within"],
    );
    let mut clearance = object(
        None,
        json!({ "distance": n, "time": n, "link": s, "obstacle": s }),
        &["distance", "time", "link", "obstacle"],
    );
    clearance["description"] = json!("smallest clearance (m) and where; absent without obstacles");
    let qp = object(
        None,
        json!({ "steps": i, "clarabel_steps": i, "clarabel_almost_solved": i }),
        &["steps", "clarabel_steps", "clarabel_almost_solved"],
    );
    let mut rrt = object(
        None,
        json!({ "samples": i, "nodes": i, "collision_checks": i }),
        &["samples", "nodes", "collision_checks"],
    );
    rrt["description"] = json!("RRT counters when the RRT solved the segment; absent otherwise");
    let fields = json!({
        "timestamp": time(),
        "action": s,
        "action_index": i,
        "segment": i,
        "action_type": enumerated::<ActionType>(
            "the paper's type I to VII, in lower case; absent for explicit segments"
        ),
        "space": enumerated::<Space>("the representation space"),
        "pattern": enumerated::<SegmentPattern>(
            "the paper's pattern: path (1), goal (2) or mixed (3)"
        ),
        "solver": enumerated::<SolverChoice>("the solver that produced the motion"),
        "focus": array(enumerated::<Variable>("a variable of the featured primitive")),
        "start": described("number", "s"),
        "end": described("number", "s"),
        "duration": described("number", "s"),
        "settle": described("number", "s"),
        "errors": array(error.clone()),
        "path_errors": array(error),
        "hard_path": b,
        "path_kept": b,
        "clearance": clearance,
        "limit_margin": described("number", "rad"),
        "stalled": b,
        "reached": b,
        "qp": qp,
        "rrt": rrt,
        "fallback": enumerated::<Fallback>(
            "why auto went on from the QP to the solver named; absent if it did not"
        ),
        "peak_velocity_ratio": described("number", "largest |q'|/limit over the segment"),
        "peak_acceleration_ratio": described("number", "largest |q''|/limit over the segment"),
        "limits_kept": b,
        "slowed_down": described("number", "factor the segment was slowed by (1: as solved)"),
        "joint_jerk": described("number", "normalised jerk of the joints (dimensionless)"),
        "wrist_jerk": described("number", "normalised jerk of the wrist path (dimensionless)"),
        "speed_peaks": described("integer", "peaks of the featured variable's speed"),
        "reference_end": {
            "type": "object",
            "description": "the references at the segment's end T: goals, path ends, holds",
            "properties": reference_properties(),
        },
    });
    let required: Vec<&str> = fields
        .as_object()
        .map(|m| m.keys().map(String::as_str).filter(|k| !SEGMENT_OPTIONAL.contains(k)).collect())
        .unwrap_or_default();
    let body = object(Some("a2ml.Segment"), fields.clone(), &required);
    Schema { name: "a2ml.Segment", body }
}

/// `std_msgs/String`, the type ROS publishes `/robot_description` with: the URDF text in
/// `data`.
pub(super) fn robot_description() -> Schema {
    let body = object(
        Some("std_msgs/String"),
        json!({ "data": described("string", "the robot's URDF document") }),
        &["data"],
    );
    Schema { name: "std_msgs/String", body }
}
