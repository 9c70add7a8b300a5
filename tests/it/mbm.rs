//! The seven MotionBenchMaker scenes (tests/data/mbm): rotated boxes and cylinders read into
//! a scene, and joint-space RRT paths among them re-checked densely and independently.

use a2ml::collision::{
    CollisionModel, CollisionScene, DistanceOptions, Inflation, Pairs, Verdict, clearance,
    coverage, distances, is_clear, min_distance, motion_bound, self_motion_bound, verdict,
    verdict_of,
};
use a2ml::kinematics::arm_pose;
use a2ml::language::Shape;
use a2ml::math::{JointVector, Matrix3, Real};
use a2ml::robot::Robot;
use a2ml::solve::rrt::{RrtError, RrtOptions, rrt_connect};
use rand::RngExt;

use crate::common::{load, rng, sphere_panda};
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

/// The discrete edge check of the RRT is sound: on random edges in the MBM scenes, with both
/// arm models and two clearances, an edge whose evenly spaced points all keep the clearance
/// with every shape inflated by the farthest it moves over half their spacing ([`Inflation`])
/// keeps it at 1000 points along it by the independent `min_distance`; the uninflated
/// check agrees with `clearance` at every point checked, and the one-pass `verdict` with the
/// two checks.
#[test]
fn edges_the_inflated_checks_call_clear_are_clear() {
    let spheres = sphere_panda();
    let mut rng = rng(22);
    for (model_name, robot) in [("spheres", spheres), ("capsules", load("panda"))] {
        let (lower, upper) = (robot.lower(), robot.upper());
        for (s, scene_name) in SCENES.iter().enumerate() {
            let problem = &problems(scene_name)[s];
            let scene = CollisionScene::new(&problem.obstacles);
            let model = CollisionModel::new(&robot, &scene);
            let none = Inflation::none(&model);
            let margin = if s % 2 == 0 { 0.0 } else { 0.01 };
            let (mut proven, mut blocked) = (0, 0);
            for _ in 0..1000 {
                if proven >= 8 && blocked > 0 {
                    break;
                }
                let a = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
                let towards = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
                let b = a + (towards - a) * rng.random_range(0.05..0.6);
                let dq = b - a;
                // Coarse spacings too, where an edge's points are far apart.
                let spacing = [0.05, 0.2, 1.0, 4.0][rng.random_range(0..4)];
                let n = (motion_bound(&model, &dq) / spacing).ceil().max(1.0) as usize;
                let inflation = Inflation::along(&model, &dq, 0.5 / n as Real);
                let mut clear = true;
                for k in 0..=n {
                    let q = a + dq * (k as Real / n as Real);
                    let exact = clearance(&model, &q);
                    let plain = is_clear(&model, &q, margin, &none);
                    assert!(
                        if plain { exact >= margin - 1e-9 } else { exact < margin + 1e-9 },
                        "{model_name}/{scene_name}: is_clear {plain}, clearance {exact}"
                    );
                    let inflated = is_clear(&model, &q, margin, &inflation);
                    // The one-pass verdict answers both questions as the two checks do.
                    let expected = match (inflated, plain) {
                        (true, _) => Verdict::Clear,
                        (false, true) => Verdict::Tight,
                        (false, false) => Verdict::Blocked,
                    };
                    assert_eq!(
                        verdict(&model, &q, margin, &inflation),
                        expected,
                        "{model_name}/{scene_name}: the verdict at {q:?}"
                    );
                    clear &= inflated;
                }
                if !clear {
                    blocked += 1;
                    continue;
                }
                proven += 1;
                let points = (0..=1000).map(|k| a + dq * (k as Real / 1000.0));
                let label = format!("{model_name}/{scene_name}");
                assert_points_keep(&robot, &scene, points, margin, Pairs::All, &label);
            }
            assert!(proven > 0 && blocked > 0, "{model_name}/{scene_name}: {proven} {blocked}");
        }
    }
}

/// An inflation halved k times in place ([`Inflation::set_share`] of 2^-k) answers as one set
/// along the motion over 2^-k of the units, verdict for verdict, in both arm models, where the
/// verdicts of the halvings differ (so the factor is used, not only carried).
#[test]
fn a_halved_inflation_answers_as_one_set_over_the_halved_stretch() {
    let spheres = sphere_panda();
    let mut rng = rng(23);
    for (model_name, robot) in [("spheres", spheres), ("capsules", load("panda"))] {
        let (lower, upper) = (robot.lower(), robot.upper());
        let mut differing = 0;
        for (s, scene_name) in SCENES.iter().enumerate() {
            let problem = &problems(scene_name)[s];
            let scene = CollisionScene::new(&problem.obstacles);
            let model = CollisionModel::new(&robot, &scene);
            let margin = if s % 2 == 0 { 0.0 } else { 0.01 };
            for _ in 0..100 {
                let q = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
                let towards = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
                let dq = towards - q;
                let units = rng.random_range(0.01..0.5);
                let mut halved = Inflation::along(&model, &dq, units);
                let mut seen = Vec::new();
                for k in 0..8 {
                    halved.set_share((0.5 as Real).powi(k));
                    let fresh = Inflation::along(&model, &dq, units / (1 << k) as Real);
                    let found = verdict(&model, &q, margin, &halved);
                    assert_eq!(
                        found,
                        verdict(&model, &q, margin, &fresh),
                        "{model_name}/{scene_name}: {k} halvings at {q:?}"
                    );
                    assert_eq!(
                        is_clear(&model, &q, margin, &halved),
                        is_clear(&model, &q, margin, &fresh),
                        "{model_name}/{scene_name}: {k} halvings at {q:?}"
                    );
                    seen.push(found);
                }
                differing += usize::from(seen.iter().any(|&v| v != seen[0]));
            }
        }
        assert!(differing > 5, "{model_name}: {differing} configurations with differing verdicts");
    }
}

