use parry3d_f64::math::Pose;
use parry3d_f64::query;
use parry3d_f64::shape::Segment;
use rand::{RngExt, SeedableRng};

use super::*;
use crate::collision::{min_distance, to_parry};
use crate::kinematics::arm_pose;

const TOL: Real = 1e-9;

fn v(x: Real, y: Real, z: Real) -> Vector3 {
    Vector3::new(x, y, z)
}

/// parry's distance between two segments, for reference.
fn parry_segments(p1: &Vector3, q1: &Vector3, p2: &Vector3, q2: &Vector3) -> Real {
    let segment = |a: &Vector3, b: &Vector3| Segment::new(to_parry(a), to_parry(b));
    query::distance(&Pose::IDENTITY, &segment(p1, q1), &Pose::IDENTITY, &segment(p2, q2))
        .expect("segments are supported")
        .distance
}

#[test]
fn segment_distances_match_parry() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let mut point =
        || v(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
    for k in 0..5000 {
        let (p1, q1, p2, w) = (point(), point(), point(), point());
        // Parallel, degenerate, crossing and general second segments.
        let (p2, q2) = match k % 5 {
            0 => (p2, p2 + (q1 - p1) * 0.7),
            1 => (p2, p2),
            2 => (p1 + (q1 - p1) * 0.3 + w, p1 + (q1 - p1) * 0.3 - w),
            _ => (p2, w),
        };
        let expected = parry_segments(&p1, &q1, &p2, &q2);
        let found = segment_segment_distance(&p1, &q1, &p2, &q2);
        assert!((found - expected).abs() < TOL, "{k}: {found} vs {expected}");
        let squared = Posed::new(p1, q1, 0.0).squared_distance_to_point(&p2);
        assert!((squared.sqrt() - parry_segments(&p1, &q1, &p2, &p2)).abs() < TOL);
    }
    // A degenerate first segment too.
    let (p, a, b) = (v(0.0, 0.0, 1.0), v(-1.0, 0.0, 0.0), v(1.0, 0.0, 0.0));
    assert!((segment_segment_distance(&p, &p, &a, &b) - 1.0).abs() < TOL);
}

/// Along straight joint motions of one or two joints at random speeds (where the bound is
/// nearly tight), no point of a capsule's segment travels farther than its `Motion` allows:
/// from the base for the obstacle pairs, and from the other capsule's frame for the self
/// pairs.
#[test]
fn capsules_move_within_their_motion_bounds() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(13);
    for name in ["panda", "coman_right_arm", "centauro_right_arm", "iiwa14", "human_arm"] {
        let path = format!("{}/../../robots/{name}.urdf", env!("CARGO_MANIFEST_DIR"));
        let robot = Robot::from_urdf_file(path).expect("robot loads");
        let model = CollisionModel::new(&robot, &CollisionScene::new(&[]));
        let (lower, upper) = (robot.lower(), robot.upper());
        // (capsule, the frame it is seen from, its levers, the joints between)
        let mut cases: Vec<(usize, usize, JointVector, std::ops::Range<usize>)> = model
            .arm
            .groups
            .iter()
            .flat_map(|g| g.members.iter())
            .map(|&i| (i, 0, model.arm.links[i].levers, 0..model.arm.links[i].frame))
            .collect();
        for pair in &model.arm.self_pairs {
            let other = if pair.distal == pair.link { pair.other } else { pair.link };
            let seen_from = model.arm.links[other].frame;
            cases.push((pair.distal, seen_from, pair.levers, pair.joints.clone()));
        }
        let mut tightest: Real = 0.0;
        for _ in 0..400 {
            let q = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
            let (j, k) = (rng.random_range(0..DOF), rng.random_range(0..DOF));
            let mut dq = JointVector::zeros();
            dq[j] = rng.random_range(-3.0..3.0);
            dq[k] = rng.random_range(-3.0..3.0);
            let frames = model.arm.chain.frames(&q);
            for (i, seen_from, levers, joints) in cases.clone() {
                let capsule = &model.arm.links[i];
                let seen = |q: &JointVector| {
                    let frames = model.arm.chain.frames(q);
                    let (from, posed) = (&frames[seen_from], capsule.posed(&frames));
                    let local = |p: Vector3| from.rotation.transpose() * (p - from.translation);
                    (local(posed.a), local(posed.b))
                };
                let posed = capsule.posed(&frames);
                let motion = Motion::new(&frames, &posed, &levers, &dq.abs(), joints);
                let (mut travelled, mut last) = (0.0, seen(&q));
                for step in 1..=200 {
                    let s = step as Real / 200.0;
                    let now = seen(&(q + dq * s));
                    // The farther travelled of the two ends, bounding every point between.
                    travelled += (now.0 - last.0).norm().max((now.1 - last.1).norm());
                    last = now;
                    let bound = motion.threshold(s);
                    assert!(travelled <= bound + 1e-9, "{name}: {travelled} > {bound} at {s}");
                    if bound > 1e-3 {
                        tightest = tightest.max(travelled / bound);
                    }
                }
            }
        }
        assert!(tightest > 0.8, "{name}: the bound is never approached: {tightest}");
    }
}

