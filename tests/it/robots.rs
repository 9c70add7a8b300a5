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

/// Third-party arms of tests/data/urdf (origins and licences in its
/// README): name, file, base and tip links (`None`: the unique chain).
pub const THIRD_PARTY: [(&str, &str, Option<&str>, Option<&str>); 10] = [
    ("lbr_iiwa", "lbr_iiwa.urdf", None, None),
    ("xarm7", "xarm7.urdf", None, None),
    ("panda", "panda.urdf", None, Some("panda_hand")),
    ("baxter", "baxter.urdf", Some("right_arm_mount"), Some("right_wrist")),
    ("pr2", "pr2.urdf", Some("torso_lift_link"), Some("r_wrist_roll_link")),
    ("tiago", "tiago.urdf", Some("torso_lift_link"), Some("arm_7_link")),
    ("tiago_pro", "tiago_pro.urdf", Some("torso_lift_link"), Some("arm_left_7_link")),
    ("talos", "talos_reduced.urdf", Some("torso_2_link"), Some("arm_left_7_link")),
    ("romeo", "romeo.urdf", Some("torso"), Some("l_wrist")),
    ("icub", "icub.urdf", Some("chest"), Some("l_hand")),
];

pub fn urdf_data(file: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/urdf").join(file)
}

/// Robot options for a third-party arm, with the vendored meshes on the
/// package path.
pub fn third_party_options(base: Option<&str>, tip: Option<&str>) -> a2ml::RobotOptions {
    let mut options = a2ml::RobotOptions {
        base: base.map(str::to_owned),
        tip: tip.map(str::to_owned),
        ..Default::default()
    };
    options.geometry.package_path = vec![urdf_data("packages")];
    options
}

pub fn third_party() -> Vec<(&'static str, a2ml::Robot)> {
    THIRD_PARTY
        .iter()
        .map(|(name, file, base, tip)| {
            let robot = a2ml::Robot::from_urdf_file_with(
                urdf_data(file),
                &third_party_options(*base, *tip),
            )
            .unwrap_or_else(|e| panic!("{name}: {e}"));
            (*name, robot)
        })
        .collect()
}

/// The tip link's pose in the base link at `q`, straight from the URDF's
/// origins and axes: an FK that shares no code with a2ml's reader.
fn reference_fk(
    text: &str,
    base: &str,
    tip: &str,
    q: &a2ml::math::JointVector,
) -> a2ml::math::Isometry {
    use a2ml::math::{Isometry, Rotation3, Translation3};
    let doc = roxmltree::Document::parse(text).expect("XML");
    let numbers = |s: Option<&str>| -> [f64; 3] {
        let v: Vec<f64> =
            s.unwrap_or("0 0 0").split_whitespace().map(|w| w.parse().expect("number")).collect();
        [v[0], v[1], v[2]]
    };
    let mut chain = Vec::new();
    let mut link = tip.to_owned();
    while link != base {
        let joint = doc
            .root_element()
            .children()
            .filter(|n| n.has_tag_name("joint"))
            .find(|j| {
                j.children().any(|c| c.has_tag_name("child") && c.attribute("link") == Some(&link))
            })
            .expect("a parent joint");
        let attr = |tag: &str, a: &str| {
            joint.children().find(|c| c.has_tag_name(tag)).and_then(|c| c.attribute(a))
        };
        link = attr("parent", "link").expect("parent").to_owned();
        chain.push(joint);
    }
    chain.reverse();
    let mut pose = Isometry::identity();
    let mut k = 0;
    for joint in chain {
        let attr = |tag: &str, a: &str| {
            joint.children().find(|c| c.has_tag_name(tag)).and_then(|c| c.attribute(a))
        };
        let [x, y, z] = numbers(attr("origin", "xyz"));
        let [r, p, w] = numbers(attr("origin", "rpy"));
        pose *= Isometry::from_parts(Translation3::new(x, y, z), Rotation3::from_euler_angles(r, p, w));
        if joint.attribute("type") != Some("fixed") {
            let axis = Vector3::from(numbers(attr("axis", "xyz").or(Some("1 0 0"))));
            let axis = nalgebra::Unit::new_normalize(axis);
            pose *= Isometry::rotation(axis.into_inner() * q[k]);
            k += 1;
        }
    }
    pose
}

#[test]
fn third_party_arms_load_with_geometry_on_every_part() {
    for (name, robot) in third_party() {
        assert!(robot.has_arm_geometry(), "{name}: {:?}", robot.geometry_warnings);
        assert!(
            robot.capsules.iter().all(|c| c.radius > 0.0 && c.a.iter().all(|v| v.is_finite())),
            "{name}"
        );
    }
}

