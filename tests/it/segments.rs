//! The seven action types decomposed on COMAN and Centauro: the segment
//! structure of paper fig. 3 and eq. 12, and goals consistent with the
//! constraints (docs/design.md §4). Tasks are written from real configurations
//! so that their goals are reachable.

use crate::common::{load, nearby, regular_q, rng, robot_path};
use a2ml::Robot;
use a2ml::decompose::{
    ActionType, ArmState, DecomposeOptions, Decomposition, SegmentPattern, decompose, goal_error,
};
use a2ml::language::{PrimitiveConstraint, Space, Target, Variable, parse};
use a2ml::math::{JointVector, UnitQuaternion, Vector3, rotation_about};

const ARMS: [&str; 2] = ["coman_right_arm", "centauro_right_arm"];

fn vector(v: &Vector3) -> String {
    format!("[{}, {}, {}]", v.x, v.y, v.z)
}

fn quat(r: &a2ml::math::Rotation3) -> String {
    let q = UnitQuaternion::from_rotation_matrix(r);
    format!("quat({}, {}, {}, {})", q.w, q.i, q.j, q.k)
}

fn state(robot: &Robot, q: &JointVector) -> ArmState {
    ArmState::at(robot, q).expect("regular")
}

/// Decomposes one action written with `body` from start `q0`.
fn plan(
    name: &str,
    q0: &JointVector,
    body: &str,
) -> Result<Decomposition, a2ml::decompose::DecomposeError> {
    let start: Vec<String> = q0.iter().map(|v| v.to_string()).collect();
    let text = format!(
        "robot \"{}\"\nstart [{}]\ntask t {{\n  action a {{\n    {body}\n  }}\n}}\n",
        robot_path(name),
        start.join(", ")
    );
    let task = parse(&text, None).unwrap_or_else(|e| panic!("{e}\n{text}"));
    decompose(&load(name), &task, &DecomposeOptions::default())
}

/// Runs `case` on random start/goal pairs until `wanted` decompositions
/// succeed; a pair whose goals the arm cannot reach within its limits may be
/// refused, but not most of them.
fn cases(
    name: &str,
    seed: u64,
    wanted: usize,
    mut case: impl FnMut(&Robot, JointVector, JointVector) -> bool,
) {
    let robot = load(name);
    let mut rng = rng(seed);
    let (mut ok, mut tries) = (0, 0);
    while ok < wanted {
        tries += 1;
        assert!(tries <= 12 * wanted, "{name}: only {ok} of {tries} cases decomposed");
        let (q0, _) = regular_q(&robot, &mut rng, 0.15);
        let q1 = nearby(&robot, &q0, &mut rng, 0.35);
        if a2ml::kinematics::hat_state(&a2ml::kinematics::arm_pose(&robot, &q1)).is_err() {
            continue;
        }
        if case(&robot, q0, q1) {
            ok += 1;
        }
    }
}

fn spaces(d: &Decomposition) -> Vec<Space> {
    d.actions[0].segments.iter().map(|s| s.space).collect()
}

fn action_type(d: &Decomposition) -> ActionType {
    d.actions[0].classification.expect("constraint action").action_type
}

#[test]
fn type_i_keeps_the_path_and_holds_the_rest() {
    for name in ARMS {
        cases(name, 40, 3, |robot, q0, _| {
            let s0 = state(robot, &q0);
            let d = Vector3::new(0.3, -0.5, 0.8).normalize();
            let Ok(plan) =
                plan(name, &q0, &format!("path Pw line {} 0.03 m, Ow θsw hold", vector(&d)))
            else {
                return false;
            };
            assert_eq!(action_type(&plan), ActionType::I);
            assert_eq!(spaces(&plan), [Space::Cpsa]);
            let seg = &plan.actions[0].segments[0];
            assert_eq!(seg.pattern, SegmentPattern::Path);
            if !seg.relaxed.is_empty() {
                return false;
            }
            let end = state(robot, &seg.end);
            assert!((end.cpsa.pw - (s0.cpsa.pw + d * 0.03)).norm() < 1e-9, "{name}");
            assert!(
                goal_error(
                    &end,
                    &[
                        (Variable::Ow, Target::Rotation(s0.cpsa.ow)),
                        (Variable::Swivel, Target::Angle(s0.cpsa.swivel))
                    ]
                ) < 1e-9
            );
            true
        });
    }
}

#[test]
fn type_ii_reaches_its_goal_in_one_segment() {
    for name in ARMS {
        cases(name, 41, 3, |robot, q0, q1| {
            let g = state(robot, &q1);
            let Ok(plan) = plan(
                name,
                &q0,
                &format!("goal Pw Ow = ({}, {})", vector(&g.cpsa.pw), quat(&g.cpsa.ow)),
            ) else {
                return false;
            };
            assert_eq!(action_type(&plan), ActionType::II);
            assert_eq!(spaces(&plan), [Space::Cpsa]);
            let seg = &plan.actions[0].segments[0];
            assert!(matches!(seg.primitives[0].constraint, PrimitiveConstraint::Goal(_)));
            let goals = [
                (Variable::Pw, Target::Position(g.cpsa.pw)),
                (Variable::Ow, Target::Rotation(g.cpsa.ow)),
            ];
            assert!(goal_error(&state(robot, &seg.end), &goals) < 1e-9, "{name}");
            true
        });
    }
}

