//! [`CollisionModel`]: the arm's capsules and a scene prepared once for queries at many
//! configurations, without allocating: closed-form capsule–sphere, capsule–capsule and
//! capsule–box/cylinder distances (the last settled by tangents of the convex distance along
//! the segment), parry only for the depth of a segment inside a box or cylinder.

use std::sync::Arc;

use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::Segment;

use super::{Body, CollisionScene, Core, from_parry, to_parry};
use crate::kinematics::{AlignedChain, Frame};
use crate::math::{
    DOF, JointVector, Matrix3, PI, Real, Rotation3, Vector3, segment_segment_distance,
};
use crate::robot::{LinkRole, Robot};

mod clear;
mod pairs;

pub use clear::{Inflation, Pairs, Verdict, coverage, is_clear, verdict, verdict_of};
pub use pairs::{Closest, Pair};

/// The arm's capsules and a scene's obstacles, prepared for [`clearance`] and
/// [`advancement`] at many configurations.
///
/// It considers the same pairs as [`super::min_distance`]: every moving link capsule against
/// every obstacle, plus the robot's self-collision pairs ([`Robot::self_pairs`]).
#[derive(Debug, Clone)]
pub struct CollisionModel {
    /// What depends on the robot alone, shared by its models in several scenes
    /// ([`CollisionModel::with_scene`]).
    arm: Arc<Arm>,
    spheres: Vec<Sphere>,
    capsules: Vec<Capsule>,
    /// Boxes and cylinders: closed forms, parry for a segment's depth inside.
    convex: Vec<Convex>,
    /// The scene's obstacles in its order, each where it is kept above.
    obstacles: Vec<ObstacleSlot>,
}

/// Where one of the scene's obstacles is kept in a [`CollisionModel`].
#[derive(Debug, Clone, Copy)]
enum ObstacleSlot {
    Sphere(usize),
    Capsule(usize),
    Convex(usize),
}

/// The arm's capsules and self pairs, prepared once per robot.
#[derive(Debug, Clone)]
struct Arm {
    chain: AlignedChain,
    links: Vec<LinkCapsule>,
    /// The capsules that move, a few of one frame at a time, each group with its bounding
    /// sphere: the broadphase that keeps the cost of a check growing with the obstacles near
    /// the arm rather than with every capsule × obstacle.
    groups: Vec<Group>,
    /// Sorted by the pair of groups, so that [`GroupPair`] ranges cover them.
    self_pairs: Vec<SelfPair>,
    /// `self_pairs`' fields the loop over all of them reads, in the same order.
    hot: Vec<HotPair>,
    group_pairs: Vec<GroupPair>,
    /// The capsules that move (not the base's), in the robot's order.
    moving: Vec<usize>,
    /// The robot's self pairs in its order ([`Robot::self_pairs`]).
    pairs_in_order: Vec<(usize, usize)>,
}

/// At most this many capsules per [`Group`], so that a check keeps their running bounds on
/// the stack.
const GROUP_SIZE: usize = 16;

// A group's members are told apart by the bits of a u32 ([`Arm::near_members`]).
const _: () = assert!(GROUP_SIZE <= 32);

/// Every member of both groups of a group pair, as [`Arm::near_members`] gives them.
const ALL_MEMBERS: (u32, u32) = (u32::MAX, u32::MAX);

/// Capsules of one moving frame (a frame with more than [`GROUP_SIZE`] has several groups).
#[derive(Debug, Clone)]
struct Group {
    frame: usize,
    /// Indices into `links`.
    members: Vec<usize>,
    /// Bounding sphere of the members (segments and radii), in the aligned frame.
    center: Vector3,
    bound: Real,
    /// The largest lever of the members per joint, so that no member moves farther.
    levers: JointVector,
}

/// The self pairs `pairs` (a range of `self_pairs`) between the capsules of two groups.
#[derive(Debug, Clone)]
struct GroupPair {
    groups: (usize, usize),
    pairs: std::ops::Range<usize>,
    /// The largest levers of those pairs.
    levers: JointVector,
    /// The smallest [`SelfPair::floor`] of those pairs (the first's: they are sorted by it).
    floor: Real,
}

/// A box or cylinder: the parry body, and what the closed forms for a point need.
#[derive(Debug, Clone)]
struct Convex {
    body: Body,
    /// {b} from the shape's own axes (a cylinder's axis is its z).
    rotation: Matrix3,
    solid: Solid,
}

#[derive(Debug, Clone, Copy)]
enum Solid {
    Cuboid { half: Vector3 },
    Cylinder { radius: Real, half_height: Real },
}

/// How close [`Convex::segment_distance`] brings its lower and upper bounds before it
/// answers with the lower (m).
const SEGMENT_TOLERANCE: Real = 1e-11;

/// Taken off every lower bound from tangents, for their rounding (m).
const ROUNDING: Real = 1e-12;

impl Convex {
    /// The signed distance from `p` to the solid (negative inside: the depth).
    #[inline]
    fn point_distance(&self, p: &Vector3) -> Real {
        self.local_point_distance(&self.local(p))
    }

    /// `frame` (an arm frame in {b}) seen from the solid's own axes about its centre: a point
    /// of the frame is placed there by one product ([`Convex::local`] of the frame's point).
    #[inline]
    fn frame_in_axes(&self, frame: &Frame) -> Frame {
        Frame {
            rotation: self.rotation.tr_mul(&frame.rotation),
            translation: self.local(&frame.translation),
        }
    }

    /// [`Convex::local_point_distance`] when below `below`, `None` when not: outside, the
    /// squared distance is compared first, so that a clear point costs no square root.
    #[inline]
    fn local_point_distance_below(&self, local: &Vector3, below: Real) -> Option<Real> {
        if let Solid::Cuboid { half } = self.solid {
            // Component by component: nalgebra's generic reductions cost several times more
            // in this, the innermost test of a collision check.
            let (x, y, z) =
                (local.x.abs() - half.x, local.y.abs() - half.y, local.z.abs() - half.z);
            let deepest = x.max(y).max(z);
            if deepest <= 0.0 {
                return (deepest < below).then_some(deepest);
            }
            let (x, y, z) = (x.max(0.0), y.max(0.0), z.max(0.0));
            let squared = x * x + y * y + z * z;
            return (below > 0.0 && squared < below * below).then(|| squared.sqrt());
        }
        Some(self.local_point_distance(local)).filter(|&distance| distance < below)
    }

