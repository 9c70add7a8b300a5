//! Joint-space RRT-Connect on the MotionBenchMaker Panda scenes of tests/data/mbm (rotated
//! boxes and cylinders): per scene, the solve rate and median over its problems, then one
//! criterion measurement over a fixed set of them.

use std::hint::black_box;
use std::time::Instant;

use a2ml::Robot;
use a2ml::collision::CollisionScene;
use a2ml::math::Real;
use a2ml::solve::rrt::{RrtOptions, rrt_connect};
use criterion::{Criterion, criterion_group, criterion_main};

#[path = "../tests/it/mbm_problems.rs"]
mod mbm_problems;

fn mbm(c: &mut Criterion) {
    let path = format!("{}/robots/panda.urdf", env!("CARGO_MANIFEST_DIR"));
    let robot = Robot::from_urdf_file(path).expect("robot");
    let options = RrtOptions::default();
    let mut group = c.benchmark_group("mbm");
    for name in ["bookshelf_small", "table_pick"] {
        let problems: Vec<_> = mbm_problems::problems(name)
            .into_iter()
            .map(|p| (CollisionScene::new(&p.obstacles), p))
            .collect();
        let mut times = Vec::new();
        for (scene, p) in &problems {
            let started = Instant::now();
            if rrt_connect(&robot, scene, &p.start, &p.goals, &options).is_ok() {
                times.push(started.elapsed().as_secs_f64());
            }
        }
        times.sort_by(Real::total_cmp);
        let median = times.get(times.len() / 2).copied().unwrap_or(Real::NAN);
        println!(
            "mbm/{name}: {} of {} solved, median {:.3} ms",
            times.len(),
            problems.len(),
            median * 1e3
        );
        let solvable: Vec<_> = problems
            .iter()
            .filter(|(scene, p)| rrt_connect(&robot, scene, &p.start, &p.goals, &options).is_ok())
            .take(10)
            .collect();
        group.bench_function(format!("{name}_10_problems"), |b| {
            b.iter(|| {
                for (scene, p) in &solvable {
                    let _ = rrt_connect(&robot, scene, &p.start, &p.goals, black_box(&options));
                }
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = mbm
}
criterion_main!(benches);
