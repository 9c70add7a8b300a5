//! Output files written from a hand-made plan and read back: the MCAP with the mcap crate's
//! reader (channels, schemas, counts, times, attachments, every message against its schema),
//! the CSV and the JSON; and no file after a failure.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

use a2ml::Robot;
use a2ml::decompose::{ActionType, SegmentPattern};
use a2ml::kinematics::{arm_pose, cpsa_state, hat_state, link_poses};
use a2ml::language::{Shape, SolverChoice, Space, Task, Variable, parse};
use a2ml::math::{JointVector, Real, UnitQuaternion, Vector3};
use a2ml::output::{OutputError, topics, write_csv, write_json, write_mcap};
use a2ml::solve::{
    Fallback, Plan, QpStats, ReferenceSample, ReferenceState, SegmentReport, VariableError,
    Warning, WarningKind,
};
use a2ml::trajectory::{CapsuleDistances, Clearance, Trajectory};
use serde_json::Value;

use crate::common::{self, load};

/// Output rate of the test plan (Hz).
const RATE: Real = 250.0;
/// Number of samples: 0.4 s at [`RATE`].
const SAMPLES: usize = 101;

/// The task of an example file, with its source.
fn task(name: &str) -> (Task, String) {
    let path = common::example(name);
    let source = fs::read_to_string(&path).expect("example readable");
    (parse(&source, Some(&path)).expect("valid example"), source)
}

/// An empty scratch folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("output-{name}"));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

fn report(action: &str, index: usize, start: Real, end: Real) -> SegmentReport {
    SegmentReport {
        action: action.into(),
        action_index: index,
        segment: 0,
        action_type: (index == 0).then_some(ActionType::II),
        space: Space::Cpsa,
        pattern: SegmentPattern::Goal,
        solver: SolverChoice::Qp,
        focus: vec![Variable::Pw, Variable::Ow],
        start,
        end,
        duration: end - start,
        settle: 0.0,
        errors: vec![VariableError { variable: Variable::Pw, error: 2e-4, within: true }],
        path_errors: (index == 1)
            .then_some(VariableError { variable: Variable::Swivel, error: 0.01, within: true })
            .into_iter()
            .collect(),
        hard_path: false,
        path_kept: true,
        clearance: (index == 1).then(|| Clearance {
            distance: 0.05,
            time: end,
            link: "forearm".into(),
            obstacle: "table".into(),
        }),
        limit_margin: 0.3,
        stalled: false,
        reached: true,
        qp: QpStats { steps: 40, ..QpStats::default() },
        rrt: None,
        fallback: (index == 1).then_some(Fallback::QpStalled),
        peak_velocity_ratio: 0.5,
        peak_acceleration_ratio: 0.25,
        limits_kept: true,
        slowed_down: 1.0,
        joint_jerk: 20.0,
        wrist_jerk: 19.0,
        speed_peaks: 1,
    }
}

/// A plan over 0.4 s: every joint swings around the middle of its range, well within limits.
fn plan(robot: &Robot) -> Plan {
    let (mid, half) = (robot.middle(), (robot.upper() - robot.lower()) * 0.3);
    let times = (0..SAMPLES).map(|i| i as Real / RATE).collect();
    let w = 5.0;
    let trajectory = Trajectory::from_fn(times, |t| {
        let s = JointVector::from_fn(|i, _| (w * t + i as Real).sin());
        let c = JointVector::from_fn(|i, _| w * (w * t + i as Real).cos());
        (mid + half.component_mul(&s), half.component_mul(&c))
    })
    .expect("valid trajectory");
    let wrist_reference = trajectory
        .times()
        .iter()
        .zip(trajectory.positions())
        .map(|(&t, q)| (t, arm_pose(robot, q).wrist + Vector3::new(0.0, 0.0, 0.01)))
        .collect();
    let references = trajectory
        .times()
        .iter()
        .zip(trajectory.positions())
        .map(|(&t, q)| ReferenceSample {
            segment: usize::from(t >= 0.201),
            state: reference_state(robot, q),
        })
        .collect();
    let ends = [trajectory.positions()[62], trajectory.positions()[SAMPLES - 1]];
    Plan {
        task: "avoid".into(),
        joint_names: robot.joint_names().iter().map(|s| s.to_string()).collect(),
        rate: RATE,
        trajectory,
        segments: vec![report("reach", 0, 0.0, 0.25), report("back", 1, 0.201, 0.4)],
        wrist_reference,
        safety_distance: 0.02,
        warnings: vec![Warning::on_segment(
            WarningKind::MissedGoal,
            "back",
            0,
            "action `back`, segment 1: a warning".to_owned(),
        )],
        references,
        reference_ends: ends.iter().map(|q| reference_state(robot, q)).collect(),
        distances: vec![CapsuleDistances {
            capsule: robot.capsules[1].name.clone(),
            capsule_index: 1,
            obstacle: "table".into(),
            distance: (0..SAMPLES)
                .map(|k| (k % 10 != 3).then_some(0.1 + k as Real * 1e-3))
                .collect(),
        }],
        swivel_maps: Vec::new(),
    }
}

