//! docs/foxglove_layout.json against what Foxglove reads and what the MCAP holds: the layout
//! format (`configById`, a `layout` tree whose leaves are panel ids `Type!name`, the 3D panel's
//! custom layers with a `foxglove.Urdf` layer whose `sourceType` is `topic`), and every topic,
//! frame and message path it names present in a planned example's MCAP.

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;

use serde_json::Value;

use a2ml::output::write_mcap;
use a2ml::solve::{PlanOptions, plan};

use crate::common;

fn layout() -> Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("docs/foxglove_layout.json");
    serde_json::from_str(&std::fs::read_to_string(path).expect("layout file")).expect("JSON")
}

/// The first message of every topic of a planned example's MCAP, and every frame `/tf` names.
fn recording() -> (BTreeMap<String, Value>, BTreeSet<String>) {
    let file = common::example("construct_path_line.a2ml");
    let source = std::fs::read_to_string(&file).expect("example");
    let task = a2ml::language::parse(&source, Some(&file)).expect("valid");
    let robot = a2ml::Robot::from_urdf_file(&task.robot).expect("robot");
    let planned = plan(&robot, &task, &PlanOptions::default()).expect("plans");
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("foxglove_layout");
    std::fs::create_dir_all(&dir).expect("scratch folder");
    let path = dir.join("plan.mcap");
    write_mcap(&path, &robot, &task, &source, &planned).expect("mcap");
    let bytes = std::fs::read(&path).expect("written");
    let mut first = BTreeMap::new();
    let mut frames = BTreeSet::new();
    for message in mcap::MessageStream::new(&bytes).expect("mcap") {
        let message = message.expect("readable");
        let value: Value = serde_json::from_slice(&message.data).expect("JSON message");
        if message.channel.topic == "/tf" {
            for transform in value["transforms"].as_array().expect("transforms") {
                for key in ["parent_frame_id", "child_frame_id"] {
                    frames.insert(transform[key].as_str().expect("a frame").to_owned());
                }
            }
        }
        first.entry(message.channel.topic.clone()).or_insert(value);
    }
    (first, frames)
}

/// The panel ids at the leaves of a layout tree.
fn leaves(node: &Value, out: &mut Vec<String>) {
    match node {
        Value::String(id) => out.push(id.clone()),
        Value::Object(split) => {
            assert!(
                ["row", "column"].contains(&split["direction"].as_str().unwrap_or("")),
                "{split:?}"
            );
            leaves(&split["first"], out);
            leaves(&split["second"], out);
        }
        other => panic!("not a layout node: {other}"),
    }
}

/// The value at a Foxglove message path such as `/joint_states.position[3]`.
fn at_path<'a>(messages: &'a BTreeMap<String, Value>, path: &str) -> Option<&'a Value> {
    let (topic, fields) = path.split_once('.')?;
    let mut value = messages.get(topic)?;
    for field in fields.split('.') {
        let (name, index) = match field.split_once('[') {
            Some((name, rest)) => (name, rest.trim_end_matches(']').parse::<usize>().ok()),
            None => (field, None),
        };
        value = value.get(name)?;
        if let Some(i) = index {
            value = value.get(i)?;
        }
    }
    Some(value)
}

#[test]
fn the_layout_is_foxglove_format_and_names_what_the_mcap_has() {
    let layout = layout();
    let (messages, frames) = recording();
    for key in ["configById", "layout", "globalVariables", "userNodes", "playbackConfig"] {
        assert!(layout.get(key).is_some(), "the layout has no `{key}`");
    }
    let configs = layout["configById"].as_object().expect("configById is an object");
    let mut shown = Vec::new();
    leaves(&layout["layout"], &mut shown);
    let ids: BTreeSet<&str> = configs.keys().map(String::as_str).collect();
    assert_eq!(shown.iter().map(String::as_str).collect::<BTreeSet<_>>(), ids);
    for (id, config) in configs {
        let (kind, name) = id.split_once('!').expect("a panel id is `Type!name`");
        assert!(!name.is_empty(), "{id}");
        match kind {
            "3D" => {
                assert_eq!(config["followTf"], "b");
                assert!(frames.contains("b"), "no /tf transform names frame b: {frames:?}");
                for topic in config["topics"].as_object().expect("topics").keys() {
                    assert!(messages.contains_key(topic), "{id}: no topic {topic}");
                }
                let layers = config["layers"].as_object().expect("layers");
                let urdf: Vec<&Value> =
                    layers.values().filter(|l| l["layerId"] == "foxglove.Urdf").collect();
                assert_eq!(urdf.len(), 1, "one URDF layer");
                assert_eq!(urdf[0]["sourceType"], "topic");
                let topic = urdf[0]["topic"].as_str().expect("the URDF layer's topic");
                let text = messages[topic]["data"].as_str().expect("URDF text in `data`");
                assert!(text.contains("<robot"), "{topic} holds no URDF");
                for layer in layers.values() {
                    assert!(layer["layerId"].as_str().is_some_and(|l| l.starts_with("foxglove.")));
                    if let Some(frame) = layer.get("frameId") {
                        assert!(frames.contains(frame.as_str().expect("a frame")), "{frame}");
                    }
                }
            }
            "Plot" => {
                let paths = config["paths"].as_array().expect("paths");
                assert!(!paths.is_empty(), "{id}");
                for path in paths {
                    let path = path["value"].as_str().expect("a message path");
                    let value = at_path(&messages, path);
                    assert!(value.is_some_and(Value::is_number), "{id}: {path} is no number");
                }
            }
            "RawMessages" => {
                let topic = config["topicPath"].as_str().expect("topicPath");
                assert!(messages.contains_key(topic), "{id}: no topic {topic}");
            }
            other => panic!("{id}: a panel kind the layout should not need: {other}"),
        }
    }
}
