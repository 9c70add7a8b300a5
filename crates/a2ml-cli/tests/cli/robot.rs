//! `a2ml robot`: output, JSON keys and exit codes.

use std::path::PathBuf;

use serde_json::Value;

use crate::{a2ml, example_path, keys, robot_path, scratch, sorted, stderr, stdout};

/// A regular iiwa14 configuration within the limits whose feasible swivel
/// angles form proper intervals (not the whole circle).
const REGULAR: &str = "0.5,-1.8,0.2,-2.0,1.2,1.7,-2";

/// Runs `a2ml robot <urdf> <args> --json`, checks exit 0 and parses stdout.
fn robot_json(urdf: &str, args: &[&str]) -> Value {
    let path = robot_path(urdf);
    let mut all = vec!["robot", path.as_str()];
    all.extend_from_slice(args);
    all.push("--json");
    let output = a2ml(&all);
    assert_eq!(output.status.code(), Some(0), "stderr: {}", stderr(&output));
    serde_json::from_str(&stdout(&output)).expect("stdout is JSON")
}

fn floats(value: &Value) -> Vec<f64> {
    value.as_array().expect("an array").iter().map(|v| v.as_f64().expect("a number")).collect()
}

/// The line of `text` that starts (after indentation) with `label`.
fn line<'a>(text: &'a str, label: &str) -> &'a str {
    text.lines()
        .find(|l| l.trim_start().starts_with(label))
        .unwrap_or_else(|| panic!("no line starting with `{label}` in:\n{text}"))
}

#[test]
fn structure_of_iiwa14() {
    let output = a2ml(&["robot", &robot_path("iiwa14.urdf")]);
    assert_eq!(output.status.code(), Some(0));
    let text = stdout(&output);
    assert!(line(&text, "upper arm lu (m)").ends_with(" 0.4200"));
    assert!(line(&text, "forearm lf (m)").ends_with(" 0.4000"));
    assert!(line(&text, "SRS (is_srs)").ends_with(" yes"));
    assert!(line(&text, "analytic IK").ends_with(" yes"));
    assert!(line(&text, "chain").contains("lbr_link_0 -> hand"));
    assert!(line(&text, "1  lbr_A1").contains("-170.00"));
    assert!(line(&text, "upper_arm").contains("lbr_link_3"));
    assert!(!text.contains("state at q"), "no state without --at");
    assert!(stderr(&output).is_empty());
}

#[test]
fn json_has_the_documented_keys() {
    let json = robot_json("iiwa14.urdf", &[]);
    assert_eq!(
        keys(&json),
        sorted(vec![
            "name",
            "base_link",
            "tip_link",
            "joints",
            "structure",
            "capsules",
            "state",
            "warnings"
        ])
    );
    assert_eq!(json["name"], "iiwa14");
    assert!(json["state"].is_null());
    assert_eq!(json["warnings"], serde_json::json!([]));
    let joints = json["joints"].as_array().expect("joints");
    assert_eq!(joints.len(), 7);
    assert_eq!(
        keys(&joints[0]),
        sorted(vec![
            "name",
            "lower",
            "upper",
            "velocity",
            "lower_deg",
            "upper_deg",
            "velocity_deg"
        ])
    );
    let s = &json["structure"];
    assert_eq!(
        keys(s),
        sorted(vec![
            "shoulder_in_base_link",
            "elbow_zero",
            "wrist_zero",
            "upper_arm_length",
            "forearm_length",
            "elbow_offsets",
            "shoulder_spherical",
            "wrist_spherical",
            "wrist_decoupled",
            "is_srs",
            "has_analytic_ik",
        ])
    );
    assert!((s["upper_arm_length"].as_f64().expect("lu") - 0.42).abs() < 1e-9);
    assert!((s["forearm_length"].as_f64().expect("lf") - 0.4).abs() < 1e-9);
    assert_eq!(s["is_srs"], true);
    assert_eq!(s["has_analytic_ik"], true);
    let capsule = &json["capsules"][0];
    assert_eq!(keys(capsule), sorted(vec!["name", "link", "role", "radius", "length", "source"]));
    assert_eq!(capsule["role"], "upper_arm");
    assert_eq!(capsule["source"], "shape");
}

