//! [`is_clear`]: whether every pair of a [`CollisionModel`] keeps a clearance at one
//! configuration, each shape inflated by an [`Inflation`]: a yes-or-no answer that stops at the
//! first pair too close and computes no distance it does not need, for the discrete edge checks
//! of sampling planners.

use super::{ALL_MEMBERS, Centers, CollisionModel, GROUP_SIZE, Posed, ROUNDING};
use crate::kinematics::Frame;
use crate::math::{DOF, JointVector, Real, segment_segment_distance};

/// How much each shape of a [`CollisionModel`] is inflated in [`is_clear`] (m): per arm capsule,
/// per self pair (the two capsules' relative motion) and per group of them, the largest of
/// their members'.
#[derive(Debug, Clone, PartialEq)]
pub struct Inflation {
    links: Vec<Real>,
    groups: Vec<Real>,
    /// Per capsule and first joint s, Σ_{j≥s} its lever_j · s |dq_j|: a self pair's inflation
    /// is its distal capsule's from the pair's first joint on (its levers are the distal's over
    /// the joints between the two frames, and a capsule's are zero past its frame).
    suffixes: Vec<[Real; DOF]>,
    group_pairs: Vec<Real>,
    /// What every value above is multiplied by when used: the share after
    /// [`Inflation::set_share`], 1 once set along a motion.
    factor: Real,
    /// The pairs the values are set for ([`Inflation::set_along_of`]); a pass over others
    /// counts them as inflated without bound.
    pairs: Pairs,
}

impl Inflation {
    /// No inflation: [`is_clear`] then asks whether every pair keeps the clearance itself.
    pub fn none(model: &CollisionModel) -> Self {
        let arm = &model.arm;
        Self {
            links: vec![0.0; arm.links.len()],
            groups: vec![0.0; arm.groups.len()],
            suffixes: vec![[0.0; DOF]; arm.links.len()],
            group_pairs: vec![0.0; arm.group_pairs.len()],
            factor: 1.0,
            pairs: Pairs::All,
        }
    }

    /// The farthest each shape moves (relative to the other capsule, for a self pair) over `s`
    /// units of the straight joint-space motion `dq`, from any configuration: its levers
    /// ([`super::motion_bound`]) times `s |dq|`.
    pub fn along(model: &CollisionModel, dq: &JointVector, s: Real) -> Self {
        let mut inflation = Self::none(model);
        inflation.set_along(model, dq, s);
        inflation
    }

    /// [`Inflation::along`] in place, for `model` (the one it was made for).
    pub fn set_along(&mut self, model: &CollisionModel, dq: &JointVector, s: Real) {
        self.set_along_of(model, dq, s, Pairs::All);
    }

    /// [`Inflation::set_along`] for `pairs` alone, for a check of them alone
    /// ([`verdict_of`]): half the work for either. A pass over pairs it is not set for
    /// counts them as inflated without bound (never [`Verdict::Clear`]).
    pub fn set_along_of(
        &mut self,
        model: &CollisionModel,
        dq: &JointVector,
        s: Real,
        pairs: Pairs,
    ) {
        let arm = &model.arm;
        self.factor = 1.0;
        self.pairs = pairs;
        let speed = dq.abs() * s;
        if pairs != Pairs::SelfPairs {
            dots(&mut self.links, arm.links.iter().map(|l| &l.levers), &speed);
            dots(&mut self.groups, arm.groups.iter().map(|g| &g.levers), &speed);
        }
        if pairs == Pairs::Obstacles {
            return;
        }
        dots(&mut self.group_pairs, arm.group_pairs.iter().map(|p| &p.levers), &speed);
        self.suffixes.resize(arm.links.len(), [0.0; DOF]);
        for (suffix, link) in self.suffixes.iter_mut().zip(&arm.links) {
            let mut sum = 0.0;
            for j in (0..DOF).rev() {
                sum += link.levers[j] * speed[j];
                suffix[j] = sum * RAISE;
            }
        }
    }
}

