//! Decomposition: the STRIPS order of the paper's push-box task (§6.4), the
//! classification of actions into the seven types (fig. 3), and every
//! shipped example decomposed whole.

use std::path::{Path, PathBuf};

use a2ml::Robot;
use a2ml::decompose::{
    ActionType, Combination, DecomposeError, DecomposeOptions, Decomposition, SegmentPattern,
    classify, decompose, order, segment_pattern,
};
use a2ml::language::{ActionBody, Space, Task, load, parse};

use crate::common;

/// Parses a task whose robot path is relative to the repository root.
fn task(text: &str) -> Task {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("decompose_test.a2ml");
    match parse(text, Some(&path)) {
        Ok(task) => task,
        Err(d) => panic!("the test task is invalid:\n{d}"),
    }
}

/// A file with one task around `body` (facts and actions).
fn file(body: &str) -> String {
    format!(
        "robot \"robots/coman_right_arm.urdf\"\nstart [0, -20, 0, -60, 0, 10, 0] deg\n\
         task t {{\n{body}\n}}\n"
    )
}

fn names(task: &Task, order: &[usize]) -> Vec<String> {
    order.iter().map(|&i| task.actions[i].name.clone()).collect()
}

/// Fig. 13 (a): the seven actions A1-A7 of the push-box task, written out
/// of order; the facts chain them in the paper's order.
const PUSH_BOX: &str = r#"
robot "robots/coman_right_arm.urdf"
start [0, -20, 0, -60, 0, 10, 0] deg

scene {
  table = box at [0.45, 0, -0.30] size [0.40, 0.80, 0.04]
  box_a = box at [0.42, 0.06, -0.23] size [0.08, 0.08, 0.10]
  box_b = box at [0.42, -0.06, -0.23] size [0.08, 0.08, 0.10]
}

task push_box_a_aside {
  init { holding, box_b_near_a }
  goal { box_a_aside, hand_empty }

  action push_a "A7: push box A leftwards" {
    pre { hand_at_a, hand_empty }
    add { box_a_aside }
    del { hand_at_a }
    path Pw line [0, 1, 0] 0.12 m, Ow hold, θsw hold
  }
  action approach_b "A4: approach box B" {
    pre { hand_above_table, hand_empty }
    add { hand_at_b }
    del { hand_above_table }
    goal Pw Ow θsw = ([0.38, -0.10, -0.12], rpy(90, 0, 90) deg, 60 deg)
  }
  action drop "A1: drop the things in the hand" {
    pre { holding }
    add { hand_empty, hand_over_bin }
    del { holding }
    goal Pw Ow = ([0.25, -0.28, -0.05], rpy(180, 0, 90) deg) > Os = axes(r: [0, 0, -1], l: [0, 1, 0])
  }
  action move_b "A5: move box B" {
    pre { hand_at_b, box_b_near_a }
    add { box_b_moved, hand_beyond_b }
    del { hand_at_b, box_b_near_a }
    path Os hold, θe by -20 deg, Ow about l 20 deg
  }
  action raise "A3: raise the hand above the table" {
    pre { hand_beside_torso }
    add { hand_above_table }
    del { hand_beside_torso }
    goal Pw θsw = ([0.30, -0.20, 0.10], 90 deg)
    path Os about l : soft
  }
  action approach_a "A6: approach box A" {
    pre { box_b_moved, hand_beyond_b }
    add { hand_at_a }
    del { hand_beyond_b }
    goal Pw Ow = ([0.40, 0.00, -0.15], rpy(90, 0, 90) deg)
    path Os hold, θe by 20 deg, Ow about l : soft
  }
  action retract "A2: retract the hand" {
    pre { hand_over_bin }
    add { hand_beside_torso }
    del { hand_over_bin }
    goal Pw Ow = ([0.15, -0.25, 0.05], rpy(180, 0, 90) deg)
    path Os about z, θe hold : hard
  }
}
"#;

const PAPER_ORDER: [&str; 7] =
    ["drop", "retract", "raise", "approach_b", "move_b", "approach_a", "push_a"];

#[test]
fn push_box_plan_is_the_papers_order() {
    let t = task(PUSH_BOX);
    let written: Vec<String> = t.actions.iter().map(|a| a.name.clone()).collect();
    assert_ne!(written, PAPER_ORDER, "the test must not give the answer away");
    let plan = order(&t).expect("the task has a plan");
    assert_eq!(names(&t, &plan), PAPER_ORDER);
}

