//! Rotated scene objects: written in a task, printed back by `fmt`, and checked for
//! collisions against brute force in each shape's own frame.

use a2ml::collision::DistanceOptions;
use a2ml::collision::{CollisionModel, CollisionScene, arm_capsules, clearance, distances};
use a2ml::kinematics::arm_pose;
use a2ml::language::{Obstacle, Shape, format, parse, parse_ast};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
use std::path::PathBuf;

use a2ml::math::{Real, Rotation3, UnitQuaternion, Vector3};
use a2ml::robot::LinkRole;
use rand::RngExt;
use rand::rngs::StdRng;

use crate::common::{load, random_q, rng};

const SCENE: &str = r#"robot "../robots/panda.urdf"
scene {
  shelf = box      at [0.5, 0, 0.3] size [0.4, 0.2, 0.02] rotation rpy(0, 0, 90) deg
  tilted = box     at [0.5, 0.3, 0.3] size [0.1, 0.1, 0.1] rotation quat(0.9239, 0.3827, 0, 0)
  framed = box     at [0.5, -0.3, 0.3] size [0.1, 0.2, 0.3] rotation axes(x: [0, 1, 0], y: [-1, 0, 0])
  post = cylinder  at [0.4, 0, 0] radius 3 cm height 0.5 axis [1, 0, 0]
  bar = capsule    at [0.4, 0.1, 0.2] radius 0.02 height 0.3 axis [0, 1, 0]
  rod = capsule    at [0.4, 0.1, 0.2] radius 0.02 height 0.3
}
task t { action a { goal θe = 1 } }
"#;

fn task_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/rotated_scene.a2ml")
}

fn shape<'a>(scene: &'a [Obstacle], name: &str) -> &'a Shape {
    &scene.iter().find(|o| o.name == name).expect("obstacle").shape
}

fn assert_rotation(found: &Rotation3, expected: &Rotation3) {
    assert!((found.matrix() - expected.matrix()).amax() < 1e-4, "{found} vs {expected}");
}

#[test]
fn rotations_axes_and_capsule_centres_are_read() {
    let task = parse(SCENE, Some(&task_path())).unwrap_or_else(|e| panic!("{e}"));
    let Shape::Box { rotation, size, .. } = shape(&task.scene, "shelf") else { panic!() };
    assert_rotation(rotation, &Rotation3::from_axis_angle(&Vector3::z_axis(), FRAC_PI_2));
    assert_eq!(*size, Vector3::new(0.4, 0.2, 0.02));
    let Shape::Box { rotation, .. } = shape(&task.scene, "tilted") else { panic!() };
    assert_rotation(rotation, &Rotation3::from_axis_angle(&Vector3::x_axis(), FRAC_PI_4));
    let Shape::Box { rotation, .. } = shape(&task.scene, "framed") else { panic!() };
    assert_rotation(rotation, &Rotation3::from_axis_angle(&Vector3::z_axis(), FRAC_PI_2));
    let Shape::Cylinder { rotation, radius, .. } = shape(&task.scene, "post") else { panic!() };
    assert!((radius - 0.03).abs() < 1e-12);
    assert!((rotation * Vector3::z() - Vector3::x()).norm() < 1e-12);
    let Shape::Capsule { a, b, radius } = shape(&task.scene, "bar") else { panic!() };
    assert!((a - Vector3::new(0.4, -0.05, 0.2)).norm() < 1e-12, "{a}");
    assert!((b - Vector3::new(0.4, 0.25, 0.2)).norm() < 1e-12, "{b}");
    assert_eq!(*radius, 0.02);
    let Shape::Capsule { a, b, .. } = shape(&task.scene, "rod") else { panic!() };
    assert!((b - a - Vector3::new(0.0, 0.0, 0.3)).norm() < 1e-12, "vertical without an axis");
}

#[test]
fn rotated_shapes_survive_fmt() {
    let tree = parse_ast(SCENE, Some(&task_path())).expect("parses");
    let printed = format(&tree);
    for word in ["rotation rpy(", "rotation quat(", "rotation axes(", "axis [1, 0, 0]"] {
        assert!(printed.contains(word), "{word} missing from\n{printed}");
    }
    let again = parse_ast(&printed, Some(&task_path())).expect("printed form parses");
    assert_eq!(again, tree);
    assert_eq!(format(&again), printed);
    let task = parse(&printed, Some(&task_path())).expect("validates");
    assert_eq!(task, parse(SCENE, Some(&task_path())).expect("validates"));
}

