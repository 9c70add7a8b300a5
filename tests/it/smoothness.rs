//! Limits and smoothness of planned motions (issue 12): every output, resampled at 1 kHz, holds
//! the position, velocity and acceleration limits and has q' equal to the derivative of q.

use a2ml::Robot;
use a2ml::decompose::SegmentPattern;
use a2ml::kinematics::arm_pose;
use a2ml::language::{self, SolverChoice, Variable};
use a2ml::math::{JointVector, Real, Vector3};
use a2ml::metrics::smoothness::{normalised_jerk, speed_peaks};
use a2ml::solve::{Plan, PlanOptions, plan};
use a2ml::trajectory::Limits;

use crate::common;

/// The tasks of the before/after table in the README.
const TABLE: [&str; 6] = [
    "type_iv_forward_bar",
    "type_iv_lateral_bar",
    "type_vii_column",
    "construct_scene",
    "push_box_aside_coman",
    "push_box_aside_centauro",
];

fn planned(name: &str) -> (Robot, Result<Plan, a2ml::solve::SolveError>) {
    let task = language::load(common::example(&format!("{name}.a2ml"))).expect("loads");
    let robot = Robot::from_urdf_file(&task.robot).expect("robot");
    let plan = plan(&robot, &task, &PlanOptions::default());
    (robot, plan)
}

/// Peak |q̈| (rad/s², finite differences of q' at the output rate), the joints' and the wrist's
/// normalised jerk over the whole plan.
fn measures(robot: &Robot, plan: &Plan) -> (Real, Real, Real) {
    let t = &plan.trajectory;
    let (times, qd) = (t.times(), t.velocities());
    let peak = (1..times.len())
        .map(|k| ((qd[k] - qd[k - 1]) / (times[k] - times[k - 1])).amax())
        .fold(0.0, Real::max);
    let wrist: Vec<Vector3> = t.positions().iter().map(|q| arm_pose(robot, q).wrist).collect();
    let wrist_velocity: Vec<Vector3> = (0..times.len())
        .map(|k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(times.len() - 1));
            (wrist[b] - wrist[a]) / (times[b] - times[a])
        })
        .collect();
    let joints: Vec<JointVector> = qd.to_vec();
    (peak, normalised_jerk(times, &joints), normalised_jerk(times, &wrist_velocity))
}

/// Prints the README's table: `cargo test -p a2ml --test it smoothness_table -- --ignored
/// --nocapture`.
#[test]
#[ignore = "a measurement for the README, not a check"]
fn smoothness_table() {
    println!("| task | peak q̈ (rad/s²) | joint NJ | wrist NJ |");
    for name in TABLE {
        let (robot, plan) = planned(name);
        match plan {
            Ok(plan) => {
                let (peak, joints, wrist) = measures(&robot, &plan);
                println!("| {name} | {peak:.1} | {joints:.0} | {wrist:.0} |");
            }
            Err(e) => println!("| {name} | failed: {e} | | |"),
        }
    }
}

/// Every example that plans (the push-box tasks on both arms among them), resampled at 1 kHz
/// from its output: every joint within its position range, speed and acceleration limits
/// (1e-6 relative), and q' equal to the derivative of q (the finite difference of q over each
/// millisecond matches the mean of q' at its ends to the cubic's third-order term).
#[test]
fn every_example_holds_the_limits_at_one_kilohertz() {
    let mut planned_count = 0;
    let mut rrt_segments = 0;
    for name in examples() {
        let task = language::load(common::example(&format!("{name}.a2ml"))).expect("loads");
        let robot = Robot::from_urdf_file(&task.robot).expect("robot");
        let Ok(plan) = plan(&robot, &task, &PlanOptions::default()) else { continue };
        planned_count += 1;
        let limits = Limits::of(&robot).with_acceleration_scale(task.settings.acceleration);
        let dense = plan.trajectory.resample(1000.0).expect("resamples");
        let (times, q, qd) = (dense.times(), dense.positions(), dense.velocities());
        for k in 0..times.len() {
            for i in 0..7 {
                let range = limits.upper[i] - limits.lower[i];
                assert!(
                    q[k][i] >= limits.lower[i] - 1e-6 * range
                        && q[k][i] <= limits.upper[i] + 1e-6 * range,
                    "{name}: joint {i} at {:.3} s: q = {}",
                    times[k],
                    q[k][i]
                );
                assert!(
                    qd[k][i].abs() <= limits.velocity[i] * (1.0 + 1e-6),
                    "{name}: joint {i} at {:.3} s: q' = {} (limit {})",
                    times[k],
                    qd[k][i],
                    limits.velocity[i]
                );
            }
            if k == 0 {
                continue;
            }
            let h = times[k] - times[k - 1];
            for i in 0..7 {
                let acceleration = (qd[k][i] - qd[k - 1][i]) / h;
                assert!(
                    acceleration.abs() <= limits.acceleration[i] * (1.0 + 1e-6),
                    "{name}: joint {i} at {:.3} s: q'' = {acceleration} (limit {})",
                    times[k],
                    limits.acceleration[i]
                );
                let difference = (q[k][i] - q[k - 1][i]) / h;
                let mean = 0.5 * (qd[k][i] + qd[k - 1][i]);
                assert!(
                    (difference - mean).abs() <= 1e-3 * limits.velocity[i],
                    "{name}: joint {i} at {:.3} s: (Δq/Δt) {difference} against q' {mean}",
                    times[k]
                );
            }
        }
        for s in plan.segments.iter().filter(|s| s.solver == SolverChoice::Rrt) {
            rrt_segments += 1;
            // No speed step: between any two samples of its time, q' changes by at most the
            // acceleration limit times the sample period.
            for k in 1..times.len() {
                if times[k] < s.start || times[k] > s.end {
                    continue;
                }
                let step = (qd[k] - qd[k - 1]).component_div(&limits.acceleration).amax();
                assert!(step <= (times[k] - times[k - 1]) * (1.0 + 1e-6), "{name}: {}", s.action);
            }
        }
        assert!(plan.segments.iter().all(|s| s.limits_kept), "{name}: {:?}", plan.warnings);
    }
    assert!(planned_count >= 15, "only {planned_count} examples planned");
    assert!(rrt_segments > 0, "no example used the RRT");
}

