//! `a2ml plan` with many tasks: outputs named by pattern, identical to one-at-a-time planning,
//! one line per task, failures reported per file without stopping the others, the worst exit
//! status.

use std::fs;
use std::path::{Path, PathBuf};

use crate::{a2ml, example_path, fixture, robot_path, scratch, stderr, stdout};

/// The formats and their output options.
const FORMATS: [(&str, &str); 4] =
    [("-o", "mcap"), ("--csv", "csv"), ("--json", "json"), ("--parquet", "parquet")];

/// The output options writing every format into `dir` by the `{stem}` pattern.
fn patterns(dir: &Path) -> Vec<String> {
    FORMATS
        .iter()
        .flat_map(|(option, ext)| {
            [(*option).to_owned(), dir.join(format!("{{stem}}.{ext}")).to_string_lossy().into()]
        })
        .collect()
}

fn run(args: &[String]) -> std::process::Output {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    a2ml(&args)
}

fn stem(task: &str) -> String {
    Path::new(task).file_stem().expect("stem").to_string_lossy().into_owned()
}

#[test]
fn a_batch_writes_what_each_task_writes_alone_byte_for_byte() {
    let dir = scratch("batch", "byte_for_byte");
    let (parallel, serial) = (dir.join("parallel"), dir.join("serial"));
    fs::create_dir_all(&parallel).expect("folder");
    fs::create_dir_all(&serial).expect("folder");
    // An RRT action with its seed, a QP reach among obstacles, a goal missed (exit 3) and a
    // task that is not valid (exit 2).
    let planned = [example_path("construct_settings.a2ml"), example_path("construct_scene.a2ml")];
    let (blocked, invalid) = (fixture("blocked.a2ml"), fixture("invalid.a2ml"));

    let mut args = vec!["plan".to_owned()];
    args.extend(planned.iter().cloned());
    args.extend([blocked.clone(), invalid.clone()]);
    args.extend(patterns(&parallel));
    args.extend(["--jobs".to_owned(), "2".to_owned()]);
    let output = run(&args);
    let text = stdout(&output);
    assert_eq!(output.status.code(), Some(2), "the worst: an invalid task\n{text}");

    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].starts_with(&format!("ok      {}  2 segments", planned[0])), "{text}");
    assert!(lines[1].starts_with(&format!("ok      {}  ", planned[1])), "{text}");
    assert!(lines[2].starts_with(&format!("missed  {blocked}  ")), "{text}");
    assert!(lines[2].contains("missed its goal beyond tolerance"), "{text}");
    assert!(lines[3].starts_with(&format!("failed  {invalid}  exit 2: ")), "{text}");
    assert!(text.contains("\n4 tasks: 2 ok, 1 missed, 1 failed, in "), "{text}");
    assert!(stderr(&output).contains("invalid.a2ml:"), "located diagnostics of the invalid task");

    for task in planned.iter().chain([&blocked]) {
        let mut args = vec!["plan".to_owned(), task.clone()];
        args.extend(patterns(&serial));
        let alone = run(&args);
        let expected = if *task == blocked { 3 } else { 0 };
        assert_eq!(alone.status.code(), Some(expected), "{task}: {}", stderr(&alone));
        for (_, ext) in FORMATS {
            let name = format!("{}.{ext}", stem(task));
            let (a, b) = (fs::read(parallel.join(&name)), fs::read(serial.join(&name)));
            let (a, b) = (a.expect("written in the batch"), b.expect("written alone"));
            assert!(a.len() > 100, "{name} has content");
            assert!(a == b, "{name} differs between the batch and planning alone");
        }
    }
    let invalid_outputs: Vec<PathBuf> = fs::read_dir(&parallel)
        .expect("folder")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.file_stem().is_some_and(|s| s == "invalid"))
        .collect();
    assert!(invalid_outputs.is_empty(), "nothing written for the invalid task");
    assert_eq!(fs::read_dir(&parallel).expect("folder").count(), 12, "no temporary left");
}

/// A task file in `dir` reaching towards `x` (m) ahead of the shoulder.
fn reach_task(dir: &Path, name: &str, x: f64) -> PathBuf {
    let text = format!(
        "robot \"{}\"\nstart [0, -20, 0, -60, 0, 10, 0] deg\n\
         task {name} {{ action reach {{ goal Pw = [{x}, -0.10, -0.15] }} }}\n",
        robot_path("coman_right_arm.urdf")
    );
    let path = dir.join(format!("{name}.a2ml"));
    fs::write(&path, text).expect("task written");
    path
}

