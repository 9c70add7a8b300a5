//! Joining the joint trajectories of consecutive segments: the transitional connection +Tr
//! (paper appendix A, eq. A.1) and the sequential connection +Se (docs/design.md §4).
//!
//! A trajectory is anything that gives joint positions and velocities at a time,
//! `Fn(Real) -> JointSample`, each in its own time starting at 0. The joined trajectory is
//! again such a function, so joins chain: join the first two, then the result with the third.
//! [`transitional`] and [`sequential`] join such functions; [`super::join_transitional`] and
//! [`super::join_sequential`] join sampled [`super::Trajectory`]s through them.

use crate::math::{DOF, JointVector, PI, Real};
use crate::profile::ProfileError;

/// Joint positions q (rad) and velocities q' (rad/s) at one instant.
pub type JointSample = (JointVector, JointVector);

/// Settings of the transitional connection.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TransitionOptions {
    /// The overlap as a fraction of the shorter segment's duration (default 0.2), the task
    /// setting `transition`.
    pub overlap_fraction: Real,
}

impl Default for TransitionOptions {
    fn default() -> Self {
        Self { overlap_fraction: 0.2 }
    }
}

/// The overlap window [t2s, t1e] of a transitional connection (appendix A), in the time of the
/// joined trajectory: the first segment runs over [0, T1] (t1e = T1), the second over
/// [t2s, t2s + T2].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    second_start: Real,
    first_end: Real,
    second_duration: Real,
}

impl Transition {
    /// The transition of a first segment of `first_duration` (s) into a second of
    /// `second_duration` (s), overlapping by `overlap` (s). A zero overlap switches at t1e.
    ///
    /// # Errors
    /// [`ProfileError::InvalidOverlap`] unless 0 ≤ overlap ≤ min(T1, T2), all finite.
    pub fn new(
        first_duration: Real,
        second_duration: Real,
        overlap: Real,
    ) -> Result<Self, ProfileError> {
        let valid =
            [first_duration, second_duration, overlap].iter().all(|x| x.is_finite() && *x >= 0.0)
                && overlap <= first_duration.min(second_duration);
        if !valid {
            return Err(ProfileError::InvalidOverlap { overlap, first_duration, second_duration });
        }
        Ok(Self {
            second_start: first_duration - overlap,
            first_end: first_duration,
            second_duration,
        })
    }

    /// The transition with the overlap `options.overlap_fraction` × min(T1, T2).
    ///
    /// # Errors
    /// [`ProfileError::InvalidOverlap`] for a fraction outside [0, 1] or invalid durations.
    pub fn with_options(
        first_duration: Real,
        second_duration: Real,
        options: &TransitionOptions,
    ) -> Result<Self, ProfileError> {
        let overlap = options.overlap_fraction * first_duration.min(second_duration);
        Self::new(first_duration, second_duration, overlap)
    }

    /// t2s: when the second segment starts (s); its local time is t - t2s.
    pub fn second_start(&self) -> Real {
        self.second_start
    }

    /// t1e: when the first segment ends (s).
    pub fn first_end(&self) -> Real {
        self.first_end
    }

    /// t1e - t2s (s).
    pub fn overlap(&self) -> Real {
        self.first_end - self.second_start
    }

    /// The duration of the joined trajectory, t2s + T2 (s).
    pub fn duration(&self) -> Real {
        self.second_start + self.second_duration
    }

    /// The first segment's share β(t) = 0.5 cos(π (t - t2s)/(t1e - t2s)) + 0.5 (eq. A.1):
    /// 1 up to t2s, 0 from t1e on.
    #[inline]
    pub fn beta(&self, t: Real) -> Real {
        let overlap = self.overlap();
        if t <= self.second_start {
            1.0
        } else if t >= self.first_end || overlap <= 0.0 {
            0.0
        } else {
            0.5 * (PI * (t - self.second_start) / overlap).cos() + 0.5
        }
    }

