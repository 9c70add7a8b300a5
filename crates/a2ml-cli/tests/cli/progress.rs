//! The progress bar of `a2ml plan` is for terminals: piped output holds none of it.

use crate::{a2ml, example_path, scratch};

/// Planning that lasts past the bar's delay (§6.3's three segments with their Opt1 and Opt2,
/// about 0.7 s on a laptop core), with stdout and stderr piped: neither holds an escape code
/// or a carriage return.
#[test]
fn piped_output_holds_no_progress_bar() {
    let dir = scratch("progress", "piped");
    let out = dir.join("plan.json").display().to_string();
    let output = a2ml(&["plan", &example_path("type_vii_column.a2ml"), "--json", &out]);
    assert!(output.status.code().is_some(), "{}", String::from_utf8_lossy(&output.stderr));
    for (stream, bytes) in [("stdout", &output.stdout), ("stderr", &output.stderr)] {
        assert!(!bytes.contains(&0x1b), "{stream} holds an escape code");
        assert!(!bytes.contains(&b'\r'), "{stream} holds a carriage return");
    }
}