/// The reference state of configuration `q`, shifted 1 cm up (so that it differs from the
/// planned state).
fn reference_state(robot: &Robot, q: &JointVector) -> ReferenceState {
    let pose = arm_pose(robot, q);
    let cpsa = cpsa_state(robot, &pose).ok();
    let hat = hat_state(&pose).ok();
    ReferenceState {
        pw: cpsa.map(|s| s.pw + Vector3::new(0.0, 0.0, 0.01)),
        ow: cpsa.map(|s| UnitQuaternion::from_rotation_matrix(&s.ow)),
        swivel: cpsa.map(|s| s.swivel + 0.1),
        shoulder_frame: hat.map(|s| UnitQuaternion::from_rotation_matrix(&s.shoulder_frame)),
        elbow_angle: hat.map(|s| s.elbow_angle),
    }
}

/// A recording read back: per topic, (log time, publish time, message) in file order.
struct Recording {
    bytes: Vec<u8>,
    messages: BTreeMap<String, Vec<(u64, u64, Value)>>,
    schemas: BTreeMap<String, (String, String, Value)>,
}

fn read(path: &Path) -> Recording {
    let bytes = fs::read(path).expect("mcap written");
    let mut messages: BTreeMap<String, Vec<(u64, u64, Value)>> = BTreeMap::new();
    let mut schemas = BTreeMap::new();
    for message in mcap::MessageStream::new(&bytes).expect("mcap") {
        let message = message.expect("readable message");
        let channel = &message.channel;
        assert_eq!(channel.message_encoding, "json", "{}", channel.topic);
        let schema = channel.schema.as_ref().expect("a schema");
        let body = serde_json::from_slice(&schema.data).expect("schema is JSON");
        schemas.insert(channel.topic.clone(), (schema.name.clone(), schema.encoding.clone(), body));
        let value = serde_json::from_slice(&message.data).expect("message is JSON");
        messages.entry(channel.topic.clone()).or_default().push((
            message.log_time,
            message.publish_time,
            value,
        ));
    }
    Recording { bytes, messages, schemas }
}

fn written(name: &str, task_file: &str) -> (Robot, Task, String, Plan, Recording) {
    let robot = load("coman_right_arm");
    let (task, source) = task(task_file);
    let plan = plan(&robot);
    let path = scratch(name).join("plan.mcap");
    write_mcap(&path, &robot, &task, &source, &plan).expect("mcap written");
    let recording = read(&path);
    (robot, task, source, plan, recording)
}

/// Whether `value` has the fields of `schema`, recursively: every required field present,
/// nothing undeclared, types as declared, enumerations among their constants.
fn conforms(value: &Value, schema: &Value, at: &str) -> Result<(), String> {
    if let Some(options) = schema["oneOf"].as_array() {
        return options
            .iter()
            .any(|o| o["const"] == *value)
            .then_some(())
            .ok_or(format!("{at}: {value} is not one of {options:?}"));
    }
    let kind = schema["type"].as_str().ok_or(format!("{at}: schema without a type"))?;
    let fits = match kind {
        "object" => return object_conforms(value, schema, at),
        "array" => {
            let items = value.as_array().ok_or(format!("{at}: not an array"))?;
            return items
                .iter()
                .enumerate()
                .try_for_each(|(i, v)| conforms(v, &schema["items"], &format!("{at}[{i}]")));
        }
        "number" => value.is_number(),
        "integer" => value.is_u64() || value.is_i64(),
        "string" => match schema["enum"].as_array() {
            Some(values) if value.is_string() => {
                return values
                    .contains(value)
                    .then_some(())
                    .ok_or(format!("{at}: {value} is not one of {values:?}"));
            }
            _ => value.is_string(),
        },
        "boolean" => value.is_boolean(),
        other => return Err(format!("{at}: unexpected schema type {other}")),
    };
    fits.then_some(()).ok_or(format!("{at}: {value} is not a {kind}"))
}

fn object_conforms(value: &Value, schema: &Value, at: &str) -> Result<(), String> {
    let fields = value.as_object().ok_or(format!("{at}: {value} is not an object"))?;
    let properties = schema["properties"].as_object().ok_or(format!("{at}: no properties"))?;
    for required in schema["required"].as_array().into_iter().flatten() {
        let name = required.as_str().unwrap_or_default();
        if !fields.contains_key(name) {
            return Err(format!("{at}: missing {name}"));
        }
    }
    for (name, v) in fields {
        let property = properties.get(name).ok_or(format!("{at}: undeclared field {name}"))?;
        conforms(v, property, &format!("{at}.{name}"))?;
    }
    Ok(())
}

fn xyz(v: &Value) -> Vector3 {
    Vector3::new(
        v["x"].as_f64().expect("x"),
        v["y"].as_f64().expect("y"),
        v["z"].as_f64().expect("z"),
    )
}