/// The closed forms for a point against a turned box or cylinder give parry's signed distance,
/// outside and inside.
#[test]
fn point_distances_to_solids_match_parry() {
    use crate::language::Obstacle;
    let path = format!("{}/../../robots/panda.urdf", env!("CARGO_MANIFEST_DIR"));
    let robot = Robot::from_urdf_file(path).expect("robot loads");
    let mut rng = rand::rngs::StdRng::seed_from_u64(17);
    let mut number = |lo: Real, hi: Real| rng.random_range(lo..hi);
    for k in 0..2000 {
        let (center, shape) = random_solid(&mut number, k, [(0.05, 0.8); 3]);
        let scene = CollisionScene::new(&[Obstacle { name: "solid".into(), shape }]);
        let model = CollisionModel::new(&robot, &scene);
        let convex = &model.convex[0];
        let p = center + v(number(-0.6, 0.6), number(-0.6, 0.6), number(-0.6, 0.6));
        let point = parry3d_f64::shape::Ball::new(1e-300);
        let expected = query::contact(
            &convex.body.pose,
            convex.body.shape.as_dyn(),
            &Pose::from_translation(to_parry(&p)),
            &point,
            10.0,
        )
        .expect("supported")
        .expect("within the prediction")
        .dist;
        let found = convex.point_distance(&p);
        assert!((found - expected).abs() < 1e-7, "{k}: {found} vs {expected}");
    }
}

/// The closed-form distance from a segment to a turned box or cylinder: a lower bound within
/// [`SEGMENT_TOLERANCE`] of parry's where the segment stays outside, `None` exactly when that
/// distance is not below the bound asked for, and parry's depth where it enters.
#[test]
fn segment_distances_to_solids_match_parry() {
    use crate::language::Obstacle;
    let path = format!("{}/../../robots/panda.urdf", env!("CARGO_MANIFEST_DIR"));
    let robot = Robot::from_urdf_file(path).expect("robot loads");
    let mut rng = rand::rngs::StdRng::seed_from_u64(19);
    let mut number = |lo: Real, hi: Real| rng.random_range(lo..hi);
    let (mut outside, mut entering, mut refused) = (0, 0, 0);
    let mut worst_parry: Real = 0.0;
    for k in 0..4000 {
        // Thin boards too, as the shelves of the MotionBenchMaker scenes.
        let (center, shape) =
            random_solid(&mut number, k, [(0.005, 0.8), (0.05, 1.2), (0.05, 0.8)]);
        let scene = CollisionScene::new(&[Obstacle { name: "solid".into(), shape }]);
        let model = CollisionModel::new(&robot, &scene);
        let convex = &model.convex[0];
        let a = center + v(number(-0.7, 0.7), number(-0.7, 0.7), number(-0.7, 0.7));
        // Every other segment parallel to a box's face or a cylinder's axis, where the minimum
        // is a plateau.
        let b = if k % 4 == 1 || k % 4 == 2 {
            a + convex.rotation.column(k % 3) * number(-0.4, 0.4)
        } else {
            a + v(number(-0.4, 0.4), number(-0.4, 0.4), number(-0.4, 0.4))
        };
        let segment = Segment::new(to_parry(&a), to_parry(&b));
        let expected = query::contact(
            &convex.body.pose,
            convex.body.shape.as_dyn(),
            &Pose::IDENTITY,
            &segment,
            10.0,
        )
        .expect("supported")
        .expect("within the prediction")
        .dist;
        let found = convex.segment_distance(&a, &b, Real::INFINITY).expect("below ∞");
        if expected > 1e-9 {
            outside += 1;
            // parry's GJK stops up to ~1e-5 m above a cylinder's true distance, so the
            // reference outside is the exact point distance minimised along the segment.
            let brute = brute_segment_distance(convex, &a, &b);
            assert!(found <= brute + 1e-10, "{k}: {found} above {brute}");
            assert!(found >= brute - 1e-10, "{k}: {found} far below {brute}");
            assert!(expected >= brute - 1e-9, "{k}: parry {expected} below {brute}");
            worst_parry = worst_parry.max(expected - brute);
        } else if expected < -1e-9 {
            entering += 1;
            assert!((found - expected).abs() < 1e-9, "{k}: {found} vs {expected}");
        }
        // A bound above the distance keeps it; one below it is refused.
        let bound = expected + number(-0.05, 0.05);
        match convex.segment_distance(&a, &b, bound) {
            Some(d) => assert!(d < bound && (d - found).abs() < 1e-9, "{k}: {d} for {bound}"),
            None => {
                refused += 1;
                assert!(expected >= bound - 1e-9, "{k}: refused {expected} below {bound}")
            }
        }
    }
    assert!(outside > 1000 && entering > 100 && refused > 500, "{outside} {entering} {refused}");
    // Why the reference is not parry: its distance to some cylinders is this far above.
    assert!(worst_parry > 1e-7, "parry agrees with the exact distance to {worst_parry}");
}