impl Inflation {
    /// The inflation last set along `dq` over `s` units ([`Inflation::set_along`]) made that
    /// of `share · s` units (`share` in [0, 1]), for the price of one number: a power of two
    /// scales every product and sum of it exactly, so [`coverage`] answers bit for bit as
    /// after `set_along(model, dq, share · s)`; another share is within a rounding of each
    /// product (far below the clearance's own allowance for rounding). The edge checks scale
    /// an edge's inflation to each check's stretch.
    pub fn set_share(&mut self, share: Real) {
        self.factor = share;
    }
}

/// `out[k] = levers[k] · speed`, written in place: an edge check sets an [`Inflation`] per
/// edge, and the lengths are the model's.
fn dots<'a>(
    out: &mut Vec<Real>,
    levers: impl ExactSizeIterator<Item = &'a JointVector>,
    speed: &JointVector,
) {
    out.resize(levers.len(), 0.0);
    for (o, l) in out.iter_mut().zip(levers) {
        *o = l.dot(speed);
    }
}

/// Over 7 terms of one sign, rounding moves a sum by far less than this: a suffix sum is never
/// below the pair's own dot product of its levers.
const RAISE: Real = 1.0 + 64.0 * Real::EPSILON;

impl Inflation {
    fn pair(&self, distal: usize, start: usize) -> Real {
        self.suffixes[distal][start]
    }
}

/// Whether, with the arm at `q`, every pair of [`crate::collision::min_distance`] is at least `clearance`
/// (m) apart once each shape is inflated by `inflation`: an arm capsule against an obstacle by
/// the capsule's, a self pair by the pair's. Stops at the first pair that is not.
///
/// Every test is a lower bound of the pair's distance (bounding spheres, closed forms, the
/// tangent bound of a segment against a box or cylinder), so a `true` is never wrong; a `false`
/// may come from a pair within `SEGMENT_TOLERANCE` (1e-11 m) of the bound.
pub fn is_clear(
    model: &CollisionModel,
    q: &JointVector,
    clearance: Real,
    inflation: &Inflation,
) -> bool {
    scan(model, q, clearance, inflation, false, Pairs::All) == Some(1.0)
}

/// What one pass over the pairs of a [`CollisionModel`] tells of a configuration
/// ([`verdict`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Every pair keeps the clearance with the shapes inflated.
    Clear,
    /// Every pair keeps the clearance, but not once inflated.
    Tight,
    /// A pair is within the clearance itself.
    Blocked,
}

/// [`is_clear`] with `inflation` and without it in one pass: [`Verdict::Clear`] when
/// `is_clear(model, q, clearance, inflation)`, else [`Verdict::Tight`] when
/// `is_clear(model, q, clearance, &Inflation::none(model))`, else [`Verdict::Blocked`].
///
/// The pass stops at the first pair within the clearance itself ([`coverage`] over every
/// pair). What a sampling planner's edge check asks at a point: covered, or a collision
/// found, or neither yet.
pub fn verdict(
    model: &CollisionModel,
    q: &JointVector,
    clearance: Real,
    inflation: &Inflation,
) -> Verdict {
    verdict_of(model, q, clearance, inflation, Pairs::All)
}

/// Which pairs of a [`CollisionModel`] a pass tests ([`verdict_of`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pairs {
    /// Every pair: the arm's capsules against the obstacles, and the self pairs.
    All,
    /// The arm's capsules against the obstacles.
    Obstacles,
    /// The self pairs.
    SelfPairs,
}

impl Pairs {
    /// Whether these pairs include `other`.
    fn covers(self, other: Pairs) -> bool {
        self == Pairs::All || self == other
    }
}

/// [`verdict`] over `pairs` alone: an edge check may cover the self pairs, which move
/// relative to each other less than the arm moves among obstacles and are seldom near, with
/// fewer checks than the obstacles need.
pub fn verdict_of(
    model: &CollisionModel,
    q: &JointVector,
    clearance: Real,
    inflation: &Inflation,
    pairs: Pairs,
) -> Verdict {
    match coverage(model, q, clearance, inflation, pairs) {
        None => Verdict::Blocked,
        Some(share) if share >= 1.0 => Verdict::Clear,
        Some(_) => Verdict::Tight,
    }
}