#[test]
fn type_iii_second_segment_keeps_g1_and_improves_g2() {
    for name in ARMS {
        cases(name, 42, 3, |robot, q0, q1| {
            let g = state(robot, &q1);
            // G2 turned off what G1 allows, so that the two conflict.
            let os =
                a2ml::math::Rotation3::from_matrix_unchecked(rotation_about(&Vector3::z(), 0.3))
                    * g.hat.shoulder_frame;
            let body = format!(
                "goal Pw Ow = ({}, {}) > Os = {}",
                vector(&g.cpsa.pw),
                quat(&g.cpsa.ow),
                quat(&os)
            );
            let Ok(plan) = plan(name, &q0, &body) else { return false };
            assert_eq!(action_type(&plan), ActionType::III);
            assert_eq!(spaces(&plan), [Space::Cpsa, Space::Cpsa]);
            let segs = &plan.actions[0].segments;
            let g1 = [
                (Variable::Pw, Target::Position(g.cpsa.pw)),
                (Variable::Ow, Target::Rotation(g.cpsa.ow)),
            ];
            let g2 = [(Variable::Os, Target::Rotation(os))];
            let (ms1, ms2) = (state(robot, &segs[0].end), state(robot, &segs[1].end));
            assert!(goal_error(&ms1, &g1) < 1e-9 && goal_error(&ms2, &g1) < 1e-9, "{name}: G1");
            assert!(
                goal_error(&ms2, &g2) <= goal_error(&ms1, &g2) + 1e-9,
                "{name}: G2 not improved"
            );
            assert_eq!(plan.actions[0].optimisations[0].solver, "Opt1");
            true
        });
    }
}

/// A hard or soft wrist line towards a HAT goal: types IV and V.
fn line_to_hat_goal(
    robot: &Robot,
    q0: JointVector,
    q1: JointVector,
    name: &str,
    hardness: &str,
) -> Option<(Decomposition, ArmState, Vector3)> {
    let (s0, g) = (state(robot, &q0), state(robot, &q1));
    let d = (g.cpsa.pw - s0.cpsa.pw).try_normalize(1e-6)?;
    let body = format!(
        "goal Os Ow = ({}, {})\n    path Pw line {} : {hardness}",
        quat(&g.hat.shoulder_frame),
        quat(&g.hat.ow),
        vector(&d)
    );
    plan(name, &q0, &body).ok().map(|p| (p, s0, d))
}

#[test]
fn type_iv_reproduces_its_goal_within_the_reported_residual() {
    for name in ARMS {
        cases(name, 43, 3, |robot, q0, q1| {
            let Some((plan, s0, d)) = line_to_hat_goal(robot, q0, q1, name, "hard") else {
                return false;
            };
            let g = state(robot, &q1);
            assert_eq!(action_type(&plan), ActionType::IV);
            assert_eq!(spaces(&plan), [Space::Cpsa]);
            let seg = &plan.actions[0].segments[0];
            assert_eq!(seg.pattern, SegmentPattern::Mixed);
            let report = &plan.actions[0].optimisations[0];
            assert_eq!(report.solver, "Opt2");
            let end = state(robot, &seg.end);
            assert!((end.cpsa.pw - s0.cpsa.pw).cross(&d).norm() < 1e-9, "{name}: end off the line");
            assert!(((end.cpsa.pw - s0.cpsa.pw).dot(&d) - report.sizes[0]).abs() < 1e-9);
            let goals = [
                (Variable::Os, Target::Rotation(g.hat.shoulder_frame)),
                (Variable::Ow, Target::Rotation(g.hat.ow)),
            ];
            assert!(
                goal_error(&end, &goals) <= report.residual + 1e-9,
                "{name}: error {} > residual {}",
                goal_error(&end, &goals),
                report.residual
            );
            true
        });
    }
}

#[test]
fn type_v_gives_way_to_its_goal_in_a_second_segment() {
    for name in ARMS {
        cases(name, 44, 3, |robot, q0, q1| {
            let Some((plan, _, _)) = line_to_hat_goal(robot, q0, q1, name, "soft") else {
                return false;
            };
            let g = state(robot, &q1);
            assert_eq!(action_type(&plan), ActionType::V);
            assert_eq!(spaces(&plan), [Space::Cpsa, Space::Hat]);
            let goals = [
                (Variable::Os, Target::Rotation(g.hat.shoulder_frame)),
                (Variable::Ow, Target::Rotation(g.hat.ow)),
            ];
            let end = state(robot, &plan.actions[0].segments[1].end);
            assert!(goal_error(&end, &goals) < 1e-9, "{name}: MS2 misses G1");
            true
        });
    }
}

