//! `a2ml check` and `a2ml fmt` on the task files of `tests/fixtures`.

use std::fs;

use crate::{a2ml, fixture, scratch, stderr, stdout};

fn read(path: &str) -> String {
    fs::read_to_string(path).expect("readable file")
}

#[test]
fn check_valid_file() {
    let valid = fixture("valid.a2ml");
    let output = a2ml(&["check", &valid]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert_eq!(stdout(&output), format!("{valid}: ok (task push_box_a_aside, 4 actions)\n"));
    assert!(stderr(&output).is_empty());
}

#[test]
fn check_invalid_file_shows_every_problem_located() {
    let invalid = fixture("invalid.a2ml");
    let output = a2ml(&["check", &invalid]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stdout(&output).is_empty());
    let err = stderr(&output);
    assert!(err.contains(&format!("--> {invalid}:3:12\n")), "{err}");
    assert!(err.contains("3 | settings { rat 100 Hz }\n  |            ^^^\n"), "{err}");
    assert!(err.contains("did you mean `rate`?"), "{err}");
    assert!(err.contains(&format!("--> {invalid}:6:10\n")), "several problems: {err}");
    assert!(err.ends_with("error: 1 of 1 file failed the check: 1 invalid\n"), "{err}");
}

#[test]
fn check_syntax_error() {
    let output = a2ml(&["check", &fixture("syntax_error.a2ml")]);
    assert_eq!(output.status.code(), Some(2));
    let err = stderr(&output);
    assert!(err.contains("syntax_error.a2ml:4:15"), "{err}");
    assert!(err.contains("\n  |               ^\n"), "{err}");
}

#[test]
fn check_missing_file_exits_1() {
    let output = a2ml(&["check", "no/such/task.a2ml"]);
    assert_eq!(output.status.code(), Some(1));
    let err = stderr(&output);
    assert!(err.starts_with("error: cannot read no/such/task.a2ml: "), "{err}");
}

#[test]
fn check_reports_every_file() {
    let (valid, invalid) = (fixture("valid.a2ml"), fixture("invalid.a2ml"));
    let output = a2ml(&["check", &invalid, &valid]);
    assert_eq!(output.status.code(), Some(2));
    assert_eq!(stdout(&output), format!("{valid}: ok (task push_box_a_aside, 4 actions)\n"));
    let err = stderr(&output);
    assert!(err.contains(&format!("{invalid}:3:12")), "{err}");
    assert!(err.ends_with("error: 1 of 2 files failed the check: 1 invalid\n"), "{err}");

    // An unreadable file outweighs an invalid one.
    let output = a2ml(&["check", &invalid, "missing.a2ml", &valid]);
    assert_eq!(output.status.code(), Some(1));
    let err = stderr(&output);
    assert!(err.contains(&format!("{invalid}:3:12")), "{err}");
    assert!(err.contains("error: cannot read missing.a2ml"), "{err}");
    assert!(err.ends_with("error: 2 of 3 files failed the check: 1 unreadable, 1 invalid\n"));
    assert!(stdout(&output).contains("valid.a2ml: ok"));
}

#[test]
fn fmt_prints_the_canonical_form() {
    let output = a2ml(&["fmt", &fixture("valid.a2ml")]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert_eq!(stdout(&output), read(&fixture("canonical.a2ml")));
    assert!(stderr(&output).is_empty(), "{}", stderr(&output));
}

#[test]
fn fmt_is_idempotent_and_keeps_the_task() {
    let canonical = fixture("canonical.a2ml");
    let output = a2ml(&["fmt", &canonical]);
    assert_eq!(output.status.code(), Some(0));
    assert_eq!(stdout(&output), read(&canonical));
    assert!(stderr(&output).is_empty(), "{}", stderr(&output));

    let output = a2ml(&["check", &canonical]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(stdout(&output).ends_with(": ok (task push_box_a_aside, 4 actions)\n"));
}

#[test]
fn fmt_check() {
    let output = a2ml(&["fmt", "--check", &fixture("canonical.a2ml")]);
    assert_eq!(output.status.code(), Some(0));
    assert!(stdout(&output).is_empty() && stderr(&output).is_empty());

    let valid = fixture("valid.a2ml");
    let output = a2ml(&["fmt", "--check", &fixture("canonical.a2ml"), &valid]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stdout(&output).is_empty());
    let err = stderr(&output);
    assert!(err.contains(&format!("error: {valid}: not in canonical form")), "{err}");
    assert!(err.ends_with("error: 1 of 2 files failed the check: 1 not canonical\n"), "{err}");
}

#[test]
fn fmt_write_rewrites_in_place() {
    let dir = scratch("language", "fmt_write");
    let path = dir.join("task.a2ml");
    fs::copy(fixture("valid.a2ml"), &path).expect("copy");
    let path = path.to_string_lossy().into_owned();
    let output = a2ml(&["fmt", "--write", &path]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(stdout(&output).is_empty());
    assert_eq!(read(&path), read(&fixture("canonical.a2ml")));
    let left: Vec<_> = fs::read_dir(&dir).expect("folder").collect();
    assert_eq!(left.len(), 1, "no temporary file left behind");

    let output = a2ml(&["fmt", "--check", &path]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
}

/// The comments of a task file, sorted: `fmt` moves a statement into
/// canonical order with its comments.
fn comments(text: &str) -> Vec<String> {
    let tree = a2ml_core::language::parse_ast(text, None).expect("the file parses");
    let mut texts: Vec<String> = tree.comments.into_iter().map(|c| c.text).collect();
    texts.sort_unstable();
    texts
}

#[test]
fn fmt_check_passes_on_a_canonical_commented_file() {
    let commented = fixture("commented.a2ml");
    let output = a2ml(&["fmt", "--check", &commented]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(stdout(&output).is_empty() && stderr(&output).is_empty());

    let output = a2ml(&["fmt", &commented]);
    assert_eq!(output.status.code(), Some(0));
    assert_eq!(stdout(&output), read(&commented));
    assert!(stderr(&output).is_empty(), "{}", stderr(&output));
}

#[test]
fn fmt_write_keeps_comments() {
    let dir = scratch("language", "fmt_write_comments");
    let path = dir.join("task.a2ml");
    fs::copy(fixture("commented_untidy.a2ml"), &path).expect("copy");
    let path = path.to_string_lossy().into_owned();
    let untidy = read(&path);

    let output = a2ml(&["fmt", "--check", &path]);
    assert_eq!(output.status.code(), Some(2), "not canonical yet");

    let output = a2ml(&["fmt", "--write", &path]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(stdout(&output).is_empty() && stderr(&output).is_empty());
    let written = read(&path);
    assert_eq!(written, read(&fixture("commented.a2ml")));
    assert_eq!(comments(&written), comments(&untidy), "every comment kept:\n{written}");
    assert!(written.contains("task reach_and_swing { # \"a # in a comment\"\n"), "{written}");
    assert!(written.contains("action reach \"Reach over the #1 table\" {\n"), "{written}");

    let output = a2ml(&["fmt", "--check", &path]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    // The written text is the fixture's, which validates where it stands (the
    // copy's relative robot path depends on where the temporary folder is).
    let output = a2ml(&["check", &fixture("commented.a2ml")]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
}

#[test]
fn fmt_needs_only_valid_syntax() {
    let output = a2ml(&["fmt", &fixture("invalid.a2ml")]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(stdout(&output).contains("goal θs = 30 degs\n"));

    let output = a2ml(&["fmt", &fixture("syntax_error.a2ml")]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stdout(&output).is_empty());
    let err = stderr(&output);
    assert!(err.contains("syntax_error.a2ml:4:15") && err.contains("  |               ^\n"));
}

#[test]
fn fmt_exit_codes() {
    let output = a2ml(&["fmt", "no/such/task.a2ml"]);
    assert_eq!(output.status.code(), Some(1));
    assert!(stderr(&output).starts_with("error: cannot read no/such/task.a2ml: "));

    let canonical = fixture("canonical.a2ml");
    let output = a2ml(&["fmt", &canonical, &canonical]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("--check or --write"));

    let output = a2ml(&["fmt", "--check", "--write", &canonical]);
    assert_eq!(output.status.code(), Some(2));
}

#[cfg(unix)]
#[test]
fn fmt_write_through_a_link_keeps_the_link_and_permissions() {
    use std::os::unix::fs::{PermissionsExt, symlink};

    let dir = scratch("language", "fmt_write_link");
    let target = dir.join("real.a2ml");
    fs::copy(fixture("valid.a2ml"), &target).expect("copy");
    fs::set_permissions(&target, fs::Permissions::from_mode(0o640)).expect("chmod");
    let link = dir.join("link.a2ml");
    symlink(&target, &link).expect("symlink");
    let output = a2ml(&["fmt", "--write", &link.to_string_lossy()]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(fs::symlink_metadata(&link).expect("link").file_type().is_symlink());
    assert_eq!(read(&target.to_string_lossy()), read(&fixture("canonical.a2ml")));
    let mode = fs::metadata(&target).expect("target").permissions().mode();
    assert_eq!(mode & 0o777, 0o640);
}

/// The `.a2ml` files under `dir`, at any depth, in order.
fn task_files(dir: &std::path::Path) -> Vec<String> {
    let mut found = Vec::new();
    for entry in fs::read_dir(dir).expect("readable folder") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            found.extend(task_files(&path));
        } else if path.extension().is_some_and(|e| e == "a2ml") {
            found.push(path.display().to_string());
        }
    }
    found.sort();
    found
}

/// Every shipped example is in canonical form: `a2ml fmt --check
/// examples/**/*.a2ml` exits 0 and says nothing.
#[test]
fn every_example_is_canonical() {
    let examples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let files = task_files(&examples);
    assert!(files.len() >= 20, "only {} examples", files.len());
    let mut args = vec!["fmt", "--check"];
    args.extend(files.iter().map(String::as_str));
    let output = a2ml(&args);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    assert!(stderr(&output).is_empty() && stdout(&output).is_empty());
}

/// A file with a syntax error is refused with the located diagnostic and
/// left as it was, under `--write` too.
#[test]
fn fmt_refuses_a_syntax_error_and_leaves_the_file() {
    let malformed = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/malformed");
    let dir = scratch("language", "fmt_refuses");
    let mut refused = 0;
    for source in task_files(&malformed) {
        let text = read(&source);
        if a2ml_core::language::parse_ast(&text, None).is_ok() {
            continue;
        }
        refused += 1;
        let name = std::path::Path::new(&source).file_name().expect("a file name");
        let path = dir.join(name).display().to_string();
        fs::write(&path, &text).expect("writable");
        for mode in ["--write", "--check"] {
            let output = a2ml(&["fmt", mode, &path]);
            assert_eq!(output.status.code(), Some(2), "{source} {mode}");
            let err = stderr(&output);
            assert!(err.contains(&format!("--> {path}:")) && err.contains('^'), "{source}: {err}");
            assert_eq!(read(&path), text, "{source}: {mode} changed a file it refused");
        }
    }
    assert!(refused >= 5, "only {refused} files of the corpus have syntax errors");
}
