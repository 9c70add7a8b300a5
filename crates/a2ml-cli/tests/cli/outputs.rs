//! `a2ml plan`'s outputs: paths that are not regular files, or are an input, are refused and
//! left as they were; a run that fails or is interrupted changes none of its outputs and
//! leaves no temporary file.

use std::fs;
use std::os::unix::fs::{FileTypeExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use crate::{a2ml, example_path, robot_path, scratch, stderr};

/// The task and its robot copied into `dir`, the task naming the copy: outputs aimed at them
/// can only harm the copies.
fn task_in(dir: &Path) -> (PathBuf, PathBuf) {
    let urdf = dir.join("arm.urdf");
    fs::copy(robot_path("coman_right_arm.urdf"), &urdf).expect("robot copied");
    let text = fs::read_to_string(example_path("construct_path_line.a2ml")).expect("example");
    let text = text.replace("../robots/coman_right_arm.urdf", "arm.urdf");
    assert!(text.contains("robot \"arm.urdf\""), "the example names its robot");
    let task = dir.join("task.a2ml");
    fs::write(&task, text).expect("task written");
    (task, urdf)
}

fn s(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

/// The hidden temporary files in `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    fs::read_dir(dir)
        .expect("folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|name| name.contains(".tmp-"))
        .collect()
}

#[test]
fn paths_that_are_not_regular_files_are_refused_and_untouched() {
    let dir = scratch("outputs", "not_regular");
    let (task, _) = task_in(&dir);
    let fifo = dir.join("pipe.mcap");
    assert!(Command::new("mkfifo").arg(&fifo).status().expect("mkfifo runs").success());
    let kept = dir.join("kept.csv");
    fs::write(&kept, "old\n").expect("written");
    let link = dir.join("link.csv");
    std::os::unix::fs::symlink(&kept, &link).expect("symlink");
    let folder = dir.join("folder.json");
    fs::create_dir(&folder).expect("folder");

    let cases: [(&str, &Path, &str); 5] = [
        ("-o", &fifo, "a FIFO"),
        ("--csv", &link, "a symbolic link"),
        ("--json", &folder, "a folder"),
        ("-o", Path::new("/dev/null"), "a device"),
        ("--csv", Path::new("/dev/stdout"), "a symbolic link"),
    ];
    for (flag, path, kind) in cases {
        let output = a2ml(&["plan", s(&task), flag, s(path)]);
        assert_eq!(output.status.code(), Some(2), "{flag} {}: {}", path.display(), stderr(&output));
        let err = stderr(&output);
        assert!(err.contains(&format!("cannot write {}: it is {kind}", path.display())), "{err}");
    }
    assert!(fs::symlink_metadata(&fifo).expect("fifo").file_type().is_fifo());
    assert!(fs::symlink_metadata(&link).expect("link").file_type().is_symlink());
    assert_eq!(fs::read_to_string(&kept).expect("kept"), "old\n");
    assert!(fs::metadata(&folder).expect("folder").is_dir());
    assert!(fs::metadata("/dev/null").expect("/dev/null").file_type().is_char_device());
    assert!(temporaries(&dir).is_empty());
}

#[test]
fn an_input_is_never_an_output() {
    let dir = scratch("outputs", "input_as_output");
    let (task, urdf) = task_in(&dir);
    let link = dir.join("also_task.a2ml");
    std::os::unix::fs::symlink(&task, &link).expect("symlink");
    let (task_text, urdf_text) = (fs::read(&task).expect("task"), fs::read(&urdf).expect("urdf"));
    // The task by its own name, the robot, and the task through a link it is read by.
    for (input, flag, path) in
        [(&task, "-o", &task), (&task, "--json", &urdf), (&link, "--csv", &task)]
    {
        let output = a2ml(&["plan", s(input), flag, s(path)]);
        assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
        let err = stderr(&output);
        assert!(
            err.contains(&format!("cannot write {}: it is the input", path.display())),
            "{err}"
        );
    }
    assert_eq!(fs::read(&task).expect("task"), task_text);
    assert_eq!(fs::read(&urdf).expect("urdf"), urdf_text);
    let output = a2ml(&[
        "plan",
        s(&task),
        "-o",
        &format!("{}/x.mcap", s(&dir)),
        "--csv",
        &format!("{}/x.mcap", s(&dir)),
    ]);
    assert_eq!(output.status.code(), Some(2), "one file for two outputs");
}

#[test]
fn an_existing_file_keeps_its_permissions() {
    let dir = scratch("outputs", "permissions");
    let (task, _) = task_in(&dir);
    let csv = dir.join("private.csv");
    fs::write(&csv, "old\n").expect("written");
    fs::set_permissions(&csv, fs::Permissions::from_mode(0o600)).expect("chmod");
    let output = a2ml(&["plan", s(&task), "--csv", s(&csv)]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(fs::read_to_string(&csv).expect("csv").starts_with("t,"));
    let mode = fs::metadata(&csv).expect("csv").permissions().mode() & 0o777;
    assert_eq!(mode, 0o600);
}

#[test]
fn a_failure_after_the_first_output_leaves_every_old_file() {
    let dir = scratch("outputs", "second_fails");
    let (task, _) = task_in(&dir);
    let (csv, json) = (dir.join("out.csv"), dir.join("out.json"));
    let output = a2ml(&["plan", s(&task), "--csv", s(&csv), "--json", s(&json)]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    let (csv_size, json_size) =
        (fs::metadata(&csv).expect("csv").len(), fs::metadata(&json).expect("json").len());
    assert!(2 * csv_size < json_size, "the JSON is the larger file: {csv_size} {json_size}");
    fs::write(&csv, "old csv\n").expect("written");
    fs::write(&json, "old json\n").expect("written");
    // A file size limit between the two: the CSV is written whole, the JSON cannot be.
    let limit_kib = (csv_size + json_size) / 2 / 1024;
    let script = format!(
        "trap '' XFSZ; ulimit -f {limit_kib}; exec \"$0\" plan \"$1\" --csv \"$2\" --json \"$3\""
    );
    let output = Command::new("bash")
        .args(["-c", &script, env!("CARGO_BIN_EXE_a2ml"), s(&task), s(&csv), s(&json)])
        .output()
        .expect("bash runs");
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    assert!(
        stderr(&output).contains(&format!("cannot write {}", json.display())),
        "{}",
        stderr(&output)
    );
    assert_eq!(fs::read_to_string(&csv).expect("csv"), "old csv\n");
    assert_eq!(fs::read_to_string(&json).expect("json"), "old json\n");
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
}

#[test]
fn a_signal_while_writing_leaves_no_temporary_and_the_old_file() {
    let dir = scratch("outputs", "signal");
    let (task, _) = task_in(&dir);
    let mcap = dir.join("out.mcap");
    for (signal, code) in [("TERM", 143), ("INT", 130), ("HUP", 129)] {
        fs::write(&mcap, "old\n").expect("written");
        // A high rate makes the file large, so that writing it takes a while.
        let mut child = Command::new(env!("CARGO_BIN_EXE_a2ml"))
            .args(["plan", s(&task), "-o", s(&mcap), "--rate", "20000"])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("the binary runs");
        let started = Instant::now();
        while temporaries(&dir).is_empty() {
            assert!(started.elapsed() < Duration::from_secs(120), "no temporary file appeared");
            assert!(child.try_wait().expect("waits").is_none(), "finished before writing");
            std::thread::sleep(Duration::from_millis(1));
        }
        let pid = child.id().to_string();
        assert!(
            Command::new("kill")
                .args([&format!("-{signal}"), &pid])
                .status()
                .expect("kill")
                .success()
        );
        let status = child.wait().expect("exits");
        assert_eq!(status.code(), Some(code), "SIG{signal}");
        assert!(temporaries(&dir).is_empty(), "SIG{signal} left {:?}", temporaries(&dir));
        assert_eq!(fs::read_to_string(&mcap).expect("mcap"), "old\n", "SIG{signal}");
    }
}
