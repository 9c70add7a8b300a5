//! The HAMP handover planner: the pattern extracted from its motion is the one it was planned
//! with, P is minimum-jerk and the duration is Fitts' T; and the comparison the HAMP paper
//! makes, its planner against A2ML's own plan for the same target, scored by the metrics.

use a2ml::Robot;
use a2ml::collision::CollisionScene;
use a2ml::decompose::FittsLaw;
use a2ml::kinematics::{arm_pose, cpsa_state};
use a2ml::language;
use a2ml::math::{JointVector, Rotation3, UnitQuaternion, Vector3, rotation_about};
use a2ml::metrics::pattern::similarity;
use a2ml::metrics::{self, Analysis, MetricsOptions, Span};
use a2ml::solve::hamp::{HampOptions, HampPlan, Handover, HandoverTarget, plan_handover};
use a2ml::solve::{PlanOptions, plan};

use crate::common;

fn coman_start() -> JointVector {
    JointVector::from_fn(|i, _| [-10.0_f64, -15.0, 45.0, -100.0, 0.0, 0.0, 0.0][i].to_radians())
}

/// A handover target from COMAN's start: the wrist 17 cm forward, out and up, the hand turned
/// 0.3 rad about the vertical, the elbow swung out by 0.35 rad.
fn target(robot: &Robot, start: &JointVector) -> HandoverTarget {
    let state = cpsa_state(robot, &arm_pose(robot, start)).expect("regular start");
    HandoverTarget {
        pw: state.pw + Vector3::new(0.10, -0.08, 0.11),
        ow: Rotation3::from_matrix_unchecked(
            rotation_about(&Vector3::z(), 0.3) * state.ow.matrix(),
        ),
        swivel: Some(state.swivel + 0.35),
    }
}

fn hamp_plan(handover: Handover) -> (Robot, HampPlan) {
    let robot = common::load("coman_right_arm");
    let start = coman_start();
    let options = HampOptions { handover, seed: 7, ..HampOptions::default() };
    let plan =
        plan_handover(&robot, &start, &target(&robot, &start), &CollisionScene::new(&[]), &options)
            .expect("plans");
    (robot, plan)
}

