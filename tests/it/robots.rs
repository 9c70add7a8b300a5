//! The shipped robot models load and have the structure of
//! robots/README.md.

use crate::common::load;
use a2ml::math::Vector3;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() < tol
}

#[test]
fn structure_matches_reference_table() {
    // name, S in the base link, lu, lf, shoulder spherical, wrist spherical, srs
    let table = [
        (
            "coman_right_arm",
            Vector3::new(-0.01498, -0.15580, 0.15771),
            0.180624,
            0.195257,
            true,
            true,
            false,
        ),
        (
            "centauro_right_arm",
            Vector3::new(0.07628, -0.22201, 0.12739),
            0.295595,
            0.251448,
            true,
            true,
            false,
        ),
        ("iiwa14", Vector3::new(0.0, 0.0, 0.36), 0.42, 0.40, true, true, true),
        ("panda", Vector3::new(0.0, 0.0, 0.333), 0.326592, 0.392762, true, false, false),
    ];
    for (name, s, lu, lf, shoulder, wrist, srs) in table {
        let r = load(name);
        let st = &r.structure;
        assert!(
            (st.shoulder_in_base_link - s).norm() < 1e-5,
            "{name}: S {:?}",
            st.shoulder_in_base_link
        );
        assert!(close(st.upper_arm_length, lu, 1e-6), "{name}: lu {}", st.upper_arm_length);
        assert!(close(st.forearm_length, lf, 1e-6), "{name}: lf {}", st.forearm_length);
        assert_eq!(
            (st.shoulder_spherical, st.wrist_spherical, st.is_srs),
            (shoulder, wrist, srs),
            "{name}"
        );
    }
}

#[test]
fn elbow_offsets_are_detected() {
    let centauro = load("centauro_right_arm");
    assert!(close(centauro.structure.elbow_offsets[0], 0.045, 1e-9));
    assert!(close(centauro.structure.elbow_offsets[1], 0.015, 1e-9));
    let coman = load("coman_right_arm");
    assert!(close(coman.structure.elbow_offsets[0], 0.015, 1e-9));
    let panda = load("panda");
    assert!(close(panda.structure.elbow_offsets[0], 0.0825, 1e-9));
}

#[test]
fn human_arm_uses_the_wrist_joint_centre() {
    let human = load("human_arm");
    let st = &human.structure;
    assert!(st.shoulder_spherical && !st.wrist_spherical && !st.is_srs);
    // U-joint centre and shoulder in the z-up frame (robots/README.md).
    let w = st.wrist_zero + st.shoulder_in_base_link;
    assert!((w - Vector3::new(0.00078, -0.2001, -0.16362)).norm() < 1e-4, "{w:?}");
}

#[test]
fn every_robot_has_limits_and_arm_capsules() {
    for (name, r) in crate::common::all_robots() {
        assert_eq!(r.joint_names().len(), 7);
        assert!(r.lower().iter().zip(r.upper().iter()).all(|(l, u)| l < u), "{name}");
        assert!(r.velocity_limits().iter().all(|v| *v > 0.0), "{name}");
        for role in [
            a2ml::robot::LinkRole::UpperArm,
            a2ml::robot::LinkRole::Forearm,
            a2ml::robot::LinkRole::Hand,
        ] {
            assert!(r.capsules.iter().any(|c| c.role == role), "{name} lacks a {role:?} capsule");
        }
        assert_eq!(r.tip_link, "hand", "{name}");
    }
}

#[test]
fn base_frame_origin_is_the_shoulder() {
    for (name, r) in crate::common::all_robots() {
        let pose = a2ml::kinematics::arm_pose(&r, &r.middle());
        assert!(pose.shoulder.norm() < 1e-12, "{name}");
        // S lies on the first three axes whenever the shoulder is spherical.
        for i in 0..3 {
            let d = pose.axes[i].cross(&(-pose.axis_points[i])).norm();
            assert!(d < 1e-9, "{name}: axis {i} misses S by {d}");
        }
    }
}
