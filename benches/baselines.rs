//! Per-step cost of the baselines next to the QP's: the same 1.2 s wrist line on COMAN (the
//! segment of benches/plan.rs `qp/segment_free`) solved whole by each solver; one step costs
//! the segment's time divided by the steps printed. GPM, CLIK and PMP integrate with RK4 (four
//! resolver calls a step), the QP with its trapezoidal ramp (one QP a step); `*/resolve` times one call of each formula.

use std::hint::black_box;

use a2ml::Robot;
use a2ml::collision::CollisionScene;
use a2ml::kinematics::{arm_pose, cpsa_state};
use a2ml::language::{PathFeature, Space, Target, Variable};
use a2ml::math::{JointVector, Real, Rotation3, Vector3};
use a2ml::profile::{BodyFrames, Reference, Role};
use a2ml::solve::control::{ControlOptions, ControlRun, HandReference, Resolver};
use a2ml::solve::qp::{Component, QpOptions, SegmentProblem, solve_segment};
use a2ml::solve::{Tolerance, clik, gpm, pmp};
use criterion::{Criterion, criterion_group, criterion_main};

fn path(relative: &str) -> String {
    format!("{}/{relative}", env!("CARGO_MANIFEST_DIR"))
}

/// Pw 12 cm along a line, Ow and θsw held, 1.2 s.
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

fn baselines(c: &mut Criterion) {
    let robot = Robot::from_urdf_file(path("robots/coman_right_arm.urdf")).expect("robot");
    let q0 = JointVector::from_fn(|i, _| [-10.0 as Real, -15.0, 45.0, -100.0, 0.0, 0.0, 0.0][i])
        .map(Real::to_radians);
    let problem = line_segment(&robot, &q0);
    let scene = CollisionScene::new(&[]);
    let (qp, control) = (QpOptions::default(), ControlOptions::default());
    let options = a2ml::solve::control::BaselineOptions::default();
    let mut group = c.benchmark_group("baselines");
    let steps = solve_segment(&robot, &scene, &problem, &q0, &qp).expect("qp").stats.steps;
    eprintln!("baselines/qp_segment: {steps} steps");
    group.bench_function("qp_segment", |b| {
        b.iter(|| solve_segment(&robot, &scene, black_box(&problem), &q0, &qp))
    });
    type Solve = fn(&Robot, &SegmentProblem, &JointVector, &ControlOptions) -> ControlRun;
    let solvers: [(&str, Solve); 3] = [
        ("gpm_segment", |r, p, q, c| {
            gpm::solve_segment(r, p, q, &Default::default(), c).expect("gpm")
        }),
        ("clik_segment", |r, p, q, c| {
            clik::solve_segment(r, p, q, &Default::default(), c).expect("clik")
        }),
        ("pmp_segment", |r, p, q, c| {
            pmp::solve_segment(r, p, q, &Default::default(), c).expect("pmp")
        }),
    ];
    for (name, solve) in solvers {
        eprintln!("baselines/{name}: {} steps", solve(&robot, &problem, &q0, &control).steps);
        group
            .bench_function(name, |b| b.iter(|| solve(&robot, black_box(&problem), &q0, &control)));
    }

    // One call of each formula at the start (FK included).
    let pose = arm_pose(&robot, &q0);
    let hand = (pose.wrist, pose.hand);
    let reference = HandReference::of_segment(&robot, &problem, hand).expect("reference");
    let tolerance = Tolerance::default();
    let mut g = gpm::Gpm::new(&robot, reference, options.gpm, tolerance);
    let mut k = clik::Clik::new(&robot, reference, options.clik, tolerance);
    let goal = a2ml::solve::control::hand_goal(&robot, &problem).expect("goal");
    let mut p =
        pmp::Pmp::new(&robot, &q0, goal, problem.duration, &options.pmp, tolerance).expect("pmp");
    group.bench_function("gpm/resolve", |b| {
        b.iter(|| g.resolve(&arm_pose(&robot, &q0), black_box(&q0), &JointVector::zeros(), 0.3))
    });
    group.bench_function("clik/resolve", |b| {
        b.iter(|| k.resolve(&arm_pose(&robot, &q0), black_box(&q0), &JointVector::zeros(), 0.3))
    });
    group.bench_function("pmp/resolve", |b| {
        b.iter(|| p.resolve(&arm_pose(&robot, &q0), black_box(&q0), &JointVector::zeros(), 0.3))
    });
    group.finish();
}

criterion_group!(benches, baselines);
criterion_main!(benches);
