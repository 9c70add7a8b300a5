//! Bell profiles, reference paths of every primitive kind, weight schedules and joining.

use crate::common::rng;
use a2ml::language::{Axis, BodyAxis, PathFeature, Target, Variable};
use a2ml::math::{
    JointVector, PI, Real, Rotation3, Vector3, rotation_distance, rotation_log, wrap_angle,
};
use a2ml::profile::*;
use a2ml::trajectory::join::{self, SequentialOptions, Transition, TransitionOptions};
use nalgebra::Unit;
use rand::RngExt;
use rand::rngs::StdRng;

/// Composite Simpson rule over [0, T] with `n` (even) intervals.
fn simpson(f: impl Fn(Real) -> Real, duration: Real, n: usize) -> Real {
    let h = duration / n as Real;
    let inner: Real =
        (1..n).map(|i| f(i as Real * h) * if i % 2 == 1 { 4.0 } else { 2.0 }).sum::<Real>();
    (f(0.0) + inner + f(duration)) * h / 3.0
}

fn rot(axis: Vector3, angle: Real) -> Rotation3 {
    Rotation3::from_axis_angle(&Unit::new_normalize(axis), angle)
}

fn random_unit(rng: &mut StdRng) -> Vector3 {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        if v.norm() > 0.1 && v.norm() < 1.0 {
            return v.normalize();
        }
    }
}

fn random_rotation(rng: &mut StdRng) -> Rotation3 {
    rot(random_unit(rng), rng.random_range(0.0..PI))
}

/// The distance between two values of `variable` (m or rad).
fn distance(variable: Variable, a: &Target, b: &Target) -> Real {
    match (a, b) {
        (Target::Position(a), Target::Position(b)) => (a - b).norm(),
        (Target::Rotation(a), Target::Rotation(b)) => rotation_distance(a, b),
        (Target::Angle(a), Target::Angle(b)) if variable == Variable::Swivel => {
            wrap_angle(a - b).abs()
        }
        (Target::Angle(a), Target::Angle(b)) => (a - b).abs(),
        _ => panic!("kinds differ: {a:?} {b:?}"),
    }
}

/// The velocity part of a sample as a 3-vector (angles in x) and its speed.
fn velocity(sample: &Sample) -> Vector3 {
    match *sample {
        Sample::Position { velocity, .. } => velocity,
        Sample::Rotation { angular_velocity, .. } => angular_velocity,
        Sample::Angle { rate, .. } => Vector3::new(rate, 0.0, 0.0),
    }
}

/// Central difference of the value at t; rotations as the spatial angular velocity.
fn finite_difference(reference: &Reference, t: Real, h: Real) -> Vector3 {
    match (reference.sample(t + h), reference.sample(t - h)) {
        (Sample::Position { value: a, .. }, Sample::Position { value: b, .. }) => {
            (a - b) / (2.0 * h)
        }
        (Sample::Rotation { value: a, .. }, Sample::Rotation { value: b, .. }) => {
            rotation_log(&(a * b.inverse())) / (2.0 * h)
        }
        (Sample::Angle { value: a, .. }, Sample::Angle { value: b, .. }) => {
            Vector3::new(wrap_angle(a - b) / (2.0 * h), 0.0, 0.0)
        }
        _ => unreachable!(),
    }
}

struct Case {
    name: String,
    variable: Variable,
    reference: Reference,
    start: Target,
    goal: Target,
    /// The length of the path travelled (m for Pw, rad otherwise).
    travel: Real,
}