#[test]
fn state_at_a_regular_configuration() {
    let json = robot_json("iiwa14.urdf", &["--at", REGULAR]);
    assert_eq!(json["warnings"], serde_json::json!([]));
    let state = &json["state"];
    assert_eq!(
        keys(state),
        sorted(vec![
            "q",
            "q_deg",
            "hand",
            "shoulder",
            "elbow",
            "wrist",
            "cpsa",
            "cpsa_error",
            "hat",
            "hat_error",
            "swivel_intervals",
            "swivel_intervals_error",
        ])
    );
    assert_eq!(keys(&state["hand"]), sorted(vec!["position", "orientation"]));
    assert_eq!(keys(&state["cpsa"]), sorted(vec!["pw", "ow", "swivel", "swivel_deg"]));
    assert_eq!(
        keys(&state["hat"]),
        sorted(vec!["r", "l", "f", "p", "shoulder_frame", "ow", "elbow_angle", "elbow_angle_deg"])
    );
    assert!(state["cpsa_error"].is_null() && state["hat_error"].is_null());
    assert!(state["swivel_intervals_error"].is_null());

    let position = floats(&state["hand"]["position"]);
    let pw = floats(&state["cpsa"]["pw"]);
    for (a, b) in position.iter().zip(&pw) {
        assert!((a - b).abs() < 1e-12, "pw {pw:?} != hand position {position:?}");
    }
    let orientation = floats(&state["hand"]["orientation"]);
    assert_eq!(orientation.len(), 4);
    assert!((orientation.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-12);
    assert!(orientation[0] >= 0.0, "w >= 0");
    assert_eq!(floats(&state["cpsa"]["ow"]), orientation);

    let swivel = state["cpsa"]["swivel"].as_f64().expect("swivel");
    let intervals = state["swivel_intervals"].as_array().expect("intervals");
    assert!(!intervals.is_empty());
    let whole = intervals.len() == 1
        && intervals[0]["upper"].as_f64().expect("upper")
            - intervals[0]["lower"].as_f64().expect("lower")
            > 6.0;
    assert!(!whole, "this configuration should restrict the swivel angle");
    assert!(
        intervals.iter().any(|i| {
            let (lower, upper) =
                (i["lower"].as_f64().expect("lower"), i["upper"].as_f64().expect("upper"));
            lower <= swivel && swivel <= upper
        }),
        "θsw {swivel} in none of {intervals:?}"
    );
    let alpha = state["hat"]["elbow_angle"].as_f64().expect("elbow angle");
    assert!(alpha > 0.0 && alpha < std::f64::consts::PI);
}

#[test]
fn state_in_text() {
    let output = a2ml(&["robot", &robot_path("iiwa14.urdf"), "--at", REGULAR]);
    assert_eq!(output.status.code(), Some(0));
    let text = stdout(&output);
    assert!(line(&text, "q (rad)").contains("-1.8000"));
    assert!(line(&text, "θsw (rad, °)").contains("-0.2583"));
    assert!(text.contains("<- θsw"), "the interval holding θsw is marked:\n{text}");
}

#[test]
fn degrees_convert() {
    let rad = robot_json("iiwa14.urdf", &["--at", "0.3,0.5,-0.2,1.2,0.4,-0.6,0.1"]);
    let deg = robot_json("iiwa14.urdf", &["--at", "30,-45,10,90,0,60,-90", "--deg"]);
    let q = floats(&deg["state"]["q"]);
    let expected = [30.0_f64, -45.0, 10.0, 90.0, 0.0, 60.0, -90.0].map(f64::to_radians);
    for (a, b) in q.iter().zip(expected) {
        assert!((a - b).abs() < 1e-15);
    }
    assert!((floats(&deg["state"]["q_deg"])[3] - 90.0).abs() < 1e-12);
    // A radian input reports the same angles back in degrees.
    let swivel = &rad["state"]["cpsa"];
    let (r, d) =
        (swivel["swivel"].as_f64().expect("rad"), swivel["swivel_deg"].as_f64().expect("deg"));
    assert!((r.to_degrees() - d).abs() < 1e-12);
}

#[test]
fn straight_arm_is_reported_not_failed() {
    let json = robot_json("iiwa14.urdf", &["--at", "0,0,0,0,0,0,0"]);
    let state = &json["state"];
    assert!(state["cpsa"].is_null());
    assert!(state["cpsa_error"].as_str().expect("error").contains("straight"));
    assert!(state["hat"].is_null());
    assert!(state["hat_error"].as_str().expect("error").contains("straight"));
    assert!(state["swivel_intervals"].is_null());
    assert!(state["swivel_intervals_error"].as_str().is_some());

    let output = a2ml(&["robot", &robot_path("iiwa14.urdf"), "--at", "0,0,0,0,0,0,0"]);
    assert_eq!(output.status.code(), Some(0));
    assert!(stdout(&output).contains("singular: the arm is straight"));
    assert!(stdout(&output).contains("not available: "));
}

#[test]
fn outside_limits_is_a_warning() {
    let at = ["--at", "0,0,0,130,0,0,0", "--deg"];
    let json = robot_json("iiwa14.urdf", &at);
    let warnings = json["warnings"].as_array().expect("warnings");
    assert_eq!(warnings.len(), 1);
    assert!(warnings[0].as_str().expect("text").contains("lbr_A4"));

    let path = robot_path("iiwa14.urdf");
    let output = a2ml(&["robot", &path, at[0], at[1], at[2]]);
    assert_eq!(output.status.code(), Some(0));
    assert!(stderr(&output).starts_with("warning: joint 4 `lbr_A4`"));
}

#[test]
fn arm_without_analytic_ik_has_no_intervals() {
    let json = robot_json("human_arm.urdf", &["--at", "0.2,-0.3,0.1,1.2,0.3,0.2,0.1"]);
    assert_eq!(json["structure"]["has_analytic_ik"], false);
    assert!(json["state"]["swivel_intervals"].is_null());
    assert!(json["state"]["swivel_intervals_error"].as_str().is_some());
}

#[test]
fn every_shipped_robot_loads() {
    for urdf in [
        "iiwa14.urdf",
        "panda.urdf",
        "centauro_right_arm.urdf",
        "coman_right_arm.urdf",
        "human_arm.urdf",
    ] {
        let json = robot_json(urdf, &["--at", "0.1,-0.2,0.1,-0.5,0.1,0.2,0.1"]);
        assert_eq!(json["joints"].as_array().map(Vec::len), Some(7), "{urdf}");
    }
}

#[test]
fn missing_file_exits_1() {
    let output = a2ml(&["robot", "/nonexistent/arm.urdf"]);
    assert_eq!(output.status.code(), Some(1));
    assert!(stderr(&output).starts_with("error: "), "{}", stderr(&output));
    assert!(stdout(&output).is_empty());
}

/// `--srdf` is the SRDF read by `robot` and `plan`: a valid one loads, one naming a link
/// the URDF lacks or that cannot be read is refused with its path (exit 2), as the SRDF
/// beside a URDF is.
#[test]
fn srdf_flag_names_the_srdf_read() {
    let dir = scratch("robot", "srdf_flag_names_the_srdf_read");
    let good = dir.join("pairs.srdf");
    std::fs::write(
        &good,
        "<robot name=\"panda\">\n  <disable_collisions link1=\"hand\" link2=\"panda_link3\" \
         reason=\"Never\"/>\n</robot>\n",
    )
    .expect("SRDF written");
    let bad = dir.join("bad.srdf");
    std::fs::write(
        &bad,
        "<robot>\n\n  <disable_collisions link1=\"hand\" link2=\"panda_link33\"/>\n</robot>",
    )
    .expect("SRDF written");
    let panda = robot_path("panda.urdf");
    let output = a2ml(&["robot", &panda, "--srdf", &good.to_string_lossy()]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));

    let output = a2ml(&["robot", &panda, "--srdf", &bad.to_string_lossy()]);
    assert_eq!(output.status.code(), Some(2));
    let err = stderr(&output);
    assert!(err.contains(&format!("{}: line 3: invalid SRDF", bad.display())), "{err}");
    assert!(err.contains("`panda_link33`"), "{err}");

    let missing = dir.join("missing.srdf");
    let task = example_path("construct_minimal.a2ml");
    let plan = dir.join("plan.mcap");
    let output =
        a2ml(&["plan", &task, "-o", &plan.to_string_lossy(), "--srdf", &missing.to_string_lossy()]);
    assert_eq!(output.status.code(), Some(2));
    let err = stderr(&output);
    assert!(err.contains(&format!("{}: invalid SRDF", missing.display())), "{err}");
    assert!(!plan.exists(), "nothing is planned with an SRDF that cannot be read");
}

