//! RRT-Connect in the constrained space of a pattern-3 segment, on the paper's §6.2 problems
//! (examples/type_iv_*_bar.a2ml, Centauro): every sample re-checked independently of the
//! planner by forward kinematics (the wrist on its line), the limits and a dense clearance
//! check; the `auto` policy; determinism and the success rate over seeds.

use a2ml::Robot;
use a2ml::collision::{CollisionScene, min_distance};
use a2ml::kinematics::arm_pose;
use a2ml::language::{self, SolverChoice, Task};
use a2ml::math::{JointVector, Real, Vector3};
use a2ml::solve::rrt::RrtError;
use a2ml::solve::{Fallback, Plan, PlanOptions, SolveError, plan};

use crate::common;

/// The wrist line of both examples: through the start's Pw, along [0.356, 0, 0.935].
const DIRECTION: [Real; 3] = [0.356, 0.0, 0.935];

fn load(file: &str) -> (Robot, Task) {
    let task = language::load(common::example(file)).expect("example loads");
    let robot = Robot::from_urdf_file(&task.robot).expect("robot");
    (robot, task)
}

fn options(solver: SolverChoice) -> PlanOptions {
    // At 500 Hz the output samples are the solver's own (one segment from t = 0), not
    // interpolated between them.
    PlanOptions { solver: Some(solver), rate: Some(500.0), ..PlanOptions::default() }
}

fn scene(task: &Task, robot: &Robot) -> CollisionScene {
    CollisionScene::new(&task.in_base_frame(&robot.structure.shoulder_in_base_link).scene)
}

/// The largest distance of the wrist from the line through the first sample's wrist (m).
fn line_error(robot: &Robot, plan: &Plan) -> Real {
    let direction = Vector3::from(DIRECTION).normalize();
    let positions = plan.trajectory.positions();
    let p0 = arm_pose(robot, &positions[0]).wrist;
    positions
        .iter()
        .map(|q| {
            let d = arm_pose(robot, q).wrist - p0;
            (d - direction * d.dot(&direction)).norm()
        })
        .fold(0.0, Real::max)
}

/// The smallest clearance between consecutive samples checked at most 1 mm of arm motion
/// apart (1.5 m of lever per radian bounds any shipped arm).
fn dense_clearance(robot: &Robot, scene: &CollisionScene, positions: &[JointVector]) -> Real {
    let mut smallest = Real::INFINITY;
    for w in positions.windows(2) {
        let (a, b) = (w[0], w[1]);
        let count = ((b - a).abs().sum() * 1.5 / 1e-3).ceil().max(1.0) as usize;
        for k in 0..=count {
            let q = a + (b - a) * (k as Real / count as Real);
            if let Some((d, ..)) = min_distance(robot, &arm_pose(robot, &q), scene) {
                smallest = smallest.min(d);
            }
        }
    }
    smallest
}

#[test]
fn the_rrt_takes_the_arm_over_the_forward_bar_on_the_line() {
    let (robot, task) = load("type_iv_forward_bar.a2ml");
    let plan = plan(&robot, &task, &options(SolverChoice::Rrt)).expect("a path");
    let segment = &plan.segments[0];
    assert_eq!(segment.solver, SolverChoice::Rrt);
    assert!(segment.reached && segment.path_kept, "{:?}", plan.warnings);
    assert!(segment.hard_path);
    let stats = segment.rrt.expect("rrt counters");
    assert!(stats.collision_checks > 0 && stats.time > 0.0, "{stats:?}");

    let error = line_error(&robot, &plan);
    assert!(error < 1e-9, "the wrist leaves its line by {error:e} m");
    common::assert_within_limits(&robot, &plan.trajectory);
    let clearance = dense_clearance(&robot, &scene(&task, &robot), plan.trajectory.positions());
    assert!(clearance >= plan.safety_distance, "{:.2} mm from the bar", clearance * 1e3);
    // The end is the goal the decomposition chose, re-measured by forward kinematics.
    for e in &segment.errors {
        assert!(e.within, "{e:?}");
    }
}

/// Paper §6.2 (a): the QP keeps the hard line as a constraint, so the bar stops it on the
/// line short of the goal; `auto` then goes on to the RRT, which reaches the goal on the line.
#[test]
fn the_qp_stalls_on_the_line_at_the_forward_bar_and_auto_goes_on_to_the_rrt() {
    let (robot, task) = load("type_iv_forward_bar.a2ml");
    let qp = plan(&robot, &task, &options(SolverChoice::Qp)).expect("plans");
    let segment = &qp.segments[0];
    assert!(segment.hard_path && segment.path_kept, "{:?}", segment.path_errors);
    let error = line_error(&robot, &qp);
    assert!(error < 1e-3, "the QP leaves the line by {:.2} mm", error * 1e3);
    assert!(segment.stalled && !segment.reached, "{:?}", segment.errors);
    assert!(!qp.reached());
    assert!(qp.warnings.iter().any(|w| w.message.contains("stalled")), "{:?}", qp.warnings);
    assert!(
        !qp.warnings.iter().any(|w| w.message.contains("left its hard path")),
        "{:?}",
        qp.warnings
    );
    let clearance = dense_clearance(&robot, &scene(&task, &robot), qp.trajectory.positions());
    assert!(clearance >= qp.safety_distance - 1e-4, "{:.2} mm", clearance * 1e3);

    let auto = plan(&robot, &task, &options(SolverChoice::Auto)).expect("plans");
    let segment = &auto.segments[0];
    assert_eq!((segment.solver, segment.fallback), (SolverChoice::Rrt, Some(Fallback::QpStalled)));
    assert!(auto.reached());
    assert!(line_error(&robot, &auto) < 1e-9);
}