/// The transform of a `foxglove.FrameTransform`.
fn isometry(t: &Value) -> a2ml::math::Isometry {
    let o = &t["rotation"];
    let [x, y, z, w] = ["x", "y", "z", "w"].map(|k| o[k].as_f64().expect("component"));
    let rotation =
        a2ml::math::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
    a2ml::math::Isometry::from_parts(xyz(&t["translation"]).into(), rotation.to_rotation_matrix())
}

fn nanos(t: Real) -> u64 {
    (t * 1e9).round() as u64
}

#[test]
fn every_channel_has_its_schema_and_encoding() {
    let (.., recording) = written("channels", "construct_scene.a2ml");
    let expected = [
        (topics::JOINT_STATES, "a2ml.JointState"),
        (topics::TF, "foxglove.FrameTransforms"),
        (topics::SCENE, "foxglove.SceneUpdate"),
        (topics::ARM_CAPSULES, "foxglove.SceneUpdate"),
        (topics::WRIST_PATH, "foxglove.SceneUpdate"),
        (topics::STATE, "a2ml.State"),
        (topics::REFERENCE, "a2ml.Reference"),
        (topics::DISTANCES, "a2ml.Distances"),
        (topics::SEGMENTS, "a2ml.Segment"),
        (topics::ROBOT_DESCRIPTION, "std_msgs/String"),
    ];
    let found: BTreeSet<&str> = recording.schemas.keys().map(String::as_str).collect();
    assert_eq!(found, expected.iter().map(|(t, _)| *t).collect());
    for (topic, name) in expected {
        let (schema_name, encoding, body) = &recording.schemas[topic];
        assert_eq!((schema_name.as_str(), encoding.as_str()), (name, "jsonschema"), "{topic}");
        assert_eq!(body["type"], "object", "{topic}");
        assert_eq!(body["title"], name, "{topic}");
    }
    let summary = mcap::Summary::read(&recording.bytes).expect("readable").expect("a summary");
    assert!(!summary.chunk_indexes.is_empty(), "chunked, with an index");
    assert!(summary.chunk_indexes.iter().all(|c| c.compression == "zstd"), "zstd chunks");
    assert_eq!(summary.channels.len(), expected.len());
}

#[test]
fn message_counts_follow_the_samples() {
    let (_, _, _, plan, recording) = written("counts", "construct_scene.a2ml");
    let count = |topic: &str| recording.messages.get(topic).map_or(0, Vec::len);
    let n = plan.trajectory.len();
    assert_eq!(n, SAMPLES);
    for topic in
        [topics::JOINT_STATES, topics::TF, topics::STATE, topics::REFERENCE, topics::DISTANCES]
    {
        assert_eq!(count(topic), n, "{topic}");
    }
    for topic in
        [topics::SCENE, topics::WRIST_PATH, topics::ARM_CAPSULES, topics::ROBOT_DESCRIPTION]
    {
        assert_eq!(count(topic), 1, "{topic} is sent once");
    }
    assert_eq!(count(topics::SEGMENTS), plan.segments.len());
}

#[test]
fn log_times_are_plan_times_and_never_go_back_per_channel() {
    let (_, _, _, plan, recording) = written("times", "construct_scene.a2ml");
    for (topic, messages) in &recording.messages {
        for pair in messages.windows(2) {
            assert!(pair[0].0 <= pair[1].0, "{topic} goes back");
        }
        for (log, publish, message) in messages {
            assert_eq!(log, publish, "{topic}");
            let stamp = &message["timestamp"];
            if stamp.is_object() {
                let ns = stamp["sec"].as_u64().expect("sec") * 1_000_000_000
                    + stamp["nsec"].as_u64().expect("nsec");
                assert_eq!(ns, *log, "{topic}: timestamp and log time differ");
            }
        }
    }
    let joint_times: Vec<u64> =
        recording.messages[topics::JOINT_STATES].iter().map(|m| m.0).collect();
    let expected: Vec<u64> = plan.trajectory.times().iter().map(|&t| nanos(t)).collect();
    assert_eq!(joint_times, expected);
    let segment_times: Vec<u64> =
        recording.messages[topics::SEGMENTS].iter().map(|m| m.0).collect();
    assert_eq!(segment_times, [nanos(0.0), nanos(0.201)]);
}

