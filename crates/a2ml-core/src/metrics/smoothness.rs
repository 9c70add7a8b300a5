//! Smoothness of a sampled motion: the normalised jerk (Flash & Hogan; Teulings et al.), the
//! number of peaks of a speed profile (one for a human point-to-point movement, paper Rule 5)
//! and the peak joint velocity and acceleration against their limits.
//!
//! Samples are (time, value) pairs at strictly increasing times; a vector value is any
//! nalgebra column vector (a wrist position, the seven joints).

use nalgebra::SVector;

use crate::math::Real;

/// A speed peak counts only when the speed falls by this fraction of the profile's largest
/// speed on each side of it, so that sampling ripple on one bell is not a second peak.
pub const PEAK_PROMINENCE: Real = 0.05;

/// The normalised jerk √(½ ∫|d³x/dt³|² dt · T⁵ / L²) of a motion given by its velocity samples
/// (dimensionless, 0 for a motion that does not move): T is the duration and L = ∫|ẋ| dt the
/// length travelled. A minimum-jerk point-to-point movement scores √360 ≈ 19; velocity steps
/// score far higher. The jerk is the second divided difference of the velocity samples.
pub fn normalised_jerk<const N: usize>(times: &[Real], velocities: &[SVector<Real, N>]) -> Real {
    let n = times.len().min(velocities.len());
    if n < 2 {
        return 0.0;
    }
    let duration = times[n - 1] - times[0];
    let length: Real = (1..n)
        .map(|k| {
            0.5 * (velocities[k].norm() + velocities[k - 1].norm()) * (times[k] - times[k - 1])
        })
        .sum();
    if !(length > 0.0 && duration > 0.0) {
        return 0.0;
    }
    // Accelerations at the interval middles, then jerks between consecutive middles.
    let middles: Vec<(Real, SVector<Real, N>)> = (1..n)
        .map(|k| {
            let h = times[k] - times[k - 1];
            (0.5 * (times[k] + times[k - 1]), (velocities[k] - velocities[k - 1]) / h)
        })
        .collect();
    let squared_jerk: Real = middles
        .windows(2)
        .map(|w| {
            let h = w[1].0 - w[0].0;
            ((w[1].1 - w[0].1) / h).norm_squared() * h
        })
        .sum();
    (0.5 * squared_jerk * duration.powi(5) / (length * length)).sqrt()
}

/// The number of peaks of a speed profile: local maxima from which the speed falls by at
/// least [`PEAK_PROMINENCE`] of the largest speed on both sides, or that the profile ends on.
/// 0 for a profile that never moves.
pub fn speed_peaks(speeds: &[Real]) -> usize {
    let top = speeds.iter().copied().fold(0.0, Real::max);
    // `max` passes over NaN speeds, so the top is 0 for a profile that never moves or is all
    // NaN; NaN is tested all the same, so that no other fold can let one through.
    if top.is_nan() || top <= 0.0 {
        return 0;
    }
    let threshold = PEAK_PROMINENCE * top;
    let mut peaks = 0;
    // The lowest speed since the last counted peak, and the highest since that low.
    let mut low = speeds[0];
    let mut high = speeds[0];
    let mut rising = true;
    for &s in speeds {
        if rising {
            high = high.max(s);
            if high - low >= threshold && high - s >= threshold {
                peaks += 1;
                rising = false;
                low = s;
            }
        } else if s < low {
            low = s;
        } else if s - low >= threshold {
            rising = true;
            high = s;
        }
    }
    // A rise that never came down by the threshold is a last peak at the end.
    peaks + usize::from(rising && high - low >= threshold)
}

/// The normalised jerk of a motion given by its position samples (a wrist path, the joints):
/// [`normalised_jerk`] of their velocities by differences at the interval middles.
pub fn path_normalised_jerk<const N: usize>(times: &[Real], samples: &[SVector<Real, N>]) -> Real {
    let n = times.len().min(samples.len());
    if n < 2 {
        return 0.0;
    }
    let middles: Vec<Real> = times[..n].windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
    let velocities: Vec<SVector<Real, N>> =
        (1..n).map(|k| (samples[k] - samples[k - 1]) / (times[k] - times[k - 1])).collect();
    normalised_jerk(&middles, &velocities)
}

