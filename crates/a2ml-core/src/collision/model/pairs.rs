//! Every pair of a [`CollisionModel`] measured one by one at a configuration: each pair's
//! signed distance ([`CollisionModel::measure_pairs`], what a report draws per capsule and
//! obstacle), the nearest pair ([`CollisionModel::nearest_pair`]), and the closest points of the
//! pairs within a distance ([`CollisionModel::near_pairs`], what a velocity controller's
//! damper rows need). The closed forms of [`CollisionModel::smallest`], which these answer the
//! same as; parry only where those hand over to it: a segment that enters a box or cylinder,
//! and two segments that cross (their normal is parry's to choose).

use parry3d_f64::math::Pose;
use parry3d_f64::query;
use parry3d_f64::shape::{Segment, Shape as ParryShape};

use super::{CollisionModel, Convex, ObstacleSlot, Placed, Posed, Search};
use crate::collision::{from_parry, to_parry};
use crate::math::{JointVector, Real, Vector3, segment_segment_closest, segment_segment_distance};

/// One pair of a [`CollisionModel`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Pair {
    /// A moving capsule (its index among the robot's capsules) and an obstacle (its index in
    /// the scene).
    Obstacle {
        /// Index into [`crate::robot::Robot::capsules`].
        capsule: usize,
        /// Index into the scene's obstacles, in their order.
        obstacle: usize,
    },
    /// A self-collision pair: its index into [`crate::robot::Robot::self_pairs`]. The pair's
    /// first capsule is the one that moves, the second stands for the obstacle.
    SelfPair(usize),
}

/// The closest points of one pair ([`CollisionModel::near_pairs`]), in {b}.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// Which pair.
    pub pair: Pair,
    /// Signed distance (m): negative is the penetration depth.
    pub distance: Real,
    /// The closest point on the moving capsule (a self pair's first).
    pub on_link: Vector3,
    /// The closest point on the obstacle (a self pair's second capsule).
    pub on_other: Vector3,
    /// Unit normal from the obstacle (the second capsule) to the link.
    pub normal: Vector3,
}

/// What a placed capsule meets in a pair of [`CollisionModel::walk_pairs`].
enum Against<'a> {
    /// One of the scene's obstacles.
    Obstacle(ObstacleSlot),
    /// The other capsule of a self pair, placed.
    Capsule(&'a Posed),
}

impl CollisionModel {
    /// The capsules that move (every one but the base's), as indices into the robot's
    /// capsules in their order: the capsules of the obstacle pairs.
    pub fn moving_capsules(&self) -> &[usize] {
        &self.arm.moving
    }

    /// Calls `f(pair, signed distance)` for every pair at `q`: each moving capsule against each
    /// obstacle (capsule by capsule, obstacles in the scene's order), then the self pairs in the
    /// robot's order. A distance is within `SEGMENT_TOLERANCE` (1e-11 m) below the exact one
    /// (exact for spheres and capsules); a penetration's depth is parry's for boxes and
    /// cylinders, as in [`super::clearance`].
    pub fn measure_pairs(&self, q: &JointVector, mut f: impl FnMut(Pair, Real)) {
        self.walk_pairs(q, |pair, link, against| {
            let distance = match against {
                Against::Obstacle(slot) => self.obstacle_distance(link, slot),
                Against::Capsule(other) => link.distance(other),
            };
            f(pair, distance);
        });
    }

    /// The pair with the smallest signed distance at `q`, and that distance (the first of
    /// [`CollisionModel::measure_pairs`]' order on a tie); `None` when there is no pair.
    pub fn nearest_pair(&self, q: &JointVector) -> Option<(Real, Pair)> {
        let mut best: Option<(Real, Pair)> = None;
        self.measure_pairs(q, |pair, distance| {
            if best.is_none_or(|(d, _)| distance < d) {
                best = Some((distance, pair));
            }
        });
        best
    }

    /// The closest points of every pair closer than `influence` (m) at `q`, appended to `out`
    /// in [`CollisionModel::measure_pairs`]' order. Pairs whose bounding spheres are that far
    /// apart are left out unmeasured.
    pub fn near_pairs(&self, q: &JointVector, influence: Real, out: &mut Vec<Closest>) {
        self.walk_pairs(q, |pair, link, against| {
            let (center, bound) = match against {
                Against::Obstacle(slot) => self.obstacle_bounds(slot),
                Against::Capsule(other) => (other.center, other.bound),
            };
            if (link.center - center).norm() - link.bound - bound >= influence {
                return;
            }
            let found = match against {
                Against::Obstacle(slot) => self.obstacle_closest(pair, link, slot, influence),
                Against::Capsule(other) => {
                    capsules_closest(pair, link, &other.a, &other.b, other.radius)
                }
            };
            out.extend(found.filter(|c| c.distance < influence));
        });
    }

