//! The (t, θsw) grid of a wrist motion: each cell labelled free or by what forbids it.

use super::sphere::{AxialCapsule, ElbowCircle, HalfWidth, half_width};
use super::{MapError, MapOptions, WristMotion};
use crate::collision::{CollisionModel, CollisionScene, PosedCapsule, arm_capsules, clearance};
use crate::kinematics::{CpsaState, SwivelInterval};
use crate::kinematics::{IkOptions, arm_pose, ik_cpsa_with, swivel_intervals};
use crate::language::{Obstacle, Shape};
use crate::math::{JointVector, PI, Real, Vector3, wrap_angle};
use crate::robot::{LinkRole, Robot};

/// What a cell's configuration does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Cell {
    /// Within limits and clear of everything.
    Free,
    /// No IK branch within the joint limits.
    Limits,
    /// A self-collision pair closer than the safety distance.
    SelfCollision,
    /// The arm closer than the safety distance to this obstacle (index into
    /// [`SwivelMap::obstacles`]); the first such obstacle is named.
    Obstacle(u16),
}

/// Why a whole column is ruled out: the wrist pose itself cannot be held.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ColumnFault {
    /// No arm configuration reaches (Pw, Ow): unreachable or singular.
    WristPose(String),
    /// The hand, which the swivel does not move away, hits this obstacle at every angle.
    Hand(String),
}

impl ColumnFault {
    /// A sentence for messages.
    pub fn describe(&self) -> String {
        match self {
            Self::WristPose(why) => format!("the wrist pose cannot be reached ({why})"),
            Self::Hand(obstacle) => format!("the hand hits `{obstacle}` at every swivel angle"),
        }
    }
}

/// A sphere's exact forbidden interval of one capsule at one column (METHODS.md §1.3): the
/// swivel angles within `half_width` of `centre` (rad, wrapped) collide.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ForbiddenInterval {
    /// Map column.
    pub column: usize,
    /// Obstacle index.
    pub obstacle: usize,
    /// The capsule (index into the robot's capsules).
    pub capsule: usize,
    /// Centre of the interval (rad).
    pub centre: Real,
    /// Half-width (rad); π for the whole circle.
    pub half_width: Real,
}

/// The map: `cells[i * angles.len() + j]` labels time `times[i]` and swivel `angles[j]`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SwivelMap {
    /// Column times from the segment's start (s), `times[0] = 0`, last = the duration.
    pub times: Vec<Real>,
    /// Cell-centre swivel angles (rad), increasing over [−π, π).
    pub angles: Vec<Real>,
    /// The labels, row-major by time.
    pub cells: Vec<Cell>,
    /// Obstacle names, in the order [`Cell::Obstacle`] counts.
    pub obstacles: Vec<String>,
    /// Per column, what rules it out as a whole, if anything.
    pub faults: Vec<Option<ColumnFault>>,
    /// The exact sphere intervals behind the sphere labels.
    pub intervals: Vec<ForbiddenInterval>,
    /// The cells labelled through the collision model rather than in closed form.
    pub cells_checked: usize,
}

impl SwivelMap {
    /// The label at column `i`, angle cell `j`.
    pub fn cell(&self, i: usize, j: usize) -> Cell {
        self.cells[i * self.angles.len() + j]
    }

    /// Whether the cell is free.
    pub fn is_free(&self, i: usize, j: usize) -> bool {
        self.cell(i, j) == Cell::Free
    }

    /// Angle cell width (rad).
    pub fn angle_step(&self) -> Real {
        2.0 * PI / self.angles.len() as Real
    }

    /// The cell containing swivel angle `theta` (rad, any turn).
    pub fn angle_index(&self, theta: Real) -> usize {
        let n = self.angles.len();
        let j = ((wrap_angle(theta) + PI) / self.angle_step()).floor() as isize;
        j.rem_euclid(n as isize) as usize
    }
}

/// The collision models one column's cell checks use.
struct Models {
    /// Whole arm, no obstacle: the self pairs.
    own: CollisionModel,
    /// Per obstacle: the capsules not handled in closed form (none: `None`).
    arm: Vec<Option<CollisionModel>>,
    /// Per obstacle: the hand capsules.
    hand: Vec<Option<CollisionModel>>,
}

/// `robot` with only the capsules `keep` accepts, and the self pairs among them (renumbered:
/// a self pair names capsules by index).
fn with_capsules(robot: &Robot, keep: impl Fn(usize) -> bool) -> Option<Robot> {
    let kept: Vec<usize> = (0..robot.capsules.len()).filter(|&i| keep(i)).collect();
    if kept.is_empty() {
        return None;
    }
    let index = |old: usize| kept.iter().position(|&k| k == old);
    let capsules = kept.iter().map(|&i| robot.capsules[i].clone()).collect();
    let self_pairs =
        robot.self_pairs.iter().filter_map(|&(a, b)| Some((index(a)?, index(b)?))).collect();
    Some(Robot { capsules, self_pairs, ..robot.clone() })
}