#[test]
fn broken_urdf_exits_2() {
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("broken.urdf");
    std::fs::write(&path, "<robot name=\"broken\"><link name=\"a\">").expect("temp file written");
    let output = a2ml(&["robot", &path.to_string_lossy()]);
    assert_eq!(output.status.code(), Some(2));
    let err = stderr(&output);
    assert!(err.starts_with("error: ") && err.contains("invalid URDF"), "{err}");
    assert!(!err.contains("panicked") && !err.contains("RobotError"), "{err}");
}

#[test]
fn not_seven_dof_exits_2() {
    let output = a2ml(&["robot", &robot_path("iiwa14.urdf"), "--base", "lbr_link_2"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("needs 7"), "{}", stderr(&output));
}

#[test]
fn wrong_count_exits_2() {
    let output = a2ml(&["robot", &robot_path("iiwa14.urdf"), "--at", "0.1,0.2,0.3"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("expected 7 comma-separated joint values, got 3"));
}

#[test]
fn unparsable_value_exits_2_naming_it() {
    let output = a2ml(&["robot", &robot_path("iiwa14.urdf"), "--at", "0.1,0.2,abc,0,0,0,0"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("joint value 3 (`abc`) is not a number"),
        "{}",
        stderr(&output)
    );
}

#[test]
fn negative_first_value_is_a_value() {
    let json = robot_json("iiwa14.urdf", &["--at", "-0.3,0.5,-0.2,1.2,0.4,-0.6,0.1"]);
    assert_eq!(floats(&json["state"]["q"])[0], -0.3);
}

#[test]
fn unknown_tip_exits_2_with_suggestion() {
    let output = a2ml(&["robot", &robot_path("iiwa14.urdf"), "--tip", "lbr_link7"]);
    assert_eq!(output.status.code(), Some(2));
    let err = stderr(&output);
    assert!(err.contains("did you mean `lbr_link_7`"), "{err}");
}

#[test]
fn version_and_help() {
    let output = a2ml(&["--version"]);
    assert_eq!(output.status.code(), Some(0));
    assert!(stdout(&output).starts_with("a2ml "));
    let output = a2ml(&["robot", "--help"]);
    assert_eq!(output.status.code(), Some(0));
    assert!(stdout(&output).contains("Examples:"));
}

/// Every key path of `value`, array elements as `[]`: `state.hat.r`, `joints[].name`.
fn key_paths(value: &Value, prefix: &str, out: &mut Vec<String>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                let path = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                out.push(path.clone());
                key_paths(v, &path, out);
            }
        }
        Value::Array(items) => {
            for item in items {
                key_paths(item, &format!("{prefix}[]"), out);
            }
        }
        _ => {}
    }
}

#[test]
fn docs_name_every_json_key() {
    let doc_path: PathBuf =
        [env!("CARGO_MANIFEST_DIR"), "..", "..", "docs", "cli.md"].iter().collect();
    let doc = std::fs::read_to_string(doc_path).expect("docs/cli.md");
    let mut paths = Vec::new();
    key_paths(&robot_json("iiwa14.urdf", &["--at", REGULAR]), "", &mut paths);
    for path in paths {
        // `joints[].lower` may be documented together with its twin as `.upper`.
        let last = path.rsplit('.').next().unwrap_or(&path);
        assert!(
            doc.contains(&format!("`{path}`")) || doc.contains(&format!("`.{last}`")),
            "docs/cli.md does not document `{path}`"
        );
    }
}