    /// dβ/dt (1/s); zero outside the overlap and at both of its ends.
    #[inline]
    pub fn beta_rate(&self, t: Real) -> Real {
        let overlap = self.overlap();
        if t <= self.second_start || t >= self.first_end || overlap <= 0.0 {
            0.0
        } else {
            -0.5 * PI / overlap * (PI * (t - self.second_start) / overlap).sin()
        }
    }

    /// The blend at t of the first segment's sample and the second's (eq. A.1):
    /// q = β q1 + (1 - β) q2, q' = β q1' + (1 - β) q2' + β' (q1 - q2).
    #[inline]
    pub fn blend(&self, t: Real, first: &JointSample, second: &JointSample) -> JointSample {
        let (beta, rate) = (self.beta(t), self.beta_rate(t));
        let q = first.0 * beta + second.0 * (1.0 - beta);
        let qd = first.1 * beta + second.1 * (1.0 - beta) + (first.0 - second.0) * rate;
        (q, qd)
    }
}

/// The transitional connection +Tr (appendix A): `first` (local time in [0, T1]) up to t2s,
/// the blend over [t2s, t1e], then `second` (called with its local time t - t2s). The
/// result is continuous in q and q' at both seams whenever the inputs are, since β' = 0 there.
pub fn transitional<F1, F2>(
    first: F1,
    second: F2,
    transition: Transition,
) -> impl Fn(Real) -> JointSample
where
    F1: Fn(Real) -> JointSample,
    F2: Fn(Real) -> JointSample,
{
    move |t| {
        if t < transition.second_start {
            first(t)
        } else if t > transition.first_end {
            second(t - transition.second_start)
        } else {
            transition.blend(t, &first(t), &second(t - transition.second_start))
        }
    }
}

/// Tolerances of the sequential connection's continuity check.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SequentialOptions {
    /// Largest |q2(0) - q1(T1)| per joint (rad, default 1e-9): the next segment is planned
    /// from where the last ended, so the gap is rounding only.
    pub position_tolerance: Real,
    /// Largest |q'| per joint on either side of the seam (rad/s, default 1e-3): a closed-loop
    /// solver ends with a small residual speed while the bell reference is at rest.
    pub velocity_tolerance: Real,
}

impl Default for SequentialOptions {
    fn default() -> Self {
        Self { position_tolerance: 1e-9, velocity_tolerance: 1e-3 }
    }
}

/// Checks that a sequential seam is at rest and continuous: `second_start` (the next
/// segment at its t = 0) equals `first_end` (the last at its T) and both are still.
///
/// # Errors
/// [`ProfileError::Discontinuous`] for the joint with the largest gap, else
/// [`ProfileError::NotAtRest`] for the joint with the largest speed, when over tolerance.
pub fn check_sequential(
    first_end: &JointSample,
    second_start: &JointSample,
    options: &SequentialOptions,
) -> Result<(), ProfileError> {
    // The largest entry by magnitude, NaN first.
    let worst = |v: JointVector| -> (usize, Real) {
        (0..DOF).map(|i| (i, v[i])).fold((0, 0.0), |a, b| {
            let worse = b.1.is_nan() || b.1.abs() > a.1.abs();
            if worse && !a.1.is_nan() { b } else { a }
        })
    };
    let (joint, gap) = worst(second_start.0 - first_end.0);
    if gap.is_nan() || gap.abs() > options.position_tolerance {
        return Err(ProfileError::Discontinuous { joint, gap: gap.abs() });
    }
    for velocity in [first_end.1, second_start.1] {
        let (joint, velocity) = worst(velocity);
        if velocity.is_nan() || velocity.abs() > options.velocity_tolerance {
            return Err(ProfileError::NotAtRest { joint, velocity });
        }
    }
    Ok(())
}