/// The passes over the obstacles alone and the self pairs alone ([`verdict_of`]) make the
/// pass over all pairs: blocked when either is, clear when both are, tight otherwise; on
/// random configurations and inflations in the MBM scenes, with both arm models, where each
/// of the three verdicts occurs. An inflation set for one part alone
/// ([`Inflation::set_along_of`]) answers for it as the whole inflation does.
#[test]
fn the_obstacles_and_the_self_pairs_pass_make_the_whole() {
    let spheres = sphere_panda();
    let mut rng = rng(24);
    for (model_name, robot) in [("spheres", spheres), ("capsules", load("panda"))] {
        let (lower, upper) = (robot.lower(), robot.upper());
        let mut seen = [0; 3];
        for (s, scene_name) in SCENES.iter().enumerate() {
            let problem = &problems(scene_name)[s];
            let model = CollisionModel::new(&robot, &CollisionScene::new(&problem.obstacles));
            let margin = if s % 2 == 0 { 0.0 } else { 0.01 };
            for _ in 0..200 {
                let q = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
                let towards = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
                let (dq, units) = (towards - q, rng.random_range(0.0..0.3));
                let inflation = Inflation::along(&model, &dq, units);
                let obstacles = verdict_of(&model, &q, margin, &inflation, Pairs::Obstacles);
                let own = verdict_of(&model, &q, margin, &inflation, Pairs::SelfPairs);
                // An inflation set for some pairs answers for them as the whole one does, and
                // for the others as if inflated without bound: never clear.
                let none = Inflation::none(&model);
                for (set, other) in
                    [(Pairs::Obstacles, Pairs::SelfPairs), (Pairs::SelfPairs, Pairs::Obstacles)]
                {
                    let mut part = Inflation::none(&model);
                    part.set_along_of(&model, &dq, units, set);
                    let whole = verdict_of(&model, &q, margin, &inflation, set);
                    assert_eq!(verdict_of(&model, &q, margin, &part, set), whole);
                    let unbounded = match verdict_of(&model, &q, margin, &none, other) {
                        Verdict::Clear => Verdict::Tight,
                        plain => plain,
                    };
                    assert_eq!(verdict_of(&model, &q, margin, &part, other), unbounded);
                    assert!(!is_clear(&model, &q, margin, &part));
                }
                let whole = verdict(&model, &q, margin, &inflation);
                assert_eq!(whole, verdict_of(&model, &q, margin, &inflation, Pairs::All));
                let expected = match (obstacles, own) {
                    (Verdict::Blocked, _) | (_, Verdict::Blocked) => Verdict::Blocked,
                    (Verdict::Clear, Verdict::Clear) => Verdict::Clear,
                    _ => Verdict::Tight,
                };
                assert_eq!(whole, expected, "{model_name}/{scene_name}: {obstacles:?} {own:?}");
                seen[whole as usize] += 1;
            }
        }
        assert!(seen.iter().all(|&n| n > 0), "{model_name}: verdicts seen {seen:?}");
    }
}

/// The self pairs' discrete edge check is sound over their own relative motion: on random
/// edges, with no obstacles, an edge whose n + 1 evenly spaced points (n from
/// `self_motion_bound` and a spacing) all keep the clearance with every self pair inflated by
/// its relative motion over half their spacing keeps it at 1000 points along it by the
/// independent `min_distance` (the self pairs alone in an empty scene); both outcomes occur.
#[test]
fn edges_the_self_pair_checks_call_clear_are_clear() {
    let empty = CollisionScene::new(&[]);
    let mut rng = rng(25);
    for (model_name, robot) in [("spheres", sphere_panda()), ("capsules", load("panda"))] {
        let (lower, upper) = (robot.lower(), robot.upper());
        let model = CollisionModel::new(&robot, &empty);
        let (mut proven, mut blocked) = (0, 0);
        for trial in 0..2000 {
            if proven >= 30 && blocked >= 5 {
                break;
            }
            let margin = if trial % 2 == 0 { 0.0 } else { 0.01 };
            let a = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
            let towards = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
            let dq = (towards - a) * rng.random_range(0.05..1.0);
            let travel = self_motion_bound(&model, &dq);
            assert!(travel <= motion_bound(&model, &dq), "{model_name}: {travel}");
            let spacing = [0.1, 0.4, 1.0][rng.random_range(0..3)];
            let n = (travel / spacing).ceil().max(1.0) as usize;
            let inflation = Inflation::along(&model, &dq, 0.5 / n as Real);
            let clear = (0..=n).all(|k| {
                let q = a + dq * (k as Real / n as Real);
                verdict_of(&model, &q, margin, &inflation, Pairs::SelfPairs) == Verdict::Clear
            });
            if !clear {
                blocked += 1;
                continue;
            }
            proven += 1;
            let points = (0..=1000).map(|k| a + dq * (k as Real / 1000.0));
            assert_points_keep(&robot, &empty, points, margin, Pairs::SelfPairs, model_name);
        }
        assert!(proven >= 30 && blocked >= 5, "{model_name}: {proven} proven, {blocked} blocked");
    }
}

