//! Timing a planned path (docs/design.md §5): one rest-to-rest bell (paper eq. 9) per straight
//! joint-space edge ([`time_parameterise`], the joint-space RRT's paths) or per chart piece
//! ([`time_constrained`], the constrained RRT's), within [`LIMIT_FRACTION`] of the velocity
//! and acceleration limits. Speed and acceleration vanish where pieces meet, so the motion is
//! C² and stays on what the collision checks covered.

use super::chart::{Chart, ChartPoint, MIN_STEP, SAME_BRANCH};
use super::constrained_rrt::ConstrainedPath;
use super::rrt::RrtError;
use crate::math::{JointVector, Real};
use crate::profile::BellProfile;
use crate::robot::Robot;
use crate::trajectory::{Limits, Trajectory, TrajectoryError, peaks, sample_times};

/// A path timed with bell-shaped speeds (paper eq. 9).
#[derive(Debug, Clone, PartialEq)]
pub struct TimedPath {
    /// Samples at the rate asked for, plus the end.
    pub trajectory: Trajectory,
    /// The duration used (s).
    pub duration: Real,
    /// Whether the duration asked for was stretched to keep every joint within its speed and
    /// acceleration limits.
    pub stretched: bool,
}

/// The share of a limit that planned timing uses; the rest absorbs the interpolation of the
/// output between samples.
pub const LIMIT_FRACTION: Real = 0.95;

/// The shortest rest-to-rest bell over `length` along the unit joint direction `u` that keeps
/// every joint within [`LIMIT_FRACTION`] of its limits: the bell's peak speed is 2L/T and its
/// peak acceleration 2πL/T², joint i moving |u_i| times as much.
pub fn shortest_bell(u: &JointVector, length: Real, limits: &Limits) -> Real {
    (0..u.len())
        .map(|i| {
            let d = length * u[i].abs();
            let v = LIMIT_FRACTION * limits.velocity[i];
            let a = LIMIT_FRACTION * limits.acceleration[i];
            (2.0 * d / v).max((2.0 * crate::math::PI * d / a).sqrt())
        })
        .fold(0.0, Real::max)
}

/// Times `waypoints` as one rest-to-rest bell (paper eq. 9) per straight edge: the speed and
/// acceleration vanish at every waypoint, so the motion is C² with no velocity step, and it
/// stays on the edges the collision checks covered. The path takes `duration`, or the sum of
/// the edges' shortest bells within the limits ([`shortest_bell`]) when that is longer.
///
/// # Errors
/// [`TrajectoryError`] for no waypoint, a non-positive rate or duration, or non-finite values.
pub fn time_parameterise(
    limits: &Limits,
    waypoints: &[JointVector],
    duration: Real,
    rate: Real,
) -> Result<TimedPath, TrajectoryError> {
    let first = *waypoints.first().ok_or(TrajectoryError::Empty)?;
    if !(rate.is_finite() && rate > 0.0) {
        return Err(TrajectoryError::InvalidRate { rate_hz: rate });
    }
    let edges: Vec<(JointVector, JointVector, Real)> = waypoints
        .windows(2)
        .filter(|w| (w[1] - w[0]).norm() > 0.0)
        .map(|w| (w[0], (w[1] - w[0]).normalize(), (w[1] - w[0]).norm()))
        .collect();
    // Each edge's share of the duration is in proportion to its shortest bell, so that every
    // edge uses the same share of its limits, and none is stretched unless all are.
    let shortest: Vec<Real> = edges.iter().map(|(_, u, l)| shortest_bell(u, *l, limits)).collect();
    let least: Real = shortest.iter().sum();
    let scale = if least > 0.0 { (duration / least).max(1.0) } else { 1.0 };
    let bells = edges
        .iter()
        .zip(&shortest)
        .map(|((_, _, l), short)| BellProfile::new(short * scale, *l))
        .collect::<Result<Vec<_>, _>>()
        .map_err(TrajectoryError::Join)?;
    let total: Real = bells.iter().map(BellProfile::duration).sum();
    if edges.is_empty() {
        let trajectory = Trajectory::new(vec![0.0], vec![first], vec![JointVector::zeros()])?;
        return Ok(TimedPath { trajectory, duration: 0.0, stretched: false });
    }
    // The rate's grid plus every waypoint's time, where the motion rests.
    let mut times = sample_times(0.0, total, rate);
    let mut start = 0.0;
    for bell in &bells {
        start += bell.duration();
        times.push(start);
    }
    times.sort_by(Real::total_cmp);
    times.dedup_by(|b, a| *b - *a <= 1e-9 / rate);
    let mut samples = Vec::with_capacity(times.len());
    let (mut edge, mut edge_start) = (0, 0.0);
    for &t in &times {
        while edge + 1 < edges.len() && t > edge_start + bells[edge].duration() {
            edge_start += bells[edge].duration();
            edge += 1;
        }
        let (from, u, _) = &edges[edge];
        let local = t - edge_start;
        samples.push((from + u * bells[edge].progress(local), u * bells[edge].speed(local)));
    }
    let (positions, velocities) = samples.into_iter().unzip();
    let trajectory = Trajectory::new(times, positions, velocities)?;
    Ok(TimedPath { trajectory, duration: total, stretched: total > duration * (1.0 + 1e-9) })
}

