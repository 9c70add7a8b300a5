//! Every Jacobian against central finite differences of its state function,
//! and the SRS closed forms of paper eq. 8 and appendix B.

use crate::common::{all_robots, load, regular_q, rng};
use a2ml::Robot;
use a2ml::kinematics::*;
use a2ml::math::{JointVector, Matrix7, Real, Rotation3, Vector3, rotation_log, wrap_angle};

const STEP: Real = 1e-6;
const TOL: Real = 1e-6;
const SAMPLES: usize = 1000;

/// Central difference of a rotation-valued function: the angular velocity in {b}.
fn omega(plus: &Rotation3, minus: &Rotation3) -> Vector3 {
    rotation_log(&(plus * minus.inverse())) / (2.0 * STEP)
}

fn perturbed(q: &JointVector, i: usize) -> (JointVector, JointVector) {
    let (mut p, mut m) = (*q, *q);
    p[i] += STEP;
    m[i] -= STEP;
    (p, m)
}

fn assert_close(name: &str, what: &str, analytic: &[Real], numeric: &[Real]) {
    for (k, (a, n)) in analytic.iter().zip(numeric).enumerate() {
        assert!(
            (a - n).abs() < TOL,
            "{name}: {what} entry {k}: analytic {a} vs finite difference {n}"
        );
    }
}

#[test]
fn geometric_and_point_jacobians_match_finite_differences() {
    for (name, robot) in all_robots() {
        let mut rng = rng(1);
        let tool_point = Vector3::new(0.03, -0.02, 0.1);
        for _ in 0..SAMPLES {
            let (q, pose) = regular_q(&robot, &mut rng, 0.05);
            let jge = geometric_jacobian(&pose);
            let je = point_jacobian(&pose, 3, &pose.elbow);
            let tool = pose.frames[7].transform_point(&tool_point.into()).coords;
            let jt = point_jacobian(&pose, 7, &tool);
            for i in 0..7 {
                let (p, m) = perturbed(&q, i);
                let (pp, pm) = (arm_pose(&robot, &p), arm_pose(&robot, &m));
                let dw = (pp.wrist - pm.wrist) / (2.0 * STEP);
                let dh = omega(&pp.hand, &pm.hand);
                let de = (pp.elbow - pm.elbow) / (2.0 * STEP);
                let tp = pp.frames[7].transform_point(&tool_point.into()).coords;
                let tm = pm.frames[7].transform_point(&tool_point.into()).coords;
                let dt = (tp - tm) / (2.0 * STEP);
                assert_close(
                    name,
                    "J_ge linear",
                    jge.fixed_view::<3, 1>(0, i).as_slice(),
                    dw.as_slice(),
                );
                assert_close(
                    name,
                    "J_ge angular",
                    jge.fixed_view::<3, 1>(3, i).as_slice(),
                    dh.as_slice(),
                );
                assert_close(name, "J_E", je.column(i).as_slice(), de.as_slice());
                assert_close(name, "J_tool", jt.column(i).as_slice(), dt.as_slice());
            }
        }
    }
}

#[test]
fn cpsa_jacobian_matches_finite_differences() {
    for (name, robot) in all_robots() {
        let mut rng = rng(2);
        for _ in 0..SAMPLES {
            let (q, pose) = regular_q(&robot, &mut rng, 0.05);
            let j = cpsa_jacobian(&robot, &pose).expect("regular");
            for i in 0..7 {
                let (p, m) = perturbed(&q, i);
                let sp = cpsa_state(&robot, &arm_pose(&robot, &p)).expect("regular");
                let sm = cpsa_state(&robot, &arm_pose(&robot, &m)).expect("regular");
                let dpw = (sp.pw - sm.pw) / (2.0 * STEP);
                let dow = omega(&sp.ow, &sm.ow);
                let dsw = wrap_angle(sp.swivel - sm.swivel) / (2.0 * STEP);
                let numeric = [dpw.x, dpw.y, dpw.z, dow.x, dow.y, dow.z, dsw];
                assert_close(name, "J_cs", j.column(i).as_slice(), &numeric);
            }
        }
    }
}

