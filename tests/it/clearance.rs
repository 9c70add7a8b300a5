//! The clearance kept by the joint-space RRT with a model of many spheres (VAMP's 59-sphere
//! Panda, tests/data/panda_spheres): every clearance plans, and every path is re-checked
//! densely and independently.

use a2ml::collision::{CollisionModel, CollisionScene, advancement, clearance, min_distance};
use a2ml::kinematics::arm_pose;
use a2ml::language::{Obstacle, Shape};
use a2ml::math::{JointVector, Real, Vector3};
use a2ml::solve::rrt::{RrtError, RrtOptions, rrt_connect};

use crate::common::{random_q, rng, sphere_panda};

/// Instance 0 of tests/data/panda_sphere_cage.json in {b} (S is 0.333 m above the root).
fn cage() -> (JointVector, JointVector, Vec<Obstacle>) {
    let path = format!("{}/tests/data/panda_sphere_cage.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("the cage is in the repository");
    let data: serde_json::Value = serde_json::from_str(&text).expect("json");
    let numbers = |v: &serde_json::Value| -> Vec<Real> {
        v.as_array().expect("array").iter().map(|x| x.as_f64().expect("number")).collect()
    };
    let q = |key: &str| JointVector::from_column_slice(&numbers(&data[key]));
    let radius = data["radius"].as_f64().expect("radius");
    let spheres = data["instances"][0]
        .as_array()
        .expect("instance")
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let c = numbers(c);
            let center = Vector3::new(c[0], c[1], c[2] - 0.333);
            Obstacle { name: format!("sphere{i}"), shape: Shape::Sphere { center, radius } }
        })
        .collect();
    (q("start"), q("goal"), spheres)
}

/// A configuration that keeps a clearance can move some way keeping it, whatever the
/// clearance: spheres on joint 1's axis do not move with it, and the bound of such a capsule
/// must not round it inside the clearance (it did at 9 and 10 mm, not at 9.9).
#[test]
fn a_clear_configuration_can_always_advance() {
    let robot = sphere_panda();
    let (start, _, spheres) = cage();
    let mut rng = rng(31);
    for scene in [CollisionScene::new(&[]), CollisionScene::new(&spheres)] {
        let model = CollisionModel::new(&robot, &scene);
        for _ in 0..20 {
            let q = if scene.is_empty() { random_q(&robot, &mut rng) } else { start };
            let dq = random_q(&robot, &mut rng) - q;
            let kept = clearance(&model, &q);
            let grid = (0..=200).map(|step| step as Real * 1e-4);
            for c in grid.chain([0.009, 0.0099, 0.01]) {
                if c < kept {
                    let s = advancement(&model, &q, &dq, c);
                    assert!(s > 0.0, "clearance {c} (kept {kept}): advancement {s}");
                }
            }
        }
    }
}

#[test]
fn the_sphere_panda_plans_at_every_clearance() {
    let robot = sphere_panda();
    let (start, goal, spheres) = cage();
    let scene = CollisionScene::new(&spheres);
    // The start keeps 15.2 mm between the spheres of links 7 and 5, a self pair the geometry
    // gives (VAMP's and MoveIt's Panda check it too): more is refused, typed.
    let options = RrtOptions { clearance: 0.02, ..RrtOptions::default() };
    match rrt_connect(&robot, &scene, &start, &[goal], &options) {
        Err(RrtError::InvalidStart { reason }) => {
            assert!(reason.contains("panda_link7"), "{reason}")
        }
        other => panic!("{other:?}"),
    }
    for c in [0.0, 0.005, 0.008, 0.009, 0.0099, 0.01, 0.015] {
        let options = RrtOptions { clearance: c, ..RrtOptions::default() };
        let path = rrt_connect(&robot, &scene, &start, &[goal], &options)
            .unwrap_or_else(|e| panic!("clearance {c}: {e}"));
        // Points no more than 1 mm of arm motion apart (1.5 m of lever per radian).
        for w in path.waypoints.windows(2) {
            let count = ((w[1] - w[0]).abs().sum() * 1.5 / 1e-3).ceil().max(1.0) as usize;
            for k in 0..=count {
                let q = w[0] + (w[1] - w[0]) * (k as Real / count as Real);
                assert!(robot.limit_violation(&q, 0.0).is_none(), "outside the limits");
                let (d, link, obstacle) =
                    min_distance(&robot, &arm_pose(&robot, &q), &scene).expect("pairs");
                assert!(d >= c, "clearance {c}: {link} {d:.5} m from {obstacle}");
            }
        }
    }
}