    /// [`Convex::point_distance`] of a point in the solid's own axes ([`Convex::local`]).
    #[inline]
    fn local_point_distance(&self, local: &Vector3) -> Real {
        let local = *local;
        match self.solid {
            Solid::Cuboid { half } => {
                let d = local.abs() - half;
                d.sup(&Vector3::zeros()).norm() + d.max().min(0.0)
            }
            Solid::Cylinder { radius, half_height } => {
                // Square roots rather than hypot (several times slower): nothing here is near
                // overflow or underflow.
                let radial = (local.x * local.x + local.y * local.y).sqrt() - radius;
                let axial = local.z.abs() - half_height;
                let (r, z) = (radial.max(0.0), axial.max(0.0));
                (r * r + z * z).sqrt() + radial.max(axial).min(0.0)
            }
        }
    }

    /// [`Convex::point_distance`] and a subgradient of it at `p` ({b}): the signed distance
    /// to a convex solid is convex, so `d + g·(x − p)` is below it at every `x`.
    fn point_distance_gradient(&self, p: &Vector3) -> (Real, Vector3) {
        let (distance, gradient) = self.local_distance_gradient(&self.local(p));
        (distance, self.rotation * gradient)
    }

    /// The point `p` ({b}) in the solid's own axes, about its centre.
    fn local(&self, p: &Vector3) -> Vector3 {
        self.rotation.tr_mul(&(p - self.body.center))
    }

    /// [`Convex::point_distance_gradient`] of a point in the solid's own axes
    /// ([`Convex::local`]), the subgradient in those axes too.
    fn local_distance_gradient(&self, local: &Vector3) -> (Real, Vector3) {
        let sign = local.map(|x| if x < 0.0 { -1.0 } else { 1.0 });
        match self.solid {
            Solid::Cuboid { half } => {
                let d = local.abs() - half;
                let outside = d.sup(&Vector3::zeros());
                let norm = outside.norm();
                if norm > 0.0 {
                    (norm, outside.component_mul(&sign) / norm)
                } else {
                    // Inside: the nearest face's plane.
                    let k = d.imax();
                    (d[k], Vector3::ith(k, sign[k]))
                }
            }
            Solid::Cylinder { radius, half_height } => {
                let length = (local.x * local.x + local.y * local.y).sqrt();
                // On the axis any horizontal unit vector is a subgradient of the radial part.
                let out = if length > 0.0 {
                    Vector3::new(local.x / length, local.y / length, 0.0)
                } else {
                    Vector3::x()
                };
                let up = Vector3::new(0.0, 0.0, sign.z);
                let (radial, axial) = (length - radius, local.z.abs() - half_height);
                if radial > 0.0 && axial > 0.0 {
                    let d = (radial * radial + axial * axial).sqrt();
                    (d, (out * radial + up * axial) / d)
                } else if radial >= axial {
                    (radial, out)
                } else {
                    (axial, up)
                }
            }
        }
    }

    /// A lower bound of the signed distance from the segment a–b to the solid, within
    /// [`SEGMENT_TOLERANCE`] of it, if below `below`; `None` when it is not. A segment that
    /// enters the solid, or one whose bracket does not close within 64 steps, is parry's;
    /// the rest is settled in closed form ([`Convex::segment_search`]).
    fn segment_distance(&self, a: &Vector3, b: &Vector3, below: Real) -> Option<Real> {
        match self.segment_search(a, b, below) {
            Search::Settled { lower, .. } => (lower < below).then_some(lower),
            Search::Above => None,
            // The segment enters the solid, or the bracket did not close to the tolerance (a
            // secant that alternates ends near an edge or a rim shrinks it slowly): parry's
            // exact distance or depth, so that the answer is never further than the tolerance
            // below it.
            Search::Unsettled => {
                let posed = Posed::new(*a, *b, 0.0);
                posed.convex_distance(&self.body, below).filter(|&d| d < below)
            }
        }
    }

    /// The closed form of [`Convex::segment_distance`], and where along the segment it is
    /// reached.
    ///
    /// Along the segment the signed distance f(t) is convex, so the tangents at the ends of a
    /// bracket [lo, hi] of its minimum (f′(lo) < 0 < f′(hi)) meet below it: their crossing is a
    /// lower bound, the smaller end an upper one, and the crossing is where the bracket is
    /// split next (a secant step on f′). Most pairs end at the first crossing, above `below`.
    fn segment_search(&self, a: &Vector3, b: &Vector3, below: Real) -> Search {
        // In the solid's own axes: a point along the segment is then one multiply-add away,
        // and the slope a dot product in the same axes.
        let (a, along) = (self.local(a), self.rotation.tr_mul(&(b - a)));
        let at = |t: Real| {
            let (f, g) = self.local_distance_gradient(&(a + along * t));
            (f, g.dot(&along))
        };
        let ((mut f_lo, mut g_lo), (mut f_hi, mut g_hi)) = (at(0.0), at(1.0));
        let (mut lo, mut hi) = (0.0, 1.0);
        let exact = |f: Real, at: Real| {
            if f < below { Search::Settled { lower: f, at } } else { Search::Above }
        };
        // A slope that does not descend into the segment puts the minimum at an end.
        if g_lo >= 0.0 && f_lo > 0.0 {
            return exact(f_lo, 0.0);
        }
        if g_hi <= 0.0 && f_hi > 0.0 {
            return exact(f_hi, 1.0);
        }
        if let Solid::Cuboid { half } = self.solid {
            if f_lo > 0.0 && f_hi > 0.0 {
                return cuboid_search(&half, &a, &along, below);
            }
        }
        // The smallest value met, and where.
        let (mut upper, mut upper_at) = if f_lo <= f_hi { (f_lo, 0.0) } else { (f_hi, 1.0) };
        // Which end of the bracket moved last: a secant step that keeps moving the same end
        // converges slowly (as regula falsi does), so then the bracket is halved.
        let (mut moved_lo, mut halve) = (None, false);
        for _ in 0..64 {
            if upper <= 0.0 {
                break;
            }
            let width = hi - lo;
            let crossing = (f_hi - f_lo + g_lo * lo - g_hi * hi) / (g_lo - g_hi);
            let lower = (f_lo + g_lo * (crossing - lo)).min(upper) - ROUNDING;
            // Only a bound at or above zero is settled this way: below it the answer is a
            // depth, and parry's penetration depth of a segment is not the deepest point's.
            if lower >= below && below >= 0.0 {
                return Search::Above;
            }
            if upper - lower <= SEGMENT_TOLERANCE {
                return if lower < below {
                    Search::Settled { lower, at: upper_at }
                } else {
                    Search::Above
                };
            }
            if width <= Real::EPSILON {
                break;
            }
            // Kept off the ends, so that the bracket shrinks whatever the slopes.
            let t = if halve || !crossing.is_finite() {
                lo + 0.5 * width
            } else {
                crossing.clamp(lo + 0.01 * width, hi - 0.01 * width)
            };
            let (f, g) = at(t);
            if f < upper {
                (upper, upper_at) = (f, t);
            }
            if g == 0.0 && f > 0.0 {
                return exact(f, t);
            }
            let side = g < 0.0;
            if side {
                (lo, f_lo, g_lo) = (t, f, g);
            } else {
                (hi, f_hi, g_hi) = (t, f, g);
            }
            halve = moved_lo == Some(side);
            moved_lo = Some(side);
        }
        Search::Unsettled
    }
}

