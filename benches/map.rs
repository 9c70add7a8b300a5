//! The swivel obstacle map: building the 200 × 360 map of the push-box task's push segment
//! (COMAN, every cell by IK and the collision model: the scene is boxes and a cylinder) and
//! planning its profile (dynamic programme, spline, 1 kHz check).

use std::hint::black_box;

use a2ml::Robot;
use a2ml::decompose::DecomposeOptions;
use a2ml::language;
use a2ml::solve::map::{MapOptions, SwivelTargets, build_map, plan_profile, segment_map};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench_map(c: &mut Criterion) {
    let file = format!("{}/examples/push_box_aside_coman.a2ml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&file).expect("example");
    let task = language::parse(&text, Some(std::path::Path::new(&file))).expect("task");
    let robot = Robot::from_urdf_file(&task.robot).expect("robot");
    let options = MapOptions { safety_distance: 0.01, ..MapOptions::default() };
    let decompose = DecomposeOptions::default();
    let segment =
        segment_map(&robot, &task, "push_a", 0, &decompose, &options).expect("push_a maps");
    segment.profile.as_ref().expect("push_a has a profile");
    let task_b = task.in_base_frame(&robot.structure.shoulder_in_base_link);
    let index = task.actions.iter().position(|a| a.name == "push_a").expect("push_a");
    let obstacles = task_b.action_scene(index);
    let mut group = c.benchmark_group("map");
    group.sample_size(10);
    group.bench_function("push_box_build_200x360", |b| {
        b.iter(|| {
            build_map(&robot, &obstacles, &segment.motion, &segment.start, &options).expect("map")
        })
    });
    let targets: &SwivelTargets = &segment.targets;
    group.bench_function("push_box_profile", |b| {
        b.iter(|| {
            plan_profile(
                &robot,
                &obstacles,
                &segment.motion,
                black_box(&segment.map),
                &segment.start,
                targets,
                &options,
            )
            .expect("profile")
        })
    });
    group.finish();
}

criterion_group!(benches, bench_map);
criterion_main!(benches);
