//! Checks between the decomposition and the solvers: the motion's size against the task's
//! [`Limits`] (samples at the faster of the output and control rates, segments), a rate
//! that gives the motion more than one sample, and every action's start (the first is the
//! task's start) clear of its obstacles and of the arm itself by the safety distance. After
//! solving, [`too_close`] names each segment that came closer than the safety distance.

use crate::collision::{CollisionScene, min_distance};
use crate::decompose::Decomposition;
use crate::kinematics::arm_pose;
use crate::language::{Limits, Task, samples};
use crate::math::Real;
use crate::robot::Robot;

use super::report::{SegmentReport, Warning, WarningKind};

/// Why a decomposed task is not planned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CheckError {
    /// The motion asks for more samples than the limit.
    #[error(
        "the motion lasts {duration:.3} s, which is {samples} samples at {rate} Hz, more than \
         the limit of {limit} (raise it with --max-samples)"
    )]
    TooManySamples {
        /// The motion's duration before joining (s).
        duration: Real,
        /// The faster of the output and control rates (Hz).
        rate: Real,
        /// Samples asked for.
        samples: u64,
        /// The limit.
        limit: u64,
    },
    /// The task decomposes into more segments than the limit.
    #[error(
        "the task decomposes into {segments} segments, more than the limit of {limit} (raise \
         it with --max-segments)"
    )]
    TooManySegments {
        /// Segments of the decomposition.
        segments: usize,
        /// The limit.
        limit: usize,
    },
    /// The output rate gives the motion a single sample.
    #[error(
        "the output rate {rate} Hz is below 1 / the motion's duration ({duration:.3} s): the \
         plan would have a single sample"
    )]
    RateBelowDuration {
        /// The output rate (Hz).
        rate: Real,
        /// The motion's duration (s).
        duration: Real,
    },
    /// An action starts in collision or closer than the safety distance.
    #[error(
        "{} starts {} `{link}` and `{obstacle}` {:.1} mm apart, closer than the safety distance \
         of {:.1} mm{}",
        if *action_index == 0 { format!("the task (action `{action}`)") } else { format!("action `{action}`") },
        if *distance < 0.0 { "in collision:" } else { "with" },
        distance * 1e3,
        safety * 1e3,
        if *distance < 0.0 { " (they overlap)" } else { "" }
    )]
    StartTooClose {
        /// The action's name.
        action: String,
        /// Its index in the file's order.
        action_index: usize,
        /// Its place in the execution order (0: the task's start).
        order: usize,
        /// The arm capsule.
        link: String,
        /// The obstacle, or the other arm capsule.
        obstacle: String,
        /// Signed distance (m).
        distance: Real,
        /// The safety distance (m).
        safety: Real,
    },
}

/// What a decomposed task is checked against before solving: the plan's settings.
#[derive(Debug, Clone, Copy)]
pub struct Bounds<'a> {
    /// The output rate (Hz).
    pub rate: Real,
    /// The control rate (Hz).
    pub control_rate: Real,
    /// The safety distance every action's start keeps (m).
    pub safety: Real,
    /// How much one task may ask for.
    pub limits: &'a Limits,
    /// Whether a start closer than `safety` is a warning rather than an error.
    pub allow_close_start: bool,
}

/// Checks the decomposition of `task` (in {b}) before any segment is solved. A start too
/// close is an error unless `bounds.allow_close_start`, when it is returned as a warning
/// instead.
///
/// # Errors
/// The first [`CheckError`].
pub fn before_solving(
    robot: &Robot,
    task: &Task,
    decomposition: &Decomposition,
    bounds: &Bounds<'_>,
) -> Result<Vec<Warning>, CheckError> {
    let Bounds { rate, control_rate, safety, limits, allow_close_start } = *bounds;
    let segments: usize = decomposition.actions.iter().map(|a| a.segments.len()).sum();
    if segments > limits.max_segments {
        return Err(CheckError::TooManySegments { segments, limit: limits.max_segments });
    }
    let duration: Real =
        decomposition.actions.iter().flat_map(|a| &a.segments).map(|s| s.duration).sum();
    let fastest = rate.max(control_rate);
    let n = samples(duration, fastest);
    if n > limits.max_samples || !duration.is_finite() {
        return Err(CheckError::TooManySamples {
            duration,
            rate: fastest,
            samples: n,
            limit: limits.max_samples,
        });
    }
    if duration > 0.0 && duration * rate < 1.0 {
        return Err(CheckError::RateBelowDuration { rate, duration });
    }
    let mut warnings = Vec::new();
    for (order, action) in decomposition.actions.iter().enumerate() {
        let Some(first) = action.segments.first() else { continue };
        let scene = CollisionScene::new(&task.action_scene(action.index));
        let Some((distance, link, obstacle)) =
            min_distance(robot, &arm_pose(robot, &first.start), &scene)
        else {
            continue;
        };
        if distance < safety {
            let error = CheckError::StartTooClose {
                action: action.name.clone(),
                action_index: action.index,
                order,
                link,
                obstacle,
                distance,
                safety,
            };
            if !allow_close_start {
                return Err(error);
            }
            let message = error.to_string();
            warnings.push(Warning::on_segment(WarningKind::CloseStart, &action.name, 0, message));
        }
    }
    Ok(warnings)
}

/// The warning for a segment that came closer than the safety distance, if it did.
pub fn too_close(s: &SegmentReport, safety: Real) -> Option<Warning> {
    let c = s.clearance.as_ref().filter(|c| c.distance < safety)?;
    let message = format!(
        "action `{}`, segment {}: `{}` and `{}` come {:.1} mm apart at t = {:.3} s, closer \
         than the safety distance of {:.1} mm",
        s.action,
        s.segment + 1,
        c.link,
        c.obstacle,
        c.distance * 1e3,
        c.time,
        safety * 1e3
    );
    Some(Warning::on_segment(WarningKind::TooClose, &s.action, s.segment, message))
}
