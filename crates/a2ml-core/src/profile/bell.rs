//! The bell-shaped speed profile of a movement primitive (paper eq. 9).

use super::ProfileError;
use crate::math::{PI, Real};

/// A bell-shaped (raised-cosine) speed profile covering `distance` in `duration` (paper eq. 9).
///
/// speed(t) = (v_max/2)(1 - cos(2πt/T)) with D = v_max T/2, so the motion starts and ends at
/// rest with zero acceleration. The distance is in the unit of the variable it drives (m for
/// Pw, rad for rotations and angles) and is never negative: references carry the direction.
/// Every query clamps t to [0, T]. The instantaneous profile (T = 0, D = 0) is allowed: it
/// has arrived at once (`fraction` = 1) and never moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BellProfile {
    duration: Real,
    distance: Real,
}

impl BellProfile {
    /// A profile travelling `distance` (≥ 0) in `duration` (s).
    ///
    /// # Errors
    /// [`ProfileError::InvalidDuration`] for a negative or non-finite duration, or a zero one
    /// with a positive distance; [`ProfileError::InvalidDistance`] for a negative or
    /// non-finite distance.
    pub fn new(duration: Real, distance: Real) -> Result<Self, ProfileError> {
        if !(distance.is_finite() && distance >= 0.0) {
            return Err(ProfileError::InvalidDistance { distance });
        }
        if !(duration.is_finite() && duration >= 0.0) || (duration == 0.0 && distance > 0.0) {
            return Err(ProfileError::InvalidDuration { duration, distance });
        }
        Ok(Self { duration, distance })
    }

    /// The shortest profile over `distance` whose peak speed does not exceed `max_speed`:
    /// T = 2D / v_max (eq. 9). Zero distance gives the instantaneous profile.
    ///
    /// # Errors
    /// [`ProfileError::InvalidSpeedLimit`] unless `max_speed` is positive and finite;
    /// [`ProfileError::InvalidDistance`] as in [`BellProfile::new`].
    pub fn for_speed_limit(distance: Real, max_speed: Real) -> Result<Self, ProfileError> {
        if !(max_speed.is_finite() && max_speed > 0.0) {
            return Err(ProfileError::InvalidSpeedLimit { limit: max_speed });
        }
        if !(distance.is_finite() && distance >= 0.0) {
            return Err(ProfileError::InvalidDistance { distance });
        }
        Self::new(2.0 * distance / max_speed, distance)
    }

    /// The duration T (s).
    #[inline]
    pub fn duration(&self) -> Real {
        self.duration
    }

    /// The distance D travelled by t = T.
    #[inline]
    pub fn distance(&self) -> Real {
        self.distance
    }

    /// The peak speed v_max = 2D/T, reached at T/2 (eq. 9); 0 for the instantaneous profile.
    #[inline]
    pub fn peak_speed(&self) -> Real {
        if self.duration > 0.0 { 2.0 * self.distance / self.duration } else { 0.0 }
    }

    /// The largest |acceleration|, π v_max / T, reached at T/4 and 3T/4.
    #[inline]
    pub fn peak_acceleration(&self) -> Real {
        if self.duration > 0.0 { PI * self.peak_speed() / self.duration } else { 0.0 }
    }

    /// Normalised time τ = t/T clamped to [0, 1]; `None` for the instantaneous profile.
    #[inline]
    fn phase(&self, t: Real) -> Option<Real> {
        (self.duration > 0.0).then(|| (t / self.duration).clamp(0.0, 1.0))
    }

    /// The fraction of the distance covered by t, in [0, 1]: τ - sin(2πτ)/(2π), τ = t/T
    /// (eq. 9 integrated). Independent of D, so it also shapes zero-distance profiles.
    #[inline]
    pub fn fraction(&self, t: Real) -> Real {
        match self.phase(t) {
            // Evaluate from the nearer end so that both ends are exact and the curve is
            // symmetric to the last bit.
            Some(tau) if tau <= 0.5 => tau - (2.0 * PI * tau).sin() / (2.0 * PI),
            Some(tau) => {
                let rest = 1.0 - tau;
                1.0 - (rest - (2.0 * PI * rest).sin() / (2.0 * PI))
            }
            None => 1.0,
        }
    }

    /// The time derivative of [`fraction`](Self::fraction) (1/s): (1 - cos(2πτ))/T.
    #[inline]
    pub fn fraction_rate(&self, t: Real) -> Real {
        match self.phase(t) {
            Some(tau) => (1.0 - (2.0 * PI * tau).cos()) / self.duration,
            None => 0.0,
        }
    }