#[test]
fn no_path_passes_the_lateral_bar_and_auto_keeps_the_qps_closest_result() {
    let (robot, task) = load("type_iv_lateral_bar.a2ml");
    let mut rrt = options(SolverChoice::Rrt);
    rrt.rrt.max_samples = 2000;
    match plan(&robot, &task, &rrt) {
        Err(SolveError::Rrt { source: RrtError::NoPath { stats, .. }, .. }) => {
            assert_eq!(stats.samples, 2000);
        }
        other => panic!("expected no path, got {other:?}"),
    }

    let mut auto = options(SolverChoice::Auto);
    auto.rrt.max_samples = 2000;
    let plan = plan(&robot, &task, &auto).expect("the QP's result");
    let segment = &plan.segments[0];
    assert_eq!((segment.solver, segment.fallback), (SolverChoice::Qp, None));
    assert!(!segment.reached);
    // Paper §6.2 (c): the QP's closest result stops on the line, short of the goal.
    assert!(segment.path_kept, "{:?}", segment.path_errors);
    let error = line_error(&robot, &plan);
    assert!(error < 1e-3, "the QP leaves the line by {:.2} mm", error * 1e3);
    let kept = "rrt: no path found in 2000 samples";
    assert!(plan.warnings.iter().any(|w| w.message.contains(kept)), "{:?}", plan.warnings);
    let clearance = dense_clearance(&robot, &scene(&task, &robot), plan.trajectory.positions());
    assert!(clearance >= plan.safety_distance - 1e-4, "{:.2} mm", clearance * 1e3);
}

#[test]
fn the_same_seed_gives_the_same_motion() {
    let (robot, mut task) = load("type_iv_forward_bar.a2ml");
    let options = options(SolverChoice::Rrt);
    let a = plan(&robot, &task, &options).expect("a path");
    let b = plan(&robot, &task, &options).expect("a path");
    assert_eq!(a.trajectory, b.trajectory);
    task.settings.seed += 1;
    let c = plan(&robot, &task, &options).expect("a path");
    assert_ne!(a.trajectory, c.trajectory);
}

/// Paper §6.2's claim for the global solver, over 100 seeds: the path is found (at least 99
/// times) and, when found, keeps the line exactly and reaches the goal.
#[test]
fn the_forward_bar_is_solved_for_nearly_every_seed() {
    let (robot, mut task) = load("type_iv_forward_bar.a2ml");
    let options = options(SolverChoice::Rrt);
    let mut found = 0;
    for seed in 0..100 {
        task.settings.seed = seed;
        if let Ok(p) = plan(&robot, &task, &options) {
            assert!(p.reached(), "seed {seed}: {:?}", p.warnings);
            assert!(line_error(&robot, &p) < 1e-9, "seed {seed}");
            found += 1;
        }
    }
    eprintln!("forward bar: {found} of 100 seeds found a path");
    assert!(found >= 99, "only {found} of 100 seeds found a path");
}

/// The velocities the timing writes (the Jacobian solved for the path's rate) are the
/// derivative of the positions it writes (the IK along the path): central differences of
/// the 500 Hz samples agree with them to the differences' own error.
#[test]
fn the_timed_velocities_are_the_derivative_of_the_timed_positions() {
    let (robot, task) = load("type_iv_forward_bar.a2ml");
    let plan = plan(&robot, &task, &options(SolverChoice::Rrt)).expect("a path");
    let (times, positions, velocities) =
        (plan.trajectory.times(), plan.trajectory.positions(), plan.trajectory.velocities());
    let peak = velocities.iter().map(|v| v.amax()).fold(0.0, Real::max);
    assert!(peak > 0.1, "the arm moves: peak joint speed {peak} rad/s");
    let mut worst: Real = 0.0;
    for k in 1..times.len() - 1 {
        let difference = (positions[k + 1] - positions[k - 1]) / (times[k + 1] - times[k - 1]);
        worst = worst.max((difference - velocities[k]).amax());
    }
    assert!(worst < 2e-3 * peak, "velocities differ from the positions' rate by {worst} rad/s");
}
