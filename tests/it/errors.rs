//! Every typed error, provoked.

use crate::common::{load, robot_path};
use a2ml::Robot;
use a2ml::kinematics::*;
use a2ml::math::{Rotation3, Vector3};
use a2ml::robot::{RobotError, RobotOptions};

#[test]
fn unreachable_wrist() {
    let robot = load("iiwa14");
    let target =
        CpsaState { pw: Vector3::new(1.0, 0.2, 0.1), ow: Rotation3::identity(), swivel: 0.3 };
    match ik_cpsa(&robot, &target, None) {
        Err(KinematicsError::Unreachable { distance, max, .. }) => {
            assert!(distance > max && (max - 0.82).abs() < 1e-9);
        }
        other => panic!("expected Unreachable, got {other:?}"),
    }
    let too_close = CpsaState { pw: Vector3::new(0.01, 0.0, 0.0), ..target };
    assert!(matches!(ik_cpsa(&robot, &too_close, None), Err(KinematicsError::Unreachable { .. })));
}

#[test]
fn straight_arm_is_singular() {
    // The iiwa's zero configuration is the straight arm pointing up... and
    // so also has the wrist above the shoulder; the arm-plane check comes first.
    let robot = load("iiwa14");
    let mut q = a2ml::JointVector::zeros();
    q[1] = 0.7; // tilt the straight arm off the vertical
    let pose = arm_pose(&robot, &q);
    assert_eq!(cpsa_state(&robot, &pose), Err(KinematicsError::Singular(Singularity::StraightArm)));
    assert_eq!(
        hat_jacobian(&pose).err(),
        Some(KinematicsError::Singular(Singularity::StraightArm))
    );
    // A HAT target with a straight elbow has no unique shoulder rotation.
    let target = HatState {
        shoulder_frame: Rotation3::identity(),
        elbow_angle: std::f64::consts::PI,
        ow: Rotation3::identity(),
    };
    assert_eq!(
        ik_hat(&robot, &target, None),
        Err(KinematicsError::Singular(Singularity::StraightArm))
    );
}

#[test]
fn wrist_above_shoulder_is_singular() {
    let robot = load("iiwa14");
    let target =
        CpsaState { pw: Vector3::new(0.0, 0.0, 0.6), ow: Rotation3::identity(), swivel: 0.0 };
    assert_eq!(
        ik_cpsa(&robot, &target, None),
        Err(KinematicsError::Singular(Singularity::WristAboveShoulder))
    );
    assert_eq!(
        swivel_intervals(&robot, &target.pw, &target.ow),
        Err(KinematicsError::Singular(Singularity::WristAboveShoulder))
    );
}

#[test]
fn targets_outside_the_limits_name_the_joint() {
    let robot = load("coman_right_arm");
    // Elbow fully bent beyond COMAN's 135 deg flexion: |Pw| just above |lu - lf|.
    let lu = robot.upper_arm_length();
    let lf = robot.forearm_length();
    let target = CpsaState {
        pw: Vector3::new(0.2, -0.3, -0.1).normalize() * ((lu - lf).abs() + 0.01),
        ow: Rotation3::identity(),
        swivel: 0.0,
    };
    match ik_cpsa(&robot, &target, None) {
        Err(KinematicsError::JointOutOfLimits { joint, excess, .. }) => {
            assert!(excess > 0.0);
            assert!(robot.joint_names().contains(&joint.as_str()));
        }
        other => panic!("expected JointOutOfLimits, got {other:?}"),
    }
}

#[test]
fn non_finite_targets_are_rejected() {
    let robot = load("iiwa14");
    let target =
        CpsaState { pw: Vector3::new(f64::NAN, 0.0, 0.3), ow: Rotation3::identity(), swivel: 0.0 };
    assert!(matches!(ik_cpsa(&robot, &target, None), Err(KinematicsError::NonFinite { .. })));
}

