use super::*;
use crate::kinematics::arm_pose;
use crate::language::{Obstacle, Shape};
use crate::math::Vector3;

fn robot() -> Robot {
    Robot::from_urdf_file(concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/coman_right_arm.urdf"))
        .expect("robot loads")
}

/// q(t) = c + a sin(w t) per joint, with its exact derivative, sampled every `dt` over [0, T].
fn sine(c: JointVector, a: Real, w: Real, duration: Real, dt: Real) -> Trajectory {
    let n = (duration / dt).round() as usize;
    let times = (0..=n).map(|i| i as Real * duration / n as Real).collect();
    Trajectory::from_fn(times, |t| {
        (c + JointVector::repeat(a * (w * t).sin()), JointVector::repeat(a * w * (w * t).cos()))
    })
    .expect("valid")
}

/// A rest-to-rest move from `from` to `to` over [0, T] (smoothstep), sampled every `dt`.
fn move_to(from: JointVector, to: JointVector, duration: Real, dt: Real) -> Trajectory {
    let n = (duration / dt).round() as usize;
    let times = (0..=n).map(|i| i as Real * duration / n as Real).collect();
    Trajectory::from_fn(times, |t| {
        let s = t / duration;
        let (b, db) = (3.0 * s * s - 2.0 * s * s * s, (6.0 * s - 6.0 * s * s) / duration);
        (from + (to - from) * b, (to - from) * db)
    })
    .expect("valid")
}

fn max_abs(v: JointVector) -> Real {
    v.amax()
}

/// Left and right limits of q and q' at `t` agree to 1e-9.
fn assert_continuous_at(tr: &Trajectory, t: Real) {
    let eps = 1e-12;
    let (left, right) = (tr.sample(t - eps), tr.sample(t + eps));
    assert!(max_abs(left.0 - right.0) < 1e-9, "q jumps at {t}");
    assert!(max_abs(left.1 - right.1) < 1e-9, "q' jumps at {t}");
}

#[test]
fn constructor_validates() {
    let q = JointVector::zeros();
    assert!(matches!(
        Trajectory::new(vec![0.0, 1.0], vec![q], vec![q, q]),
        Err(TrajectoryError::LengthMismatch { .. })
    ));
    assert!(matches!(Trajectory::new(vec![], vec![], vec![]), Err(TrajectoryError::Empty)));
    assert!(matches!(
        Trajectory::new(vec![0.0, 0.0], vec![q, q], vec![q, q]),
        Err(TrajectoryError::TimesNotIncreasing { sample: 1, .. })
    ));
    assert!(matches!(
        Trajectory::new(vec![0.0, 1.0], vec![q, JointVector::repeat(Real::NAN)], vec![q, q]),
        Err(TrajectoryError::NonFinite { what: "position", sample: 1 })
    ));
}

#[test]
fn hermite_hits_the_knots_and_is_c1() {
    let tr = sine(JointVector::zeros(), 0.5, 2.0, 2.0, 0.1);
    for (i, &t) in tr.times().iter().enumerate() {
        let (q, qd) = tr.sample(t);
        assert!(max_abs(q - tr.positions()[i]) < 1e-12);
        assert!(max_abs(qd - tr.velocities()[i]) < 1e-12);
    }
    for &t in &tr.times()[1..tr.len() - 1] {
        assert_continuous_at(&tr, t);
    }
    // q' is the derivative of q between knots, and close to the exact curve.
    let (t, h) = (0.537, 1e-6);
    let fd = (tr.sample(t + h).0 - tr.sample(t - h).0) / (2.0 * h);
    assert!(max_abs(fd - tr.sample(t).1) < 1e-7);
    assert!((tr.sample(t).0[0] - 0.5 * (2.0 * t).sin()).abs() < 1e-4);
    // Clamped outside.
    assert_eq!(tr.sample(-1.0), tr.sample(0.0));
    assert_eq!(tr.sample(9.0), tr.sample(tr.end()));
}

#[test]
fn resample_keeps_the_end_points() {
    let tr = sine(JointVector::zeros(), 0.5, 2.0, 1.05, 0.05);
    let r = tr.resample(10.0).expect("valid rate");
    assert_eq!(r.start(), tr.start());
    assert_eq!(r.end(), tr.end());
    assert_eq!(r.len(), 12);
    assert_eq!(r.positions()[r.len() - 1], tr.positions()[tr.len() - 1]);
    assert!(matches!(tr.resample(0.0), Err(TrajectoryError::InvalidRate { .. })));
}

#[test]
fn sequential_join_is_continuous_and_rejects_gaps() {
    let (a, b, c) = (JointVector::zeros(), JointVector::repeat(0.3), JointVector::repeat(-0.2));
    let first = move_to(a, b, 1.0, 0.1);
    let second = move_to(b, c, 2.0, 0.1);
    let joined = join_sequential(&first, &second).expect("continuous");
    assert!((joined.duration() - 3.0).abs() < 1e-12);
    assert_continuous_at(&joined, 1.0);
    assert!(max_abs(joined.sample(3.0).0 - c) < 1e-12);

    let gap = move_to(b + JointVector::repeat(1e-5), c, 2.0, 0.1);
    assert!(matches!(
        join_sequential(&first, &gap),
        Err(TrajectoryError::Join(ProfileError::Discontinuous { .. }))
    ));
}

#[test]
fn transitional_join_is_c1_at_both_seams() {
    let first = sine(JointVector::zeros(), 0.4, 1.5, 2.0, 0.1);
    let second = sine(JointVector::repeat(0.2), 0.3, -2.0, 1.5, 0.1);
    let overlap = 0.5;
    let joined = join_transitional(&first, &second, overlap).expect("valid overlap");
    assert!((joined.duration() - (2.0 + 1.5 - overlap)).abs() < 1e-12);
    let (t2s, t1e) = (2.0 - overlap, 2.0);
    for t in [t2s, t1e] {
        assert_continuous_at(&joined, t);
    }
    // At the seams the blend equals the segment it hands over from / to.
    let at_start = joined.sample(t2s);
    assert!(max_abs(at_start.0 - first.sample(t2s).0) < 1e-12);
    assert!(max_abs(at_start.1 - first.sample(t2s).1) < 1e-12);
    let at_end = joined.sample(t1e);
    assert!(max_abs(at_end.0 - second.sample(overlap).0) < 1e-12);
    assert!(max_abs(at_end.1 - second.sample(overlap).1) < 1e-12);
    assert!(matches!(
        join_transitional(&first, &second, 3.0),
        Err(TrajectoryError::Join(ProfileError::InvalidOverlap { .. }))
    ));
}

#[test]
fn limits_flag_violations_only() {
    let robot = robot();
    let mid = robot.middle();
    let calm = move_to(mid, mid, 1.0, 0.1);
    assert!(check_limits(&calm, &robot, 1e-9).is_empty());

    let mut q = vec![mid; 3];
    let mut qd = vec![JointVector::zeros(); 3];
    q[1][2] = robot.upper()[2] + 0.1;
    qd[2][4] = -2.0 * robot.velocity_limits()[4];
    let bad = Trajectory::new(vec![0.0, 0.5, 1.0], q, qd).expect("valid");
    let v = check_limits(&bad, &robot, 1e-9);
    let found = |sample, joint, kind, limit| {
        v.iter().any(|x| (x.sample, x.joint, x.kind, x.limit) == (sample, joint, kind, limit))
    };
    assert!(found(1, 2, LimitKind::Position, robot.upper()[2]), "{v:?}");
    assert!(found(2, 4, LimitKind::Velocity, -robot.velocity_limits()[4]), "{v:?}");
    // Only those joints, at those samples or on the curve next to them.
    assert!(v.iter().all(|x| x.joint == 2 || x.joint == 4), "{v:?}");

    // Between samples: a rest-to-rest step of 0.1 rad in 10 ms is the cubic whose speed peaks
    // at 1.5 × 0.1 / 0.01 rad/s mid-way and whose acceleration is 6 × 0.1 / 0.01² at the ends.
    let mut end = mid;
    end[0] += 0.1;
    let zeros = vec![JointVector::zeros(); 2];
    let step = Trajectory::new(vec![0.0, 0.01], vec![mid, end], zeros).expect("valid");
    let v = check_limits(&step, &robot, 1e-9);
    let acceleration = v.iter().find(|x| x.kind == LimitKind::Acceleration).expect("flagged");
    assert_eq!((acceleration.sample, acceleration.joint), (0, 0));
    assert!((acceleration.value - 6000.0).abs() < 1e-6, "{acceleration:?}");
    let peaks = crate::trajectory::peaks(&step, 0.0, 0.01);
    assert!((peaks.velocity[0] - 15.0).abs() < 1e-9, "{peaks:?}");
}

#[test]
fn min_clearance_is_the_worst_sample() {
    let robot = robot();
    let (a, b) = (robot.middle(), robot.middle() + JointVector::repeat(0.2));
    let tr = move_to(a, b, 1.0, 0.1);
    // A sphere 5 cm beyond the hand at the final pose.
    let hand = arm_pose(&robot, &b).hand_frame().translation.vector;
    let center: Vector3 = hand + hand.normalize() * 0.1;
    let scene = CollisionScene::new(&[Obstacle {
        name: "ball".into(),
        shape: Shape::Sphere { center, radius: 0.05 },
    }]);
    let worst = min_clearance(&tr, &robot, &scene).expect("pairs exist");
    let per_sample: Vec<Real> = tr
        .positions()
        .iter()
        .map(|q| collision::min_distance(&robot, &arm_pose(&robot, q), &scene).expect("pairs").0)
        .collect();
    // parry's distances, the independent measure: the same smallest distance (sphere and
    // capsule distances are closed forms in both), at the same sample, between the same pair.
    let smallest = per_sample.iter().copied().fold(Real::INFINITY, Real::min);
    assert!((worst.distance - smallest).abs() < 1e-12, "{} against {smallest}", worst.distance);
    let i = per_sample.iter().position(|&d| d == smallest).expect("a sample");
    assert_eq!(worst.time, tr.times()[i]);
    let (_, link, obstacle) =
        collision::min_distance(&robot, &arm_pose(&robot, &tr.positions()[i]), &scene)
            .expect("pairs");
    assert_eq!((worst.link.as_str(), worst.obstacle.as_str()), (link.as_str(), obstacle.as_str()));
}

/// Every sample measured with the same closed forms, as min_clearance did before it left
/// out the samples its bound rules out: the first sample of the smallest distance; and
/// parry's smallest distance over the samples, the independent measure.
fn exhaustive_clearance(
    tr: &Trajectory,
    robot: &Robot,
    scene: &CollisionScene,
) -> (Option<Clearance>, Option<Real>) {
    let model = collision::CollisionModel::new(robot, scene);
    let mut best: Option<Clearance> = None;
    let mut parrys: Option<Real> = None;
    for (&time, q) in tr.times().iter().zip(tr.positions()) {
        if let Some((distance, pair)) = model.nearest_pair(q) {
            if best.as_ref().is_none_or(|b| distance < b.distance) {
                let (link, obstacle) = distances::pair_names(robot, scene, pair);
                best = Some(Clearance { distance, time, link, obstacle });
            }
        }
        if let Some((distance, ..)) = collision::min_distance(robot, &arm_pose(robot, q), scene) {
            parrys = Some(parrys.map_or(distance, |d: Real| d.min(distance)));
        }
    }
    (best, parrys)
}

/// The samples min_clearance leaves out never change its answer: the same distance, time
/// and pair as measuring every sample, on dense motions past boxes, a cylinder, a capsule
/// and a sphere, grazing, touching and passing through them.
#[test]
fn min_clearance_equals_measuring_every_sample() {
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};
    let robot = robot();
    let scene = CollisionScene::new(&[
        Obstacle {
            name: "table".into(),
            shape: Shape::Box {
                center: Vector3::new(0.4, 0.0, -0.235),
                size: Vector3::new(0.4, 0.8, 0.03),
                rotation: crate::math::Rotation3::identity(),
            },
        },
        Obstacle {
            name: "box".into(),
            shape: Shape::Box {
                center: Vector3::new(0.3, 0.06, -0.18),
                size: Vector3::new(0.06, 0.06, 0.08),
                rotation: crate::math::Rotation3::from_euler_angles(0.3, -0.2, 0.7),
            },
        },
        Obstacle {
            name: "can".into(),
            shape: Shape::Cylinder {
                center: Vector3::new(0.3, -0.1, -0.42),
                radius: 0.07,
                height: 0.2,
                rotation: crate::math::Rotation3::identity(),
            },
        },
        Obstacle {
            name: "bar".into(),
            shape: Shape::Capsule {
                a: Vector3::new(0.0, -0.17, -0.1),
                b: Vector3::new(0.5, -0.17, -0.1),
                radius: 0.02,
            },
        },
        Obstacle {
            name: "ball".into(),
            shape: Shape::Sphere { center: Vector3::new(0.25, -0.2, 0.05), radius: 0.04 },
        },
    ]);
    let mut rng = StdRng::seed_from_u64(22);
    let (lower, upper) = (robot.lower(), robot.upper());
    let mut skipped_any = false;
    for _ in 0..40 {
        let random =
            |rng: &mut StdRng| JointVector::from_fn(|i, _| rng.random_range(lower[i]..=upper[i]));
        let (a, b) = (random(&mut rng), random(&mut rng));
        // 2 ms samples, as the solvers give them.
        let tr = move_to(a, b, 1.0, 0.002);
        let fast = min_clearance(&tr, &robot, &scene);
        let (every, parrys) = exhaustive_clearance(&tr, &robot, &scene);
        assert_eq!(fast, every);
        // Never above parry's measure by more than parry may be off by, and below it by at
        // most what a closed form may be (a penetration of a box is parry's depth in both).
        let (found, parrys) = (every.as_ref().map(|c| c.distance), parrys);
        if let (Some(found), Some(parrys)) = (found, parrys) {
            assert!(
                found <= parrys + 1e-9 && found >= parrys - MEASURE_SLACK,
                "{found} against {parrys}"
            );
        }
        assert_eq!(found.is_some(), parrys.is_some());
        skipped_any |= every.is_some_and(|c| c.distance > 0.0);
    }
    assert!(skipped_any, "no motion stayed clear: the bound was never tried");
}

