//! The swivel obstacle map (METHODS.md §1.7): the elbow-circle frame, the sphere theorem
//! against brute force, the grid against direct checks, the planned profile re-checked at
//! 1 kHz, completeness, and the paper scenario's derived numbers (§1.6).

use a2ml::collision::{CollisionScene, min_distance};

use a2ml::kinematics::{CpsaState, arm_pose, cpsa_state, cpsa_to_hat, ik_cpsa};
use a2ml::language::{Obstacle, Shape};
use a2ml::math::{JointVector, PI, Real, Rotation3, Vector3, wrap_angle};
use a2ml::solve::map::sphere::{AxialCapsule, ElbowCircle, HalfWidth, half_width};
use a2ml::solve::map::{MapError, MapOptions, SwivelTargets, WristMotion, build_map, plan_profile};
use rand::RngExt;

use crate::common::{load, random_q, regularity, rng};

fn mm(x: Real, y: Real, z: Real) -> Vector3 {
    Vector3::new(x, y, z) * 1e-3
}

fn sphere(name: &str, center: Vector3, radius: Real) -> Obstacle {
    Obstacle { name: name.to_owned(), shape: Shape::Sphere { center, radius } }
}

/// The paper's scene (§4): wrist path S → V1 → V2 → G in 5 s, two spheres.
fn paper_points() -> Vec<Vector3> {
    vec![mm(0.0, 60.0, 0.0), mm(12.9, 83.4, 19.8), mm(46.9, 75.7, 31.3), mm(70.0, 100.0, 30.0)]
}

fn paper_spheres() -> Vec<Obstacle> {
    vec![
        sphere("sphere1", mm(33.0, 63.0, 0.0), 0.020),
        sphere("sphere2", mm(45.0, 95.0, 10.0), 0.015),
    ]
}

fn paper_motion(ow: Rotation3) -> WristMotion {
    WristMotion::through(&paper_points(), 5.0, ow).expect("spline")
}

/// Point-to-segment distance, written out independently of the library.
fn point_segment(p: &Vector3, a: &Vector3, b: &Vector3) -> Real {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared().max(1e-300)).clamp(0.0, 1.0);
    (a + ab * t - p).norm()
}

#[test]
fn elbow_circle_frame_gives_minus_swivel() {
    let mut r = rng(14);
    for name in ["swivel_map_arm", "human_arm", "coman_right_arm", "iiwa14"] {
        let robot = load(name);
        let (lu, lf) = (robot.upper_arm_length(), robot.forearm_length());
        let mut checked = 0;
        while checked < 2500 {
            let q = random_q(&robot, &mut r);
            let pose = arm_pose(&robot, &q);
            if regularity(&robot, &pose) < 1e-3 {
                continue;
            }
            let pw = pose.wrist - pose.shoulder;
            let swivel = r.random_range(-PI..PI);
            let hat = cpsa_to_hat(&robot, &CpsaState { pw, ow: pose.hand, swivel }).expect("hat");
            let elbow: Vector3 = hat.shoulder_frame.matrix().column(0) * lu;
            let circle = ElbowCircle::new(lu, lf, &pw, &robot.vertical).expect("circle");
            let gap = (circle.elbow(-swivel) - elbow).norm();
            assert!(gap < 1e-12, "{name}: elbow differs by {gap:e} m");
            checked += 1;
        }
    }
}

