//! The map of one segment of a task, for the pipeline and for pictures.

use super::{
    MapError, MapOptions, SwivelMap, SwivelProfile, SwivelTargets, WristMotion, build_map,
    plan_profile,
};
use crate::decompose::{DecomposeOptions, decompose};
use crate::language::{Obstacle, Task};
use crate::math::JointVector;
use crate::robot::Robot;
use crate::solve::SolveError;
use crate::solve::plan::segment_problem;
use crate::solve::problem::SegmentProblem;

/// A segment's map with what it was built from, and its profile or why there is none.
#[derive(Debug, Clone)]
pub struct SegmentMap {
    /// The action's name.
    pub action: String,
    /// The segment's index in its action (0-based).
    pub segment: usize,
    /// The wrist motion the map is built for.
    pub motion: WristMotion,
    /// The start configuration.
    pub start: JointVector,
    /// The end and reference the profile aims for.
    pub targets: SwivelTargets,
    /// The map.
    pub map: SwivelMap,
    /// The planned profile, or why there is none.
    pub profile: Result<SwivelProfile, MapError>,
}

/// The map and profile of a CPSA segment from configuration `start` among `obstacles`
/// ({b}): the pipeline's `map` solver.
///
/// # Errors
/// [`MapError`] from [`build_map`] and [`plan_profile`], and
/// [`MapError::NotWristSegment`] for a HAT segment.
pub fn map_segment(
    robot: &Robot,
    obstacles: &[Obstacle],
    problem: &SegmentProblem,
    start: &JointVector,
    options: &MapOptions,
) -> Result<(SwivelMap, SwivelProfile), MapError> {
    let motion = WristMotion::of_problem(problem)?;
    let map = build_map(robot, obstacles, &motion, start, options)?;
    let targets = SwivelTargets::of_problem(problem, &map.times);
    let profile = plan_profile(robot, obstacles, &motion, &map, start, &targets, options)?;
    Ok((map, profile))
}

/// Why a segment's map cannot be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SegmentMapError {
    /// The task does not decompose, or the segment's references cannot be built.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// No action of that name.
    #[error("no action `{name}` in the task (actions: {known})")]
    NoAction {
        /// The name asked for.
        name: String,
        /// The task's action names.
        known: String,
    },
    /// The action has fewer segments.
    #[error("action `{action}` has {count} segment(s); segment {asked} does not exist")]
    NoSegment {
        /// The action.
        action: String,
        /// Its number of segments.
        count: usize,
        /// The 1-based number asked for.
        asked: usize,
    },
    /// The map itself cannot be built.
    #[error("action `{action}`, segment {}: {source}", segment + 1)]
    Map {
        /// The action.
        action: String,
        /// Segment index (0-based).
        segment: usize,
        /// Why.
        source: MapError,
    },
}

/// The map of segment `segment` (0-based) of action `action` in `task`, from the
/// decomposition's start configuration of that segment; the profile's failure is kept in
/// the result, so a map without a profile can still be drawn.
///
/// # Errors
/// [`SegmentMapError`]: the task does not decompose, no such action or segment, or the map
/// cannot be built (a HAT segment, an arm without analytic IK).
pub fn segment_map(
    robot: &Robot,
    task: &Task,
    action: &str,
    segment: usize,
    decompose_options: &DecomposeOptions,
    options: &MapOptions,
) -> Result<SegmentMap, SegmentMapError> {
    let decomposition = decompose(robot, task, decompose_options).map_err(SolveError::from)?;
    let Some(planned) = decomposition.actions.iter().find(|a| a.name == action) else {
        let known: Vec<&str> = decomposition.actions.iter().map(|a| a.name.as_str()).collect();
        return Err(SegmentMapError::NoAction { name: action.to_owned(), known: known.join(", ") });
    };
    let Some(part) = planned.segments.get(segment) else {
        return Err(SegmentMapError::NoSegment {
            action: action.to_owned(),
            count: planned.segments.len(),
            asked: segment + 1,
        });
    };
    let task_b = task.in_base_frame(&robot.structure.shoulder_in_base_link);
    let obstacles = task_b.action_scene(planned.index);
    let problem = segment_problem(robot, &part.start, planned, segment, part)?;
    let failed = |source| SegmentMapError::Map { action: action.to_owned(), segment, source };
    let motion = WristMotion::of_problem(&problem).map_err(failed)?;
    let map = build_map(robot, &obstacles, &motion, &part.start, options).map_err(failed)?;
    let targets = SwivelTargets::of_problem(&problem, &map.times);
    let profile = plan_profile(robot, &obstacles, &motion, &map, &part.start, &targets, options);
    Ok(SegmentMap {
        action: action.to_owned(),
        segment,
        motion,
        start: part.start,
        targets,
        map,
        profile,
    })
}