/// [`Convex::segment_search`] for a box of half-sides `half` and the segment from `a` along
/// `along` (both in the box's axes), both ends outside it, in closed form. The squared
/// distance Σ_i max(|a_i + t along_i| − half_i, 0)² is a convex quadratic between the (at most
/// six) t where a coordinate crosses a face's plane: each piece's minimiser is exact, and the
/// smallest of them the minimum. A segment that meets the box is parry's.
fn cuboid_search(half: &Vector3, a: &Vector3, along: &Vector3, below: Real) -> Search {
    let mut ts = [0.0; 8];
    ts[1] = 1.0;
    let mut n = 2;
    for i in 0..3 {
        if along[i] != 0.0 {
            for side in [-half[i], half[i]] {
                let t = (side - a[i]) / along[i];
                if t > 0.0 && t < 1.0 {
                    ts[n] = t;
                    n += 1;
                }
            }
        }
    }
    let ts = &mut ts[..n];
    ts.sort_unstable_by(Real::total_cmp);
    let outside = |t: Real| ((a + along * t).abs() - half).sup(&Vector3::zeros()).norm();
    let (mut best, mut best_at) = (Real::INFINITY, 0.0);
    for piece in ts.windows(2) {
        let (t0, t1) = (piece[0], piece[1]);
        // The faces each coordinate is beyond, the same over the piece: its middle's.
        let middle = a + along * (0.5 * (t0 + t1));
        let (mut num, mut den, mut beyond) = (0.0, 0.0, false);
        for i in 0..3 {
            // Beyond a face the excess is s (a_i + t along_i) − half_i, s its side's sign.
            let s = if middle[i] > half[i] {
                1.0
            } else if middle[i] < -half[i] {
                -1.0
            } else {
                continue;
            };
            beyond = true;
            num += (s * a[i] - half[i]) * s * along[i];
            den += along[i] * along[i];
        }
        if !beyond {
            // Within every slab of the box: the segment meets it.
            return Search::Unsettled;
        }
        // Beyond faces whose planes the segment runs along only: the same distance all over.
        let t = if den > 0.0 { (-num / den).clamp(t0, t1) } else { t0 };
        let f = outside(t);
        if f < best {
            (best, best_at) = (f, t);
        }
    }
    if best <= 0.0 {
        return Search::Unsettled;
    }
    // Measured at a point of the segment, so never below the minimum; the minimiser is exact
    // but for rounding, which moves the value by far less than ROUNDING.
    let lower = best - ROUNDING;
    if lower < below { Search::Settled { lower, at: best_at } } else { Search::Above }
}

/// What [`Convex::segment_search`] found.
#[derive(Debug, Clone, Copy)]
enum Search {
    /// The distance is `lower` (within [`SEGMENT_TOLERANCE`] above it), below the bound asked
    /// for, at most [`SEGMENT_TOLERANCE`] less than the solid's distance from the segment's
    /// point at fraction `at`.
    Settled { lower: Real, at: Real },
    /// Not below the bound asked for.
    Above,
    /// The segment enters the solid, or the bracket did not close: parry's to answer.
    Unsettled,
}

/// A robot capsule in its moving frame.
#[derive(Debug, Clone)]
struct LinkCapsule {
    frame: usize,
    /// Segment ends in the aligned frame (see [`AlignedChain`]).
    a: Vector3,
    b: Vector3,
    radius: Real,
    /// The midpoint of a–b (aligned frame), and the radius of the bounding sphere about it.
    center: Vector3,
    bound: Real,
    /// Whether the segment is a point (a sphere): its distances need no segment.
    point: bool,
    /// Per joint, how far any point of the segment can be from the joint's axis (m), over all
    /// configurations: the segment moves at most Σ levers_j |Δq_j| along a straight
    /// joint-space motion Δq.
    levers: JointVector,
}

/// A self-collision pair: `link` moving, `other` treated as the obstacle.
#[derive(Debug, Clone)]
struct SelfPair {
    link: usize,
    other: usize,
    /// The one of the two farther along the chain.
    distal: usize,
    /// The joints between the two frames: only they move one capsule relative to the other
    /// (the joints before both move them as one).
    joints: std::ops::Range<usize>,
    /// The distal capsule's levers for those joints, zero for the others.
    levers: JointVector,
    /// The sum of the two bounding spheres' radii.
    bounds: Real,
    /// A lower bound of the pair's signed distance at every configuration within the limits
    /// ([`floors`]); −∞ where none is known.
    floor: Real,
}

#[derive(Debug, Clone)]
struct Sphere {
    center: Vector3,
    radius: Real,
}

#[derive(Debug, Clone)]
struct Capsule {
    a: Vector3,
    b: Vector3,
    radius: Real,
}

impl CollisionModel {
    /// Prepares `robot`'s capsules against `scene`.
    pub fn new(robot: &Robot, scene: &CollisionScene) -> Self {
        Self::of(Arc::new(Arm::new(robot)), scene)
    }

    /// The same arm against `scene`: the arm's part (its capsules, self pairs and their floors,
    /// the costlier half to prepare) is shared, not built again. For a planner that meets many
    /// scenes with one robot.
    pub fn with_scene(&self, scene: &CollisionScene) -> Self {
        Self::of(Arc::clone(&self.arm), scene)
    }

    /// Whether this model was prepared for `robot`'s capsules and self pairs (not a proof: the
    /// counts and each capsule's frame and radius are compared).
    pub fn fits(&self, robot: &Robot) -> bool {
        let arm = &*self.arm;
        arm.links.len() == robot.capsules.len()
            && arm.self_pairs.len() == robot.self_pairs.len()
            && arm
                .links
                .iter()
                .zip(&robot.capsules)
                .all(|(l, c)| l.frame == c.frame && l.radius == c.radius)
    }

