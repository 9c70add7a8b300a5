//! `a2ml compare`: the table, the JSON records and the plans written per solver.

use crate::{a2ml, example_path, scratch, stdout};

#[test]
fn compare_prints_one_row_per_solver_and_segment_and_writes_each_plan() {
    let dir = scratch("compare", "rows_and_files");
    let task = example_path("baseline_pmp.a2ml");
    let dir_text = dir.to_string_lossy().into_owned();
    let output = a2ml(&["compare", &task, "--solvers", "qp,pmp", "-o", &dir_text]);
    assert_eq!(output.status.code(), Some(0), "{}", crate::stderr(&output));
    let text = stdout(&output);
    let rows = |solver: &str| text.lines().filter(|l| l.trim_start().starts_with(solver)).count();
    assert_eq!((rows("qp "), rows("pmp ")), (2, 2), "{text}");
    for name in ["baseline_pmp_qp.mcap", "baseline_pmp_pmp.csv"] {
        assert!(dir.join(name).is_file(), "{name} missing");
    }

    let output = a2ml(&["compare", &task, "--solvers", "pmp,hamp", "--json"]);
    assert_eq!(output.status.code(), Some(0));
    let records: serde_json::Value = serde_json::from_str(&stdout(&output)).expect("JSON");
    let records = records.as_array().expect("a list");
    assert_eq!(records.len(), 3);
    assert_eq!(records[0]["solver"], "pmp");
    assert_eq!(records[0]["solved_by"], "pmp");
    assert!(records[0]["errors"]["pw"].as_f64().expect("pw error") < 1e-3);
    assert!(records[0]["limit_joint"].is_string() && records[0]["peak_speed_ratio"].is_number());
    assert!(
        records[2]["error"].as_str().expect("hamp fails on a path").contains("not available yet")
    );
}
