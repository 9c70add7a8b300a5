//! Opt1 and Opt2 recover constraints that a real configuration satisfies,
//! keep the fixed goals exactly, and respect the joint limits.

use crate::common::{load, nearby, regular_q, rng};
use a2ml::Robot;
use a2ml::decompose::{ArmState, OptOptions, along_path, goal_error, opt1, opt2};
use a2ml::kinematics::ik_cpsa;
use a2ml::language::{
    Axis, BodyAxis, PathConstraint, PathFeature, PathItem, Space, Target, Variable,
};
use a2ml::math::{JointVector, Vector3};
use rand::RngExt;

const ARMS: [&str; 2] = ["coman_right_arm", "centauro_right_arm"];

fn state(robot: &Robot, q: &JointVector) -> ArmState {
    ArmState::at(robot, q).expect("regular configuration")
}

fn goals(s: &ArmState, vars: &[Variable]) -> Vec<(Variable, Target)> {
    vars.iter().map(|v| (*v, s.value(*v))).collect()
}

fn assert_reaches(robot: &Robot, q: &JointVector, s: &ArmState) {
    assert!(robot.within_limits(q, 1e-9));
    let reached = state(robot, q);
    assert!(
        goal_error(&reached, &goals(s, &[Variable::Pw, Variable::Ow, Variable::Swivel])) < 1e-8
    );
}

#[test]
fn opt1_finds_the_swivel_that_matches_the_shoulder_frame() {
    // Type III, paper eq. 13: G1 = (Pw, Ow) fixed, G2 = Os through θsw.
    for name in ARMS {
        let robot = load(name);
        let mut rng = rng(30);
        for _ in 0..20 {
            let (q0, _) = regular_q(&robot, &mut rng, 0.1);
            let (q1, _) = regular_q(&robot, &mut rng, 0.1);
            let target = state(&robot, &q1);
            let g1 = goals(&target, &[Variable::Pw, Variable::Ow]);
            let g2 = goals(&target, &[Variable::Os]);
            let sol = opt1(&robot, &g1, &g2, &q0, None, &OptOptions::default()).expect("feasible");
            assert!(goal_error(&sol.state, &g1) < 1e-9, "{name}: G1 not kept");
            assert!(sol.residual < 1e-6, "{name}: G2 residual {}", sol.residual);
            assert_reaches(&robot, &sol.q, &sol.state);
        }
    }
}

#[test]
fn opt1_reduces_the_secondary_error_of_the_first_segment() {
    // MS1 ends at G1 with the start's swivel; Opt1's MS2 goal does better on G2.
    for name in ARMS {
        let robot = load(name);
        let mut rng = rng(31);
        let mut improved = 0;
        for _ in 0..20 {
            let (q0, _) = regular_q(&robot, &mut rng, 0.1);
            let q1 = nearby(&robot, &q0, &mut rng, 0.3);
            let target = state(&robot, &q1);
            let g1 = goals(&target, &[Variable::Pw, Variable::Ow]);
            // A shoulder frame no configuration holds together with G1.
            let mut os = target.hat.shoulder_frame;
            os = a2ml::math::Rotation3::new(Vector3::new(0.0, 0.0, 0.4)) * os;
            let g2 = vec![(Variable::Os, Target::Rotation(os))];
            let start = state(&robot, &q0);
            let ms1_end = a2ml::language::Target::Angle(start.cpsa.swivel);
            let Ok(sol) = opt1(&robot, &g1, &g2, &q0, None, &OptOptions::default()) else {
                continue;
            };
            assert!(goal_error(&sol.state, &g1) < 1e-9);
            // The end of MS1: G1 reached with the swivel unchanged, if reachable.
            let Target::Angle(sw) = ms1_end else { unreachable!() };
            let ms1 =
                a2ml::kinematics::CpsaState { pw: target.cpsa.pw, ow: target.cpsa.ow, swivel: sw };
            if let Ok(hat) = a2ml::kinematics::cpsa_to_hat(&robot, &ms1) {
                if ik_cpsa(&robot, &ms1, None).is_ok() {
                    let before = ArmState { cpsa: ms1, hat };
                    assert!(sol.residual <= goal_error(&before, &g2) + 1e-12);
                    improved += 1;
                }
            }
        }
        assert!(improved > 5, "{name}: only {improved} comparable cases");
    }
}