    fn of(arm: Arc<Arm>, scene: &CollisionScene) -> Self {
        let (mut spheres, mut capsules, mut convex) = (Vec::new(), Vec::new(), Vec::new());
        let mut obstacles = Vec::with_capacity(scene.bodies.len());
        for body in &scene.bodies {
            let slot = match body.shape {
                Core::Ball(ball) => {
                    let t = body.pose.translation;
                    spheres
                        .push(Sphere { center: Vector3::new(t.x, t.y, t.z), radius: ball.radius });
                    ObstacleSlot::Sphere(spheres.len() - 1)
                }
                Core::Segment(s) => {
                    capsules.push(Capsule {
                        a: Vector3::new(s.a.x, s.a.y, s.a.z),
                        b: Vector3::new(s.b.x, s.b.y, s.b.z),
                        radius: body.margin,
                    });
                    ObstacleSlot::Capsule(capsules.len() - 1)
                }
                Core::Cuboid(cuboid) => {
                    convex.push(Convex {
                        body: body.clone(),
                        rotation: rotation_of(&body.pose),
                        solid: Solid::Cuboid { half: from_parry(cuboid.half_extents) },
                    });
                    ObstacleSlot::Convex(convex.len() - 1)
                }
                Core::Cylinder(cylinder) => {
                    // parry's cylinder runs along its y; the closed form wants it along z.
                    let z_to_y = Rotation3::from_axis_angle(&Vector3::x_axis(), -PI / 2.0);
                    convex.push(Convex {
                        body: body.clone(),
                        rotation: rotation_of(&body.pose) * z_to_y.matrix(),
                        solid: Solid::Cylinder {
                            radius: cylinder.radius,
                            half_height: cylinder.half_height,
                        },
                    });
                    ObstacleSlot::Convex(convex.len() - 1)
                }
            };
            obstacles.push(slot);
        }
        Self { arm, spheres, capsules, convex, obstacles }
    }
}

impl Arm {
    /// Per group of `group_pair` (both moving, with bounding spheres `spheres`: centre and
    /// radius), the members (bit m: member m) that `near(gap, member's bound, other group's
    /// bound)` keeps, `gap` from the other group's centre to the member's bounding-sphere centre:
    /// a self pair with a member not kept is settled by that test. [`ALL_MEMBERS`] where the
    /// group pair has no more pairs than members, so that the tests would cost more than they
    /// save. Centres are placed through `centers`, as the pair loops do.
    fn near_members(
        &self,
        group_pair: &GroupPair,
        spheres: ((Vector3, Real), (Vector3, Real)),
        (centers, frames): (&mut Centers, &[Frame; DOF + 1]),
        near: impl Fn(Vector3, Real, Real) -> bool,
    ) -> (u32, u32) {
        let (a, b) = group_pair.groups;
        let (members_a, members_b) = (&self.groups[a].members, &self.groups[b].members);
        if group_pair.pairs.len() <= members_a.len() + members_b.len() {
            return ALL_MEMBERS;
        }
        let mut mask = |members: &[usize], (center, bound): (Vector3, Real)| {
            let mut bits = 0;
            for (m, &i) in members.iter().enumerate() {
                let gap = centers.get(i, &self.links, frames) - center;
                if near(gap, self.links[i].bound, bound) {
                    bits |= 1 << m;
                }
            }
            bits
        };
        (mask(members_a, spheres.1), mask(members_b, spheres.0))
    }

    fn new(robot: &Robot) -> Self {
        let last = robot.capsules.iter().map(|c| c.frame).max().unwrap_or(0);
        let chain = AlignedChain::new(robot, last);
        let links: Vec<LinkCapsule> = robot
            .capsules
            .iter()
            .map(|c| {
                let (a, b) = (
                    chain.aligned_from_frame[c.frame] * c.a,
                    chain.aligned_from_frame[c.frame] * c.b,
                );
                LinkCapsule {
                    frame: c.frame,
                    a,
                    b,
                    radius: c.radius,
                    center: 0.5 * (a + b),
                    bound: 0.5 * (b - a).norm() + c.radius,
                    point: a == b,
                    levers: levers(robot, c.frame, &c.a, &c.b),
                }
            })
            .collect();
        let mut groups: Vec<Group> = Vec::new();
        for (i, capsule) in robot.capsules.iter().enumerate() {
            if capsule.role == LinkRole::Base {
                continue;
            }
            match groups
                .iter_mut()
                .find(|g| g.frame == capsule.frame && g.members.len() < GROUP_SIZE)
            {
                Some(group) => group.members.push(i),
                None => groups.push(Group {
                    frame: capsule.frame,
                    members: vec![i],
                    center: Vector3::zeros(),
                    bound: 0.0,
                    levers: JointVector::zeros(),
                }),
            }
        }
        for group in &mut groups {
            let ends = || group.members.iter().flat_map(|&i| [&links[i].a, &links[i].b]);
            let count = 2.0 * group.members.len() as Real;
            group.center = ends().sum::<Vector3>() / count;
            group.bound = group
                .members
                .iter()
                .map(|&i| {
                    let l = &links[i];
                    (l.a - group.center).norm().max((l.b - group.center).norm()) + l.radius
                })
                .fold(0.0, Real::max);
            group.levers =
                group.members.iter().fold(JointVector::zeros(), |m, &i| m.sup(&links[i].levers));
        }
        let mut self_pairs: Vec<SelfPair> = robot
            .self_pairs
            .iter()
            .map(|&(link, other)| {
                let (f, g) = (links[link].frame, links[other].frame);
                let distal = if f >= g { link } else { other };
                let joints = f.min(g)..f.max(g);
                let levers = JointVector::from_fn(|j, _| {
                    if joints.contains(&j) { links[distal].levers[j] } else { 0.0 }
                });
                let bounds = links[link].bound + links[other].bound;
                SelfPair { link, other, distal, joints, levers, bounds, floor: Real::NEG_INFINITY }
            })
            .collect();
        let floors = floors(robot, &chain, &links, &self_pairs);
        for (pair, floor) in self_pairs.iter_mut().zip(floors) {
            pair.floor = floor;
        }
        // Looked up once per capsule: the sort below asks for it at every comparison.
        let mut groups_of: Vec<Option<usize>> = vec![None; links.len()];
        for (g, group) in groups.iter().enumerate() {
            for &i in &group.members {
                groups_of[i] = Some(g);
            }
        }
        let group_of = |capsule: usize| groups_of[capsule];
        let mut slot_of = vec![0; links.len()];
        for group in &groups {
            for (m, &i) in group.members.iter().enumerate() {
                slot_of[i] = m;
            }
        }
        // A base capsule never moves: it has no group, and stands for itself. Within a pair of
        // groups the lowest floor first, so that a check stops at the first floor too high.
        let key = |pair: &SelfPair| (group_of(pair.link), group_of(pair.other));
        // Indices sorted, then the pairs moved once: a pair is large to move.
        let keys: Vec<_> = self_pairs.iter().map(key).collect();
        let mut order: Vec<usize> = (0..self_pairs.len()).collect();
        order.sort_by(|&k, &l| {
            let (p, r) = (&self_pairs[k], &self_pairs[l]);
            (keys[k].cmp(&keys[l]))
                .then(p.floor.total_cmp(&r.floor))
                .then((p.link, p.other).cmp(&(r.link, r.other)))
        });
        let self_pairs: Vec<SelfPair> = order.iter().map(|&k| self_pairs[k].clone()).collect();
        let mut group_pairs: Vec<GroupPair> = Vec::new();
        for (k, pair) in self_pairs.iter().enumerate() {
            let (a, b) = key(pair);
            let groups = (a.unwrap_or(usize::MAX), b.unwrap_or(usize::MAX));
            match group_pairs.last_mut() {
                Some(last) if last.groups == groups => {
                    last.pairs.end = k + 1;
                    last.levers = last.levers.sup(&pair.levers);
                }
                _ => group_pairs.push(GroupPair {
                    groups,
                    pairs: k..k + 1,
                    levers: pair.levers,
                    floor: pair.floor,
                }),
            }
        }
        let hot = self_pairs
            .iter()
            .map(|p| HotPair {
                link: p.link,
                other: p.other,
                slots: (slot_of[p.link], slot_of[p.other]),
                distal: p.distal,
                start: p.joints.start,
                bounds: p.bounds,
                floor: p.floor,
                points: links[p.link].point && links[p.other].point,
            })
            .collect();
        let moving = (0..robot.capsules.len())
            .filter(|&i| robot.capsules[i].role != LinkRole::Base)
            .collect();
        let pairs_in_order = robot.self_pairs.clone();
        Self { chain, links, groups, self_pairs, hot, group_pairs, moving, pairs_in_order }
    }
}

