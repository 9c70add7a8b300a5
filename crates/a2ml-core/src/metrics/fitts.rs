//! Durations against Fitts' law (HAMP paper eq. 8): T = a + b log2(2A/W), A the hand's travel.
//! The law itself is [`FittsLaw`], shared with the decomposition's default durations.

use crate::decompose::FittsLaw;
use crate::math::Real;

/// A motion's duration beside the one Fitts' law gives for its travel.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FittsCheck {
    /// A: the straight-line distance the wrist travelled, |P_f - P_0| (m).
    pub amplitude: Real,
    /// T of Fitts' law for that distance (s).
    pub fitts: Real,
    /// The motion's duration (s).
    pub duration: Real,
    /// `duration / fitts`: 1 for a motion timed as a person would be.
    pub ratio: Real,
}

/// The duration `duration` of a motion whose wrist travels `amplitude` metres, against `law`.
pub fn fitts_check(law: &FittsLaw, amplitude: Real, duration: Real) -> FittsCheck {
    let fitts = law.duration(amplitude);
    FittsCheck { amplitude, fitts, duration, ratio: duration / fitts }
}

/// The swivel windows of the HAMP planner (paper eqs. 9-10): the time of P's speed peak T1
/// (T/2 for the symmetric minimum-jerk profile, eq. 13) and the phase durations T1, T2 = T - T1.
pub fn phase_durations(total: Real) -> (Real, Real) {
    let t1 = 0.5 * total;
    (t1, total - t1)
}