#[test]
fn push_box_actions_have_the_papers_types() {
    let t = task(PUSH_BOX);
    let plan = order(&t).expect("the task has a plan");
    let types: Vec<ActionType> = plan
        .iter()
        .map(|&i| classify(&t.actions[i]).expect("in the table").expect("constraints").action_type)
        .collect();
    use ActionType::*;
    // §6.4: A1 III, A2 IV, A3 V, A4 II, A5 I, A6 V, A7 I.
    assert_eq!(types, [III, IV, V, II, I, V, I]);
}

#[test]
fn without_init_and_goal_the_written_order_stands() {
    let t = task(&file(
        "action b { goal Pw = [0.3, -0.1, 0.0] }\n\
         action a { path Pw line [0, 1, 0] 5 cm, Ow hold, θsw hold }",
    ));
    assert_eq!(order(&t), Ok(vec![0, 1]));
}

#[test]
fn an_unreachable_goal_fact_is_named() {
    // `box_a_lifted` is added only by `lift_a`, which needs a fact that only
    // `reach_under` adds, which needs `box_a_lifted`.
    let t = task(&file(
        "init { hand_empty }\n\
         goal { box_a_lifted, hand_empty }\n\
         action lift_a { pre { hand_under_a } add { box_a_lifted } goal Pw = [0.4, 0.0, 0.0] }\n\
         action reach_under { pre { box_a_lifted } add { hand_under_a } goal Pw = [0.4, 0.0, -0.2] }",
    ));
    let err = order(&t).expect_err("no plan");
    assert_eq!(
        err,
        DecomposeError::UnreachableGoal { task: "t".into(), facts: vec!["box_a_lifted".into()] }
    );
    let message = a2ml::Error::from(err).to_string();
    assert!(message.contains("goal fact `box_a_lifted` can never become true"), "{message}");
}

/// Placing the cup drips on the table; wiping it clean must come after.
const WIPE_AND_PLACE: &str = "init { holding_cup }\n\
     goal { table_clean, cup_on_table }\n\
     action wipe { add { table_clean } path Pw line [0, 1, 0] 20 cm, Ow hold, θsw hold }\n\
     action place_cup { pre { holding_cup } add { cup_on_table } del { table_clean, holding_cup } \
     goal Pw = [0.4, -0.1, -0.2] }";

#[test]
fn a_goal_reachable_only_by_ordering() {
    let t = task(&file(WIPE_AND_PLACE));
    let plan = order(&t).expect("place, then wipe");
    assert_eq!(names(&t, &plan), ["place_cup", "wipe"]);
}

#[test]
fn a_goal_no_ordering_reaches_is_reported() {
    // Here wiping also knocks the cup off the table.
    let body =
        WIPE_AND_PLACE.replace("add { table_clean }", "add { table_clean } del { cup_on_table }");
    let err = order(&task(&file(&body))).expect_err("no ordering");
    assert!(matches!(err, DecomposeError::NoOrdering { .. }), "{err:?}");
    let message = err.to_string();
    assert!(
        message.contains("makes facts `table_clean`, `cup_on_table` true together"),
        "{message}"
    );
}

/// The one action of a task with `body` as its statements, classified.
fn classify_one(body: &str) -> Result<Option<a2ml::decompose::Classification>, DecomposeError> {
    let t = task(&file(&format!("action act {{ {body} }}")));
    classify(&t.actions[0])
}

fn type_of(body: &str) -> ActionType {
    match classify_one(body) {
        Ok(Some(c)) => c.action_type,
        other => panic!("{body}: {other:?}"),
    }
}

