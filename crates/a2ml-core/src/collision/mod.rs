//! Distances between the arm's capsules and the task's obstacles, shared by
//! every solver that keeps the arm clear (Opt1/Opt2, the velocity QP, RRT).
//!
//! Entry points: [`CollisionScene::new`], [`arm_capsules`], [`distances`],
//! [`min_distance`]; for many configurations of one scene (sampling
//! planners), [`CollisionModel`] with [`clearance`], [`advancement`] (and
//! [`advancement_at_least`]) and [`motion_bound`], [`is_clear`] for a yes-or-no check with
//! shapes inflated by an [`Inflation`] ([`verdict`]: with and without it in one pass;
//! [`coverage`]: the share of it kept; [`verdict_of`]: the obstacles' or the self pairs' alone);
//! [`check_shapes`] before any query, so
//! that no pair is skipped for a shape parry cannot handle. Everything is in {b}, SI
//! units. parry enters the crate here only; its glam types never leave this
//! module.

use std::f64::consts::FRAC_PI_2;

use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query::{self, Contact};
use parry3d_f64::shape::{Ball, Cuboid, Cylinder, Segment, Shape as ParryShape};

use crate::kinematics::ArmPose;
use crate::language::{Obstacle, Shape};
use crate::math::{JointVector, Real, Rotation3, UnitQuaternion, Vector3};
use crate::robot::{LinkRole, Robot};

mod guard;
mod model;

pub use guard::{ShapeError, check_shapes};
pub use model::{
    Closest, CollisionModel, Inflation, Pair, Pairs, Verdict, advancement, advancement_at_least,
    advancement_within, clearance, coverage, is_clear, motion_bound, self_motion_bound, verdict,
    verdict_of,
};

/// How much [`min_distance`] or [`clearance`] may differ from the exact
/// distance of a separated pair (m): parry's GJK stops up to 1e-5 m above it (README,
/// "Speed"), and the closed forms are within 1e-11 m; ten times that, for a bound that is
/// never too high.
pub const MEASURE_SLACK: Real = 1e-4;

/// A lower bound of [`min_distance`] at `q` from its value `distance` at
/// `measured`: no point of any capsule moves farther than [`motion_bound`] between
/// the two configurations, so no pair (a self pair's two capsules both moving) comes more
/// than twice that closer, less what the measure itself may be off by ([`MEASURE_SLACK`],
/// twice). Only a positive bound says anything: a penetration's depth has no such slack.
pub fn clearance_bound(
    model: &CollisionModel,
    distance: Real,
    measured: &JointVector,
    q: &JointVector,
) -> Real {
    distance - 2.0 * motion_bound(model, &(q - measured)) - 2.0 * MEASURE_SLACK
}

/// The task's obstacles as parry shapes, positioned in {b}.
///
/// Positions are read as {b} coordinates whatever `settings.frame` says:
/// scenes written in the URDF root frame must be moved first with
/// [`crate::language::Task::in_base_frame`] (as `decompose` does).
#[derive(Debug, Clone)]
pub struct CollisionScene {
    bodies: Vec<Body>,
}

impl CollisionScene {
    /// Builds the scene from validated obstacles (positions in {b}).
    pub fn new(obstacles: &[Obstacle]) -> Self {
        Self { bodies: obstacles.iter().map(Body::from_obstacle).collect() }
    }

    /// Names of the obstacles, in the order given.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.bodies.iter().map(|b| b.name.as_str())
    }

    /// The name of obstacle `k` (in the order given).
    pub fn name(&self, k: usize) -> &str {
        &self.bodies[k].name
    }

    /// Number of obstacles.
    pub fn len(&self) -> usize {
        self.bodies.len()
    }

    /// Whether the scene has no obstacle.
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }
}

/// One link capsule placed in {b}.
#[derive(Debug, Clone, PartialEq)]
pub struct PosedCapsule {
    /// The capsule's name (URDF collision name, else link name).
    pub name: String,
    /// Part of the arm carrying it.
    pub role: LinkRole,
    /// The moving frame it is attached to.
    pub frame: usize,
    /// Segment end in {b} (m).
    pub a: Vector3,
    /// Other segment end in {b} (m).
    pub b: Vector3,
    /// Radius (m).
    pub radius: Real,
}

/// Settings of [`distances`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceOptions {
    /// Pairs at this distance or farther are not reported (m), default 0.1.
    pub influence: Real,
}

