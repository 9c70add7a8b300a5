//! From a parsed URDF tree to the 7-joint chain. urdf-rs enters the library
//! here and nowhere else.

use std::collections::HashMap;

use super::{
    Capsule, ChainLink, Joint, JointLimits, LinkRole, Robot, RobotError, RobotOptions, structure,
};
use crate::math::{DOF, Isometry, Real, Rotation3, Translation3, Vector3};

fn pose(p: &urdf_rs::Pose) -> Isometry {
    let [x, y, z] = p.xyz.0;
    let [roll, pitch, yaw] = p.rpy.0;
    Isometry::from_parts(Translation3::new(x, y, z), Rotation3::from_euler_angles(roll, pitch, yaw))
}

fn is_movable(kind: &urdf_rs::JointType) -> bool {
    !matches!(kind, urdf_rs::JointType::Fixed)
}

fn kind_name(kind: &urdf_rs::JointType) -> &'static str {
    use urdf_rs::JointType::*;
    match kind {
        Revolute => "revolute",
        Continuous => "continuous",
        Prismatic => "prismatic",
        Fixed => "fixed",
        Floating => "floating",
        Planar => "planar",
        Spherical => "spherical",
    }
}

struct Tree<'a> {
    urdf: &'a urdf_rs::Robot,
    /// child link -> index of the joint whose child it is
    parent_joint: HashMap<&'a str, usize>,
}

impl<'a> Tree<'a> {
    fn new(urdf: &'a urdf_rs::Robot) -> Self {
        let parent_joint =
            urdf.joints.iter().enumerate().map(|(i, j)| (j.child.link.as_str(), i)).collect();
        Self { urdf, parent_joint }
    }

    fn check_link(&self, name: &str) -> Result<(), RobotError> {
        if self.urdf.links.iter().any(|l| l.name == name) {
            return Ok(());
        }
        let did_you_mean = self
            .urdf
            .links
            .iter()
            .map(|l| (crate::names::edit_distance(name, &l.name), &l.name))
            .filter(|(d, _)| *d <= name.len().max(3) / 2)
            .min()
            .map(|(_, n)| n.clone());
        Err(RobotError::UnknownLink { name: name.to_owned(), did_you_mean })
    }

    /// Joints from `base` down to `tip`, or `None` if base is not above tip.
    fn path(&self, base: &str, tip: &str) -> Option<Vec<usize>> {
        let mut joints = Vec::new();
        let mut link = tip;
        while link != base {
            let j = *self.parent_joint.get(link)?;
            joints.push(j);
            link = &self.urdf.joints[j].parent.link;
        }
        joints.reverse();
        Some(joints)
    }

    fn root(&self) -> Result<&'a str, RobotError> {
        let roots: Vec<&str> = self
            .urdf
            .links
            .iter()
            .map(|l| l.name.as_str())
            .filter(|n| !self.parent_joint.contains_key(n))
            .collect();
        match roots.as_slice() {
            [root] => Ok(root),
            [] => Err(RobotError::Urdf { path: None, message: "the link tree has no root".into() }),
            _ => Err(RobotError::Urdf {
                path: None,
                message: format!("the links form several trees (roots: {})", roots.join(", ")),
            }),
        }
    }

    fn leaves_below(&self, base: &str) -> Vec<&'a str> {
        let parents: std::collections::HashSet<&str> =
            self.urdf.joints.iter().map(|j| j.parent.link.as_str()).collect();
        self.urdf
            .links
            .iter()
            .map(|l| l.name.as_str())
            .filter(|n| !parents.contains(n) && self.path(base, n).is_some())
            .collect()
    }

    fn movable(&self, path: &[usize]) -> Vec<usize> {
        path.iter().copied().filter(|&j| is_movable(&self.urdf.joints[j].joint_type)).collect()
    }

    /// The base link and the joint path of the chain the options select.
    fn select(&self, options: &RobotOptions) -> Result<(String, Vec<usize>), RobotError> {
        let base = match &options.base {
            Some(b) => {
                self.check_link(b)?;
                b.clone()
            }
            None => self.root()?.to_owned(),
        };
        if let Some(tip) = &options.tip {
            self.check_link(tip)?;
            let path = self
                .path(&base, tip)
                .ok_or_else(|| RobotError::NotAncestor { base: base.clone(), tip: tip.clone() })?;
            return Ok((base, path));
        }
        let leaves = self.leaves_below(&base);
        let paths: Vec<Vec<usize>> = leaves.iter().filter_map(|l| self.path(&base, l)).collect();
        let seven: Vec<&Vec<usize>> =
            paths.iter().filter(|p| self.movable(p).len() == DOF).collect();
        let Some(first) = seven.first() else {
            let longest = paths.iter().map(|p| self.movable(p).len()).max().unwrap_or(0);
            return Err(if longest > DOF || longest == 0 {
                RobotError::NoSevenDofChain { longest }
            } else {
                let p =
                    paths.iter().max_by_key(|p| self.movable(p).len()).cloned().unwrap_or_default();
                self.not_seven(&base, &p)
            });
        };
        let joints = self.movable(first);
        if seven.iter().any(|p| self.movable(p) != joints) {
            let tips: Vec<String> = seven
                .iter()
                .filter_map(|p| p.last().map(|&j| self.urdf.joints[j].child.link.clone()))
                .collect();
            return Err(RobotError::AmbiguousChain { tips: tips.join(", ") });
        }
        // Several leaves past the 7th joint: stop where their paths part.
        let common = (0..)
            .take_while(|&i| seven.iter().all(|p| p.get(i).is_some() && p[i] == first[i]))
            .count();
        Ok((base, first[..common].to_vec()))
    }

    fn not_seven(&self, base: &str, path: &[usize]) -> RobotError {
        let movable = self.movable(path);
        let tip = path.last().map_or(base.to_owned(), |&j| self.urdf.joints[j].child.link.clone());
        RobotError::NotSevenDof {
            base: base.to_owned(),
            tip,
            found: movable.len(),
            joints: movable
                .iter()
                .map(|&j| self.urdf.joints[j].name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        }
    }
}

