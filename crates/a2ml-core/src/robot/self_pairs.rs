//! Which of the arm's capsules are checked against each other, as MoveIt's setup assistant
//! decides it from the geometry: every pair except those adjacent (on one rigid body, or on
//! bodies with no body carrying geometry between them: a link without geometry joins its
//! neighbours, as in MoveIt's connection graph, so a spherical shoulder's capsules do not
//! count as touching the torso at the joint they share), those already in contact at the home
//! configuration, and those an SRDF beside the URDF disables
//! (`<disable_collisions link1= link2= />`).

use std::path::Path;

use super::srdf;
use super::urdf::Document;
use super::{Capsule, Joint, RobotError};
use crate::math::{DOF, Isometry, JointVector, Real, Rotation3, segment_segment_distance};

/// Pairs closer than this at home are left out (m): they could not keep the planners' default
/// clearance (0.01 m) at rest, so a check between them would refuse the home pose itself.
pub const SELF_CONTACT_MARGIN: Real = 0.01;

/// The home configuration the contact test uses: every joint at 0, or at the middle of its
/// range where 0 is outside it (MoveIt's default state).
pub fn home(joints: &[Joint; DOF]) -> JointVector {
    JointVector::from_fn(|k, _| {
        let limits = &joints[k].limits;
        if limits.contains(0.0, 0.0) { 0.0 } else { limits.middle() }
    })
}

/// The disabled link pairs of the SRDF at `path`, every link checked against the URDF.
///
/// # Errors
/// [`RobotError::Srdf`] when the file cannot be read, is malformed, or names a link the URDF
/// does not have.
pub(super) fn read_srdf(path: &Path, urdf: &Document) -> Result<Vec<(String, String)>, RobotError> {
    let text = std::fs::read_to_string(path).map_err(|e| RobotError::Srdf {
        path: Some(path.display().to_string()),
        line: None,
        message: e.to_string(),
    })?;
    let pairs = srdf::disabled_pairs(&text).map_err(|e| e.in_srdf(path))?;
    for pair in &pairs {
        for name in [&pair.link1, &pair.link2] {
            if !urdf.links.iter().any(|l| &l.name == name) {
                return Err(RobotError::Srdf {
                    path: Some(path.display().to_string()),
                    line: Some(pair.line),
                    message: format!("<disable_collisions> names `{name}`, not a link of the URDF"),
                });
            }
        }
    }
    Ok(pairs.into_iter().map(|p| (p.link1, p.link2)).collect())
}

/// The self-collision pairs of `capsules` (indices; first the capsule farther along the
/// chain, which moves against the other), with the arm's joints already in {b}.
pub(super) fn build(
    joints: &[Joint; DOF],
    capsules: &[Capsule],
    disabled: &[(String, String)],
) -> Vec<(usize, usize)> {
    let q = home(joints);
    let mut frames = [Isometry::identity(); DOF + 1];
    for (k, joint) in joints.iter().enumerate() {
        let turn = Rotation3::new(joint.axis * q[k]);
        frames[k + 1] = frames[k]
            * joint.parent_from_joint
            * Isometry::from_parts(nalgebra::Translation3::identity(), turn);
    }
    let placed: Vec<_> = capsules
        .iter()
        .map(|c| {
            (
                frames[c.frame] * nalgebra::Point3::from(c.a),
                frames[c.frame] * nalgebra::Point3::from(c.b),
            )
        })
        .collect();
    let allowed = |a: &Capsule, b: &Capsule| {
        disabled
            .iter()
            .any(|(l1, l2)| (l1 == &a.link && l2 == &b.link) || (l1 == &b.link && l2 == &a.link))
    };
    let adjacent = |f: usize, g: usize| {
        let (low, high) = (f.min(g), f.max(g));
        high - low <= 1 || !capsules.iter().any(|c| c.frame > low && c.frame < high)
    };
    let mut pairs = Vec::new();
    for i in 0..capsules.len() {
        for j in 0..i {
            let (a, b) = (&capsules[i], &capsules[j]);
            if adjacent(a.frame, b.frame) || allowed(a, b) {
                continue;
            }
            let distance = segment_segment_distance(
                &placed[i].0.coords,
                &placed[i].1.coords,
                &placed[j].0.coords,
                &placed[j].1.coords,
            ) - a.radius
                - b.radius;
            if distance < SELF_CONTACT_MARGIN {
                continue;
            }
            pairs.push(if a.frame > b.frame { (i, j) } else { (j, i) });
        }
    }
    pairs.sort_unstable();
    pairs
}