#[test]
fn one_action_of_each_type() {
    let cases = [
        ("path Pw line [0, 1, 0] 12 cm, Ow hold, θsw hold", ActionType::I),
        ("goal Pw Ow θsw = ([0.38, -0.1, -0.12], rpy(90, 0, 90) deg, 60 deg)", ActionType::II),
        (
            "goal Pw Ow = ([0.25, -0.28, -0.05], rpy(180, 0, 90) deg) > Os = axes(r: [0, 0, -1], \
             l: [0, 1, 0])",
            ActionType::III,
        ),
        (
            "goal Pw Ow = ([0.15, -0.25, 0.05], rpy(180, 0, 90) deg) path Os about z, θe hold",
            ActionType::IV,
        ),
        ("goal Pw θsw = ([0.3, -0.2, 0.1], 90 deg) path Os about l : soft", ActionType::V),
        (
            "goal Pw Ow = ([0.27, -0.1, 0.05], rpy(0, 90, 0) deg) > Os = axes(r: [0, 0, -1], \
             l: [0, 1, 0]) path θe hold : hard",
            ActionType::VI,
        ),
        (
            "goal Pw Ow = ([0.27, -0.1, 0.05], rpy(0, 90, 0) deg) > θe = 100 deg \
             path Os about r : soft",
            ActionType::VII,
        ),
    ];
    for (body, expected) in cases {
        assert_eq!(type_of(body), expected, "{body}");
    }
}

#[test]
fn a_path_in_the_goal_space_is_type_ii() {
    // Pw and θsw are independent of Ow: no conflict, the rest is held.
    let c =
        classify_one("goal Ow = rpy(0, 90, 0) deg path Pw line [0, 0, 1] 5 cm, θsw hold : hard")
            .expect("classifies")
            .expect("constraints");
    assert_eq!(c.action_type, ActionType::II);
    assert!(c.path_in_goal_space());
    assert_eq!((c.goal_space, c.path_space), (Some(Space::Cpsa), Some(Space::Cpsa)));
    assert!(c.to_string().contains("path in the goal's space"), "{c}");
    // The same in HAT, with a soft path.
    assert_eq!(
        type_of("goal Os = axes(r: [0, 0, -1], l: [0, 1, 0]) path θe hold : soft"),
        ActionType::II
    );
}

#[test]
fn a_soft_path_sharing_the_goal_variable_gives_way() {
    // In one space, yet in conflict: the path gives way at the end.
    assert_eq!(type_of("goal Pw = [0.3, 0.1, 0.0] path Pw line [0, 1, 0] : soft"), ActionType::V);
}

#[test]
fn ow_only_constraints_are_placed() {
    let c = classify_one("goal Ow = rpy(0, 90, 0) deg").expect("ok").expect("constraints");
    assert_eq!((c.action_type, c.goal_space), (ActionType::II, Some(Space::Cpsa)));
    let c = classify_one("path Ow about z 30 deg").expect("ok").expect("constraints");
    assert_eq!((c.action_type, c.path_space), (ActionType::I, Some(Space::Cpsa)));
    // Beside a HAT path, an Ow goal is in HAT: no conflict.
    let c = classify_one("goal Ow = rpy(0, 90, 0) deg path Os about z 20 deg, θe hold")
        .expect("ok")
        .expect("constraints");
    assert_eq!((c.action_type, c.goal_space), (ActionType::II, Some(Space::Hat)));
    // A goal and a soft path both on Ow conflict.
    assert_eq!(type_of("goal Ow = rpy(0, 90, 0) deg path Ow about z : soft"), ActionType::V);
    // Ow ≻ Pw: Ow takes the space Pw lacks.
    let c = classify_one("goal Ow = rpy(0, 90, 0) deg > Pw = [0.3, -0.1, 0.0]")
        .expect("ok")
        .expect("constraints");
    assert_eq!(c.action_type, ActionType::III);
    assert_eq!((c.goal_space, c.secondary_goal_space), (Some(Space::Hat), Some(Space::Cpsa)));
}

#[test]
fn a_path_without_size_where_nothing_chooses_it() {
    // The path is in the goal's space, so no optimiser sizes it.
    let err = classify_one("goal Ow = rpy(0, 90, 0) deg path Pw line [0, 0, 1], θsw hold")
        .expect_err("no size");
    assert!(matches!(err, DecomposeError::MissingPathSize { line: true, .. }), "{err:?}");
    let message = err.to_string();
    assert!(message.contains("action `act`: the path on Pw has no size"), "{message}");
    assert!(message.contains("give the length"), "{message}");
}