/// The distance from the segment a–b to a solid outside it, independently of the tangent
/// search: the exact point distance sampled densely along the segment, then a golden-section
/// search (the distance is convex along it) in the best sample's neighbourhood.
fn brute_segment_distance(convex: &Convex, a: &Vector3, b: &Vector3) -> Real {
    let f = |t: Real| convex.point_distance(&(a + (b - a) * t));
    let n = 4000;
    let best = (0..=n).map(|i| i as Real / n as Real).min_by(|&s, &t| f(s).total_cmp(&f(t)));
    let best = best.expect("samples");
    let step = 1.0 / n as Real;
    let (mut lo, mut hi) = ((best - step).max(0.0), (best + step).min(1.0));
    for _ in 0..100 {
        let (m1, m2) = (lo + (hi - lo) * 0.382, lo + (hi - lo) * 0.618);
        if f(m1) < f(m2) { hi = m2 } else { lo = m1 }
    }
    f(best).min(f(0.5 * (lo + hi)))
}

/// A turned solid about the origin: a box (even `k`, its sides drawn from `box_sides`) or a
/// cylinder (odd `k`); its centre and its shape.
fn random_solid(
    number: &mut impl FnMut(Real, Real) -> Real,
    k: usize,
    box_sides: [(Real, Real); 3],
) -> (Vector3, crate::language::Shape) {
    use crate::language::Shape;
    let center = v(number(-1.0, 1.0), number(-1.0, 1.0), number(-1.0, 1.0));
    let rotation = Rotation3::from_euler_angles(number(-PI, PI), number(-PI, PI), number(-PI, PI));
    let shape = if k % 2 == 0 {
        let [x, y, z] = box_sides;
        let size = v(number(x.0, x.1), number(y.0, y.1), number(z.0, z.1));
        Shape::Box { center, size, rotation }
    } else {
        Shape::Cylinder { center, radius: number(0.02, 0.4), height: number(0.05, 0.8), rotation }
    };
    (center, shape)
}

/// The arm models whose self pairs the floors are tested on: VAMP's 59-sphere Panda (1028
/// pairs) and two capsule arms.
fn floor_robots() -> Vec<Robot> {
    let root = format!("{}/../..", env!("CARGO_MANIFEST_DIR"));
    ["tests/data/panda_spheres/panda_spheres.urdf", "robots/panda.urdf", "robots/iiwa14.urdf"]
        .iter()
        .map(|path| Robot::from_urdf_file(format!("{root}/{path}")).expect("robot loads"))
        .collect()
}

