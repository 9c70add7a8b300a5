//! [`CollisionModel`]: the arm's capsules and a scene prepared once for queries at many
//! configurations, without allocating: closed-form capsule–sphere and capsule–capsule
//! distances, parry only for boxes and cylinders.

use parry3d_f64::math::Pose;
use parry3d_f64::query;
use parry3d_f64::shape::Segment;

use super::{Body, CollisionScene, Core, self_pairs, to_parry};
use crate::math::{DOF, JointVector, Matrix3, PI, Real, Rotation3, Vector3};
use crate::robot::{LinkRole, Robot};

/// The arm's capsules and a scene's obstacles, prepared for [`clearance`] and
/// [`advancement`] at many configurations.
///
/// It considers the same pairs as [`super::min_distance`]: every moving link capsule against
/// every obstacle, plus [`self_pairs`].
#[derive(Debug, Clone)]
pub struct CollisionModel {
    chain: Chain,
    links: Vec<LinkCapsule>,
    /// Indices into `links` of the capsules that move.
    moving: Vec<usize>,
    spheres: Vec<Sphere>,
    capsules: Vec<Capsule>,
    /// Boxes and cylinders, through parry.
    convex: Vec<Body>,
    self_pairs: Vec<SelfPair>,
}

/// A robot capsule in its moving frame.
#[derive(Debug, Clone)]
struct LinkCapsule {
    frame: usize,
    /// Segment ends in the aligned frame (see [`Chain`]).
    a: Vector3,
    b: Vector3,
    radius: Real,
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
        let last = robot.capsules.iter().map(|c| c.frame).max().unwrap_or(0);
        let chain = Chain::new(robot, last);
        let links: Vec<LinkCapsule> = robot
            .capsules
            .iter()
            .map(|c| LinkCapsule {
                frame: c.frame,
                a: chain.aligned_from_frame[c.frame] * c.a,
                b: chain.aligned_from_frame[c.frame] * c.b,
                radius: c.radius,
                levers: levers(robot, c.frame, &c.a, &c.b),
            })
            .collect();
        let role = |i: usize| robot.capsules[i].role;
        let moving = (0..links.len()).filter(|&i| role(i) != LinkRole::Base).collect();
        let count = links.len();
        let with_role = move |r: LinkRole| (0..count).filter(move |&i| role(i) == r);
        let self_pairs = self_pairs()
            .iter()
            .flat_map(|&(moving, against)| {
                with_role(moving).flat_map(move |i| with_role(against).map(move |j| (i, j)))
            })
            .map(|(link, other)| {
                let (f, g) = (links[link].frame, links[other].frame);
                let distal = if f >= g { link } else { other };
                let joints = f.min(g)..f.max(g);
                let levers = JointVector::from_fn(|j, _| {
                    if joints.contains(&j) { links[distal].levers[j] } else { 0.0 }
                });
                SelfPair { link, other, distal, joints, levers }
            })
            .collect();
        let (mut spheres, mut capsules, mut convex) = (Vec::new(), Vec::new(), Vec::new());
        for body in &scene.bodies {
            match body.shape {
                Core::Ball(ball) => {
                    let t = body.pose.translation;
                    spheres
                        .push(Sphere { center: Vector3::new(t.x, t.y, t.z), radius: ball.radius })
                }
                Core::Segment(s) => capsules.push(Capsule {
                    a: Vector3::new(s.a.x, s.a.y, s.a.z),
                    b: Vector3::new(s.b.x, s.b.y, s.b.z),
                    radius: body.margin,
                }),
                Core::Cuboid(_) | Core::Cylinder(_) => convex.push(body.clone()),
            }
        }
        Self { chain, links, moving, spheres, capsules, convex, self_pairs }
    }
}

/// The smallest signed distance (m, negative for a penetration) over the pairs of
/// [`super::min_distance`] with the arm at `q`; ∞ when there is no pair.
pub fn clearance(model: &CollisionModel, q: &JointVector) -> Real {
    model.smallest(q, 0.0, None, Real::NEG_INFINITY)
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
    model.smallest(q, clearance, Some(&dq.abs()), Real::NEG_INFINITY)
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
    let found = model.smallest(q, clearance, Some(&dq.abs()), least);
    (found >= least).then_some(found)
}

