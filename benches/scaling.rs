//! Costs that must grow linearly: planning 100 and 1,000 actions, and rendering 1,000 and
//! 10,000 errors. Each pair is measured at both sizes, so the report shows the ratio.

use std::hint::black_box;
use std::path::PathBuf;

use a2ml::Robot;
use a2ml::language::{Limits, parse, parse_with};
use a2ml::solve::{PlanOptions, plan};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};

fn robot_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("robots/coman_right_arm.urdf")
}

/// `n` short actions sliding the hand 1 cm left and right.
fn sliding_task(n: usize) -> String {
    let mut text = format!(
        "robot \"{}\"\nstart [0, -20, 0, -60, 0, 10, 0] deg\ntask slides {{\n",
        robot_path().display()
    );
    for i in 0..n {
        let y = if i % 2 == 0 { 1 } else { -1 };
        text += &format!(
            "  action a{i} {{\n    path Pw line [0, {y}, 0] 1 cm, Ow hold, θsw hold\n    \
             duration 0.2 s\n  }}\n"
        );
    }
    text + "}\n"
}

/// A file with `n` errors: a `start` given `n + 1` times, ten to a line.
fn erroneous_task(n: usize) -> String {
    let mut text = format!("robot \"{}\"\n", robot_path().display());
    for i in 0..=n {
        text += "start [0, 0, 0, 0, 0, 0, 0] ";
        if i % 10 == 9 {
            text.push('\n');
        }
    }
    text + "\ntask t { action a { path Pw line [0, 1, 0] 1 cm } }\n"
}

fn planning(c: &mut Criterion) {
    let robot = Robot::from_urdf_file(robot_path()).expect("robot");
    let mut group = c.benchmark_group("plan_actions");
    group.sample_size(10);
    for n in [100, 1000] {
        let task = parse(&sliding_task(n), None).expect("valid task");
        group.bench_with_input(BenchmarkId::from_parameter(n), &task, |b, task| {
            b.iter(|| plan(&robot, black_box(task), &PlanOptions::default()).expect("planned"))
        });
    }
    group.finish();
}

fn rendering(c: &mut Criterion) {
    let mut group = c.benchmark_group("render_errors");
    group.sample_size(10);
    for n in [1000, 10_000] {
        let text = erroneous_task(n);
        let limits = Limits { max_errors: usize::MAX, ..Limits::default() };
        let diagnostics = parse_with(&text, None, &limits).expect_err("invalid");
        assert_eq!(diagnostics.items.len(), n);
        group.bench_with_input(BenchmarkId::from_parameter(n), &diagnostics, |b, d| {
            b.iter(|| black_box(d).to_string())
        });
    }
    group.finish();
}

criterion_group!(benches, planning, rendering);
criterion_main!(benches);
