//! IK round trips through CPSA and HAT on every robot, and the CPSA <-> HAT
//! mapping.

use crate::common::{all_robots, regular_q, rng};
use a2ml::Robot;
use a2ml::kinematics::*;
use a2ml::math::{JointVector, Real, rotation_distance, wrap_angle};

const SAMPLES: usize = 10_000;

fn cpsa_error(a: &CpsaState, b: &CpsaState) -> Real {
    (a.pw - b.pw)
        .norm()
        .max(rotation_distance(&a.ow, &b.ow))
        .max(wrap_angle(a.swivel - b.swivel).abs())
}

fn hat_error(a: &HatState, b: &HatState) -> Real {
    rotation_distance(&a.shoulder_frame, &b.shoulder_frame)
        .max((a.elbow_angle - b.elbow_angle).abs())
        .max(rotation_distance(&a.ow, &b.ow))
}

fn tolerance(robot: &Robot) -> Real {
    if robot.has_analytic_ik() { 1e-9 } else { 1e-8 }
}

fn contains(branches: &[JointVector], q: &JointVector) -> bool {
    branches.iter().any(|b| (b - q).amax() < 1e-6)
}

#[test]
fn cpsa_ik_round_trip() {
    for (name, robot) in all_robots() {
        let mut rng = rng(10);
        for _ in 0..SAMPLES {
            let (q, pose) = regular_q(&robot, &mut rng, 0.1);
            let target = cpsa_state(&robot, &pose).expect("regular");
            let solutions = ik_cpsa(&robot, &target, None)
                .unwrap_or_else(|e| panic!("{name}: IK failed at {q:?}: {e}"));
            assert!(!solutions.is_empty());
            for s in &solutions {
                assert!(robot.within_limits(s, 1e-9), "{name}: branch outside limits");
                let reached = cpsa_state(&robot, &arm_pose(&robot, s)).expect("regular");
                let err = cpsa_error(&reached, &target);
                assert!(err < tolerance(&robot), "{name}: CPSA round trip error {err:e}");
            }
            if robot.has_analytic_ik() {
                assert!(
                    contains(&solutions, &q),
                    "{name}: the original branch is missing at {q:?}"
                );
            }
        }
    }
}

#[test]
fn hat_ik_round_trip() {
    for (name, robot) in all_robots() {
        let mut rng = rng(11);
        for _ in 0..SAMPLES {
            let (q, pose) = regular_q(&robot, &mut rng, 0.1);
            let target = hat_state(&pose).expect("regular");
            let solutions = ik_hat(&robot, &target, None)
                .unwrap_or_else(|e| panic!("{name}: IK failed at {q:?}: {e}"));
            for s in &solutions {
                let reached = hat_state(&arm_pose(&robot, s)).expect("regular");
                let err = hat_error(&reached, &target);
                assert!(err < tolerance(&robot), "{name}: HAT round trip error {err:e}");
            }
            if robot.has_analytic_ik() {
                assert!(contains(&solutions, &q), "{name}: the original branch is missing");
            }
        }
    }
}

#[test]
fn nearest_branch_comes_first() {
    for (name, robot) in all_robots().into_iter().filter(|(_, r)| r.has_analytic_ik()) {
        let mut rng = rng(12);
        for _ in 0..1000 {
            let (q, pose) = regular_q(&robot, &mut rng, 0.1);
            let target = cpsa_state(&robot, &pose).expect("regular");
            let solutions = ik_cpsa(&robot, &target, Some(&q)).expect("reachable");
            assert!((solutions[0] - q).amax() < 1e-6, "{name}: nearest branch not first");
        }
    }
}

#[test]
fn mapping_round_trips() {
    for (name, robot) in all_robots() {
        let mut rng = rng(13);
        for _ in 0..SAMPLES {
            let (_, pose) = regular_q(&robot, &mut rng, 0.1);
            let cpsa = cpsa_state(&robot, &pose).expect("regular");
            let hat = cpsa_to_hat(&robot, &cpsa).expect("reachable");
            let back = hat_to_cpsa(&robot, &hat).expect("regular");
            assert!(
                cpsa_error(&cpsa, &back) < 1e-12,
                "{name}: CPSA->HAT->CPSA {:e}",
                cpsa_error(&cpsa, &back)
            );
            let again = cpsa_to_hat(&robot, &back).expect("reachable");
            assert!(
                hat_error(&hat, &again) < 1e-12,
                "{name}: HAT->CPSA->HAT {:e}",
                hat_error(&hat, &again)
            );
        }
    }
}

#[test]
fn mapping_agrees_with_the_arm_on_analytic_arms() {
    // For a rigid triangle the mapping is exact: the HAT state FK reports
    // equals the mapped CPSA state FK reports.
    for (name, robot) in all_robots().into_iter().filter(|(_, r)| r.has_analytic_ik()) {
        let mut rng = rng(14);
        for _ in 0..1000 {
            let (_, pose) = regular_q(&robot, &mut rng, 0.1);
            let mapped = cpsa_to_hat(&robot, &cpsa_state(&robot, &pose).expect("regular"))
                .expect("reachable");
            let err = hat_error(&mapped, &hat_state(&pose).expect("regular"));
            assert!(err < 1e-9, "{name}: mapping differs from the arm by {err:e}");
        }
    }
}