/// The farthest any point of the arm's capsule segments moves along the straight joint-space
/// motion `dq` (m), from any configuration.
pub fn motion_bound(model: &CollisionModel, dq: &JointVector) -> Real {
    let dq = dq.abs();
    model.links.iter().map(|l| l.levers.dot(&dq)).fold(0.0, Real::max)
}

impl CollisionModel {
    /// The smallest `reach(d − offset)` over the pairs, d the signed distance of a pair and
    /// `reach` the advancement its [`Motion`] along `speed` (|dq|) allows; with no motion,
    /// the smallest d − offset.
    fn smallest(
        &self,
        q: &JointVector,
        offset: Real,
        speed: Option<&JointVector>,
        least: Real,
    ) -> Real {
        let frames = self.chain.frames(q);
        // The configuration-independent motion bound first: cheap, and never below the
        // configuration's own, so it tells which pairs cannot lower `best`; the
        // configuration's own only for the nearest obstacle of a capsule that may.
        let loose =
            |levers: &JointVector| speed.map_or(Motion::UNIT, |s| Motion::at_most(levers.dot(s)));
        let exact = |link: &Posed, levers: &JointVector, joints: std::ops::Range<usize>| {
            speed.map_or(Motion::UNIT, |speed| Motion::new(&frames, link, levers, speed, joints))
        };
        let mut best = Real::INFINITY;
        for &i in &self.moving {
            let capsule = &self.links[i];
            let link = capsule.posed(&frames);
            // Only distances (between the segment and an obstacle's core) below this may lower
            // `best`; it falls to the nearest found.
            let mut below = offset + loose(&capsule.levers).threshold(best) + link.radius;
            // Whether an obstacle was found below the bound: without one, the capsule cannot
            // lower `best`, and the bound itself is no distance (rounded, it can even put a
            // capsule that cannot move a hair inside the clearance).
            let mut found = false;
            for sphere in &self.spheres {
                let reach = below + sphere.radius;
                if reach > 0.0 {
                    let squared = link.squared_distance_to_point(&sphere.center);
                    if squared < reach * reach {
                        below = squared.sqrt() - sphere.radius;
                        found = true;
                    }
                }
            }
            for capsule in &self.capsules {
                let reach = below + capsule.radius;
                if reach > 0.0 {
                    let distance =
                        segment_segment_distance(&link.a, &link.b, &capsule.a, &capsule.b);
                    if distance < reach {
                        below = distance - capsule.radius;
                        found = true;
                    }
                }
            }
            for body in &self.convex {
                let gap = (link.center - body.center).norm() - link.bound - body.bound;
                if gap < below - link.radius {
                    if let Some(distance) = link.convex_distance(body, below) {
                        if distance < below {
                            below = distance;
                            found = true;
                        }
                    }
                }
            }
            if !found {
                continue;
            }
            let slack = below - link.radius - offset;
            if loose(&capsule.levers).reach(slack) < best {
                best = best.min(exact(&link, &capsule.levers, 0..capsule.frame).reach(slack));
                if best < least {
                    return best;
                }
            }
        }
        for pair in &self.self_pairs {
            let (link, other) =
                (self.links[pair.link].posed(&frames), self.links[pair.other].posed(&frames));
            let moved = if pair.distal == pair.link { &link } else { &other };
            let loose = loose(&pair.levers);
            if link.gap_bound(&other) - offset < loose.threshold(best) {
                let slack = link.distance(&other) - offset;
                if loose.reach(slack) < best {
                    let exact = exact(moved, &pair.levers, pair.joints.clone());
                    best = best.min(exact.reach(slack));
                }
            }
        }
        best
    }
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

/// Forward kinematics of the moving frames up to the last carrying a capsule, in aligned
/// frames: each frame k+1 turned so that the axis of joint k is its z, which makes a joint's
/// turn a two-column update and folds the joint axes into constant transforms.
///
/// With F the moving frames of [`crate::kinematics::arm_pose`] and A_k a rotation taking z onto
/// joint k's axis u_k: R(u_k, q) A_k = A_k Rz(q), so the aligned frame G_{k+1} = F_{k+1} A_k is
/// G_k (A_{k−1}ᵀ P_k A_k) Rz(q_k), P_k being the joint's parent-from-joint transform.
#[derive(Debug, Clone)]
struct Chain {
    /// A_{k−1}ᵀ P_k A_k per joint, up to the last frame needed.
    steps: Vec<Frame>,
    /// A_{k−1}ᵀ per frame k (the identity for {b}).
    aligned_from_frame: [Matrix3; DOF + 1],
}

/// A rigid transform: rotation then translation.
#[derive(Debug, Clone, Copy)]
struct Frame {
    rotation: Matrix3,
    translation: Vector3,
}

impl Frame {
    fn identity() -> Self {
        Self { rotation: Matrix3::identity(), translation: Vector3::zeros() }
    }

