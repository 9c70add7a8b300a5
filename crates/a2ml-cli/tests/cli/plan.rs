//! `a2ml plan`: the files written, the summary table and the exit codes.

use std::fs;
use std::path::Path;
use std::process::Command;

use serde_json::Value;

use crate::{a2ml, a2ml_in_repo, example_path, fixture, scratch, stderr, stdout};

/// The first bytes of every MCAP file.
const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

fn path_in(dir: &Path, name: &str) -> String {
    dir.join(name).to_string_lossy().into_owned()
}

/// The names in `dir`, hidden files (a writer's temporary file) included, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .expect("folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort_unstable();
    names
}

/// The summary row of each segment: the lines after the header up to the blank line.
fn rows(text: &str) -> Vec<&str> {
    text.lines()
        .skip_while(|l| !l.trim_start().starts_with("action "))
        .skip(1)
        .take_while(|l| !l.is_empty())
        .collect()
}

#[test]
fn writes_mcap_csv_and_json() {
    let dir = scratch("plan", "writes_mcap_csv_and_json");
    let (mcap, csv, json) =
        (path_in(&dir, "lines.mcap"), path_in(&dir, "lines.csv"), path_in(&dir, "lines.json"));
    let task = example_path("construct_path_line.a2ml");
    let output = a2ml(&["plan", &task, "-o", &mcap, "--csv", &csv, "--json", &json]);
    assert_eq!(output.status.code(), Some(0), "stderr: {}", stderr(&output));
    assert!(stderr(&output).is_empty(), "no warning, no progress bar off a terminal");

    let text = stdout(&output);
    assert!(text.starts_with("plan lines\n"), "{text}");
    assert!(text.contains("  robot  coman_right_arm\n"), "{text}");
    let header = text.lines().find(|l| l.trim_start().starts_with("action ")).expect("header");
    let columns = [
        "action",
        "segment",
        "type",
        "pattern",
        "space",
        "solver",
        "duration (s)",
        "goal error",
        "clearance (mm)",
        "limit margin (°)",
        "status",
    ];
    let at: Vec<usize> = columns.iter().map(|c| header.find(c).expect(c)).collect();
    assert!(at.windows(2).all(|w| w[0] < w[1]), "{header}");
    let rows = rows(&text);
    assert_eq!(rows.len(), 3, "{text}");
    let row: Vec<&str> = rows[2].split_whitespace().collect();
    assert_eq!(&row[..6], ["rise_towards_elbow_goal", "1", "iv", "mixed", "cpsa", "qp"], "{text}");
    assert_eq!(row.last(), Some(&"ok"), "{text}");
    assert!(rows[0].starts_with("  slide_left ") && rows[0].contains(" i "), "{text}");
    let total = text.lines().find(|l| l.starts_with("total  ")).expect("a total line");
    assert!(total.contains(" s of motion, ") && total.contains(" at 100 Hz, planned in "));
    assert!(total.contains(" QP steps (") && total.ends_with("%)"), "{total}");
    for path in [&mcap, &csv, &json] {
        assert!(text.contains(&format!("wrote  {path}\n")), "{text}");
    }

    let bytes = fs::read(&mcap).expect("MCAP written");
    assert!(bytes.len() > MCAP_MAGIC.len() && bytes.starts_with(MCAP_MAGIC));

    let table = fs::read_to_string(&csv).expect("CSV written");
    let mut lines = table.lines();
    let head: Vec<&str> = lines.next().expect("a header").split(',').collect();
    // t, 7 positions, 7 velocities, the 14 reference columns; no obstacle, no distance.
    assert_eq!(head.len(), 1 + 2 * 7 + 14, "{head:?}");
    assert_eq!((head[0], head[1], head[8]), ("t", "RShSag_pos", "RShSag_vel"));
    assert_eq!((head[15], head[28]), ("ref_segment", "ref_elbow"));
    // The total line counts the samples, one CSV row each.
    let samples: usize = total
        .split(", ")
        .find_map(|part| part.strip_suffix(" samples at 100 Hz"))
        .and_then(|n| n.parse().ok())
        .expect("a sample count");
    assert_eq!(lines.clone().count(), samples);
    assert!(lines.all(|l| l.split(',').count() == head.len()));

    let plan: Value =
        serde_json::from_str(&fs::read_to_string(&json).expect("JSON written")).expect("JSON");
    assert_eq!(plan["task"], "lines");
    assert_eq!(plan["rate"], 100.0);
    let segments = plan["segments"].as_array().expect("segments");
    let actions: Vec<&str> = segments.iter().map(|s| s["action"].as_str().expect("name")).collect();
    assert_eq!(actions, ["slide_left", "slide_back", "rise_towards_elbow_goal"]);
    assert!(segments.iter().all(|s| s["reached"] == true));
    assert_eq!(plan["warnings"], serde_json::json!([]));
    assert_eq!(plan["trajectory"]["times"].as_array().expect("times").len(), samples);
}