#[test]
fn the_sampler_gives_the_samples_bits_at_any_time_in_any_order() {
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};
    // Uneven sample times, so that intervals differ in length.
    let mut rng = StdRng::seed_from_u64(3);
    let times: Vec<Real> = (0..200)
        .scan(0.0, |t, _| {
            *t += rng.random_range(1e-3..0.05);
            Some(*t)
        })
        .collect();
    let tr = Trajectory::from_fn(times, |t| {
        (JointVector::repeat(t.sin()), JointVector::repeat(t.cos()))
    })
    .expect("valid");
    let (start, end) = (tr.start(), tr.end());
    let rising: Vec<Real> =
        (0..=1000).map(|i| start + (end - start) * i as Real / 1000.0).collect();
    let mut queries: Vec<Real> = tr.times().to_vec();
    queries.extend(&rising);
    queries.extend(rising.iter().rev());
    queries.extend((0..500).map(|_| rng.random_range(start - 1.0..end + 1.0)));
    queries.extend([start - 1.0, start, end, end + 1.0, end, start]);
    let sampler = tr.sampler();
    for &t in &queries {
        let ((q, dq), (sq, sdq)) = (sampler(t), tr.sample(t));
        for i in 0..DOF {
            assert_eq!(q[i].to_bits(), sq[i].to_bits(), "q at {t}");
            assert_eq!(dq[i].to_bits(), sdq[i].to_bits(), "q' at {t}");
        }
    }
}