/// The largest |value_i| / limit_i over the samples and components (0 for no sample).
pub fn peak_ratio<const N: usize>(values: &[SVector<Real, N>], limits: &SVector<Real, N>) -> Real {
    values.iter().flat_map(|v| (0..N).map(move |i| v[i].abs() / limits[i])).fold(0.0, Real::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{PI, Vector3};

    /// A minimum-jerk movement over distance 1 in time 1, sampled at `rate`.
    fn minimum_jerk(rate: usize) -> (Vec<Real>, Vec<Vector3>) {
        let times: Vec<Real> = (0..=rate).map(|k| k as Real / rate as Real).collect();
        let speed = |t: Real| 30.0 * t * t * (1.0 - t) * (1.0 - t);
        let v = times.iter().map(|&t| Vector3::new(speed(t), 0.0, 0.0)).collect();
        (times, v)
    }

    #[test]
    fn minimum_jerk_scores_root_360() {
        let (times, v) = minimum_jerk(2000);
        let nj = normalised_jerk(&times, &v);
        assert!((nj - 360.0_f64.sqrt()).abs() < 0.05, "{nj}");
    }

    #[test]
    fn normalised_jerk_is_scale_free() {
        let (times, v) = minimum_jerk(1000);
        let slow: Vec<Real> = times.iter().map(|t| 3.0 * t).collect();
        let far: Vec<Vector3> = v.iter().map(|v| v * (7.0 / 3.0)).collect();
        let (a, b) = (normalised_jerk(&times, &v), normalised_jerk(&slow, &far));
        assert!((a - b).abs() < 1e-6 * a, "{a} {b}");
        assert_eq!(normalised_jerk(&times, &vec![Vector3::zeros(); times.len()]), 0.0);
    }

    #[test]
    fn a_velocity_step_scores_far_worse() {
        let (times, mut v) = minimum_jerk(1000);
        for (t, v) in times.iter().zip(&mut v) {
            if (0.4..0.5).contains(t) {
                v.x *= 0.5;
            }
        }
        assert!(normalised_jerk(&times, &v) > 10.0 * 360.0_f64.sqrt());
    }

    #[test]
    fn peaks_of_bells() {
        let bell = |t: Real| 0.5 * (1.0 - (2.0 * PI * t).cos());
        let one: Vec<Real> = (0..=100).map(|k| bell(k as Real / 100.0)).collect();
        assert_eq!(speed_peaks(&one), 1);
        let two: Vec<Real> = (0..=200).map(|k| bell(k as Real / 100.0)).collect();
        assert_eq!(speed_peaks(&two), 2);
        // Ripple below the prominence is not a peak.
        let rippled: Vec<Real> =
            one.iter().enumerate().map(|(k, s)| s + 0.01 * (k as Real).sin()).collect();
        assert_eq!(speed_peaks(&rippled), 1);
        assert_eq!(speed_peaks(&[0.0; 5]), 0);
        assert_eq!(speed_peaks(&[Real::NAN; 3]), 0);
        // A plateau is one peak; a profile ending at speed still has its peak.
        assert_eq!(speed_peaks(&[0.0, 1.0, 1.0, 1.0, 0.0]), 1);
        assert_eq!(speed_peaks(&[0.0, 0.5, 1.0]), 1);
    }

    #[test]
    fn peak_ratio_takes_the_worst_component() {
        let limits = Vector3::new(1.0, 2.0, 4.0);
        let values = [Vector3::new(0.5, -3.0, 1.0), Vector3::new(0.0, 0.0, -4.4)];
        assert!((peak_ratio(&values, &limits) - 1.5).abs() < 1e-15);
        assert_eq!(peak_ratio::<3>(&[], &limits), 0.0);
    }
}