#[test]
fn constraints_outside_the_table() {
    // The validator rejects an action without constraints; a task built in
    // code may still have one.
    let mut t = task(&file("action act { goal Pw = [0.3, -0.1, 0.0] }"));
    t.actions[0].body = ActionBody::Constraints { goal: None, path: None, duration: None };
    let err = classify(&t.actions[0]).expect_err("empty");
    assert_eq!(
        err,
        DecomposeError::OutOfTable { action: "act".into(), combination: Combination::Nothing }
    );
    assert!(a2ml::Error::from(err).to_string().contains("neither a goal nor a path"));
    // Nor a hard path on a goal's variable: it could not give way.
    let mut t =
        task(&file("action act { goal Pw = [0.3, 0.1, 0.0] path Pw line [0, 1, 0] : soft }"));
    let ActionBody::Constraints { path: Some(path), .. } = &mut t.actions[0].body else {
        panic!("constraints")
    };
    path.hard = true;
    let err = classify(&t.actions[0]).expect_err("hard path on Pw");
    assert!(err.to_string().contains("Pw is in a goal and in a hard path"), "{err}");
}

#[test]
fn explicit_actions_are_not_classified_and_segments_have_patterns() {
    let t = task(&file(
        "action type_vii explicit {\n\
           segment 1.2 s { Os.path(about r, 24.7 deg) +Pa (θe Ow).goal(100 deg, rpy(-15.5, -11.5, -104.6) deg) }\n\
           +Tr segment 1.0 s { (Pw Ow).goal([0.27, -0.10, 0.05], axes(f: [1,0,0], p: [0,1,0])) +Pa θsw.hold }\n\
           +Tr segment 0.8 s { (Pw Ow θsw).goal([0.27, -0.10, 0.05], rpy(0, 90, 0) deg, 63.2 deg) }\n\
           +Tr segment 0.5 s { (Pw Ow θsw).hold }\n\
         }",
    ));
    assert_eq!(classify(&t.actions[0]), Ok(None));
    let ActionBody::Explicit(segments) = &t.actions[0].body else { panic!("explicit") };
    let patterns: Vec<Option<SegmentPattern>> =
        segments.iter().map(|s| segment_pattern(&s.primitives)).collect();
    use SegmentPattern::*;
    assert_eq!(patterns, [Some(Mixed), Some(Mixed), Some(Goal), Some(Path)]);
}

/// Decomposes a file of `examples/` with the default options.
fn decompose_example(path: &Path) -> (Robot, Task, Result<Decomposition, DecomposeError>) {
    let task = load(path).unwrap_or_else(|e| panic!("{} does not validate:\n{e}", path.display()));
    let robot = Robot::from_urdf_file(&task.robot).expect("the example's robot loads");
    let decomposition = decompose(&robot, &task, &DecomposeOptions::default());
    (robot, task, decomposition)
}

/// Every shipped example decomposes with the default options, but for a
/// file without `start` (construct_minimal.a2ml), which is valid yet has
/// nowhere to plan from.
#[test]
fn every_example_decomposes() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut paths: Vec<PathBuf> = ["examples", "examples/paper"]
        .iter()
        .flat_map(|f| std::fs::read_dir(root.join(f)).expect("examples folder"))
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "a2ml"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 20, "only {} examples", paths.len());
    let mut without_start = Vec::new();
    for path in &paths {
        let (_, task, decomposition) = decompose_example(path);
        match (&task.start, decomposition) {
            (Some(_), Ok(d)) => {
                assert_eq!(d.actions.len(), task.actions.len(), "{}", path.display())
            }
            (Some(_), Err(e)) => panic!("{} does not decompose: {e}", path.display()),
            (None, result) => {
                assert!(
                    matches!(result, Err(DecomposeError::NoStart { .. })),
                    "{}",
                    path.display()
                );
                without_start.push(path.file_name().expect("a file"));
            }
        }
    }
    assert_eq!(without_start, ["construct_minimal.a2ml"]);
}

/// §6.4 on both arms: the same seven actions in the same order, of the
/// paper's types, each pushing hand against the box it names in `contact`.
#[test]
fn push_box_examples_run_the_papers_seven_actions_on_both_arms() {
    use ActionType::*;
    for name in ["push_box_aside_coman.a2ml", "push_box_aside_centauro.a2ml"] {
        let (_, task, decomposition) = decompose_example(&common::example(name));
        let d = decomposition.unwrap_or_else(|e| panic!("{name}: {e}"));
        let names: Vec<&str> = d.actions.iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, PAPER_ORDER, "{name}");
        let types: Vec<ActionType> = d
            .actions
            .iter()
            .map(|a| a.classification.as_ref().expect("constraints").action_type)
            .collect();
        assert_eq!(types, [III, IV, V, II, I, V, I], "{name}");
        let contact = |action: &str| -> Vec<String> {
            task.actions.iter().find(|a| a.name == action).expect("action").contact.clone()
        };
        assert_eq!(contact("move_b"), ["box_b"], "{name}");
        assert_eq!(contact("approach_a"), ["box_a", "box_b"], "{name}");
        assert_eq!(contact("push_a"), ["box_a", "box_b"], "{name}");
    }
}

