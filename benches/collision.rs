//! The cost of one collision query on the MotionBenchMaker Panda scenes of tests/data/mbm, in
//! both arm models (`robots/panda.urdf`: capsules with the hand and fingers; VAMP's 59
//! spheres): building the model, `clearance` at a configuration, and the edge check's
//! `advancement_within` along a full RRT step. Each measurement runs over the same 64 seeded in-limit configurations of
//! the scene's first problem, so a figure is the mean over free and colliding ones alike.

use std::hint::black_box;

use a2ml::Robot;
use a2ml::collision::{CollisionModel, CollisionScene, advancement_within, clearance};
use a2ml::math::JointVector;
use a2ml::solve::rrt::RrtOptions;
use criterion::{Criterion, criterion_group, criterion_main};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

#[path = "../tests/it/mbm_problems.rs"]
#[allow(dead_code, reason = "the starts and goals are for the RRT, not for one query")]
mod mbm_problems;

/// The arm models compared: name and URDF path in the repository.
const MODELS: [(&str, &str); 2] =
    [("capsules", "robots/panda.urdf"), ("spheres", "tests/data/panda_spheres/panda_spheres.urdf")];

/// The configurations of one measurement, and as many motions of an RRT step's length.
fn queries(robot: &Robot, step: f64) -> Vec<(JointVector, JointVector)> {
    let mut rng = StdRng::seed_from_u64(3);
    let (lower, upper) = (robot.lower(), robot.upper());
    let mut sample = || JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
    (0..64)
        .map(|_| {
            let (q, toward) = (sample(), sample());
            let dq = toward - q;
            (q, dq * (step / dq.norm()))
        })
        .collect()
}

fn collision(c: &mut Criterion) {
    let options = RrtOptions::default();
    let mut group = c.benchmark_group("collision");
    for (model_name, urdf) in MODELS {
        let robot =
            Robot::from_urdf_file(format!("{}/{urdf}", env!("CARGO_MANIFEST_DIR"))).expect("robot");
        let queries = queries(&robot, options.step);
        for name in mbm_problems::SCENES {
            let problem = mbm_problems::problems(name).swap_remove(0);
            let scene = CollisionScene::new(&problem.obstacles);
            // What every `rrt_connect` pays before its first query.
            group.bench_function(format!("model/{model_name}/{name}"), |b| {
                b.iter(|| black_box(CollisionModel::new(&robot, black_box(&scene))))
            });
            let model = CollisionModel::new(&robot, &scene);
            group.bench_function(format!("clearance/{model_name}/{name}_64"), |b| {
                b.iter(|| {
                    for (q, _) in &queries {
                        black_box(clearance(&model, black_box(q)));
                    }
                })
            });
            // As an edge check asks at its ends: nothing required, no use for more than the
            // whole edge.
            group.bench_function(format!("advancement/{model_name}/{name}_64"), |b| {
                b.iter(|| {
                    for (q, dq) in &queries {
                        black_box(advancement_within(
                            &model,
                            black_box(q),
                            dq,
                            options.clearance,
                            0.0,
                            1.0,
                        ));
                    }
                })
            });
        }
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = collision
}
criterion_main!(benches);
