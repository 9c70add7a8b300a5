//! Inputs that once crashed a2ml or made it allocate without bound: each is refused with
//! exit 2 and a message naming where it is written and, for a limit, how to raise it. A start
//! in collision is an error located at the `start`, or a warning when allowed.

use std::fs;
use std::path::{Path, PathBuf};

use crate::{a2ml, robot_path, scratch, stderr, stdout};

/// A one-action task on the COMAN arm with `extra` items before the task and `body` in the
/// action (a goal the arm reaches when nothing else is wrong).
fn task(dir: &Path, name: &str, extra: &str, body: &str) -> PathBuf {
    let text = format!(
        "robot \"{}\"\nstart [0, -20, 0, -60, 0, 10, 0] deg\n{extra}\ntask t {{\n  action \
         slide {{\n    path Pw line [0, 1, 0] 0.05 m, Ow hold, θsw hold\n    {body}\n  }}\n}}\n",
        robot_path("coman_right_arm.urdf")
    );
    let path = dir.join(name);
    fs::write(&path, text).expect("task written");
    path
}

/// Runs `a2ml plan` on `task`, expecting exit 2 and `expected` in a message located at
/// `line` of the file.
fn refused(task: &Path, line: usize, expected: &str) {
    let mcap = task.with_extension("mcap");
    let output =
        a2ml(&["plan", task.to_str().expect("UTF-8"), "-o", mcap.to_str().expect("UTF-8")]);
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{}: {err}", task.display());
    assert!(err.contains(expected), "{}: {err}", task.display());
    assert!(err.contains(&format!("{}:{line}:", task.display())), "not located: {err}");
    assert!(!mcap.exists());
}

