//! Generated hostile inputs at every library entry point: task text with extreme numbers in
//! every slot, and URDF text with its numbers perturbed. Parsing, validation, decomposition
//! and planning may refuse them, never panic; a plan that comes out has finite samples.
//!
//! `A2ML_HOSTILE_CASES` sets the number of cases per property (default 200, CI-sized);
//! raise it for a longer run.

use std::path::PathBuf;

use a2ml::Robot;
use a2ml::collision::check_shapes;
use a2ml::decompose::{DecomposeOptions, decompose};
use a2ml::language::{Limits, parse_with};
use a2ml::robot::RobotOptions;
use a2ml::solve::{PlanOptions, plan};
use proptest::prelude::*;

fn cases() -> u32 {
    std::env::var("A2ML_HOSTILE_CASES").ok().and_then(|n| n.parse().ok()).unwrap_or(200)
}

fn robot_file() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("robots/coman_right_arm.urdf")
}

/// Numbers at the edges: zeros, subnormals, the largest, overflowing text, NaN-producing
/// text, ordinary values.
const EXTREMES: [&str; 18] = [
    "0",
    "-0",
    "1e-320",
    "1e-9",
    "0.05",
    "0.3",
    "-0.2",
    "1",
    "-1",
    "90",
    "1e6",
    "1e9",
    "1e19",
    "1e200",
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e400",
];

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => proptest::sample::select(&EXTREMES[..]).prop_map(str::to_owned),
        1 => any::<f64>().prop_filter("finite", |x| x.is_finite()).prop_map(|x| format!("{x:e}")),
        1 => (-2.0..2.0f64).prop_map(|x| format!("{x}")),
    ]
}

/// A task with every value slot drawn from [`number`].
fn task_text() -> impl Strategy<Value = String> {
    proptest::collection::vec(number(), 24).prop_map(|n| {
        format!(
            "robot \"{robot}\"\nstart [{}, {}, 0, {}, 0, 10, 0] deg\n\
             scene {{\n  b = box at [{}, {}, {}] size [{}, 0.1, 0.1]\n  \
             s = sphere at [0.3, {}, 0] radius {}\n  \
             c = capsule from [{}, 0, 0] to [0.3, 0.3, {}] radius 0.02\n  \
             y = cylinder at [0.4, 0, {}] radius 0.03 height {}\n}}\n\
             settings {{ rate {} Hz  seed 7  transition 20 % }}\n\
             task t {{\n  action a {{\n    path Pw line [{}, {}, {}] {} m, Ow hold, θsw hold\n    \
             duration {} s\n  }}\n  action b {{\n    goal Pw Ow = ([{}, -0.1, -0.2], rpy({}, 0, {}) deg)\n  }}\n}}\n",
            n[0], n[1], n[2], n[3], n[4], n[5], n[6], n[7], n[8], n[9], n[10], n[11], n[12],
            n[13], n[14], n[15], n[16], n[17], n[18], n[19], n[20], n[21],
            robot = robot_file().display()
        )
    })
}

/// Small limits, so that a valid generated task plans quickly.
fn small() -> Limits {
    Limits { max_samples: 5_000, ..Limits::default() }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn task_values_never_panic(text in task_text()) {
        let robot = Robot::from_urdf_file(robot_file()).expect("robot");
        if let Ok(task) = parse_with(&text, None, &small()) {
            let decomposed = decompose(&robot, &task, &DecomposeOptions::default());
            if decomposed.is_ok() {
                let options = PlanOptions { rate: Some(20.0), limits: small(), ..PlanOptions::default() };
                if let Ok(plan) = plan(&robot, &task, &options) {
                    prop_assert!(plan.trajectory.positions().iter().all(|q| q.iter().all(|x| x.is_finite())));
                }
            }
        }
    }

    #[test]
    fn urdf_numbers_never_panic(
        picks in proptest::collection::vec((0usize..400, number()), 1..4)
    ) {
        let text = std::fs::read_to_string(robot_file()).expect("urdf");
        let mut text = text;
        for (k, value) in picks {
            text = replace_number(&text, k, &value);
        }
        if let Ok(robot) = Robot::from_urdf_str(&text, &RobotOptions::default()) {
            let _ = check_shapes(&robot, &[]);
            let task = parse_with(
                &format!(
                    "robot \"{}\"\nstart [0, -20, 0, -60, 0, 10, 0] deg\n\
                     scene {{ b = box at [0.3, 0, -0.3] size [0.2, 0.2, 0.2] }}\n\
                     task t {{ action a {{ path Pw line [0, 1, 0] 2 cm }} }}\n",
                    robot_file().display()
                ),
                None,
                &small(),
            )
            .expect("valid task");
            if decompose(&robot, &task, &DecomposeOptions::default()).is_ok() {
                let options = PlanOptions { rate: Some(20.0), limits: small(), ..PlanOptions::default() };
                let _ = plan(&robot, &task, &options);
            }
        }
    }
}

/// `text` with its `k`-th number (counting modulo how many there are) replaced by `value`.
fn replace_number(text: &str, k: usize, value: &str) -> String {
    let is_number_char = |c: char| c.is_ascii_digit() || matches!(c, '.' | '-' | 'e' | '+');
    let mut spans = Vec::new();
    let mut start = None;
    for (i, c) in text.char_indices() {
        match (start, c.is_ascii_digit() || (start.is_some() && is_number_char(c))) {
            (None, true) => start = Some(i),
            (Some(s), false) => {
                spans.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    if spans.is_empty() {
        return text.to_owned();
    }
    let (s, e) = spans[k % spans.len()];
    format!("{}{value}{}", &text[..s], &text[e..])
}