/// Checks the laws every reference obeys: start and goal, velocity as the derivative of the
/// value, and the integrated speed as the length of the path.
fn check(case: &Case, rng: &mut StdRng) {
    let Case { name, variable, reference, start, goal, travel } = case;
    let duration = reference.duration();
    let at_start = reference.sample(0.0).value();
    let at_end = reference.sample(duration).value();
    assert!(distance(*variable, &at_start, start) < 1e-12, "{name}: start {at_start:?}");
    assert!(distance(*variable, &at_end, goal) < 1e-12, "{name}: end {at_end:?} vs {goal:?}");
    assert!(distance(*variable, &reference.end(), goal) < 1e-12, "{name}: end()");
    assert!(velocity(&reference.sample(0.0)).norm() < 1e-15, "{name}: moving at 0");
    assert!(velocity(&reference.sample(duration)).norm() < 1e-12, "{name}: moving at T");

    for _ in 0..50 {
        let t = rng.random_range(0.01 * duration..0.99 * duration);
        let analytic = velocity(&reference.sample(t));
        let numeric = finite_difference(reference, t, 1e-5);
        assert!(
            (analytic - numeric).norm() < 1e-6,
            "{name}: t {t}: velocity {analytic:?} vs finite difference {numeric:?}"
        );
    }

    let integrated = simpson(|t| velocity(&reference.sample(t)).norm(), duration, 4000);
    assert!(
        (integrated - travel).abs() < 1e-9,
        "{name}: integrated speed {integrated} vs travel {travel}"
    );
}

fn cases(rng: &mut StdRng) -> Vec<Case> {
    let duration = rng.random_range(0.5..3.0);
    let pw0 = Vector3::new(0.35, -0.2, -0.3) + 0.05 * random_unit(rng);
    let ow0 = random_rotation(rng);
    let os0 = random_rotation(rng);
    let frames = BodyFrames { shoulder_frame: os0, ow: ow0 };
    let col = |r: &Rotation3, i: usize| -> Vector3 { r.matrix().column(i).into() };
    let mut out = Vec::new();

    let mut goal = |variable: Variable, start: Target, goal: Target, travel: Real| {
        let reference = Reference::goal(variable, start, goal, duration).expect("goal");
        out.push(Case {
            name: format!("{} goal", variable.symbol()),
            variable,
            reference,
            start,
            goal,
            travel,
        });
    };
    let pw1 = pw0 + 0.3 * random_unit(rng);
    goal(Variable::Pw, Target::Position(pw0), Target::Position(pw1), (pw1 - pw0).norm());
    for (variable, r0) in [(Variable::Ow, ow0), (Variable::Os, os0)] {
        let r1 = random_rotation(rng);
        goal(variable, Target::Rotation(r0), Target::Rotation(r1), rotation_distance(&r0, &r1));
    }
    // The swivel goes the short way across ±π; the elbow by the plain difference.
    goal(Variable::Swivel, Target::Angle(2.9), Target::Angle(-2.8), 2.0 * PI - 5.7);
    goal(Variable::Swivel, Target::Angle(-0.4), Target::Angle(1.1), 1.5);
    goal(Variable::Elbow, Target::Angle(0.5), Target::Angle(2.0), 1.5);
    goal(Variable::Elbow, Target::Angle(2.5), Target::Angle(0.3), 2.2);

    let mut path =
        |variable: Variable, start: Target, feature: PathFeature, goal: Target, travel: Real| {
            let reference =
                Reference::path(variable, start, &feature, &frames, duration).expect("path");
            out.push(Case {
                name: format!("{} {feature:?}", variable.symbol()),
                variable,
                reference,
                start,
                goal,
                travel,
            });
        };
    let d = random_unit(rng);
    path(
        Variable::Pw,
        Target::Position(pw0),
        PathFeature::Line { direction: d, length: Some(0.25) },
        Target::Position(pw0 + 0.25 * d),
        0.25,
    );
    // Pw about an axis through S: a circular arc of radius |axis × Pw0|.
    let pw_axes = [
        (Axis::Base(-Vector3::z()), -Vector3::z()),
        (Axis::Body(BodyAxis::R, -1.0), -col(&os0, 0)),
        (Axis::Body(BodyAxis::P, 1.0), col(&ow0, 1)),
    ];
    for (axis, a) in pw_axes {
        let angle = 0.8;
        path(
            Variable::Pw,
            Target::Position(pw0),
            PathFeature::About { axis, angle: Some(angle) },
            Target::Position(rot(a, angle) * pw0),
            a.cross(&pw0).norm() * angle,
        );
    }
    let rotation_axes = [
        (Axis::Base(Vector3::y()), Vector3::y()),
        (Axis::Body(BodyAxis::R, 1.0), col(&os0, 0)),
        (Axis::Body(BodyAxis::L, -1.0), -col(&os0, 1)),
        (Axis::Body(BodyAxis::F, 1.0), col(&ow0, 0)),
        (Axis::Body(BodyAxis::P, -1.0), -col(&ow0, 1)),
    ];
    for (variable, r0) in [(Variable::Ow, ow0), (Variable::Os, os0)] {
        for (axis, a) in rotation_axes {
            let angle = 1.2;
            path(
                variable,
                Target::Rotation(r0),
                PathFeature::About { axis, angle: Some(angle) },
                Target::Rotation(rot(a, angle) * r0),
                angle,
            );
        }
    }
    path(
        Variable::Swivel,
        Target::Angle(2.8),
        PathFeature::By { angle: 1.0 },
        Target::Angle(3.8 - 2.0 * PI),
        1.0,
    );
    path(
        Variable::Swivel,
        Target::Angle(0.3),
        PathFeature::By { angle: -0.7 },
        Target::Angle(-0.4),
        0.7,
    );
    path(
        Variable::Elbow,
        Target::Angle(1.2),
        PathFeature::By { angle: 0.4 },
        Target::Angle(1.6),
        0.4,
    );
    let holds = [
        (Variable::Pw, Target::Position(pw0)),
        (Variable::Ow, Target::Rotation(ow0)),
        (Variable::Os, Target::Rotation(os0)),
        (Variable::Swivel, Target::Angle(-1.0)),
        (Variable::Elbow, Target::Angle(2.0)),
    ];
    for (variable, start) in holds {
        path(variable, start, PathFeature::Hold, start, 0.0);
    }
    out
}