/// The smallest signed distance (m, negative for a penetration) over the pairs of
/// [`super::min_distance`] with the arm at `q`; ∞ when there is no pair.
pub fn clearance(model: &CollisionModel, q: &JointVector) -> Real {
    model.smallest(q, 0.0, None, Real::NEG_INFINITY, Real::INFINITY)
}

/// How far the arm at `q` can move along the straight joint-space motion `dq`, either way,
/// while keeping `clearance` (m) from the scene and between the self-collision pairs: every
/// configuration q ± s·dq with s up to the result keeps it.
///
/// Conservative advancement. A point p of a capsule moves at the speed Σ_j |dq_j| r_j, r_j its
/// distance from joint j's axis: at most the lever bounding r_j over all configurations, and
/// near q at most r_j(q) plus what the joints after j have moved p since, so p moves at most
/// min(Σ lever_j |dq_j| s, Σ r_j(q) |dq_j| s + Σ_{k>j} lever_k |dq_k| |dq_j| s² / 2) over s.
/// An obstacle stands still, and the capsules of a self pair move relative to each other only
/// by the joints between them; a pair at distance d keeps the clearance until that motion
/// reaches d − clearance. Negative when some pair is already closer than `clearance`; ∞ when
/// no pair can approach.
pub fn advancement(
    model: &CollisionModel,
    q: &JointVector,
    dq: &JointVector,
    clearance: Real,
) -> Real {
    model.smallest(q, clearance, Some(&dq.abs()), Real::NEG_INFINITY, Real::INFINITY)
}

/// [`advancement`] if it is at least `least`, else `None`: a check that only needs to know
/// whether the arm can move that far stops at the first pair that says no.
pub fn advancement_at_least(
    model: &CollisionModel,
    q: &JointVector,
    dq: &JointVector,
    clearance: Real,
    least: Real,
) -> Option<Real> {
    advancement_within(model, q, dq, clearance, least, Real::INFINITY)
}

/// [`advancement_at_least`] capped at `enough`: the smaller of the advancement and `enough`
/// if that is at least `least`. A check that has no use for more than `enough` (an edge
/// check covering a stretch of that half-length) leaves out every pair that cannot come
/// that near, which is most of them.
pub fn advancement_within(
    model: &CollisionModel,
    q: &JointVector,
    dq: &JointVector,
    clearance: Real,
    least: Real,
    enough: Real,
) -> Option<Real> {
    let found = model.smallest(q, clearance, Some(&dq.abs()), least, enough);
    (found >= least).then_some(found)
}

/// The farthest any point of the arm's capsule segments moves along the straight joint-space
/// motion `dq` (m), from any configuration.
pub fn motion_bound(model: &CollisionModel, dq: &JointVector) -> Real {
    let dq = dq.abs();
    model.arm.links.iter().map(|l| l.levers.dot(&dq)).fold(0.0, Real::max)
}

/// The farthest a capsule of a self pair moves relative to the other along the straight
/// joint-space motion `dq` (m), from any configuration: at most [`motion_bound`], and less
/// where the pairs span few joints (0 with no self pairs).
pub fn self_motion_bound(model: &CollisionModel, dq: &JointVector) -> Real {
    let speed = dq.abs();
    // A group pair's levers are its pairs' largest per joint, which may bound more than any
    // one capsule moves; a pair's relative motion is its distal capsule's over some joints.
    let pairs = model.arm.group_pairs.iter().map(|p| p.levers.dot(&speed)).fold(0.0, Real::max);
    pairs.min(motion_bound(model, dq))
}