#[test]
fn the_task_source_and_the_urdf_are_attached_with_the_metadata() {
    let (robot, task, source, plan, recording) = written("attachments", "construct_scene.a2ml");
    let bytes = &recording.bytes;
    let summary = mcap::Summary::read(bytes).expect("readable").expect("a summary");
    let attachments: BTreeMap<String, (String, Vec<u8>)> = summary
        .attachment_indexes
        .iter()
        .map(|index| {
            let a = mcap::read::attachment(bytes, index).expect("attachment");
            (a.name, (a.media_type, a.data.into_owned()))
        })
        .collect();
    assert_eq!(attachments.len(), 2);
    let (media, data) = &attachments[&format!("{}.a2ml", task.name)];
    assert_eq!((media.as_str(), data.as_slice()), ("text/plain", source.as_bytes()));
    let (media, data) = &attachments[&format!("{}.urdf", robot.name)];
    assert_eq!((media.as_str(), data.as_slice()), ("application/xml", robot.urdf.as_bytes()));
    let [index] = summary.metadata_indexes.as_slice() else { panic!("one metadata record") };
    let metadata = mcap::read::metadata(bytes, index).expect("metadata");
    assert_eq!(metadata.name, "a2ml");
    let entries = &metadata.metadata;
    assert_eq!(entries["task"], task.name);
    assert_eq!(entries["robot"], robot.name);
    assert_eq!(entries["a2ml_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(entries["rate_hz"].parse::<Real>().expect("a number"), plan.rate);
    assert_eq!(entries["warnings"], plan.warnings[0].to_string());
}

#[test]
fn every_message_has_the_fields_of_its_schema() {
    let (.., recording) = written("conformance", "construct_scene.a2ml");
    for (topic, messages) in &recording.messages {
        let schema = &recording.schemas[topic].2;
        for (i, (_, _, message)) in messages.iter().enumerate() {
            if let Err(e) = conforms(message, schema, &format!("{topic}#{i}")) {
                panic!("{e}");
            }
        }
    }
}

#[test]
fn joint_states_and_transforms_follow_the_trajectory() {
    let (robot, _, _, plan, recording) = written("kinematics", "construct_scene.a2ml");
    let trajectory = &plan.trajectory;
    for (i, (_, _, m)) in recording.messages[topics::JOINT_STATES].iter().enumerate() {
        assert_eq!(m["name"], serde_json::json!(plan.joint_names));
        assert_eq!(m["lower"], serde_json::json!(robot.lower().as_slice()));
        assert_eq!(m["upper"], serde_json::json!(robot.upper().as_slice()));
        for j in 0..7 {
            let (q, qd) = (trajectory.positions()[i][j], trajectory.velocities()[i][j]);
            assert!((m["position"][j].as_f64().expect("q") - q).abs() <= 1e-12 * q.abs());
            assert!((m["velocity"][j].as_f64().expect("q'") - qd).abs() <= 1e-12 * qd.abs());
        }
    }
    let last = SAMPLES - 1;
    let transforms = &recording.messages[topics::TF][last].2["transforms"];
    let poses = link_poses(&robot, &arm_pose(&robot, &trajectory.positions()[last]));
    let transforms = transforms.as_array().expect("transforms");
    assert_eq!(transforms.len(), robot.links.len());
    // The links as a tree (each from the one before it, the first from "b"): composed from
    // the root, every link lands on its pose in {b}.
    let mut b_from_parent = a2ml::math::Isometry::identity();
    let mut parent = "b";
    for ((t, link), pose) in transforms.iter().zip(&robot.links).zip(&poses) {
        assert_eq!(
            (t["parent_frame_id"].as_str(), t["child_frame_id"].as_str()),
            (Some(parent), Some(link.name.as_str()))
        );
        let b_from_link = b_from_parent * isometry(t);
        assert!((b_from_link.translation.vector - pose.translation.vector).norm() < 1e-12);
        assert!((b_from_link.rotation.matrix() - pose.rotation.matrix()).norm() < 1e-12);
        (b_from_parent, parent) = (b_from_link, link.name.as_str());
    }
    // The base link's transform places the URDF in {b}.
    let base = &transforms[0];
    assert_eq!(base["child_frame_id"], robot.base_link.as_str());
    assert!((xyz(&base["translation"]) - robot.b_from_base_link.translation.vector).norm() < 1e-15);
}

#[test]
fn the_scene_has_one_entity_per_obstacle() {
    let (.., recording) = written("scene", "construct_scene.a2ml");
    let entities = &recording.messages[topics::SCENE][0].2["entities"];
    let entities = entities.as_array().expect("entities");
    let ids: Vec<&str> = entities.iter().map(|e| e["id"].as_str().expect("id")).collect();
    let names = ["table", "cup", "ball", "bar", "crate"].map(|n| format!("obstacle/{n}"));
    assert_eq!(ids, names);
    // Cubes, spheres, cylinders: box, cylinder, sphere, capsule (a cylinder and two caps).
    let counts =
        |e: &Value| ["cubes", "spheres", "cylinders"].map(|k| e[k].as_array().map_or(0, Vec::len));
    let expected = [[1, 0, 0], [0, 0, 1], [0, 1, 0], [0, 2, 1], [1, 0, 0]];
    assert_eq!(entities.iter().map(counts).collect::<Vec<_>>(), expected);
    let ball = &entities[2]["spheres"][0];
    assert!((xyz(&ball["pose"]["position"]) - Vector3::new(0.28, -0.20, -0.18)).norm() < 1e-12);
    assert!((ball["size"]["x"].as_f64().expect("size") - 0.08).abs() < 1e-12);
    assert!(entities.iter().all(|e| e["frame_id"] == "b"));
}

#[test]
fn a_scene_written_in_the_root_frame_is_drawn_in_the_base_frame() {
    let (robot, task, _, _, recording) = written("scene_root", "construct_frame_root.a2ml");
    let table = &recording.messages[topics::SCENE][0].2["entities"][0]["cubes"][0];
    let in_b = task.in_base_frame(&robot.structure.shoulder_in_base_link);
    let Shape::Box { center, .. } = in_b.scene[0].shape else { panic!("the table is a box") };
    assert!((xyz(&table["pose"]["position"]) - center).norm() < 1e-12);
    // The file's comment: the table's centre is [0.36, 0, -0.235] in {b}.
    assert!((center - Vector3::new(0.36, 0.0, -0.235)).norm() < 1e-3, "{center}");
}

#[test]
fn the_arm_capsules_ride_on_their_links() {
    let (robot, _, _, plan, recording) = written("capsules", "construct_scene.a2ml");
    let [(time, _, update)] = recording.messages[topics::ARM_CAPSULES].as_slice() else {
        panic!("the capsules are sent once")
    };
    assert_eq!(*time, nanos(plan.trajectory.start()));
    let entities = update["entities"].as_array().expect("entities");
    assert_eq!(entities.len(), robot.capsules.len());
    // At every tenth sample, the caps placed by their link's pose (composed from /tf) are
    // where the collision model puts the capsule's ends.
    let tf = &recording.messages[topics::TF];
    for (i, q) in plan.trajectory.positions().iter().enumerate().step_by(10) {
        let mut b_from = BTreeMap::from([("b".to_owned(), a2ml::math::Isometry::identity())]);
        for t in tf[i].2["transforms"].as_array().expect("transforms") {
            let parent = b_from[t["parent_frame_id"].as_str().expect("parent")];
            b_from
                .insert(t["child_frame_id"].as_str().expect("child").into(), parent * isometry(t));
        }
        let capsules = a2ml::collision::arm_capsules(&robot, &arm_pose(&robot, q));
        for (e, c) in entities.iter().zip(&capsules) {
            assert_eq!(e["frame_locked"], true);
            let b_from_link = b_from[e["frame_id"].as_str().expect("a link frame")];
            let caps: Vec<Vector3> = e["spheres"]
                .as_array()
                .expect("caps")
                .iter()
                .map(|s| b_from_link.transform_point(&xyz(&s["pose"]["position"]).into()).coords)
                .collect();
            assert!((caps[0] - c.a).norm() < 1e-9 && (caps[1] - c.b).norm() < 1e-9, "sample {i}");
        }
    }
}

#[test]
fn the_robot_description_is_the_urdf() {
    let (robot, .., recording) = written("description", "construct_scene.a2ml");
    let [(_, _, message)] = recording.messages[topics::ROBOT_DESCRIPTION].as_slice() else {
        panic!("sent once")
    };
    assert_eq!(message["data"].as_str(), Some(robot.urdf.as_str()));
}

#[test]
fn the_files_are_the_same_bytes_every_time() {
    let robot = load("coman_right_arm");
    let (task, source) = task("construct_scene.a2ml");
    let plan = plan(&robot);
    let dir = scratch("reproducible");
    let bytes = |name: &str| -> [Vec<u8>; 3] {
        let [mcap, csv, json] = ["mcap", "csv", "json"].map(|e| dir.join(format!("{name}.{e}")));
        write_mcap(&mcap, &robot, &task, &source, &plan).expect("mcap");
        write_csv(&csv, &robot, &plan).expect("csv");
        write_json(&json, &robot, &task, &plan).expect("json");
        [mcap, csv, json].map(|p| fs::read(p).expect("written"))
    };
    let mut timed = plan.clone();
    // Wall-clock timings differ from run to run; the files must not show them.
    timed.segments[0].qp.mean_step_time = 1.25e-3;
    timed.segments[0].qp.worst_step_time = 9.5e-3;
    let first = bytes("first");
    let again = bytes("again");
    assert_eq!(first, again);
    let json = String::from_utf8(first[2].clone()).expect("UTF-8");
    assert!(!json.contains("step_time"), "no timings");
    let dir_timed = scratch("reproducible_timed");
    let [mcap, json_path] = ["mcap", "json"].map(|e| dir_timed.join(format!("plan.{e}")));
    write_mcap(&mcap, &robot, &task, &source, &timed).expect("mcap");
    write_json(&json_path, &robot, &task, &timed).expect("json");
    assert_eq!(fs::read(mcap).expect("written"), first[0], "MCAP without timings");
    assert_eq!(fs::read(json_path).expect("written"), first[2], "JSON without timings");
}

#[test]
fn the_wrist_paths_are_the_planned_and_the_reference_one() {
    let (robot, _, _, plan, recording) = written("wrist", "construct_scene.a2ml");
    let entities = &recording.messages[topics::WRIST_PATH][0].2["entities"];
    assert_eq!(
        (entities[0]["id"].as_str(), entities[1]["id"].as_str()),
        (Some("wrist/planned"), Some("wrist/reference"))
    );
    let points = |e: &Value| -> Vec<Vector3> {
        let line = &e["lines"][0];
        assert_eq!(line["type"], 0, "a line strip");
        line["points"].as_array().expect("points").iter().map(xyz).collect()
    };
    let planned = points(&entities[0]);
    assert_eq!(planned.len(), SAMPLES);
    for (p, q) in planned.iter().zip(plan.trajectory.positions()) {
        assert!((p - arm_pose(&robot, q).wrist).norm() < 1e-12);
    }
    let reference = points(&entities[1]);
    assert_eq!(reference.len(), plan.wrist_reference.len());
    assert!((reference[7] - plan.wrist_reference[7].1).norm() < 1e-12);
}

#[test]
fn the_states_are_the_cpsa_and_hat_states_of_each_sample() {
    let (robot, _, _, plan, recording) = written("states", "construct_scene.a2ml");
    let states = &recording.messages[topics::STATE];
    for ((_, _, m), q) in states.iter().zip(plan.trajectory.positions()).step_by(10) {
        let pose = arm_pose(&robot, q);
        let cpsa = a2ml::kinematics::cpsa_state(&robot, &pose).expect("regular");
        let hat = a2ml::kinematics::hat_state(&pose).expect("regular");
        assert!((xyz(&m["cpsa"]["pw"]) - cpsa.pw).norm() < 1e-12);
        assert!((m["cpsa"]["swivel"].as_f64().expect("θsw") - cpsa.swivel).abs() < 1e-12);
        assert!((m["hat"]["elbow_angle"].as_f64().expect("θe") - hat.elbow_angle).abs() < 1e-12);
        let o = &m["hat"]["shoulder_frame"];
        let [x, y, z, w] = ["x", "y", "z", "w"].map(|k| o[k].as_f64().expect("component"));
        let os = a2ml::math::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
        let difference = os.to_rotation_matrix().matrix() - hat.shoulder_frame.matrix();
        assert!(difference.norm() < 1e-12, "{difference}");
    }
}

#[test]
fn each_segment_is_recorded_at_its_start() {
    let (_, _, _, plan, recording) = written("segments", "construct_scene.a2ml");
    let records: Vec<&Value> = recording.messages[topics::SEGMENTS].iter().map(|m| &m.2).collect();
    assert_eq!(records[0]["action"], "reach");
    assert_eq!(records[0]["action_type"], "ii");
    assert_eq!(records[0]["pattern"], "goal");
    assert_eq!(records[0]["space"], "cpsa");
    assert_eq!(records[0]["solver"], "qp");
    assert_eq!(records[0]["focus"], serde_json::json!(["pw", "ow"]));
    assert!(records[0].get("clearance").is_none(), "absent, not null");
    assert!(records[1].get("action_type").is_none());
    assert!(records[0].get("rrt").is_none() && records[0].get("fallback").is_none());
    let qp = serde_json::json!({ "steps": 40, "clarabel_steps": 0, "clarabel_almost_solved": 0 });
    assert_eq!(records[0]["qp"], qp);
    assert_eq!(records[1]["clearance"]["obstacle"], "table");
    assert_eq!(records[1]["path_errors"][0]["variable"], "swivel");
    assert_eq!(records[1]["start"].as_f64(), Some(plan.segments[1].start));
    assert_eq!(records[1]["reached"], true);
}

#[test]
fn the_references_and_distances_are_recorded_per_sample() {
    let (_, _, _, plan, recording) = written("references", "construct_scene.a2ml");
    for (k, (_, _, m)) in recording.messages[topics::REFERENCE].iter().enumerate() {
        let expected = &plan.references[k];
        assert_eq!(m["segment"].as_u64(), Some(expected.segment as u64));
        let pw = expected.state.pw.expect("Pw");
        assert_eq!(xyz(&m["pw"]), pw, "Pw at sample {k}");
        assert_eq!(m["swivel"].as_f64(), expected.state.swivel);
        assert_eq!(m["elbow_angle"].as_f64(), expected.state.elbow_angle);
        let o = &m["shoulder_frame"];
        let [x, y, z, w] = ["x", "y", "z", "w"].map(|c| o[c].as_f64().expect("component"));
        let os = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
        assert!(os.angle_to(&expected.state.shoulder_frame.expect("Os")) < 1e-12);
    }
    for (k, (_, _, m)) in recording.messages[topics::DISTANCES].iter().enumerate() {
        let pairs = m["distances"].as_array().expect("pairs");
        assert_eq!(pairs.len(), 1);
        assert_eq!(pairs[0]["obstacle"], "table");
        assert_eq!(pairs[0]["capsule_index"], 1);
        assert_eq!(pairs[0]["distance"].as_f64(), plan.distances[0].distance[k], "sample {k}");
    }
    let records = &recording.messages[topics::SEGMENTS];
    let end = &records[1].2["reference_end"];
    assert_eq!(end["swivel"].as_f64(), plan.reference_ends[1].swivel);
    assert_eq!(xyz(&end["pw"]), plan.reference_ends[1].pw.expect("Pw"));
}

#[test]
fn a_recording_reads_back_as_the_plan() {
    let (robot, task, source, plan, recording) = written("read_back", "construct_scene.a2ml");
    let back = a2ml::output::read_mcap_bytes(&recording.bytes, "plan.mcap").expect("reads");
    let mut expected = a2ml::output::RecordedPlan::of(&plan);
    assert_eq!(back.trajectory, expected.trajectory, "the times exactly");
    assert_eq!(back.task_source.as_deref(), Some(source.as_str()));
    assert!(back.urdf.is_some());
    (expected.urdf, expected.task_source) = (back.urdf.clone(), back.task_source.clone());
    // The scene as the recording draws it, in {b}.
    expected.obstacles = task.in_base_frame(&robot.structure.shoulder_in_base_link).scene;
    assert_eq!(back.obstacles.len(), 5);
    // Quaternions come back on the hemisphere the recording kept them on.
    let same = |a: &Option<UnitQuaternion>, b: &Option<UnitQuaternion>| match (a, b) {
        (Some(a), Some(b)) => a.angle_to(b) < 1e-12,
        (a, b) => a.is_none() && b.is_none(),
    };
    for (a, b) in back.references.iter().zip(&expected.references) {
        assert!(
            same(&a.state.ow, &b.state.ow)
                && same(&a.state.shoulder_frame, &b.state.shoulder_frame)
        );
    }
    for (a, b) in back.segments.iter().zip(&expected.segments) {
        assert!(same(&a.reference_end.ow, &b.reference_end.ow));
    }
    let strip = |p: &mut a2ml::output::RecordedPlan| {
        for r in &mut p.references {
            (r.state.ow, r.state.shoulder_frame) = (None, None);
        }
        for s in &mut p.segments {
            (s.reference_end.ow, s.reference_end.shoulder_frame) = (None, None);
        }
    };
    let mut back = back;
    strip(&mut back);
    strip(&mut expected);
    assert_eq!(back, expected);
}

/// Parses the CSV written for `plan`: header and rows of numbers (`None` for an empty field).
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<Option<Real>>>) {
    let text = fs::read_to_string(path).expect("csv written");
    let mut lines = text.lines();
    let header = lines.next().expect("a header").split(',').map(str::to_owned).collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|x| (!x.is_empty()).then(|| x.parse::<Real>().expect("a number")))
                .collect()
        })
        .collect();
    (header, rows)
}