#[test]
fn every_primitive_starts_ends_and_moves_as_its_reference_says() {
    let mut rng = rng(90);
    for _ in 0..20 {
        for case in cases(&mut rng) {
            check(&case, &mut rng);
        }
    }
}

#[test]
fn a_body_axis_of_the_turning_frame_stays_put() {
    let mut rng = rng(91);
    let ow0 = random_rotation(&mut rng);
    let frames = BodyFrames { shoulder_frame: Rotation3::identity(), ow: ow0 };
    let feature = PathFeature::About { axis: Axis::Body(BodyAxis::F, 1.0), angle: Some(2.0) };
    let reference =
        Reference::path(Variable::Ow, Target::Rotation(ow0), &feature, &frames, 1.0).expect("path");
    let f0: Vector3 = ow0.matrix().column(0).into();
    for k in 0..=10 {
        let Sample::Rotation { value, .. } = reference.sample(k as Real / 10.0) else {
            panic!("a rotation")
        };
        assert!((Vector3::from(value.matrix().column(0)) - f0).norm() < 1e-14);
    }
}

#[test]
fn bell_profile_rests_at_both_ends_and_covers_its_distance() {
    let mut rng = rng(92);
    for _ in 0..100 {
        let duration = rng.random_range(0.05..10.0);
        let distance = rng.random_range(0.0..5.0);
        let bell = BellProfile::new(duration, distance).expect("valid");
        assert_eq!(bell.speed(0.0), 0.0);
        assert!(bell.speed(duration).abs() < 1e-12 * distance.max(1.0) / duration);
        assert_eq!(bell.acceleration(0.0), 0.0);
        assert!(bell.acceleration(duration).abs() < 1e-12 * distance.max(1.0) / duration.powi(2));
        assert_eq!(bell.progress(0.0), 0.0);
        assert!((bell.progress(duration) - distance).abs() <= 1e-15 * distance);
        let integrated = simpson(|t| bell.speed(t), duration, 2000);
        assert!((integrated - distance).abs() < 1e-9, "{integrated} vs {distance}");
        assert!((bell.speed(duration / 2.0) - bell.peak_speed()).abs() < 1e-12);
        // progress is the integral of speed, speed that of acceleration.
        let t = rng.random_range(0.0..duration);
        let h = 1e-6 * duration;
        let t = t.clamp(h, duration - h);
        let ds = (bell.progress(t + h) - bell.progress(t - h)) / (2.0 * h);
        let dv = (bell.speed(t + h) - bell.speed(t - h)) / (2.0 * h);
        assert!((ds - bell.speed(t)).abs() < 1e-6 * bell.peak_speed().max(1.0));
        assert!((dv - bell.acceleration(t)).abs() < 1e-6 * bell.peak_acceleration().max(1.0));
    }
}

