//! Joint-space RRT-Connect: every path re-checked densely and independently (1 mm of arm-point
//! motion between checks), limits, determinism per seed, and clear failures.

use a2ml::Robot;
use a2ml::collision::{CollisionModel, CollisionScene, arm_capsules, min_distance};
use a2ml::kinematics::arm_pose;
use a2ml::language::{Obstacle, Shape};
use a2ml::math::{JointVector, Real, Vector3};
use a2ml::robot::LinkRole;
use a2ml::solve::rrt::{
    DynamicDomain, RrtError, RrtOptions, RrtPath, rrt_connect, rrt_connect_with, time_parameterise,
};
use a2ml::trajectory::{Limits, peaks};

use crate::common;

/// The Panda caged by 14 spheres (tests/data/panda_sphere_cage.json, instance `k`), in
/// {b}: the file's frame is the URDF root, S is 0.333 m above it.
fn sphere_cage(k: usize) -> (JointVector, JointVector, CollisionScene) {
    let (start, goal, spheres) = cage_spheres(k);
    (start, goal, CollisionScene::new(&spheres))
}

/// The start, goal and spheres of [`sphere_cage`].
fn cage_spheres(k: usize) -> (JointVector, JointVector, Vec<Obstacle>) {
    let path = format!("{}/tests/data/panda_sphere_cage.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path)
        .expect("tests/data/panda_sphere_cage.json is in the repository");
    let data: serde_json::Value = serde_json::from_str(&text).expect("json");
    let vector = |v: &serde_json::Value| -> Vec<Real> {
        v.as_array().expect("array").iter().map(|x| x.as_f64().expect("number")).collect()
    };
    let q = |key: &str| JointVector::from_column_slice(&vector(&data[key]));
    let radius = data["radius"].as_f64().expect("radius");
    let obstacles: Vec<Obstacle> = data["instances"][k]
        .as_array()
        .expect("instance")
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let c = vector(c);
            Obstacle {
                name: format!("sphere{i}"),
                shape: Shape::Sphere { center: Vector3::new(c[0], c[1], c[2] - 0.333), radius },
            }
        })
        .collect();
    (q("start"), q("goal"), obstacles)
}

/// Every edge at points no more than 1 mm of arm motion apart (bounded by 1.5 m of lever per
/// radian, more than any shipped arm's reach): within limits and `clearance` from the scene.
fn assert_collision_free(robot: &Robot, scene: &CollisionScene, path: &RrtPath, clearance: Real) {
    for w in path.waypoints.windows(2) {
        let (a, b) = (w[0], w[1]);
        let count = ((b - a).abs().sum() * 1.5 / 1e-3).ceil().max(1.0) as usize;
        for k in 0..=count {
            let q = a + (b - a) * (k as Real / count as Real);
            assert!(robot.limit_violation(&q, 0.0).is_none(), "outside the limits");
            if let Some((d, link, obstacle)) = min_distance(robot, &arm_pose(robot, &q), scene) {
                assert!(d >= clearance, "{link} {d:.4} m from {obstacle}");
            }
        }
    }
}

#[test]
fn the_caged_panda_finds_a_collision_free_path() {
    let robot = common::load("panda");
    let options = RrtOptions::default();
    for k in [0, 1, 2] {
        let (start, goal, scene) = sphere_cage(k);
        let path = rrt_connect(&robot, &scene, &start, &[goal], &options).expect("a path");
        assert_eq!(path.waypoints.first(), Some(&start));
        assert_eq!(path.waypoints.last(), Some(&goal));
        assert_collision_free(&robot, &scene, &path, options.clearance);
        assert!(path.stats.collision_checks > 0 && path.stats.nodes >= 2);
    }
}