    fn apply(&self, p: &Vector3) -> Vector3 {
        self.rotation * p + self.translation
    }
}

impl Chain {
    fn new(robot: &Robot, last: usize) -> Self {
        let z = Vector3::z();
        let align: Vec<Matrix3> = robot
            .joints
            .iter()
            .map(|j| {
                Rotation3::rotation_between(&z, &j.axis)
                    // The axis is -z: half a turn about x.
                    .unwrap_or_else(|| Rotation3::from_axis_angle(&Vector3::x_axis(), PI))
                    .into_inner()
            })
            .collect();
        let mut aligned_from_frame = [Matrix3::identity(); DOF + 1];
        for k in 1..=DOF {
            aligned_from_frame[k] = align[k - 1].transpose();
        }
        let steps = robot.joints[..last]
            .iter()
            .enumerate()
            .map(|(k, joint)| {
                let p = &joint.parent_from_joint;
                let before = aligned_from_frame[k];
                Frame {
                    rotation: before * p.rotation.matrix() * align[k],
                    translation: before * p.translation.vector,
                }
            })
            .collect();
        Self { steps, aligned_from_frame }
    }

    /// The aligned frames at `q`, `b_from_aligned`; those past the last needed are left at
    /// the identity.
    fn frames(&self, q: &JointVector) -> [Frame; DOF + 1] {
        let mut frames = [Frame::identity(); DOF + 1];
        for (k, step) in self.steps.iter().enumerate() {
            let parent = frames[k];
            let m = parent.rotation * step.rotation;
            let (s, c) = q[k].sin_cos();
            let (x, y) = (m.column(0), m.column(1));
            frames[k + 1] = Frame {
                rotation: Matrix3::from_columns(&[
                    x * c + y * s,
                    y * c - x * s,
                    m.column(2).into(),
                ]),
                translation: parent.translation + parent.rotation * step.translation,
            };
        }
        frames
    }
}

/// A capsule placed in {b}, with its bounding sphere.
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

    /// A lower bound of the distance to `other` from the bounding spheres.
    fn gap_bound(&self, other: &Posed) -> Real {
        (self.center - other.center).norm() - self.bound - other.bound
    }

    /// Signed distance to another capsule.
    fn distance(&self, other: &Posed) -> Real {
        segment_segment_distance(&self.a, &self.b, &other.a, &other.b) - self.radius - other.radius
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

/// Distance between the segments p1–q1 and p2–q2 (Ericson, Real-Time Collision Detection
/// §5.1.9).
fn segment_segment_distance(p1: &Vector3, q1: &Vector3, p2: &Vector3, q2: &Vector3) -> Real {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let tiny = Real::MIN_POSITIVE;
    let (s, t) = if a <= tiny && e <= tiny {
        (0.0, 0.0)
    } else if a <= tiny {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= tiny {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denominator = a * e - b * b;
            // Parallel segments: any s works; start from p1.
            let s = if denominator > 0.0 {
                ((b * f - c * e) / denominator).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t = (b * s + f) / e;
            if t < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s, t)
            }
        }
    };
    ((p1 + d1 * s) - (p2 + d2 * t)).norm()
}

#[cfg(test)]
mod tests;