#[test]
fn speed_limit_is_met_with_equality() {
    let bell = BellProfile::for_speed_limit(0.4, 0.25).expect("valid");
    assert!((bell.peak_speed() - 0.25).abs() < 1e-15);
    let max =
        (0..=1000).map(|k| bell.speed(bell.duration() * k as Real / 1000.0)).fold(0.0, Real::max);
    assert!(max <= 0.25 + 1e-15);
}

#[test]
fn goal_weights_are_equal_at_the_ends_and_lowest_in_the_middle() {
    let schedule = WeightSchedule::new(1.6, WeightOptions::default());
    let (start, end) = (schedule.goal(0.0), schedule.goal(1.6));
    assert!((start - end).abs() < 1e-15);
    assert!((start - 1.0).abs() < 1e-15);
    let samples: Vec<Real> = (0..=160).map(|k| schedule.goal(k as Real * 0.01)).collect();
    let (argmin, min) = samples
        .iter()
        .enumerate()
        .fold((0, Real::INFINITY), |a, (i, &w)| if w < a.1 { (i, w) } else { a });
    assert_eq!(argmin, 80);
    assert!((min - 0.1).abs() < 1e-15);
    // Decreasing to the middle, increasing after it.
    assert!(samples[..=80].windows(2).all(|w| w[1] <= w[0]));
    assert!(samples[80..].windows(2).all(|w| w[1] >= w[0]));
    assert!((0..=160).all(|k| schedule.weight(Role::Path, k as Real * 0.01) == 10.0));
}

/// A smooth joint trajectory q(t) = a + b sin(c t + d) with its derivative.
fn smooth(rng: &mut StdRng) -> impl Fn(Real) -> (JointVector, JointVector) + Clone + use<> {
    let a = JointVector::from_fn(|_, _| rng.random_range(-1.0..1.0));
    let b = JointVector::from_fn(|_, _| rng.random_range(-0.5..0.5));
    let c = JointVector::from_fn(|_, _| rng.random_range(0.5..3.0));
    let d = JointVector::from_fn(|_, _| rng.random_range(-PI..PI));
    move |t| {
        let q = JointVector::from_fn(|i, _| a[i] + b[i] * (c[i] * t + d[i]).sin());
        let qd = JointVector::from_fn(|i, _| b[i] * c[i] * (c[i] * t + d[i]).cos());
        (q, qd)
    }
}

