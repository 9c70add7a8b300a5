//! Parsing and validating a long generated task.

use std::hint::black_box;
use std::path::PathBuf;

use a2ml::language::{parse, parse_ast};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

/// A task of `n` actions cycling through the constructs of the language.
fn generated_task(n: usize) -> String {
    let robot = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("robots/coman_right_arm.urdf");
    let mut text = format!(
        "robot \"{}\"\nstart [0, -20, 0, -60, 0, 10, 0] deg\n\
         scene {{\n  table = box at [0.45, 0, -0.3] size [0.4, 0.8, 0.04]\n  \
         bar = capsule from [0.3, -0.3, 0.1] to [0.3, 0.3, 0.1] radius 2 cm\n}}\n\
         settings {{ rate 100 Hz  solver auto  seed 7 }}\ntask generated {{\n",
        robot.display()
    );
    for i in 0..n {
        text += &match i % 4 {
            0 => format!(
                "  action a{i} {{\n    goal Pw Ow = ([0.25, -0.28, -0.05], rpy(180, 0, 90) deg) > Os = axes(r: [0, 0, -1], l: [0, 1, 0])\n    duration 2 s\n  }}\n"
            ),
            1 => format!(
                "  action a{i} {{\n    path Pw line [0, 1, 0] 12 cm, Ow hold, θsw hold : hard\n  }}\n"
            ),
            2 => format!(
                "  action a{i} {{\n    goal Pw Ow = ([0.15, -0.25, 0.05], quat(0, 1, 0, 0))\n    path Os about z, θe hold : soft\n    solver qp\n  }}\n"
            ),
            _ => format!(
                "  action a{i} explicit {{\n    segment 1.2 s {{ Os.path(about r, 24.7 deg) +Pa (θe Ow).goal(100 deg, rpy(-15.5, -11.5, -104.6) deg) }}\n    +Tr segment 0.8 s {{ (Pw Ow).hold +Pa θsw.goal(63.2 deg) }}\n  }}\n"
            ),
        };
    }
    text + "}\n"
}

fn language(c: &mut Criterion) {
    let text = generated_task(10_000);
    let mut group = c.benchmark_group("parse_10000_actions");
    group.throughput(Throughput::Bytes(text.len() as u64));
    group.sample_size(20);
    group.bench_function("syntax", |b| b.iter(|| parse_ast(black_box(&text), None)));
    group.bench_function("syntax+validation", |b| {
        b.iter(|| parse(black_box(&text), None).expect("the generated task is valid"))
    });
    group.finish();
}

criterion_group!(benches, language);
criterion_main!(benches);
