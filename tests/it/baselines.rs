//! The baselines GPM, weighted CLIK and λ0-PMP (METHODS.md §2, §4, §5): their laws checked
//! along simulated runs on the shipped arms, the paper's 3-DoF wrist for λ0-PMP, and their
//! examples planned through the whole pipeline.

use a2ml::Robot;
use a2ml::kinematics::{arm_pose, geometric_jacobian};
use a2ml::language::{self, SolverChoice};
use a2ml::math::{JointVector, PI, Real, Rotation3, Vector3, rotation_about};
use a2ml::solve::clik::{Clik, ClikOptions, HeightTarget, pen_point};
use a2ml::solve::control::{ControlOptions, ControlRun, HandReference, Vector6, run};
use a2ml::solve::gpm::{Gpm, GpmOptions, centring, gpm_velocity};
use a2ml::solve::pmp::{
    Pmp, PmpOptions, PmpTask, PmpVariant, largest_damping, pmp_velocity, stiffness_ramp,
    task_damping, task_jacobian,
};
use a2ml::solve::{PlanOptions, Tolerance, plan};
use nalgebra::{DMatrix, DVector};

use crate::common;

/// A regular in-limit start on `robot`, the same for every test.
fn start(robot: &Robot, seed: u64) -> JointVector {
    common::regular_q(robot, &mut common::rng(seed), 0.3).0
}

/// The hand's pose at q.
fn hand(robot: &Robot, q: &JointVector) -> (Vector3, Rotation3) {
    let pose = arm_pose(robot, q);
    (pose.wrist, pose.hand)
}

/// Samples solved by the resolver (the braking tail excluded).
fn solved(run: &ControlRun) -> impl Iterator<Item = (Real, &JointVector, &JointVector)> {
    let t = &run.trajectory;
    t.times()
        .iter()
        .zip(t.positions())
        .zip(t.velocities())
        .take(run.steps)
        .map(|((t, q), v)| (*t, q, v))
}

#[test]
fn gpm_tracks_the_hand_twist_exactly_on_every_arm() {
    for (name, robot) in common::all_robots() {
        let q0 = start(&robot, 1);
        let (p0, r0) = hand(&robot, &q0);
        let turn =
            Rotation3::from_matrix_unchecked(rotation_about(&Vector3::new(0.0, 0.6, 0.8), 0.3));
        let goal = (p0 + Vector3::new(0.05, -0.04, 0.03), turn * r0);
        let reference = HandReference::straight((p0, r0), goal, 1.0).expect("reference");
        let gpm = Gpm::new(&robot, reference, GpmOptions::default(), Tolerance::default());
        let run =
            run(&robot, &mut gpm.clone(), &q0, 1.0, &ControlOptions::default()).expect("runs");
        let mut checked = 0;
        for (t, q, v) in solved(&run) {
            let pose = arm_pose(&robot, q);
            let j = geometric_jacobian(&pose);
            if (j * j.transpose()).symmetric_eigen().eigenvalues.min() < 1e-5 {
                continue; // near a singularity
            }
            let twist: Vector6 = gpm.twist(&pose, t);
            assert!((j * v - twist).norm() <= 1e-10 * (1.0 + twist.norm()), "{name} at {t}");
            checked += 1;
        }
        assert!(checked > run.steps / 2, "{name}: {checked} of {} steps regular", run.steps);
        // Closed loop: the hand ends on its goal.
        // Closed loop and never near a singularity: the hand ends on its goal.
        if checked == run.steps {
            let end = hand(&robot, &run.trajectory.positions()[run.steps - 1]);
            assert!((end.0 - goal.0).norm() < 1e-3, "{name}: {}", (end.0 - goal.0).norm());
        }
    }
}

