//! Sampled joint trajectories (time, q, q' per sample), their joining with +Tr blends and +Se
//! (docs/design.md §4, §5) and the checks run on the whole result: joint limits and clearance.
//!
//! Entry points: [`Trajectory::new`], [`join_sequential`], [`join_transitional`] (over the
//! joins of [`join`], which take any function of time),
//! [`check_limits`], [`peaks`], [`min_clearance`], [`distance_pass`] (per sample, both),
//! [`sample_times`] (the output grid),
//! [`Trajectory::stretched`]. Between samples q follows the cubic Hermite curve through the
//! samples' q and q', so the two stay consistent and the limits are checked at every instant
//! of that curve, not only at the samples.

use std::cell::Cell;

use crate::collision::{self, CollisionScene, MEASURE_SLACK, clearance_bound};
use crate::math::{DOF, JointVector, Real};
use crate::profile::ProfileError;
use crate::robot::Robot;

mod distances;
pub mod join;
mod limits;
#[cfg(test)]
mod tests;

pub use distances::{CapsuleDistances, DistancePass, capsule_distances, distance_pass};
pub use join::{JointSample, SequentialOptions, Transition, TransitionOptions, check_sequential};
pub use limits::{Limits, Peaks, peaks};

/// Largest |q2(0) - q1(T1)| per joint accepted by [`join_sequential`] (rad).
pub const SEQUENTIAL_GAP: Real = 1e-6;

/// Why a trajectory cannot be built or joined.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrajectoryError {
    /// Times, positions and velocities differ in length.
    #[error("{times} times, {positions} positions and {velocities} velocities")]
    LengthMismatch {
        /// Number of times.
        times: usize,
        /// Number of positions.
        positions: usize,
        /// Number of velocities.
        velocities: usize,
    },
    /// There is no sample.
    #[error("a trajectory needs at least one sample")]
    Empty,
    /// A time is not strictly after the one before.
    #[error("time {time} s at sample {sample} does not follow {previous} s")]
    TimesNotIncreasing {
        /// Index of the offending sample.
        sample: usize,
        /// Its time (s).
        time: Real,
        /// The previous time (s).
        previous: Real,
    },
    /// A time, position or velocity is NaN or infinite.
    #[error("non-finite {what} at sample {sample}")]
    NonFinite {
        /// Which value: "time", "position" or "velocity".
        what: &'static str,
        /// Index of the sample.
        sample: usize,
    },
    /// The resampling rate is not positive and finite.
    #[error("invalid sampling rate {rate_hz} Hz")]
    InvalidRate {
        /// The rate asked for (Hz).
        rate_hz: Real,
    },
    /// The segments cannot be joined (gap, not at rest, invalid overlap).
    #[error(transparent)]
    Join(#[from] ProfileError),
}

/// Joint positions and velocities sampled at strictly increasing times. Deserialising checks
/// what [`Trajectory::new`] checks.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "Samples")]
pub struct Trajectory {
    times: Vec<Real>,
    positions: Vec<JointVector>,
    velocities: Vec<JointVector>,
}

/// A trajectory's fields as serialised, before [`Trajectory::new`] checks them.
#[derive(serde::Deserialize)]
struct Samples {
    times: Vec<Real>,
    positions: Vec<JointVector>,
    velocities: Vec<JointVector>,
}

impl TryFrom<Samples> for Trajectory {
    type Error = TrajectoryError;

    fn try_from(s: Samples) -> Result<Self, TrajectoryError> {
        Trajectory::new(s.times, s.positions, s.velocities)
    }
}

impl Trajectory {
    /// A trajectory from its samples: times (s), q (rad) and q' (rad/s).
    ///
    /// # Errors
    /// [`TrajectoryError`] for different lengths, no sample, times not strictly increasing
    /// or non-finite values.
    pub fn new(
        times: Vec<Real>,
        positions: Vec<JointVector>,
        velocities: Vec<JointVector>,
    ) -> Result<Self, TrajectoryError> {
        if times.len() != positions.len() || times.len() != velocities.len() {
            return Err(TrajectoryError::LengthMismatch {
                times: times.len(),
                positions: positions.len(),
                velocities: velocities.len(),
            });
        }
        if times.is_empty() {
            return Err(TrajectoryError::Empty);
        }
        for (sample, ((t, q), qd)) in times.iter().zip(&positions).zip(&velocities).enumerate() {
            for (what, finite) in [
                ("time", t.is_finite()),
                ("position", q.iter().all(|x| x.is_finite())),
                ("velocity", qd.iter().all(|x| x.is_finite())),
            ] {
                if !finite {
                    return Err(TrajectoryError::NonFinite { what, sample });
                }
            }
            if sample > 0 && *t <= times[sample - 1] {
                let previous = times[sample - 1];
                return Err(TrajectoryError::TimesNotIncreasing { sample, time: *t, previous });
            }
        }
        Ok(Self { times, positions, velocities })
    }