#[test]
fn sphere_interval_matches_a_brute_force_sweep() {
    let mut r = rng(1414);
    let sweep_step = (0.05 as Real).to_radians();
    let steps = (2.0 * PI / sweep_step).round() as usize;
    let (mut scenes, mut partial) = (0, 0);
    while scenes < 300 {
        let (lu, lf) = (r.random_range(0.2..0.45), r.random_range(0.2..0.45));
        let (rho_u, rho_f) = (r.random_range(0.0..0.05), r.random_range(0.0..0.05));
        let dir = Vector3::new(
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
        );
        if dir.norm() < 0.1 || dir.normalize().z.abs() > 0.99 {
            continue;
        }
        let reach = r.random_range((lu - lf as Real).abs() + 0.01..lu + lf - 0.01);
        let pw = dir.normalize() * reach;
        let circle = ElbowCircle::new(lu, lf, &pw, &Vector3::z()).expect("circle");
        // Near the arm, so that most scenes forbid part of the circle.
        let near = circle.elbow(r.random_range(-PI..PI)) * r.random_range(0.3..1.3);
        let center = near
            + Vector3::new(
                r.random_range(-0.1..0.1),
                r.random_range(-0.1..0.1),
                r.random_range(-0.1..0.1),
            );
        let radius = r.random_range(0.01..0.15);
        scenes += 1;
        let (h, p, phase) = circle.cylindrical(&center);
        let upper =
            AxialCapsule { a: (0.0, 0.0), b: (circle.centre, circle.radius), radius: rho_u };
        let fore =
            AxialCapsule { a: (circle.centre, circle.radius), b: (reach, 0.0), radius: rho_f };
        let width = |c: &AxialCapsule| match half_width(c, (h, p), radius, 0.0) {
            HalfWidth::Empty => -1.0,
            HalfWidth::Within(w) => w,
            HalfWidth::Full => PI + 1.0,
        };
        let delta = width(&upper).max(width(&fore));
        if delta > 0.0 && delta < PI {
            partial += 1;
        }
        let mut last_g = Real::NEG_INFINITY;
        for k in 0..=steps / 2 {
            // g(δ) is non-decreasing on [0, π].
            let d = k as Real * sweep_step;
            let elbow = circle.elbow(phase + d);
            let g = (point_segment(&center, &Vector3::zeros(), &elbow) - radius - rho_u)
                .min(point_segment(&center, &elbow, &pw) - radius - rho_f);
            assert!(g >= last_g - 1e-12, "g decreases at δ = {d}");
            last_g = g;
        }
        for k in 0..steps {
            let phi = -PI + k as Real * sweep_step;
            let elbow = circle.elbow(phi);
            let hit = point_segment(&center, &Vector3::zeros(), &elbow) < radius + rho_u
                || point_segment(&center, &elbow, &pw) < radius + rho_f;
            let off = wrap_angle(phi - phase).abs();
            let inside = off <= delta;
            if hit != inside {
                assert!(
                    (off - delta).abs() <= sweep_step,
                    "sweep and interval disagree at φ = {phi} (Δ = {delta}, |φ − φ_O| = {off})"
                );
            }
        }
    }
    assert!(partial > 50, "too few scenes with a partial interval: {partial}");
}

/// Δ1, Δ2 (deg) and their maximum over the upper-arm and forearm capsules.
fn paper_half_widths(t: Real, rho: Real) -> [Option<Real>; 2] {
    let motion = paper_motion(Rotation3::identity());
    let pw = motion.at(t).pw;
    let circle = ElbowCircle::new(0.0727, 0.068, &pw, &Vector3::z()).expect("reach");
    let upper = AxialCapsule { a: (0.0, 0.0), b: (circle.centre, circle.radius), radius: rho };
    let fore =
        AxialCapsule { a: (circle.centre, circle.radius), b: (circle.reach, 0.0), radius: rho };
    paper_spheres().map_into(|o| {
        let Shape::Sphere { center, radius } = o.shape else { unreachable!() };
        let (h, p, _) = circle.cylindrical(&center);
        let w = |c| match half_width(c, (h, p), radius, 0.0) {
            HalfWidth::Empty => None,
            HalfWidth::Within(w) => Some(w.to_degrees()),
            HalfWidth::Full => Some(180.0),
        };
        match (w(&upper), w(&fore)) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        }
    })
}

trait MapInto<T> {
    fn map_into<U>(self, f: impl Fn(T) -> U) -> [U; 2];
}

impl<T> MapInto<T> for Vec<T> {
    fn map_into<U>(self, f: impl Fn(T) -> U) -> [U; 2] {
        let mut it = self.into_iter().map(f);
        let a = it.next().expect("two");
        let b = it.next().expect("two");
        [a, b]
    }
}

