//! Judging a motion's path: the largest deviation over its samples, which leaves out the
//! states a bound shows cannot raise it, against measuring every state; and a whole plan,
//! which judges and reports segments on other threads, against the thread pool's size.

use a2ml::Robot;
use a2ml::decompose::ArmState;
use a2ml::language::{self, Target, Variable};
use a2ml::math::{Real, Vector3};
use a2ml::profile::{PositionReference, Reference, Role, RotationReference};
use a2ml::solve::chart::Chart;
use a2ml::solve::problem::{Component, SegmentProblem};
use a2ml::solve::{PlanOptions, Tolerance, plan};

use crate::common;

/// A CPSA segment whose wrist follows a line while its orientation turns about an axis (two
/// moving path components: the deviation searches σ), the swivel angle held.
fn line_and_turn(start: &ArmState) -> SegmentProblem {
    let pw = PositionReference::line(start.cpsa.pw, &Vector3::new(0.3, -0.5, 0.8), 0.12, 1.2)
        .expect("valid line");
    let ow = RotationReference::about(start.cpsa.ow, &Vector3::new(-0.2, 0.9, 0.4), 0.7, 1.2)
        .expect("valid turn");
    let swivel = Reference::hold(Variable::Swivel, Target::Angle(start.cpsa.swivel), 1.2)
        .expect("valid hold");
    let path = |variable, reference| Component { variable, reference, role: Role::Path };
    SegmentProblem {
        space: a2ml::language::Space::Cpsa,
        components: [
            path(Variable::Pw, Reference::Position(pw)),
            path(Variable::Ow, Reference::Rotation(ow)),
            path(Variable::Swivel, swivel),
        ],
        duration: 1.2,
    }
}

#[test]
fn the_largest_deviation_is_that_of_every_state_measured() {
    let robot = common::load("coman_right_arm");
    let mut rng = common::rng(7);
    let tolerances = [
        Tolerance::default(),
        Tolerance { position: 1e-4, angle: 0.05 },
        Tolerance { position: 0.05, angle: 1e-4 },
    ];
    let mut left_out = 0;
    for case in 0..6 {
        let (q0, _) = common::regular_q(&robot, &mut rng, 0.2);
        let start = ArmState::at(&robot, &q0).expect("regular");
        let problem = line_and_turn(&start);
        let chart = Chart::new(&robot, &problem);
        // States spread from close to the start to well off it, in no particular order.
        let states: Vec<ArmState> = (0..120)
            .map(|k| {
                let spread = 1e-3 + 0.1 * ((k * 37) % 120) as Real / 120.0;
                common::nearby(&robot, &q0, &mut rng, spread)
            })
            .filter_map(|q| ArmState::at(&robot, &q).ok())
            .collect();
        for tolerance in &tolerances {
            let every = states
                .iter()
                .map(|s| chart.deviation(s, tolerance))
                .fold([0.0; 3], |worst: [Real; 3], e| std::array::from_fn(|k| worst[k].max(e[k])));
            let largest = chart.largest_deviation(&states, tolerance);
            assert_eq!(largest.map(Real::to_bits), every.map(Real::to_bits), "case {case}");
            for state in &states {
                let bound = chart.deviation_bound(state, tolerance).expect("two moving paths");
                let e = chart.deviation(state, tolerance);
                let worst = (0..3)
                    .map(|k| e[k] / tolerance.of(problem.components[k].variable))
                    .fold(0.0, Real::max);
                assert!(worst <= bound, "case {case}: {worst} above its bound {bound}");
                let raises =
                    (0..3).any(|k| tolerance.of(problem.components[k].variable) * bound > every[k]);
                left_out += usize::from(!raises);
            }
        }
    }
    // The bound is tight enough to leave states out, or the test would not test it.
    assert!(left_out > 0);
}

/// The segments are judged and reported beside the solving, and Opt1/Opt2's starts searched
/// side by side: none of it may change the plan, whatever the number of threads.
#[test]
fn a_plan_is_the_same_on_any_number_of_threads() {
    let task = language::load(common::example("push_box_aside_coman.a2ml")).expect("loads");
    let robot = Robot::from_urdf_file(&task.robot).expect("robot");
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        let planned = pool.install(|| plan(&robot, &task, &PlanOptions::default())).expect("plans");
        serde_json::to_string(&planned).expect("serialises")
    };
    let one = on(1);
    assert_eq!(one, on(2));
    assert_eq!(one, on(3));
}
