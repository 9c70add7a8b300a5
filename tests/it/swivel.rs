//! Closed-form swivel feasibility against a dense sweep through IK.

use crate::common::{all_robots, regular_q, rng};
use a2ml::kinematics::*;
use a2ml::math::PI;

#[test]
fn swivel_intervals_agree_with_brute_force() {
    const POSES: usize = 1000;
    const SWEEP: usize = 1440;
    for (name, robot) in all_robots().into_iter().filter(|(_, r)| r.has_analytic_ik()) {
        let mut rng = rng(20);
        let mut checked = 0usize;
        for _ in 0..POSES {
            let (_, pose) = regular_q(&robot, &mut rng, 0.05);
            let cpsa = cpsa_state(&robot, &pose).expect("regular");
            let intervals = swivel_intervals(&robot, &cpsa.pw, &cpsa.ow).expect("reachable");
            // The configuration we came from is feasible.
            assert!(
                intervals.iter().any(|i| i.contains(cpsa.swivel)),
                "{name}: own swivel excluded"
            );
            let near_boundary = |t: f64| {
                intervals.iter().any(|i| (i.lower - t).abs() < 1e-6 || (i.upper - t).abs() < 1e-6)
            };
            for k in 0..SWEEP {
                let theta = -PI + (k as f64 + 0.5) * 2.0 * PI / SWEEP as f64;
                if near_boundary(theta) {
                    continue;
                }
                let target = CpsaState { swivel: theta, ..cpsa };
                let brute = matches!(ik_cpsa(&robot, &target, None), Ok(ref s) if !s.is_empty());
                let closed = intervals.iter().any(|i| i.contains(theta));
                assert_eq!(
                    closed, brute,
                    "{name}: θsw {theta:.6} closed form {closed}, sweep {brute}, {intervals:?}"
                );
                checked += 1;
            }
        }
        assert!(checked > POSES * SWEEP / 2);
    }
}

#[test]
fn intervals_are_sorted_and_disjoint() {
    for (name, robot) in all_robots().into_iter().filter(|(_, r)| r.has_analytic_ik()) {
        let mut rng = rng(21);
        for _ in 0..200 {
            let (_, pose) = regular_q(&robot, &mut rng, 0.05);
            let cpsa = cpsa_state(&robot, &pose).expect("regular");
            let intervals = swivel_intervals(&robot, &cpsa.pw, &cpsa.ow).expect("reachable");
            for pair in intervals.windows(2) {
                assert!(pair[0].upper < pair[1].lower, "{name}: {intervals:?}");
            }
            assert!(intervals.iter().all(|i| -PI <= i.lower && i.lower < i.upper && i.upper <= PI));
        }
    }
}
