//! The human-likeness measures against METHODS.md §3.7: pattern extraction on synthetic CPSA
//! trajectories with known windows, the similarity indices, Fitts' law and RULA.

use a2ml::decompose::FittsLaw;
use a2ml::kinematics::{CpsaState, HatState, arm_pose, hat_state, ik_hat};
use a2ml::math::{JointVector, PI, Real, Rotation3, Vector3, rotation_about};
use a2ml::metrics::pattern::{
    ElementSpeeds, Hamp, PatternOptions, Primitive, connection_frequencies, connection_similarity,
    extract, similarity,
};
use a2ml::metrics::rula::{self, RulaAngles, RulaOptions};

use crate::common;

fn hamp(text: &str) -> Hamp {
    text.parse().expect("a pattern")
}

/// Travelled fraction of a (1 - cos) velocity bell over [start, end] at time t.
fn bell_fraction(t: Real, start: Real, end: Real) -> Real {
    let tau = ((t - start) / (end - start)).clamp(0.0, 1.0);
    tau - (2.0 * PI * tau).sin() / (2.0 * PI)
}

/// A CPSA trajectory over [0, 1] s at 120 Hz: P and O on cosine bells over the whole of it, Φ
/// on a cosine bell over `swivel` (or constant).
fn synthetic(swivel: Option<(Real, Real)>) -> ElementSpeeds {
    let times: Vec<Real> = (0..=120).map(|k| Real::from(k) / 120.0).collect();
    let axis = Vector3::new(1.0, 2.0, -0.5).normalize();
    let states: Vec<CpsaState> = times
        .iter()
        .map(|&t| {
            let s = bell_fraction(t, 0.0, 1.0);
            let phi = swivel.map_or(0.0, |(a, b)| bell_fraction(t, a, b));
            CpsaState {
                pw: Vector3::new(0.3, -0.2, -0.3) + s * Vector3::new(0.0, 0.25, 0.2),
                ow: Rotation3::from_matrix_unchecked(rotation_about(&axis, 0.8 * s)),
                swivel: 0.2 + 0.7 * phi,
            }
        })
        .collect();
    ElementSpeeds::of_cpsa(&times, &states)
}

fn test_thresholds() -> PatternOptions {
    PatternOptions {
        relative: 0.001,
        position_speed: 0.0,
        orientation_speed: 0.0,
        swivel_speed: 0.0,
        ..PatternOptions::default()
    }
}

#[test]
fn extraction_finds_the_constructed_windows() {
    let early = extract(&synthetic(Some((0.0, 0.6))), &test_thresholds());
    assert_eq!(early.whole.hamp.to_string(), "ΦPO-PO");
    assert_eq!(early.phase1.hamp.to_string(), "ΦPO");
    assert_eq!(early.phase2.hamp.to_string(), "ΦPO-PO");
    assert!((early.swivel_ratio - 0.60).abs() < 0.02, "R_Φ {}", early.swivel_ratio);
    // P peaks at T/2.
    assert_eq!(early.peak, Some(60));

    let late = extract(&synthetic(Some((0.3, 1.0))), &test_thresholds());
    assert_eq!(late.whole.hamp.to_string(), "PO-ΦPO");
    let still = extract(&synthetic(None), &test_thresholds());
    assert_eq!(still.whole.hamp.to_string(), "PO");
    assert_eq!(still.swivel_ratio, 0.0);

    // With the default η = 0.05, P's window shrinks to 85.6 % of T while Φ's bell starts
    // before it: R_Φ = (0.557 - 0.072) / 0.856 ≈ 0.57.
    let default = extract(&synthetic(Some((0.0, 0.6))), &PatternOptions::default());
    assert_eq!(default.whole.hamp.to_string(), "ΦPO-PO");
    assert!((default.swivel_ratio - 0.567).abs() < 0.02, "R_Φ {}", default.swivel_ratio);
    let (first, last) = default.window.expect("P moves");
    let window = Real::from(u32::try_from(last - first).expect("small")) / 120.0;
    assert!((window - 0.856).abs() < 0.02, "window {window}");
}

#[test]
fn the_durations_of_the_runs_add_up_to_the_window() {
    let phases = extract(&synthetic(Some((0.0, 0.6))), &test_thresholds());
    let runs = &phases.whole.runs;
    assert_eq!(runs.len(), 2);
    assert_eq!(runs[0].last + 1, runs[1].first);
    // Φ's run ends where its bell does, at 0.6 T.
    assert!((runs[0].duration - 0.6).abs() < 0.02, "{}", runs[0].duration);
}