    /// Calls `visit(pair, link, against)` for every pair at `q`, in
    /// [`CollisionModel::measure_pairs`]' order, each capsule placed once.
    fn walk_pairs(&self, q: &JointVector, mut visit: impl FnMut(Pair, &Posed, Against<'_>)) {
        let frames = self.arm.chain.frames(q);
        let mut placed = Placed::new();
        let links = &self.arm.links;
        for &capsule in &self.arm.moving {
            let link = placed.get(capsule, links, &frames);
            for (obstacle, &slot) in self.obstacles.iter().enumerate() {
                visit(Pair::Obstacle { capsule, obstacle }, &link, Against::Obstacle(slot));
            }
        }
        for (k, &(a, b)) in self.arm.pairs_in_order.iter().enumerate() {
            let (link, other) = (placed.get(a, links, &frames), placed.get(b, links, &frames));
            visit(Pair::SelfPair(k), &link, Against::Capsule(&other));
        }
    }

    /// The signed distance of a placed capsule to one obstacle.
    fn obstacle_distance(&self, link: &Posed, slot: ObstacleSlot) -> Real {
        match slot {
            ObstacleSlot::Sphere(s) => {
                let sphere = &self.spheres[s];
                link.squared_distance_to_point(&sphere.center).sqrt() - sphere.radius - link.radius
            }
            ObstacleSlot::Capsule(c) => {
                let capsule = &self.capsules[c];
                segment_segment_distance(&link.a, &link.b, &capsule.a, &capsule.b)
                    - capsule.radius
                    - link.radius
            }
            ObstacleSlot::Convex(c) => {
                let convex = &self.convex[c];
                let core = if link.inverse_squared_length == 0.0 {
                    convex.point_distance(&link.a)
                } else {
                    // Without a bound parry's answer (when the closed form hands over) is never
                    // `None`: the prediction reaches past the farthest points.
                    convex.segment_distance(&link.a, &link.b, Real::INFINITY).unwrap_or_else(|| {
                        convex.point_distance(&link.a).min(convex.point_distance(&link.b))
                    })
                };
                core - link.radius
            }
        }
    }

    /// An obstacle's bounding sphere: centre and radius.
    fn obstacle_bounds(&self, slot: ObstacleSlot) -> (Vector3, Real) {
        match slot {
            ObstacleSlot::Sphere(s) => (self.spheres[s].center, self.spheres[s].radius),
            ObstacleSlot::Capsule(c) => {
                let capsule = &self.capsules[c];
                let half = 0.5 * (capsule.b - capsule.a).norm();
                (0.5 * (capsule.a + capsule.b), half + capsule.radius)
            }
            ObstacleSlot::Convex(c) => (self.convex[c].body.center, self.convex[c].body.bound),
        }
    }

    /// The closest points of `pair`: a placed capsule and one obstacle (not always closer
    /// than `influence`: the caller filters).
    fn obstacle_closest(
        &self,
        pair: Pair,
        link: &Posed,
        slot: ObstacleSlot,
        influence: Real,
    ) -> Option<Closest> {
        match slot {
            ObstacleSlot::Sphere(s) => {
                let sphere = &self.spheres[s];
                capsules_closest(pair, link, &sphere.center, &sphere.center, sphere.radius)
            }
            ObstacleSlot::Capsule(c) => {
                let capsule = &self.capsules[c];
                capsules_closest(pair, link, &capsule.a, &capsule.b, capsule.radius)
            }
            ObstacleSlot::Convex(c) => convex_closest(pair, &self.convex[c], link, influence),
        }
    }
}

/// The closest points of `pair`: the capsule `link` and the capsule a–b of radius `radius`.
/// Two segments that meet have no normal of their own: parry's, as
/// [`super::super::distances`] gives it.
fn capsules_closest(
    pair: Pair,
    link: &Posed,
    a: &Vector3,
    b: &Vector3,
    radius: Real,
) -> Option<Closest> {
    let (s, t) = segment_segment_closest(&link.a, &link.b, a, b);
    let (on_link_core, on_other_core) = (link.a + link.along * s, a + (b - a) * t);
    let between = on_link_core - on_other_core;
    let core = between.norm();
    if core == 0.0 {
        let segment = Segment::new(to_parry(a), to_parry(b));
        return parry_closest(pair, &segment, &Pose::IDENTITY, radius, link, 0.0);
    }
    let normal = between / core;
    Some(Closest {
        pair,
        distance: core - link.radius - radius,
        on_link: on_link_core - normal * link.radius,
        on_other: on_other_core + normal * radius,
        normal,
    })
}

/// The closest points of `pair`: the capsule `link` and a box or cylinder, if closer than
/// `influence`: the closed form where [`Convex::segment_search`] settles it outside the solid,
/// else parry's.
fn convex_closest(pair: Pair, convex: &Convex, link: &Posed, influence: Real) -> Option<Closest> {
    let below = influence + link.radius;
    let at = if link.inverse_squared_length == 0.0 {
        Some(0.0)
    } else {
        match convex.segment_search(&link.a, &link.b, below) {
            Search::Settled { at, .. } => Some(at),
            Search::Above => return None,
            Search::Unsettled => None,
        }
    };
    if let Some(at) = at {
        let point = link.a + link.along * at;
        let (core, normal) = convex.point_distance_gradient(&point);
        if core > 0.0 {
            return Some(Closest {
                pair,
                distance: core - link.radius,
                on_link: point - normal * link.radius,
                on_other: point - normal * core,
                normal,
            });
        }
    }
    let body = &convex.body;
    parry_closest(pair, body.shape.as_dyn(), &body.pose, 0.0, link, influence)
}

/// parry's closest points of `pair`: the capsule `link` and `shape` at `pose` grown by
/// `margin`, if closer than `influence` (what [`super::super::distances`] computes for it).
fn parry_closest(
    pair: Pair,
    shape: &dyn ParryShape,
    pose: &Pose,
    margin: Real,
    link: &Posed,
    influence: Real,
) -> Option<Closest> {
    let segment = Segment::new(to_parry(&link.a), to_parry(&link.b));
    let margins = link.radius + margin;
    let prediction = (influence + margins).max(0.0);
    // Shape 1 is the obstacle, so parry's normal1 points from it to the link. Every pair of
    // these shapes is supported by parry's default dispatcher.
    let contact = query::contact(pose, shape, &Pose::IDENTITY, &segment, prediction).ok()??;
    let normal = from_parry(contact.normal1);
    Some(Closest {
        pair,
        distance: contact.dist - margins,
        on_link: from_parry(contact.point2) - normal * link.radius,
        on_other: from_parry(contact.point1) + normal * margin,
        normal,
    })
}
