//! Every shipped example does what its comments say: `check`, `explain` and `plan` on each,
//! with the exit code its comment documents and, for the intended failures, the segment that
//! fails and why. Outcomes only (exit codes, statuses), not numbers a solver change may move.

use std::fs;
use std::path::PathBuf;

use crate::{a2ml, scratch, stderr, stdout};

/// What an example's comments promise.
struct Outcome {
    /// The file in `examples/` (`paper/..` for the paper's §6, `examples/paper/`).
    file: &'static str,
    /// Exit code of `a2ml explain`.
    explain: i32,
    /// Exit code of `a2ml plan`.
    plan: i32,
    /// Text that stderr of `a2ml plan` must hold: which action and segment failed and why.
    plan_says: &'static [&'static str],
}

const fn ok(file: &'static str) -> Outcome {
    Outcome { file, explain: 0, plan: 0, plan_says: &[] }
}

/// Every example and its documented outcome; `every_example_is_listed` keeps the list whole.
const OUTCOMES: &[Outcome] = &[
    // The baselines show their characteristic failures, judged like every solver (exit 3):
    // CLIK tracks only its pen, so the wrist and hand goals are missed.
    Outcome {
        file: "baseline_clik.a2ml",
        explain: 0,
        plan: 3,
        plan_says: &["action `base`, segment 1: missed Pw"],
    },
    // GPM spends the redundancy on centring the joints and gives up the swivel hold.
    Outcome {
        file: "baseline_gpm.a2ml",
        explain: 0,
        plan: 3,
        plan_says: &["action `slide_left`, segment 1: missed θsw", "left its hard path"],
    },
    // PMP reaches its goals on curved paths, so it leaves the straight lines.
    Outcome {
        file: "baseline_pmp.a2ml",
        explain: 0,
        plan: 3,
        plan_says: &["action `out_diagonal`, segment 1: left its hard path"],
    },
    ok("construct_action_options.a2ml"),
    ok("construct_ascii_names.a2ml"),
    ok("construct_comments.a2ml"),
    ok("construct_explicit_segments.a2ml"),
    ok("construct_frame_root.a2ml"),
    ok("construct_goal.a2ml"),
    ok("construct_goal_priority.a2ml"),
    // "There is no default start": explain and plan stop with exit 2, saying so.
    Outcome {
        file: "construct_minimal.a2ml",
        explain: 2,
        plan: 2,
        plan_says: &["task `reach` has no `start`"],
    },
    ok("construct_path_about.a2ml"),
    ok("construct_path_by.a2ml"),
    ok("construct_path_line.a2ml"),
    ok("construct_path_soft.a2ml"),
    ok("construct_scene.a2ml"),
    ok("construct_sequence_se.a2ml"),
    ok("construct_settings.a2ml"),
    ok("construct_start_joints.a2ml"),
    ok("construct_start_state.a2ml"),
    ok("construct_start_state_hat.a2ml"),
    ok("construct_strips.a2ml"),
    ok("construct_units.a2ml"),
    ok("push_box_aside_centauro.a2ml"),
    ok("push_box_aside_coman.a2ml"),
    // The map releases the held swivel angle to pass the sphere, so θsw's hold is reported
    // as missed (exit 3) while Pw and Ow are kept exactly.
    Outcome {
        file: "swivel_map_spheres.a2ml",
        explain: 0,
        plan: 3,
        plan_says: &["action `pass_spheres`, segment 1: missed θsw"],
    },
    // `auto` runs the QP, which stalls on the line, then the constrained RRT, which reaches
    // the goal on it.
    ok("type_iv_forward_bar.a2ml"),
    // The QP keeps the hard line and the bar stops it there: the goal missed, stalled, exit 3.
    Outcome {
        file: "type_iv_lateral_bar.a2ml",
        explain: 0,
        plan: 3,
        plan_says: &["action `rise_along_line`, segment 1: missed", "stalled"],
    },
    ok("type_vi_elbow_hold.a2ml"),
    ok("type_vii_column.a2ml"),
    // Paper §6 (docs/paper.md). GPM on the semi-elliptic wrist paths (fig. 12) drives joints
    // past their limits, and on the straight one (fig. 10(b)) the hand into the column.
    Outcome {
        file: "paper/column_gpm_arc_0.a2ml",
        explain: 0,
        plan: 3,
        plan_says: &["action `reach`, segment 1", "limit"],
    },
    Outcome {
        file: "paper/column_gpm_arc_minus30.a2ml",
        explain: 0,
        plan: 3,
        plan_says: &["action `reach`, segment 1", "limit"],
    },
    Outcome {
        file: "paper/column_gpm_arc_plus30.a2ml",
        explain: 0,
        plan: 3,
        plan_says: &["action `reach`, segment 1", "limit"],
    },
    Outcome {
        file: "paper/column_gpm_straight.a2ml",
        explain: 0,
        plan: 3,
        plan_says: &["action `reach`, segment 1", "column"],
    },
    // The QP keeps the hard line and the bar stops it there, short of the goal (fig. 7(a)).
    Outcome {
        file: "paper/forward_bar_qp.a2ml",
        explain: 0,
        plan: 3,
        plan_says: &["action `rise_along_line`, segment 1: missed", "stalled"],
    },
    ok("paper/type_vii_about_minus_z.a2ml"),
    ok("paper/type_vii_about_r.a2ml"),
    // MS1 by the constrained RRT; MS2 `auto` (the QP stalls, the RRT takes it), MS3 QP.
    ok("paper/type_vii_column.a2ml"),
    ok("paper/type_vii_column_about_minus_z.a2ml"),
];

