//! Hot paths of the kinematics: FK + J_ge, CPSA state + J_cs, analytic IK
//! (all branches, and the nearest only), closed-form swivel intervals; and per configuration
//! of a batch, the batched kernel (`BatchedChain`) against `arm_pose` in a loop.

use std::hint::black_box;

use a2ml::Robot;
use a2ml::kinematics::{
    BatchedChain, FRAME_VALUES, JACOBIAN_VALUES, arm_pose, cpsa_jacobian, cpsa_state,
    geometric_jacobian, hat_jacobian, hat_state, ik_cpsa, ik_cpsa_nearest, swivel_intervals,
};
use a2ml::math::JointVector;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

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
        // The same two results by the batched steps on one lane (the wheel's per-call path).
        let chain = BatchedChain::new(&robot);
        let row: [f64; 7] = std::array::from_fn(|k| q[k]);
        group.bench_function("fk_hand+J_ge_one_lane", |b| {
            let (mut frame, mut jacobian) = ([0.0; FRAME_VALUES], [0.0; JACOBIAN_VALUES]);
            b.iter(|| {
                chain.hand_frame_and_jacobian(black_box(&row), &mut frame, &mut jacobian);
                black_box((&frame, &jacobian));
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

/// Configurations per batch.
const BATCH: usize = 1000;

/// `BATCH` rows of joint values spread over the limits (row-major), as a batch caller has them.
fn batch(robot: &Robot) -> Vec<f64> {
    let (lo, hi) = (robot.lower(), robot.upper());
    (0..BATCH * 7)
        .map(|i| {
            let (row, k) = (i / 7, i % 7);
            let fraction = ((row * 7 + k * 3) % 101) as f64 / 100.0;
            lo[k] + fraction * (hi[k] - lo[k])
        })
        .collect()
}

fn batched(c: &mut Criterion) {
    for name in ["iiwa14", "panda"] {
        let robot = robot(name);
        let chain = BatchedChain::new(&robot);
        let q = batch(&robot);
        let mut frames = vec![0.0; BATCH * FRAME_VALUES];
        let mut jacobians = vec![0.0; BATCH * JACOBIAN_VALUES];
        let mut group = c.benchmark_group(format!("{name}_batch"));
        group.throughput(Throughput::Elements(BATCH as u64));
        group.bench_function("hand_frames", |b| {
            b.iter(|| chain.hand_frames(black_box(&q), &mut frames))
        });
        group.bench_function("jacobians", |b| {
            b.iter(|| chain.jacobians(black_box(&q), &mut jacobians))
        });
        group.bench_function("hand_frames_and_jacobians", |b| {
            b.iter(|| chain.hand_frames_and_jacobians(black_box(&q), &mut frames, &mut jacobians))
        });
        group.bench_function("cpsa_states", |b| {
            b.iter(|| chain.cpsa_states(&robot, black_box(&q), |_, s| drop(black_box(s))))
        });
        // cpsa_many's kernel: the states written as values.
        let (mut pw, mut ow, mut swivel) =
            (vec![0.0; 3 * BATCH], vec![0.0; 9 * BATCH], vec![0.0; BATCH]);
        group.bench_function("cpsa_values", |b| {
            b.iter(|| chain.cpsa_values(&robot, black_box(&q), &mut pw, &mut ow, &mut swivel))
        });
        group.bench_function("arm_pose_loop_hand+J_ge", |b| {
            b.iter(|| {
                for row in black_box(&q).chunks_exact(7) {
                    let pose = arm_pose(&robot, &JointVector::from_column_slice(row));
                    black_box((pose.hand_frame(), geometric_jacobian(&pose)));
                }
            })
        });
        group.finish();
    }
}

criterion_group!(benches, kinematics, batched);
criterion_main!(benches);
