//! Paper §6.4, the push-box task, planned by the velocity QP on COMAN and Centauro.

use a2ml::Robot;
use a2ml::collision::CollisionScene;
use a2ml::kinematics::arm_pose;
use a2ml::language::{self, Task, Variable};
use a2ml::math::Real;
use a2ml::solve::{Plan, PlanOptions, plan};

use crate::common;

/// Paper §6.4 on both arms: every limit at every sample, clearance from every obstacle the
/// action does not touch, every goal within 1 mm / 1°, and the same actions in the same order.
#[test]
fn the_push_box_task_plans_on_both_arms() {
    let mut sequences = Vec::new();
    for name in ["push_box_aside_coman", "push_box_aside_centauro"] {
        let task = language::load(common::example(&format!("{name}.a2ml"))).expect("loads");
        let robot = Robot::from_urdf_file(&task.robot).expect("robot");
        let plan = plan(&robot, &task, &PlanOptions::default()).expect("plans");
        assert!(plan.reached(), "{name}: {:?}", plan.warnings);
        common::assert_within_limits(&robot, &plan.trajectory);
        let task_b = task.in_base_frame(&robot.structure.shoulder_in_base_link);
        for (i, action) in task_b.actions.iter().enumerate() {
            let reports: Vec<_> = plan.segments.iter().filter(|s| s.action_index == i).collect();
            let (start, end) = (reports[0].start, reports.last().expect("segments").end);
            let scene = CollisionScene::new(&task_b.action_scene(i));
            for (t, q) in plan.trajectory.times().iter().zip(plan.trajectory.positions()) {
                if *t < start || *t > end {
                    continue;
                }
                if let Some((d, link, obstacle)) =
                    a2ml::collision::min_distance(&robot, &arm_pose(&robot, q), &scene)
                {
                    assert!(
                        d >= plan.safety_distance - 1e-9,
                        "{name}: {} at {t:.3} s: {link} {d:.4} m from {obstacle}",
                        action.name
                    );
                }
            }
            check_action_goal(&robot, &task_b, i, &plan, end, name);
        }
        let sequence: Vec<(String, Option<a2ml::decompose::ActionType>)> = plan
            .segments
            .iter()
            .filter(|s| s.segment == 0)
            .map(|s| (s.action.clone(), s.action_type))
            .collect();
        sequences.push(sequence);
    }
    assert_eq!(sequences[0], sequences[1]);
    assert_eq!(sequences[0].len(), 7);
}

/// The action's own goal constraint (its primary goal), re-measured by FK at its end.
fn check_action_goal(robot: &Robot, task: &Task, i: usize, plan: &Plan, end: Real, name: &str) {
    let language::ActionBody::Constraints { goal: Some(goal), .. } = &task.actions[i].body else {
        return;
    };
    let (q, _) = plan.trajectory.sample(end);
    let state = a2ml::decompose::ArmState::at(robot, &q).expect("regular end");
    for (variable, target) in &goal.primary.targets {
        let error = a2ml::decompose::goal_error(&state, &[(*variable, *target)]);
        let limit = if *variable == Variable::Pw { 1e-3 } else { 1.0_f64.to_radians() };
        assert!(error <= limit, "{name}: {} {variable:?} off by {error}", task.actions[i].name);
    }
}
