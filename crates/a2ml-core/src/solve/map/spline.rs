//! Clamped cubic splines in time (METHODS.md §1.3 step 1.4): C² through their knots, with
//! given end velocities. They carry the wrist through via points and smooth the swivel
//! profile.

use crate::math::Real;

/// A value a spline can carry: reals and 3-vectors.
pub trait Knot:
    Copy
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Real, Output = Self>
{
    /// The zero value.
    fn zero() -> Self;
}

impl Knot for Real {
    fn zero() -> Self {
        0.0
    }
}

impl Knot for crate::math::Vector3 {
    fn zero() -> Self {
        Self::zeros()
    }
}

/// Why a spline cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SplineError {
    /// Fewer than two knots, or knots and values of different lengths.
    #[error(
        "a spline needs at least two knots with one value each (got {times} times, {values} values)"
    )]
    Knots {
        /// Knot times given.
        times: usize,
        /// Values given.
        values: usize,
    },
    /// Knot times not finite and strictly increasing.
    #[error("spline knot times must be finite and strictly increasing (knot {index})")]
    Times {
        /// The first offending knot.
        index: usize,
    },
}

/// A clamped cubic spline: `value(t)` passes through `(times[k], values[k])`, is C² inside,
/// and has the given velocities at both ends.
#[derive(Debug, Clone, PartialEq)]
pub struct ClampedSpline<V: Knot> {
    times: Vec<Real>,
    values: Vec<V>,
    /// Second derivatives at the knots.
    moments: Vec<V>,
}

impl<V: Knot> ClampedSpline<V> {
    /// The spline through `values` at `times` with end velocities `start_velocity` and
    /// `end_velocity`.
    ///
    /// # Errors
    /// [`SplineError`] for fewer than two knots or times not strictly increasing.
    pub fn new(
        times: Vec<Real>,
        values: Vec<V>,
        start_velocity: V,
        end_velocity: V,
    ) -> Result<Self, SplineError> {
        let n = times.len();
        if n < 2 || values.len() != n {
            return Err(SplineError::Knots { times: n, values: values.len() });
        }
        if let Some(index) =
            (0..n).find(|&k| !times[k].is_finite() || (k > 0 && times[k] <= times[k - 1]))
        {
            return Err(SplineError::Times { index });
        }
        let h: Vec<Real> = times.windows(2).map(|w| w[1] - w[0]).collect();
        let slope = |k: usize| (values[k + 1] - values[k]) * (1.0 / h[k]);
        // The tridiagonal system of METHODS.md §1.3 step 1.4, solved by the Thomas algorithm.
        let mut diagonal = vec![0.0; n];
        let mut upper = vec![0.0; n];
        let mut lower = vec![0.0; n];
        let mut rhs = vec![V::zero(); n];
        diagonal[0] = 2.0 * h[0];
        upper[0] = h[0];
        rhs[0] = (slope(0) - start_velocity) * 6.0;
        for k in 1..n - 1 {
            lower[k] = h[k - 1];
            diagonal[k] = 2.0 * (h[k - 1] + h[k]);
            upper[k] = h[k];
            rhs[k] = (slope(k) - slope(k - 1)) * 6.0;
        }
        lower[n - 1] = h[n - 2];
        diagonal[n - 1] = 2.0 * h[n - 2];
        rhs[n - 1] = (end_velocity - slope(n - 2)) * 6.0;
        for k in 1..n {
            let w = lower[k] / diagonal[k - 1];
            diagonal[k] -= w * upper[k - 1];
            let previous = rhs[k - 1];
            rhs[k] = rhs[k] - previous * w;
        }
        let mut moments = vec![V::zero(); n];
        moments[n - 1] = rhs[n - 1] * (1.0 / diagonal[n - 1]);
        for k in (0..n - 1).rev() {
            moments[k] = (rhs[k] - moments[k + 1] * upper[k]) * (1.0 / diagonal[k]);
        }
        Ok(Self { times, values, moments })
    }

    /// The spline through `values` at rest at both ends.
    ///
    /// # Errors
    /// As [`ClampedSpline::new`].
    pub fn at_rest(times: Vec<Real>, values: Vec<V>) -> Result<Self, SplineError> {
        Self::new(times, values, V::zero(), V::zero())
    }

    /// The knot times.
    pub fn times(&self) -> &[Real] {
        &self.times
    }

    /// The knot values.
    pub fn values(&self) -> &[V] {
        &self.values
    }

    /// Value, first and second derivative at `t` (clamped to the knot range).
    pub fn sample(&self, t: Real) -> (V, V, V) {
        let n = self.times.len();
        let t = t.clamp(self.times[0], self.times[n - 1]);
        let k = self.times.partition_point(|&x| x <= t).saturating_sub(1).min(n - 2);
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        let h = t1 - t0;
        let (a, b) = (t1 - t, t - t0);
        let (m0, m1) = (self.moments[k], self.moments[k + 1]);
        let (p0, p1) = (self.values[k], self.values[k + 1]);
        let c0 = p0 * (1.0 / h) - m0 * (h / 6.0);
        let c1 = p1 * (1.0 / h) - m1 * (h / 6.0);
        let value = m0 * (a * a * a / (6.0 * h)) + m1 * (b * b * b / (6.0 * h)) + c0 * a + c1 * b;
        let velocity = m1 * (b * b / (2.0 * h)) - m0 * (a * a / (2.0 * h)) + c1 - c0;
        let acceleration = m0 * (a / h) + m1 * (b / h);
        (value, velocity, acceleration)
    }
}

/// Chord-length knot times over [0, duration] for points visited in order (METHODS.md §1.3
/// step 1.3): each stretch takes time in proportion to its length.
pub fn chord_length_times(points: &[crate::math::Vector3], duration: Real) -> Vec<Real> {
    let mut along = vec![0.0];
    for w in points.windows(2) {
        let last = along.last().copied().unwrap_or(0.0);
        along.push(last + (w[1] - w[0]).norm());
    }
    let total = along.last().copied().unwrap_or(0.0);
    if total <= 0.0 {
        let n = points.len().max(2) - 1;
        return (0..points.len()).map(|k| duration * k as Real / n as Real).collect();
    }
    along.iter().map(|s| duration * s / total).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_at_rest_and_is_c2() {
        let s = ClampedSpline::at_rest(vec![0.0, 1.0, 2.5, 4.0], vec![0.0, 2.0, -1.0, 3.0])
            .expect("spline");
        for (t, v) in [(0.0, 0.0), (1.0, 2.0), (2.5, -1.0), (4.0, 3.0)] {
            assert!((s.sample(t).0 - v).abs() < 1e-12);
        }
        assert!(s.sample(0.0).1.abs() < 1e-12 && s.sample(4.0).1.abs() < 1e-12);
        for knot in [1.0, 2.5] {
            let (before, after) = (s.sample(knot - 1e-9), s.sample(knot + 1e-9));
            assert!((before.1 - after.1).abs() < 1e-6 && (before.2 - after.2).abs() < 1e-6);
        }
        // The derivative agrees with a central difference.
        let t = 1.7;
        let fd = (s.sample(t + 1e-6).0 - s.sample(t - 1e-6).0) / 2e-6;
        assert!((fd - s.sample(t).1).abs() < 1e-6);
    }

    #[test]
    fn rejects_bad_knots() {
        assert!(ClampedSpline::at_rest(vec![0.0], vec![1.0]).is_err());
        assert!(ClampedSpline::at_rest(vec![0.0, 0.0], vec![1.0, 2.0]).is_err());
    }
}