/// An arm prepared once (in another scene) gives the very paths of `rrt_connect` in every
/// scene, and is refused for another robot.
#[test]
fn a_prepared_arm_gives_the_same_paths() {
    let robot = common::load("panda");
    let arm = CollisionModel::new(&robot, &sphere_cage(0).2);
    let options = RrtOptions::default();
    for k in [1, 2, 3] {
        let (start, goal, scene) = sphere_cage(k);
        let fresh = rrt_connect(&robot, &scene, &start, &[goal], &options).expect("a path");
        let prepared =
            rrt_connect_with(&arm, &robot, &scene, &start, &[goal], &options).expect("a path");
        assert_eq!(fresh.waypoints, prepared.waypoints);
        assert_eq!(fresh.stats.collision_checks, prepared.stats.collision_checks);
    }
    let (start, goal, scene) = sphere_cage(1);
    let other = common::load("iiwa14");
    assert!(matches!(
        rrt_connect_with(&arm, &other, &scene, &start, &[goal], &options),
        Err(RrtError::InvalidOptions { .. })
    ));
}

#[test]
fn the_same_seed_gives_the_same_path() {
    let robot = common::load("panda");
    let (start, goal, scene) = sphere_cage(3);
    let options = RrtOptions { seed: 7, ..RrtOptions::default() };
    let a = rrt_connect(&robot, &scene, &start, &[goal], &options).expect("a path");
    let b = rrt_connect(&robot, &scene, &start, &[goal], &options).expect("a path");
    assert_eq!(a.waypoints, b.waypoints);
    let other = RrtOptions { seed: 8, ..options };
    let c = rrt_connect(&robot, &scene, &start, &[goal], &other).expect("a path");
    assert_collision_free(&robot, &scene, &c, options.clearance);
}

/// The dynamic domain and the balanced trees (the default) and the plain RRT-Connect both find
/// paths that keep the clearance at every 1 mm, each the same for the same seed; a domain out
/// of range is refused.
#[test]
fn the_dynamic_domain_and_the_plain_growth_both_find_clear_paths() {
    let robot = common::load("panda");
    let plain = RrtOptions { dynamic_domain: None, balance: false, ..RrtOptions::default() };
    for options in [RrtOptions::default(), plain] {
        for k in [4, 5] {
            let (start, goal, scene) = sphere_cage(k);
            let a = rrt_connect(&robot, &scene, &start, &[goal], &options).expect("a path");
            let b = rrt_connect(&robot, &scene, &start, &[goal], &options).expect("a path");
            assert_eq!(a.waypoints, b.waypoints);
            assert_eq!(a.stats.collision_checks, b.stats.collision_checks);
            assert_eq!(a.waypoints.last(), Some(&goal));
            assert_collision_free(&robot, &scene, &a, options.clearance);
        }
    }
    let (start, goal, scene) = sphere_cage(0);
    let domain = DynamicDomain::default();
    for bad in [
        DynamicDomain { radius: 0.0, ..domain },
        DynamicDomain { min_radius: 5.0, ..domain },
        DynamicDomain { alpha: 1.0, ..domain },
        DynamicDomain { alpha: Real::NAN, ..domain },
    ] {
        let options = RrtOptions { dynamic_domain: Some(bad), ..RrtOptions::default() };
        assert!(matches!(
            rrt_connect(&robot, &scene, &start, &[goal], &options),
            Err(RrtError::InvalidOptions { .. })
        ));
    }
}

#[test]
fn invalid_ends_and_exhausted_searches_are_reported() {
    let robot = common::load("panda");
    let (start, goal, scene) = sphere_cage(0);
    let options = RrtOptions::default();
    // A goal outside the limits, and a start inside an obstacle.
    let mut outside = goal;
    outside[3] = 1.0;
    assert!(matches!(
        rrt_connect(&robot, &scene, &start, &[outside], &options),
        Err(RrtError::NoValidGoal { count: 1 })
    ));
    let wrist = arm_pose(&robot, &start).wrist;
    let block = CollisionScene::new(&[Obstacle {
        name: "block".into(),
        shape: Shape::Sphere { center: wrist, radius: 0.05 },
    }]);
    let message = rrt_connect(&robot, &block, &start, &[goal], &options)
        .expect_err("the start is in the block")
        .to_string();
    assert!(message.contains("from `block`"), "{message}");
    // Too few samples for the cage.
    let few = RrtOptions { max_samples: 1, ..options };
    match rrt_connect(&robot, &scene, &start, &[goal], &few) {
        Err(RrtError::NoPath { stats, closest }) => {
            assert_eq!(stats.samples, 1);
            assert!(closest > 0.0);
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        rrt_connect(&robot, &scene, &start, &[goal], &RrtOptions { step: 0.0, ..options }),
        Err(RrtError::InvalidOptions { .. })
    ));
}