impl Models {
    fn new(robot: &Robot, obstacles: &[Obstacle], closed_form: &[bool]) -> Self {
        let empty = CollisionScene::new(&[]);
        let role = |i: usize| robot.capsules[i].role;
        let arm = |o: &Obstacle| {
            let scene = CollisionScene::new(std::slice::from_ref(o));
            let sphere = matches!(o.shape, Shape::Sphere { .. });
            with_capsules(robot, |i| {
                matches!(role(i), LinkRole::UpperArm | LinkRole::Forearm)
                    && !(sphere && closed_form[i])
            })
            .map(|r| CollisionModel::new(&r, &scene))
        };
        let hand = |o: &Obstacle| {
            let scene = CollisionScene::new(std::slice::from_ref(o));
            with_capsules(robot, |i| role(i) == LinkRole::Hand)
                .map(|r| CollisionModel::new(&r, &scene))
        };
        Self {
            own: CollisionModel::new(robot, &empty),
            arm: obstacles.iter().map(arm).collect(),
            hand: obstacles.iter().map(hand).collect(),
        }
    }
}

/// The capsules of frames 3 and 4 lying in a half-plane bounded by the S–W axis, in that
/// axis's coordinates: frames 3 and 4 turn rigidly about the axis as θsw changes (frames 1
/// and 2, and the wrist's, do not), so the sphere theorem holds for exactly these.
fn axial_capsules(
    robot: &Robot,
    circle: &ElbowCircle,
    posed: &[PosedCapsule],
) -> Vec<Option<(AxialCapsule, Real)>> {
    posed
        .iter()
        .zip(&robot.capsules)
        .map(|(p, c)| {
            if !(matches!(c.role, LinkRole::UpperArm | LinkRole::Forearm)
                && (3..=4).contains(&c.frame))
            {
                return None;
            }
            let (ha, ra, pa) = circle.cylindrical(&p.a);
            let (hb, rb, pb) = circle.cylindrical(&p.b);
            let scale = 1e-9 * (1.0 + ra.max(rb));
            let same_phase =
                ra < scale || rb < scale || wrap_angle(pa - pb).abs() * ra.min(rb) < scale;
            let phase = if ra >= rb { pa } else { pb };
            same_phase
                .then_some((AxialCapsule { a: (ha, ra), b: (hb, rb), radius: c.radius }, phase))
        })
        .collect()
}

/// The cell-centre angles of an `n`-cell turn.
fn cell_angles(n: usize) -> Vec<Real> {
    let step = 2.0 * PI / n as Real;
    (0..n).map(|j| -PI + (j as Real + 0.5) * step).collect()
}

/// IK at a cell without the joint limits (they are labelled from the closed-form
/// intervals), the branch nearest `near`.
fn configuration(
    robot: &Robot,
    pw: &Vector3,
    ow: &crate::math::Rotation3,
    swivel: Real,
    near: &JointVector,
) -> Option<JointVector> {
    let unlimited = IkOptions { limit_tolerance: Real::INFINITY, ..IkOptions::default() };
    ik_cpsa_with(robot, &CpsaState { pw: *pw, ow: *ow, swivel }, Some(near), &unlimited)
        .ok()
        .and_then(|b| b.into_iter().next())
}

fn within(intervals: &[SwivelInterval], theta: Real) -> bool {
    intervals.iter().any(|i| i.contains(theta))
}

