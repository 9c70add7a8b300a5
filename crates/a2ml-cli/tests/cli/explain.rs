//! `a2ml explain`: the tree, JSON keys and exit codes.

use std::path::PathBuf;

use serde_json::Value;

use crate::{a2ml, a2ml_in_repo, example_path, keys, robot_path, sorted, stderr, stdout};

/// Runs `a2ml explain <example>`, checks exit 0 and returns stdout.
fn explain_text(example: &str) -> String {
    let output = a2ml(&["explain", &example_path(example)]);
    assert_eq!(output.status.code(), Some(0), "stderr: {}", stderr(&output));
    stdout(&output)
}

/// Runs `a2ml explain <example> --json`, checks exit 0 and parses stdout.
fn explain_json(example: &str) -> Value {
    let output = a2ml(&["explain", &example_path(example), "--json"]);
    assert_eq!(output.status.code(), Some(0), "stderr: {}", stderr(&output));
    assert!(stderr(&output).is_empty(), "warnings go to the JSON: {}", stderr(&output));
    serde_json::from_str(&stdout(&output)).expect("stdout is JSON")
}

/// Writes a task file next to the test binary and returns its path.
fn temp_task(name: &str, text: &str) -> String {
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::write(&path, text).expect("temp file written");
    path.to_string_lossy().into_owned()
}

/// The text and the JSON of `a2ml explain` on examples of each kind (type I
/// sequences, Opt2, a STRIPS order, type VII), whole, against their snapshots
/// in `snapshots/`. A mismatch fails the test; `cargo insta review` accepts a
/// deliberate change.
#[test]
fn text_and_json_match_their_snapshots() {
    for example in
        ["construct_path_by", "type_iv_forward_bar", "construct_strips", "type_vii_column"]
    {
        let file = format!("examples/{example}.a2ml");
        for (format, args) in
            [("text", vec!["explain", &file]), ("json", vec!["explain", &file, "--json"])]
        {
            let output = a2ml_in_repo(&args);
            assert_eq!(output.status.code(), Some(0), "{file}: {}", stderr(&output));
            insta::assert_snapshot!(format!("{example}_{format}"), stdout(&output));
        }
    }
}

const TARGET_KEYS: [&str; 8] =
    ["variable", "kind", "text", "position", "quaternion", "rpy_deg", "angle", "angle_deg"];
const FEATURE_KEYS: [&str; 7] =
    ["feature", "direction", "axis", "size", "size_deg", "through", "to"];

/// The properties of a type I sequence; its lines to the letter are in the snapshot
/// ([`text_and_json_match_their_snapshots`]).
#[test]
fn type_i_actions_in_written_order() {
    let text = explain_text("construct_path_by.a2ml");
    assert!(text.starts_with("task changes\n"), "{text}");
    assert!(text.contains("order  as written, 4 actions"), "{text}");
    let actions = ["swing_out", "swing_in", "open_elbow", "close_elbow"];
    let at: Vec<usize> = actions
        .iter()
        .map(|a| text.find(&format!("`{a}`")).unwrap_or_else(|| panic!("no {a} in:\n{text}")))
        .collect();
    assert!(at.windows(2).all(|w| w[0] < w[1]), "execution order:\n{text}");
    assert_eq!(text.matches("type I: one path constraint, no goal").count(), 4, "{text}");
    assert!(text.contains("pattern path (all path)"), "{text}");
    assert!(text.contains("+Se: from rest"), "{text}");
}

#[test]
fn type_iv_names_opt2() {
    let text = explain_text("type_iv_forward_bar.a2ml");
    assert!(text.contains("action 1 `rise_along_line`: Raise the wrist"), "{text}");
    assert!(text.contains("type IV: one goal and a hard path in another space"), "{text}");
    assert!(text.contains("96.3 deg"), "{text}");
    assert!(text.contains("[hat]") && text.contains("[cpsa]"), "{text}");
    assert!(text.contains("(size left to Opt2)"), "{text}");
    assert!(text.contains("segment 1  cpsa, pattern mixed (path and goal)"), "{text}");
    assert!(text.contains("solver rrt, from the start"), "{text}");
    assert!(text.contains("+Pa (Ow θsw).goal(rpy("), "{text}");
    let opt = text.lines().find(|l| l.trim_start().starts_with("Opt2")).expect("an Opt2 line");
    assert!(opt.contains("residual ") && opt.contains("sizes Pw line "), "{opt}");
    assert!(opt.ends_with(" evaluations"), "{opt}");
}