#[test]
fn gpm_with_a_still_hand_raises_the_centring_criterion_monotonically() {
    for (name, robot) in common::all_robots() {
        // A start where the self-motion has something to do: ‖(I - J⁺J)∇H‖ > 0.5.
        let null_gradient = |q: &JointVector| {
            let j = geometric_jacobian(&arm_pose(&robot, q));
            let gradient = a2ml::solve::gpm::centring_gradient(q, &robot.middle());
            gpm_velocity(&j, &Vector6::zeros(), &gradient, 1.0).map_or(0.0, |v| v.norm())
        };
        let q0 = (2..)
            .map(|seed| start(&robot, seed))
            .find(|q| null_gradient(q) > 0.5)
            .expect("a start");
        let still =
            HandReference::straight(hand(&robot, &q0), hand(&robot, &q0), 1.0).expect("hold");
        // X' = 0: no reference motion and no feedback.
        let options = GpmOptions { feedback_gain: 0.0, ..GpmOptions::default() };
        let mut gpm = Gpm::new(&robot, still, options, Tolerance::default());
        let control = ControlOptions { max_settle: 0.0, ..ControlOptions::default() };
        let run = run(&robot, &mut gpm, &q0, 1.0, &control).expect("runs");
        let centre = robot.middle();
        let h: Vec<Real> =
            run.trajectory.positions().iter().map(|q| centring(q, &centre)).collect();
        assert!(h.windows(2).all(|w| w[1] >= w[0] - 1e-12), "{name}: H decreased");
        assert!(
            h[h.len() - 1] > h[0] + 1e-3,
            "{name}: H did not rise: {} -> {}",
            h[0],
            h[h.len() - 1]
        );
    }
}

/// The corners of a trapezoid in the horizontal plane, relative to the start (m).
const TRAPEZOID: [[Real; 2]; 4] = [[0.0, 0.0], [0.0, 0.16], [0.08, 0.12], [0.08, 0.04]];

/// CLIK traces the trapezoid, scaled by `size`, from q0 with the hand's orientation held: one
/// run per side, each from where the last ended; the pen starts `offset` away from its path.
fn draw(
    robot: &Robot,
    q0: &JointVector,
    options: ClikOptions,
    control: &ControlOptions,
    offset: Vector3,
    size: Real,
) -> Vec<(Clik, ControlRun)> {
    let (p0, r0) = hand(robot, q0);
    let mut q = *q0;
    let mut out = Vec::new();
    for k in 0..4 {
        let corner =
            |i: usize| p0 + Vector3::new(TRAPEZOID[i % 4][0], TRAPEZOID[i % 4][1], 0.0) * size;
        let from = if k == 0 { corner(0) + offset } else { corner(k) };
        let reference =
            HandReference::straight((from, r0), (corner(k + 1), r0), 1.0).expect("side");
        let mut clik = Clik::new(robot, reference, options, Tolerance::default());
        let side = run(robot, &mut clik, &q, 1.0, control).expect("draws");
        q = *side.trajectory.positions().last().expect("samples");
        out.push((clik, side));
    }
    out
}

/// A drawing posture on the iiwa: the elbow 0.39 m in front of the shoulder and 0.14 m below
/// it, the forearm pointing down, the pen 5 cm below the wrist.
fn drawing_start() -> JointVector {
    JointVector::from_column_slice(&[0.0, 110.0, 0.0, -60.0, 0.0, -50.0, 0.0]).map(Real::to_radians)
}

#[test]
fn clik_corrects_a_centimetre_start_error_at_its_gain() {
    let robot = common::load("iiwa14");
    let q0 = drawing_start();
    let options = ClikOptions {
        elbow_height: HeightTarget::Off,
        wrist_height: HeightTarget::Off,
        ..ClikOptions::default()
    };
    let sides =
        draw(&robot, &q0, options, &ControlOptions::default(), Vector3::new(0.0, 0.0, 0.01), 1.0);
    let (clik, first) = &sides[0];
    let error = |i: usize| {
        let q = &first.trajectory.positions()[i];
        let t = first.trajectory.times()[i];
        (clik.pen_target(t) - pen_point(&arm_pose(&robot, q), &ClikOptions::default().pen)).norm()
    };
    let at = |time: Real| {
        first.trajectory.times().iter().position(|t| (t - time).abs() < 1e-9).expect("grid point")
    };
    let ratio = error(at(0.1)) / error(0);
    assert!((error(0) - 0.01).abs() < 1e-12);
    assert!((ratio / (-3.0_f64).exp() - 1.0).abs() < 0.1, "ratio {ratio}");
    // Converged: below a micrometre for the rest of the drawing.
    for (k, (clik, side)) in sides.iter().enumerate() {
        for (i, (t, q, _)) in solved(side).enumerate() {
            if k == 0 && t < 0.6 {
                continue;
            }
            let pen = pen_point(&arm_pose(&robot, q), &ClikOptions::default().pen);
            let e = (clik.pen_target(t) - pen).norm();
            assert!(e < 1e-6, "side {k}: pen error {e} at sample {i}");
        }
    }
}

/// Σ_{i≥5}|q_i'| / Σ|q_i'| over a drawing.
fn distal_share(sides: &[(Clik, ControlRun)]) -> Real {
    let (mut distal, mut all) = (0.0, 0.0);
    for (_, side) in sides {
        for (_, _, v) in solved(side) {
            distal += v.rows(4, 3).abs().sum();
            all += v.abs().sum();
        }
    }
    distal / all
}

