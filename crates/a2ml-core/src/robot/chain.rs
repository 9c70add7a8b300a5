//! From a parsed URDF tree to the 7-joint chain: which chain, its joints and
//! limits, its links, and their capsules.

use std::collections::HashMap;

use super::urdf::{Document, JointKind};
use super::{ChainLink, Joint, JointLimits, Robot, RobotError, RobotOptions, capsules, structure};
use crate::math::{DOF, Isometry, PI, Real, Rotation3, Vector3};

fn is_movable(kind: JointKind) -> bool {
    kind != JointKind::Fixed
}

struct Tree<'a> {
    urdf: &'a Document,
    /// child link -> index of the joint whose child it is
    parent_joint: HashMap<&'a str, usize>,
}

impl<'a> Tree<'a> {
    fn new(urdf: &'a Document) -> Self {
        let parent_joint =
            urdf.joints.iter().enumerate().map(|(i, j)| (j.child.as_str(), i)).collect();
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
            link = &self.urdf.joints[j].parent;
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
            self.urdf.joints.iter().map(|j| j.parent.as_str()).collect();
        self.urdf
            .links
            .iter()
            .map(|l| l.name.as_str())
            .filter(|n| !parents.contains(n) && self.path(base, n).is_some())
            .collect()
    }

    fn movable(&self, path: &[usize]) -> Vec<usize> {
        path.iter().copied().filter(|&j| is_movable(self.urdf.joints[j].kind)).collect()
    }

