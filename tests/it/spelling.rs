//! One spelling per enum on every surface, and core types that read back what they write:
//! every example's plan and task through JSON, every enum value of the plan JSON and of the
//! MCAP segment messages (and their schema) among the values docs/cli.md documents, the same
//! in both.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

use a2ml::language::{self, Task};
use a2ml::output::{topics, write_json, write_mcap};
use a2ml::solve::{Plan, PlanOptions, plan};
use a2ml::spelling::catalogue;
use a2ml::{Robot, RobotOptions};
use serde_json::Value;

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("spelling-{name}"));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// The shipped examples of examples/ (not its subfolders), by name.
fn examples() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut files: Vec<PathBuf> = fs::read_dir(&dir)
        .expect("examples/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "a2ml"))
        .collect();
    files.sort();
    files
}

/// Every example that plans, with its robot and plan (some examples are meant to fail).
fn planned_examples() -> Vec<(String, Task, String, Robot, Plan)> {
    examples()
        .into_iter()
        .filter_map(|path| {
            let name = path.file_stem().expect("stem").to_string_lossy().into_owned();
            let source = fs::read_to_string(&path).expect("readable");
            let task = language::parse(&source, Some(&path)).expect("every example is valid");
            let robot = task.load_robot(&RobotOptions::default()).expect("robot");
            let planned = plan(&robot, &task, &PlanOptions::default()).ok()?;
            Some((name, task, source, robot, planned))
        })
        .collect()
}

/// The plan without what plan files leave out on purpose: the wall-clock timings.
fn without_timings(mut plan: Plan) -> Plan {
    for s in &mut plan.segments {
        s.qp.mean_step_time = 0.0;
        s.qp.worst_step_time = 0.0;
        s.qp.median_fast_time = 0.0;
        s.qp.median_clarabel_time = 0.0;
        if let Some(rrt) = &mut s.rrt {
            rrt.time = 0.0;
        }
    }
    plan
}

/// The "Enum values" table of docs/cli.md: enum name -> values.
fn documented() -> BTreeMap<String, Vec<String>> {
    let docs = fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/cli.md"))
        .expect("docs/cli.md");
    let section = docs.split("## Enum values").nth(1).expect("an Enum values section");
    let mut table = BTreeMap::new();
    for line in section.lines().skip_while(|l| !l.starts_with("| enum |")).skip(2) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 4 {
            break;
        }
        let values = cells[2].split(", ").map(|v| v.trim_matches('`').to_owned()).collect();
        table.insert(cells[1].to_owned(), values);
    }
    table
}

#[test]
fn the_docs_table_is_the_code() {
    let docs = documented();
    let code: BTreeMap<String, Vec<String>> = catalogue()
        .into_iter()
        .map(|(what, values)| (what.to_owned(), values.into_iter().map(str::to_owned).collect()))
        .collect();
    assert_eq!(docs, code);
}

#[test]
fn every_examples_plan_and_task_round_trip_through_json() {
    let planned = planned_examples();
    assert!(planned.len() >= 20, "only {} examples planned", planned.len());
    for (name, task, _, _, planned) in planned {
        let json = serde_json::to_string(&planned).expect("serialises");
        let back: Plan = serde_json::from_str(&json).expect("deserialises");
        assert_eq!(back, without_timings(planned), "{name}");
        assert_eq!(serde_json::to_string(&back).expect("serialises"), json, "{name}: same text");
        let task_json = serde_json::to_string(&task).expect("serialises");
        let task_back: Task = serde_json::from_str(&task_json).expect("deserialises");
        assert_eq!(task_back, task, "{name}");
        assert_eq!(task_back.robot, task.robot, "{name}");
    }
}

#[test]
fn a_plan_file_with_bad_samples_is_an_error() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/construct_goal.a2ml");
    let task = language::load(&path).expect("loads");
    let robot = task.load_robot(&RobotOptions::default()).expect("robot");
    let planned = plan(&robot, &task, &PlanOptions::default()).expect("plans");
    let mut json: Value = serde_json::to_value(&planned).expect("serialises");
    json["trajectory"]["times"][1] = json["trajectory"]["times"][0].clone();
    let error = serde_json::from_value::<Plan>(json).expect_err("times not increasing");
    assert!(error.to_string().contains("does not follow"), "{error}");
    let mut json: Value = serde_json::to_value(&planned).expect("serialises");
    json["segments"][0]["space"] = Value::from("CPSA");
    let error = serde_json::from_value::<Plan>(json).expect_err("an old spelling");
    assert!(error.to_string().contains("cpsa"), "{error}");
}

