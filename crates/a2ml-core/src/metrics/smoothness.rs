//! Smoothness of a sampled motion: the normalised jerk of a path (of the wrist, or of the
//! joints) and the number of peaks of a speed profile.

use nalgebra::SVector;

use crate::math::Real;

/// Normalised jerk sqrt(½ ∫|x'''|² dt · T⁵ / L²) of `samples` at `times` (dimensionless; 0 for
/// fewer than four samples or a path that does not move), x''' by successive differences and
/// L the path length. A minimum-jerk point-to-point motion scores √360 ≈ 18.97 (Hogan).
pub fn normalized_jerk<const N: usize>(times: &[Real], samples: &[SVector<Real, N>]) -> Real {
    let n = times.len().min(samples.len());
    if n < 4 {
        return 0.0;
    }
    let difference = |t: &[Real], x: &[SVector<Real, N>]| -> (Vec<Real>, Vec<SVector<Real, N>>) {
        let mids = t.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        let rates = x.windows(2).zip(t.windows(2)).map(|(x, t)| (x[1] - x[0]) / (t[1] - t[0]));
        (mids, rates.collect())
    };
    let (t1, velocity) = difference(&times[..n], &samples[..n]);
    let (t2, acceleration) = difference(&t1, &velocity);
    let (t3, jerk) = difference(&t2, &acceleration);
    let length: Real = samples[..n].windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    if length <= 0.0 {
        return 0.0;
    }
    // ∫|x'''|² dt over the jerk samples, each standing for the time between its neighbours.
    let integral: Real = jerk
        .iter()
        .enumerate()
        .map(|(k, j)| {
            let before = if k == 0 { t2[0] } else { t3[k - 1] };
            let after = if k + 1 == t3.len() { t2[t2.len() - 1] } else { t3[k + 1] };
            j.norm_squared() * 0.5 * (after - before)
        })
        .sum();
    let duration = times[n - 1] - times[0];
    (0.5 * integral * duration.powi(5) / (length * length)).sqrt()
}

/// Peaks of a speed profile: rises above `relative` × its maximum that then fall by
/// `prominence` (a share of the peak) before the next rise, a peak still rising at the end
/// included. A bell has one; a stop-and-go motion one per go.
pub fn speed_peaks(speeds: &[Real], relative: Real, prominence: Real) -> usize {
    let max = speeds.iter().copied().filter(|s| s.is_finite()).fold(0.0, Real::max);
    if max <= 0.0 {
        return 0;
    }
    let threshold = relative * max;
    let (mut count, mut peak, mut trough): (usize, Option<Real>, Real) = (0, None, 0.0);
    for &s in speeds.iter().filter(|s| s.is_finite()) {
        match peak {
            Some(p) if s > p => peak = Some(s),
            Some(p) if s < (1.0 - prominence) * p => {
                count += 1;
                peak = None;
                trough = s;
            }
            Some(_) => {}
            None => {
                trough = trough.min(s);
                if s > threshold && s * (1.0 - prominence) > trough {
                    peak = Some(s);
                }
            }
        }
    }
    count + usize::from(peak.is_some())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vector3;

    fn minimum_jerk(tau: Real) -> Real {
        tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau)
    }

    #[test]
    fn a_minimum_jerk_reach_has_hogans_normalised_jerk() {
        let times: Vec<Real> = (0..=1000).map(|k| Real::from(k) / 1000.0).collect();
        let path: Vec<Vector3> =
            times.iter().map(|&t| Vector3::new(0.3, -0.1, 0.2) * minimum_jerk(t)).collect();
        let nj = normalized_jerk(&times, &path);
        // Third differences of 1001 samples: within 1 % of the continuous value.
        assert!((nj - 360.0_f64.sqrt()).abs() < 0.01 * 360.0_f64.sqrt(), "{nj}");
    }

    #[test]
    fn one_bell_has_one_peak_and_two_bells_two() {
        let bell = |t: Real| (1.0 - (2.0 * std::f64::consts::PI * t).cos()).max(0.0);
        let one: Vec<Real> = (0..=100).map(|k| bell(Real::from(k) / 100.0)).collect();
        assert_eq!(speed_peaks(&one, 0.05, 0.2), 1);
        let two: Vec<Real> = (0..=200).map(|k| bell(Real::from(k) / 100.0)).collect();
        assert_eq!(speed_peaks(&two, 0.05, 0.2), 2);
        assert_eq!(speed_peaks(&[0.0; 5], 0.05, 0.2), 0);
    }
}