#[test]
fn huge_shapes_rates_and_durations_are_located_errors() {
    let dir = scratch("bounds", "huge");
    let cases = [
        (
            "box.a2ml",
            "scene { b = box at [0.4, 0, 0] size [1e200, 1, 1] }",
            "",
            3,
            "beyond the workspace bound of 100 m",
        ),
        (
            "capsule.a2ml",
            "scene { c = capsule from [1e308, 0, 0] to [0, 0, 0] radius 0.1 }",
            "",
            3,
            "beyond the workspace bound",
        ),
        ("rate19.a2ml", "settings { rate 1e19 Hz }", "", 3, "(raise it with --max-samples)"),
        ("rate9.a2ml", "settings { rate 1e9 Hz }", "", 3, "(raise it with --max-samples)"),
        (
            "day.a2ml",
            "",
            "duration 1e6 s",
            7,
            "more than the limit of 1000000 (raise it with --max-samples)",
        ),
        ("forever.a2ml", "", "duration 1e308 s", 7, "more than 2^64 samples"),
    ];
    for (name, extra, body, line, expected) in cases {
        refused(&task(&dir, name, extra, body), line, expected);
    }
    // The limit is an option: raised, the same task plans (a long, slow motion is not the
    // point here, so a short one with a low limit shows it).
    let short = task(&dir, "short.a2ml", "", "duration 2 s");
    let mcap = dir.join("short.mcap");
    let args = |limit: &'static str| {
        vec![
            "plan".to_owned(),
            short.display().to_string(),
            "-o".into(),
            mcap.display().to_string(),
            "--max-samples".into(),
            limit.into(),
        ]
    };
    let low: Vec<String> = args("100");
    let output = a2ml(&low.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    assert!(stderr(&output).contains("--max-samples"), "{}", stderr(&output));
    let high: Vec<String> = args("10000");
    let output = a2ml(&high.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
}

#[test]
fn an_overflowing_direction_is_invalid_input_and_a_big_one_is_fine() {
    let dir = scratch("bounds", "direction");
    let text = |d: &str| {
        format!(
            "robot \"{}\"\nstart [0, -20, 0, -60, 0, 10, 0] deg\ntask t {{\n  action slide {{\n    \
             path Pw line {d} 0.05 m, Ow hold, θsw hold\n  }}\n}}\n",
            robot_path("coman_right_arm.urdf")
        )
    };
    let big = dir.join("big.a2ml");
    fs::write(&big, text("[0, 1e308, 1e308]")).expect("written");
    let output = a2ml(&["check", big.to_str().expect("UTF-8")]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    let explained = a2ml(&["explain", big.to_str().expect("UTF-8"), "--json"]);
    assert_eq!(explained.status.code(), Some(0), "{}", stderr(&explained));
    let json: serde_json::Value = serde_json::from_str(&stdout(&explained)).expect("JSON");
    let direction = &json["actions"][0]["path"]["features"][0]["direction"];
    if let Some(d) = direction.as_array() {
        let d: Vec<f64> = d.iter().map(|x| x.as_f64().expect("number")).collect();
        assert!(
            (d[1] - 0.5f64.sqrt()).abs() < 1e-12 && (d[2] - 0.5f64.sqrt()).abs() < 1e-12,
            "{d:?}"
        );
    }
    let infinite = dir.join("inf.a2ml");
    fs::write(&infinite, text("[0, 1e309, 0]")).expect("written");
    let output = a2ml(&["check", infinite.to_str().expect("UTF-8")]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("inf.a2ml:5:"), "{}", stderr(&output));
}

#[test]
fn every_u64_is_a_seed_in_the_file_as_on_the_command_line() {
    let dir = scratch("bounds", "seed");
    let max = u64::MAX.to_string();
    let path = task(&dir, "seed.a2ml", &format!("settings {{ seed {max} }}"), "");
    let output = a2ml(&["check", path.to_str().expect("UTF-8")]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    let over = task(&dir, "over.a2ml", "settings { seed 18446744073709551616 }", "");
    let output = a2ml(&["check", over.to_str().expect("UTF-8")]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains(&format!("from 0 to {max}")), "{}", stderr(&output));
}

#[test]
fn a_rate_below_one_over_the_duration_is_an_error() {
    let dir = scratch("bounds", "slow_rate");
    let path = task(&dir, "slow.a2ml", "settings { rate 0.1 Hz }", "duration 2 s");
    let output = a2ml(&[
        "plan",
        path.to_str().expect("UTF-8"),
        "-o",
        dir.join("x.mcap").to_str().expect("UTF-8"),
    ]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    assert!(stderr(&output).contains("below 1 / the motion's duration"), "{}", stderr(&output));
}

#[test]
fn twenty_thousand_errors_on_one_line_report_the_first_hundred() {
    let dir = scratch("bounds", "many_errors");
    let line = "start [0, 0, 0, 0, 0, 0, 0] ".repeat(20_000);
    let path = dir.join("many.a2ml");
    fs::write(
        &path,
        format!(
            "robot \"{}\"\n{line}\ntask t {{ action a {{ path Pw line [0, 1, 0] 1 cm }} }}\n",
            robot_path("coman_right_arm.urdf")
        ),
    )
    .expect("written");
    assert!(fs::metadata(&path).expect("file").len() > 500_000);
    let output = a2ml(&["check", path.to_str().expect("UTF-8")]);
    assert_eq!(output.status.code(), Some(2));
    let err = stderr(&output);
    assert_eq!(err.matches("a file has one `start`").count(), 100, "the first hundred");
    assert!(
        err.contains("19999 errors, the first 100 shown (raise the limit with --max-errors)")
            || err.contains("errors, the first 100 shown"),
        "{}",
        &err[err.len().saturating_sub(300)..]
    );
    assert!(err.len() < 100 * 1_000, "each error shows a window of its line: {} bytes", err.len());
    let output = a2ml(&["check", path.to_str().expect("UTF-8"), "--max-errors", "1000"]);
    assert_eq!(stderr(&output).matches("a file has one `start`").count(), 1000);
}

#[test]
fn an_endless_input_is_read_up_to_the_limit() {
    let output =
        a2ml(&["plan", "/dev/zero", "--max-input-bytes", "1000000", "-o", "/tmp/a2ml-never.mcap"]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    assert!(
        stderr(&output)
            .contains("larger than the limit of 1000000 bytes (raise it with --max-input-bytes)"),
        "{}",
        stderr(&output)
    );
    let output = a2ml(&["check", "/dev/zero", "--max-input-bytes", "1000000"]);
    assert_ne!(output.status.code(), Some(0));
    let output = a2ml(&["robot", "/dev/zero"]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
}

#[test]
fn a_start_in_collision_is_a_located_error_or_an_allowed_warning() {
    let dir = scratch("bounds", "start_in_collision");
    // A ball around the middle of the forearm at the start configuration.
    let path = task(
        &dir,
        "collides.a2ml",
        "scene { ball = sphere at [0.095, -0.08, -0.22] radius 3 cm }",
        "",
    );
    let mcap = dir.join("collides.mcap");
    let (task_arg, mcap_arg) = (path.to_str().expect("UTF-8"), mcap.to_str().expect("UTF-8"));
    let output = a2ml(&["plan", task_arg, "-o", mcap_arg]);
    let err = stderr(&output);
    assert_eq!(output.status.code(), Some(2), "{err}");
    assert!(err.contains("starts in collision: `forearm` and `ball`"), "{err}");
    assert!(err.contains(&format!("{}:2:7", path.display())), "at the start's angles: {err}");
    assert!(err.contains("--allow-close-start"), "{err}");
    assert!(!mcap.exists());

    let output = a2ml(&["plan", task_arg, "-o", mcap_arg, "--allow-close-start"]);
    let err = stderr(&output);
    assert_ne!(output.status.code(), Some(2), "{err}");
    assert!(err.contains("warning: the task (action `slide`) starts in collision"), "{err}");
}

/// Generated command lines: every subcommand with extreme numbers, hostile paths and stray
/// options. Each run ends with one of the documented exit codes, never a panic (101) or a
/// signal. `A2ML_HOSTILE_CASES` sets how many (default 60).
#[test]
fn generated_command_lines_end_with_a_documented_exit_code() {
    let cases: u64 =
        std::env::var("A2ML_HOSTILE_CASES").ok().and_then(|n| n.parse().ok()).unwrap_or(60);
    let dir = scratch("bounds", "generated_command_lines");
    let valid = task(&dir, "valid.a2ml", "", "duration 0.5 s");
    let out = dir.join("out.mcap");
    let values = [
        "0",
        "-1",
        "1e308",
        "-1e308",
        "1e19",
        "NaN",
        "inf",
        "18446744073709551616",
        "0.001",
        "7",
        "",
        "--",
        "-",
        "/dev/zero",
        "/dev/null",
    ];
    let paths = [
        valid.display().to_string(),
        "/dev/zero".into(),
        "/dev/null".into(),
        dir.display().to_string(),
        "missing.a2ml".into(),
        robot_path("coman_right_arm.urdf"),
    ];
    let options = [
        "--rate",
        "--seed",
        "--max-samples",
        "--max-segments",
        "--max-errors",
        "--max-input-bytes",
        "--solver",
        "--csv",
        "--json",
        "-o",
        "--at",
        "--tip",
        "--base",
    ];
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = |n: usize| {
        // xorshift64*: deterministic, no dependency.
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 33) as usize % n
    };
    for _ in 0..cases {
        let command = ["plan", "check", "explain", "fmt", "robot"][next(5)];
        let mut args = vec![command.to_owned(), paths[next(paths.len())].clone()];
        for _ in 0..next(4) {
            let option = options[next(options.len())];
            args.push(option.to_owned());
            let value = if matches!(option, "--csv" | "--json" | "-o") && next(2) == 0 {
                out.display().to_string()
            } else {
                values[next(values.len())].to_owned()
            };
            args.push(value);
        }
        let output = a2ml(&args.iter().map(String::as_str).collect::<Vec<_>>());
        let code = output.status.code();
        assert!(
            matches!(code, Some(0..=4)),
            "a2ml {}: exit {code:?}: {}",
            args.join(" "),
            stderr(&output)
        );
    }
}