    /// Samples `f` (time from 0, returning q and q') at the given times.
    ///
    /// # Errors
    /// As [`Trajectory::new`].
    pub fn from_fn(
        times: Vec<Real>,
        f: impl Fn(Real) -> JointSample,
    ) -> Result<Self, TrajectoryError> {
        let (positions, velocities) = times.iter().map(|&t| f(t)).unzip();
        Self::new(times, positions, velocities)
    }

    /// Sample times (s).
    pub fn times(&self) -> &[Real] {
        &self.times
    }

    /// Joint positions per sample (rad).
    pub fn positions(&self) -> &[JointVector] {
        &self.positions
    }

    /// Joint velocities per sample (rad/s).
    pub fn velocities(&self) -> &[JointVector] {
        &self.velocities
    }

    /// Number of samples (at least one).
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// Always false: a trajectory has at least one sample.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// Time of the first sample (s).
    pub fn start(&self) -> Real {
        self.times[0]
    }

    /// Time of the last sample (s).
    pub fn end(&self) -> Real {
        self.times[self.times.len() - 1]
    }

    /// Last time minus first time (s).
    pub fn duration(&self) -> Real {
        self.end() - self.start()
    }

    /// q and q' at time `t` (clamped to the trajectory's span) by cubic Hermite
    /// interpolation of the neighbouring samples' q and q'.
    pub fn sample(&self, t: Real) -> JointSample {
        let t = t.clamp(self.start(), self.end());
        self.interpolate(self.interval(t), t)
    }

    /// [`Trajectory::sample`] for times that mostly rise, as joining and resampling ask:
    /// the interval is looked for where the last call found it and in the one after before
    /// it is bisected for. The same values as `sample`, bit for bit.
    fn sampler(&self) -> impl Fn(Real) -> JointSample + '_ {
        let last = Cell::new(0);
        move |t| {
            let t = t.clamp(self.start(), self.end());
            let holds = |k: usize| {
                k < self.len()
                    && self.times[k] <= t
                    && self.times.get(k + 1).is_none_or(|&next| t < next)
            };
            let k = [last.get(), last.get() + 1]
                .into_iter()
                .find(|&k| holds(k))
                .unwrap_or_else(|| self.interval(t));
            last.set(k);
            self.interpolate(k, t)
        }
    }

    /// The index k of the interval [t_k, t_k+1) holding `t` (the last sample's at or after
    /// it): the number of samples at or before `t`, less one.
    fn interval(&self, t: Real) -> usize {
        self.times.partition_point(|&s| s <= t).saturating_sub(1)
    }

    /// The cubic Hermite curve of interval `k` at `t` (within it); the last sample from its
    /// last index on.
    fn interpolate(&self, k: usize, t: Real) -> JointSample {
        if k + 1 >= self.len() {
            return (self.positions[k], self.velocities[k]);
        }
        let h = self.times[k + 1] - self.times[k];
        let s = (t - self.times[k]) / h;
        let (p0, p1) = (self.positions[k], self.positions[k + 1]);
        let (m0, m1) = (self.velocities[k] * h, self.velocities[k + 1] * h);
        let (s2, s3) = (s * s, s * s * s);
        let q = p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
            + m0 * (s3 - 2.0 * s2 + s)
            + p1 * (-2.0 * s3 + 3.0 * s2)
            + m1 * (s3 - s2);
        let dq = p0 * (6.0 * s2 - 6.0 * s)
            + m0 * (3.0 * s2 - 4.0 * s + 1.0)
            + p1 * (-6.0 * s2 + 6.0 * s)
            + m1 * (3.0 * s2 - 2.0 * s);
        (q, dq / h)
    }

    /// The trajectory sampled every 1/`rate_hz` s from its start, plus its end.
    ///
    /// # Errors
    /// [`TrajectoryError::InvalidRate`] unless the rate is positive and finite.
    pub fn resample(&self, rate_hz: Real) -> Result<Self, TrajectoryError> {
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(TrajectoryError::InvalidRate { rate_hz });
        }
        Self::from_fn(sample_times(self.start(), self.end(), rate_hz), self.sampler())
    }

    /// The same motion `factor` times slower: times from the start times `factor`, q' divided
    /// by it. The Hermite curve keeps its shape, so |q'| falls by `factor` and |q̈| by its
    /// square.
    pub fn stretched(&self, factor: Real) -> Self {
        let start = self.start();
        Self {
            times: self.times.iter().map(|t| start + (t - start) * factor).collect(),
            positions: self.positions.clone(),
            velocities: self.velocities.iter().map(|v| v / factor).collect(),
        }
    }

    /// `sample` in local time (0 at the first sample).
    fn local(&self) -> impl Fn(Real) -> JointSample + '_ {
        let sample = self.sampler();
        move |t| sample(self.start() + t)
    }
}

