//! The distance of each arm capsule to each obstacle at every sample of a trajectory: what
//! the paper's Fig. 11 draws (upper arm, forearm and hand against the safety distance).

use crate::collision::{self, CollisionScene, DistanceOptions};
use crate::kinematics::arm_pose;
use crate::language::Obstacle;
use crate::math::Real;
use crate::robot::{LinkRole, Robot};

use super::Trajectory;

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

/// Far enough that every capsule-obstacle pair of a workspace is measured (m).
const EVERY_PAIR: Real = 1e3;

/// The signed distance of every moving capsule (the base's left out) to every obstacle of
/// `scene` (in {b}) at each sample, obstacle by obstacle, capsules in the robot's order.
/// `contact(sample, obstacle)` says when a pair is not measured because the running action
/// touches the obstacle on purpose; that sample's distance is `None`.
pub fn capsule_distances(
    trajectory: &Trajectory,
    robot: &Robot,
    scene: &[Obstacle],
    contact: impl Fn(usize, &str) -> bool,
) -> Vec<CapsuleDistances> {
    let moving: Vec<(usize, &str)> = robot
        .capsules
        .iter()
        .enumerate()
        .filter(|(_, c)| c.role != LinkRole::Base)
        .map(|(i, c)| (i, c.name.as_str()))
        .collect();
    let mut out: Vec<CapsuleDistances> = scene
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
    let scenes: Vec<CollisionScene> =
        scene.iter().map(|o| CollisionScene::new(std::slice::from_ref(o))).collect();
    let options = DistanceOptions { influence: EVERY_PAIR };
    for (sample, q) in trajectory.positions().iter().enumerate() {
        let pose = arm_pose(robot, q);
        for (k, (obstacle, one)) in scene.iter().zip(&scenes).enumerate() {
            let touched = contact(sample, &obstacle.name);
            let pairs: Vec<(String, Real)> = if touched {
                Vec::new()
            } else {
                collision::distances(robot, &pose, one, &options)
                    .into_iter()
                    .filter(|p| p.obstacle_frame.is_none())
                    .map(|p| (p.link, p.distance))
                    .collect()
            };
            for (j, (_, name)) in moving.iter().enumerate() {
                let d = pairs.iter().find(|(link, _)| link == name).map(|(_, d)| *d);
                out[k * moving.len() + j].distance.push(if touched { None } else { d });
            }
        }
    }
    out
}