impl Default for DistanceOptions {
    fn default() -> Self {
        Self { influence: 0.1 }
    }
}

/// The closest points of a link capsule and an obstacle (or another link).
#[derive(Debug, Clone, PartialEq)]
pub struct Proximity {
    /// The link capsule's name.
    pub link: String,
    /// The obstacle's name, or the other capsule's name for self-collision.
    pub obstacle: String,
    /// Signed distance (m): negative is the penetration depth.
    pub distance: Real,
    /// Closest point on the link capsule, {b}.
    pub on_link: Vector3,
    /// Closest point on the obstacle, {b}.
    pub on_obstacle: Vector3,
    /// Unit normal from the obstacle to the link, {b}.
    pub normal: Vector3,
    /// The moving frame carrying the link capsule (for its point Jacobian).
    pub link_frame: usize,
    /// The moving frame carrying the other capsule of a self-collision pair;
    /// `None` for a scene obstacle, which does not move.
    pub obstacle_frame: Option<usize>,
}

/// The link capsules at `pose`, in {b}.
pub fn arm_capsules(robot: &Robot, pose: &ArmPose) -> Vec<PosedCapsule> {
    robot
        .capsules
        .iter()
        .map(|c| {
            let b_from_frame = &pose.frames[c.frame];
            PosedCapsule {
                name: c.name.clone(),
                role: c.role,
                frame: c.frame,
                a: b_from_frame.transform_point(&c.a.into()).coords,
                b: b_from_frame.transform_point(&c.b.into()).coords,
                radius: c.radius,
            }
        })
        .collect()
}

/// Every moving link capsule × obstacle pair, plus the robot's self-collision pairs
/// ([`Robot::self_pairs`]), closer than `options.influence`.
///
/// Pairs whose bounding spheres are already `influence` apart are skipped
/// without a narrow-phase query.
pub fn distances(
    robot: &Robot,
    pose: &ArmPose,
    scene: &CollisionScene,
    options: &DistanceOptions,
) -> Vec<Proximity> {
    let influence = options.influence;
    let mut out = Vec::new();
    for_each_pair(robot, pose, scene, |link, other| {
        if bounding_gap(link, other) >= influence {
            return;
        }
        if let Some(p) = proximity(link, other, influence) {
            if p.distance < influence {
                out.push(p);
            }
        }
    });
    out
}

/// The smallest signed distance over the pairs [`distances`] considers, and
/// the pair (link, obstacle); `None` when there is no pair.
pub fn min_distance(
    robot: &Robot,
    pose: &ArmPose,
    scene: &CollisionScene,
) -> Option<(Real, String, String)> {
    let mut best: Option<(Real, String, String)> = None;
    for_each_pair(robot, pose, scene, |link, other| {
        let bound = best.as_ref().map_or(Real::INFINITY, |b| b.0);
        // Broad phase against the best so far.
        if bounding_gap(link, other) >= bound {
            return;
        }
        // Prediction large enough to always find the pair: the farthest
        // two points of the bounding spheres.
        let reach = (link.center - other.center).norm() + link.bound + other.bound + 1.0;
        if let Some(p) = proximity(link, other, reach.min(bound)) {
            if p.distance < bound {
                best = Some((p.distance, p.link, p.obstacle));
            }
        }
    });
    best
}

/// A convex body in {b}: a parry shape, its pose, and a radius added
/// around it (capsules are segments plus a radius, which keeps parry on its
/// exact point/segment/polytope paths).
#[derive(Debug, Clone)]
struct Body {
    name: String,
    shape: Core,
    pose: Pose,
    margin: Real,
    /// Bounding sphere centre, {b}.
    center: Vector3,
    /// Bounding sphere radius, margin included.
    bound: Real,
    /// The moving frame of an arm capsule; `None` for an obstacle.
    frame: Option<usize>,
}

#[derive(Debug, Clone, Copy)]
enum Core {
    Ball(Ball),
    Segment(Segment),
    Cuboid(Cuboid),
    Cylinder(Cylinder),
}

impl Core {
    fn as_dyn(&self) -> &dyn ParryShape {
        match self {
            Self::Ball(s) => s,
            Self::Segment(s) => s,
            Self::Cuboid(s) => s,
            Self::Cylinder(s) => s,
        }
    }
}