/// Times every 1/`rate_hz` s from `start`, then `end` exactly (a grid point within 1e-9 of
/// a step of it is dropped). `rate_hz` must be positive and finite.
pub fn sample_times(start: Real, end: Real, rate_hz: Real) -> Vec<Real> {
    let step = 1.0 / rate_hz;
    let count = ((end - start) / step).floor() as usize;
    let mut times: Vec<Real> = (0..=count).map(|i| start + i as Real * step).collect();
    times.retain(|&t| t < end - 1e-9 * step);
    times.push(end);
    times
}

/// Merges sorted time lists, dropping times within 1e-12 s of the one before.
fn merge_times(mut times: Vec<Real>) -> Vec<Real> {
    times.sort_by(Real::total_cmp);
    times.dedup_by(|b, a| *b - *a <= 1e-12);
    times
}

/// The sequential connection +Se: `second` starts where `first` ends, both at rest there.
/// The result starts at `first`'s start; `second`'s samples follow, shifted in time.
///
/// # Errors
/// [`TrajectoryError::Join`] with [`ProfileError::Discontinuous`] when q differs by more
/// than [`SEQUENTIAL_GAP`] at the seam, or [`ProfileError::NotAtRest`] when either side moves
/// faster than the default velocity tolerance.
pub fn join_sequential(
    first: &Trajectory,
    second: &Trajectory,
) -> Result<Trajectory, TrajectoryError> {
    let options =
        SequentialOptions { position_tolerance: SEQUENTIAL_GAP, ..SequentialOptions::default() };
    let t1 = first.duration();
    let joined = join::sequential(first.local(), t1, second.local(), &options)?;
    let times = first.times.iter().map(|t| t - first.start());
    let later = second.times.iter().skip(1).map(|t| t - second.start() + t1);
    let times: Vec<Real> = merge_times(times.chain(later).collect());
    Trajectory::from_fn(times.iter().map(|t| t + first.start()).collect(), |t| {
        joined(t - first.start())
    })
}

/// The transitional connection +Tr (appendix A, eq. A.1): `second` starts `overlap` s before
/// `first` ends and the two are blended over the overlap with β(t) = 0.5 cos(π (t - t2s) /
/// (t1e - t2s)) + 0.5, q = β q1 + (1 - β) q2, q' = β q1' + (1 - β) q2' + β' (q1 - q2). The
/// result lasts T1 + T2 - overlap and holds both inputs' sample times plus the seams.
///
/// # Errors
/// [`TrajectoryError::Join`] with [`ProfileError::InvalidOverlap`] unless
/// 0 ≤ overlap ≤ min(T1, T2).
pub fn join_transitional(
    first: &Trajectory,
    second: &Trajectory,
    overlap: Real,
) -> Result<Trajectory, TrajectoryError> {
    let transition = Transition::new(first.duration(), second.duration(), overlap)?;
    let joined = join::transitional(first.local(), second.local(), transition);
    let t2s = transition.second_start();
    let mut times: Vec<Real> = first.times.iter().map(|t| t - first.start()).collect();
    times.extend(second.times.iter().map(|t| t - second.start() + t2s));
    times.extend([t2s, transition.first_end()]);
    let times = merge_times(times);
    Trajectory::from_fn(times.iter().map(|t| t + first.start()).collect(), |t| {
        joined(t - first.start())
    })
}

/// Which limit a sample exceeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LimitKind {
    /// The joint's position range.
    Position,
    /// The joint's speed limit.
    Velocity,
    /// The joint's acceleration limit.
    Acceleration,
}

/// One joint outside one of its limits at or after one sample.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LimitViolation {
    /// Index of the sample, or of the first sample of the interval where the curve between
    /// samples goes outside.
    pub sample: usize,
    /// Index of the joint (0-6).
    pub joint: usize,
    /// The position (rad), speed (rad/s) or |acceleration| (rad/s²) found.
    pub value: Real,
    /// The limit exceeded: the lower or upper bound, ± the speed limit, or the acceleration
    /// limit.
    pub limit: Real,
    /// Position, velocity or acceleration.
    pub kind: LimitKind,
}

/// Every sample or interval and joint outside the robot's limits by more than `tolerance`
/// (rad, rad/s, rad/s²), as [`check_within`].
pub fn check_limits(
    trajectory: &Trajectory,
    robot: &Robot,
    tolerance: Real,
) -> Vec<LimitViolation> {
    check_within(trajectory, &Limits::of(robot), tolerance)
}