impl CollisionModel {
    /// The smallest `reach(d − offset)` over the pairs, at most `enough`, d the signed
    /// distance of a pair and `reach` the advancement its [`Motion`] along `speed` (|dq|)
    /// allows; with no motion, the smallest d − offset. Stops below `least`.
    fn smallest(
        &self,
        q: &JointVector,
        offset: Real,
        speed: Option<&JointVector>,
        least: Real,
        enough: Real,
    ) -> Real {
        let frames = self.arm.chain.frames(q);
        // The configuration-independent motion bound first: cheap, and never below the
        // configuration's own, so it tells which pairs cannot lower `best`; the
        // configuration's own only for the nearest obstacle of a capsule that may.
        let loose =
            |levers: &JointVector| speed.map_or(Motion::UNIT, |s| Motion::at_most(levers.dot(s)));
        let exact = |link: &Posed, levers: &JointVector, joints: std::ops::Range<usize>| {
            speed.map_or(Motion::UNIT, |speed| Motion::new(&frames, link, levers, speed, joints))
        };
        let mut best = enough;
        for group in &self.arm.groups {
            let frame = &frames[group.frame];
            let center = frame.apply(&group.center);
            // Obstacles whose distance from the group's bounding sphere is this or more
            // cannot lower `best` through any member.
            let near = offset + loose(&group.levers).threshold(best);
            let n = group.members.len();
            let mut posed: [Option<Posed>; GROUP_SIZE] = Default::default();
            // Per member: only distances (between its segment and an obstacle's core) below
            // `below` may lower `best`; it falls to the nearest found. `found`: an obstacle
            // was found below the bound (without one the member cannot lower `best`, and the
            // bound itself is no distance: rounded, it can even put a capsule that cannot move
            // a hair inside the clearance).
            let mut below = [0.0; GROUP_SIZE];
            let mut found = [false; GROUP_SIZE];
            for (m, &i) in group.members.iter().enumerate() {
                let capsule = &self.arm.links[i];
                below[m] = offset + loose(&capsule.levers).threshold(best) + capsule.radius;
            }
            // Members are placed when an obstacle first comes near the group.
            let place = |m: usize| self.arm.links[group.members[m]].posed(&frames);
            for sphere in &self.spheres {
                if (center - sphere.center).norm() - group.bound - sphere.radius >= near {
                    continue;
                }
                for m in 0..n {
                    let reach = below[m] + sphere.radius;
                    if reach > 0.0 {
                        let squared = posed[m]
                            .get_or_insert_with(|| place(m))
                            .squared_distance_to_point(&sphere.center);
                        if squared < reach * reach {
                            below[m] = squared.sqrt() - sphere.radius;
                            found[m] = true;
                        }
                    }
                }
            }
            for capsule in &self.capsules {
                let gap = (center - 0.5 * (capsule.a + capsule.b)).norm()
                    - group.bound
                    - 0.5 * (capsule.b - capsule.a).norm()
                    - capsule.radius;
                if gap >= near {
                    continue;
                }
                for m in 0..n {
                    let reach = below[m] + capsule.radius;
                    if reach > 0.0 {
                        let link = posed[m].get_or_insert_with(|| place(m));
                        let distance =
                            segment_segment_distance(&link.a, &link.b, &capsule.a, &capsule.b);
                        if distance < reach {
                            below[m] = distance - capsule.radius;
                            found[m] = true;
                        }
                    }
                }
            }
            for convex in &self.convex {
                let body = &convex.body;
                // The bounding spheres first, then the solid's own distance from the group's
                // centre: a long thin shelf's bounding sphere says little.
                if (center - body.center).norm() - group.bound - body.bound >= near
                    || convex.point_distance(&center) - group.bound >= near
                {
                    continue;
                }
                // The group's frame in the solid's axes, where its spheres are placed directly.
                let mut in_axes: Option<Frame> = None;
                for m in 0..n {
                    let capsule = &self.arm.links[group.members[m]];
                    if capsule.point {
                        let frame = in_axes
                            .get_or_insert_with(|| convex.frame_in_axes(&frames[group.frame]));
                        let local = frame.apply(&capsule.a);
                        if let Some(distance) = convex.local_point_distance_below(&local, below[m])
                        {
                            below[m] = distance;
                            found[m] = true;
                        }
                        continue;
                    }
                    let link = posed[m].get_or_insert_with(|| place(m));
                    let gap = (link.center - body.center).norm() - link.bound - body.bound;
                    if gap >= below[m] - link.radius {
                        continue;
                    }
                    let half_length = link.bound - link.radius;
                    let distance = if link.inverse_squared_length == 0.0 {
                        // A sphere: the exact point distance.
                        Some(convex.point_distance(&link.a))
                    } else if convex.point_distance(&link.center) - half_length >= below[m] {
                        continue;
                    } else {
                        convex.segment_distance(&link.a, &link.b, below[m])
                    };
                    if let Some(distance) = distance {
                        if distance < below[m] {
                            below[m] = distance;
                            found[m] = true;
                        }
                    }
                }
            }
            for m in 0..n {
                if !found[m] {
                    continue;
                }
                let capsule = &self.arm.links[group.members[m]];
                let slack = below[m] - capsule.radius - offset;
                if loose(&capsule.levers).reach(slack) < best {
                    let link = posed[m].get_or_insert_with(|| place(m));
                    best = best.min(exact(link, &capsule.levers, 0..capsule.frame).reach(slack));
                    if best < least {
                        return best;
                    }
                }
            }
        }
        // A capsule is in many self pairs: its bounding sphere's centre placed once, and the
        // capsule itself once, only for a pair the bounding spheres do not settle.
        let mut centers = Centers::new();
        let rates = speed.map(|speed| Rates::new(&self.arm.links, speed));
        let mut placed = Placed::new();
        let bounding = |group: usize| {
            self.arm.groups.get(group).map(|g| (frames[g.frame].apply(&g.center), g.bound))
        };
        for group_pair in &self.arm.group_pairs {
            let loose_pair = loose(&group_pair.levers);
            // A pair whose floor is this high cannot lower `best`: its slack is at least the
            // floor's, and its own rate is at most the group pair's, which can only raise a
            // positive threshold (at or below zero a faster motion lowers it: no cut there).
            let floor_limit = |best: Real| {
                if best > 0.0 { loose_pair.threshold(best) + offset } else { Real::INFINITY }
            };
            let mut limit = floor_limit(best);
            if group_pair.floor >= limit {
                continue;
            }
            // A member far from the other group's whole bounding sphere cannot lower `best`.
            let mut near = ALL_MEMBERS;
            let (a, b) = group_pair.groups;
            if let (Some(sphere_a), Some(sphere_b)) = (bounding(a), bounding(b)) {
                let threshold = loose_pair.threshold(best);
                if (sphere_a.0 - sphere_b.0).norm() - sphere_a.1 - sphere_b.1 - offset >= threshold
                {
                    continue;
                }
                near = self.arm.near_members(
                    group_pair,
                    (sphere_a, sphere_b),
                    (&mut centers, &frames),
                    |gap, member, other| {
                        // A NaN threshold keeps the member: the pair loop decides.
                        let far = gap.norm() - member - other - offset >= threshold;
                        !far
                    },
                );
                if near.0 == 0 || near.1 == 0 {
                    continue;
                }
            }
            for (k, pair) in self.arm.hot[group_pair.pairs.clone()].iter().enumerate() {
                // Sorted by floor: the rest are higher still.
                if pair.floor >= limit {
                    break;
                }
                if !pair.among(near) {
                    continue;
                }
                let levers = || &self.arm.self_pairs[group_pair.pairs.start + k].levers;
                let loose = match (speed, &rates) {
                    (Some(_), Some(rates)) if pair.distal < Rates::CAPACITY => {
                        Motion::at_most(rates.rate(pair.distal, pair.start))
                    }
                    _ => loose(levers()),
                };
                // Only bounding spheres closer than this (centre to centre) may lower `best`;
                // compared squared, so that most pairs cost no square root.
                let reach = loose.threshold(best) + offset + pair.bounds;
                if reach.is_nan() || reach <= 0.0 {
                    continue;
                }
                let gap = centers.get(pair.link, &self.arm.links, &frames)
                    - centers.get(pair.other, &self.arm.links, &frames);
                if gap.norm_squared() >= reach * reach {
                    continue;
                }
                let link = placed.get(pair.link, &self.arm.links, &frames);
                let other = placed.get(pair.other, &self.arm.links, &frames);
                let moved = if pair.distal == pair.link { &link } else { &other };
                let slack = link.distance(&other) - offset;
                if loose.reach(slack) < best {
                    let joints = pair.start..self.arm.links[pair.distal].frame;
                    let exact = exact(moved, levers(), joints);
                    best = best.min(exact.reach(slack));
                    if best < least {
                        return best;
                    }
                    limit = floor_limit(best);
                }
            }
        }
        best
    }
}