/// A joint's limits; its acceleration limit from `stated` (the robot file's
/// `a2ml_acceleration` attributes) or the default.
fn limits(
    joint: &urdf_rs::Joint,
    stated: &std::collections::HashMap<String, Real>,
) -> Result<JointLimits, RobotError> {
    let l = &joint.limit;
    let ok = l.lower.is_finite()
        && l.upper.is_finite()
        && l.lower < l.upper
        && l.velocity.is_finite()
        && l.velocity > 0.0;
    if !ok {
        return Err(RobotError::JointWithoutLimits {
            joint: joint.name.clone(),
            lower: l.lower,
            upper: l.upper,
            velocity: l.velocity,
        });
    }
    let acceleration = stated
        .get(&joint.name)
        .copied()
        .unwrap_or(super::DEFAULT_ACCELERATION_PER_SECOND * l.velocity);
    Ok(JointLimits { lower: l.lower, upper: l.upper, velocity: l.velocity, acceleration })
}

fn unit_axis(joint: &urdf_rs::Joint) -> Result<Vector3, RobotError> {
    let [x, y, z] = joint.axis.xyz.0;
    let v = Vector3::new(x, y, z);
    let n = v.norm();
    if !(n.is_finite() && n > 1e-12) {
        return Err(RobotError::Urdf {
            path: None,
            message: format!("joint `{}` has a zero axis", joint.name),
        });
    }
    Ok(v / n)
}

fn capsules_of(link: &urdf_rs::Link, chain_link: &ChainLink) -> Vec<Capsule> {
    link.collision
        .iter()
        .filter_map(|c| {
            let (radius, length) = match c.geometry {
                urdf_rs::Geometry::Cylinder { radius, length }
                | urdf_rs::Geometry::Capsule { radius, length } => (radius, length),
                urdf_rs::Geometry::Sphere { radius } => (radius, 0.0),
                // Boxes and meshes have no capsule reading; they are ignored.
                _ => return None,
            };
            let frame_from_shape = chain_link.frame_from_link * pose(&c.origin);
            let half = Vector3::new(0.0, 0.0, 0.5 * length);
            Some(Capsule {
                name: c.name.clone().unwrap_or_else(|| link.name.clone()),
                link: link.name.clone(),
                role: LinkRole::of_frame(chain_link.frame),
                frame: chain_link.frame,
                a: frame_from_shape.transform_point(&(-half).into()).coords,
                b: frame_from_shape.transform_point(&half.into()).coords,
                radius,
            })
        })
        .collect()
}

