use a2ml::Robot;
use a2ml::kinematics::{ArmPose, arm_pose, cpsa_jacobian, hat_jacobian};
use a2ml::math::{JointVector, Real, Vector3};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

pub const ROBOTS: [&str; 5] =
    ["coman_right_arm", "centauro_right_arm", "iiwa14", "panda", "human_arm"];

pub fn robot_path(name: &str) -> String {
    format!("{}/robots/{name}.urdf", env!("CARGO_MANIFEST_DIR"))
}

pub fn load(name: &str) -> Robot {
    Robot::from_urdf_file(robot_path(name)).expect("robot loads")
}

/// VAMP's 59-sphere Panda (tests/data/panda_spheres), the MotionBenchMaker comparison's model.
pub fn sphere_panda() -> Robot {
    let path =
        format!("{}/tests/data/panda_spheres/panda_spheres.urdf", env!("CARGO_MANIFEST_DIR"));
    Robot::from_urdf_file(path).expect("the sphere Panda loads")
}

pub fn all_robots() -> Vec<(&'static str, Robot)> {
    ROBOTS.iter().map(|n| (*n, load(n))).collect()
}

pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

pub fn random_q(robot: &Robot, rng: &mut StdRng) -> JointVector {
    JointVector::from_fn(|i, _| {
        let l = robot.joints[i].limits;
        rng.random_range(l.lower..l.upper)
    })
}

/// Distance from the two representation singularities: the straight arm
/// (sin of the elbow angle) and the wrist on the vertical through S.
pub fn regularity(robot: &Robot, pose: &ArmPose) -> Real {
    let r = (pose.elbow - pose.shoulder).normalize();
    let u = (pose.wrist - pose.elbow).normalize();
    let pw = pose.wrist - pose.shoulder;
    let vertical: Vector3 = robot.vertical;
    u.cross(&r).norm().min(vertical.cross(&pw.normalize()).norm())
}

/// A random in-limit configuration at least `margin` away from the
/// representation singularities, where neither task Jacobian is nearly
/// singular (smallest singular value above 1e-3).
pub fn regular_q(robot: &Robot, rng: &mut StdRng, margin: Real) -> (JointVector, ArmPose) {
    loop {
        let q = random_q(robot, rng);
        let pose = arm_pose(robot, &q);
        if regularity(robot, &pose) <= margin {
            continue;
        }
        let conditioned = |j: Result<a2ml::math::Matrix7, _>| {
            j.map(|j| j.singular_values().min() > 1e-3).unwrap_or(false)
        };
        if conditioned(cpsa_jacobian(robot, &pose)) && conditioned(hat_jacobian(&pose)) {
            return (q, pose);
        }
    }
}

/// A second configuration within `spread` of `q` per joint, inside the limits.
pub fn nearby(robot: &Robot, q: &JointVector, rng: &mut StdRng, spread: Real) -> JointVector {
    JointVector::from_fn(|i, _| {
        let l = robot.joints[i].limits;
        (q[i] + rng.random_range(-spread..spread)).clamp(l.lower + 1e-3, l.upper - 1e-3)
    })
}

/// A file of the shipped examples/ folder.
pub fn example(file: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples").join(file)
}

/// No joint outside its position range or speed limit at any sample.
pub fn assert_within_limits(robot: &Robot, t: &a2ml::trajectory::Trajectory) {
    let violations = a2ml::trajectory::check_limits(t, robot, 0.0);
    assert!(
        violations.is_empty(),
        "{} limit violations, first {:?}",
        violations.len(),
        violations.first()
    );
}
