//! Hot paths of the kinematics: FK + J_ge, CPSA state + J_cs, analytic IK
//! (all branches, and the nearest only), closed-form swivel intervals.

use std::hint::black_box;

use a2ml::Robot;
use a2ml::kinematics::{
    arm_pose, cpsa_jacobian, cpsa_state, geometric_jacobian, hat_jacobian, hat_state, ik_cpsa,
    ik_cpsa_nearest, swivel_intervals,
};
use a2ml::math::JointVector;
use criterion::{Criterion, criterion_group, criterion_main};

fn robot(name: &str) -> Robot {
    Robot::from_urdf_file(format!("{}/robots/{name}.urdf", env!("CARGO_MANIFEST_DIR")))
        .expect("shipped robot loads")
}

/// A regular in-limit configuration of every shipped arm.
fn configuration(robot: &Robot) -> JointVector {
    let (lo, hi) = (robot.lower(), robot.upper());
    JointVector::from_fn(|i, _| lo[i] + [0.55, 0.35, 0.6, 0.3, 0.45, 0.6, 0.4][i] * (hi[i] - lo[i]))
}

fn kinematics(c: &mut Criterion) {
    for name in ["iiwa14", "centauro_right_arm", "panda", "human_arm"] {
        let robot = robot(name);
        let q = configuration(&robot);
        let pose = arm_pose(&robot, &q);
        let cpsa = cpsa_state(&robot, &pose).expect("regular configuration");
        let mut group = c.benchmark_group(name);
        group.bench_function("fk_hand+J_ge", |b| {
            b.iter(|| {
                let pose = arm_pose(&robot, black_box(&q));
                (pose.hand_frame(), geometric_jacobian(&pose))
            })
        });
        group.bench_function("cpsa_state+J_cs", |b| {
            b.iter(|| {
                let pose = arm_pose(&robot, black_box(&q));
                (cpsa_state(&robot, &pose), cpsa_jacobian(&robot, &pose))
            })
        });
        group.bench_function("hat_state+J_tr", |b| {
            b.iter(|| {
                let pose = arm_pose(&robot, black_box(&q));
                (hat_state(&pose), hat_jacobian(&pose))
            })
        });
        let ik_name = if robot.has_analytic_ik() { "ik_cpsa_analytic" } else { "ik_cpsa_newton" };
        group.bench_function(ik_name, |b| b.iter(|| ik_cpsa(&robot, black_box(&cpsa), Some(&q))));
        // What tracking a branch asks for: the nearest solution only, `near` close by.
        let near = q.map(|v| v + 1e-3);
        group.bench_function("ik_cpsa_nearest", |b| {
            b.iter(|| ik_cpsa_nearest(&robot, black_box(&cpsa), &near))
        });
        if robot.has_analytic_ik() {
            group.bench_function("swivel_intervals", |b| {
                b.iter(|| swivel_intervals(&robot, black_box(&cpsa.pw), &cpsa.ow))
            });
        }
        group.finish();
    }
}

criterion_group!(benches, kinematics);
criterion_main!(benches);