/// The same model with no floors: every self pair checked as before them.
fn without_floors(model: &CollisionModel) -> CollisionModel {
    let mut plain = model.clone();
    let arm = Arc::make_mut(&mut plain.arm);
    arm.self_pairs.iter_mut().for_each(|p| p.floor = Real::NEG_INFINITY);
    arm.hot.iter_mut().for_each(|p| p.floor = Real::NEG_INFINITY);
    arm.group_pairs.iter_mut().for_each(|g| g.floor = Real::NEG_INFINITY);
    plain
}

/// No self pair comes closer than its floor, at random configurations and at the corners of
/// the limits, and the spheres' floors rule out a good share of the pairs two joints apart
/// (more than a quarter above 5 cm: fewer would mean the grid bound had lost its use).
#[test]
fn self_pairs_keep_their_floors() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(29);
    for (r, robot) in floor_robots().iter().enumerate() {
        let model = CollisionModel::new(robot, &CollisionScene::new(&[]));
        let (lower, upper) = (robot.lower(), robot.upper());
        let mut tightest = Real::INFINITY;
        for k in 0..3000 {
            let q = JointVector::from_fn(|i, _| match k % 3 {
                0 => {
                    if rng.random_bool(0.5) {
                        lower[i]
                    } else {
                        upper[i]
                    }
                }
                _ => rng.random_range(lower[i]..upper[i]),
            });
            let frames = model.arm.chain.frames(&q);
            for pair in model.arm.self_pairs.iter().filter(|p| p.floor.is_finite()) {
                let d = model.arm.links[pair.link]
                    .posed(&frames)
                    .distance(&model.arm.links[pair.other].posed(&frames));
                assert!(d >= pair.floor, "robot {r}: {d} below its floor {}", pair.floor);
                tightest = tightest.min(d - pair.floor);
            }
        }
        // A capsule arm may have no pair within two joints (no floor); the spheres have many.
        assert!(
            tightest < 0.05 || (r > 0 && tightest == Real::INFINITY),
            "robot {r}: the floors are never approached ({tightest})"
        );
        if r == 0 {
            let two = model.arm.self_pairs.iter().filter(|p| p.joints.len() == 2);
            let high = two.clone().filter(|p| p.floor > 0.05).count();
            assert!(high * 4 > two.count(), "only {high} floors above 5 cm");
        }
    }
}

/// With the floors, clearance and every advancement are those of the plain check: the same
/// value (a floor only leaves out pairs that could not lower it), and `advancement_within`
/// the same answer, on random configurations and motions among a shelf's boards.
#[test]
fn floors_leave_clearance_and_advancement_unchanged() {
    use crate::language::{Obstacle, Shape};
    let board = |z: Real| Obstacle {
        name: format!("board {z}"),
        shape: Shape::Box {
            center: v(0.55, 0.0, z),
            size: v(0.3, 0.8, 0.02),
            rotation: Rotation3::identity(),
        },
    };
    let shelf = [board(0.2), board(0.6)];
    let mut rng = rand::rngs::StdRng::seed_from_u64(31);
    for (r, robot) in floor_robots().iter().enumerate() {
        for scene in [CollisionScene::new(&[]), CollisionScene::new(&shelf)] {
            let model = CollisionModel::new(robot, &scene);
            let plain = without_floors(&model);
            let (lower, upper) = (robot.lower(), robot.upper());
            for k in 0..2000 {
                let q = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
                let dq = JointVector::from_fn(|_, _| rng.random_range(-1.0..1.0))
                    * rng.random_range(0.01..2.0);
                let (fast, slow) = (clearance(&model, &q), clearance(&plain, &q));
                assert!((fast - slow).abs() <= 1e-12, "robot {r}, {k}: {fast} vs {slow}");
                let offset = [0.0, 0.01][k % 2];
                let (fast, slow) =
                    (advancement(&model, &q, &dq, offset), advancement(&plain, &q, &dq, offset));
                assert!(fast <= slow + 1e-12 && (fast - slow).abs() <= 1e-12, "{fast} vs {slow}");
                let (least, enough) = (rng.random_range(0.0..0.05), rng.random_range(0.05..1.0));
                let fast = advancement_within(&model, &q, &dq, offset, least, enough);
                let slow = advancement_within(&plain, &q, &dq, offset, least, enough);
                assert_eq!(fast.is_some(), slow.is_some(), "robot {r}, {k}");
                if let (Some(f), Some(s)) = (fast, slow) {
                    assert!(f <= s + 1e-12 && (f - s).abs() <= 1e-12, "{f} vs {s}");
                }
            }
        }
    }
}

