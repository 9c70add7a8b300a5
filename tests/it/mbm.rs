//! The seven MotionBenchMaker scenes (tests/data/mbm): rotated boxes and cylinders read into
//! a scene, and joint-space RRT paths among them re-checked densely and independently.

use a2ml::collision::{CollisionScene, min_distance};
use a2ml::kinematics::arm_pose;
use a2ml::language::Shape;
use a2ml::math::{Matrix3, Real};
use a2ml::solve::rrt::{RrtError, RrtOptions, rrt_connect};

use crate::common::load;
use crate::mbm_problems::{SCENES, problems};

#[test]
fn motion_bench_maker_paths_keep_the_clearance() {
    let robot = load("panda");
    let options = RrtOptions::default();
    let mut solved = 0;
    for scene_name in SCENES {
        let problems = problems(scene_name);
        assert_eq!(problems.len(), 100);
        for problem in problems.iter().take(4) {
            let rotated = problem.obstacles.iter().filter(|o| match &o.shape {
                Shape::Box { rotation, .. } | Shape::Cylinder { rotation, .. } => {
                    (rotation.matrix() - Matrix3::identity()).amax() > 1e-6
                }
                _ => false,
            });
            assert!(rotated.count() > 0, "{scene_name}: the scene has rotated shapes");
            let scene = CollisionScene::new(&problem.obstacles);
            let path = match rrt_connect(&robot, &scene, &problem.start, &problem.goals, &options) {
                Ok(path) => path,
                // The capsule model may find an end invalid that VAMP's spheres find clear, and
                // a search may use its budget: counted as unsolved, and bounded below.
                Err(
                    RrtError::InvalidStart { .. }
                    | RrtError::NoValidGoal { .. }
                    | RrtError::NoPath { .. },
                ) => continue,
                Err(e) => panic!("{scene_name}: {e}"),
            };
            solved += 1;
            for w in path.waypoints.windows(2) {
                let count = ((w[1] - w[0]).abs().sum() * 1.5 / 1e-3).ceil().max(1.0) as usize;
                for k in 0..=count {
                    let q = w[0] + (w[1] - w[0]) * (k as Real / count as Real);
                    let (d, link, o) =
                        min_distance(&robot, &arm_pose(&robot, &q), &scene).expect("pairs");
                    assert!(d >= options.clearance, "{scene_name}: {link} {d:.5} m from {o}");
                }
            }
        }
    }
    assert!(solved >= 14, "only {solved} of 28 problems solved");
}
