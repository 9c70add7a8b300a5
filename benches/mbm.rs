//! Joint-space RRT-Connect on the seven MotionBenchMaker Panda scenes of tests/data/mbm
//! (rotated boxes and cylinders), in both arm models: `robots/panda.urdf` (capsules, the hand
//! and fingers) and VAMP's 59 spheres (tests/data/panda_spheres), the spheres at the default
//! 1 cm clearance and at VAMP's own criterion (0 m: touching is free). Per scene and model, the
//! solve rate and median over its 100 problems with what a solved problem costs (samples, tree
//! nodes, collision queries, time per query), then one criterion measurement over a fixed set
//! of them. `cargo bench --bench mbm -- none` prints the table alone; with another filter only
//! the rows whose `mbm/<model>/<scene>` name contains it are computed (`-- spheres@0mm`).

use std::hint::black_box;
use std::time::Instant;

use a2ml::Robot;
use a2ml::collision::{CollisionModel, CollisionScene};
use a2ml::math::Real;
use a2ml::solve::rrt::{RrtError, RrtOptions, RrtStats, rrt_connect_with};
use criterion::{Criterion, criterion_group, criterion_main};

#[path = "../tests/it/mbm_problems.rs"]
mod mbm_problems;

/// VAMP's 59-sphere Panda.
const SPHERES: &str = "tests/data/panda_spheres/panda_spheres.urdf";

/// The arm models compared: name, URDF path in the repository and the clearance kept (m): the
/// default 1 cm, and for the spheres also VAMP's own criterion (touching is free), the
/// like-for-like with VAMP.
const MODELS: [(&str, &str, Real); 3] = [
    ("capsules", "robots/panda.urdf", 0.01),
    ("spheres", SPHERES, 0.01),
    ("spheres@0mm", SPHERES, 0.0),
];

/// The median of `values` (NaN for none).
fn median(mut values: Vec<Real>) -> Real {
    values.sort_by(Real::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(Real::NAN)
}

/// Why the unsolved problems of a scene were not solved: an end refused (outside the limits or
/// within the clearance), or the sample budget used.
#[derive(Default)]
struct Refused {
    start: usize,
    goals: usize,
    budget: usize,
}

/// One line of the table: solve rate, median time, and the median counters of a solved problem.
fn report(model: &str, name: &str, total: usize, solved: &[(Real, RrtStats)], refused: &Refused) {
    let of = |f: fn(&(Real, RrtStats)) -> Real| median(solved.iter().map(f).collect());
    let per_check = of(|(t, s)| t / s.collision_checks.max(1) as Real);
    println!(
        "mbm/{model}/{name}: {} of {total} solved, median {:.3} ms; per solved problem (medians) \
         {} samples, {} nodes, {} collision queries, {:.2} µs per query; unsolved: {} starts \
         invalid, {} with no valid goal, {} out of samples",
        solved.len(),
        of(|(t, _)| *t) * 1e3,
        of(|(_, s)| s.samples as Real),
        of(|(_, s)| s.nodes as Real),
        of(|(_, s)| s.collision_checks as Real),
        per_check * 1e6,
        refused.start,
        refused.goals,
        refused.budget,
    );
}

/// Criterion's filter: the first argument that is neither a flag nor a flag's value (cargo
/// passes `--bench` first).
fn filter() -> Option<String> {
    const VALUED: [&str; 6] = [
        "--profile-time",
        "--sample-size",
        "--measurement-time",
        "--warm-up-time",
        "--save-baseline",
        "--baseline",
    ];
    let args: Vec<String> = std::env::args().skip(1).collect();
    (0..args.len())
        .find(|&i| !args[i].starts_with('-') && (i == 0 || !VALUED.contains(&args[i - 1].as_str())))
        .map(|i| args[i].clone())
}

fn mbm(c: &mut Criterion) {
    let mut group = c.benchmark_group("mbm");
    // Each row solves 100 problems: only those a filter asks for (all for `none` or none).
    let wanted = |row: &str| filter().is_none_or(|f| f == "none" || row.contains(&f));
    for (model, urdf, clearance) in MODELS {
        let options = RrtOptions { clearance, ..RrtOptions::default() };
        let robot =
            Robot::from_urdf_file(format!("{}/{urdf}", env!("CARGO_MANIFEST_DIR"))).expect("robot");
        // The arm's half of the collision model, once per robot (as VAMP's robot is compiled
        // once): its build is timed on its own in benches/collision.rs.
        let arm = CollisionModel::new(&robot, &CollisionScene::new(&[]));
        for name in mbm_problems::SCENES {
            if !wanted(&format!("mbm/{model}/{name}")) {
                continue;
            }
            let problems: Vec<_> = mbm_problems::problems(name)
                .into_iter()
                .map(|p| (CollisionScene::new(&p.obstacles), p))
                .collect();
            let mut solved = Vec::new();
            let mut solvable = Vec::new();
            let mut refused = Refused::default();
            for (scene, p) in &problems {
                let started = Instant::now();
                match rrt_connect_with(&arm, &robot, scene, &p.start, &p.goals, &options) {
                    Ok(path) => {
                        solved.push((started.elapsed().as_secs_f64(), path.stats));
                        solvable.push((scene, p));
                    }
                    Err(RrtError::InvalidStart { .. }) => refused.start += 1,
                    Err(RrtError::NoValidGoal { .. }) => refused.goals += 1,
                    Err(RrtError::NoPath { .. }) => refused.budget += 1,
                    Err(e) => panic!("{model}/{name}: {e}"),
                }
            }
            report(model, name, problems.len(), &solved, &refused);
            solvable.truncate(10);
            group.bench_function(format!("{model}/{name}_10_problems"), |b| {
                b.iter(|| {
                    for (scene, p) in &solvable {
                        let _ = rrt_connect_with(
                            &arm,
                            &robot,
                            scene,
                            &p.start,
                            &p.goals,
                            black_box(&options),
                        );
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