#[test]
fn newton_arms_have_no_closed_form_swivel() {
    let robot = load("human_arm");
    let pose = arm_pose(&robot, &robot.middle());
    let cpsa = cpsa_state(&robot, &pose).expect("regular");
    assert!(matches!(
        swivel_intervals(&robot, &cpsa.pw, &cpsa.ow),
        Err(KinematicsError::NotAnalytic { .. })
    ));
}

#[test]
fn missing_file() {
    let err = Robot::from_urdf_file("robots/no_such_arm.urdf").unwrap_err();
    assert!(matches!(err, RobotError::FileMissing { .. }));
    assert!(err.to_string().contains("no_such_arm.urdf"));
}

#[test]
fn broken_urdf() {
    let err =
        Robot::from_urdf_str("<robot name='x'><link name='a'></robot>", &RobotOptions::default())
            .unwrap_err();
    assert!(matches!(err, RobotError::Urdf { .. }), "{err:?}");
}

fn chain(joints: usize, extra: &str) -> String {
    let mut s = String::from("<robot name='chain'><link name='l0'/>");
    for i in 1..=joints {
        let axis = ["0 0 1", "0 1 0"][i % 2];
        s += &format!(
            "<link name='l{i}'/><joint name='j{i}' type='revolute'><parent link='l{}'/><child link='l{i}'/>\
             <origin xyz='0 0 0.1'/><axis xyz='{axis}'/><limit lower='-1' upper='1' velocity='1' effort='1'/></joint>",
            i - 1
        );
    }
    s + extra + "</robot>"
}

#[test]
fn six_joint_chain_is_not_an_arm() {
    let err = Robot::from_urdf_str(&chain(6, ""), &RobotOptions::default()).unwrap_err();
    assert!(matches!(err, RobotError::NotSevenDof { found: 6, .. }), "{err:?}");
}

#[test]
fn ambiguous_chain() {
    // A second 7-joint branch from l0.
    let mut extra = String::new();
    for i in 1..=7 {
        let parent = if i == 1 { "l0".to_owned() } else { format!("b{}", i - 1) };
        extra += &format!(
            "<link name='b{i}'/><joint name='k{i}' type='revolute'><parent link='{parent}'/><child link='b{i}'/>\
             <axis xyz='0 0 1'/><limit lower='-1' upper='1' velocity='1' effort='1'/></joint>"
        );
    }
    let err = Robot::from_urdf_str(&chain(7, &extra), &RobotOptions::default()).unwrap_err();
    assert!(matches!(err, RobotError::AmbiguousChain { .. }), "{err:?}");
    let picked = Robot::from_urdf_str(
        &chain(7, &extra),
        &RobotOptions { tip: Some("l7".into()), ..Default::default() },
    );
    // The chosen chain has parallel axes 1 and 3 through one line: not an arm, but the chain itself was selected.
    assert!(!matches!(picked, Err(RobotError::AmbiguousChain { .. })));
}

#[test]
fn joint_without_limits() {
    let text = std::fs::read_to_string(robot_path("iiwa14")).expect("shipped");
    let broken = text.replacen("velocity=", "velocityX=", 1);
    let err = Robot::from_urdf_str(&broken, &RobotOptions::default()).unwrap_err();
    assert!(
        matches!(err, RobotError::JointWithoutLimits { .. } | RobotError::Urdf { .. }),
        "{err:?}"
    );
    let zero_range = text.replacen("lower=\"-2.96", "lower=\"2.96", 1);
    let err = Robot::from_urdf_str(&zero_range, &RobotOptions::default()).unwrap_err();
    assert!(matches!(err, RobotError::JointWithoutLimits { .. }), "{err:?}");
}

#[test]
fn unknown_link_suggests_a_name() {
    let options = RobotOptions { tip: Some("hnd".into()), ..Default::default() };
    let err = Robot::from_urdf_file_with(robot_path("iiwa14"), &options).unwrap_err();
    assert_eq!(
        err,
        RobotError::UnknownLink { name: "hnd".into(), did_you_mean: Some("hand".into()) }
    );
}