/// A chart edge and the configurations checked along it (edge fraction, joints).
struct Edge {
    a: ChartPoint,
    b: ChartPoint,
    track: Vec<(Real, JointVector)>,
}

/// One stretch of a timed constrained path.
enum Piece {
    /// Along a chart edge, by IK near the configurations checked along it.
    Edge(Box<Edge>),
    /// A self-motion at one chart point: two IK solutions of the same state at a
    /// singularity (the wrist's first and last axes aligned, say), joined straight in joint
    /// space, which does not move the state.
    SelfMotion { a: JointVector, b: JointVector },
}

impl Piece {
    fn length(&self, chart: &Chart) -> Real {
        match self {
            Piece::Edge(e) => chart.distance(&e.a, &e.b),
            Piece::SelfMotion { a, b } => (b - a).norm(),
        }
    }
}

/// The pieces of `path`: its edges, and a self-motion wherever an edge leaves a singular
/// configuration on another IK solution of the same state than the one recorded (at a
/// singularity the solutions form a continuum, and the one the motion departs on is the limit
/// of those just after), or reaches its end on another one than the next edge starts from.
fn pieces(robot: &Robot, chart: &Chart, path: &ConstrainedPath) -> Result<Vec<Piece>, RrtError> {
    let mut out = Vec::new();
    let mut travelled = 0.0;
    let edges = path.waypoints.windows(2).zip(path.configurations.windows(2)).zip(&path.tracks);
    for ((w, c), track) in edges {
        let (a, b) = (w[0], w[1]);
        let lost = || RrtError::Tracking { at: travelled };
        // Far enough along for the IK to see the direction of departure, near enough for
        // that direction not to have turned.
        let probe = chart.interpolate(&a, &b, 1e-6);
        let after = chart.ik_near(robot, &probe, &c[0]).ok_or_else(lost)?;
        let departure = chart.ik_near(robot, &a, &after).ok_or_else(lost)?;
        if (departure - c[0]).amax() > 0.0 {
            out.push(Piece::SelfMotion { a: c[0], b: departure });
        }
        let mut track = track.clone();
        if track.last().is_none_or(|(t, _)| *t < 1.0) {
            return Err(lost());
        }
        let arrival = track.last().map_or(departure, |(_, q)| *q);
        if let Some(first) = track.first_mut() {
            first.1 = departure;
        }
        out.push(Piece::Edge(Box::new(Edge { a, b, track })));
        if (c[1] - arrival).amax() > 0.0 {
            out.push(Piece::SelfMotion { a: arrival, b: c[1] });
        }
        travelled += chart.distance(&a, &b);
    }
    Ok(out)
}

/// The IK solution at fraction `tau` of an edge, nearest the checked configurations around it;
/// `None` when it is not within [`MAX_JUMP`] of them (the IK has left their branch). Passing
/// close by a wrist or shoulder singularity, the solution can sweep away from the chord
/// between two checks faster than the checks' spacing assumed; the sweep turns the links
/// next to the aligned axes about those axes.
fn on_track(
    robot: &Robot,
    chart: &Chart,
    (a, b): (&ChartPoint, &ChartPoint),
    track: &[(Real, JointVector)],
    tau: Real,
) -> Option<JointVector> {
    let k = track.partition_point(|(t, _)| *t <= tau).clamp(1, track.len().max(1)) - 1;
    let near = match (track.get(k), track.get(k + 1)) {
        (Some((t0, q0)), Some((t1, q1))) if t1 > t0 => q0 + (q1 - q0) * ((tau - t0) / (t1 - t0)),
        (Some((_, q0)), _) => *q0,
        _ => return None,
    };
    let q = chart.ik_near(robot, &chart.interpolate(a, b, tau), &near)?;
    if (q - near).amax() <= SAME_BRANCH {
        return Some(q);
    }
    // Far from the chord (close by a singularity): follow the IK from the checked point
    // before, in steps that change no joint by much.
    let (mut t, mut q) = *track.get(k)?;
    let mut step = tau - t;
    while t < tau {
        let trial = step.min(tau - t);
        let at = if trial >= tau - t { tau } else { t + trial };
        let next = chart.ik_near(robot, &chart.interpolate(a, b, at), &q)?;
        if (next - q).amax() <= SAME_BRANCH {
            (t, q) = (at, next);
            step = 2.0 * trial;
        } else if trial > MIN_STEP {
            step = 0.5 * trial;
        } else {
            return None;
        }
    }
    Some(q)
}