/// Per capsule (the first [`Rates::CAPACITY`]) and first joint s, Σ_{j≥s} lever_j |dq_j|: the
/// configuration-independent rate of a self pair whose distal capsule it is and whose joints
/// start at s (its levers are the distal's from s on, and a capsule's are zero past its frame),
/// for every pair at the cost of one table per query. Raised by a few units in the last place,
/// so that a rate summed in another order than the pair's own dot product is never below it:
/// a pair is then left out only where the dot product would leave it out.
struct Rates {
    suffix: [[Real; DOF]; Self::CAPACITY],
}

impl Rates {
    const CAPACITY: usize = 64;

    /// Over 16 terms of one sign, rounding moves a sum by far less than this.
    const RAISE: Real = 1.0 + 64.0 * Real::EPSILON;

    fn new(links: &[LinkCapsule], speed: &JointVector) -> Self {
        let mut suffix = [[0.0; DOF]; Self::CAPACITY];
        for (rates, link) in suffix.iter_mut().zip(links) {
            let mut sum = 0.0;
            for j in (0..DOF).rev() {
                sum += link.levers[j] * speed[j];
                rates[j] = sum * Self::RAISE;
            }
        }
        Self { suffix }
    }

    fn rate(&self, distal: usize, start: usize) -> Real {
        self.suffix[distal][start]
    }
}

/// What the self-pair loop reads of every pair, packed apart from the levers and joints that
/// only the pairs the bounding spheres do not settle need (a third of a [`SelfPair`]'s bytes).
#[derive(Debug, Clone, Copy)]
struct HotPair {
    link: usize,
    other: usize,
    /// Where `link` and `other` are among their groups' members ([`Group::members`]; 0 for a
    /// base capsule, which has no group).
    slots: (usize, usize),
    distal: usize,
    /// The first joint between the two frames.
    start: usize,
    bounds: Real,
    floor: Real,
    /// Both capsules are points: the distance of their bounding spheres (`bounds` apart) is
    /// theirs.
    points: bool,
}

/// The first [`Placed::CAPACITY`] capsules placed at most once per query, on the stack; the
/// others (a model of more) placed at each use.
struct Placed {
    slots: [Option<Posed>; Self::CAPACITY],
}

impl Placed {
    const CAPACITY: usize = 64;

    fn new() -> Self {
        Self { slots: std::array::from_fn(|_| None) }
    }

    fn get(&mut self, i: usize, links: &[LinkCapsule], frames: &[Frame; DOF + 1]) -> Posed {
        match self.slots.get_mut(i) {
            Some(slot) => *slot.get_or_insert_with(|| links[i].posed(frames)),
            None => links[i].posed(frames),
        }
    }
}

/// The centres of the first [`Centers::CAPACITY`] capsules' bounding spheres placed at most
/// once per query, on the stack; the others (a model of more) placed at each use.
struct Centers {
    placed: u64,
    slots: [Vector3; Self::CAPACITY],
}

impl HotPair {
    /// Whether both capsules of the pair are among the members `near` keeps
    /// ([`Arm::near_members`]).
    fn among(&self, near: (u32, u32)) -> bool {
        near.0 & (1 << self.slots.0) != 0 && near.1 & (1 << self.slots.1) != 0
    }
}

impl Centers {
    const CAPACITY: usize = 64;

    fn new() -> Self {
        Self { placed: 0, slots: [Vector3::zeros(); Self::CAPACITY] }
    }

    #[inline]
    fn get(&mut self, i: usize, links: &[LinkCapsule], frames: &[Frame; DOF + 1]) -> Vector3 {
        let place = || frames[links[i].frame].apply(&links[i].center);
        if i >= Self::CAPACITY {
            return place();
        }
        if self.placed & (1 << i) == 0 {
            self.slots[i] = place();
            self.placed |= 1 << i;
        }
        self.slots[i]
    }
}

/// Grid points per joint of [`floors`], for pairs one joint apart and two.
const FLOOR_GRID: [usize; 2] = [48, 12];

/// Per self pair, a lower bound of its signed distance at every configuration within the
/// limits, for the pairs one or two joints move relative to each other (−∞ for the others, and
/// where a limit is not finite): the smallest distance on a grid of cell centres, less the
/// farthest the distal capsule can move from a centre within its cell (Σ lever_j h_j/2, the
/// configuration-independent motion bound of [`Motion`]). The joints before both move the two
/// as one, so any values of them serve; the frames of a grid point are shared by every pair
/// of its joints.
fn floors(
    robot: &Robot,
    chain: &AlignedChain,
    links: &[LinkCapsule],
    pairs: &[SelfPair],
) -> Vec<Real> {
    let mut floors = vec![Real::NEG_INFINITY; pairs.len()];
    let (lower, upper) = (robot.lower(), robot.upper());
    let mut ranges: Vec<(usize, usize)> = pairs
        .iter()
        .filter(|p| (1..=FLOOR_GRID.len()).contains(&p.joints.len()))
        .map(|p| (p.joints.start, p.joints.end))
        .collect();
    ranges.sort_unstable();
    ranges.dedup();
    for (start, end) in ranges {
        let members: Vec<usize> =
            (0..pairs.len()).filter(|&k| pairs[k].joints == (start..end)).collect();
        let n = FLOOR_GRID[end - start - 1];
        let width = |j: usize| (upper[j] - lower[j]) / n as Real;
        if (start..end).any(|j| !width(j).is_finite()) {
            continue;
        }
        // The capsules of these pairs, placed once per cell, and each pair's two slots.
        let mut used: Vec<usize> =
            members.iter().flat_map(|&k| [pairs[k].link, pairs[k].other]).collect();
        used.sort_unstable();
        used.dedup();
        let slot = |i: usize| used.partition_point(|&u| u < i);
        let slots: Vec<(usize, usize)> =
            members.iter().map(|&k| (slot(pairs[k].link), slot(pairs[k].other))).collect();
        let mut posed: Vec<Posed> = Vec::with_capacity(used.len());
        let mut q = crate::robot::home(&robot.joints);
        let mut smallest = vec![Real::INFINITY; members.len()];
        for cell in 0..n.pow((end - start) as u32) {
            let mut rest = cell;
            for j in start..end {
                q[j] = lower[j] + ((rest % n) as Real + 0.5) * width(j);
                rest /= n;
            }
            let frames = chain.frames(&q);
            posed.clear();
            posed.extend(used.iter().map(|&i| links[i].posed(&frames)));
            for (least, &(a, b)) in smallest.iter_mut().zip(&slots) {
                *least = least.min(posed[a].distance(&posed[b]));
            }
        }
        for (m, &k) in members.iter().enumerate() {
            let within_cell: Real = (start..end).map(|j| pairs[k].levers[j] * 0.5 * width(j)).sum();
            floors[k] = smallest[m] - within_cell - ROUNDING;
        }
    }
    floors
}