/// A pair's rate from the per-query table is never below its own dot product (so the table
/// leaves out no pair the dot product keeps) and above it by rounding only.
#[test]
fn rate_table_bounds_every_pair_dot_product() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(37);
    for robot in floor_robots() {
        let model = CollisionModel::new(&robot, &CollisionScene::new(&[]));
        for _ in 0..200 {
            let speed = JointVector::from_fn(|_, _| rng.random_range(0.0..3.0));
            let rates = Rates::new(&model.arm.links, &speed);
            for (pair, hot) in model.arm.self_pairs.iter().zip(&model.arm.hot) {
                assert_eq!(
                    (pair.link, pair.other, pair.joints.start),
                    (hot.link, hot.other, hot.start)
                );
                let (table, dot) = (rates.rate(hot.distal, hot.start), pair.levers.dot(&speed));
                assert!(table >= dot && table <= dot * (1.0 + 1e-12), "{table} vs {dot}");
            }
        }
    }
}

/// A model made for another scene from a prepared arm answers as one built from scratch, bit
/// for bit: the arm's half depends on the robot alone.
#[test]
fn a_model_with_another_scene_answers_as_a_new_one() {
    use crate::language::{Obstacle, Shape};
    let shelf = [Obstacle {
        name: "board".to_owned(),
        shape: Shape::Box {
            center: v(0.5, 0.1, 0.3),
            size: v(0.3, 0.8, 0.02),
            rotation: Rotation3::from_euler_angles(0.1, 0.2, 0.3),
        },
    }];
    let mut rng = rand::rngs::StdRng::seed_from_u64(41);
    for robot in floor_robots() {
        let scene = CollisionScene::new(&shelf);
        let fresh = CollisionModel::new(&robot, &scene);
        let prepared = CollisionModel::new(&robot, &CollisionScene::new(&[])).with_scene(&scene);
        assert!(prepared.fits(&robot));
        let (lower, upper) = (robot.lower(), robot.upper());
        for _ in 0..300 {
            let q = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
            let dq = JointVector::from_fn(|_, _| rng.random_range(-1.0..1.0));
            assert_eq!(clearance(&fresh, &q).to_bits(), clearance(&prepared, &q).to_bits());
            let (a, b) =
                (advancement(&fresh, &q, &dq, 0.01), advancement(&prepared, &q, &dq, 0.01));
            assert_eq!(a.to_bits(), b.to_bits());
        }
    }
}

/// The independent distance (parry's, over every pair) of `robot` at `q` in `scene`: ∞ when
/// there is no pair.
fn independent_distance(robot: &Robot, scene: &CollisionScene, q: &JointVector) -> Real {
    min_distance(robot, &arm_pose(robot, q), scene).map_or(Real::INFINITY, |(d, _, _)| d)
}

/// The one-pass verdict on the self pairs alone (no obstacles, where the members-near-the-
/// other-group masks decide most pairs): uninflated, `Blocked` exactly where the independent
/// `min_distance` is within the clearance; inflated along a motion, `Clear` only where every
/// configuration the inflation covers keeps the clearance by `min_distance`, and always what
/// `is_clear` says with and without the inflation.
#[test]
fn verdicts_on_self_pairs_match_the_independent_distance() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(43);
    for (r, robot) in floor_robots().iter().enumerate() {
        let scene = CollisionScene::new(&[]);
        let model = CollisionModel::new(robot, &scene);
        let none = Inflation::none(&model);
        let (lower, upper) = (robot.lower(), robot.upper());
        let mut seen = [0; 3];
        for k in 0..1500 {
            let margin = if k % 2 == 0 { 0.0 } else { 0.01 };
            let q = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
            let exact = independent_distance(robot, &scene, &q);
            let plain = verdict(&model, &q, margin, &none);
            assert_ne!(plain, Verdict::Tight, "robot {r}: nothing is inflated");
            if (exact - margin).abs() > 1e-9 {
                assert_eq!(
                    plain == Verdict::Blocked,
                    exact < margin,
                    "robot {r}: {plain:?} at {exact} m"
                );
            }
            let dq = JointVector::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let s = rng.random_range(0.0..0.2);
            let inflation = Inflation::along(&model, &dq, s);
            let inflated = verdict(&model, &q, margin, &inflation);
            let expected = if is_clear(&model, &q, margin, &inflation) {
                Verdict::Clear
            } else if is_clear(&model, &q, margin, &none) {
                Verdict::Tight
            } else {
                Verdict::Blocked
            };
            assert_eq!(inflated, expected, "robot {r}");
            seen[inflated as usize] += 1;
            if inflated == Verdict::Clear {
                for t in 0..=20 {
                    let p = q + dq * (s * (t as Real / 10.0 - 1.0));
                    let d = independent_distance(robot, &scene, &p);
                    assert!(d >= margin - 1e-9, "robot {r}: {d} m within the covered motion");
                }
            }
        }
        // The spheres' self pairs come close often enough for every answer to occur.
        if r == 0 {
            assert!(seen.iter().all(|&n| n > 0), "verdicts seen {seen:?}");
        }
    }
}