/// Times a constrained path at `rate` as one rest-to-rest bell (paper eq. 9) per piece, along
/// its length (chart length for edges, joint-space length for self-motions at singular
/// points): speed and acceleration vanish where pieces meet, so nothing steps there. Every
/// sample on an edge is the IK of a chart point on the path, tracked on the path's branch, so
/// the path constraint holds at every sample. Joint velocities are the IK's derivative along
/// the path ([`Chart::joint_rate`]) times the bell speed. Each piece takes its share of `duration` by length,
/// stretched until its joints keep [`LIMIT_FRACTION`] of their velocity and acceleration
/// limits.
///
/// # Errors
/// [`RrtError::Timing`] for a non-positive rate or duration, or a piece whose timing does not
/// settle within the limits; [`RrtError::Tracking`] when the IK cannot follow the path between
/// its checked points.
pub fn time_constrained(
    robot: &Robot,
    limits: &Limits,
    chart: &Chart,
    path: &ConstrainedPath,
    duration: Real,
    rate: Real,
) -> Result<TimedPath, RrtError> {
    let trajectory_error = |e: TrajectoryError| RrtError::Timing { reason: e.to_string() };
    if !(rate.is_finite() && rate > 0.0) {
        return Err(trajectory_error(TrajectoryError::InvalidRate { rate_hz: rate }));
    }
    let pieces = pieces(robot, chart, path)?;
    let lengths: Vec<Real> = pieces.iter().map(|p| p.length(chart)).collect();
    let length: Real = lengths.iter().sum();
    let within = Limits {
        velocity: limits.velocity * LIMIT_FRACTION,
        acceleration: limits.acceleration * LIMIT_FRACTION,
        ..*limits
    };
    let first = path.configurations[0];
    let (mut times, mut positions, mut velocities) =
        (vec![0.0], vec![first], vec![JointVector::zeros()]);
    let mut stretched = false;
    let mut travelled = 0.0;
    for (piece, &piece_length) in pieces.iter().zip(&lengths) {
        if piece_length <= 0.0 {
            continue;
        }
        let mut piece_duration = duration * piece_length / length;
        let mut timed = None;
        for _ in 0..8 {
            let samples = time_piece(robot, chart, piece, piece_length, piece_duration, rate)
                .map_err(|e| match e {
                    RrtError::Tracking { at } => RrtError::Tracking { at: travelled + at },
                    e => e,
                })?;
            let trajectory =
                Trajectory::new(samples.0, samples.1, samples.2).map_err(trajectory_error)?;
            let stretch = peaks(&trajectory, 0.0, piece_duration).stretch(&within);
            if stretch <= 1.0 {
                timed = Some(trajectory);
                break;
            }
            piece_duration *= stretch * 1.01;
            stretched = true;
        }
        let trajectory = timed.ok_or_else(|| RrtError::Timing {
            reason: "a piece's duration does not settle under the joint limits".into(),
        })?;
        let offset = *times.last().unwrap_or(&0.0);
        // The piece's first sample is where the last one ended, at rest.
        for ((t, q), qd) in trajectory
            .times()
            .iter()
            .zip(trajectory.positions())
            .zip(trajectory.velocities())
            .skip(1)
        {
            times.push(offset + t);
            positions.push(*q);
            velocities.push(*qd);
        }
        travelled += piece_length;
    }
    let total = *times.last().unwrap_or(&0.0);
    let trajectory = Trajectory::new(times, positions, velocities).map_err(trajectory_error)?;
    Ok(TimedPath {
        trajectory,
        duration: total,
        stretched: stretched || total > duration * (1.0 + 1e-9),
    })
}

/// Samples of a motion: times, q, q'.
type Samples = (Vec<Real>, Vec<JointVector>, Vec<JointVector>);

/// One piece timed by a rest-to-rest bell of `duration` over its `length`: times from 0, q,
/// q'.
fn time_piece(
    robot: &Robot,
    chart: &Chart,
    piece: &Piece,
    length: Real,
    duration: Real,
    rate: Real,
) -> Result<Samples, RrtError> {
    let bell = BellProfile::new(duration, length)
        .map_err(|e| RrtError::Timing { reason: TrajectoryError::Join(e).to_string() })?;
    let times = sample_times(0.0, duration, rate);
    let mut positions = Vec::with_capacity(times.len());
    let mut velocities = Vec::with_capacity(times.len());
    for &t in &times {
        let s = bell.progress(t);
        let lost = || RrtError::Tracking { at: s };
        let (q, rate_of_change) = match piece {
            Piece::SelfMotion { a, b } => {
                let u = (b - a) / length;
                (a + u * s, u)
            }
            Piece::Edge(edge) => {
                let Edge { a, b, track } = edge.as_ref();
                let tau = (s / length).clamp(0.0, 1.0);
                let at = |t: Real| on_track(robot, chart, (a, b), track, t);
                let q = at(tau).ok_or_else(lost)?;
                let rate = match chart.joint_rate(robot, (a, b), tau, &q) {
                    Some(rate) => rate,
                    None => {
                        // A singular Jacobian: dq/dτ by a central difference on the same
                        // branch.
                        let h = 1e-6;
                        let (lo, hi) = ((tau - h).max(0.0), (tau + h).min(1.0));
                        let ahead = at(hi).ok_or_else(lost)?;
                        let behind = at(lo).ok_or_else(lost)?;
                        (ahead - behind) / (hi - lo)
                    }
                };
                (q, rate / length)
            }
        };
        positions.push(q);
        velocities.push(rate_of_change * bell.speed(t));
    }
    Ok((times, positions, velocities))
}