fn hand_rotation(options: &RobotOptions) -> Result<Rotation3, RobotError> {
    let f = options.finger_axis.try_normalize(1e-12);
    let p = options.palm_axis.try_normalize(1e-12);
    match (f, p) {
        (Some(f), Some(p)) if f.dot(&p).abs() < 1e-9 => {
            Ok(Rotation3::from_basis_unchecked(&[f, p, f.cross(&p)]))
        }
        _ => Err(RobotError::InvalidOption {
            reason: "the finger and palm axes must be non-zero and orthogonal".into(),
        }),
    }
}

pub(super) fn build(
    urdf: &urdf_rs::Robot,
    text: &str,
    options: &RobotOptions,
) -> Result<Robot, RobotError> {
    let tree = Tree::new(urdf);
    let (base, path) = tree.select(options)?;
    let movable = tree.movable(&path);
    if movable.len() != DOF {
        return Err(tree.not_seven(&base, &path));
    }
    let vertical = options.vertical.try_normalize(1e-12).ok_or_else(|| {
        RobotError::InvalidOption { reason: "the vertical axis must be non-zero".into() }
    })?;
    let tool = hand_rotation(options)?;
    let accelerations = super::acceleration::stated(text)?;

    // Walk the chain in base-link coordinates; shift to {b} once S is known.
    let mut joints: Vec<Joint> = Vec::with_capacity(DOF);
    let mut links =
        vec![ChainLink { name: base.clone(), frame: 0, frame_from_link: Isometry::identity() }];
    let mut acc = Isometry::identity();
    for &j in &path {
        let joint = &urdf.joints[j];
        match joint.joint_type {
            urdf_rs::JointType::Fixed => acc *= pose(&joint.origin),
            urdf_rs::JointType::Revolute => {
                joints.push(Joint {
                    name: joint.name.clone(),
                    parent_from_joint: acc * pose(&joint.origin),
                    axis: unit_axis(joint)?,
                    limits: limits(joint, &accelerations)?,
                });
                acc = Isometry::identity();
            }
            urdf_rs::JointType::Continuous => {
                return Err(RobotError::JointWithoutLimits {
                    joint: joint.name.clone(),
                    lower: Real::NEG_INFINITY,
                    upper: Real::INFINITY,
                    velocity: joint.limit.velocity,
                });
            }
            ref other => {
                return Err(RobotError::UnsupportedJoint {
                    joint: joint.name.clone(),
                    kind: kind_name(other).to_owned(),
                });
            }
        }
        links.push(ChainLink {
            name: joint.child.link.clone(),
            frame: joints.len(),
            frame_from_link: acc,
        });
    }
    let tip = links.last().map(|l| l.name.clone()).unwrap_or_else(|| base.clone());
    let frame7_from_hand = acc.rotation * tool;

    let mut frames_zero = [Isometry::identity(); DOF + 1];
    let mut axes = [Vector3::zeros(); DOF];
    let mut points = [Vector3::zeros(); DOF];
    for (k, joint) in joints.iter().enumerate() {
        let joint_frame = frames_zero[k] * joint.parent_from_joint;
        axes[k] = joint_frame.rotation * joint.axis;
        points[k] = joint_frame.translation.vector;
        frames_zero[k + 1] = joint_frame;
    }
    let hand_zero = frames_zero[DOF].rotation * frame7_from_hand;
    let structure = structure::analyse(&axes, &points, &frames_zero, hand_zero)
        .map_err(|reason| RobotError::NotAnthropomorphic { reason })?;

    let b_from_base_link = Isometry::translation(
        -structure.shoulder_in_base_link.x,
        -structure.shoulder_in_base_link.y,
        -structure.shoulder_in_base_link.z,
    );
    joints[0].parent_from_joint = b_from_base_link * joints[0].parent_from_joint;
    for link in links.iter_mut().filter(|l| l.frame == 0) {
        link.frame_from_link = b_from_base_link * link.frame_from_link;
    }
    let capsules = links
        .iter()
        .filter_map(|cl| urdf.links.iter().find(|l| l.name == cl.name).map(|l| capsules_of(l, cl)))
        .flatten()
        .collect();

    let joints: [Joint; DOF] = joints.try_into().map_err(|_| tree.not_seven(&base, &path))?;
    Ok(Robot {
        name: urdf.name.clone(),
        base_link: base,
        tip_link: tip,
        joints,
        links,
        capsules,
        b_from_base_link,
        frame7_from_hand,
        vertical,
        structure,
        urdf: text.to_owned(),
    })
}