#[test]
fn paper_scenario_derived_numbers() {
    let motion = paper_motion(Rotation3::identity());
    let WristMotion::Through { pw: spline, .. } = &motion else { unreachable!() };
    let knots = spline.times();
    assert!((knots[1] - 1.606).abs() < 5e-4 && (knots[2] - 3.379).abs() < 5e-4, "{knots:?}");
    // Closest approach of the wrist spline to each centre.
    for (o, expected) in paper_spheres().iter().zip([31.25, 27.26]) {
        let Shape::Sphere { center, .. } = o.shape else { unreachable!() };
        let closest = (0..=50_000)
            .map(|k| (motion.at(k as Real * 1e-4).pw - center).norm())
            .fold(Real::INFINITY, Real::min);
        assert!((closest * 1e3 - expected).abs() < 0.05, "{}: {:.3} mm", o.name, closest * 1e3);
    }
    // METHODS.md §1.6: Δ1, Δ2 at ρ = 0 and ρ = 5 mm, and the phase of O2 from O1.
    type Row = (Real, Real, Option<Real>, Real, Option<Real>, Real);
    let table: [Row; 11] = [
        (0.0, 26.7, None, 42.1, None, -12.5),
        (0.5, 33.5, None, 48.7, None, -12.7),
        (1.0, 42.0, None, 56.9, None, -12.2),
        (1.5, 43.8, None, 57.8, None, -10.4),
        (2.0, 45.3, None, 60.0, None, -6.8),
        (2.5, 48.1, None, 64.4, None, 0.4),
        (3.0, 48.1, None, 64.4, None, 8.7),
        (3.5, 44.4, None, 59.4, None, 13.7),
        (4.0, 39.8, None, 54.7, Some(37.7), 17.0),
        (4.5, 40.8, Some(31.2), 56.5, Some(54.7), 19.8),
        (5.0, 45.3, Some(36.5), 61.5, Some(59.7), 21.2),
    ];
    let close = |a: Option<Real>, b: Option<Real>| match (a, b) {
        (Some(a), Some(b)) => (a - b).abs() <= 0.3,
        (None, None) => true,
        _ => false,
    };
    for (t, d1, d2, d1_5, d2_5, sep) in table {
        let [a1, a2] = paper_half_widths(t, 0.0);
        assert!(close(a1, Some(d1)) && close(a2, d2), "t = {t}, ρ = 0: {a1:?} {a2:?}");
        let [b1, b2] = paper_half_widths(t, 0.005);
        assert!(close(b1, Some(d1_5)) && close(b2, d2_5), "t = {t}, ρ = 5 mm: {b1:?} {b2:?}");
        let pw = motion.at(t).pw;
        let circle = ElbowCircle::new(0.0727, 0.068, &pw, &Vector3::z()).expect("reach");
        let phases = paper_spheres().map_into(|o| {
            let Shape::Sphere { center, .. } = o.shape else { unreachable!() };
            circle.cylindrical(&center).2
        });
        let measured = wrap_angle(phases[1] - phases[0]).to_degrees();
        assert!((measured - sep).abs() <= 0.3, "t = {t}: separation {measured:.2}°");
    }
    // Sphere 2 appears between 4.0 and 4.1 s (ρ = 0), sphere 1 throughout.
    for k in 0..=400 {
        let t = k as Real * 0.01;
        assert!(paper_half_widths(t, 0.0)[1].is_none(), "sphere 2 forbids at t = {t}");
    }
    for k in 411..=500 {
        let t = k as Real * 0.01;
        let [a, b] = paper_half_widths(t, 0.0);
        assert!(a.is_some() && b.is_some(), "t = {t}");
    }
}

/// A held hand orientation whose palm normal p (the axis of joint 7) stays far from every
/// forearm direction of the motion: p along the mean shoulder–wrist direction, 68° from the
/// cone the forearm sweeps about it, keeps the wrist away from its singularity.
fn paper_ow() -> Rotation3 {
    let p = Vector3::new(0.3, 0.93, 0.12).normalize();
    let f = (Vector3::z() - p * p.z).normalize();
    Rotation3::from_basis_unchecked(&[f, p, f.cross(&p)])
}

fn paper_arm() -> a2ml::Robot {
    load("swivel_map_arm")
}

/// A start configuration of the paper arm at Pw(0) with swivel `swivel`.
fn start_at(robot: &a2ml::Robot, motion: &WristMotion, swivel: Real) -> JointVector {
    let w = motion.at(0.0);
    ik_cpsa(robot, &CpsaState { pw: w.pw, ow: w.ow, swivel }, None).expect("start IK")[0]
}