#[test]
fn third_party_forward_kinematics_matches_the_reference() {
    let mut rng = crate::common::rng(13);
    for ((name, robot), (_, file, _, _)) in third_party().into_iter().zip(THIRD_PARTY) {
        let text = std::fs::read_to_string(urdf_data(file)).expect("vendored");
        let tip = robot.links.last().expect("tip");
        assert_eq!(tip.frame, 7, "{name}");
        for _ in 0..20 {
            let q = crate::common::random_q(&robot, &mut rng);
            let pose = a2ml::kinematics::arm_pose(&robot, &q);
            let ours = robot.b_from_base_link.inverse() * pose.frames[7] * tip.frame_from_link;
            let reference = reference_fk(&text, &robot.base_link, &robot.tip_link, &q);
            let dp = (ours.translation.vector - reference.translation.vector).norm();
            let dr = (ours.rotation.matrix()
                - reference.rotation.matrix())
            .norm();
            assert!(dp < 1e-12 && dr < 1e-12, "{name}: {dp:e} m, {dr:e} rad");
        }
    }
}

#[test]
fn capsules_are_fitted_to_meshes_found_on_the_package_path() {
    use a2ml::robot::CapsuleSource;
    let (_, file, base, tip) = THIRD_PARTY[2];
    let panda = a2ml::Robot::from_urdf_file_with(urdf_data(file), &third_party_options(base, tip))
        .expect("panda");
    let meshes: Vec<_> =
        panda.capsules.iter().filter(|c| c.source == CapsuleSource::Mesh).collect();
    assert!(meshes.len() >= 8, "{:?}", panda.geometry_warnings);
    // Link 4 of the Panda reaches from joint 4 to joint 5: about 0.1 m
    // across, under 0.1 m thick.
    let link4 = meshes.iter().find(|c| c.link == "panda_link4").expect("link 4");
    assert!(link4.radius > 0.04 && link4.radius < 0.1, "{}", link4.radius);
    assert!(panda.geometry_warnings.iter().any(|w| w.contains("fitted to meshes")));
    // Without the package path: the skeleton, said so.
    let bare = a2ml::Robot::from_urdf_file_with(
        urdf_data(file),
        &a2ml::RobotOptions { tip: tip.map(str::to_owned), ..Default::default() },
    )
    .expect("panda");
    assert!(bare.capsules.iter().all(|c| c.source == CapsuleSource::Skeleton));
    assert_eq!(bare.capsules.len(), 3);
    assert!(bare.geometry_warnings.iter().any(|w| w.contains("not found on the package path")));
}

#[test]
fn non_arms_are_refused_with_a_hint() {
    // TALOS's left-arm file starts one joint into the arm and ends on the
    // gripper: six arm joints and a finger.
    let err = a2ml::Robot::from_urdf_file(urdf_data("talos_left_arm.urdf")).unwrap_err();
    let message = err.to_string();
    assert!(matches!(err, a2ml::RobotError::NotAnthropomorphic { .. }), "{err:?}");
    assert!(message.contains("far too short") && message.contains("base and tip"), "{message}");
}

#[test]
fn several_chains_list_their_base_and_tip_pairs() {
    let err = a2ml::Robot::from_urdf_file(urdf_data("baxter.urdf")).unwrap_err().to_string();
    assert!(err.contains("base `right_arm_mount` tip `right_wrist`"), "{err}");
    assert!(err.contains("base `left_arm_mount` tip `left_wrist`"), "{err}");
    let err = a2ml::Robot::from_urdf_file(urdf_data("tiago_pro.urdf")).unwrap_err().to_string();
    assert!(err.contains("longest has 10") && err.contains("`torso_lift_link` tip `arm_left_7_link`"), "{err}");
}

#[test]
fn continuous_joints_and_wide_ranges() {
    let (_, pr2) = third_party().into_iter().find(|(n, _)| *n == "pr2").expect("pr2");
    let continuous: Vec<&str> =
        pr2.joints.iter().filter(|j| j.continuous).map(|j| j.name.as_str()).collect();
    assert_eq!(continuous, ["r_forearm_roll_joint", "r_wrist_roll_joint"]);
    for j in pr2.joints.iter().filter(|j| j.continuous) {
        assert_eq!((j.limits.lower, j.limits.upper), (-2.0 * std::f64::consts::PI, 2.0 * std::f64::consts::PI));
    }
}