/// The velocity QP leaves the arm at the safety distance (the clearance) from an obstacle:
/// such a start, and such a goal, must be planned from and to.
#[test]
fn an_end_just_beyond_the_clearance_is_planned_from_and_to() {
    let robot = common::load("panda");
    let options = RrtOptions::default();
    let (start, goal, cage) = cage_spheres(0);
    let pose = arm_pose(&robot, &start);
    let hand = arm_capsules(&robot, &pose)
        .into_iter()
        .find(|c| c.role == LinkRole::Hand)
        .expect("the Panda has a hand capsule");
    let side = (hand.b - hand.a).cross(&Vector3::z()).normalize();
    // A ball beside the hand at the start, 1 mm and 0.1 mm beyond the clearance: less than the
    // clearance plus the resolution, so a check that asked for that margin would refuse it.
    for slack in [1e-3, 1e-4] {
        let (radius, gap) = (0.03, options.clearance + slack);
        let center = 0.5 * (hand.a + hand.b) + side * (hand.radius + gap + radius);
        let ball = Obstacle { name: "beside".into(), shape: Shape::Sphere { center, radius } };
        let scene = CollisionScene::new(&[cage.clone(), vec![ball]].concat());
        let (d, _, obstacle) = min_distance(&robot, &pose, &scene).expect("pairs");
        assert!((d - gap).abs() < 1e-9 && obstacle == "beside", "{d} from {obstacle}");
        assert!(gap < options.clearance + options.resolution);
        for (from, to) in [(start, goal), (goal, start)] {
            let path = rrt_connect(&robot, &scene, &from, &[to], &options).expect("a path");
            assert_eq!((path.waypoints.first(), path.waypoints.last()), (Some(&from), Some(&to)));
            assert_collision_free(&robot, &scene, &path, options.clearance);
        }
    }
}

#[test]
fn a_path_is_timed_with_a_bell_within_the_speed_limits() {
    let robot = common::load("panda");
    let (start, goal, scene) = sphere_cage(0);
    let path = rrt_connect(&robot, &scene, &start, &[goal], &RrtOptions::default()).expect("path");
    // Asked for far too fast: stretched until the fastest joint just meets its limit.
    let limits = Limits::of(&robot);
    let timed = time_parameterise(&limits, &path.waypoints, 0.1, 100.0).expect("timed");
    assert!(timed.stretched && timed.duration > 0.1);
    let t = &timed.trajectory;
    assert!((t.positions()[0] - start).amax() < 1e-12);
    assert!((t.positions().last().expect("samples") - goal).amax() < 1e-9);
    assert!(
        t.velocities()[0].amax() < 1e-12 && t.velocities().last().expect("samples").amax() < 1e-9
    );
    let violations = a2ml::trajectory::check_limits(t, &robot, 1e-9);
    assert!(violations.is_empty(), "{:?}", violations.first());
    // Some joint meets its velocity or acceleration limit (within the planned share of it).
    let fastest = peaks(t, t.start(), t.end()).stretch(&limits);
    assert!(fastest > 0.9 && fastest <= 1.0, "the stretch is no longer than needed: {fastest}");
    // Asked for slowly enough: kept.
    let slow =
        time_parameterise(&limits, &path.waypoints, 3.0 * timed.duration, 100.0).expect("timed");
    assert!(!slow.stretched && (slow.duration - 3.0 * timed.duration).abs() < 1e-12);
    // Every sample lies on the path: within the timed trajectory, a dense re-check holds too.
    let dense = RrtPath { waypoints: slow.trajectory.positions().to_vec(), ..path };
    assert_collision_free(&robot, &scene, &dense, RrtOptions::default().clearance - 1e-9);
}