#[test]
fn clik_beta_weights_keep_the_distal_joints_out_of_the_drawing() {
    let robot = common::load("iiwa14");
    let q0 = drawing_start();
    let off = ClikOptions {
        elbow_height: HeightTarget::Off,
        wrist_height: HeightTarget::Off,
        ..ClikOptions::default()
    };
    let control = ControlOptions::default();
    let weighted = distal_share(&draw(&robot, &q0, off, &control, Vector3::zeros(), 1.0));
    let plain = ClikOptions { beta: JointVector::repeat(1.0), ..off };
    let unweighted = distal_share(&draw(&robot, &q0, plain, &control, Vector3::zeros(), 1.0));
    assert!(weighted < unweighted, "{weighted} vs {unweighted}");
}

#[test]
fn clik_layers_take_elbow_and_wrist_to_their_heights_without_moving_the_pen() {
    let robot = common::load("iiwa14");
    let q0 = drawing_start();
    let pose = arm_pose(&robot, &q0);
    let (elbow, wrist) = (pose.elbow.z - 0.04, pose.wrist.z - 0.02);
    let layered = ClikOptions {
        elbow_height: HeightTarget::At(elbow),
        wrist_height: HeightTarget::At(wrist),
        ..ClikOptions::default()
    };
    let off =
        ClikOptions { elbow_height: HeightTarget::Off, wrist_height: HeightTarget::Off, ..layered };
    // A finer step, so that RK4's error on the layers' fast (200/s) motion stays far below
    // the micrometre compared.
    let control = ControlOptions { step: 5e-4, ..ControlOptions::default() };
    // Half size: far enough from the edge of what the heights allow while the pen moves.
    let with = draw(&robot, &q0, layered, &control, Vector3::zeros(), 0.5);
    let without = draw(&robot, &q0, off, &control, Vector3::zeros(), 0.5);
    let pen = ClikOptions::default().pen;
    for (k, ((_, a), (_, b))) in with.iter().zip(&without).enumerate() {
        for ((_, qa, _), (_, qb, _)) in solved(a).zip(solved(b)) {
            let (pa, pb) =
                (pen_point(&arm_pose(&robot, qa), &pen), pen_point(&arm_pose(&robot, qb), &pen));
            assert!((pa - pb).norm() <= 1e-6, "side {k}: pen paths differ by {}", (pa - pb).norm());
        }
        let end = arm_pose(&robot, a.trajectory.positions().last().expect("samples"));
        assert!(
            (end.elbow.z - elbow).abs() <= 1e-3,
            "side {k}: elbow at {} for {elbow}",
            end.elbow.z
        );
        assert!(
            (end.wrist.z - wrist).abs() <= 1e-3,
            "side {k}: wrist at {} for {wrist}",
            end.wrist.z
        );
        let free = arm_pose(&robot, b.trajectory.positions().last().expect("samples"));
        assert!(
            (free.elbow.z - elbow).abs() > 1e-2,
            "side {k}: the elbow got there without its layer"
        );
    }
}

/// PMP from q0 towards the hand pose at q_goal over `duration`, with τ = `tau`.
fn pmp_run(
    robot: &Robot,
    q0: &JointVector,
    goal: (Vector3, Rotation3),
    options: PmpOptions,
    duration: Real,
    tau: Real,
) -> (Pmp, ControlRun) {
    let options = PmpOptions { time_constant_fraction: tau / duration, ..options };
    let pmp = Pmp::new(robot, q0, goal, duration, &options, Tolerance::default()).expect("pmp");
    let control = ControlOptions { max_settle: 0.0, ..ControlOptions::default() };
    let run = run(robot, &mut pmp.clone(), q0, duration, &control).expect("runs");
    (pmp, run)
}

#[test]
fn lambda0_pmp_moves_the_task_by_its_damping_exactly() {
    let robot = common::load("iiwa14");
    let q0 = start(&robot, 3);
    let goal = hand(&robot, &common::nearby(&robot, &q0, &mut common::rng(4), 0.4));
    for task in [PmpTask::Position, PmpTask::Pose] {
        let options = PmpOptions { task, ..PmpOptions::default() };
        let (pmp, run) = pmp_run(&robot, &q0, goal, options, 1.0, 0.2);
        for (t, q, v) in solved(&run) {
            let pose = arm_pose(&robot, q);
            let b = pmp.damping(&pose).expect("regular");
            let j = task_jacobian(task, &pose);
            let left = &b * (&j * DVector::from_column_slice(v.as_slice()));
            let right = pmp.task_error(&pose) * pmp.ramp(t);
            // Relative to the terms the identity balances: at t = 0 K(t) = 0 and λ0 cancels
            // the elastic term alone.
            let scale = right.norm().max(b.norm() * j.norm() * v.norm());
            assert!((&left - &right).norm() <= 1e-9 * scale, "{task:?} at {t}");
        }
    }
}