/// Clearance and advancement on the self pairs alone (no obstacles, where the members-near-the-
/// other-group masks decide most pairs) against the independent `min_distance`: the clearance
/// is its value, and an advancement keeps the clearance over the whole motion it allows.
#[test]
fn clearance_and_advancement_on_self_pairs_match_the_independent_distance() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(47);
    for (r, robot) in floor_robots().iter().enumerate() {
        let scene = CollisionScene::new(&[]);
        let model = CollisionModel::new(robot, &scene);
        let (lower, upper) = (robot.lower(), robot.upper());
        let distance = |q: &JointVector| independent_distance(robot, &scene, q);
        for k in 0..1000 {
            let q = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
            let exact = distance(&q);
            let fast = clearance(&model, &q);
            assert!(
                (fast - exact).abs() <= 1e-9 || (fast.is_infinite() && exact.is_infinite()),
                "robot {r}, {k}: clearance {fast} against {exact}"
            );
            let offset = [0.0, 0.01][k % 2];
            if exact < offset {
                continue;
            }
            let dq = JointVector::from_fn(|_, _| rng.random_range(-1.0..1.0))
                * rng.random_range(0.01..2.0);
            let s = advancement(&model, &q, &dq, offset).min(1.0);
            for t in 0..=20 {
                let p = q + dq * (s * (t as Real / 10.0 - 1.0));
                let d = distance(&p);
                assert!(d >= offset - 1e-9, "robot {r}, {k}: {d} m within an advancement of {s}");
            }
        }
    }
}

/// An obstacle of every kind near the arm's reach, turned at random.
fn mixed_scene(number: &mut impl FnMut(Real, Real) -> Real) -> Vec<crate::language::Obstacle> {
    use crate::language::{Obstacle, Shape};
    let near = |number: &mut dyn FnMut(Real, Real) -> Real| {
        v(number(-0.6, 0.6), number(-0.6, 0.6), number(-0.6, 0.6))
    };
    let mut obstacles = Vec::new();
    for k in 0..4 {
        let (_, shape) = random_solid(number, k, [(0.02, 0.5); 3]);
        let shape = match shape {
            Shape::Box { size, rotation, .. } => {
                Shape::Box { center: near(number), size, rotation }
            }
            Shape::Cylinder { radius, height, rotation, .. } => {
                Shape::Cylinder { center: near(number), radius: 0.5 * radius, height, rotation }
            }
            other => other,
        };
        obstacles.push(Obstacle { name: format!("solid {k}"), shape });
    }
    let a = near(number);
    let b = a + v(number(-0.3, 0.3), number(-0.3, 0.3), number(-0.3, 0.3));
    let radius = number(0.01, 0.1);
    obstacles.push(Obstacle { name: "bar".into(), shape: Shape::Capsule { a, b, radius } });
    let (center, radius) = (near(number), number(0.01, 0.15));
    obstacles.push(Obstacle { name: "ball".into(), shape: Shape::Sphere { center, radius } });
    obstacles
}