/// Every sample or interval and joint outside its position range, speed or acceleration limit
/// by more than `tolerance` (rad, rad/s, rad/s²) anywhere on the Hermite curve, in sample then
/// joint order: a sample's own q and q', then the extremes of the curve up to the next sample.
pub fn check_within(
    trajectory: &Trajectory,
    limits: &Limits,
    tolerance: Real,
) -> Vec<LimitViolation> {
    let (lower, upper, speed) = (limits.lower, limits.upper, limits.velocity);
    let mut out = Vec::new();
    let mut extremes = limits::intervals(trajectory).peekable();
    for (sample, (q, qd)) in trajectory.positions.iter().zip(&trajectory.velocities).enumerate() {
        let mut flag = |joint: usize, value: Real, limit: Real, kind| {
            out.push(LimitViolation { sample, joint, value, limit, kind });
        };
        for joint in 0..DOF {
            if q[joint] < lower[joint] - tolerance {
                flag(joint, q[joint], lower[joint], LimitKind::Position);
            } else if q[joint] > upper[joint] + tolerance {
                flag(joint, q[joint], upper[joint], LimitKind::Position);
            }
            if qd[joint].abs() > speed[joint] + tolerance {
                flag(joint, qd[joint], speed[joint].copysign(qd[joint]), LimitKind::Velocity);
            }
        }
        while let Some((_, joint, [low, high, top, accel])) =
            extremes.next_if(|(k, _, _)| *k == sample)
        {
            if low < lower[joint] - tolerance && q[joint] >= lower[joint] - tolerance {
                flag(joint, low, lower[joint], LimitKind::Position);
            } else if high > upper[joint] + tolerance && q[joint] <= upper[joint] + tolerance {
                flag(joint, high, upper[joint], LimitKind::Position);
            }
            if top > speed[joint] + tolerance && qd[joint].abs() <= speed[joint] + tolerance {
                flag(joint, top, speed[joint], LimitKind::Velocity);
            }
            let a = limits.acceleration[joint];
            if accel > a + tolerance {
                flag(joint, accel, a, LimitKind::Acceleration);
            }
        }
    }
    out
}

/// The smallest clearance along a trajectory, checked at its samples.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Clearance {
    /// Signed distance (m); negative is a penetration depth.
    pub distance: Real,
    /// Time of the worst sample (s).
    pub time: Real,
    /// The link capsule's name.
    pub link: String,
    /// The obstacle's name (or the other capsule's for self-collision).
    pub obstacle: String,
}

/// The smallest signed distance of any pair (as [`collision::min_distance`] considers them)
/// over the trajectory's samples, with when and between what it occurs (the first worst
/// sample); `None` when there is no pair to measure. The same as [`distance_pass`]'s
/// clearance, without the per-capsule series. Every pair is measured
/// ([`collision::CollisionModel::nearest_pair`]) only at the samples that may be the worst:
/// [`collision::clearance_bound`] leaves out those near a sample already measured, and
/// [`collision::clearance`] (the same closed forms, with a broadphase) those whose distance,
/// less [`collision::MEASURE_SLACK`], is above the smallest so far.
pub fn min_clearance(
    trajectory: &Trajectory,
    robot: &Robot,
    scene: &CollisionScene,
) -> Option<Clearance> {
    let (times, positions) = (&trajectory.times, &trajectory.positions);
    let model = collision::CollisionModel::new(robot, scene);
    let exact = |q: &JointVector| collision::clearance(&model, q);
    // A first look at every STRIDE-th sample (and the last) bounds the smallest distance
    // from above, so that the pass below can leave out the samples far from it. At or below
    // zero the bound is only compared with zero.
    const STRIDE: usize = 16;
    let last = positions.len().checked_sub(1)?;
    let mut above = Real::INFINITY;
    for k in (0..last).step_by(STRIDE).chain([last]) {
        above = above.min(exact(&positions[k]) + MEASURE_SLACK);
    }
    // The smallest distance, when, and the pair (named once, at the end).
    let mut best: Option<(Real, Real, collision::Pair)> = None;
    // The last sample measured (by either): a sample near it in joint space is about as far
    // away.
    let mut anchor: Option<(&JointVector, Real)> = None;
    for (&time, q) in times.iter().zip(positions) {
        if let Some((measured, distance)) = anchor {
            let bound = clearance_bound(&model, distance, measured, q);
            if bound > above.max(0.0) {
                continue;
            }
        }
        let closed = exact(q);
        anchor = Some((q, closed));
        if closed - MEASURE_SLACK > above.max(0.0) {
            continue;
        }
        let Some((distance, pair)) = model.nearest_pair(q) else { continue };
        anchor = Some((q, distance));
        above = above.min(distance);
        if best.is_none_or(|(d, ..)| distance < d) {
            best = Some((distance, time, pair));
        }
    }
    best.map(|(distance, time, pair)| {
        let (link, obstacle) = distances::pair_names(robot, scene, pair);
        Clearance { distance, time, link, obstacle }
    })
}