/// A check that keeps the clearance under a share c of an inflation along a motion over s
/// units ([`coverage`]) covers c·s units either way: on random configurations and motions in
/// the MBM scenes, with both arm models and two clearances, every pair keeps the clearance at
/// 200 points of that stretch by the independent `min_distance`; `None` only where a pair is
/// within it at the point itself, 1 exactly where the verdict is clear, and shares strictly
/// between 0 and 1 occur (the partial covering is used, not only carried).
#[test]
fn the_share_of_an_inflation_a_check_keeps_covers_that_share_of_its_stretch() {
    let mut rng = rng(26);
    for (model_name, robot) in [("spheres", sphere_panda()), ("capsules", load("panda"))] {
        let (lower, upper) = (robot.lower(), robot.upper());
        let mut partial = 0;
        for (s, scene_name) in SCENES.iter().enumerate() {
            let problem = &problems(scene_name)[s];
            let scene = CollisionScene::new(&problem.obstacles);
            let model = CollisionModel::new(&robot, &scene);
            let none = Inflation::none(&model);
            for trial in 0..60 {
                let margin = if trial % 2 == 0 { 0.0 } else { 0.01 };
                let pairs = [Pairs::All, Pairs::Obstacles, Pairs::SelfPairs][trial % 3];
                let q = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
                let towards = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
                let dq = towards - q;
                let units = rng.random_range(0.01..0.4);
                let mut inflation = Inflation::along(&model, &dq, units);
                // Shares set on top of the inflation scale it as one set over fewer units.
                let share = [1.0, 0.5, 0.3][trial % 3];
                inflation.set_share(share);
                let found = coverage(&model, &q, margin, &inflation, pairs);
                let plain = verdict_of(&model, &q, margin, &none, pairs);
                assert_eq!(found.is_none(), plain == Verdict::Blocked, "{model_name}/{scene_name}");
                let Some(c) = found else { continue };
                assert!((0.0..=1.0).contains(&c), "{model_name}/{scene_name}: share {c}");
                let verdict = verdict_of(&model, &q, margin, &inflation, pairs);
                assert_eq!(c == 1.0, verdict == Verdict::Clear, "{model_name}/{scene_name}");
                partial += usize::from(c > 0.0 && c < 1.0);
                let reach = c * share * units;
                let points = (0..=200).map(|k| q + dq * (reach * (2.0 * k as Real / 200.0 - 1.0)));
                let label = format!("{model_name}/{scene_name}");
                assert_points_keep(&robot, &scene, points, margin, pairs, &label);
            }
        }
        assert!(partial > 10, "{model_name}: {partial} partial shares");
    }
}

/// Asserts that `pairs` keep `margin` (less 1e-9 m) at every one of `points`, by the
/// independent distances: [`min_distance`] for all pairs and the self pairs (those alone in an
/// empty scene; there must be some), [`distances`] for the obstacles (the pairs closer than
/// 5 cm whose other shape is not the robot's; none closer passes).
fn assert_points_keep(
    robot: &Robot,
    scene: &CollisionScene,
    points: impl Iterator<Item = JointVector>,
    margin: Real,
    pairs: Pairs,
    label: &str,
) {
    let empty = CollisionScene::new(&[]);
    for q in points {
        let pose = arm_pose(robot, &q);
        let closest = match pairs {
            Pairs::All | Pairs::SelfPairs => {
                let scene = if pairs == Pairs::All { scene } else { &empty };
                Some(min_distance(robot, &pose, scene).expect("the robot has pairs"))
            }
            Pairs::Obstacles => {
                let options = DistanceOptions { influence: 0.05 };
                distances(robot, &pose, scene, &options)
                    .into_iter()
                    .filter(|p| p.obstacle_frame.is_none())
                    .min_by(|a, b| a.distance.total_cmp(&b.distance))
                    .map(|p| (p.distance, p.link, p.obstacle))
            }
        };
        if let Some((d, link, other)) = closest {
            assert!(d >= margin - 1e-9, "{label}: {pairs:?}: {link} {d} m from {other} at {q:?}");
        }
    }
}