/// Opt1 is a local search from several starts, not a global one: it must
/// recover nearly every target, and keep G1 exactly whenever it answers.
#[test]
fn opt1_from_hat_finds_the_shoulder_frame_for_a_wrist_position() {
    // Paper eq. 5: G1 = (θe, Ow) fixed, G2 = Pw through Os.
    for name in ARMS {
        let robot = load(name);
        let mut rng = rng(32);
        let mut solved = 0;
        for _ in 0..20 {
            let (q0, _) = regular_q(&robot, &mut rng, 0.1);
            let q1 = nearby(&robot, &q0, &mut rng, 0.5);
            let target = state(&robot, &q1);
            let g1 = goals(&target, &[Variable::Elbow, Variable::Ow]);
            let g2 = goals(&target, &[Variable::Pw]);
            let Ok(sol) = opt1(&robot, &g1, &g2, &q0, None, &OptOptions::default()) else {
                continue;
            };
            assert!(goal_error(&sol.state, &g1) < 1e-9);
            assert_reaches(&robot, &sol.q, &sol.state);
            solved += usize::from(sol.residual < 1e-6);
        }
        assert!(solved >= 18, "{name}: recovered {solved} of 20");
    }
}

#[test]
fn opt2_recovers_the_length_of_a_hard_wrist_line() {
    // Type IV, paper eq. 6: Pw along a line (length left open), goal (Os, Ow).
    for name in ARMS {
        let robot = load(name);
        let mut rng = rng(33);
        let mut solved = 0;
        for _ in 0..10 {
            let (q0, _) = regular_q(&robot, &mut rng, 0.1);
            let q1 = nearby(&robot, &q0, &mut rng, 0.25);
            let (s0, s1) = (state(&robot, &q0), state(&robot, &q1));
            let travel = s1.cpsa.pw - s0.cpsa.pw;
            let Some(direction) = travel.try_normalize(1e-6) else { continue };
            let path = PathConstraint {
                items: vec![PathItem {
                    variables: vec![Variable::Pw],
                    feature: PathFeature::Line { direction, length: None },
                }],
                space: Some(Space::Cpsa),
                hard: true,
                span: Default::default(),
            };
            let g = goals(&s1, &[Variable::Os, Variable::Ow]);
            let sol = opt2(&robot, &g, &path, &q0, None, &OptOptions::default()).expect("feasible");
            // Pw stays on the line whatever else happens.
            let off_line = (sol.state.cpsa.pw - s0.cpsa.pw).cross(&direction).norm();
            assert!(off_line < 1e-12, "{name}: end off the line by {off_line}");
            if sol.residual < 1e-6 {
                assert!(
                    (sol.sizes[0] - travel.norm()).abs() < 1e-5,
                    "{name}: S {} vs {}",
                    sol.sizes[0],
                    travel.norm()
                );
                solved += 1;
            }
        }
        assert!(solved >= 8, "{name}: recovered {solved} of 10");
    }
}

#[test]
fn opt2_recovers_a_shoulder_rotation_about_the_upper_arm() {
    // Type VII, paper eq. 14: Os about r (angle open), goal the full CPSA state.
    for name in ARMS {
        let robot = load(name);
        let mut rng = rng(34);
        let (mut solved, mut attempted) = (0, 0);
        for _ in 0..30 {
            let (q0, _) = regular_q(&robot, &mut rng, 0.1);
            let s0 = state(&robot, &q0);
            let angle = rng.random_range(0.1..0.5);
            let feature = PathFeature::About { axis: Axis::Body(BodyAxis::R, 1.0), angle: None };
            let Target::Rotation(os) = along_path(Variable::Os, &feature, angle, &s0) else {
                unreachable!()
            };
            // The goal: that shoulder frame with a nearby elbow and hand.
            let elbow = s0.hat.elbow_angle + rng.random_range(-0.1..0.1);
            let hat = a2ml::kinematics::HatState {
                shoulder_frame: os,
                elbow_angle: elbow,
                ow: s0.hat.ow,
            };
            let Ok(cpsa) = a2ml::kinematics::hat_to_cpsa(&robot, &hat) else { continue };
            if ik_cpsa(&robot, &cpsa, Some(&q0)).is_err() {
                continue;
            }
            let target = ArmState { cpsa, hat };
            let g = goals(&target, &[Variable::Pw, Variable::Ow, Variable::Swivel]);
            let path = PathConstraint {
                items: vec![PathItem { variables: vec![Variable::Os], feature }],
                space: Some(Space::Hat),
                hard: false,
                span: Default::default(),
            };
            // A reachable target: Opt2 must find it.
            attempted += 1;
            let sol = opt2(&robot, &g, &path, &q0, None, &OptOptions::default())
                .expect("reachable target");
            if sol.residual < 1e-6 {
                assert!(
                    (sol.sizes[0] - angle).abs() < 1e-5,
                    "{name}: angle {} vs {angle}",
                    sol.sizes[0]
                );
                solved += 1;
            }
        }
        assert!(attempted >= 5, "{name}: only {attempted} reachable targets");
        assert_eq!(solved, attempted, "{name}: recovered {solved} of {attempted}");
    }
}

