use std::fs;
use std::io::Write;
use std::path::PathBuf;

use super::atomic::{Failure, write_atomically};
use super::messages::{self, QuaternionSeries, Time};
use super::{OutputError, csv};
use crate::math::{Isometry, PI, Real, Rotation3, UnitQuaternion, Vector3};
use crate::robot::Robot;
use nalgebra::Point3;

/// An empty scratch folder of this test process.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("a2ml-output-{}-{name}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

fn entries(dir: &PathBuf) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .expect("readable")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_successful_write_leaves_only_the_target() {
    let dir = scratch("success");
    let path = dir.join("out.txt");
    write_atomically(&path, |out| Ok(out.write_all(b"hello")?)).expect("written");
    assert_eq!(fs::read_to_string(&path).expect("readable"), "hello");
    assert_eq!(entries(&dir), ["out.txt"]);
    fs::remove_dir_all(dir).ok();
}

#[test]
fn a_failing_writer_leaves_no_file_and_names_the_path() {
    let dir = scratch("failure");
    let path = dir.join("out.mcap");
    let err = write_atomically(&path, |out| {
        out.write_all(b"half a file")?;
        out.flush()?;
        Err(Failure::Mcap("simulated".into()))
    })
    .expect_err("fails");
    assert_eq!(
        err,
        OutputError::Mcap { path: path.display().to_string(), message: "simulated".into() }
    );
    assert!(entries(&dir).is_empty(), "left {:?}", entries(&dir));
    fs::remove_dir_all(dir).ok();
}

#[test]
fn a_failing_writer_keeps_the_previous_file() {
    let dir = scratch("keep");
    let path = dir.join("plan.csv");
    fs::write(&path, "old").expect("written");
    let err = write_atomically(&path, |out| {
        out.write_all(b"new")?;
        Err(Failure::Json("simulated".into()))
    });
    assert!(matches!(err, Err(OutputError::Json { .. })));
    assert_eq!(fs::read_to_string(&path).expect("readable"), "old");
    assert_eq!(entries(&dir), ["plan.csv"]);
    fs::remove_dir_all(dir).ok();
}

#[test]
fn a_missing_folder_is_an_io_error_and_a_folder_is_refused_without_leftovers() {
    let dir = scratch("io");
    let missing = dir.join("no/such/folder/out.mcap");
    let err = write_atomically(&missing, |_| Ok(())).expect_err("no folder");
    assert!(matches!(&err, OutputError::Io { path, .. } if path.contains("no/such/folder")));
    let folder = dir.join("sub");
    fs::create_dir(&folder).expect("created");
    let err = write_atomically(&folder, |out| Ok(out.write_all(b"x")?)).expect_err("a folder");
    assert!(matches!(err, OutputError::NotRegularFile { kind: "a folder", .. }), "{err}");
    assert_eq!(entries(&dir), ["sub"]);
    assert!(entries(&folder).is_empty());
    fs::remove_dir_all(dir).ok();
}

#[test]
fn csv_numbers_read_back_exactly() {
    let values =
        [0.0, -0.0, 1.0, -2.5, 0.1, 1.0 / 3.0, PI, 1e-4, 9.99e-5, 1e-300, -7e-17, 1e16, 1e300];
    for x in values {
        let text = csv::number(x);
        assert_eq!(text.parse::<Real>().expect("a number"), x, "{text}");
        assert!(text.len() <= 24, "{text}");
    }
    assert_eq!(csv::number(0.25), "0.25");
    assert_eq!(csv::number(1e-300), "1e-300");
}

#[test]
fn csv_header_quotes_only_what_needs_it() {
    assert_eq!(csv::header(&["j1", "a,b"]), "t,j1_pos,\"a,b_pos\",j1_vel,\"a,b_vel\"");
}

#[test]
fn time_splits_nanoseconds() {
    let json = serde_json::to_value(Time::from_nanos(2_500_000_001)).expect("json");
    assert_eq!(json, serde_json::json!({ "sec": 2, "nsec": 500_000_001 }));
}

#[test]
fn quaternions_stay_on_one_hemisphere() {
    let mut series = QuaternionSeries::default();
    let mut last = series.next(&Rotation3::identity());
    // Past π about z the canonical quaternion flips sign; the series must not.
    for k in 1..=40 {
        let r = Rotation3::from_axis_angle(&Vector3::z_axis(), k as Real * 0.1);
        let q = series.next(&r);
        assert!(q.coords.dot(&last.coords) > 0.9, "jump at step {k}");
        assert!(q.rotation_to(&r.into()).angle() < 1e-12);
        last = q;
    }
}

/// COMAN with one capsule, "c", from `a` to `b` (in its moving frame) of radius 5 cm, and the
/// transform from that frame to the capsule's link.
fn one_capsule(a: Vector3, b: Vector3) -> (Robot, Isometry) {
    let mut robot = Robot::from_urdf_file(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/coman_right_arm.urdf"
    ))
    .expect("robot loads");
    robot.capsules.truncate(1);
    let c = &mut robot.capsules[0];
    (c.name, c.a, c.b, c.radius) = ("c".into(), a, b, 0.05);
    let link = robot.links.iter().find(|l| l.name == c.link).expect("the capsule's link");
    let link_from_frame = link.frame_from_link.inverse();
    (robot, link_from_frame)
}

