//! `a2ml analyze`: every example's plan read back from MCAP and from CSV gives the measures
//! the library computes on the fresh plan; the table, the JSON and the exit codes.

use std::path::Path;

use serde_json::Value;

use a2ml_core::Robot;
use a2ml_core::language;
use a2ml_core::metrics::{self, MetricsOptions, Span};
use a2ml_core::solve::{PlanOptions, plan};

use crate::{a2ml, example_path, robot_path, scratch, stderr, stdout};

fn examples() -> Vec<String> {
    let dir = Path::new(&example_path("")).to_path_buf();
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("examples/")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".a2ml"))
        .collect();
    names.sort_unstable();
    names
}

fn json(args: &[&str]) -> Value {
    let out = a2ml(args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    serde_json::from_str(&stdout(&out)).expect("JSON")
}

fn close(a: &Value, b: f64, what: &str) {
    let a = a.as_f64().unwrap_or_else(|| panic!("{what}: {a}"));
    assert!((a - b).abs() <= 1e-6 * (1.0 + b.abs()), "{what}: {a} vs {b}");
}

/// The whole-motion numbers of the JSON against the library's on the fresh plan.
fn agrees(value: &Value, m: &metrics::SpanMetrics, name: &str) {
    let p = &value["patterns"];
    assert_eq!(p["whole"]["hamp"], m.patterns.whole.hamp.to_string(), "{name}");
    assert_eq!(p["phase1"]["hamp"], m.patterns.phase1.hamp.to_string(), "{name}");
    assert_eq!(p["phase2"]["hamp"], m.patterns.phase2.hamp.to_string(), "{name}");
    close(&p["swivel_ratio"], m.patterns.swivel_ratio, name);
    let rula = m.rula.expect("scored");
    close(&value["rula"]["mean"], rula.mean, name);
    assert_eq!(value["rula"]["max"], u64::from(rula.max), "{name}");
    close(&value["rula_sum"]["mean"], m.rula_sum.expect("scored").mean, name);
    close(&value["fitts"]["duration"], m.fitts.duration, name);
    close(&value["fitts"]["fitts"], m.fitts.fitts, name);
    close(&value["wrist_speed"]["symmetry"], m.wrist_speed.symmetry, name);
    close(&value["wrist_speed"]["peak_time_ratio"], m.wrist_speed.peak_time_ratio, name);
    close(&value["wrist_jerk"], m.wrist_jerk, name);
    assert_eq!(value["speed_peaks"], m.speed_peaks as u64, "{name}");
}

#[test]
fn every_example_analyzes_from_mcap_and_csv_as_the_library_does() {
    let dir = scratch("analyze", "every_example");
    let mut analysed = 0;
    for name in examples() {
        let path = example_path(&name);
        let task = language::load(Path::new(&path)).expect("valid example");
        let robot = Robot::from_urdf_file(&task.robot).expect("robot");
        let mcap = dir.join(format!("{name}.mcap")).to_string_lossy().into_owned();
        let csv = dir.join(format!("{name}.csv")).to_string_lossy().into_owned();
        let planned = a2ml(&["plan", &path, "-o", &mcap, "--csv", &csv]);
        // An example whose solver does not exist yet (`solver map`) has no plan to analyse.
        let Ok(fresh) = plan(&robot, &task, &PlanOptions::default()) else {
            assert!(!planned.status.success(), "{name}: the CLI planned it");
            continue;
        };
        analysed += 1;
        let expected = metrics::analyze(
            &robot,
            &fresh.trajectory,
            &Span::of_plan(&fresh),
            &MetricsOptions::default(),
        );

        assert!(matches!(planned.status.code(), Some(0 | 3)), "{name}: {}", stderr(&planned));

        let from_mcap = json(&["analyze", &mcap, "--json"]);
        agrees(&from_mcap["whole"], &expected.whole, &name);
        let segments = from_mcap["segments"].as_array().expect("segments");
        assert_eq!(segments.len(), expected.segments.len(), "{name}");
        for (value, m) in segments.iter().zip(&expected.segments) {
            assert_eq!(value["span"]["label"], m.span.label, "{name}");
            agrees(value, m, &name);
        }
        let urdf = task.robot.to_string_lossy().into_owned();
        let from_csv = json(&["analyze", &csv, "--robot", &urdf, "--json"]);
        agrees(&from_csv["whole"], &expected.whole, &name);
        assert_eq!(from_csv["segments"].as_array().map(Vec::len), Some(0));
    }
    assert!(analysed >= 20, "only {analysed} examples planned");
}

#[test]
fn the_table_has_a_row_per_segment_and_one_for_the_whole_motion() {
    let dir = scratch("analyze", "table");
    let mcap = dir.join("goal.mcap").to_string_lossy().into_owned();
    let planned = a2ml(&["plan", &example_path("construct_goal.a2ml"), "-o", &mcap]);
    assert!(matches!(planned.status.code(), Some(0 | 3)), "{}", stderr(&planned));
    let out = a2ml(&["analyze", &mcap]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("HAMP 1") && text.contains("RULA A"), "{text}");
    assert!(text.lines().any(|l| l.trim_start().starts_with("reach/1")), "{text}");
    assert!(text.lines().any(|l| l.trim_start().starts_with("whole")), "{text}");
}

#[test]
fn bad_files_and_missing_robots_are_input_errors() {
    let dir = scratch("analyze", "bad");
    let csv = dir.join("plan.csv");
    std::fs::write(&csv, "t,a_pos\n0,1\n").expect("write");
    let csv = csv.to_string_lossy().into_owned();
    let out = a2ml(&["analyze", &csv]);
    assert_eq!(out.status.code(), Some(2));
    let out = a2ml(&["analyze", &csv, "--robot", &robot_path("iiwa14.urdf")]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("plan.csv:1:"), "{}", stderr(&out));
    let text = dir.join("plan.txt");
    std::fs::write(&text, "x").expect("write");
    assert_eq!(a2ml(&["analyze", &text.to_string_lossy()]).status.code(), Some(2));
    let missing = dir.join("missing.mcap");
    assert_eq!(a2ml(&["analyze", &missing.to_string_lossy()]).status.code(), Some(1));
    let not_mcap = dir.join("not.mcap");
    std::fs::write(&not_mcap, "not an mcap file").expect("write");
    assert_eq!(a2ml(&["analyze", &not_mcap.to_string_lossy()]).status.code(), Some(2));
}
