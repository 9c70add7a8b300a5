//! The plan's trajectory put together segment by segment in time linear in its length: a
//! join (+Tr or +Se) only changes the samples from the seam on, so only the last piece's
//! tail is rebuilt and the samples before it are kept as they are until [`Assembly::finish`]
//! concatenates everything once.

use crate::math::Real;
use crate::trajectory::{self, Trajectory, TrajectoryError};

/// Joined pieces: `done` in time order, then the `open` one a join may still change.
#[derive(Debug, Default)]
pub(super) struct Assembly {
    done: Vec<Trajectory>,
    open: Option<Trajectory>,
}

impl Assembly {
    /// Time of the last sample so far.
    pub(super) fn end(&self) -> Option<Real> {
        self.open.as_ref().map(Trajectory::end)
    }

    /// Starts with `first`, or appends `next` with [`trajectory::join_sequential`].
    pub(super) fn join_sequential(&mut self, next: &Trajectory) -> Result<(), TrajectoryError> {
        self.join_with(next, 0.0, |tail, next| Ok((trajectory::join_sequential(tail, next)?, ())))
            .map(|_| ())
    }

    /// Appends `next` with [`trajectory::join_transitional`] over `overlap` s.
    #[cfg(test)]
    pub(super) fn join_transitional(
        &mut self,
        next: &Trajectory,
        overlap: Real,
    ) -> Result<(), TrajectoryError> {
        self.join_with(next, overlap, |tail, next| {
            Ok((trajectory::join_transitional(tail, next, overlap)?, ()))
        })
        .map(|_| ())
    }

    /// Starts with `next`, or joins it by `join` to the samples of the open piece from just
    /// before the seam (its end minus `reach`, at least as far back as any join reads or
    /// changes); returns what `join` decided (`None` for the first piece).
    pub(super) fn join_with<R, E: From<TrajectoryError>>(
        &mut self,
        next: &Trajectory,
        reach: Real,
        join: impl FnOnce(&Trajectory, &Trajectory) -> Result<(Trajectory, R), E>,
    ) -> Result<Option<R>, E> {
        let Some(open) = self.open.take() else {
            self.open = Some(next.clone());
            return Ok(None);
        };
        // One sample before the last one at or before the seam: the seam computed as end -
        // overlap may round past a sample, which would leave the tail shorter than the overlap.
        let seam = open.end() - reach;
        let k = open.times().partition_point(|&t| t <= seam).saturating_sub(2);
        let (joined, decided) = join(&slice(&open, k, open.len())?, next)?;
        if k > 0 {
            self.done.push(slice(&open, 0, k)?);
        }
        self.open = Some(joined);
        Ok(Some(decided))
    }

    /// The whole trajectory; `None` when nothing was joined.
    pub(super) fn finish(self) -> Result<Option<Trajectory>, TrajectoryError> {
        let Some(open) = self.open else { return Ok(None) };
        if self.done.is_empty() {
            return Ok(Some(open));
        }
        let pieces = || self.done.iter().chain(std::iter::once(&open));
        Trajectory::new(
            pieces().flat_map(|p| p.times().iter().copied()).collect(),
            pieces().flat_map(|p| p.positions().iter().copied()).collect(),
            pieces().flat_map(|p| p.velocities().iter().copied()).collect(),
        )
        .map(Some)
    }
}

/// Samples `from..to` of `t`.
fn slice(t: &Trajectory, from: usize, to: usize) -> Result<Trajectory, TrajectoryError> {
    Trajectory::new(
        t.times()[from..to].to_vec(),
        t.positions()[from..to].to_vec(),
        t.velocities()[from..to].to_vec(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::JointVector;

    /// A rest-to-rest ramp of joint 0 from `a` to `b` over [0, 1] s.
    fn ramp(a: Real, b: Real, samples: usize) -> Trajectory {
        let times: Vec<Real> = (0..samples).map(|i| i as Real / (samples - 1) as Real).collect();
        Trajectory::from_fn(times, |t| {
            let s = 3.0 * t * t - 2.0 * t * t * t;
            let ds = 6.0 * t - 6.0 * t * t;
            (JointVector::repeat(a + (b - a) * s), JointVector::repeat((b - a) * ds))
        })
        .expect("valid")
    }

    #[test]
    fn joins_equal_the_joins_of_whole_trajectories() {
        let pieces = [ramp(0.0, 1.0, 41), ramp(1.0, 0.5, 33), ramp(0.5, 2.0, 57)];
        let mut assembly = Assembly::default();
        assembly.join_sequential(&pieces[0]).expect("first");
        assembly.join_transitional(&pieces[1], 0.2).expect("+Tr");
        assembly.join_sequential(&pieces[2]).expect("+Se");
        let assembled = assembly.finish().expect("finished").expect("some");
        let transitional = trajectory::join_transitional(&pieces[0], &pieces[1], 0.2).expect("+Tr");
        let whole = trajectory::join_sequential(&transitional, &pieces[2]).expect("+Se");
        assert_eq!(assembled.len(), whole.len());
        for k in 0..whole.len() {
            assert!((assembled.times()[k] - whole.times()[k]).abs() < 1e-12);
            assert!((assembled.positions()[k] - whole.positions()[k]).amax() < 1e-12);
            assert!((assembled.velocities()[k] - whole.velocities()[k]).amax() < 1e-9);
        }
    }
}
