//! The distance of each arm capsule to each obstacle at every sample of a trajectory: what
//! the paper's Fig. 11 draws (upper arm, forearm and hand against the safety distance).
//!
//! One query per sample ([`distance_pass`]): the arm is posed once and every capsule-obstacle
//! pair and self pair measured once, which gives both the per-capsule series and the sample's
//! clearance (the smallest of those pairs, as [`super::min_clearance`] finds it).

use crate::collision::{self, CollisionScene, DistanceOptions};
use crate::kinematics::arm_pose;
use crate::language::Obstacle;
use crate::math::Real;
use crate::robot::{LinkRole, Robot};

use super::{Clearance, Trajectory};

/// The signed distance of one arm capsule to one obstacle over the plan's samples (m).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CapsuleDistances {
    /// The capsule's name.
    pub capsule: String,
    /// Its index in the robot's capsules.
    pub capsule_index: usize,
    /// The obstacle's name.
    pub obstacle: String,
    /// One per sample; `None` while the running action touches the obstacle on purpose
    /// (`contact`), when no clearance is kept from it.
    pub distance: Vec<Option<Real>>,
}

/// What one pass over a trajectory's samples measures.
#[derive(Debug, Clone, PartialEq)]
pub struct DistancePass {
    /// Every moving capsule (the base's left out) against every obstacle, obstacle by
    /// obstacle, capsules in the robot's order.
    pub distances: Vec<CapsuleDistances>,
    /// The smallest signed distance of any measured pair (self pairs included) over the
    /// samples, at its first worst sample; `None` when no pair was measured.
    pub clearance: Option<Clearance>,
}

/// Far enough that every capsule-obstacle pair of a workspace is measured (m).
const EVERY_PAIR: Real = 1e3;

/// The signed distance of every moving capsule to every obstacle of `scene` (in {b}) at each
/// sample; [`DistancePass::distances`] of [`distance_pass`].
pub fn capsule_distances(
    trajectory: &Trajectory,
    robot: &Robot,
    scene: &[Obstacle],
    contact: impl Fn(usize, &str) -> bool,
) -> Vec<CapsuleDistances> {
    distance_pass(trajectory, robot, scene, contact).distances
}

/// Every moving capsule's distance to every obstacle of `scene` (in {b}) and the clearance,
/// in one collision query per sample. `contact(sample, obstacle)` says when an obstacle is
/// not measured because the running action touches it on purpose: that sample's distances
/// to it are `None` and it does not count towards the clearance.
pub fn distance_pass(
    trajectory: &Trajectory,
    robot: &Robot,
    scene: &[Obstacle],
    contact: impl Fn(usize, &str) -> bool,
) -> DistancePass {
    let moving: Vec<(usize, &str)> = robot
        .capsules
        .iter()
        .enumerate()
        .filter(|(_, c)| c.role != LinkRole::Base)
        .map(|(i, c)| (i, c.name.as_str()))
        .collect();
    let mut distances: Vec<CapsuleDistances> = scene
        .iter()
        .flat_map(|o| {
            moving.iter().map(|(i, name)| CapsuleDistances {
                capsule: (*name).to_owned(),
                capsule_index: *i,
                obstacle: o.name.clone(),
                distance: Vec::with_capacity(trajectory.len()),
            })
        })
        .collect();
    let collision_scene = CollisionScene::new(scene);
    let options = DistanceOptions { influence: EVERY_PAIR };
    let mut clearance: Option<Clearance> = None;
    let mut row: Vec<Option<Real>> = vec![None; distances.len()];
    for (sample, (&time, q)) in trajectory.times().iter().zip(trajectory.positions()).enumerate() {
        let touched: Vec<bool> = scene.iter().map(|o| contact(sample, &o.name)).collect();
        row.fill(None);
        let pose = arm_pose(robot, q);
        for pair in collision::distances(robot, &pose, &collision_scene, &options) {
            if pair.obstacle_frame.is_none() {
                let Some(k) = scene.iter().position(|o| o.name == pair.obstacle) else {
                    continue;
                };
                if touched[k] {
                    continue;
                }
                // Capsules that share a name are met in the robot's order: each takes the
                // first slot of its name still empty.
                let slots = &mut row[k * moving.len()..(k + 1) * moving.len()];
                let free = moving
                    .iter()
                    .zip(slots.iter())
                    .position(|((_, name), slot)| *name == pair.link.as_str() && slot.is_none());
                if let Some(j) = free {
                    slots[j] = Some(pair.distance);
                }
            }
            if clearance.as_ref().is_none_or(|c| pair.distance < c.distance) {
                clearance = Some(Clearance {
                    distance: pair.distance,
                    time,
                    link: pair.link,
                    obstacle: pair.obstacle,
                });
            }
        }
        for (series, value) in distances.iter_mut().zip(&row) {
            series.distance.push(*value);
        }
    }
    DistancePass { distances, clearance }
}