/// Every pair's distance from the closed forms is parry's ([`super::super::distances`], the
/// independent measure, which visits the pairs in the same order), to within what parry's GJK
/// may be off by; the nearest pair is the smallest of them; and the closest points of the pairs
/// within the influence distance are the measured pairs' own: each point on its shape's
/// surface, apart by the distance along the normal.
#[test]
fn pairs_match_parrys_pairs() {
    use crate::collision::{DistanceOptions, distances};
    let mut rng = rand::rngs::StdRng::seed_from_u64(47);
    let root = format!("{}/../..", env!("CARGO_MANIFEST_DIR"));
    let (mut measured, mut near, mut penetrating) = (0, 0, 0);
    for name in ["robots/coman_right_arm.urdf", "robots/panda.urdf", "robots/iiwa14.urdf"] {
        let robot = Robot::from_urdf_file(format!("{root}/{name}")).expect("robot loads");
        let (lower, upper) = (robot.lower(), robot.upper());
        for _ in 0..40 {
            let obstacles = mixed_scene(&mut |lo, hi| rng.random_range(lo..hi));
            let scene = CollisionScene::new(&obstacles);
            let model = CollisionModel::new(&robot, &scene);
            for _ in 0..10 {
                let q = JointVector::from_fn(|i, _| rng.random_range(lower[i]..upper[i]));
                let pose = arm_pose(&robot, &q);
                let parrys = distances(&robot, &pose, &scene, &DistanceOptions { influence: 1e3 });
                let mut mine = Vec::new();
                model.measure_pairs(&q, |pair, d| mine.push((pair, d)));
                assert_eq!(mine.len(), parrys.len());
                for ((pair, d), p) in mine.iter().zip(&parrys) {
                    let expected = match *pair {
                        Pair::Obstacle { capsule, obstacle } => {
                            (robot.capsules[capsule].name.as_str(), scene.name(obstacle))
                        }
                        Pair::SelfPair(k) => {
                            let (a, b) = robot.self_pairs[k];
                            (robot.capsules[a].name.as_str(), robot.capsules[b].name.as_str())
                        }
                    };
                    assert_eq!(expected, (p.link.as_str(), p.obstacle.as_str()));
                    let slack = crate::collision::MEASURE_SLACK;
                    assert!(
                        *d <= p.distance + 1e-9 && *d >= p.distance - slack,
                        "{pair:?} at {q}: {d} against parry's {}",
                        p.distance
                    );
                    penetrating += usize::from(*d < 0.0);
                }
                measured += mine.len();
                let smallest = mine.iter().map(|(_, d)| *d).fold(Real::INFINITY, Real::min);
                assert_eq!(model.nearest_pair(&q).map(|(d, _)| d), Some(smallest));
                let influence = 0.1;
                let mut closest = Vec::new();
                model.near_pairs(&q, influence, &mut closest);
                let within: Vec<_> = mine.iter().filter(|(_, d)| *d < influence).collect();
                assert_eq!(closest.len(), within.len(), "at {q}");
                for (c, (pair, d)) in closest.iter().zip(within) {
                    assert_eq!(c.pair, *pair);
                    assert!((c.distance - d).abs() <= 1e-9, "{pair:?}: {} against {d}", c.distance);
                    assert!((c.normal.norm() - 1.0).abs() < 1e-9);
                    let apart = c.on_link - c.on_other;
                    assert!((apart - c.normal * c.distance).norm() < 1e-6, "{pair:?}: {c:?}");
                    let capsule = |i: usize| {
                        let (a, b) = (
                            pose.frames[robot.capsules[i].frame]
                                * nalgebra::Point3::from(robot.capsules[i].a),
                            pose.frames[robot.capsules[i].frame]
                                * nalgebra::Point3::from(robot.capsules[i].b),
                        );
                        (a.coords, b.coords, robot.capsules[i].radius)
                    };
                    let on_capsule = |(a, b, r): (Vector3, Vector3, Real), p: &Vector3| {
                        (Posed::new(a, b, r).squared_distance_to_point(p).sqrt() - r).abs() < 1e-6
                    };
                    let link = match c.pair {
                        Pair::Obstacle { capsule: i, .. } => i,
                        Pair::SelfPair(k) => robot.self_pairs[k].0,
                    };
                    assert!(on_capsule(capsule(link), &c.on_link), "{pair:?}: {c:?}");
                    if let Pair::SelfPair(k) = c.pair {
                        assert!(on_capsule(capsule(robot.self_pairs[k].1), &c.on_other));
                    }
                    near += 1;
                }
            }
        }
    }
    assert!(
        measured > 10_000 && near > 500 && penetrating > 100,
        "{measured} {near} {penetrating}"
    );
}