    /// The distance travelled by t: s(t) = D (τ - sin(2πτ)/(2π)) (eq. 9 integrated).
    #[inline]
    pub fn progress(&self, t: Real) -> Real {
        self.distance * self.fraction(t)
    }

    /// The speed at t: (v_max/2)(1 - cos(2πt/T)) (eq. 9).
    #[inline]
    pub fn speed(&self, t: Real) -> Real {
        self.distance * self.fraction_rate(t)
    }

    /// The acceleration at t: (v_max/2)(2π/T) sin(2πt/T).
    #[inline]
    pub fn acceleration(&self, t: Real) -> Real {
        match self.phase(t) {
            Some(tau) => {
                self.distance * 2.0 * PI * (2.0 * PI * tau).sin() / (self.duration * self.duration)
            }
            None => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_at_rest_and_covers_the_distance() {
        let bell = BellProfile::new(1.7, 0.42).expect("valid");
        assert_eq!(bell.speed(0.0), 0.0);
        assert!(bell.speed(1.7).abs() < 1e-15);
        assert_eq!(bell.acceleration(0.0), 0.0);
        assert!(bell.acceleration(1.7).abs() < 1e-14);
        assert_eq!(bell.progress(0.0), 0.0);
        assert_eq!(bell.progress(1.7), 0.42);
        assert!((bell.speed(0.85) - bell.peak_speed()).abs() < 1e-15);
        assert!((bell.peak_speed() - 2.0 * 0.42 / 1.7).abs() < 1e-15);
    }

    #[test]
    fn clamps_time() {
        let bell = BellProfile::new(2.0, 3.0).expect("valid");
        assert_eq!(bell.progress(-1.0), 0.0);
        assert_eq!(bell.progress(5.0), 3.0);
        assert_eq!(bell.speed(-1.0), 0.0);
        assert!(bell.speed(5.0).abs() < 1e-15);
        assert_eq!(bell.fraction(f64::INFINITY), 1.0);
    }

    #[test]
    fn symmetric_about_the_middle() {
        let bell = BellProfile::new(1.3, 1.0).expect("valid");
        for k in 0..=20 {
            let t = 1.3 * k as Real / 20.0;
            assert!((bell.fraction(t) + bell.fraction(1.3 - t) - 1.0).abs() < 1e-15);
            assert!((bell.speed(t) - bell.speed(1.3 - t)).abs() < 1e-14);
        }
    }

    #[test]
    fn acceleration_peak() {
        let bell = BellProfile::new(0.8, 0.3).expect("valid");
        assert!((bell.acceleration(0.2) - bell.peak_acceleration()).abs() < 1e-12);
        assert!((bell.acceleration(0.6) + bell.peak_acceleration()).abs() < 1e-12);
    }

    #[test]
    fn degenerate_inputs_are_errors_or_still() {
        assert!(matches!(BellProfile::new(-1.0, 1.0), Err(ProfileError::InvalidDuration { .. })));
        assert!(matches!(BellProfile::new(0.0, 1.0), Err(ProfileError::InvalidDuration { .. })));
        assert!(matches!(BellProfile::new(1.0, -1.0), Err(ProfileError::InvalidDistance { .. })));
        assert!(matches!(
            BellProfile::new(Real::NAN, 1.0),
            Err(ProfileError::InvalidDuration { .. })
        ));
        assert!(matches!(
            BellProfile::new(1.0, Real::INFINITY),
            Err(ProfileError::InvalidDistance { .. })
        ));

        let still = BellProfile::new(0.0, 0.0).expect("instantaneous");
        for t in [-1.0, 0.0, 1.0] {
            assert_eq!(still.fraction(t), 1.0);
            assert_eq!(still.speed(t), 0.0);
            assert_eq!(still.acceleration(t), 0.0);
            assert_eq!(still.progress(t), 0.0);
        }
        assert_eq!(still.peak_speed(), 0.0);

        let zero = BellProfile::new(1.0, 0.0).expect("zero distance");
        assert_eq!(zero.progress(0.5), 0.0);
        assert_eq!(zero.speed(0.5), 0.0);
        assert_eq!(zero.fraction(0.5), 0.5);
    }

    #[test]
    fn speed_limit_gives_the_shortest_duration() {
        let bell = BellProfile::for_speed_limit(0.6, 0.5).expect("valid");
        assert!((bell.duration() - 2.4).abs() < 1e-15);
        assert!((bell.peak_speed() - 0.5).abs() < 1e-15);
        let still = BellProfile::for_speed_limit(0.0, 0.5).expect("valid");
        assert_eq!(still.duration(), 0.0);
        assert!(matches!(
            BellProfile::for_speed_limit(1.0, 0.0),
            Err(ProfileError::InvalidSpeedLimit { .. })
        ));
    }
}
