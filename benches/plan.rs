//! Planning: one velocity-QP segment (per step = time / steps) in free space and grazing an
//! obstacle, and whole tasks (decomposition + QP + joining) on COMAN and Centauro.

use std::hint::black_box;

use a2ml::Robot;
use a2ml::collision::CollisionScene;
use a2ml::kinematics::{arm_pose, cpsa_state};
use a2ml::language::{self, Obstacle, PathFeature, Shape, Space, Target, Variable};
use a2ml::math::{JointVector, Real, Rotation3, Vector3};
use a2ml::profile::{BodyFrames, Reference, Role};
use a2ml::solve::qp::{Component, QpOptions, SegmentProblem, solve_segment};
use a2ml::solve::{PlanOptions, plan};
use criterion::{Criterion, criterion_group, criterion_main};

fn path(relative: &str) -> String {
    format!("{}/{relative}", env!("CARGO_MANIFEST_DIR"))
}

/// COMAN's hand in front of the body; Pw 12 cm along a line, Ow and θsw held, 1.2 s.
fn line_segment(robot: &Robot, q0: &JointVector) -> SegmentProblem {
    let s = cpsa_state(robot, &arm_pose(robot, q0)).expect("regular start");
    let duration = 1.2;
    let line = PathFeature::Line { direction: Vector3::new(0.0, -1.0, 0.2), length: Some(0.12) };
    let frames = BodyFrames { shoulder_frame: Rotation3::identity(), ow: s.ow };
    let held = |variable, value| Reference::hold(variable, value, duration).expect("hold");
    let pw = Reference::path(Variable::Pw, Target::Position(s.pw), &line, &frames, duration)
        .expect("line");
    let component = |variable, reference| Component { variable, reference, role: Role::Path };
    SegmentProblem {
        space: Space::Cpsa,
        components: [
            component(Variable::Pw, pw),
            component(Variable::Ow, held(Variable::Ow, Target::Rotation(s.ow))),
            component(Variable::Swivel, held(Variable::Swivel, Target::Angle(s.swivel))),
        ],
        duration,
    }
}

fn qp(c: &mut Criterion) {
    let robot = Robot::from_urdf_file(path("robots/coman_right_arm.urdf")).expect("robot");
    let q0 = JointVector::from_fn(|i, _| [-10.0 as Real, -15.0, 45.0, -100.0, 0.0, 0.0, 0.0][i])
        .map(Real::to_radians);
    let problem = line_segment(&robot, &q0);
    let p0 = arm_pose(&robot, &q0).wrist;
    let slab = Obstacle {
        name: "slab".into(),
        shape: Shape::Box {
            center: p0 + Vector3::new(0.0, -0.08, -0.09),
            size: Vector3::new(0.3, 0.1, 0.05),
            rotation: Rotation3::identity(),
        },
    };
    let options = QpOptions::default();
    let mut group = c.benchmark_group("qp");
    for (name, scene) in [
        ("segment_free", CollisionScene::new(&[])),
        ("segment_grazing_box", CollisionScene::new(&[slab])),
    ] {
        let steps = solve_segment(&robot, &scene, &problem, &q0, &options).expect("solves");
        eprintln!(
            "qp/{name}: {} steps, {} with Clarabel; step medians {:.2} µs (least squares), \
             {:.1} µs (Clarabel)",
            steps.stats.steps,
            steps.stats.clarabel_steps,
            steps.stats.median_fast_time * 1e6,
            steps.stats.median_clarabel_time * 1e6
        );
        group.bench_function(name, |b| {
            b.iter(|| solve_segment(&robot, &scene, black_box(&problem), &q0, &options))
        });
    }
    group.finish();
}

fn tasks(c: &mut Criterion) {
    let mut group = c.benchmark_group("plan");
    group.sample_size(20);
    for name in ["push_box_aside_coman", "push_box_aside_centauro", "construct_path_line"] {
        let task = language::load(path(&format!("examples/{name}.a2ml"))).expect("task loads");
        let robot = Robot::from_urdf_file(&task.robot).expect("robot");
        let options = PlanOptions::default();
        match plan(&robot, &task, &options) {
            Ok(p) => {
                let steps: usize = p.segments.iter().map(|s| s.qp.steps).sum();
                let clarabel: usize = p.segments.iter().map(|s| s.qp.clarabel_steps).sum();
                eprintln!(
                    "plan/{name}: {} segments, {steps} QP steps, {:.1} % with Clarabel",
                    p.segments.len(),
                    100.0 * clarabel as Real / steps.max(1) as Real
                );
            }
            Err(e) => {
                eprintln!("plan/{name}: skipped, {e}");
                continue;
            }
        }
        group.bench_function(name, |b| b.iter(|| plan(&robot, black_box(&task), &options)));
        let decompose_options = a2ml::decompose::DecomposeOptions::default();
        group.bench_function(format!("{name}/decompose_only"), |b| {
            b.iter(|| a2ml::decompose::decompose(&robot, black_box(&task), &decompose_options))
        });
    }
    group.finish();
}