/// The whole summary of a few examples against its snapshot in `snapshots/`,
/// the planning time (the clock's, different on every run) and the scratch
/// folder redacted, every other figure kept.
#[test]
fn summary_matches_its_snapshot() {
    let dir = scratch("plan", "summary_matches_its_snapshot");
    let folder = dir.to_string_lossy().into_owned();
    for example in ["construct_path_line", "construct_strips", "type_vi_elbow_hold"] {
        let mcap = path_in(&dir, &format!("{example}.mcap"));
        let output = a2ml_in_repo(&["plan", &format!("examples/{example}.a2ml"), "-o", &mcap]);
        assert_eq!(output.status.code(), Some(0), "{example}: {}", stderr(&output));
        let text = stdout(&output).replace(&folder, "[scratch]");
        insta::with_settings!({
            filters => vec![(r"planned in \d+\.\d+ s", "planned in [seconds] s")],
        }, {
            insta::assert_snapshot!(example, text);
        });
    }
}

#[test]
fn without_outputs_writes_the_stem_as_mcap_here() {
    let dir = scratch("plan", "without_outputs");
    let output = Command::new(env!("CARGO_BIN_EXE_a2ml"))
        .args(["plan", &example_path("construct_path_by.a2ml")])
        .current_dir(&dir)
        .output()
        .expect("the binary runs");
    assert_eq!(output.status.code(), Some(0), "stderr: {}", stderr(&output));
    assert_eq!(listing(&dir), ["construct_path_by.mcap"]);
    assert!(stdout(&output).ends_with("\nwrote  construct_path_by.mcap\n"));
    let bytes = fs::read(dir.join("construct_path_by.mcap")).expect("MCAP written");
    assert!(bytes.starts_with(MCAP_MAGIC));
}

#[test]
fn rate_and_seed_override_the_settings() {
    let dir = scratch("plan", "rate_and_seed");
    let json = path_in(&dir, "plan.json");
    let task = example_path("construct_path_by.a2ml");
    let output = a2ml(&["plan", &task, "--json", &json, "--rate", "50", "--seed", "7"]);
    assert_eq!(output.status.code(), Some(0), "stderr: {}", stderr(&output));
    assert!(stdout(&output).contains(" at 50 Hz, "), "{}", stdout(&output));
    let plan: Value =
        serde_json::from_str(&fs::read_to_string(&json).expect("JSON")).expect("JSON");
    assert_eq!(plan["rate"], 50.0);
    let times = plan["trajectory"]["times"].as_array().expect("times");
    assert!((times[1].as_f64().expect("t") - 0.02).abs() < 1e-9);
}

