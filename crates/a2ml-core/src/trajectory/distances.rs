//! The distance of each arm capsule to each obstacle at every sample of a trajectory: what
//! the paper's Fig. 11 draws (upper arm, forearm and hand against the safety distance).
//!
//! One query per sample ([`distance_pass`]): the arm is posed once and every capsule-obstacle
//! pair and self pair measured once in closed form ([`CollisionModel::measure_pairs`]), which
//! gives both the per-capsule series and the sample's clearance (the smallest of those pairs,
//! as [`super::min_clearance`] finds it).

use crate::collision::{CollisionModel, CollisionScene, Pair};
use crate::language::Obstacle;
use crate::math::Real;
use crate::parallel;
use crate::robot::Robot;

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

/// One sample's row of capsule-obstacle distances (`None`: not measured) and its nearest pair.
type SampleMeasure = (Vec<Option<Real>>, Option<(Real, Pair)>);

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
    let collision_scene = CollisionScene::new(scene);
    let model = CollisionModel::new(robot, &collision_scene);
    let moving = model.moving_capsules();
    let mut distances: Vec<CapsuleDistances> = scene
        .iter()
        .flat_map(|o| {
            moving.iter().map(|&i| CapsuleDistances {
                capsule: robot.capsules[i].name.clone(),
                capsule_index: i,
                obstacle: o.name.clone(),
                distance: Vec::with_capacity(trajectory.len()),
            })
        })
        .collect();
    // The model's obstacle pairs are capsule by capsule; a series is obstacle by obstacle.
    let mut slot_of: Vec<Option<usize>> = vec![None; robot.capsules.len()];
    for (j, &i) in moving.iter().enumerate() {
        slot_of[i] = Some(j);
    }
    // Which obstacles each sample's action touches, asked in the samples' order.
    let touched: Vec<Vec<bool>> = (0..trajectory.len())
        .map(|sample| scene.iter().map(|o| contact(sample, &o.name)).collect())
        .collect();
    // Each sample measured on its own (on the thread pool): its row of capsule-obstacle
    // distances and its nearest pair (the first of the smallest, in the model's order).
    let width = distances.len();
    let measured: Vec<SampleMeasure> = parallel::map(trajectory.positions(), |sample, q| {
        let touched = &touched[sample];
        let mut row = vec![None; width];
        let mut nearest: Option<(Real, Pair)> = None;
        model.measure_pairs(q, |pair, distance| {
            if let Pair::Obstacle { capsule, obstacle } = pair {
                if touched[obstacle] {
                    return;
                }
                if let Some(j) = slot_of[capsule] {
                    row[obstacle * moving.len() + j] = Some(distance);
                }
            }
            if nearest.is_none_or(|(d, _)| distance < d) {
                nearest = Some((distance, pair));
            }
        });
        (row, nearest)
    });
    // The clearance at the first of the smallest samples, as one pass in order finds it.
    let mut clearance: Option<(Real, Real, Pair)> = None;
    for ((row, nearest), &time) in measured.into_iter().zip(trajectory.times()) {
        for (series, value) in distances.iter_mut().zip(row) {
            series.distance.push(value);
        }
        if let Some((distance, pair)) = nearest {
            if clearance.is_none_or(|(d, _, _)| distance < d) {
                clearance = Some((distance, time, pair));
            }
        }
    }
    let clearance = clearance.map(|(distance, time, pair)| {
        let (link, obstacle) = pair_names(robot, &collision_scene, pair);
        Clearance { distance, time, link, obstacle }
    });
    DistancePass { distances, clearance }
}

/// The names of a pair's two sides: the capsule's, and the obstacle's or the other capsule's.
pub(super) fn pair_names(robot: &Robot, scene: &CollisionScene, pair: Pair) -> (String, String) {
    let capsule = |i: usize| robot.capsules[i].name.clone();
    match pair {
        Pair::Obstacle { capsule: i, obstacle } => (capsule(i), scene.name(obstacle).to_owned()),
        Pair::SelfPair(k) => {
            let (a, b) = robot.self_pairs[k];
            (capsule(a), capsule(b))
        }
    }
}