fn to_parry(v: &Vector3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// The parry pose placing a shape's centre at `center`, turned by `rotation`.
fn pose(center: &Vector3, rotation: &Rotation3) -> Pose {
    let q = UnitQuaternion::from_rotation_matrix(rotation).into_inner().coords;
    Pose::from_parts(to_parry(center), Rotation::from_xyzw(q.x, q.y, q.z, q.w).normalize())
}

fn from_parry(v: Vector) -> Vector3 {
    Vector3::new(v.x, v.y, v.z)
}

impl Body {
    fn from_obstacle(o: &Obstacle) -> Self {
        let name = o.name.clone();
        match &o.shape {
            Shape::Box { center, size, rotation } => Self {
                name,
                shape: Core::Cuboid(Cuboid::new(to_parry(&(size * 0.5)))),
                pose: pose(center, rotation),
                margin: 0.0,
                center: *center,
                bound: 0.5 * size.norm(),
                frame: None,
            },
            Shape::Sphere { center, radius } => Self {
                name,
                shape: Core::Ball(Ball::new(*radius)),
                pose: Pose::from_translation(to_parry(center)),
                margin: 0.0,
                center: *center,
                bound: *radius,
                frame: None,
            },
            Shape::Capsule { a, b, radius } => Self::capsule(name, a, b, *radius, None),
            Shape::Cylinder { center, radius, height, rotation } => Self {
                name,
                shape: Core::Cylinder(Cylinder::new(0.5 * height, *radius)),
                // parry's cylinder runs along y; turn y onto z first.
                pose: pose(
                    center,
                    &(rotation * Rotation3::from_axis_angle(&Vector3::x_axis(), FRAC_PI_2)),
                ),
                margin: 0.0,
                center: *center,
                bound: radius.hypot(0.5 * height),
                frame: None,
            },
        }
    }

    fn capsule(name: String, a: &Vector3, b: &Vector3, radius: Real, frame: Option<usize>) -> Self {
        Self {
            name,
            shape: Core::Segment(Segment::new(to_parry(a), to_parry(b))),
            pose: Pose::IDENTITY,
            margin: radius,
            center: 0.5 * (a + b),
            bound: 0.5 * (b - a).norm() + radius,
            frame,
        }
    }

    fn from_capsule(c: &PosedCapsule) -> Self {
        Self::capsule(c.name.clone(), &c.a, &c.b, c.radius, Some(c.frame))
    }
}

/// Calls `f(link, obstacle)` for every pair [`distances`] considers.
fn for_each_pair(
    robot: &Robot,
    pose: &ArmPose,
    scene: &CollisionScene,
    mut f: impl FnMut(&Body, &Body),
) {
    let capsules = arm_capsules(robot, pose);
    let bodies: Vec<Body> = capsules.iter().map(Body::from_capsule).collect();
    for (link, capsule) in bodies.iter().zip(&capsules) {
        if capsule.role == LinkRole::Base {
            continue;
        }
        for obstacle in &scene.bodies {
            f(link, obstacle);
        }
    }
    for &(link, other) in &robot.self_pairs {
        f(&bodies[link], &bodies[other]);
    }
}

/// Lower bound of the distance between two bodies from their bounding spheres.
fn bounding_gap(a: &Body, b: &Body) -> Real {
    (a.center - b.center).norm() - a.bound - b.bound
}

/// The signed distance and closest points of `link` and `obstacle`, if
/// closer than `prediction`.
fn proximity(link: &Body, obstacle: &Body, prediction: Real) -> Option<Proximity> {
    let margins = link.margin + obstacle.margin;
    // Shape 1 is the obstacle, so parry's normal1 points from it to the link.
    let contact: Contact = query::contact(
        &obstacle.pose,
        obstacle.shape.as_dyn(),
        &link.pose,
        link.shape.as_dyn(),
        (prediction + margins).max(0.0),
    )
    // Every pair of the four shapes is supported by parry's default dispatcher.
    .ok()??;
    let normal = from_parry(contact.normal1);
    Some(Proximity {
        link: link.name.clone(),
        obstacle: obstacle.name.clone(),
        distance: contact.dist - margins,
        on_link: from_parry(contact.point2) - normal * link.margin,
        on_obstacle: from_parry(contact.point1) + normal * obstacle.margin,
        normal,
        link_frame: link.frame.unwrap_or(0),
        obstacle_frame: obstacle.frame,
    })
}

#[cfg(test)]
mod tests;