/// The reference columns of a state: Pw, Ow (x y z w), θsw, Os (x y z w), θe.
fn reference_values(state: &ReferenceState) -> Vec<Option<Real>> {
    let quaternion = |q: Option<UnitQuaternion>| {
        [q.map(|q| q.i), q.map(|q| q.j), q.map(|q| q.k), q.map(|q| q.w)]
    };
    let mut values: Vec<Option<Real>> = (0..3).map(|i| state.pw.map(|p| p[i])).collect();
    values.extend(quaternion(state.ow));
    values.push(state.swivel);
    values.extend(quaternion(state.shoulder_frame));
    values.push(state.elbow_angle);
    values
}

/// Whether two quaternion column groups are the same rotation (q or -q).
fn same_rotation(a: &[Option<Real>], b: &[Option<Real>]) -> bool {
    let (a, b): (Vec<Real>, Vec<Real>) =
        (a.iter().flatten().copied().collect(), b.iter().flatten().copied().collect());
    a.len() == b.len()
        && (a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-15)
            || a.iter().zip(&b).all(|(x, y)| (x + y).abs() < 1e-15))
}

#[test]
fn the_csv_holds_every_sample_exactly() {
    let robot = load("coman_right_arm");
    let plan = plan(&robot);
    let path = scratch("csv").join("plan.csv");
    write_csv(&path, &robot, &plan).expect("csv written");
    let (header, rows) = read_csv(&path);
    let names = robot.joint_names();
    let mut expected = vec!["t".to_owned()];
    expected.extend(names.iter().map(|n| format!("{n}_pos")));
    expected.extend(names.iter().map(|n| format!("{n}_vel")));
    expected.push("ref_segment".to_owned());
    for v in ["pw_x", "pw_y", "pw_z", "ow_x", "ow_y", "ow_z", "ow_w", "swivel"] {
        expected.push(format!("ref_{v}"));
    }
    for v in
        ["shoulder_frame_x", "shoulder_frame_y", "shoulder_frame_z", "shoulder_frame_w", "elbow"]
    {
        expected.push(format!("ref_{v}"));
    }
    expected.push(format!("distance_{}_to_table", robot.capsules[1].name));
    assert_eq!(header, expected);
    assert_eq!(rows.len(), plan.trajectory.len());
    let trajectory = &plan.trajectory;
    for (i, row) in rows.iter().enumerate() {
        let q = trajectory.positions()[i];
        let qd = trajectory.velocities()[i];
        let values: Vec<Real> = std::iter::once(trajectory.times()[i])
            .chain(q.iter().copied())
            .chain(qd.iter().copied())
            .collect();
        for (read, value) in row.iter().zip(&values) {
            let read = read.expect("a joint value");
            assert!((read - value).abs() <= 1e-12 * value.abs(), "{read} vs {value}");
        }
        let reference = &plan.references[i];
        assert_eq!(row[15], Some(reference.segment as Real));
        let expected = reference_values(&reference.state);
        let read = &row[16..29];
        assert_eq!(&read[0..3], &expected[0..3], "Pw at sample {i}");
        assert!(same_rotation(&read[3..7], &expected[3..7]), "Ow at sample {i}");
        assert_eq!(read[7], expected[7], "θsw at sample {i}");
        assert!(same_rotation(&read[8..12], &expected[8..12]), "Os at sample {i}");
        assert_eq!(read[12], expected[12], "θe at sample {i}");
        assert_eq!(row[29], plan.distances[0].distance[i], "distance at sample {i}");
        assert_eq!(row.len(), 30);
    }
    // The table reads back as the trajectory, its other columns aside.
    let back = a2ml::output::read_csv(&path).expect("reads back");
    assert_eq!(back.trajectory, plan.trajectory);
}