/// An obstacle at the goal: Opt1 finds no end state clear of it, unless
/// the action names it in `contact`.
#[test]
fn contact_lets_an_action_reach_into_an_obstacle() {
    let text = |contact: &str| {
        file(&format!(
            "action touch {{\n{contact}\n\
             goal Pw = [0.2, -0.1, -0.2] > Os = axes(r: [0, 0, -1], l: [0, 1, 0])\n}}"
        ))
        .replace("task t", "scene { ball = sphere at [0.2, -0.1, -0.2] radius 0.05 }\ntask t")
    };
    let robot = Robot::from_urdf_file(common::robot_path("coman_right_arm")).expect("robot");
    let options = DecomposeOptions::default();
    let blocked = decompose(&robot, &task(&text("")), &options);
    assert!(matches!(blocked, Err(DecomposeError::Unreachable { .. })), "{blocked:?}");
    let touching = decompose(&robot, &task(&text("contact { ball }")), &options);
    let d = touching.unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(d.actions[0].classification.as_ref().map(|c| c.action_type), Some(ActionType::III));
}

/// Opt2 of a hard path sizes it as far as the arm allows, which ends on a
/// joint limit; the end state keeps `OptOptions::limit_margin` from it.
#[test]
fn opt_end_states_keep_the_limit_margin() {
    let path = common::example("push_box_aside_coman.a2ml");
    let (robot, task, _) = decompose_example(&path);
    let end_of_retract = |margin: f64| {
        let mut options = DecomposeOptions::default();
        options.opt.limit_margin = margin;
        let d = decompose(&robot, &task, &options).expect("decomposes");
        let retract = d.actions.iter().find(|a| a.name == "retract").expect("retract");
        assert_eq!(retract.optimisations[0].solver, "Opt2");
        retract.segments[0].end
    };
    let room = |q: &a2ml::math::JointVector| {
        (0..q.len())
            .map(|i| {
                let l = &robot.joints[i].limits;
                (q[i] - l.lower).min(l.upper - q[i])
            })
            .fold(f64::INFINITY, f64::min)
    };
    assert!(room(&end_of_retract(0.0)) < 1e-6, "without a margin the optimum is on a limit");
    let default = DecomposeOptions::default().opt.limit_margin;
    assert!(default > 0.0);
    assert!(room(&end_of_retract(default)) >= default - 1e-9);
}

/// `solver MSk ..` reaches the decomposed segments: type III decomposes
/// into MS1 and MS2, each carrying its own solver (the action's for the one
/// not named), and naming MS3 is refused with the entry's place.
#[test]
fn a_solver_per_segment_reaches_the_segments() {
    let robot = common::load("coman_right_arm");
    let action = |solver: &str| {
        file(&format!(
            "  action a {{\n    goal Pw Ow = ([0.27, -0.1, 0.05], axes(f: [1, 0, 0], p: [0, 1, 0]))\n      \
             > Os = axes(r: [0.707, -0.707, 0], l: [0, 0, -1])\n    {solver}\n  }}"
        ))
    };
    let text = action("solver rrt, MS2 qp");
    let decomposition =
        decompose(&robot, &task(&text), &DecomposeOptions::default()).expect("type III decomposes");
    let solvers: Vec<&str> =
        decomposition.actions[0].segments.iter().map(|s| s.solver.name()).collect();
    assert_eq!(solvers, ["rrt", "qp"]);

    let text = action("solver MS1 qp, MS3 rrt");
    match decompose(&robot, &task(&text), &DecomposeOptions::default()) {
        Err(error @ DecomposeError::NoSuchSegment { segment: 2, count: 2, span, .. }) => {
            assert_eq!(&text[span.start..span.end], "MS3 rrt");
            assert!(error.to_string().contains("`solver MS3` names no segment"), "{error}");
        }
        other => panic!("expected NoSuchSegment, got {other:?}"),
    }
}