#[test]
fn json_has_the_documented_keys() {
    let json = explain_json("type_iv_forward_bar.a2ml");
    assert_eq!(
        keys(&json),
        sorted(vec![
            "task",
            "file",
            "robot",
            "robot_name",
            "start",
            "start_deg",
            "order",
            "actions",
            "warnings"
        ])
    );
    assert_eq!(json["task"], "type_iv_forward_bar");
    assert_eq!(json["robot_name"], "centauro_right_arm");
    assert_eq!(json["order"], "written");
    assert!((json["start_deg"][1].as_f64().expect("deg") + 10.0).abs() < 1e-9);
    let action = &json["actions"][0];
    assert_eq!(
        keys(action),
        sorted(vec![
            "index",
            "name",
            "description",
            "action_type",
            "type_description",
            "goal_space",
            "secondary_goal_space",
            "path_space",
            "goal",
            "path",
            "duration",
            "segments",
            "optimisations",
        ])
    );
    assert_eq!(action["action_type"], "iv");
    assert_eq!(action["goal_space"], "hat");
    assert_eq!(action["path_space"], "cpsa");
    assert!(action["secondary_goal_space"].is_null());

    let goal = &action["goal"];
    assert_eq!(keys(goal), sorted(vec!["text", "primary", "secondary"]));
    assert_eq!(keys(&goal["primary"]), sorted(vec!["space", "targets"]));
    let targets = goal["primary"]["targets"].as_array().expect("targets");
    assert_eq!(targets.len(), 3);
    for t in targets {
        assert_eq!(keys(t), sorted(TARGET_KEYS.to_vec()));
    }
    assert_eq!(targets[0]["variable"], "shoulder_frame");
    assert_eq!(targets[0]["kind"], "rotation");
    assert_eq!(targets[0]["quaternion"].as_array().map(Vec::len), Some(4));
    assert_eq!(targets[1]["variable"], "elbow");
    assert!((targets[1]["angle_deg"].as_f64().expect("deg") - 96.3).abs() < 1e-9);
    assert!(targets[1]["position"].is_null());

    let path = &action["path"];
    assert_eq!(keys(path), sorted(vec!["text", "hard", "space", "items"]));
    assert_eq!(path["hard"], true);
    let item = &path["items"][0];
    let mut item_keys = FEATURE_KEYS.to_vec();
    item_keys.push("variables");
    assert_eq!(keys(item), sorted(item_keys));
    assert_eq!(item["feature"], "line");
    assert!(item["size"].is_null(), "left to Opt2");

    let segments = action["segments"].as_array().expect("segments");
    assert_eq!(segments.len(), 1);
    let segment = &segments[0];
    assert_eq!(
        keys(segment),
        sorted(vec![
            "number",
            "space",
            "pattern",
            "duration",
            "duration_raised",
            "solver",
            "connection",
            "primitives",
            "relaxed",
            "start",
            "start_deg",
            "end",
            "end_deg",
        ])
    );
    assert_eq!(segment["number"], 1);
    assert_eq!(segment["space"], "cpsa");
    assert_eq!(segment["pattern"], "mixed");
    assert_eq!(segment["solver"], "rrt");
    assert_eq!(segment["connection"], "start");
    assert!(segment["duration"].as_f64().expect("duration") > 0.0);
    let primitives = segment["primitives"].as_array().expect("primitives");
    for p in primitives {
        assert_eq!(keys(p), sorted(vec!["constraint", "variables", "text", "targets", "path"]));
    }
    assert_eq!(primitives[0]["constraint"], "path");
    assert_eq!(keys(&primitives[0]["path"]), sorted(FEATURE_KEYS.to_vec()));
    assert_eq!(primitives[1]["constraint"], "goal");
    assert_eq!(primitives[1]["variables"], serde_json::json!(["ow", "swivel"]));

    let opts = action["optimisations"].as_array().expect("optimisations");
    assert_eq!(opts.len(), 1);
    assert_eq!(keys(&opts[0]), sorted(vec!["solver", "residual", "sizes", "evaluations"]));
    assert_eq!(opts[0]["solver"], "Opt2");
    assert!(opts[0]["residual"].as_f64().expect("residual") >= 0.0);
    // The length Opt2 chose is the one the path primitive travels.
    assert_eq!(opts[0]["sizes"][0], primitives[0]["path"]["size"]);
    assert_eq!(json["warnings"], serde_json::json!([]));
}

#[test]
fn json_of_type_i_connects_actions_sequentially() {
    let json = explain_json("construct_path_by.a2ml");
    let actions = json["actions"].as_array().expect("actions");
    assert_eq!(actions.len(), 4);
    for (i, a) in actions.iter().enumerate() {
        assert_eq!(a["action_type"], "i");
        assert_eq!(a["index"], i);
        assert!(a["goal"].is_null());
        assert_eq!(a["optimisations"], serde_json::json!([]));
        let expected = if i == 0 { "start" } else { "sequential" };
        assert_eq!(a["segments"][0]["connection"], expected);
    }
    let by = &actions[0]["path"]["items"][0];
    assert_eq!(by["feature"], "by");
    assert!((by["size_deg"].as_f64().expect("deg") - 20.0).abs() < 1e-9);
    // Each action starts where the last one ended.
    assert_eq!(actions[1]["segments"][0]["start"], actions[0]["segments"][0]["end"]);
}