#[test]
fn transitional_blend_is_continuous_at_the_seams() {
    let mut rng = rng(93);
    for _ in 0..50 {
        let (t1, t2) = (rng.random_range(0.5..3.0), rng.random_range(0.5..3.0));
        let first = smooth(&mut rng);
        let second = smooth(&mut rng);
        let transition =
            Transition::with_options(t1, t2, &TransitionOptions::default()).expect("valid");
        assert!((transition.overlap() - 0.2 * t1.min(t2)).abs() < 1e-15);
        let joined = join::transitional(first.clone(), second.clone(), transition);
        let t2s = transition.second_start();
        let t1e = transition.first_end();

        for seam in [t2s, t1e] {
            let delta = 1e-12;
            let (before, after) = (joined(seam - delta), joined(seam + delta));
            assert!((before.0 - after.0).amax() < 1e-9, "q jumps at {seam}");
            assert!((before.1 - after.1).amax() < 1e-9, "q' jumps at {seam}");
        }
        // At the seams the join is exactly the segment on the other side.
        let (q, qd) = joined(t2s);
        assert!((q - first(t2s).0).amax() < 1e-15 && (qd - first(t2s).1).amax() < 1e-15);
        let (q, qd) = joined(t1e);
        assert!((q - second(t1e - t2s).0).amax() < 1e-12);
        assert!((qd - second(t1e - t2s).1).amax() < 1e-12);
        // Outside the overlap each segment alone, in its own time.
        let t = 0.5 * t2s;
        assert_eq!(joined(t), first(t));
        let t = t1e + 0.5 * (transition.duration() - t1e);
        assert_eq!(joined(t), second(t - t2s));

        // Inside, the velocity (with its β' term) is the derivative of the position.
        for _ in 0..20 {
            let t = rng.random_range(t2s + 1e-4..t1e - 1e-4);
            let h = 1e-6;
            let fd = (joined(t + h).0 - joined(t - h).0) / (2.0 * h);
            assert!((fd - joined(t).1).amax() < 1e-6, "q' at {t}");
        }
    }
}

#[test]
fn transitions_chain() {
    let mut rng = rng(94);
    let segments: Vec<_> = (0..3).map(|_| smooth(&mut rng)).collect();
    let durations = [1.0, 2.0, 1.5];
    let first = Transition::with_options(durations[0], durations[1], &TransitionOptions::default())
        .expect("valid");
    let joined = join::transitional(segments[0].clone(), segments[1].clone(), first);
    let second =
        Transition::with_options(first.duration(), durations[2], &TransitionOptions::default())
            .expect("valid");
    let all = join::transitional(joined, segments[2].clone(), second);
    assert!((second.duration() - (1.0 + 2.0 + 1.5 - 0.2 - 0.3)).abs() < 1e-12);
    for seam in [first.second_start(), first.first_end(), second.second_start(), second.first_end()]
    {
        let (a, b) = (all(seam - 1e-12), all(seam + 1e-12));
        assert!((a.0 - b.0).amax() < 1e-9 && (a.1 - b.1).amax() < 1e-9, "seam {seam}");
    }
}

#[test]
fn sequential_join_starts_the_next_segment_at_rest_where_the_last_ended() {
    // Two bell-shaped joint motions: the second starts where the first ends.
    let q0 = JointVector::from_fn(|i, _| 0.1 * i as Real);
    let q1 = JointVector::from_fn(|i, _| -0.2 * i as Real + 0.3);
    let q2 = JointVector::repeat(0.7);
    let (t1, t2) = (1.2, 0.8);
    let motion = move |from: JointVector, to: JointVector, duration: Real| {
        let bell = BellProfile::new(duration, 1.0).expect("valid");
        move |t: Real| (from + (to - from) * bell.fraction(t), (to - from) * bell.fraction_rate(t))
    };
    let options = SequentialOptions::default();
    let joined =
        join::sequential(motion(q0, q1, t1), t1, motion(q1, q2, t2), &options).expect("at rest");
    let (a, b) = (joined(t1 - 1e-12), joined(t1 + 1e-12));
    assert!((a.0 - b.0).amax() < 1e-9 && (a.1 - b.1).amax() < 1e-9);
    assert!((joined(t1 + t2).0 - q2).amax() < 1e-15);

    let elsewhere = motion(q0, q2, t2);
    assert!(matches!(
        join::sequential(motion(q0, q1, t1), t1, elsewhere, &options),
        Err(ProfileError::Discontinuous { .. })
    ));
}