#[test]
fn the_json_is_the_plan_with_its_origin() {
    let robot = load("coman_right_arm");
    let (task, _) = task("construct_scene.a2ml");
    let plan = plan(&robot);
    let path = scratch("json").join("plan.json");
    write_json(&path, &robot, &task, &plan).expect("json written");
    let json: Value =
        serde_json::from_str(&fs::read_to_string(&path).expect("written")).expect("JSON");
    assert_eq!(json["a2ml_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(json["robot"], robot.name.as_str());
    assert_eq!(json["task"], "avoid");
    assert_eq!(json["joint_names"], serde_json::json!(plan.joint_names));
    assert_eq!(json["rate"].as_f64(), Some(RATE));
    assert_eq!(json["trajectory"]["times"].as_array().map(Vec::len), Some(SAMPLES));
    let q = &json["trajectory"]["positions"][SAMPLES - 1];
    assert_eq!(q.as_array().map(Vec::len), Some(7));
    assert_eq!(json["segments"][1]["action"], "back");
    let warning = &json["warnings"][0];
    assert_eq!(warning["kind"], "missed_goal");
    assert_eq!(
        (&warning["action"], &warning["segment"]),
        (&serde_json::json!("back"), &serde_json::json!(0))
    );
    assert_eq!(warning["message"], plan.warnings[0].message.as_str());
    let reference = &json["references"][70];
    assert_eq!(reference["segment"], 1);
    let state = &plan.references[70].state;
    assert_eq!(reference["swivel"].as_f64(), state.swivel);
    let pw = state.pw.expect("Pw");
    assert_eq!(reference["pw"], serde_json::json!([pw.x, pw.y, pw.z]));
    let ow = state.ow.expect("Ow");
    assert_eq!(reference["ow"], serde_json::json!([ow.i, ow.j, ow.k, ow.w]), "x y z w");
    assert_eq!(json["reference_ends"].as_array().map(Vec::len), Some(2));
    assert_eq!(json["distances"][0]["obstacle"], "table");
    assert_eq!(json["distances"][0]["distance"][3], Value::Null, "not measured");
    assert_eq!(json["distances"][0]["distance"][4].as_f64(), plan.distances[0].distance[4]);
}

#[test]
fn a_failed_write_leaves_no_file() {
    let robot = load("coman_right_arm");
    let (task, source) = task("construct_scene.a2ml");
    let plan = plan(&robot);
    let dir = scratch("failure");
    let missing = dir.join("missing").join("plan.mcap");
    let err = write_mcap(&missing, &robot, &task, &source, &plan).expect_err("no folder");
    assert!(matches!(&err, OutputError::Io { path, .. } if path.ends_with("plan.mcap")), "{err}");
    let a2ml_error: a2ml::Error = err.into();
    assert!(a2ml_error.to_string().contains("plan.mcap"));
    // A folder in the way of the target is refused before anything is written.
    let blocked = dir.join("plan.csv");
    fs::create_dir(&blocked).expect("folder");
    assert!(matches!(write_csv(&blocked, &robot, &plan), Err(OutputError::NotRegularFile { .. })));
    let json = write_json(&blocked, &robot, &task, &plan);
    assert!(matches!(json, Err(OutputError::NotRegularFile { .. })));
    let left: Vec<_> =
        fs::read_dir(&dir).expect("readable").map(|e| e.expect("entry").file_name()).collect();
    assert_eq!(left, ["plan.csv"], "only the folder itself");
    assert!(fs::read_dir(&blocked).expect("readable").next().is_none());
}