/// How much of `inflation` the shapes of `pairs` keep the clearance under, with the arm at
/// `q`: `None` when a pair is within the clearance itself, else a share c in [0, 1] such that
/// every pair keeps it with each shape inflated by c times its inflation (1: all of it, as
/// [`Verdict::Clear`]). An inflation along a motion over s units scales with s, so a check
/// that keeps a share c of it covers c·s units either way: where an edge check's stretch is
/// not covered whole, it is covered in part.
///
/// One pass: a pair within the inflated clearance lowers the share to what it keeps, and the
/// rest of the pass tests the shapes inflated by that share. The share is found from lower
/// bounds of the distances, so it is never more than the pairs keep (and may be less).
pub fn coverage(
    model: &CollisionModel,
    q: &JointVector,
    clearance: Real,
    inflation: &Inflation,
    pairs: Pairs,
) -> Option<Real> {
    scan(model, q, clearance, inflation, true, pairs)
}

/// The pass of [`coverage`]; with `settle` false it stops at the first pair within the inflated
/// clearance, answering `None` (not clear, without telling which way).
fn scan(
    model: &CollisionModel,
    q: &JointVector,
    clearance: Real,
    inflation: &Inflation,
    settle: bool,
    pairs: Pairs,
) -> Option<Real> {
    let arm = &*model.arm;
    let frames = arm.chain.frames(q);
    // Distances are compared with this raised by a shape's inflation (and its radius).
    let limit = clearance + ROUNDING;
    // The share of the inflation every pair tested so far keeps the clearance under, and the
    // factor the shapes are inflated by for the rest of the pass (the inflation's, times it):
    // a pair that keeps that keeps the clearance over the share of the stretch.
    // Pairs the inflation is not set for are inflated without bound: the pass then tells only
    // whether the shapes themselves keep the clearance.
    let mut covered: Real = if inflation.pairs.covers(pairs) { 1.0 } else { 0.0 };
    let mut scale: Real = inflation.factor * covered;
    // A pair at `distance` (a lower bound) below `inflated`, its clearance with the shapes
    // inflated by `scale`, whose plain clearance is `plain`: the pass ends (not settling, or a
    // collision), or goes on with the share the pair keeps. The clearances differ by the
    // pair's inflation times `scale`, so the share is the distance's part of the difference;
    // its rounding is far below the ROUNDING every clearance carries.
    macro_rules! violated {
        ($distance:expr, $plain:expr, $inflated:expr) => {{
            let (distance, plain) = ($distance, $plain);
            if !settle || distance < plain {
                return None;
            }
            covered *= (distance - plain) / ($inflated - plain);
            scale = inflation.factor * covered;
        }};
    }
    let groups = if pairs == Pairs::SelfPairs { &[][..] } else { &arm.groups[..] };
    for (g, group) in groups.iter().enumerate() {
        let center = frames[group.frame].apply(&group.center);
        let near = limit + inflation.groups[g] * scale + group.bound;
        let mut posed: [Option<Posed>; GROUP_SIZE] = Default::default();
        let place = |m: usize| arm.links[group.members[m]].posed(&frames);
        // What a member's segment (its core) must keep from an obstacle's surface: inflated
        // (`scale` 1) or not.
        let keep = |m: usize, scale: Real| {
            let i = group.members[m];
            limit + inflation.links[i] * scale + arm.links[i].radius
        };
        for sphere in &model.spheres {
            let reach = near + sphere.radius;
            if (center - sphere.center).norm_squared() >= reach * reach {
                continue;
            }
            for (m, slot) in posed.iter_mut().enumerate().take(group.members.len()) {
                let reach = keep(m, scale) + sphere.radius;
                let link = slot.get_or_insert_with(|| place(m));
                let squared = link.squared_distance_to_point(&sphere.center);
                if squared < reach * reach {
                    violated!(squared.sqrt(), keep(m, 0.0) + sphere.radius, reach);
                }
            }
        }
        for capsule in &model.capsules {
            let gap = (center - 0.5 * (capsule.a + capsule.b)).norm()
                - 0.5 * (capsule.b - capsule.a).norm()
                - capsule.radius;
            if gap >= near {
                continue;
            }
            for (m, slot) in posed.iter_mut().enumerate().take(group.members.len()) {
                let link = slot.get_or_insert_with(|| place(m));
                let distance = segment_segment_distance(&link.a, &link.b, &capsule.a, &capsule.b);
                let inflated = keep(m, scale) + capsule.radius;
                if distance < inflated {
                    violated!(distance, keep(m, 0.0) + capsule.radius, inflated);
                }
            }
        }
        for convex in &model.convex {
            let body = &convex.body;
            let reach = near + body.bound;
            if (center - body.center).norm_squared() >= reach * reach
                || convex.local_point_distance_below(&convex.local(&center), near).is_none()
            {
                continue;
            }
            // The group's frame in the solid's axes, where its spheres are placed directly.
            let mut in_axes: Option<Frame> = None;
            for (m, slot) in posed.iter_mut().enumerate().take(group.members.len()) {
                let inflated = keep(m, scale);
                let capsule = &arm.links[group.members[m]];
                if capsule.point {
                    let frame =
                        in_axes.get_or_insert_with(|| convex.frame_in_axes(&frames[group.frame]));
                    let local = frame.apply(&capsule.a);
                    if let Some(distance) = convex.local_point_distance_below(&local, inflated) {
                        violated!(distance, keep(m, 0.0), inflated);
                    }
                    continue;
                }
                let link = slot.get_or_insert_with(|| place(m));
                // A lower bound of the segment's distance, when below the inflated clearance.
                // A point's distance is as cheap as a bounding-sphere test, and exact.
                if link.inverse_squared_length == 0.0 {
                    let distance = convex.point_distance(&link.a);
                    if distance < inflated {
                        violated!(distance, keep(m, 0.0), inflated);
                    }
                    continue;
                }
                let half_length = link.bound - link.radius;
                if (link.center - body.center).norm() - half_length - body.bound >= inflated {
                    continue;
                }
                let close = if convex.point_distance(&link.center) - half_length < inflated {
                    convex.segment_distance(&link.a, &link.b, inflated)
                } else {
                    None
                };
                if let Some(distance) = close {
                    violated!(distance, keep(m, 0.0), inflated);
                }
            }
        }
    }
    let group_pairs = if pairs == Pairs::Obstacles { &[][..] } else { &arm.group_pairs[..] };
    let group_center = |g: usize| {
        arm.groups.get(g).map(|group| (frames[group.frame].apply(&group.center), group.bound))
    };
    // A capsule is in many self pairs: its bounding sphere's centre placed once.
    let mut centers = Centers::new();
    for (gp, group_pair) in group_pairs.iter().enumerate() {
        let keep = limit + inflation.group_pairs[gp] * scale;
        // Sorted by floor within the group pair: the pairs from here on keep it at every
        // configuration.
        if group_pair.floor >= keep {
            continue;
        }
        // A pair with a member far from the other group's whole bounding sphere keeps the
        // clearance.
        let mut near = ALL_MEMBERS;
        let (a, b) = group_pair.groups;
        if let (Some(sphere_a), Some(sphere_b)) = (group_center(a), group_center(b)) {
            if (sphere_a.0 - sphere_b.0).norm() - sphere_a.1 - sphere_b.1 >= keep {
                continue;
            }
            near = arm.near_members(
                group_pair,
                (sphere_a, sphere_b),
                (&mut centers, &frames),
                |gap, member, other| {
                    let reach = keep + member + other;
                    gap.norm_squared() < reach * reach
                },
            );
            if near.0 == 0 || near.1 == 0 {
                continue;
            }
        }
        for k in group_pair.pairs.clone() {
            let pair = &arm.hot[k];
            if pair.floor >= limit + inflation.group_pairs[gp] * scale {
                break;
            }
            if !pair.among(near) {
                continue;
            }
            let keep = limit + inflation.pair(pair.distal, pair.start) * scale;
            if pair.floor >= keep {
                continue;
            }
            let reach = keep + pair.bounds;
            let gap = centers.get(pair.link, &arm.links, &frames)
                - centers.get(pair.other, &arm.links, &frames);
            if gap.norm_squared() >= reach * reach {
                continue;
            }
            let distance = if pair.points {
                gap.norm() - pair.bounds
            } else {
                let (link, other) = (&arm.links[pair.link], &arm.links[pair.other]);
                link.posed(&frames).distance(&other.posed(&frames))
            };
            if distance < keep {
                violated!(distance, limit, keep);
            }
        }
    }
    Some(covered)
}
