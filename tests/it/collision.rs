//! Capsule-obstacle distances against independent brute force.

use crate::common::{all_robots, load, random_q, rng, sphere_panda};
use a2ml::collision::*;
use a2ml::kinematics::arm_pose;
use a2ml::language::{Obstacle, Shape};
use a2ml::math::{Real, Rotation3, UnitQuaternion, Vector3};
use a2ml::robot::LinkRole;
use rand::RngExt;
use rand::rngs::StdRng;

const TOL: Real = 1e-9;

/// The closest point of segment [a, b] to p.
fn closest_on_segment(a: &Vector3, b: &Vector3, p: &Vector3) -> Vector3 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 { ((p - a).dot(&ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    a + ab * t
}

fn random_vector(rng: &mut StdRng, half: Real) -> Vector3 {
    Vector3::new(
        rng.random_range(-half..half),
        rng.random_range(-half..half),
        rng.random_range(-half..half),
    )
}

fn sphere(center: Vector3, radius: Real) -> Obstacle {
    Obstacle { name: "ball".into(), shape: Shape::Sphere { center, radius } }
}

#[test]
fn capsule_sphere_matches_brute_force() {
    let robot = load("coman_right_arm");
    let mut rng = rng(7);
    let mut penetrating = 0;
    for _ in 0..500 {
        let pose = arm_pose(&robot, &random_q(&robot, &mut rng));
        let capsules = arm_capsules(&robot, &pose);
        // Sometimes centred on a link's axis, to exercise penetration.
        let center = if rng.random_range(0.0..1.0) < 0.2 {
            let c = &capsules[rng.random_range(0..capsules.len())];
            c.a + (c.b - c.a) * rng.random_range(0.0..1.0)
        } else {
            random_vector(&mut rng, 0.6)
        };
        let radius = rng.random_range(0.01..0.2);
        let scene = CollisionScene::new(&[sphere(center, radius)]);
        let influence = rng.random_range(0.02..0.5);
        let found = distances(&robot, &pose, &scene, &DistanceOptions { influence });

        for c in capsules.iter().filter(|c| c.role != LinkRole::Base) {
            let on_axis = closest_on_segment(&c.a, &c.b, &center);
            let expected = (on_axis - center).norm() - c.radius - radius;
            let hit = found.iter().find(|p| p.link == c.name && p.obstacle == "ball");
            let Some(p) = hit else {
                // The broad phase may only drop pairs at or beyond the influence.
                assert!(expected >= influence - TOL, "{}: dropped at {expected}", c.name);
                continue;
            };
            assert!(expected < influence + TOL);
            assert!(
                (p.distance - expected).abs() < TOL,
                "{}: {} vs {expected}",
                c.name,
                p.distance
            );
            if p.distance <= 0.0 {
                penetrating += 1;
            }
            // Closest points on the surfaces.
            assert!(((p.on_obstacle - center).norm() - radius).abs() < TOL);
            let axis_point = closest_on_segment(&c.a, &c.b, &p.on_link);
            assert!(((p.on_link - axis_point).norm() - c.radius).abs() < TOL);
            // Unit normal from the obstacle to the link.
            assert!((p.normal.norm() - 1.0).abs() < TOL);
            if (on_axis - center).norm() > 1e-6 {
                let n = (on_axis - center).normalize();
                assert!((p.normal - n).norm() < 1e-7, "{:?} vs {n:?}", p.normal);
            }
            assert!(((p.on_link - p.on_obstacle) - p.normal * p.distance).norm() < TOL);
        }
    }
    assert!(penetrating > 20, "too few penetrations exercised: {penetrating}");
}

/// Axis-aligned half of the time, else a uniform random rotation.
fn random_rotation(rng: &mut StdRng) -> Rotation3 {
    if rng.random_range(0.0..1.0) < 0.5 {
        return Rotation3::identity();
    }
    let q = nalgebra::Quaternion::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    UnitQuaternion::from_quaternion(q).to_rotation_matrix()
}

fn random_scene(rng: &mut StdRng) -> Vec<Obstacle> {
    (0..6)
        .map(|i| {
            let center = random_vector(rng, 0.6);
            let shape = match i % 4 {
                0 => Shape::Sphere { center, radius: rng.random_range(0.02..0.2) },
                1 => Shape::Box {
                    center,
                    size: Vector3::new(
                        rng.random_range(0.02..0.4),
                        rng.random_range(0.02..0.4),
                        rng.random_range(0.02..0.4),
                    ),
                    rotation: random_rotation(rng),
                },
                2 => Shape::Capsule {
                    a: center,
                    b: center + random_vector(rng, 0.2),
                    radius: rng.random_range(0.01..0.1),
                },
                _ => Shape::Cylinder {
                    center,
                    radius: rng.random_range(0.02..0.2),
                    height: rng.random_range(0.02..0.5),
                    rotation: random_rotation(rng),
                },
            };
            Obstacle { name: format!("o{i}"), shape }
        })
        .collect()
}

#[test]
fn broad_phase_never_drops_a_close_pair() {
    let robot = load("coman_right_arm");
    let moving = robot.capsules.iter().filter(|c| c.role != LinkRole::Base).count();
    let mut rng = rng(11);
    for _ in 0..200 {
        let pose = arm_pose(&robot, &random_q(&robot, &mut rng));
        let scene = CollisionScene::new(&random_scene(&mut rng));
        // An influence no bounding sphere can exceed: every pair, queried.
        let all = distances(&robot, &pose, &scene, &DistanceOptions { influence: 1e3 });
        assert!(all.len() >= moving * scene.len());
        let influence = rng.random_range(0.01..0.3);
        let near = distances(&robot, &pose, &scene, &DistanceOptions { influence });
        for p in &all {
            let kept = near.iter().find(|n| n.link == p.link && n.obstacle == p.obstacle);
            if p.distance < influence - TOL {
                let kept = kept.unwrap_or_else(|| panic!("dropped {} {}", p.link, p.obstacle));
                assert!((kept.distance - p.distance).abs() < TOL);
            } else if p.distance > influence + TOL {
                assert!(kept.is_none());
            }
            assert!((p.normal.norm() - 1.0).abs() < TOL);
        }
        // min_distance is the smallest of them all.
        let best = all.iter().min_by(|a, b| a.distance.total_cmp(&b.distance));
        let (d, link, obstacle) = min_distance(&robot, &pose, &scene).expect("pairs exist");
        let best = best.expect("pairs exist");
        assert!((d - best.distance).abs() < TOL, "{d} vs {}", best.distance);
        let named = all.iter().find(|p| p.link == link && p.obstacle == obstacle);
        assert!(named.is_some_and(|p| (p.distance - d).abs() < TOL), "{link} {obstacle}");
    }
}

#[test]
fn empty_scene_keeps_self_pairs_only() {
    let robot = load("coman_right_arm");
    let pose = arm_pose(&robot, &random_q(&robot, &mut rng(3)));
    let scene = CollisionScene::new(&[]);
    let all = distances(&robot, &pose, &scene, &DistanceOptions { influence: 1e3 });
    let index = |name: &str| robot.capsules.iter().position(|c| c.name == name).expect("a capsule");
    for p in &all {
        let pair = (index(&p.link), index(&p.obstacle));
        assert!(robot.self_pairs.contains(&pair), "{p:?}");
    }
    assert_eq!(all.len(), robot.self_pairs.len());
    assert_eq!(min_distance(&robot, &pose, &scene).is_some(), !robot.self_pairs.is_empty());
}

/// The self pairs follow from the geometry: never between adjacent bodies (no body carrying
/// geometry between them), never in contact at home, the farther capsule first; the Panda's hand is checked against its upper arm and
/// base, and an SRDF beside the URDF removes the pairs it disables.
#[test]
fn self_pairs_come_from_the_geometry_and_the_srdf() {
    for (name, robot) in all_robots() {
        let home = arm_pose(&robot, &a2ml::robot::home(&robot.joints));
        let capsules = a2ml::collision::arm_capsules(&robot, &home);
        for &(a, b) in &robot.self_pairs {
            let (ca, cb) = (&robot.capsules[a], &robot.capsules[b]);
            let between = robot.capsules.iter().any(|c| c.frame > cb.frame && c.frame < ca.frame);
            assert!(ca.frame > cb.frame + 1 && between, "{name}: {} {}", ca.name, cb.name);
            let (pa, pb) = (&capsules[a], &capsules[b]);
            let d = a2ml::math::segment_segment_distance(&pa.a, &pa.b, &pb.a, &pb.b)
                - pa.radius
                - pb.radius;
            assert!(
                d >= a2ml::robot::SELF_CONTACT_MARGIN,
                "{name}: {} {} at {d}",
                ca.name,
                cb.name
            );
        }
    }
    let panda = load("panda");
    let named = |robot: &a2ml::Robot, a: &str, b: &str| {
        robot
            .self_pairs
            .iter()
            .any(|&(i, j)| robot.capsules[i].name == a && robot.capsules[j].name == b)
    };
    assert!(named(&panda, "finger_left", "upper_arm"));
    assert!(named(&panda, "gripper_0", "base"));
    // The same URDF with an SRDF beside it.
    let dir = std::env::temp_dir().join(format!("a2ml_srdf_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let urdf = std::fs::read_to_string(crate::common::robot_path("panda")).expect("urdf");
    std::fs::write(dir.join("panda.urdf"), &urdf).expect("write");
    std::fs::write(
        dir.join("panda.srdf"),
        "<robot name=\"panda\">\n  <disable_collisions link1=\"hand\" link2=\"panda_link3\" \
         reason=\"Never\"/>\n</robot>\n",
    )
    .expect("write");
    let with_srdf = a2ml::Robot::from_urdf_file(dir.join("panda.urdf")).expect("loads");
    assert_eq!(with_srdf.allowed_pairs, vec![("hand".to_owned(), "panda_link3".to_owned())]);
    assert!(!named(&with_srdf, "finger_left", "upper_arm"));
    assert!(named(&with_srdf, "gripper_0", "base"));
    // A bad SRDF is a located error.
    std::fs::write(
        dir.join("panda.srdf"),
        "<robot>\n\n  <disable_collisions link1=\"hand\" link2=\"panda_link33\"/>\n</robot>",
    )
    .expect("write");
    match a2ml::Robot::from_urdf_file(dir.join("panda.urdf")) {
        Err(a2ml::RobotError::Srdf { line: Some(3), message, path: Some(_) }) => {
            assert!(message.contains("panda_link33"), "{message}")
        }
        other => panic!("{other:?}"),
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn the_collision_model_agrees_with_min_distance() {
    for (name, robot) in all_robots() {
        let mut rng = rng(23);
        let mut close = 0;
        for _ in 0..300 {
            let scene = CollisionScene::new(&random_scene(&mut rng));
            let model = CollisionModel::new(&robot, &scene);
            for _ in 0..5 {
                let q = random_q(&robot, &mut rng);
                let (expected, link, obstacle) =
                    min_distance(&robot, &arm_pose(&robot, &q), &scene).expect("pairs");
                let found = clearance(&model, &q);
                // parry's distance to a cylinder (o3) is iterative (GJK) and stops up to
                // ~1e-5 m above the true distance; the model's closed form is within 1e-11 of
                // a brute-force minimum (the unit test
                // `segment_distances_to_cylinders_match_brute_force`), so it may be below
                // parry by that much, never above.
                let context = format!("{name}: {found} vs {expected} ({link}, {obstacle})");
                if obstacle == "o3" {
                    assert!(found < expected + 1e-8 && found > expected - 2e-5, "{context}");
                } else {
                    assert!((found - expected).abs() < TOL, "{context}");
                }
                if expected < 0.05 {
                    close += 1;
                }
            }
        }
        assert!(close > 100, "{name}: too few close or penetrating configurations: {close}");
    }
}

#[test]
fn advancement_keeps_the_clearance_either_way() {
    for (name, robot) in all_robots() {
        let mut rng = rng(29);
        let mut moved = 0;
        for _ in 0..200 {
            let scene = CollisionScene::new(&random_scene(&mut rng));
            let model = CollisionModel::new(&robot, &scene);
            let q = random_q(&robot, &mut rng);
            let dq = random_q(&robot, &mut rng) - q;
            let kept = rng.random_range(0.0..0.05);
            let s = advancement(&model, &q, &dq, kept);
            for least in [-1.0, 0.0, 0.5 * s, s, 2.0 * s, rng.random_range(0.0..0.2)] {
                let expected = (s >= least).then_some(s);
                assert_eq!(advancement_at_least(&model, &q, &dq, kept, least), expected);
            }
            let d = |q| {
                min_distance(&robot, &arm_pose(&robot, &q), &scene).map_or(Real::INFINITY, |m| m.0)
            };
            assert_eq!(s < 0.0, d(q) < kept, "{name}: {s} at {}", d(q));
            if s <= 0.0 || !s.is_finite() {
                continue;
            }
            moved += 1;
            for k in -20..=20 {
                let t = s * k as Real / 20.0;
                assert!(d(q + dq * t) >= kept - TOL, "{name}: at {t} of {s}");
            }
        }
        assert!(moved > 50, "{name}: too few configurations clear to move from: {moved}");
    }
}

/// Both Panda models of the MotionBenchMaker comparison: capsules with the hand, and VAMP's
/// 59 spheres.
fn mbm_models() -> Vec<(&'static str, a2ml::Robot)> {
    vec![("capsules", load("panda")), ("spheres", sphere_panda())]
}

/// On the MotionBenchMaker scenes (thin shelves, rotated boxes and cylinders), the collision
/// model's clearance is parry's pair-by-pair minimum: within 1e-8 m where the arm is clear,
/// and of the same sign where it is not; and its advancement is safe along the motion and
/// agrees with the bounded queries the RRT's edge checks make.
#[test]
fn the_collision_model_agrees_with_min_distance_on_mbm_scenes() {
    for (model_name, robot) in mbm_models() {
        let mut rng = rng(31);
        let (mut close, mut colliding, mut moved) = (0, 0, 0);
        for scene_name in crate::mbm_problems::SCENES {
            let problem = crate::mbm_problems::problems(scene_name).swap_remove(0);
            let scene = CollisionScene::new(&problem.obstacles);
            let model = CollisionModel::new(&robot, &scene);
            let d = |q: &a2ml::math::JointVector| {
                min_distance(&robot, &arm_pose(&robot, q), &scene).map_or(Real::INFINITY, |m| m.0)
            };
            for _ in 0..60 {
                let q = random_q(&robot, &mut rng);
                let (expected, found) = (d(&q), clearance(&model, &q));
                let context = format!("{model_name}/{scene_name}: {found} vs {expected}");
                if expected > 1e-9 {
                    assert!((found - expected).abs() < 1e-8, "{context}");
                    close += usize::from(expected < 0.05);
                } else if expected < -1e-9 {
                    assert!(found < 0.0, "{context}");
                    colliding += 1;
                }
                assert_eq!(found.to_bits(), clearance(&model, &q).to_bits(), "{context}");
                // A motion of an RRT step's length (2 rad).
                let toward = random_q(&robot, &mut rng) - q;
                let dq = toward * (2.0 / toward.norm());
                let kept = 0.01;
                let s = advancement(&model, &q, &dq, kept);
                assert_eq!(s < 0.0, expected < kept, "{context}: advancement {s}");
                for (least, enough) in
                    [(0.0, 1.0), (0.5 * s, 0.5), (s, Real::INFINITY), (0.01, 0.02)]
                {
                    let capped = s.min(enough);
                    let expected = (capped >= least).then_some(capped);
                    let within = advancement_within(&model, &q, &dq, kept, least, enough);
                    assert_eq!(within, expected, "{context}: within {least}..{enough}");
                }
                if s <= 0.0 || !s.is_finite() {
                    continue;
                }
                moved += 1;
                for k in -10..=10 {
                    let t = s * k as Real / 10.0;
                    let at = d(&(q + dq * t));
                    assert!(at >= kept - 1e-9, "{context}: {at} at {t} of {s}");
                }
            }
        }
        assert!(
            close > 20 && colliding > 20 && moved > 20,
            "{model_name}: {close} {colliding} {moved}"
        );
    }
}