/// The Panda sphere cage of tests/data/panda_sphere_cage.json: the first 10 instances
/// per iteration (divide by 10 for one).
fn rrt(c: &mut Criterion) {
    use a2ml::solve::rrt::{RrtOptions, rrt_connect};
    let text = std::fs::read_to_string(path("tests/data/panda_sphere_cage.json"))
        .expect("tests/data/panda_sphere_cage.json is in the repository");
    let data: serde_json::Value = serde_json::from_str(&text).expect("json");
    let vector = |v: &serde_json::Value| -> Vec<Real> {
        v.as_array().expect("array").iter().map(|x| x.as_f64().expect("number")).collect()
    };
    let start = JointVector::from_column_slice(&vector(&data["start"]));
    let goal = JointVector::from_column_slice(&vector(&data["goal"]));
    let radius = data["radius"].as_f64().expect("radius");
    let scenes: Vec<CollisionScene> = (0..10)
        .map(|k| {
            let spheres: Vec<Obstacle> = data["instances"][k]
                .as_array()
                .expect("instance")
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    let v = vector(v);
                    // The file's frame is the URDF root; {b} has S 0.333 m above it.
                    let center = Vector3::new(v[0], v[1], v[2] - 0.333);
                    Obstacle { name: format!("s{i}"), shape: Shape::Sphere { center, radius } }
                })
                .collect();
            CollisionScene::new(&spheres)
        })
        .collect();
    let robot = Robot::from_urdf_file(path("robots/panda.urdf")).expect("robot");
    let options = RrtOptions::default();
    // Each instance alone, a few rounds: the median per instance and the check rate.
    let (mut times, mut checks, mut total) = (Vec::new(), Vec::new(), 0.0);
    for _ in 0..20 {
        for scene in &scenes {
            let started = std::time::Instant::now();
            let found = rrt_connect(&robot, scene, &start, &[goal], &options).expect("a path");
            let time = started.elapsed().as_secs_f64();
            times.push(time);
            total += time;
            checks.push(found.stats.collision_checks);
        }
    }
    times.sort_by(Real::total_cmp);
    checks.sort_unstable();
    eprintln!(
        "rrt/panda_sphere_cage: median {:.3} ms and {} collision checks per instance, {:.0} \
         checks/s",
        times[times.len() / 2] * 1e3,
        checks[checks.len() / 2],
        checks.iter().sum::<usize>() as Real / total
    );
    let mut group = c.benchmark_group("rrt");
    group.sample_size(10);
    group.bench_function("panda_sphere_cage_10_instances", |b| {
        b.iter(|| {
            for scene in &scenes {
                let _ = rrt_connect(&robot, scene, &start, &[goal], black_box(&options));
            }
        })
    });
    group.finish();
}

/// Paper §6.2's forward bar (examples/type_iv_forward_bar.a2ml, Centauro): the whole plan with
/// the constrained RRT, one type IV segment. Prints the median over 100 seeds first.
fn constrained_rrt(c: &mut Criterion) {
    let task = language::load(path("examples/type_iv_forward_bar.a2ml")).expect("task loads");
    let robot = Robot::from_urdf_file(&task.robot).expect("robot");
    let options =
        PlanOptions { solver: Some(language::SolverChoice::Rrt), ..PlanOptions::default() };
    let (mut times, mut checks, mut found) = (Vec::new(), Vec::new(), 0);
    for seed in 0..100 {
        let mut task = task.clone();
        task.settings.seed = seed;
        let started = std::time::Instant::now();
        if let Ok(p) = plan(&robot, &task, &options) {
            times.push(started.elapsed().as_secs_f64());
            checks.extend(p.segments[0].rrt.map(|r| r.collision_checks));
            found += 1;
        }
    }
    times.sort_by(Real::total_cmp);
    checks.sort_unstable();
    eprintln!(
        "rrt/forward_bar: {found} of 100 seeds found a path; median {:.1} ms (plan, timing \
         included) and {} collision checks",
        times.get(times.len() / 2).copied().unwrap_or(Real::NAN) * 1e3,
        checks.get(checks.len() / 2).copied().unwrap_or(0)
    );
    let mut group = c.benchmark_group("rrt");
    group.sample_size(20);
    group.bench_function("forward_bar_plan", |b| {
        b.iter(|| plan(&robot, black_box(&task), &options))
    });
    group.finish();
}

criterion_group!(benches, qp, tasks, rrt, constrained_rrt);
criterion_main!(benches);