/// {b} from a parry pose's axes.
fn rotation_of(pose: &Pose) -> Matrix3 {
    let r = pose.rotation;
    Matrix3::from_columns(&[
        from_parry(r * Vector::X),
        from_parry(r * Vector::Y),
        from_parry(r * Vector::Z),
    ])
}

/// A bound on how far the points of a capsule (or of one capsule relative to another) move
/// over s units of a joint-space motion: min(bound·s, linear·s + quadratic·s²/2).
#[derive(Debug, Clone, Copy)]
struct Motion {
    bound: Real,
    linear: Real,
    quadratic: Real,
}

impl Motion {
    /// The distance itself: s is in metres.
    const UNIT: Self = Self::at_most(1.0);

    /// Never more than `rate` per unit of s.
    const fn at_most(rate: Real) -> Self {
        Self { bound: rate, linear: rate, quadratic: 0.0 }
    }

    /// The motion of the segment `link` (posed at `frames`, with `levers` bounding its
    /// distances from the joint axes) by the `joints` given, at joint speeds `speed` (|dq|).
    fn new(
        frames: &[Frame; DOF + 1],
        link: &Posed,
        levers: &JointVector,
        speed: &JointVector,
        joints: std::ops::Range<usize>,
    ) -> Self {
        let (mut bound, mut linear, mut quadratic, mut before) = (0.0, 0.0, 0.0, 0.0);
        for j in joints {
            // Joint j turns about the z of aligned frame j+1, through its origin.
            let axis = &frames[j + 1];
            let off_axis = |p: &Vector3| {
                let r = p - axis.translation;
                let along = r.dot(&axis.rotation.column(2));
                r.norm_squared() - along * along
            };
            let r = off_axis(&link.a).max(off_axis(&link.b)).max(0.0).sqrt();
            bound += levers[j] * speed[j];
            linear += r * speed[j];
            // What the joints before j add to their distance from their axes as j turns.
            quadratic += levers[j] * speed[j] * before;
            before += speed[j];
        }
        Self { bound, linear, quadratic }
    }

    /// The largest s whose motion stays within `slack` (m): negative for a negative slack,
    /// ∞ when nothing moves.
    fn reach(&self, slack: Real) -> Real {
        if self.bound <= 0.0 {
            return if slack >= 0.0 { Real::INFINITY } else { Real::NEG_INFINITY };
        }
        if slack <= 0.0 {
            return slack / self.bound;
        }
        let curved = 2.0 * slack
            / (self.linear + (self.linear * self.linear + 2.0 * self.quadratic * slack).sqrt());
        curved.max(slack / self.bound)
    }

    /// The slack below which [`Motion::reach`] is below `s`.
    fn threshold(&self, s: Real) -> Real {
        if s == Real::NEG_INFINITY {
            Real::NEG_INFINITY
        } else if self.bound <= 0.0 {
            0.0
        } else if s <= 0.0 {
            s * self.bound
        } else if s == Real::INFINITY {
            Real::INFINITY
        } else {
            (self.bound * s).min(self.linear * s + 0.5 * self.quadratic * s * s)
        }
    }
}

/// Per joint, a bound on the distance of the segment a–b (in moving frame `frame`) from the
/// joint's axis over all configurations. Joint j turns frames j+1..; its axis passes through
/// the origin of frame j+1, and from there to frame `frame`'s origin are at most the joint
/// offsets between. The last joint before the frame turns it about the axis itself, so there
/// the exact distance from the axis is used.
fn levers(robot: &Robot, frame: usize, a: &Vector3, b: &Vector3) -> JointVector {
    let offsets: Vec<Real> =
        robot.joints.iter().map(|j| j.parent_from_joint.translation.vector.norm()).collect();
    let reach = a.norm().max(b.norm());
    JointVector::from_fn(|j, _| {
        if j + 1 > frame {
            0.0
        } else if j + 1 == frame {
            let axis = robot.joints[j].axis;
            let off_axis = |p: &Vector3| (p - axis * axis.dot(p)).norm();
            off_axis(a).max(off_axis(b))
        } else {
            offsets[j + 1..frame].iter().sum::<Real>() + reach
        }
    })
}

/// A capsule placed in {b}, with its bounding sphere.
#[derive(Debug, Clone, Copy)]
struct Posed {
    a: Vector3,
    b: Vector3,
    radius: Real,
    /// b − a, and the inverse of its squared length (0 for a point).
    along: Vector3,
    inverse_squared_length: Real,
    center: Vector3,
    bound: Real,
}

impl LinkCapsule {
    fn posed(&self, frames: &[Frame; DOF + 1]) -> Posed {
        let frame = &frames[self.frame];
        Posed::new(frame.apply(&self.a), frame.apply(&self.b), self.radius)
    }
}

impl Posed {
    fn new(a: Vector3, b: Vector3, radius: Real) -> Self {
        let along = b - a;
        let squared_length = along.norm_squared();
        Self {
            a,
            b,
            radius,
            along,
            inverse_squared_length: if squared_length > Real::MIN_POSITIVE {
                1.0 / squared_length
            } else {
                0.0
            },
            center: 0.5 * (a + b),
            bound: 0.5 * squared_length.sqrt() + radius,
        }
    }

    /// Signed distance to another capsule.
    fn distance(&self, other: &Posed) -> Real {
        // Two spheres (most pairs of a spherised arm): the distance of the centres, the bits
        // `segment_segment_distance` gives for two points (it takes s = t = 0 on the same
        // test of the squared lengths), without its branches.
        let core = if self.inverse_squared_length == 0.0 && other.inverse_squared_length == 0.0 {
            (self.a - other.a).norm()
        } else {
            segment_segment_distance(&self.a, &self.b, &other.a, &other.b)
        };
        core - self.radius - other.radius
    }

    /// The squared distance from the segment to `p`.
    fn squared_distance_to_point(&self, p: &Vector3) -> Real {
        let from_a = p - self.a;
        let t = (from_a.dot(&self.along) * self.inverse_squared_length).clamp(0.0, 1.0);
        (from_a - self.along * t).norm_squared()
    }

    /// The distance from the segment to a parry body, if below `below`.
    fn convex_distance(&self, body: &Body, below: Real) -> Option<Real> {
        let segment = Segment::new(to_parry(&self.a), to_parry(&self.b));
        // Without a bound, far enough to always find the pair: the farthest two points of
        // the bounding spheres.
        let reach = (self.center - body.center).norm() + self.bound + body.bound + 1.0;
        let prediction = below.clamp(0.0, reach);
        let contact =
            query::contact(&body.pose, body.shape.as_dyn(), &Pose::IDENTITY, &segment, prediction);
        // Every pair of shapes here is supported by parry's default dispatcher.
        contact.ok().flatten().map(|c| c.dist)
    }
}

#[cfg(test)]
mod tests;
