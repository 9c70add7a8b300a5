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
        pose *=
            Isometry::from_parts(Translation3::new(x, y, z), Rotation3::from_euler_angles(r, p, w));
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
            let dr = (ours.rotation.matrix() - reference.rotation.matrix()).norm();
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
    assert!(
        err.contains("longest has 10") && err.contains("`torso_lift_link` tip `arm_left_7_link`"),
        "{err}"
    );
}

#[test]
fn continuous_joints_and_wide_ranges() {
    let (_, pr2) = third_party().into_iter().find(|(n, _)| *n == "pr2").expect("pr2");
    let continuous: Vec<&str> =
        pr2.joints.iter().filter(|j| j.continuous).map(|j| j.name.as_str()).collect();
    assert_eq!(continuous, ["r_forearm_roll_joint", "r_wrist_roll_joint"]);
    for j in pr2.joints.iter().filter(|j| j.continuous) {
        assert_eq!(
            (j.limits.lower, j.limits.upper),
            (-2.0 * std::f64::consts::PI, 2.0 * std::f64::consts::PI)
        );
    }
}

/// Distance from `p` to the segment a-b.
fn segment_distance(p: &Vector3, a: &Vector3, b: &Vector3) -> f64 {
    let ab = b - a;
    let t = if ab.norm_squared() > 0.0 {
        (ab.dot(&(p - a)) / ab.norm_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// Clearance between the arm's capsules, placed by FK at `q`, and a ball.
fn ball_clearance(
    robot: &a2ml::Robot,
    q: &a2ml::math::JointVector,
    centre: &Vector3,
    radius: f64,
) -> f64 {
    let pose = a2ml::kinematics::arm_pose(robot, q);
    robot
        .capsules
        .iter()
        .map(|c| {
            let frame = pose.frames[c.frame];
            let a = frame.transform_point(&c.a.into()).coords;
            let b = frame.transform_point(&c.b.into()).coords;
            segment_distance(centre, &a, &b) - c.radius - radius
        })
        .fold(f64::INFINITY, f64::min)
}

/// A reach from one in-limit configuration to the CPSA state of another,
/// with a 4 cm ball on the way: the task text, the ball's centre and radius.
fn reach_around_ball(
    robot: &a2ml::Robot,
    file: &str,
    base: Option<&str>,
    tip: Option<&str>,
    seed: u64,
) -> (String, Vector3, f64) {
    // A 4 cm ball on an adult-sized arm, scaled down on a child-sized one (iCub).
    let reach = robot.upper_arm_length() + robot.forearm_length();
    let radius = 0.04_f64.min(0.05 * reach);
    let mut rng = crate::common::rng(seed);
    for _ in 0..100_000 {
        let (q0, p0) = crate::common::regular_q(robot, &mut rng, 0.2);
        let (q1, p1) = crate::common::regular_q(robot, &mut rng, 0.2);
        let distance = (p1.wrist - p0.wrist).norm();
        let centre = 0.5 * (p0.wrist + p1.wrist);
        if !(0.25 * reach..0.6 * reach).contains(&distance)
            || ball_clearance(robot, &q0, &centre, radius) < 0.03_f64.min(0.06 * reach)
            || ball_clearance(robot, &q1, &centre, radius) < 0.03_f64.min(0.06 * reach)
        {
            continue;
        }
        let goal = a2ml::kinematics::cpsa_state(robot, &p1).expect("regular");
        let quat = a2ml::math::UnitQuaternion::from_rotation_matrix(&goal.ow);
        let mut line = format!("robot \"{}\"", urdf_data(file).display());
        if let Some(b) = base {
            line += &format!(" base \"{b}\"");
        }
        if let Some(t) = tip {
            line += &format!(" tip \"{t}\"");
        }
        let v = |x: &[f64]| x.iter().map(|v| format!("{v:.12}")).collect::<Vec<_>>().join(", ");
        let text = format!(
            "{line}\nstart [{}] rad\nscene {{ ball = sphere at [{}] radius {radius} }}\n\
             task reach {{ action a {{ goal Pw Ow θsw = ([{}], quat({}), {:.12} rad) }} }}\n",
            v(q0.as_slice()),
            v(centre.as_slice()),
            v(goal.pw.as_slice()),
            v(&[quat.w, quat.i, quat.j, quat.k]),
            goal.swivel,
        );
        return (text, centre, radius);
    }
    panic!("no reach with a ball between its ends found for {}", robot.name);
}

#[test]
fn third_party_reach_around_a_ball_keeps_its_clearance() {
    for ((name, robot), (_, file, base, tip)) in third_party().into_iter().zip(THIRD_PARTY) {
        // iCub's meshes are not vendored, and the default skeleton radius
        // (6 cm) is an adult's: a child-sized arm gets one of its own.
        let robot = if name == "icub" {
            let mut options = third_party_options(base, tip);
            options.geometry.skeleton_radius = Some(0.025);
            a2ml::Robot::from_urdf_file_with(urdf_data(file), &options).expect("icub")
        } else {
            robot
        };
        let (text, centre, radius) = reach_around_ball(&robot, file, base, tip, 5);
        let task =
            a2ml::language::parse(&text, None).unwrap_or_else(|d| panic!("{name}: {d}\n{text}"));
        assert_eq!((task.robot_base.as_deref(), task.robot_tip.as_deref()), (base, tip));
        let started = std::time::Instant::now();
        let plan = a2ml::solve::plan(&robot, &task, &a2ml::solve::PlanOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}\n{text}"));
        let seconds = started.elapsed().as_secs_f64();
        let trajectory = &plan.trajectory;
        let mut worst = f64::INFINITY;
        let mut t = trajectory.start();
        while t <= trajectory.end() {
            let q = trajectory.sample(t).0;
            assert!(robot.within_limits(&q, 1e-6), "{name}: limits at t = {t}");
            worst = worst.min(ball_clearance(&robot, &q, &centre, radius));
            t += 1e-3;
        }
        let reached = plan.segments.iter().all(|s| s.reached);
        println!(
            "{name}: planned in {seconds:.3} s, clearance {:.1} mm, goal reached {reached}",
            worst * 1e3
        );
        assert!(
            worst >= plan.safety_distance - 1e-4,
            "{name}: the arm comes within {worst} m of the ball (safety {})",
            plan.safety_distance
        );
    }
}

#[test]
fn an_arm_without_geometry_is_covered_by_its_skeleton_or_refused() {
    // xArm7's meshes are not vendored: its collision geometry is the skeleton,
    // and a task with an obstacle says so.
    let (_, file, base, tip) = THIRD_PARTY[1];
    let xarm = a2ml::Robot::from_urdf_file(urdf_data(file)).expect("xarm");
    assert!(xarm.capsules.iter().all(|c| c.source == a2ml::robot::CapsuleSource::Skeleton));
    let (text, centre, radius) = reach_around_ball(&xarm, file, base, tip, 9);
    let task = a2ml::language::parse(&text, None).expect("task");
    let plan = a2ml::solve::plan(&xarm, &task, &a2ml::solve::PlanOptions::default()).expect("plan");
    assert!(
        plan.warnings.iter().any(|w| w.message.contains("skeleton capsule")),
        "{:?}",
        plan.warnings
    );
    let mut t = plan.trajectory.start();
    while t <= plan.trajectory.end() {
        let q = plan.trajectory.sample(t).0;
        assert!(ball_clearance(&xarm, &q, &centre, radius) >= plan.safety_distance - 1e-4);
        t += 1e-3;
    }
    // Skeleton off: nothing to check obstacles against, so planning refuses.
    let mut options = a2ml::RobotOptions::default();
    options.geometry.skeleton_radius = None;
    let bare = a2ml::Robot::from_urdf_file_with(urdf_data(file), &options).expect("xarm");
    assert!(bare.capsules.is_empty() && !bare.has_arm_geometry());
    let err = a2ml::solve::plan(&bare, &task, &a2ml::solve::PlanOptions::default()).unwrap_err();
    assert!(matches!(err, a2ml::solve::SolveError::NoArmGeometry { .. }), "{err:?}");
}

#[test]
fn a_task_loads_the_chain_its_robot_line_names() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/tasks/baxter_left_reach.a2ml");
    let task = a2ml::language::load(&path).expect("the task is valid");
    assert!(a2ml::Robot::from_urdf_file(&task.robot).is_err(), "two arms: no unique chain");
    let left = task.load_robot(&a2ml::RobotOptions::default()).expect("the left arm");
    assert_eq!((left.base_link.as_str(), left.tip_link.as_str()), ("left_arm_mount", "left_wrist"));
    assert!(left.joints.iter().all(|j| j.name.starts_with("left_")));
    // Options that name a chain win over the task's.
    let options = a2ml::RobotOptions {
        base: Some("right_arm_mount".into()),
        tip: Some("right_wrist".into()),
        ..a2ml::RobotOptions::default()
    };
    let right = task.load_robot(&options).expect("the right arm");
    assert!(right.joints.iter().all(|j| j.name.starts_with("right_")));
}