#[test]
fn a_folder_or_a_pattern_names_its_task_files() {
    let dir = scratch("batch", "folder_or_pattern");
    let tasks = dir.join("tasks");
    fs::create_dir_all(&tasks).expect("folder");
    reach_task(&tasks, "near", 0.22);
    reach_task(&tasks, "far", 0.26);
    fs::write(tasks.join("notes.txt"), "not a task").expect("written");

    let out = dir.join("out");
    fs::create_dir_all(&out).expect("folder");
    let csv = out.join("{stem}.csv").to_string_lossy().into_owned();
    let folder = tasks.to_string_lossy().into_owned();
    let output = a2ml(&["plan", &folder, "--csv", &csv]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    let text = stdout(&output);
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].contains("far.a2ml") && lines[1].contains("near.a2ml"), "sorted: {text}");
    assert!(text.contains("2 tasks: 2 ok, 0 missed, 0 failed"), "{text}");
    assert!(out.join("near.csv").is_file() && out.join("far.csv").is_file());

    let pattern = tasks.join("n*.a2ml").to_string_lossy().into_owned();
    let json = out.join("{stem}.json").to_string_lossy().into_owned();
    let output = a2ml(&["plan", &pattern, "--json", &json, "--jobs", "1"]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(stdout(&output).contains("1 task: 1 ok"), "{}", stdout(&output));
    assert!(out.join("near.json").is_file() && !out.join("far.json").exists());

    let nothing = tasks.join("z*.a2ml").to_string_lossy().into_owned();
    let output = a2ml(&["plan", &nothing]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("no file matches"), "{}", stderr(&output));
}

#[test]
fn a_missing_task_file_fails_alone_and_the_batch_exits_1() {
    let dir = scratch("batch", "missing_file");
    let task = reach_task(&dir, "reach", 0.24);
    let missing = dir.join("nowhere.a2ml");
    let mcap = dir.join("{stem}.mcap").to_string_lossy().into_owned();
    let output = a2ml(&["plan", &missing.to_string_lossy(), &task.to_string_lossy(), "-o", &mcap]);
    assert_eq!(output.status.code(), Some(1), "an unreadable file is the worst");
    let text = stdout(&output);
    assert!(text.starts_with(&format!("failed  {}  exit 1: ", missing.display())), "{text}");
    assert!(text.contains("1 ok, 0 missed, 1 failed"), "{text}");
    assert!(dir.join("reach.mcap").is_file(), "the other task is written");
}

#[test]
fn two_tasks_writing_one_file_are_refused_before_planning() {
    let dir = scratch("batch", "one_file");
    let (a, b) = (reach_task(&dir, "a", 0.22), reach_task(&dir, "b", 0.24));
    let mcap = dir.join("plan.mcap").to_string_lossy().into_owned();
    let output = a2ml(&["plan", &a.to_string_lossy(), &b.to_string_lossy(), "-o", &mcap]);
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(message.contains("would both write") && message.contains("{stem}"), "{message}");
    assert!(stdout(&output).is_empty(), "nothing planned");
    assert!(!dir.join("plan.mcap").exists());
}

#[test]
fn every_command_loads_the_chain_the_task_names() {
    let dir = scratch("batch", "task_chain");
    let task: PathBuf = [env!("CARGO_MANIFEST_DIR"), "..", "..", "tests", "data", "tasks"]
        .iter()
        .collect::<PathBuf>()
        .join("baxter_left_reach.a2ml");
    let task = task.to_string_lossy().into_owned();
    let out = |name: &str| dir.join(name).to_string_lossy().into_owned();
    for args in [
        vec!["plan", &task, "-o", &out("plan.mcap")],
        vec!["plot", &task, "-o", &out("plot.svg")],
        vec!["report", &task, "-o", &out("report.html")],
        vec!["compare", &task, "--solvers", "qp"],
    ] {
        let output = a2ml(&args);
        assert_eq!(output.status.code(), Some(0), "{args:?}: {}", stderr(&output));
    }
    assert!(stdout(&a2ml(&["plan", &task, "-o", &out("plan.mcap")])).contains("robot  baxter"));
    // Baxter's offset wrist has no analytic IK, which the map needs: the chain was loaded.
    let output = a2ml(&["map", &task, "--action", "reach", "-o", &out("map.svg")]);
    assert!(stderr(&output).contains("analytic IK"), "{}", stderr(&output));
}