/// The orientation of a Foxglove pose.
fn orientation(pose: &serde_json::Value) -> UnitQuaternion {
    let o = &pose["orientation"];
    let [x, y, z, w] = ["x", "y", "z", "w"].map(|k| o[k].as_f64().expect("component"));
    UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z))
}

fn position(pose: &serde_json::Value) -> Vector3 {
    let p = &pose["position"];
    let [x, y, z] = ["x", "y", "z"].map(|k| p[k].as_f64().expect("component"));
    Vector3::new(x, y, z)
}

#[test]
fn a_capsule_is_a_cylinder_along_its_axis_and_two_balls_in_its_link() {
    let (a, b) = (Vector3::new(0.1, 0.2, 0.3), Vector3::new(0.1, 0.5, 0.3));
    let (robot, link_from_frame) = one_capsule(a, b);
    let update = messages::arm_capsules(Time::from_nanos(0), &robot);
    let json = serde_json::to_value(update).expect("json");
    let entity = &json["entities"][0];
    assert_eq!(entity["id"], "capsule/0/c");
    assert_eq!(entity["frame_id"], robot.capsules[0].link.as_str());
    assert_eq!(entity["frame_locked"], true);
    let caps = entity["spheres"].as_array().expect("caps");
    assert_eq!(caps.len(), 2);
    let (a_link, b_link) = (link_from_frame * Point3::from(a), link_from_frame * Point3::from(b));
    assert!((position(&caps[0]["pose"]) - a_link.coords).norm() < 1e-12);
    assert!((position(&caps[1]["pose"]) - b_link.coords).norm() < 1e-12);
    let cylinder = &entity["cylinders"][0];
    assert!((cylinder["size"]["z"].as_f64().expect("z") - 0.3).abs() < 1e-12);
    assert!((cylinder["size"]["x"].as_f64().expect("x") - 0.1).abs() < 1e-12);
    let middle = 0.5 * (a_link.coords + b_link.coords);
    assert!((position(&cylinder["pose"]) - middle).norm() < 1e-12);
    // The pose's z axis is the capsule's axis.
    let q = orientation(&cylinder["pose"]);
    assert!((q * Vector3::z() - (b_link - a_link).normalize()).norm() < 1e-12);
}

#[test]
fn a_capsule_pointing_down_and_a_ball_capsule_are_drawn() {
    let a = Vector3::new(0.0, 0.0, 0.2);
    let (robot, link_from_frame) = one_capsule(a, Vector3::zeros());
    let json =
        serde_json::to_value(messages::arm_capsules(Time::from_nanos(0), &robot)).expect("json");
    let q = orientation(&json["entities"][0]["cylinders"][0]["pose"]);
    let down = link_from_frame.rotation * -Vector3::z();
    assert!((q * Vector3::z() - down).norm() < 1e-12);
    let (ball, _) = one_capsule(a, a);
    let json =
        serde_json::to_value(messages::arm_capsules(Time::from_nanos(0), &ball)).expect("json");
    assert_eq!(json["entities"][0]["cylinders"].as_array().map(Vec::len), Some(0));
}

#[test]
fn a_singular_state_is_left_out() {
    let state = messages::state(Time::from_nanos(0), None, None, &mut Default::default());
    let json = serde_json::to_value(state).expect("json");
    assert_eq!(json, serde_json::json!({ "timestamp": { "sec": 0, "nsec": 0 } }));
}

#[cfg(unix)]
#[test]
fn special_files_and_links_are_refused_and_left_alone() {
    let dir = scratch("special");
    let kept = dir.join("kept.txt");
    fs::write(&kept, "old").expect("written");
    let link = dir.join("link.txt");
    std::os::unix::fs::symlink(&kept, &link).expect("symlink");
    let err = write_atomically(&link, |out| Ok(out.write_all(b"new")?)).expect_err("a link");
    assert!(matches!(err, OutputError::NotRegularFile { kind: "a symbolic link", .. }), "{err}");
    assert!(fs::symlink_metadata(&link).expect("link").file_type().is_symlink());
    let device = std::path::Path::new("/dev/null");
    let err = write_atomically(device, |out| Ok(out.write_all(b"new")?)).expect_err("a device");
    assert!(matches!(err, OutputError::NotRegularFile { kind: "a device", .. }), "{err}");
    assert_eq!(fs::read_to_string(&kept).expect("kept"), "old");
    assert_eq!(entries(&dir), ["kept.txt", "link.txt"]);
    fs::remove_dir_all(dir).ok();
}

#[test]
fn staged_files_are_removed_unless_committed() {
    use super::Staged;
    let dir = scratch("staged");
    let (first, second) = (dir.join("a.txt"), dir.join("b.txt"));
    fs::write(&first, "old a").expect("written");
    let mut a = Staged::create(&first).expect("staged");
    a.fill(|out| Ok(out.write_all(b"new a")?)).expect("filled");
    let b = Staged::create(&second).expect("staged");
    assert!(a.temporary().exists() && b.temporary().exists());
    drop((a, b));
    assert_eq!(entries(&dir), ["a.txt"], "no temporary left");
    assert_eq!(fs::read_to_string(&first).expect("a"), "old a");
    fs::remove_dir_all(dir).ok();
}