fn examples_folder() -> PathBuf {
    [env!("CARGO_MANIFEST_DIR"), "..", "..", "examples"].iter().collect()
}

#[test]
fn every_example_is_listed() {
    let mut found: Vec<String> = ["", "paper/"]
        .iter()
        .flat_map(|sub| {
            fs::read_dir(examples_folder().join(sub))
                .expect("examples/")
                .map(move |e| format!("{sub}{}", e.expect("entry").file_name().to_string_lossy()))
        })
        .filter(|name| name.ends_with(".a2ml"))
        .collect();
    found.sort_unstable();
    let mut listed: Vec<&str> = OUTCOMES.iter().map(|o| o.file).collect();
    listed.sort_unstable();
    assert_eq!(found, listed);
}

#[test]
fn every_example_checks_explains_and_plans_as_documented() {
    let dir = scratch("examples", "outcomes");
    let mut types = std::collections::BTreeSet::new();
    for outcome in OUTCOMES {
        let file = examples_folder().join(outcome.file);
        let file = file.to_string_lossy();
        let check = a2ml(&["check", &file]);
        assert_eq!(check.status.code(), Some(0), "check {}: {}", outcome.file, stderr(&check));

        let explain = a2ml(&["explain", &file]);
        assert_eq!(
            explain.status.code(),
            Some(outcome.explain),
            "explain {}: {}",
            outcome.file,
            stderr(&explain)
        );
        for line in stdout(&explain).lines() {
            if let Some(kind) = line.trim_start().strip_prefix("type ") {
                types.insert(kind.split(':').next().unwrap_or_default().to_owned());
            }
        }

        let mcap = dir.join(outcome.file.replace('/', "_").replace(".a2ml", ".mcap"));
        let plan = a2ml(&["plan", &file, "-o", &mcap.to_string_lossy()]);
        let (out, err) = (stdout(&plan), stderr(&plan));
        assert_eq!(plan.status.code(), Some(outcome.plan), "plan {}: {out}\n{err}", outcome.file);
        for says in outcome.plan_says {
            assert!(err.contains(says), "plan {}: stderr lacks {says:?}:\n{err}", outcome.file);
        }
        // A plan that ends in 0 or 3 is written; one refused (2) writes nothing.
        assert_eq!(mcap.exists(), matches!(outcome.plan, 0 | 3), "{}", outcome.file);
        if outcome.plan == 0 {
            // Every segment's status is `ok` (possibly with the solver that took over).
            let rows: Vec<&str> = out
                .lines()
                .skip_while(|l| !l.trim_start().starts_with("action "))
                .skip(1)
                .take_while(|l| !l.is_empty())
                .collect();
            assert!(!rows.is_empty(), "plan {}: {out}", outcome.file);
            for row in rows {
                let ok = row.trim_end().ends_with("  ok") || row.contains("  ok (");
                assert!(ok, "plan {}: a segment is not ok: {row}\n{err}", outcome.file);
            }
        }
    }
    // One example at least for each of the seven action types.
    let all: Vec<String> = ["I", "II", "III", "IV", "V", "VI", "VII"].map(String::from).into();
    assert_eq!(types.into_iter().collect::<Vec<_>>(), all);
}
