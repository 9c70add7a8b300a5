//! The repository stands on its own: no tracked file reads, links or mentions the team's
//! reference folder that sits beside some checkouts (a user's clone never has it).

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository's root (the facade package's manifest folder).
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every file git tracks, or, outside a git checkout (a source tarball), every file under the
/// root except build and environment folders.
fn tracked_files(root: &Path) -> Vec<PathBuf> {
    let listed = Command::new("git").arg("-C").arg(root).args(["ls-files", "-z"]).output();
    match listed {
        Ok(out) if out.status.success() => out
            .stdout
            .split(|&b| b == 0)
            .filter(|name| !name.is_empty())
            .map(|name| root.join(String::from_utf8_lossy(name).as_ref()))
            .collect(),
        _ => {
            let mut files = Vec::new();
            walk(root, &mut files);
            files
        }
    }
}

fn walk(dir: &Path, files: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name();
        if matches!(name.to_str(), Some("target" | ".git" | ".venv")) {
            continue;
        }
        match entry.file_type() {
            Ok(kind) if kind.is_dir() => walk(&path, files),
            Ok(kind) if kind.is_file() => files.push(path),
            _ => {}
        }
    }
}

#[test]
fn no_tracked_file_mentions_the_reference_folder() {
    // Spelled in two pieces so that this file does not mention it itself.
    let needle = format!("..{}shared", '/');
    let files = tracked_files(&root());
    assert!(files.len() > 50, "the listing found the repository's files ({})", files.len());
    let offenders: Vec<String> = files
        .iter()
        .filter(|path| {
            // Deleted but still tracked files (a work in progress) are not read.
            std::fs::read(path)
                .map(|bytes| String::from_utf8_lossy(&bytes).contains(needle.as_str()))
                .unwrap_or(false)
        })
        .map(|path| path.strip_prefix(root()).unwrap_or(path).display().to_string())
        .collect();
    assert!(offenders.is_empty(), "files that mention {needle}: {offenders:?}");
}

#[test]
fn vendored_test_data_is_in_the_repository() {
    let data = root().join("tests/data");
    let cage = std::fs::read_to_string(data.join("panda_sphere_cage.json"))
        .expect("tests/data/panda_sphere_cage.json");
    let value: serde_json::Value = serde_json::from_str(&cage).expect("JSON");
    assert_eq!(value["instances"].as_array().map(Vec::len), Some(100));
    let readme = std::fs::read_to_string(data.join("README.md")).expect("tests/data/README.md");
    assert!(readme.contains("panda_sphere_cage.json"), "the README says where the file came from");
}

#[test]
fn the_foxglove_layout_shows_the_written_topics() {
    use a2ml::output::topics;
    let text = std::fs::read_to_string(root().join("docs/foxglove_layout.json"))
        .expect("docs/foxglove_layout.json");
    let layout: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    let panels = layout["configById"].as_object().expect("panels by id");
    let (_, three_d) = panels.iter().find(|(id, _)| id.starts_with("3D!")).expect("a 3D panel");
    assert_eq!(three_d["followTf"], "b", "the 3D panel opens on frame b");
    for topic in
        [topics::ROBOT_DESCRIPTION, topics::ARM_CAPSULES, topics::SCENE, topics::WRIST_PATH]
    {
        assert_eq!(three_d["topics"][topic]["visible"], true, "{topic}");
    }
    let written = [topics::JOINT_STATES, topics::STATE, topics::SEGMENTS];
    let mut joints_with_limits = 0;
    for (id, panel) in panels {
        for path in panel["paths"].as_array().into_iter().flatten() {
            let value = path["value"].as_str().expect("a message path");
            assert!(written.iter().any(|t| value.starts_with(&format!("{t}."))), "{id}: {value}");
            joints_with_limits += usize::from(value.starts_with("/joint_states.upper["));
        }
    }
    assert_eq!(joints_with_limits, 7, "each joint is plotted against its limits");
}