#[test]
fn hat_jacobian_matches_finite_differences() {
    for (name, robot) in all_robots() {
        let mut rng = rng(3);
        for _ in 0..SAMPLES {
            let (q, pose) = regular_q(&robot, &mut rng, 0.05);
            let j = hat_jacobian(&pose).expect("regular");
            for i in 0..7 {
                let (p, m) = perturbed(&q, i);
                let sp = hat_state(&arm_pose(&robot, &p)).expect("regular");
                let sm = hat_state(&arm_pose(&robot, &m)).expect("regular");
                let dos = omega(&sp.shoulder_frame, &sm.shoulder_frame);
                let de = (sp.elbow_angle - sm.elbow_angle) / (2.0 * STEP);
                let dow = omega(&sp.ow, &sm.ow);
                let numeric = [dos.x, dos.y, dos.z, de, dow.x, dow.y, dow.z];
                assert_close(name, "J_tr", j.column(i).as_slice(), &numeric);
            }
        }
    }
}

/// Paper eq. 8: J_tr of an SRS arm from blocks of J_ge.
fn eq8(robot: &Robot, pose: &ArmPose) -> Matrix7 {
    let jge = geometric_jacobian(pose);
    let hat = hat_state(pose).expect("regular");
    let l: Vector3 = hat.shoulder_frame.matrix().column(1).into();
    let mut j = Matrix7::zeros();
    j.fixed_view_mut::<3, 3>(0, 0).copy_from(&jge.fixed_view::<3, 3>(3, 0));
    j[(3, 3)] = l.dot(&pose.axes[3]);
    j.fixed_view_mut::<3, 7>(4, 0).copy_from(&jge.fixed_view::<3, 7>(3, 0));
    let _ = robot;
    j
}

/// Paper appendix B (B.4): the derivative of the unsigned swivel angle
/// arccos(n·l); the signed angle's derivative carries the sign of θsw.
fn appendix_b(robot: &Robot, pose: &ArmPose) -> [Real; 7] {
    let jge = geometric_jacobian(pose);
    let pw = pose.wrist;
    let z = robot.vertical;
    let n = pw.cross(&(-z)).normalize();
    let hat = hat_state(pose).expect("regular");
    let l: Vector3 = hat.shoulder_frame.matrix().column(1).into();
    let rho = (pw.x * pw.x + pw.y * pw.y).sqrt();
    let scale = -1.0 / (1.0 - n.dot(&l).powi(2)).sqrt();
    std::array::from_fn(|i| {
        let jw: Vector3 = jge.fixed_view::<3, 1>(0, i).into();
        let js: Vector3 =
            if i < 3 { jge.fixed_view::<3, 1>(3, i).into() } else { Vector3::zeros() };
        scale * ((jw.dot(&n) / rho) * z.cross(&n).dot(&l) + n.dot(&js.cross(&l)))
    })
}

#[test]
fn srs_jacobians_equal_the_paper_closed_forms() {
    let robot = load("iiwa14");
    let mut rng = rng(4);
    let mut checked = 0;
    while checked < SAMPLES {
        let (_, pose) = regular_q(&robot, &mut rng, 0.05);
        let cpsa = cpsa_state(&robot, &pose).expect("regular");
        if cpsa.swivel.abs() < 0.1 || cpsa.swivel.abs() > std::f64::consts::PI - 0.1 {
            continue;
        }
        let jtr = hat_jacobian(&pose).expect("regular");
        assert!((jtr - eq8(&robot, &pose)).amax() < 1e-9, "J_tr differs from eq. 8");
        let jcs = cpsa_jacobian(&robot, &pose).expect("regular");
        let b = appendix_b(&robot, &pose);
        for i in 0..7 {
            let ours = jcs[(6, i)];
            assert!(
                (ours - cpsa.swivel.signum() * b[i]).abs() < 1e-9,
                "J_sw col {i}: {ours} vs {}",
                b[i]
            );
        }
        checked += 1;
    }
}