#[test]
fn lambda0_pmp_obeys_donders_law_and_pmp1_does_not() {
    let robot = common::load("iiwa14");
    let q0 = start(&robot, 5);
    let mut rng = common::rng(6);
    let goal = hand(&robot, &common::nearby(&robot, &q0, &mut rng, 0.4));
    let via = hand(&robot, &common::nearby(&robot, &q0, &mut rng, 0.4));
    let end = |run: &ControlRun| *run.trajectory.positions().last().expect("samples");
    let mut finals = Vec::new();
    for variant in [PmpVariant::Lambda0, PmpVariant::Pmp1] {
        let options = PmpOptions { variant, stiffness: Some(20.0), ..PmpOptions::default() };
        // 40 τ per target: the posture converges to far below 1e-6 rad.
        let (_, direct) = pmp_run(&robot, &q0, goal, options, 8.0, 0.2);
        let (_, first) = pmp_run(&robot, &q0, via, options, 8.0, 0.2);
        let (_, second) = pmp_run(&robot, &end(&first), goal, options, 8.0, 0.2);
        finals.push((end(&direct), end(&second)));
        let reached = hand(&robot, &end(&direct));
        assert!((reached.0 - goal.0).norm() < 1e-6, "{variant:?} missed the target");
    }
    let (a, b) = finals[0];
    assert!((a - b).amax() <= 1e-6, "λ0-PMP: {}", (a - b).amax());
    let (a, b) = finals[1];
    assert!((a - b).amax() > 1e-3, "PMP1: {}", (a - b).amax());
}

#[test]
fn pmp2_leaves_a_steady_state_error() {
    let robot = common::load("iiwa14");
    let q0 = start(&robot, 7);
    let goal = hand(&robot, &common::nearby(&robot, &q0, &mut common::rng(8), 0.4));
    let options =
        PmpOptions { variant: PmpVariant::Pmp2, task: PmpTask::Position, ..PmpOptions::default() };
    let (_, run) = pmp_run(&robot, &q0, goal, options, 3.0, 0.2);
    let reached = hand(&robot, run.trajectory.positions().last().expect("samples"));
    assert!((reached.0 - goal.0).norm() > 1e-3, "{}", (reached.0 - goal.0).norm());
}

/// The paper's wrist (eq. 6, d = 1 m): q = (PS, FE, RUD) to the screen point x.
fn wrist_point(q: &DVector<Real>) -> DVector<Real> {
    let r = rotation_about(&-Vector3::x(), q[0])
        * rotation_about(&Vector3::z(), q[1])
        * rotation_about(&Vector3::y(), q[2]);
    let pointing = r * Vector3::x();
    DVector::from_column_slice(&[-pointing.y, pointing.z])
}

fn wrist_jacobian(q: &DVector<Real>) -> DMatrix<Real> {
    let h = 1e-7;
    let mut j = DMatrix::zeros(2, 3);
    for c in 0..3 {
        let mut step = DVector::zeros(3);
        step[c] = h;
        j.set_column(c, &((wrist_point(&(q + &step)) - wrist_point(&(q - &step))) / (2.0 * h)));
    }
    j
}