    /// The base link and the joint path of the chain the options select.
    fn select(
        &self,
        options: &RobotOptions,
        is_arm: &dyn Fn(&str, &str) -> bool,
    ) -> Result<(String, Vec<usize>), RobotError> {
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
                RobotError::NoSevenDofChain { longest, candidates: self.candidates(&paths, is_arm) }
            } else {
                let p =
                    paths.iter().max_by_key(|p| self.movable(p).len()).cloned().unwrap_or_default();
                self.not_seven(&base, &p)
            });
        };
        let joints = self.movable(first);
        if seven.iter().any(|p| self.movable(p) != joints) {
            return Err(RobotError::AmbiguousChain { candidates: self.candidates(&paths, is_arm) });
        }
        // Several leaves past the 7th joint: stop where their paths part.
        let common = (0..)
            .take_while(|&i| seven.iter().all(|p| p.get(i).is_some() && p[i] == first[i]))
            .count();
        Ok((base, first[..common].to_vec()))
    }

    /// Every run of 7 consecutive rotating joints on the given paths, as
    /// `base -> tip` link pairs: the choices a user can pass as base and tip;
    /// only those that are shoulder-elbow-wrist arms when there are any.
    fn candidates(&self, paths: &[Vec<usize>], is_arm: &dyn Fn(&str, &str) -> bool) -> String {
        let mut pairs: Vec<(String, String)> = Vec::new();
        for path in paths {
            let movable = self.movable(path);
            for window in movable.windows(DOF) {
                let rotating = window.iter().all(|&j| {
                    matches!(self.urdf.joints[j].kind, JointKind::Revolute | JointKind::Continuous)
                });
                let pair = (
                    self.urdf.joints[window[0]].parent.clone(),
                    self.urdf.joints[window[DOF - 1]].child.clone(),
                );
                if rotating && !pairs.contains(&pair) {
                    pairs.push(pair);
                }
            }
        }
        if pairs.is_empty() {
            return "none: no run of 7 revolute joints".into();
        }
        let arms: Vec<(String, String)> =
            pairs.iter().filter(|(b, t)| is_arm(b, t)).cloned().collect();
        if !arms.is_empty() {
            pairs = arms;
        }
        const SHOWN: usize = 12;
        let mut text: Vec<String> =
            pairs.iter().take(SHOWN).map(|(b, t)| format!("base `{b}` tip `{t}`")).collect();
        if pairs.len() > SHOWN {
            text.push(format!("and {} more", pairs.len() - SHOWN));
        }
        text.join("; ")
    }

    fn not_seven(&self, base: &str, path: &[usize]) -> RobotError {
        let movable = self.movable(path);
        let tip = path.last().map_or(base.to_owned(), |&j| self.urdf.joints[j].child.clone());
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

/// Planning window of a continuous joint: two turns either way of zero, so
/// that every angle has a 2π shift inside it with room to move past ±π.
pub(crate) const CONTINUOUS_RANGE: Real = 2.0 * PI;

/// The widest joint range a2ml plans: two turns (a continuous joint's window), with room for
/// a URDF that writes ±2π to four decimals.
const MAX_RANGE: Real = 2.0 * CONTINUOUS_RANGE + 1e-3;

/// A joint's limits; its acceleration limit from the robot file's `a2ml_acceleration`
/// attribute or the default.
fn limits(joint: &super::urdf::Joint) -> Result<JointLimits, RobotError> {
    let l = joint.limit.unwrap_or(super::urdf::Limit {
        lower: 0.0,
        upper: 0.0,
        velocity: 0.0,
        acceleration: None,
    });
    let (lower, upper) = match joint.kind {
        JointKind::Continuous => (-CONTINUOUS_RANGE, CONTINUOUS_RANGE),
        _ => (l.lower, l.upper),
    };
    if !(lower < upper && l.velocity > 0.0) {
        return Err(RobotError::JointWithoutLimits {
            joint: joint.name.clone(),
            lower: l.lower,
            upper: l.upper,
            velocity: l.velocity,
        });
    }
    // Every 2π shift of an angle within the range is an IK candidate, so a range of many turns
    // would multiply the branches per joint (and a hostile file could ask for millions).
    if upper - lower > MAX_RANGE {
        return Err(RobotError::Urdf {
            path: None,
            message: format!(
                "line {}, <joint name=\"{}\">: its range [{lower}, {upper}] rad spans more than \
                 two turns (4π rad), which a2ml does not plan",
                joint.line, joint.name
            ),
        });
    }
    let acceleration =
        l.acceleration.unwrap_or(super::DEFAULT_ACCELERATION_PER_SECOND * l.velocity);
    if !(acceleration.is_finite() && acceleration > 0.0) {
        return Err(RobotError::InvalidAcceleration {
            joint: joint.name.clone(),
            text: acceleration.to_string(),
        });
    }
    Ok(JointLimits { lower, upper, velocity: l.velocity, acceleration })
}

fn unit_axis(joint: &super::urdf::Joint) -> Result<Vector3, RobotError> {
    let n = joint.axis.norm();
    if !(n.is_finite() && n > 1e-12) {
        return Err(RobotError::Urdf {
            path: None,
            message: format!("line {}, <joint name=\"{}\">: a zero axis", joint.line, joint.name),
        });
    }
    Ok(joint.axis / n)
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

/// The 7-joint chain the options select, with its capsules.
pub(super) fn build(
    urdf: &Document,
    text: &str,
    options: &RobotOptions,
) -> Result<Robot, RobotError> {
    let tree = Tree::new(urdf);
    let is_arm = |base: &str, tip: &str| {
        let quick = RobotOptions {
            base: Some(base.to_owned()),
            tip: Some(tip.to_owned()),
            geometry: super::GeometryOptions {
                package_path: Vec::new(),
                urdf_dir: None,
                skeleton_radius: None,
                srdf: None,
            },
            ..options.clone()
        };
        build(urdf, "", &quick).is_ok()
    };
    let (base, path) = tree.select(options, &is_arm)?;
    let movable = tree.movable(&path);
    if movable.len() != DOF {
        return Err(tree.not_seven(&base, &path));
    }
    let vertical = options.vertical.try_normalize(1e-12).ok_or_else(|| {
        RobotError::InvalidOption { reason: "the vertical axis must be non-zero".into() }
    })?;
    let tool = hand_rotation(options)?;

    // Walk the chain in base-link coordinates; shift to {b} once S is known.
    let mut joints: Vec<Joint> = Vec::with_capacity(DOF);
    let mut links =
        vec![ChainLink { name: base.clone(), frame: 0, frame_from_link: Isometry::identity() }];
    let mut acc = Isometry::identity();
    for &j in &path {
        let joint = &urdf.joints[j];
        if let (Some(mimic), true) = (&joint.mimic, is_movable(joint.kind)) {
            return Err(RobotError::MimicJoint {
                joint: joint.name.clone(),
                follows: mimic.joint.clone(),
            });
        }
        match joint.kind {
            JointKind::Fixed => acc *= joint.parent_from_joint,
            JointKind::Revolute | JointKind::Continuous => {
                joints.push(Joint {
                    name: joint.name.clone(),
                    parent_from_joint: acc * joint.parent_from_joint,
                    axis: unit_axis(joint)?,
                    limits: limits(joint)?,
                    continuous: joint.kind == JointKind::Continuous,
                });
                acc = Isometry::identity();
            }
            other => {
                return Err(RobotError::UnsupportedJoint {
                    joint: joint.name.clone(),
                    kind: other.as_str().to_owned(),
                });
            }
        }
        links.push(ChainLink {
            name: joint.child.clone(),
            frame: joints.len(),
            frame_from_link: acc,
        });
    }
    let tip = links.last().map(|l| l.name.clone()).unwrap_or_else(|| base.clone());
    let frame7_from_hand = acc.rotation * tool;
    let tip_in_frame7 = acc.translation.vector;

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
    let skeleton = capsules::Skeleton::new(&structure, &frames_zero, tip_in_frame7);
    let (capsules, geometry_warnings) =
        capsules::build(urdf, &links, &skeleton, &options.geometry)?;

    let joints: [Joint; DOF] = joints.try_into().map_err(|_| tree.not_seven(&base, &path))?;
    let allowed_pairs = match &options.geometry.srdf {
        Some(path) => super::self_pairs::read_srdf(path, urdf)?,
        None => Vec::new(),
    };
    let self_pairs = super::self_pairs::build(&joints, &capsules, &allowed_pairs);
    Ok(Robot {
        name: urdf.name.clone(),
        base_link: base,
        tip_link: tip,
        joints,
        links,
        capsules,
        self_pairs,
        allowed_pairs,
        b_from_base_link,
        frame7_from_hand,
        vertical,
        structure,
        geometry_warnings,
        urdf: text.to_owned(),
    })
}