fn random_rotation(rng: &mut StdRng) -> Rotation3 {
    let q = nalgebra::Quaternion::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    UnitQuaternion::from_quaternion(q).to_rotation_matrix()
}

/// The signed distance from `p` (scene frame) to the shape, computed in the shape's frame.
fn point_distance(shape: &Shape, p: &Vector3) -> Real {
    match shape {
        Shape::Box { center, size, rotation } => {
            let local = rotation.inverse() * (p - center);
            let outside = (local.abs() - size * 0.5).map(|x| x.max(0.0)).norm();
            let inside = (local.abs() - size * 0.5).max().min(0.0);
            outside + inside
        }
        Shape::Cylinder { center, radius, height, rotation } => {
            let local = rotation.inverse() * (p - center);
            let (radial, axial) = (local.xy().norm() - radius, local.z.abs() - 0.5 * height);
            radial.max(0.0).hypot(axial.max(0.0)) + radial.max(axial).min(0.0)
        }
        _ => unreachable!("boxes and cylinders only"),
    }
}

/// Each arm capsule's distance to a randomly rotated box or cylinder equals the smallest
/// distance over dense points of its segment, measured in the shape's own frame.
#[test]
fn rotated_boxes_and_cylinders_match_brute_force() {
    let robot = load("panda");
    let mut rng = rng(23);
    let mut close = 0;
    for k in 0..60 {
        let q = random_q(&robot, &mut rng);
        let pose = arm_pose(&robot, &q);
        let center = Vector3::new(
            rng.random_range(-0.4..0.6),
            rng.random_range(-0.5..0.5),
            rng.random_range(-0.3..0.7),
        );
        let rotation = random_rotation(&mut rng);
        let shape = if k % 2 == 0 {
            let size = Vector3::from_fn(|_, _| rng.random_range(0.02..0.5));
            Shape::Box { center, size, rotation }
        } else {
            let (radius, height) = (rng.random_range(0.02..0.2), rng.random_range(0.05..0.6));
            Shape::Cylinder { center, radius, height, rotation }
        };
        let scene = CollisionScene::new(&[Obstacle { name: "o".into(), shape: shape.clone() }]);
        let found = distances(&robot, &pose, &scene, &DistanceOptions { influence: 10.0 });
        let mut smallest = Real::INFINITY;
        for c in arm_capsules(&robot, &pose).iter().filter(|c| c.role != LinkRole::Base) {
            let samples = 4000;
            let step = (c.b - c.a).norm() / samples as Real;
            let brute = (0..=samples)
                .map(|i| {
                    point_distance(&shape, &(c.a + (c.b - c.a) * (i as Real / samples as Real)))
                })
                .fold(Real::INFINITY, Real::min)
                - c.radius;
            let p = found
                .iter()
                .find(|p| p.link == c.name && p.obstacle == "o")
                .expect("every pair within a 10 m influence");
            // Dense points bound the distance from above, within half a step (distance is
            // 1-Lipschitz); inside the shape the signed distance is exact only at the surface,
            // so penetrations are compared by sign.
            // parry's GJK meets a cylinder's curved side to about 10 µm; a box's faces exactly.
            let precision = if k % 2 == 0 { 1e-6 } else { 2e-5 };
            if brute > 1e-3 {
                assert!(
                    p.distance <= brute + precision,
                    "{k} {}: {} > {brute}",
                    c.name,
                    p.distance
                );
                assert!(p.distance >= brute - step, "{k} {}: {} < {brute}", c.name, p.distance);
            } else {
                assert!(p.distance < 1e-3 + step, "{k} {}: {} vs {brute}", c.name, p.distance);
            }
            if brute < 0.1 {
                close += 1;
            }
            smallest = smallest.min(p.distance);
        }
        // The allocation-free model agrees with the general query.
        let model = CollisionModel::new(
            &robot,
            &CollisionScene::new(&[Obstacle { name: "o".into(), shape }]),
        );
        let arm_only = clearance(&model, &q);
        let empty = CollisionModel::new(&robot, &CollisionScene::new(&[]));
        let self_only = clearance(&empty, &q);
        let expected = smallest.min(self_only);
        // The model's capsule-cylinder distance is closed form (within 1e-11 m of the true
        // one), parry's GJK above it by up to 2e-5 m (as above): the model may be below parry
        // by that much, never above.
        let below = if k % 2 == 0 { 1e-9 } else { 2e-5 };
        assert!(
            arm_only < expected + 1e-9 && arm_only > expected - below,
            "{k}: {arm_only} vs {expected}"
        );
    }
    assert!(close > 20, "too few close pairs exercised: {close}");
}
