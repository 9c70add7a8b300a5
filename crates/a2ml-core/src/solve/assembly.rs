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
        match self.open {
            Some(open) if self.done.is_empty() => Ok(Some(open)),
            _ => self.assembled(),
        }
    }

    /// The whole trajectory so far, the assembly left as it is; `None` when nothing was
    /// joined.
    fn assembled(&self) -> Result<Option<Trajectory>, TrajectoryError> {
        let Some(open) = &self.open else { return Ok(None) };
        let pieces = || self.done.iter().chain(std::iter::once(open));
        Trajectory::new(
            pieces().flat_map(|p| p.times().iter().copied()).collect(),
            pieces().flat_map(|p| p.positions().iter().copied()).collect(),
            pieces().flat_map(|p| p.velocities().iter().copied()).collect(),
        )
        .map(Some)
    }
}

/// An [`Assembly`] joined group by group (the plan's actions) that keeps where it stood after
/// each group, with the group's notes, so that joining again after a later group changed
/// starts from the end of the group before it: what was joined before a group does not
/// depend on it. The plan's limit rounds slow a few segments at a time and rejoin from the
/// first action they changed.
#[derive(Debug)]
pub(super) struct Checkpointed<N> {
    assembly: Assembly,
    after: Vec<Checkpoint<N>>,
}

/// Where a [`Checkpointed`] assembly stood after one group: how many pieces were done (later
/// ones are never changed, only more are pushed), the open piece, and the group's notes.
#[derive(Debug)]
struct Checkpoint<N> {
    done: usize,
    open: Option<Trajectory>,
    notes: Vec<N>,
}

impl<N> Default for Checkpointed<N> {
    fn default() -> Self {
        Self { assembly: Assembly::default(), after: Vec::new() }
    }
}

impl<N: Clone> Checkpointed<N> {
    /// Forgets group `group` and every later one: the assembly as it stood after the group
    /// before (empty for the first), to join group `group` on. `group` is at most the number
    /// of groups closed.
    pub(super) fn rewind(&mut self, group: usize) -> &mut Assembly {
        self.after.truncate(group);
        match self.after.last() {
            Some(checkpoint) => {
                self.assembly.done.truncate(checkpoint.done);
                self.assembly.open.clone_from(&checkpoint.open);
            }
            None => self.assembly = Assembly::default(),
        }
        &mut self.assembly
    }

    /// Closes a group joined since the last checkpoint, with its notes.
    pub(super) fn close_group(&mut self, notes: Vec<N>) {
        let (done, open) = (self.assembly.done.len(), self.assembly.open.clone());
        self.after.push(Checkpoint { done, open, notes });
    }

    /// The whole trajectory so far and every closed group's notes in order; `None` when
    /// nothing was joined.
    pub(super) fn assembled(&self) -> Result<(Option<Trajectory>, Vec<N>), TrajectoryError> {
        let notes = self.after.iter().flat_map(|c| c.notes.iter().cloned()).collect();
        Ok((self.assembly.assembled()?, notes))
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
    fn rewinding_to_a_group_and_joining_again_gives_the_same_bits() {
        let pieces =
            [ramp(0.0, 1.0, 41), ramp(1.0, 0.5, 33), ramp(0.5, 2.0, 57), ramp(2.0, 0.0, 9)];
        let mut checkpointed = Checkpointed::default();
        for (k, piece) in pieces.iter().enumerate() {
            checkpointed.rewind(k).join_sequential(piece).expect("+Se");
            checkpointed.close_group(vec![k]);
        }
        let (first, notes) = checkpointed.assembled().expect("assembled");
        assert_eq!(notes, [0, 1, 2, 3]);
        // Group 2 joined differently, then as before: the first two groups are kept.
        let other = ramp(0.5, 1.5, 20);
        checkpointed.rewind(2).join_sequential(&other).expect("+Se");
        checkpointed.close_group(vec![7]);
        let (changed, notes) = checkpointed.assembled().expect("assembled");
        assert_eq!(notes, [0, 1, 7]);
        assert_ne!(changed, first);
        for (k, piece) in pieces.iter().enumerate().skip(2) {
            checkpointed.rewind(k).join_sequential(piece).expect("+Se");
            checkpointed.close_group(vec![k]);
        }
        let (again, notes) = checkpointed.assembled().expect("assembled");
        assert_eq!(notes, [0, 1, 2, 3]);
        assert_eq!(again, first);
        let mut whole = Assembly::default();
        pieces.iter().for_each(|p| whole.join_sequential(p).expect("+Se"));
        assert_eq!(whole.finish().expect("finished"), first);
        assert_eq!(checkpointed.rewind(0).end(), None);
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