#[test]
fn patterns_read_and_print_back() {
    for text in ["ΦPO-PO", "P-ΦPO-PO", "ΦP-ΦPO", "PO", ""] {
        assert_eq!(hamp(text).to_string(), text);
    }
    assert_eq!(hamp("phiPO-PO"), hamp("ΦPO-PO"));
    for bad in ["OP", "ΦΦ", "X", "ΦPO--PO"] {
        assert!(bad.parse::<Hamp>().is_err(), "{bad}");
    }
    assert_eq!("PO".parse::<Primitive>(), Ok(Primitive::POSITION_ORIENTATION));
}

#[test]
fn similarity_matches_the_worked_examples() {
    assert_eq!(similarity(&hamp("ΦPO-PO"), &hamp("P-ΦPO-PO")), 0.8);
    assert_eq!(similarity(&hamp("ΦPO-PO"), &hamp("ΦPO")), 2.0 / 3.0);
    assert_eq!(similarity(&hamp("PO-ΦPO"), &hamp("PO-ΦPO")), 1.0);
}

/// Table III (delivery), phase 2, the top five rows as the population (shares of all samples).
fn delivery_phase2() -> Vec<(Hamp, Real)> {
    [
        ("ΦPO-PO", 0.4120),
        ("ΦPO", 0.2500),
        ("ΦPO-PO-ΦPO", 0.1071),
        ("ΦPO-PO-ΦPO-PO", 0.0852),
        ("PO-ΦPO-PO", 0.0396),
    ]
    .into_iter()
    .map(|(h, f)| (hamp(h), f))
    .collect()
}

#[test]
fn connection_frequencies_and_simc_match_the_worked_example() {
    let population = delivery_phase2();
    let f_l = connection_frequencies(&population);
    let by_name: Vec<(String, Real)> = f_l.iter().map(|(c, f)| (c.to_string(), *f)).collect();
    let get = |name: &str| by_name.iter().find(|(n, _)| n == name).map(|(_, f)| *f);
    assert!((get("ΦPO-PO").expect("type") - 0.6021).abs() < 1e-4);
    assert!((get("ΦPO-").expect("type") - 0.2064).abs() < 1e-4);
    assert!((get("PO-ΦPO").expect("type") - 0.1915).abs() < 1e-4);
    assert!((f_l.values().sum::<Real>() - 1.0).abs() < 1e-12);

    let (h, s) = (hamp("ΦPO-PO"), hamp("ΦPO"));
    let simc = connection_similarity(&h, &s, 0.412, &f_l);
    assert!((simc - 0.842).abs() < 1e-3, "simc {simc}");
    for text in ["ΦPO-PO", "ΦPO", "PO-ΦPO-PO"] {
        assert_eq!(connection_similarity(&hamp(text), &hamp(text), 0.3, &f_l), 1.0);
    }
    // simc does not decrease as the target grows more frequent.
    let mut previous = 0.0;
    for k in 0..=10 {
        let value = connection_similarity(&h, &s, Real::from(k) / 10.0, &f_l);
        assert!(value >= previous);
        previous = value;
    }
}

#[test]
fn mpcsi_prefers_the_pattern_closest_to_the_samples() {
    let population = delivery_phase2();
    let samples: Vec<Hamp> = ["ΦPO-PO", "ΦPO-PO", "ΦPO-PO-ΦPO"].map(hamp).to_vec();
    let candidates = [hamp("ΦPO-PO"), hamp("PO")];
    let scores = a2ml::metrics::pattern::mpcsi(&candidates, &samples, &population);
    assert!(scores[0] > scores[1], "{scores:?}");
    assert!(scores.iter().all(|s| (0.0..=1.0).contains(s)));
}

#[test]
fn fitts_durations_match_the_derived_values() {
    let law = FittsLaw::default();
    assert!((law.duration(0.100) - 0.8027).abs() < 1e-4);
    assert!((law.duration(0.300) - 1.0127).abs() < 1e-4);
    let check = a2ml::metrics::fitts::fitts_check(&law, 0.3, 2.0 * law.duration(0.3));
    assert!((check.ratio - 2.0).abs() < 1e-12);
    let (t1, t2) = a2ml::metrics::fitts::phase_durations(1.2);
    assert_eq!((t1, t2), (0.6, 0.6));
}

#[test]
fn table_a_lookups() {
    assert_eq!(rula::table_a(1, 1, 1, 1), 1);
    assert_eq!(rula::table_a(3, 2, 2, 1), 4);
    assert_eq!(rula::table_a(4, 3, 4, 2), 6);
    for w in 1..=4 {
        for wt in 1..=2 {
            assert_eq!(rula::table_a(6, 3, w, wt), 9);
        }
    }
    // The decided disputed cells (see the comment on the table).
    assert_eq!(rula::table_a(5, 2, 3, 2), 7);
    assert_eq!(rula::table_a(2, 3, 1, 2), 4);
}