/// The sequential connection +Se: `first` over [0, T1], then `second` (local time t - T1),
/// after checking the seam with [`check_sequential`].
///
/// # Errors
/// As [`check_sequential`]; [`ProfileError::InvalidDuration`] for a negative or non-finite T1.
pub fn sequential<F1, F2>(
    first: F1,
    first_duration: Real,
    second: F2,
    options: &SequentialOptions,
) -> Result<impl Fn(Real) -> JointSample, ProfileError>
where
    F1: Fn(Real) -> JointSample,
    F2: Fn(Real) -> JointSample,
{
    if !(first_duration.is_finite() && first_duration >= 0.0) {
        return Err(ProfileError::InvalidDuration { duration: first_duration, distance: 0.0 });
    }
    check_sequential(&first(first_duration), &second(0.0), options)?;
    Ok(move |t: Real| if t <= first_duration { first(t) } else { second(t - first_duration) })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constant(q: Real) -> impl Fn(Real) -> JointSample {
        move |_| (JointVector::repeat(q), JointVector::zeros())
    }

    #[test]
    fn beta_goes_from_one_to_zero_smoothly() {
        let tr = Transition::new(2.0, 1.0, 0.5).expect("valid");
        assert_eq!((tr.second_start(), tr.first_end(), tr.duration()), (1.5, 2.0, 2.5));
        assert_eq!(tr.beta(1.5), 1.0);
        assert!(tr.beta(2.0).abs() < 1e-15);
        assert!((tr.beta(1.75) - 0.5).abs() < 1e-15);
        assert_eq!(tr.beta_rate(1.5), 0.0);
        assert_eq!(tr.beta_rate(2.0), 0.0);
        let h = 1e-6;
        let fd = (tr.beta(1.6 + h) - tr.beta(1.6 - h)) / (2.0 * h);
        assert!((fd - tr.beta_rate(1.6)).abs() < 1e-8);
    }

    #[test]
    fn default_overlap_is_a_fifth_of_the_shorter_segment() {
        let tr = Transition::with_options(3.0, 1.0, &TransitionOptions::default()).expect("valid");
        assert!((tr.overlap() - 0.2).abs() < 1e-15);
        assert!((tr.second_start() - 2.8).abs() < 1e-15);
    }

    #[test]
    fn invalid_overlaps_are_errors() {
        for (a, b, o) in [(1.0, 1.0, 1.5), (1.0, 1.0, -0.1), (1.0, Real::NAN, 0.1)] {
            assert!(matches!(Transition::new(a, b, o), Err(ProfileError::InvalidOverlap { .. })));
        }
    }

    #[test]
    fn zero_overlap_switches() {
        let tr = Transition::new(1.0, 1.0, 0.0).expect("valid");
        let joined = transitional(constant(1.0), constant(2.0), tr);
        assert_eq!(joined(1.0).0[0], 1.0);
        assert_eq!(joined(1.0 + 1e-12).0[0], 2.0);
    }

    #[test]
    fn sequential_checks_the_seam() {
        let options = SequentialOptions::default();
        let joined = sequential(constant(0.5), 1.0, constant(0.5), &options).expect("at rest");
        assert_eq!(joined(1.5).0[3], 0.5);
        assert!(matches!(
            sequential(constant(0.5), 1.0, constant(0.6), &options),
            Err(ProfileError::Discontinuous { .. })
        ));
        let moving = |_: Real| (JointVector::repeat(0.5), JointVector::from_fn(|i, _| i as Real));
        assert!(matches!(
            sequential(constant(0.5), 1.0, moving, &options),
            Err(ProfileError::NotAtRest { joint: 6, .. })
        ));
        let broken = |_: Real| {
            (
                JointVector::from_fn(|i, _| if i == 2 { Real::NAN } else { 0.5 }),
                JointVector::zeros(),
            )
        };
        assert!(matches!(
            check_sequential(&constant(0.5)(1.0), &broken(0.0), &options),
            Err(ProfileError::Discontinuous { joint: 2, .. })
        ));
    }
}
