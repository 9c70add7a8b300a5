//! Joint-space RRT-Connect on the MotionBenchMaker Panda scenes of tests/data/mbm (rotated
//! boxes and cylinders), in both arm models: `robots/panda.urdf` (capsules, the hand and
//! fingers) and VAMP's 59 spheres (tests/data/panda_spheres). Per scene and model, the solve
//! rate and median over its problems, then one criterion measurement over a fixed set of them.

use std::hint::black_box;
use std::time::Instant;

use a2ml::Robot;
use a2ml::collision::CollisionScene;
use a2ml::math::Real;
use a2ml::solve::rrt::{RrtOptions, rrt_connect};
use criterion::{Criterion, criterion_group, criterion_main};

#[path = "../tests/it/mbm_problems.rs"]
mod mbm_problems;

/// The arm models compared: name and URDF path in the repository.
const MODELS: [(&str, &str); 2] =
    [("capsules", "robots/panda.urdf"), ("spheres", "tests/data/panda_spheres/panda_spheres.urdf")];

fn mbm(c: &mut Criterion) {
    let options = RrtOptions::default();
    let mut group = c.benchmark_group("mbm");
    for (model, urdf) in MODELS {
        let robot =
            Robot::from_urdf_file(format!("{}/{urdf}", env!("CARGO_MANIFEST_DIR"))).expect("robot");
        for name in mbm_problems::SCENES {
            let problems: Vec<_> = mbm_problems::problems(name)
                .into_iter()
                .map(|p| (CollisionScene::new(&p.obstacles), p))
                .collect();
            let mut times = Vec::new();
            let mut solvable = Vec::new();
            for (scene, p) in &problems {
                let started = Instant::now();
                if rrt_connect(&robot, scene, &p.start, &p.goals, &options).is_ok() {
                    times.push(started.elapsed().as_secs_f64());
                    solvable.push((scene, p));
                }
            }
            times.sort_by(Real::total_cmp);
            let median = times.get(times.len() / 2).copied().unwrap_or(Real::NAN);
            println!(
                "mbm/{model}/{name}: {} of {} solved, median {:.3} ms",
                times.len(),
                problems.len(),
                median * 1e3
            );
            solvable.truncate(10);
            group.bench_function(format!("{model}/{name}_10_problems"), |b| {
                b.iter(|| {
                    for (scene, p) in &solvable {
                        let _ = rrt_connect(&robot, scene, &p.start, &p.goals, black_box(&options));
                    }
                })
            });
        }
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = mbm
}
criterion_main!(benches);