fn posture(upper: Real, abduction: Real, elbow: Real, wrist: Real, deviation: Real) -> RulaAngles {
    RulaAngles {
        upper_arm_flexion: upper.to_radians(),
        upper_arm_abduction: abduction.to_radians(),
        elbow_flexion: elbow.to_radians(),
        across_or_out: false,
        wrist_flexion: wrist.to_radians(),
        wrist_deviation: deviation.to_radians(),
        twist: 0.0,
    }
}

fn group(angles: &RulaAngles) -> [u8; 6] {
    let s = rula::scores(angles, &RulaOptions::default());
    [s.upper_arm, s.lower_arm, s.wrist, s.wrist_twist, s.table_a, s.sum]
}

#[test]
fn rula_postures_a_b_c() {
    assert_eq!(group(&posture(0.0, 0.0, 90.0, 0.0, 0.0)), [1, 1, 1, 1, 1, 3]);
    let b = RulaAngles { twist: 1.0, ..posture(60.0, 30.0, 80.0, 20.0, 15.0) };
    assert_eq!(group(&b), [4, 1, 4, 2, 5, 9]);
    assert_eq!(group(&posture(-30.0, 0.0, 110.0, 10.0, 0.0)), [2, 2, 2, 1, 3, 6]);
}

#[test]
fn rula_bands_include_their_lower_bound() {
    let options = RulaOptions::default();
    let upper = |deg: Real| rula::upper_arm_score(&posture(deg, 0.0, 90.0, 0.0, 0.0), &options);
    assert_eq!([upper(19.9), upper(20.0)], [1, 2]);
    assert_eq!([upper(44.9), upper(45.0)], [2, 3]);
    assert_eq!([upper(89.9), upper(90.0)], [3, 4]);
    assert_eq!([upper(-20.0), upper(-20.1)], [1, 2]);
    let lower = |deg: Real| rula::lower_arm_score(&posture(0.0, 0.0, deg, 0.0, 0.0));
    assert_eq!([lower(59.9), lower(60.0)], [2, 1]);
    assert_eq!([lower(99.9), lower(100.0)], [1, 2]);
    let wrist = |deg: Real| rula::wrist_score(&posture(0.0, 0.0, 90.0, deg, 0.0), &options);
    assert_eq!([wrist(5.0), wrist(5.1), wrist(14.9), wrist(15.0)], [1, 2, 2, 3]);
    let twist = |at: Real| {
        rula::wrist_twist_score(
            &RulaAngles { twist: at, ..posture(0.0, 0.0, 90.0, 0.0, 0.0) },
            &options,
        )
    };
    assert_eq!([twist(0.0), twist(0.49), twist(0.5), twist(1.0)], [1, 1, 2, 2]);
}

/// COMAN's arm turned rigidly about S (wrist joints unchanged) so that its upper arm is
/// flexed 60° forward in the sagittal plane, placed by HAT IK: the RULA angles read back from
/// the joints are those, and the elbow and wrist read as at the start.
#[test]
fn rula_angles_read_the_posture_reached_by_ik() {
    let robot = common::load("coman_right_arm");
    let options = RulaOptions::default();
    let start = JointVector::from_fn(|i, _| {
        [-10.0_f64, -15.0, 45.0, -100.0, 0.0, 0.0, 0.0][i].to_radians()
    });
    let before = hat_state(&arm_pose(&robot, &start)).expect("regular");
    let (at_start, _) = rula::rula_at(&robot, &start, &options).expect("regular");
    let flexion = 60.0_f64.to_radians();
    let r = Vector3::new(flexion.sin(), 0.0, -flexion.cos());
    let mut reached = None;
    for l in [-Vector3::y(), Vector3::y()] {
        let frame = Rotation3::from_basis_unchecked(&[r, l, r.cross(&l)]);
        let turn = frame * before.shoulder_frame.inverse();
        let hat = HatState {
            shoulder_frame: frame,
            elbow_angle: before.elbow_angle,
            ow: turn * before.ow,
        };
        if let Some(q) = ik_hat(&robot, &hat, Some(&start)).ok().and_then(|s| s.first().copied()) {
            reached = Some(q);
            break;
        }
    }
    let q = reached.expect("one arm plane is reachable");
    let (angles, scores) = rula::rula_at(&robot, &q, &options).expect("regular");
    assert!((angles.upper_arm_flexion - flexion).abs() < 1e-6, "{angles:?}");
    assert!(angles.upper_arm_abduction.abs() < 1e-6, "{angles:?}");
    assert!((angles.elbow_flexion - (PI - before.elbow_angle)).abs() < 1e-6);
    assert!((angles.wrist_flexion - at_start.wrist_flexion).abs() < 1e-6);
    assert!((angles.wrist_deviation - at_start.wrist_deviation).abs() < 1e-6);
    assert_eq!(scores.upper_arm, 3);
}