#[test]
fn opt_is_deterministic() {
    let robot = load("coman_right_arm");
    let mut rng = rng(35);
    let (q0, _) = regular_q(&robot, &mut rng, 0.1);
    let (q1, _) = regular_q(&robot, &mut rng, 0.1);
    let target = state(&robot, &q1);
    let g1 = goals(&target, &[Variable::Pw, Variable::Ow]);
    let g2 = goals(&target, &[Variable::Os]);
    let a = opt1(&robot, &g1, &g2, &q0, None, &OptOptions::default()).expect("feasible");
    let b = opt1(&robot, &g1, &g2, &q0, None, &OptOptions::default()).expect("feasible");
    assert_eq!(a.q, b.q);
    assert_eq!(a.residual, b.residual);
}

/// Opt1 keeps the clearance: a sphere placed on the elbow of the
/// unobstructed answer pushes the answer elsewhere on G1's swivel circle.
#[test]
fn opt1_keeps_clear_of_obstacles() {
    use a2ml::collision::{CollisionScene, min_distance};
    use a2ml::language::{Obstacle, Shape};
    for name in ARMS {
        let robot = load(name);
        let mut rng = rng(36);
        let mut moved = 0;
        for _ in 0..10 {
            let (q0, _) = regular_q(&robot, &mut rng, 0.1);
            let (q1, _) = regular_q(&robot, &mut rng, 0.1);
            let target = state(&robot, &q1);
            let g1 = goals(&target, &[Variable::Pw, Variable::Ow]);
            let g2 = goals(&target, &[Variable::Os]);
            let free = opt1(&robot, &g1, &g2, &q0, None, &OptOptions::default()).expect("feasible");
            let elbow = a2ml::kinematics::arm_pose(&robot, &free.q).elbow;
            let scene = CollisionScene::new(&[Obstacle {
                name: "ball".into(),
                shape: Shape::Sphere { center: elbow, radius: 0.03 },
            }]);
            let options = OptOptions::default();
            let Ok(sol) = opt1(&robot, &g1, &g2, &q0, Some(&scene), &options) else {
                // No answer: then no swivel angle keeps G1 clear (dense re-check).
                for k in 0..720 {
                    let swivel = -std::f64::consts::PI + k as f64 * std::f64::consts::PI / 360.0;
                    let cpsa = a2ml::kinematics::CpsaState { swivel, ..target.cpsa };
                    for q in ik_cpsa(&robot, &cpsa, Some(&q0)).unwrap_or_default() {
                        let pose = a2ml::kinematics::arm_pose(&robot, &q);
                        let (d, ..) = min_distance(&robot, &pose, &scene).expect("pairs");
                        assert!(
                            d < options.clearance + 1e-3,
                            "{name}: missed a clear swivel {swivel}"
                        );
                    }
                }
                continue;
            };
            let (d, ..) = min_distance(&robot, &a2ml::kinematics::arm_pose(&robot, &sol.q), &scene)
                .expect("pairs");
            assert!(d >= options.clearance, "{name}: clearance {d}");
            assert!(goal_error(&sol.state, &g1) < 1e-9, "{name}: G1 not kept");
            assert!(sol.residual >= free.residual - 1e-12);
            moved += 1;
        }
        assert!(moved >= 3, "{name}: only {moved} cases found a clear answer");
    }
}