/// Builds the map of `motion` for `robot` among `obstacles` (positions in {b}), starting the
/// IK branch tracking at `start` (the segment's start configuration).
///
/// Joint limits come from the closed-form swivel intervals; spheres against the capsules
/// that turn rigidly with the swivel from their exact intervals; every other obstacle,
/// capsule and the self-collision pairs from the collision model at each cell's IK
/// configuration. A column where the wrist pose cannot be reached, or the hand hits an
/// obstacle at every angle, is a [`ColumnFault`], its cells labelled [`Cell::Limits`].
///
/// # Errors
/// [`MapError::Options`] for a grid smaller than 2 × 8 or a non-finite safety distance;
/// [`MapError::NotAnalytic`] for an arm without analytic IK.
pub fn build_map(
    robot: &Robot,
    obstacles: &[Obstacle],
    motion: &WristMotion,
    start: &JointVector,
    options: &MapOptions,
) -> Result<SwivelMap, MapError> {
    if options.time_steps < 2 || options.angle_steps < 8 {
        return Err(MapError::Options("the grid needs at least 2 time steps and 8 angle steps"));
    }
    if !options.safety_distance.is_finite() {
        return Err(MapError::Options("the safety distance must be finite"));
    }
    if !robot.has_analytic_ik() {
        return Err(MapError::NotAnalytic);
    }
    let duration = motion.duration();
    let nt = options.time_steps;
    let times: Vec<Real> = (0..nt).map(|i| duration * i as Real / (nt - 1) as Real).collect();
    let angles = cell_angles(options.angle_steps);
    let n = angles.len();
    let safety = options.safety_distance;
    let mut map = SwivelMap {
        times: times.clone(),
        angles: angles.clone(),
        cells: vec![Cell::Limits; nt * n],
        obstacles: obstacles.iter().map(|o| o.name.clone()).collect(),
        faults: vec![None; nt],
        intervals: Vec::new(),
        cells_checked: 0,
    };
    let (lu, lf) = (robot.upper_arm_length(), robot.forearm_length());
    let mut near = *start;
    let mut models: Option<(Vec<bool>, Models)> = None;
    for (i, &t) in times.iter().enumerate() {
        let wrist = motion.at(t);
        let fault = |why: String| Some(ColumnFault::WristPose(why));
        let circle = match ElbowCircle::new(lu, lf, &wrist.pw, &robot.vertical) {
            Ok(c) => c,
            Err(e) => {
                map.faults[i] = fault(e.to_string());
                continue;
            }
        };
        let limits = match swivel_intervals(robot, &wrist.pw, &wrist.ow) {
            Ok(l) => l,
            Err(e) => {
                map.faults[i] = fault(e.to_string());
                continue;
            }
        };
        let Some(first) = configuration(robot, &wrist.pw, &wrist.ow, angles[0], &near) else {
            map.faults[i] = fault("no IK solution".to_owned());
            continue;
        };
        let posed = arm_capsules(robot, &arm_pose(robot, &first));
        let axial = axial_capsules(robot, &circle, &posed);
        let closed_form: Vec<bool> = axial.iter().map(Option::is_some).collect();
        if models.as_ref().is_none_or(|(c, _)| *c != closed_form) {
            models = Some((closed_form.clone(), Models::new(robot, obstacles, &closed_form)));
        }
        let Some((_, m)) = models.as_ref() else { continue };
        // Exact sphere intervals: the capsule's phase at swivel θ is its phase at angles[0]
        // minus (θ − angles[0]), since the swivel turns it by Rot(x, −Δθ).
        let mut sphere_hits: Vec<(usize, Real, Real)> = Vec::new();
        for (k, o) in obstacles.iter().enumerate() {
            let Shape::Sphere { center, radius } = o.shape else { continue };
            let (h, p, phase_o) = circle.cylindrical(&center);
            for (c, entry) in axial.iter().enumerate() {
                let Some((capsule, phase)) = entry else { continue };
                let hw = match half_width(capsule, (h, p), radius, safety) {
                    HalfWidth::Empty => continue,
                    HalfWidth::Within(w) => w,
                    HalfWidth::Full => PI,
                };
                let centre = wrap_angle(phase + angles[0] - phase_o);
                map.intervals.push(ForbiddenInterval {
                    column: i,
                    obstacle: k,
                    capsule: c,
                    centre,
                    half_width: hw,
                });
                sphere_hits.push((k, centre, hw));
            }
        }
        let mut hand_everywhere: Vec<bool> = vec![true; obstacles.len()];
        let mut column_near = first;
        for (j, &theta) in angles.iter().enumerate() {
            let q = configuration(robot, &wrist.pw, &wrist.ow, theta, &column_near);
            let mut label = None;
            for (k, _) in obstacles.iter().enumerate() {
                let by_sphere = sphere_hits
                    .iter()
                    .any(|&(o, centre, hw)| o == k && wrap_angle(theta - centre).abs() <= hw);
                let by_model = q.is_some_and(|q| {
                    m.arm[k].as_ref().is_some_and(|model| clearance(model, &q) < safety)
                });
                let by_hand = q.is_some_and(|q| {
                    m.hand[k].as_ref().is_some_and(|model| clearance(model, &q) < safety)
                });
                hand_everywhere[k] &= by_hand;
                if label.is_none() && (by_sphere || by_model || by_hand) {
                    label = Some(Cell::Obstacle(k as u16));
                }
            }
            if q.is_some() {
                map.cells_checked += 1;
            }
            let label = label.unwrap_or_else(|| match q {
                Some(q) if clearance(&m.own, &q) < safety => Cell::SelfCollision,
                Some(_) if within(&limits, theta) => Cell::Free,
                _ => Cell::Limits,
            });
            map.cells[i * n + j] = label;
            if let Some(q) = q {
                column_near = q;
            }
        }
        if let Some(k) = hand_everywhere.iter().position(|&h| h) {
            map.faults[i] = Some(ColumnFault::Hand(obstacles[k].name.clone()));
        }
        near = first;
    }
    Ok(map)
}