/// Eq. 12's setting: G1 = (Pw, Ow) ≻ G2 = Os with the shoulder turning
/// about r; `hard` gives type VI, `soft` type VII.
fn about_r(
    robot: &Robot,
    q0: JointVector,
    q1: JointVector,
    name: &str,
    hardness: &str,
) -> Option<(Decomposition, ArmState)> {
    let g = state(robot, &q1);
    // A hard path may not share a variable with a goal: there G2 is θe.
    let g2 = if hardness == "hard" {
        format!("θe = {}", g.hat.elbow_angle)
    } else {
        format!("Os = {}", quat(&g.hat.shoulder_frame))
    };
    let body = format!(
        "goal Pw Ow = ({}, {}) > {g2}\n    path Os about r : {hardness}",
        vector(&g.cpsa.pw),
        quat(&g.cpsa.ow),
    );
    plan(name, &q0, &body).ok().map(|p| (p, g))
}

#[test]
fn type_vi_is_one_path_segment_towards_the_opt1_configuration() {
    for name in ARMS {
        cases(name, 45, 3, |robot, q0, q1| {
            let Some((plan, _)) = about_r(robot, q0, q1, name, "hard") else { return false };
            assert_eq!(action_type(&plan), ActionType::VI);
            assert_eq!(spaces(&plan), [Space::Hat]);
            let a = &plan.actions[0];
            assert_eq!(
                a.optimisations.iter().map(|o| o.solver).collect::<Vec<_>>(),
                ["Opt1", "Opt2"]
            );
            // Os only turned about the upper arm's start direction.
            let (s0, end) = (state(robot, &q0), state(robot, &a.segments[0].end));
            let r0: Vector3 = s0.hat.shoulder_frame.matrix().column(0).into();
            let turned =
                rotation_about(&r0, a.optimisations[1].sizes[0]) * s0.hat.shoulder_frame.matrix();
            assert!((turned - end.hat.shoulder_frame.matrix()).amax() < 1e-9, "{name}");
            true
        });
    }
}

#[test]
fn type_vii_follows_eq_12() {
    for name in ARMS {
        cases(name, 46, 3, |robot, q0, q1| {
            let Some((plan, g)) = about_r(robot, q0, q1, name, "soft") else { return false };
            assert_eq!(action_type(&plan), ActionType::VII);
            // MS1 in HAT (Os about r), MS2 and MS3 in CPSA.
            assert_eq!(spaces(&plan), [Space::Hat, Space::Cpsa, Space::Cpsa]);
            let segs = &plan.actions[0].segments;
            assert!(segs[0].primitives.iter().any(|p| p.variables == [Variable::Os]
                && matches!(p.constraint, PrimitiveConstraint::Path(_))));
            let g1 = [
                (Variable::Pw, Target::Position(g.cpsa.pw)),
                (Variable::Ow, Target::Rotation(g.cpsa.ow)),
            ];
            let (ms2, ms3) = (state(robot, &segs[1].end), state(robot, &segs[2].end));
            assert!(goal_error(&ms2, &g1) < 1e-9 && goal_error(&ms3, &g1) < 1e-9, "{name}: G1");
            // MS3 sends θsw to Opt1's G4 (eq. 13), which serves G2 at least as well.
            let g2 = [(Variable::Os, Target::Rotation(g.hat.shoulder_frame))];
            assert!(goal_error(&ms3, &g2) <= goal_error(&ms2, &g2) + 1e-6, "{name}: G2");
            true
        });
    }
}

/// `settings { frame root }` positions are the {b} ones plus the shoulder
/// centre: both tasks decompose to the same configurations.
#[test]
fn root_frame_tasks_decompose_like_base_frame_ones() {
    for name in ARMS {
        let robot = load(name);
        let mut rng = rng(47);
        let (q0, _) = regular_q(&robot, &mut rng, 0.15);
        let q1 = nearby(&robot, &q0, &mut rng, 0.3);
        let g = state(&robot, &q1);
        let s = robot.structure.shoulder_in_base_link;
        let start: Vec<String> = q0.iter().map(|v| v.to_string()).collect();
        let text = |frame: &str, pw: Vector3, ball: Vector3| {
            format!(
                "robot \"{}\"\nstart [{}]\nscene {{ ball = sphere at {} radius 0.01 }}\n\
                 settings {{ frame {frame} }}\ntask t {{ action a {{ goal Pw Ow = ({}, {}) }} }}\n",
                robot_path(name),
                start.join(", "),
                vector(&ball),
                vector(&pw),
                quat(&g.cpsa.ow)
            )
        };
        let ball = Vector3::new(0.5, 0.5, 0.5);
        let base = parse(&text("base", g.cpsa.pw, ball), None).expect("valid");
        let root = parse(&text("root", g.cpsa.pw + s, ball + s), None).expect("valid");
        let options = DecomposeOptions::default();
        let (a, b) = (decompose(&robot, &base, &options), decompose(&robot, &root, &options));
        let (Ok(a), Ok(b)) = (a, b) else { panic!("{name}: both should decompose") };
        for (x, y) in a.actions[0].segments.iter().zip(&b.actions[0].segments) {
            assert!((x.end - y.end).amax() < 1e-9, "{name}");
        }
    }
}
