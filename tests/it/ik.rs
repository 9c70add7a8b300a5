//! IK round trips through CPSA and HAT on every robot, and the CPSA <-> HAT
//! mapping.

use crate::common::{all_robots, regular_q, rng};
use a2ml::Robot;
use a2ml::kinematics::*;
use a2ml::math::{JointVector, Real, rotation_distance, wrap_angle};
use rand::RngExt;

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

/// The nearest-only solvers give exactly the first of the full solvers' solutions, or their
/// error: near the configuration (tracking), far from it (another branch nearest), and at
/// random `near`s and targets, on every arm.
#[test]
fn nearest_only_ik_equals_the_first_solution() {
    for (name, robot) in all_robots() {
        let mut rng = rng(14);
        let samples = if robot.has_analytic_ik() { 2000 } else { 20 };
        for k in 0..samples {
            let (q, pose) = regular_q(&robot, &mut rng, 0.1);
            let near = match k % 3 {
                0 => q.map(|v| v + 1e-3),
                1 => crate::common::random_q(&robot, &mut rng),
                _ => robot.middle(),
            };
            let mut cpsa = cpsa_state(&robot, &pose).expect("regular");
            if k % 7 == 0 {
                cpsa.pw *= 1.3; // often out of reach: the errors must agree too
            }
            let full = ik_cpsa(&robot, &cpsa, Some(&near)).map(|s| s[0]);
            assert_eq!(ik_cpsa_nearest(&robot, &cpsa, &near), full, "{name}: CPSA at {q:?}");
            let hat = hat_state(&pose).expect("regular");
            let full = ik_hat(&robot, &hat, Some(&near)).map(|s| s[0]);
            assert_eq!(ik_hat_nearest(&robot, &hat, &near), full, "{name}: HAT at {q:?}");
        }
    }
}

/// The same along tracked edges, where the nearest solver prunes shoulder and wrist solutions
/// by their middle joints: `near` a step of up to 0.3 rad away, and configurations whose
/// joint 2 or 6 is within a few milliradians of zero (the two solutions of that group then
/// lie close together, their middle angles of either sign).
#[test]
fn nearest_only_ik_equals_the_first_solution_when_tracking() {
    for (name, robot) in all_robots() {
        if !robot.has_analytic_ik() {
            continue;
        }
        let mut rng = rng(15);
        for k in 0..3000 {
            let mut q = crate::common::random_q(&robot, &mut rng);
            match k % 4 {
                1 => q[1] = rng.random_range(-3e-3..3e-3),
                2 => q[5] = rng.random_range(-3e-3..3e-3),
                3 => (q[1], q[5]) = (rng.random_range(-1e-6..1e-6), rng.random_range(-1e-6..1e-6)),
                _ => {}
            }
            let pose = a2ml::kinematics::arm_pose(&robot, &q);
            let Ok(cpsa) = cpsa_state(&robot, &pose) else { continue };
            let size = [1e-4, 0.03, 0.3][k % 3];
            let near = q.map(|v| v + rng.random_range(-size..size));
            let full = ik_cpsa(&robot, &cpsa, Some(&near)).map(|s| s[0]);
            assert_eq!(ik_cpsa_nearest(&robot, &cpsa, &near), full, "{name}: CPSA at {q:?}");
            let Ok(hat) = hat_state(&pose) else { continue };
            let full = ik_hat(&robot, &hat, Some(&near)).map(|s| s[0]);
            assert_eq!(ik_hat_nearest(&robot, &hat, &near), full, "{name}: HAT at {q:?}");
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

/// Round trips q -> CPSA -> IK on the third-party arms, from a start 0.3 rad
/// off in every joint: the rate that reaches the state within limits, and,
/// on analytic arms, the rate whose branches include q.
fn third_party_round_trips(samples: usize) -> Vec<(&'static str, &'static str, Real, Real)> {
    use a2ml::math::DOF;
    let mut out = Vec::new();
    for (name, robot) in crate::robots::third_party() {
        let mut rng = rng(21);
        let (mut reached, mut found) = (0usize, 0usize);
        for _ in 0..samples {
            let (q, pose) = regular_q(&robot, &mut rng, 0.05);
            let target = cpsa_state(&robot, &pose).expect("regular");
            let mut near = q;
            for i in 0..DOF {
                let l = robot.joints[i].limits;
                near[i] = (q[i] + rng.random_range(-0.3..0.3)).clamp(l.lower, l.upper);
            }
            let Ok(solutions) = ik_cpsa(&robot, &target, Some(&near)) else { continue };
            let good = solutions.iter().all(|s| {
                let state = cpsa_state(&robot, &arm_pose(&robot, s)).expect("regular");
                robot.within_limits(s, 1e-9) && cpsa_error(&state, &target) < 1e-8
            });
            reached += usize::from(good && !solutions.is_empty());
            found += usize::from(contains(&solutions, &q));
        }
        let kind = match (robot.has_analytic_ik(), robot.structure.idealisation > 1e-9) {
            (true, false) => "analytic",
            (true, true) => "analytic + Newton polish",
            (false, _) => "Newton from the spherical approximation",
        };
        let n = samples as Real;
        out.push((name, kind, reached as Real / n, found as Real / n));
    }
    out
}

#[test]
fn third_party_ik_round_trips_succeed() {
    for (name, kind, reached, found) in third_party_round_trips(400) {
        println!(
            "{name}: {kind}: reached {:.2} %, original among branches {:.2} %",
            100.0 * reached,
            100.0 * found
        );
        assert!(reached >= 0.995, "{name} ({kind}): round trips reach only {reached}");
        if kind.starts_with("analytic") {
            // Nearest first holds only if q itself is a candidate, 2π shifts included.
            assert!(found >= 0.995, "{name}: the original configuration is a branch in {found}");
        }
    }
}

#[test]
fn newton_ik_respects_its_budget_and_deadline() {
    let (_, robot) = crate::robots::third_party()
        .into_iter()
        .find(|(_, r)| !r.has_analytic_ik())
        .expect("an arm with offsets");
    let mut target = cpsa_state(&robot, &arm_pose(&robot, &robot.middle())).expect("regular");
    // Far out of reach: Newton can only give up.
    target.pw *= 10.0;
    let budget = IkOptions { max_total_iterations: 50, ..IkOptions::default() };
    let err = ik_cpsa_with(&robot, &target, None, &budget).unwrap_err();
    assert!(
        matches!(err, KinematicsError::NoConvergence { starts, .. } if starts <= 50),
        "{err:?}"
    );
    let past = IkOptions { deadline: Some(std::time::Instant::now()), ..IkOptions::default() };
    let err = ik_cpsa_with(&robot, &target, None, &past).unwrap_err();
    assert!(matches!(err, KinematicsError::NoConvergence { .. }), "{err:?}");
}