/// The fields of a segment report or message that hold enum values, with their enum.
const SEGMENT_ENUMS: [(&str, &str); 5] = [
    ("action_type", "action type"),
    ("space", "space"),
    ("pattern", "segment pattern"),
    ("solver", "solver"),
    ("fallback", "fallback"),
];

/// Every enum value of a segment record, as (enum, value), checked against the docs.
fn segment_values(record: &Value, docs: &BTreeMap<String, Vec<String>>) -> Vec<(String, String)> {
    let mut values = Vec::new();
    for (field, what) in SEGMENT_ENUMS {
        if let Some(v) = record.get(field).filter(|v| !v.is_null()) {
            values.push((what.to_owned(), v.as_str().expect("a string").to_owned()));
        }
    }
    let variables = record["focus"].as_array().expect("focus").iter().chain(
        ["errors", "path_errors"]
            .iter()
            .flat_map(|k| record[*k].as_array().expect("errors"))
            .map(|e| &e["variable"]),
    );
    values.extend(variables.map(|v| ("variable".to_owned(), v.as_str().expect("text").to_owned())));
    for (what, value) in &values {
        assert!(docs[what].contains(value), "{what} `{value}` is not in docs/cli.md");
    }
    values
}

#[test]
fn every_enum_value_of_the_json_and_the_mcap_is_documented_and_the_same() {
    let docs = documented();
    let mut seen: BTreeSet<(String, String)> = BTreeSet::new();
    for (name, task, source, robot, planned) in planned_examples() {
        let dir = scratch(&name);
        write_json(&dir.join("plan.json"), &robot, &task, &planned).expect("json written");
        write_mcap(&dir.join("plan.mcap"), &robot, &task, &source, &planned).expect("mcap");
        let json: Value =
            serde_json::from_slice(&fs::read(dir.join("plan.json")).expect("json")).expect("JSON");
        let bytes = fs::read(dir.join("plan.mcap")).expect("mcap");
        let mut messages = Vec::new();
        for message in mcap::MessageStream::new(&bytes).expect("mcap") {
            let message = message.expect("readable");
            if message.channel.topic != topics::SEGMENTS {
                continue;
            }
            let schema = message.channel.schema.as_ref().expect("a schema");
            let schema: Value = serde_json::from_slice(&schema.data).expect("schema JSON");
            for (field, what) in SEGMENT_ENUMS {
                let listed = &schema["properties"][field]["enum"];
                assert_eq!(*listed, serde_json::json!(docs[what]), "{name}: schema of {field}");
            }
            messages.push(serde_json::from_slice::<Value>(&message.data).expect("JSON"));
        }
        let segments = json["segments"].as_array().expect("segments");
        assert_eq!(messages.len(), segments.len(), "{name}");
        // Both in start order here: segments are planned in time order.
        for (segment, message) in segments.iter().zip(&messages) {
            let from_json = segment_values(segment, &docs);
            assert_eq!(segment_values(message, &docs), from_json, "{name}");
            seen.extend(from_json);
        }
        for warning in json["warnings"].as_array().expect("warnings") {
            let kind = warning["kind"].as_str().expect("a kind");
            assert!(docs["warning kind"].iter().any(|k| k == kind), "{name}: {kind}");
            let message = warning["message"].as_str().expect("a message");
            if let Some(action) = warning["action"].as_str() {
                assert!(message.contains(&format!("`{action}`")), "{name}: {message}");
            }
            seen.insert(("warning kind".to_owned(), kind.to_owned()));
        }
    }
    // The examples between them show every space, pattern and variable.
    for what in ["space", "segment pattern", "variable"] {
        for value in &docs[what] {
            assert!(seen.contains(&(what.to_owned(), value.clone())), "no example shows {value}");
        }
    }
}