fn paper_scene_with_box() -> Vec<Obstacle> {
    let mut scene = paper_spheres();
    scene.push(Obstacle {
        name: "block".to_owned(),
        shape: Shape::Box {
            center: mm(20.0, 20.0, -45.0),
            size: mm(30.0, 30.0, 20.0),
            rotation: Rotation3::identity(),
        },
    });
    scene
}

#[test]
fn every_cell_matches_a_direct_check() {
    let robot = paper_arm();
    let motion = paper_motion(paper_ow());
    let obstacles = paper_scene_with_box();
    let scene = CollisionScene::new(&obstacles);
    let start = start_at(&robot, &motion, 2.5);
    let options = MapOptions { time_steps: 51, angle_steps: 180, ..MapOptions::default() };
    let map = build_map(&robot, &obstacles, &motion, &start, &options).expect("map");
    assert!(map.faults.iter().all(Option::is_none));
    let (nt, n) = (map.times.len(), map.angles.len());
    let free = |i: usize, j: usize| map.is_free(i, j);
    let (mut boundary, mut mismatched, mut forbidden) = (0, 0, 0);
    for i in 0..nt {
        let w = motion.at(map.times[i]);
        for j in 0..n {
            let target = CpsaState { pw: w.pw, ow: w.ow, swivel: map.angles[j] };
            let direct_free = match ik_cpsa(&robot, &target, None) {
                Err(_) => false,
                Ok(branches) => {
                    let pose = arm_pose(&robot, &branches[0]);
                    min_distance(&robot, &pose, &scene).is_none_or(|(d, _, _)| d >= 0.0)
                }
            };
            forbidden += usize::from(!direct_free);
            let on_boundary = [(i.wrapping_sub(1), j), (i + 1, j)]
                .into_iter()
                .filter(|(a, _)| *a < nt)
                .chain([(i, (j + n - 1) % n), (i, (j + 1) % n)])
                .any(|(a, b)| free(a, b) != free(i, j));
            boundary += usize::from(on_boundary);
            if direct_free != free(i, j) {
                assert!(on_boundary, "cell ({i}, {j}) is mislabelled away from any boundary");
                mismatched += 1;
            }
        }
    }
    assert!(forbidden > nt * n / 10, "the scene forbids too little to test: {forbidden}");
    assert!(map.cells.contains(&a2ml::solve::map::Cell::Obstacle(2)), "the box shows");
    assert!(
        (mismatched as Real) < 0.02 * boundary as Real,
        "{mismatched} of {boundary} boundary cells disagree"
    );
}

#[test]
fn planned_profile_holds_at_one_kilohertz() {
    let robot = paper_arm();
    let motion = paper_motion(paper_ow());
    let obstacles = paper_spheres();
    let scene = CollisionScene::new(&obstacles);
    let safety = 0.001;
    let accel_limit = 40.0;
    let options = MapOptions {
        safety_distance: safety,
        acceleration_limits: Some(JointVector::repeat(accel_limit)),
        ..MapOptions::default()
    };
    let probe = build_map(&robot, &obstacles, &motion, &start_at(&robot, &motion, 0.0), &options)
        .expect("map");
    // Start opposite sphere 1's interval at t = 0: in the large free arc.
    let first = probe.intervals.iter().find(|i| i.column == 0 && i.obstacle == 0).expect("Δ1");
    let start = start_at(&robot, &motion, wrap_angle(first.centre + PI));
    let map = build_map(&robot, &obstacles, &motion, &start, &options).expect("map");
    let profile = plan_profile(
        &robot,
        &obstacles,
        &motion,
        &map,
        &start,
        &SwivelTargets::default(),
        &options,
    )
    .expect("profile");
    let trajectory = &profile.trajectory;
    let times = trajectory.times();
    assert!(
        (times[1] - times[0] - 1e-3).abs() < 1e-9 && (times[times.len() - 1] - 5.0).abs() < 1e-12
    );
    assert!((trajectory.positions()[0] - start).amax() < 1e-9, "starts where the arm is");
    let (lower, upper, speed) = (robot.lower(), robot.upper(), robot.velocity_limits());
    let mut worst_track: Real = 0.0;
    for (k, ((t, q), qd)) in
        times.iter().zip(trajectory.positions()).zip(trajectory.velocities()).enumerate()
    {
        let pose = arm_pose(&robot, q);
        let (d, link, obstacle) = min_distance(&robot, &pose, &scene).expect("pairs");
        assert!(d >= safety, "t = {t}: {link} – {obstacle} at {d}");
        for i in 0..7 {
            assert!(q[i] >= lower[i] && q[i] <= upper[i], "t = {t}: joint {i} at {}", q[i]);
            assert!(qd[i].abs() <= speed[i], "t = {t}: joint {i} speed {}", qd[i]);
        }
        if k > 0 {
            let accel = (qd - trajectory.velocities()[k - 1]) / (t - times[k - 1]);
            assert!(accel.amax() <= accel_limit, "t = {t}: acceleration {}", accel.amax());
            // The rates are the positions' derivative (central difference agrees).
            if k + 1 < times.len() {
                let fd = (trajectory.positions()[k + 1] - trajectory.positions()[k - 1]) / 2e-3;
                assert!((fd - qd).amax() < 1e-3, "t = {t}: q' differs from q's slope");
            }
        }
        let w = motion.at(*t);
        worst_track = worst_track.max((pose.wrist - pose.shoulder - w.pw).norm());
        assert!(a2ml::math::rotation_distance(&pose.hand, &w.ow) < 1e-9);
        let swivel = cpsa_state(&robot, &pose).expect("state").swivel;
        assert!(wrap_angle(swivel - profile.swivel[k]).abs() < 1e-9);
    }
    assert!(worst_track <= 1e-9, "wrist path tracked to {worst_track:e} m");
}