#[test]
fn planned_order_and_explicit_actions() {
    let task = temp_task(
        "planned_explicit.a2ml",
        &format!(
            "robot \"{}\"\nstart [0, -20, 0, -60, 0, 10, 0] deg\n\
             task t {{\n  init {{ low }}\n  goal {{ done }}\n\
             action down {{ pre {{ high }} add {{ done }} path Pw line [0, 0, -1] 3 cm, Ow hold, θsw hold }}\n\
             action up explicit {{ pre {{ low }} add {{ high }}\n\
             segment 0.5 s {{ (Pw Ow θsw).hold }}\n\
             +Tr segment {{ Pw.path(line [0, 0, 1], 2 cm) +Pa (Ow θsw).hold }} }}\n}}\n",
            robot_path("coman_right_arm.urdf")
        ),
    );
    let output = a2ml(&["explain", &task, "--json"]);
    assert_eq!(output.status.code(), Some(0), "stderr: {}", stderr(&output));
    let json: Value = serde_json::from_str(&stdout(&output)).expect("stdout is JSON");
    assert_eq!(json["order"], "planned");
    let up = &json["actions"][0];
    assert_eq!((up["name"].as_str(), up["index"].as_u64()), (Some("up"), Some(1)));
    assert!(up["action_type"].is_null() && up["goal"].is_null() && up["path"].is_null());
    let connections: Vec<&Value> =
        [&up["segments"][0], &up["segments"][1], &json["actions"][1]["segments"][0]]
            .into_iter()
            .map(|s| &s["connection"])
            .collect();
    assert_eq!(
        connections,
        [&Value::from("start"), &Value::from("transitional"), &Value::from("sequential")]
    );
    assert_eq!(up["segments"][0]["duration"], 0.5);
    assert_eq!(up["segments"][1]["primitives"][0]["text"], "Pw.path(line [0, 0, 1], 0.02 m)");

    let output = a2ml(&["explain", &task]);
    let text = stdout(&output);
    assert!(text.contains("order  planned from `init` to `goal` (STRIPS), 2 actions"), "{text}");
    assert!(text.contains("explicit: the segments are written out"), "{text}");
}

#[test]
fn task_without_start_exits_2() {
    let task = temp_task(
        "no_start.a2ml",
        &format!(
            "robot \"{}\"\ntask reach {{ action go {{ goal θsw = 10 deg }} }}\n",
            robot_path("iiwa14.urdf")
        ),
    );
    let output = a2ml(&["explain", &task]);
    assert_eq!(output.status.code(), Some(2));
    let err = stderr(&output);
    assert!(err.starts_with("error: ") && err.contains("task `reach` has no `start`"), "{err}");
    assert!(stdout(&output).is_empty());
}

#[test]
fn invalid_task_exits_2_with_diagnostics() {
    let task = temp_task(
        "invalid_explain.a2ml",
        "robot \"nowhere.urdf\"\ntask t { action a { goal θsw = 1 deg } }\n",
    );
    let output = a2ml(&["explain", &task]);
    assert_eq!(output.status.code(), Some(2));
    let err = stderr(&output);
    assert!(err.contains("invalid_explain.a2ml:1:8") && err.contains('^'), "{err}");
    assert!(err.contains("is not a valid task"), "{err}");
    assert!(stdout(&output).is_empty());
}

#[test]
fn missing_file_exits_1() {
    let output = a2ml(&["explain", "/nonexistent/task.a2ml"]);
    assert_eq!(output.status.code(), Some(1));
    let err = stderr(&output);
    assert!(err.starts_with("error: cannot read /nonexistent/task.a2ml"), "{err}");
    assert!(stdout(&output).is_empty());
}

/// Every key of `value`, at any depth.
fn all_keys(value: &Value, out: &mut Vec<String>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                out.push(k.clone());
                all_keys(v, out);
            }
        }
        Value::Array(items) => items.iter().for_each(|v| all_keys(v, out)),
        _ => {}
    }
}

#[test]
fn docs_name_every_json_key() {
    let doc_path: PathBuf =
        [env!("CARGO_MANIFEST_DIR"), "..", "..", "docs", "cli.md"].iter().collect();
    let doc = std::fs::read_to_string(doc_path).expect("docs/cli.md");
    let section = doc.split("## `a2ml explain`").nth(1).expect("an explain section");
    let section = section.split("\n## ").next().unwrap_or(section);
    let mut names = Vec::new();
    all_keys(&explain_json("type_iv_forward_bar.a2ml"), &mut names);
    all_keys(&explain_json("construct_path_by.a2ml"), &mut names);
    for name in names {
        assert!(
            section.contains(&format!("`{name}`")),
            "the explain section of docs/cli.md does not document `{name}`"
        );
    }
}