/// λ0-PMP on the wrist with the Fig. 3 parameters from q* to the target at `angle`, RK4 with
/// dt = 0.5 ms over T = 0.4 s: the largest deviation from the straight line (m).
fn wrist_deviation(angle: Real) -> Real {
    let stiffness = DVector::from_column_slice(&[0.5, 1.5, 2.0]);
    let tau = 0.08;
    let w_inverse = stiffness.map(|k| 1.0 / (tau * k));
    let rest = DVector::from_column_slice(&[5.0_f64.to_radians(), 0.0, 0.0]);
    let target = DVector::from_column_slice(&[angle.cos(), angle.sin()]) * (PI / 12.0);
    let velocity = |q: &DVector<Real>, t: Real| {
        let force = (&target - wrist_point(q)) * stiffness_ramp(t, 22.5, tau);
        let elastic = (q - &rest).component_mul(&stiffness);
        pmp_velocity(PmpVariant::Lambda0, &wrist_jacobian(q), &w_inverse, &elastic, &force)
            .expect("regular")
    };
    let (dt, mut q, mut worst) = (5e-4, rest.clone(), 0.0_f64);
    let direction = &target / target.norm();
    for k in 0..800 {
        let t = k as Real * dt;
        let k1 = velocity(&q, t);
        let k2 = velocity(&(&q + &k1 * (dt / 2.0)), t + dt / 2.0);
        let k3 = velocity(&(&q + &k2 * (dt / 2.0)), t + dt / 2.0);
        let k4 = velocity(&(&q + &k3 * dt), t + dt);
        q += (k1 + (k2 + k3) * 2.0 + k4) * (dt / 6.0);
        let x = wrist_point(&q);
        worst = worst.max((&x - &direction * x.dot(&direction)).norm());
    }
    assert!((wrist_point(&q) - &target).norm() < 1e-6, "the wrist missed its target");
    worst
}

#[test]
fn lambda0_pmp_on_the_papers_wrist_curves_diagonal_paths_only() {
    let length = PI / 12.0;
    for k in 0..8 {
        let deviation = wrist_deviation(k as Real * PI / 4.0) / length;
        if k % 2 == 0 {
            assert!(deviation < 0.01, "cardinal {k}: {deviation}");
        } else {
            assert!(deviation > 0.03, "diagonal {k}: {deviation}");
        }
    }
    let stiffness = DVector::from_column_slice(&[0.5, 1.5, 2.0]);
    let w_inverse = stiffness.map(|k| 1.0 / (0.08 * k));
    let rest = DVector::from_column_slice(&[5.0_f64.to_radians(), 0.0, 0.0]);
    let b = task_damping(&wrist_jacobian(&rest), &w_inverse).expect("regular");
    let eigen = b.symmetric_eigen().eigenvalues;
    assert!(
        (largest_damping(&wrist_jacobian(&rest), &w_inverse).expect("regular") - 0.16).abs() < 1e-8
    );
    assert!((eigen.min() - 0.12).abs() < 1e-8, "{eigen}");
}

#[test]
fn the_baseline_examples_plan_and_show_their_character() {
    let load = |name: &str| {
        let task = language::load(common::example(name)).expect("loads");
        let robot = Robot::from_urdf_file(&task.robot).expect("robot");
        (task, robot)
    };
    let with = |solver| PlanOptions { solver: Some(solver), ..PlanOptions::default() };

    // GPM: the joints end nearer the middle of their ranges than the QP leaves them.
    let (task, robot) = load("baseline_gpm.a2ml");
    let gpm = plan(&robot, &task, &PlanOptions::default()).expect("plans");
    assert!(gpm.segments.iter().all(|s| s.solver == SolverChoice::Gpm));
    let qp = plan(&robot, &task, &with(SolverChoice::Qp)).expect("plans");
    let off_centre = |p: &a2ml::solve::Plan| {
        (p.trajectory.positions().last().expect("samples") - robot.middle()).norm()
    };
    assert!(
        off_centre(&gpm) < off_centre(&qp) - 0.05,
        "{} vs {}",
        off_centre(&gpm),
        off_centre(&qp)
    );
    // The swivel angle it was told to hold goes where the centring takes it.
    let s = &gpm.segments[0];
    assert!(!s.path_errors[2].within, "{:?}", s.path_errors);

    // CLIK: the pen's trapezoid drawn with the elbow lower than the QP holds it.
    let (task, robot) = load("baseline_clik.a2ml");
    let clik = plan(&robot, &task, &PlanOptions::default()).expect("plans");
    let qp = plan(&robot, &task, &with(SolverChoice::Qp)).expect("plans");
    let lowest = |p: &a2ml::solve::Plan| {
        p.trajectory
            .positions()
            .iter()
            .map(|q| arm_pose(&robot, q).elbow.z)
            .fold(Real::INFINITY, Real::min)
    };
    assert!(lowest(&clik) < lowest(&qp) - 0.02, "{} vs {}", lowest(&clik), lowest(&qp));

    // PMP: the wrist reaches each goal along a curve, where the QP keeps the line.
    let (task, robot) = load("baseline_pmp.a2ml");
    let pmp = plan(&robot, &task, &PlanOptions::default()).expect("plans");
    for s in &pmp.segments {
        assert!(s.errors[0].within, "{:?}", s.errors);
        assert!(s.path_errors[0].error > 2e-3, "{:?}", s.path_errors);
    }
}