#[test]
fn a_sphere_on_the_wrist_path_names_the_time_it_cuts() {
    let robot = paper_arm();
    let motion = paper_motion(paper_ow());
    let center = motion.at(2.5).pw;
    let obstacles = vec![sphere("on_path", center, 0.004)];
    let start = start_at(&robot, &motion, 2.0);
    let options = MapOptions { time_steps: 101, ..MapOptions::default() };
    let map = build_map(&robot, &obstacles, &motion, &start, &options).expect("map");
    let error = plan_profile(
        &robot,
        &obstacles,
        &motion,
        &map,
        &start,
        &SwivelTargets::default(),
        &options,
    )
    .expect_err("no profile through a sphere on the wrist path");
    // The forearm's wrist end enters the sphere (radius 4 + 5 mm) at this time.
    let enter = (0..=5000)
        .map(|k| k as Real * 1e-3)
        .find(|&t| (motion.at(t).pw - center).norm() < 0.009)
        .expect("enters");
    let MapError::NoProfile { time, .. } = error else { panic!("{error}") };
    let dt = map.times[1];
    assert!(
        time >= enter - 0.5 && time <= enter + dt,
        "cut at {time}, the wrist enters at {enter}"
    );
    // The column at the cut, or the one before, is forbidden at every angle reachable.
    let column = map.times.iter().position(|&t| (t - time).abs() < 1e-12).expect("a column");
    assert!((0..map.angles.len()).any(|j| !map.is_free(column, j)));
    assert!(error.to_string().contains(&format!("t = {time:.3} s")), "{error}");
}

#[test]
fn map_solver_plans_the_example_task() {
    let path = format!("{}/examples/swivel_map_spheres.a2ml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).expect("example");
    let task = a2ml::language::parse(&text, Some(std::path::Path::new(&path))).expect("task");
    let robot = a2ml::Robot::from_urdf_file(&task.robot).expect("robot");
    let plan =
        a2ml::solve::plan(&robot, &task, &a2ml::solve::PlanOptions::default()).expect("plan");
    let segment = &plan.segments[0];
    assert_eq!(segment.solver, a2ml::language::SolverChoice::Map);
    // Pw and Ow reach their goal and hold exactly; θsw, which the map releases from its
    // hold, ends away from its start and the report says so (not reached).
    let [pw, ow, swivel] = [&segment.errors[0], &segment.errors[1], &segment.errors[2]];
    assert!(pw.within && ow.within, "{:?}", segment.errors);
    assert!(!swivel.within && !segment.reached && !plan.warnings.is_empty());
    let clearance = segment.clearance.as_ref().expect("pairs");
    assert!(clearance.distance >= 0.0, "{clearance:?}");
    assert!(segment.limit_margin >= 0.0);
    let violations = a2ml::trajectory::check_limits(&plan.trajectory, &robot, 1e-9);
    assert!(violations.is_empty(), "{violations:?}");
}