#[test]
fn a_hamp_pick_up_shows_its_planned_pattern_minimum_jerk_and_fitts_duration() {
    let (robot, plan) = hamp_plan(Handover::PickUp);
    assert_eq!(plan.phase1.to_string(), "ΦPO");
    assert_eq!(plan.phase2.to_string(), "ΦPO-PO");
    assert!(plan.limit_violations.is_empty(), "{:?}", plan.limit_violations);

    let analysis = metrics::analyze(&robot, &plan.trajectory, &[], &MetricsOptions::default());
    let patterns = &analysis.whole.patterns;
    assert_eq!(patterns.phase1.hamp, plan.phase1);
    assert_eq!(patterns.phase2.hamp, plan.phase2);

    // Duration: Fitts' T for the wrist's travel, measured by FK at the ends.
    let trajectory = &plan.trajectory;
    let first = arm_pose(&robot, &trajectory.positions()[0]).wrist;
    let last = arm_pose(&robot, &trajectory.positions()[trajectory.len() - 1]).wrist;
    let travel = (last - first).norm();
    assert!((travel - plan.travel).abs() < 1e-9);
    assert!((trajectory.duration() - FittsLaw::default().duration(travel)).abs() < 1e-12);

    // P's speed by central differences of FK positions: 1.875 ΔP/T at T/2, within 1 %.
    let times = trajectory.times();
    let speed = |k: usize| {
        let (a, b) = (&trajectory.positions()[k - 1], &trajectory.positions()[k + 1]);
        (arm_pose(&robot, b).wrist - arm_pose(&robot, a).wrist).norm()
            / (times[k + 1] - times[k - 1])
    };
    let (peak_frame, peak) = (1..trajectory.len() - 1)
        .map(|k| (k, speed(k)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .expect("samples");
    let expected = 1.875 * travel / trajectory.duration();
    assert!((peak - expected).abs() < 0.01 * expected, "peak {peak}, expected {expected}");
    let half = 0.5 * trajectory.duration();
    assert!((times[peak_frame] - half).abs() <= 1.0 / 120.0 + 1e-9, "{}", times[peak_frame]);
    // And the planned velocities agree with the positions (the speeds the patterns used).
    let planned = analysis.frames.speeds.position[peak_frame];
    assert!((planned - peak).abs() < 0.01 * expected);
}

#[test]
fn a_hamp_delivery_plans_the_patterns_its_ratio_selects_and_shows_them() {
    let (robot, plan) = hamp_plan(Handover::Delivery);
    let r_d = plan.duration_ratio;
    let expected = if r_d >= 1.6 { ("ΦPO", "ΦPO") } else { ("PO-ΦPO", "ΦPO-PO") };
    assert_eq!((plan.phase1.to_string().as_str(), plan.phase2.to_string().as_str()), expected);
    let analysis = metrics::analyze(&robot, &plan.trajectory, &[], &MetricsOptions::default());
    assert_eq!(analysis.whole.patterns.phase1.hamp, plan.phase1, "R_d {r_d}");
    assert_eq!(analysis.whole.patterns.phase2.hamp, plan.phase2, "R_d {r_d}");
}

#[test]
fn the_same_seed_plans_the_same_handover() {
    let (_, a) = hamp_plan(Handover::PickUp);
    let (_, b) = hamp_plan(Handover::PickUp);
    assert_eq!(a, b);
}

fn quat(r: &Rotation3) -> String {
    let q = UnitQuaternion::from_rotation_matrix(r);
    format!("quat({}, {}, {}, {})", q.w, q.i, q.j, q.k)
}

/// The handover of [`target`] from COMAN's start as a task with one goal action, solved by
/// `solver` (the task's default when `None`).
fn handover_task(robot: &Robot, solver: Option<&str>) -> a2ml::language::Task {
    let start = coman_start();
    let goal = target(robot, &start);
    let q = start.iter().map(|v| format!("{v}")).collect::<Vec<_>>().join(", ");
    let solver = solver.map_or(String::new(), |s| format!("    solver {s}\n"));
    let source = format!(
        "robot \"../robots/coman_right_arm.urdf\"\nstart [{q}] rad\nsettings {{ rate 120 Hz }}\ntask \
         handover {{\n  action pick_up {{\n    goal Pw Ow θsw = ([{}, {}, {}], {}, {})\n{solver}  }}\n}}\n",
        goal.pw.x,
        goal.pw.y,
        goal.pw.z,
        quat(&goal.ow),
        goal.swivel.expect("given")
    );
    language::parse(&source, Some(&common::example("inline.a2ml")))
        .unwrap_or_else(|d| panic!("{d}"))
}

fn row(name: &str, a: &Analysis) -> String {
    let w = &a.whole;
    let rula = w.rula.expect("scored");
    let sum = w.rula_sum.expect("scored");
    format!(
        "{name:<6} {:>6.3} s  Fitts ×{:.2}  {:<10} {:<14} RULA A {:.2} (max {})  sum {:.2} (max {})  sym {:.3}",
        w.fitts.duration,
        w.fitts.ratio,
        w.patterns.phase1.hamp.to_string(),
        w.patterns.phase2.hamp.to_string(),
        rula.mean,
        rula.max,
        sum.mean,
        sum.max,
        w.wrist_speed.symmetry,
    )
}

/// The HAMP paper's comparison: for one handover target, the HAMP planner and A2ML's own
/// goal action, both scored with RULA and the pattern measures (printed as a table; the
/// numbers are in docs/metrics.md).
#[test]
fn hamp_and_a2ml_plans_of_one_handover_scored_side_by_side() {
    let (robot, hamp) = hamp_plan(Handover::PickUp);
    let task = handover_task(&robot, None);
    let a2ml = plan(&robot, &task, &PlanOptions::default()).expect("plans");
    assert!(a2ml.reached(), "{:?}", a2ml.warnings);

    let options = MetricsOptions::default();
    let of_hamp = metrics::analyze(&robot, &hamp.trajectory, &[], &options);
    let of_a2ml = metrics::analyze(&robot, &a2ml.trajectory, &Span::of_plan(&a2ml), &options);
    println!("{}\n{}", row("HAMP", &of_hamp), row("A2ML", &of_a2ml));

    // Both end at the same hand pose, so the postures at the end score the same.
    let end_scores = |a: &Analysis| *a.frames.rula.last().expect("frames");
    assert_eq!(end_scores(&of_hamp).map(|s| s.table_a), end_scores(&of_a2ml).map(|s| s.table_a));
    // HAMP's patterns are the ones the paper selects for a pick-up; A2ML's are scored against them.
    for (analysis, exact) in [(&of_hamp, true), (&of_a2ml, false)] {
        let p = &analysis.whole.patterns;
        let score = 0.5
            * (similarity(&p.phase1.hamp, &hamp.phase1) + similarity(&p.phase2.hamp, &hamp.phase2));
        assert!((0.0..=1.0).contains(&score));
        if exact {
            assert_eq!(score, 1.0);
        }
    }
    // HAMP is timed by Fitts' law; A2ML's goal action starts from the same law (LANGUAGE.md),
    // stretched only for the joint speed limits, and settles after it.
    assert!((of_hamp.whole.fitts.ratio - 1.0).abs() < 1e-9);
    assert!(of_a2ml.whole.fitts.ratio >= 1.0 - 1e-9);
}

/// `solver hamp` on a goal action: the plan's segment is solved by the HAMP planner, reaches
/// the goal, lasts Fitts' T and shows the pick-up patterns.
#[test]
fn solver_hamp_plans_a_goal_action_as_a_pick_up() {
    let robot = common::load("coman_right_arm");
    let start = coman_start();
    let goal = target(&robot, &start);
    let task = handover_task(&robot, Some("hamp"));
    let planned = plan(&robot, &task, &PlanOptions::default()).expect("plans");
    assert!(planned.reached(), "{:?}", planned.warnings);
    let segment = &planned.segments[0];
    assert_eq!(segment.solver.name(), "hamp");
    let travel =
        (goal.pw - cpsa_state(&robot, &arm_pose(&robot, &start)).expect("regular").pw).norm();
    assert!((segment.duration - FittsLaw::default().duration(travel)).abs() < 1e-9);
    let analysis = metrics::analyze(
        &robot,
        &planned.trajectory,
        &Span::of_plan(&planned),
        &MetricsOptions::default(),
    );
    let patterns = &analysis.segments[0].patterns;
    assert_eq!(patterns.phase1.hamp.to_string(), "ΦPO");
    assert_eq!(patterns.phase2.hamp.to_string(), "ΦPO-PO");
}