/// Every goal segment in free space moves its featured variable with one bell: its speed,
/// measured independently from the output (the wrist's speed by FK for a wrist goal), has
/// one peak, as the report says.
#[test]
fn free_space_goal_segments_have_one_speed_peak() {
    let mut seen = 0;
    for name in examples() {
        let task = language::load(common::example(&format!("{name}.a2ml"))).expect("loads");
        let robot = Robot::from_urdf_file(&task.robot).expect("robot");
        let Ok(plan) = plan(&robot, &task, &PlanOptions::default()) else { continue };
        for s in &plan.segments {
            let free = task.action_scene(s.action_index).is_empty();
            if !(free && s.pattern == SegmentPattern::Goal) {
                continue;
            }
            seen += 1;
            assert_eq!(s.speed_peaks, 1, "{name}: {} segment {}", s.action, s.segment + 1);
            let alone = plan.segments.iter().filter(|o| o.action_index == s.action_index).count();
            if s.focus.first() == Some(&Variable::Pw) && alone == 1 {
                // The action's only segment starts and ends at rest, away from any blend.
                let dense = plan.trajectory.resample(1000.0).expect("resamples");
                let wrist: Vec<(Real, Vector3)> = dense
                    .times()
                    .iter()
                    .zip(dense.positions())
                    .filter(|(t, _)| **t >= s.start && **t <= s.end)
                    .map(|(t, q)| (*t, arm_pose(&robot, q).wrist))
                    .collect();
                let speeds: Vec<Real> = wrist
                    .windows(2)
                    .map(|w| (w[1].1 - w[0].1).norm() / (w[1].0 - w[0].0))
                    .collect();
                assert_eq!(speed_peaks(&speeds), 1, "{name}: {} wrist speed", s.action);
            }
        }
    }
    assert!(seen >= 5, "only {seen} free-space goal segments");
}

/// The examples' names.
fn examples() -> Vec<String> {
    let folder = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut names: Vec<String> = std::fs::read_dir(folder)
        .expect("examples")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter_map(|n| n.strip_suffix(".a2ml").map(str::to_owned))
        .collect();
    names.sort();
    names
}

/// Panda's file states Franka's acceleration limits; COMAN's states none, so it gets the
/// default; a bad value is an error naming the joint.
#[test]
fn acceleration_limits_come_from_the_robot_file_or_the_default() {
    let panda = common::load("panda");
    let franka = [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0];
    assert_eq!(panda.acceleration_limits().as_slice(), &franka);
    let coman = common::load("coman_right_arm");
    let default = coman.velocity_limits() * a2ml::robot::DEFAULT_ACCELERATION_PER_SECOND;
    assert_eq!(coman.acceleration_limits(), default);
    let text = std::fs::read_to_string(common::robot_path("panda")).expect("reads");
    // Not a number: the URDF reader's located error names the attribute.
    let junk = text.replacen("a2ml_acceleration=\"7.5\"", "a2ml_acceleration=\"fast\"", 1);
    let error = Robot::from_urdf_str(&junk, &a2ml::RobotOptions::default()).expect_err("junk");
    assert!(error.to_string().contains("a2ml_acceleration"), "{error}");
    // A number that is no acceleration limit.
    let negative = text.replacen("a2ml_acceleration=\"7.5\"", "a2ml_acceleration=\"-3\"", 1);
    match Robot::from_urdf_str(&negative, &a2ml::RobotOptions::default()) {
        Err(a2ml::RobotError::InvalidAcceleration { joint, text }) => {
            assert_eq!((joint.as_str(), text.as_str()), ("panda_joint2", "-3"));
        }
        other => panic!("{other:?}"),
    }
}

/// A wall-clock limit is the user's option: when it passes, the plan fails with a timeout.
/// Without it, the RRT's plan, counters and messages are the same on every run.
#[test]
fn time_limits_are_optional_and_results_repeat_without_one() {
    let task = language::load(common::example("type_iv_forward_bar.a2ml")).expect("loads");
    let robot = Robot::from_urdf_file(&task.robot).expect("robot");
    let options = PlanOptions { time_limit: Some(1e-9), ..PlanOptions::default() };
    let error = plan(&robot, &task, &options).expect_err("the limit has passed");
    assert!(error.to_string().contains("timeout"), "{error}");
    let a = plan(&robot, &task, &PlanOptions::default()).expect("plans");
    let b = plan(&robot, &task, &PlanOptions::default()).expect("plans");
    assert_eq!(a.trajectory, b.trajectory);
    assert_eq!(a.warnings, b.warnings);
    let counters = |p: &Plan| -> Vec<Option<(usize, usize, usize)>> {
        p.segments.iter().map(|s| s.rrt.map(|r| (r.samples, r.nodes, r.collision_checks))).collect()
    };
    assert_eq!(counters(&a), counters(&b));
    assert!(counters(&a).iter().any(Option::is_some), "the forward bar uses the RRT");
}