#[test]
fn blocked_goal_exits_3_with_the_files_written() {
    let dir = scratch("plan", "blocked_goal");
    let (mcap, json) = (path_in(&dir, "blocked.mcap"), path_in(&dir, "blocked.json"));
    let output = a2ml(&["plan", &fixture("blocked.a2ml"), "-o", &mcap, "--json", &json]);
    assert_eq!(output.status.code(), Some(3), "stderr: {}", stderr(&output));
    let err = stderr(&output);
    // `auto` went on from the stalled QP to the constrained RRT, which finds the goal
    // inside the ball too.
    assert!(
        err.starts_with(
            "warning: action `reach_into_ball`, segment 1: the QP stalled; rrt: none of the 1 \
             goal configurations is within the limits and clear; the QP's result is kept\n"
        ),
        "{err}"
    );
    assert!(err.contains("\nwarning: action `reach_into_ball`, segment 1: missed Pw by "), "{err}");
    assert!(
        err.ends_with(
            "error: 1 of 1 segment missed its goal beyond tolerance; the plan was written all \
             the same\n"
        ),
        "{err}"
    );
    let text = stdout(&output);
    let rows = rows(&text);
    assert_eq!(rows.len(), 1, "{text}");
    assert!(rows[0].contains(" pw ") && rows[0].ends_with("  stalled"), "{text}");
    assert!(fs::read(&mcap).expect("MCAP written").starts_with(MCAP_MAGIC));
    let plan: Value =
        serde_json::from_str(&fs::read_to_string(&json).expect("JSON")).expect("JSON");
    assert_eq!(plan["segments"][0]["reached"], false);
    assert_eq!(plan["warnings"].as_array().expect("warnings").len(), 2);
}

#[test]
fn invalid_task_exits_2_with_located_diagnostics() {
    let dir = scratch("plan", "invalid_task");
    let mcap = path_in(&dir, "out.mcap");
    let output = a2ml(&["plan", &fixture("invalid.a2ml"), "-o", &mcap]);
    assert_eq!(output.status.code(), Some(2));
    let err = stderr(&output);
    assert!(err.contains("error: unknown setting `rat`"), "{err}");
    assert!(err.contains("invalid.a2ml:3:12\n"), "{err}");
    assert!(err.contains("^^^"), "{err}");
    assert!(err.contains("is not a valid task ("), "{err}");
    assert!(stdout(&output).is_empty());
    assert!(listing(&dir).is_empty());
}

#[test]
fn unavailable_solver_exits_2() {
    let dir = scratch("plan", "unavailable_solver");
    let mcap = path_in(&dir, "out.mcap");
    let task = example_path("construct_path_line.a2ml");
    let output = a2ml(&["plan", &task, "--solver", "hamp", "-o", &mcap]);
    assert_eq!(output.status.code(), Some(2));
    let err = stderr(&output);
    assert!(err.starts_with("error: ") && err.lines().count() == 1, "{err}");
    assert!(err.contains("action `slide_left`: solver `hamp` is not available yet"), "{err}");
    assert!(listing(&dir).is_empty());

    let output = a2ml(&["plan", &task, "--solver", "fast"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("[possible values: auto, qp, rrt, map, gpm, clik, pmp, hamp]")
    );
}

#[test]
fn bad_rate_exits_2() {
    let task = example_path("construct_path_line.a2ml");
    for rate in ["0", "-10", "inf", "fast"] {
        let output = a2ml(&["plan", &task, "--rate", rate]);
        assert_eq!(output.status.code(), Some(2), "--rate {rate}");
        let err = stderr(&output);
        assert!(err.contains(&format!("invalid value '{rate}' for '--rate <HZ>'")), "{err}");
    }
}

#[test]
fn unwritable_output_exits_and_leaves_no_file() {
    let dir = scratch("plan", "unwritable_output");
    let task = example_path("construct_path_by.a2ml");

    // A missing folder is found before planning.
    let missing = path_in(&dir.join("no_such_folder"), "out.mcap");
    let output = a2ml(&["plan", &task, "-o", &missing]);
    assert_eq!(output.status.code(), Some(1));
    let err = stderr(&output);
    assert!(err.starts_with(&format!("error: cannot write {missing}: there is no folder ")));
    assert!(stdout(&output).is_empty(), "nothing planned");

    // A folder in the way is found before planning too, and is invalid input.
    let folder = path_in(&dir, "taken.mcap");
    fs::create_dir(&folder).expect("folder");
    let output = a2ml(&["plan", &task, "-o", &folder]);
    assert_eq!(output.status.code(), Some(2), "stderr: {}", stderr(&output));
    assert!(stderr(&output).starts_with(&format!("error: cannot write {folder}: it is a folder")));
    assert!(stdout(&output).is_empty(), "nothing planned");
    assert_eq!(listing(&dir), ["taken.mcap"], "no temporary file left");
    assert!(listing(Path::new(&folder)).is_empty());
}
