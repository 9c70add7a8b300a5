//! The robot model: a URDF read into an immutable [`Robot`] — the 7-joint
//! chain, its limits, the capsules of its links and its shoulder/elbow/wrist
//! structure.
//!
//! Entry points: [`Robot::from_urdf_file`], [`Robot::from_urdf_str`].
//! Every position of the model is in the base frame {b}: the axes of the
//! chain's base link, the origin at the shoulder centre S (docs/design.md §2).

mod acceleration;
mod capsules;
mod chain;
mod error;
mod self_pairs;
mod srdf;
mod structure;
mod urdf;

pub use capsules::{CapsuleSource, DEFAULT_SKELETON_RADIUS, GeometryOptions};
pub use error::RobotError;
pub use self_pairs::{SELF_CONTACT_MARGIN, home};
pub use structure::{ArmStructure, least_squares_point, line_distance};

pub use acceleration::{ATTRIBUTE as ACCELERATION_ATTRIBUTE, DEFAULT_ACCELERATION_PER_SECOND};

use crate::math::{DOF, Isometry, JointVector, Real, Rotation3, Vector3};

/// Limits of one joint.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct JointLimits {
    /// Lower position limit (rad).
    pub lower: Real,
    /// Upper position limit (rad).
    pub upper: Real,
    /// Velocity limit (rad/s).
    pub velocity: Real,
    /// Acceleration limit (rad/s²): the `<limit>` element's `a2ml_acceleration` attribute,
    /// else [`DEFAULT_ACCELERATION_PER_SECOND`] × `velocity`.
    pub acceleration: Real,
}

impl JointLimits {
    /// Whether `q` lies within [lower - tol, upper + tol].
    pub fn contains(&self, q: Real, tol: Real) -> bool {
        q >= self.lower - tol && q <= self.upper + tol
    }

    /// The middle of the range.
    pub fn middle(&self) -> Real {
        0.5 * (self.lower + self.upper)
    }
}

/// One revolute joint of the chain.
#[derive(Debug, Clone)]
pub struct Joint {
    /// URDF joint name.
    pub name: String,
    /// Transform from the previous moving frame (frame k-1; frame 0 is {b})
    /// to this joint's frame at zero angle, fixed joints folded in.
    pub parent_from_joint: Isometry,
    /// Unit rotation axis in the joint frame.
    pub axis: Vector3,
    /// Position and velocity limits; a continuous joint plans within
    /// ±2π, where every angle has a 2π shift.
    pub limits: JointLimits,
    /// A URDF `continuous` joint: no mechanical limit.
    pub continuous: bool,
}

/// A link of the chain, rigidly attached to one moving frame.
#[derive(Debug, Clone)]
pub struct ChainLink {
    /// URDF link name.
    pub name: String,
    /// Moving frame the link belongs to: 0 is {b}, k the child of joint k.
    pub frame: usize,
    /// The link's pose in that frame.
    pub frame_from_link: Isometry,
}

/// Which part of the arm a capsule belongs to (by the joint it moves after).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LinkRole {
    /// Fixed to the base (torso).
    Base,
    /// Moved by joints 1-3.
    UpperArm,
    /// Moved by joints 4-5.
    Forearm,
    /// Moved by joints 6-7.
    Hand,
}

impl LinkRole {
    /// The snake_case name used in outputs.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Base => "base",
            Self::UpperArm => "upper_arm",
            Self::Forearm => "forearm",
            Self::Hand => "hand",
        }
    }

    /// The role of a link attached to moving frame `frame`.
    pub fn of_frame(frame: usize) -> Self {
        match frame {
            0 => Self::Base,
            1..=3 => Self::UpperArm,
            4..=5 => Self::Forearm,
            _ => Self::Hand,
        }
    }
}

/// A collision capsule: the set of points within `radius` of the segment a-b.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Capsule {
    /// The URDF collision name, else the link name.
    pub name: String,
    /// The link carrying it.
    pub link: String,
    /// Part of the arm.
    pub role: LinkRole,
    /// Moving frame it is attached to.
    pub frame: usize,
    /// Segment end in the moving frame (m).
    pub a: Vector3,
    /// Other segment end in the moving frame (m).
    pub b: Vector3,
    /// Radius (m).
    pub radius: Real,
    /// Where the capsule came from.
    pub source: CapsuleSource,
}

impl Capsule {
    /// Length of the segment, caps excluded (m).
    pub fn length(&self) -> Real {
        (self.b - self.a).norm()
    }
}

/// How to read a URDF into a [`Robot`].
#[derive(Debug, Clone)]
pub struct RobotOptions {
    /// Base link of the chain; default: the root of the unique 7-joint chain.
    pub base: Option<String>,
    /// Tip link; default: the last link of the unique 7-joint chain.
    pub tip: Option<String>,
    /// Tool axis (in the tip link) giving the finger direction f.
    pub finger_axis: Vector3,
    /// Tool axis (in the tip link) giving the palm normal p.
    pub palm_axis: Vector3,
    /// The vertical direction z_b, in the base link.
    pub vertical: Vector3,
    /// Where capsules come from when the URDF has no capsule shapes.
    pub geometry: GeometryOptions,
}

impl Default for RobotOptions {
    fn default() -> Self {
        Self {
            base: None,
            tip: None,
            finger_axis: Vector3::z(),
            palm_axis: Vector3::x(),
            vertical: Vector3::z(),
            geometry: GeometryOptions::default(),
        }
    }
}

/// A 7-DoF anthropomorphic arm, immutable once loaded.
#[derive(Debug, Clone)]
pub struct Robot {
    /// URDF robot name.
    pub name: String,
    /// Base link of the chain.
    pub base_link: String,
    /// Tip link of the chain.
    pub tip_link: String,
    /// The seven revolute joints, base to tip.
    pub joints: [Joint; DOF],
    /// Links of the chain, base to tip (fixed links included).
    pub links: Vec<ChainLink>,
    /// Collision capsules of the chain's links.
    pub capsules: Vec<Capsule>,
    /// The capsule pairs checked against each other (indices into `capsules`, the one
    /// farther along the chain first): those with a body carrying geometry between them, not
    /// within [`SELF_CONTACT_MARGIN`] at [`home`], and not disabled by the SRDF.
    pub self_pairs: Vec<(usize, usize)>,
    /// The link pairs the SRDF disables (`<disable_collisions>`), in its order.
    pub allowed_pairs: Vec<(String, String)>,
    /// Pose of the base link in {b} (a pure translation by -S).
    pub b_from_base_link: Isometry,
    /// Frame 7 to the hand frame {W}'s orientation: columns f, p, f × p.
    pub frame7_from_hand: Rotation3,
    /// The vertical unit vector z_b in {b}.
    pub vertical: Vector3,
    /// Shoulder, elbow and wrist structure.
    pub structure: ArmStructure,
    /// Capsules that are not the URDF's own shapes (boxes, meshes, the
    /// skeleton) and parts of the arm left without any, one message each.
    pub geometry_warnings: Vec<String>,
    /// The URDF document the model was read from (to attach to outputs and
    /// to rebuild the model elsewhere).
    pub urdf: String,
}

impl Robot {
    /// Reads a URDF file with default options.
    ///
    /// # Errors
    /// [`RobotError`] when the file is missing or unreadable, or holds no
    /// unique 7-revolute-joint chain with limits.
    pub fn from_urdf_file(path: impl AsRef<std::path::Path>) -> Result<Self, RobotError> {
        Self::from_urdf_file_with(path, &RobotOptions::default())
    }

    /// Reads a URDF file.
    ///
    /// # Errors
    /// As [`Robot::from_urdf_file`].
    pub fn from_urdf_file_with(
        path: impl AsRef<std::path::Path>,
        options: &RobotOptions,
    ) -> Result<Self, RobotError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| {
            if source.kind() == std::io::ErrorKind::NotFound {
                RobotError::FileMissing { path: path.display().to_string() }
            } else {
                RobotError::Io { path: path.display().to_string(), message: source.to_string() }
            }
        })?;
        let mut options = options.clone();
        if options.geometry.urdf_dir.is_none() {
            options.geometry.urdf_dir = path.parent().map(std::path::Path::to_path_buf);
        }
        if options.geometry.srdf.is_none() {
            let beside = path.with_extension("srdf");
            options.geometry.srdf = beside.is_file().then_some(beside);
        }
        Self::from_urdf_str(&text, &options).map_err(|e| e.in_file(path))
    }

    /// Reads a URDF document.
    ///
    /// # Errors
    /// As [`Robot::from_urdf_file`].
    pub fn from_urdf_str(text: &str, options: &RobotOptions) -> Result<Self, RobotError> {
        chain::build(&urdf::parse(text)?, text, options)
    }

    /// Joint names, base to tip.
    pub fn joint_names(&self) -> Vec<&str> {
        self.joints.iter().map(|j| j.name.as_str()).collect()
    }

    /// Lower position limits.
    pub fn lower(&self) -> JointVector {
        JointVector::from_fn(|i, _| self.joints[i].limits.lower)
    }

    /// Upper position limits.
    pub fn upper(&self) -> JointVector {
        JointVector::from_fn(|i, _| self.joints[i].limits.upper)
    }

    /// Velocity limits.
    pub fn velocity_limits(&self) -> JointVector {
        JointVector::from_fn(|i, _| self.joints[i].limits.velocity)
    }

    /// Acceleration limits (rad/s²).
    pub fn acceleration_limits(&self) -> JointVector {
        JointVector::from_fn(|i, _| self.joints[i].limits.acceleration)
    }

    /// The middle of every joint range.
    pub fn middle(&self) -> JointVector {
        JointVector::from_fn(|i, _| self.joints[i].limits.middle())
    }

    /// The first joint outside its limits by more than `tol`, if any.
    pub fn limit_violation(&self, q: &JointVector, tol: Real) -> Option<(usize, Real)> {
        (0..DOF).find_map(|i| {
            let l = &self.joints[i].limits;
            (!l.contains(q[i], tol)).then_some((i, q[i]))
        })
    }

    /// Whether every joint lies within its limits (with tolerance `tol`).
    pub fn within_limits(&self, q: &JointVector, tol: Real) -> bool {
        self.limit_violation(q, tol).is_none()
    }

    /// Upper-arm length lu = |E - S| (m).
    pub fn upper_arm_length(&self) -> Real {
        self.structure.upper_arm_length
    }

    /// Forearm length lf = |W - E| at zero configuration (m).
    pub fn forearm_length(&self) -> Real {
        self.structure.forearm_length
    }

    /// Whether every part of the arm (upper arm, forearm, hand) carries a
    /// capsule, so that obstacles can be checked against the whole arm.
    pub fn has_arm_geometry(&self) -> bool {
        [LinkRole::UpperArm, LinkRole::Forearm, LinkRole::Hand]
            .iter()
            .all(|role| self.capsules.iter().any(|c| c.role == *role))
    }

    /// Whether IK is analytic: a spherical shoulder, and a wrist centre that
    /// joints 5-7 do not move (a spherical wrist, or Panda's W56).
    pub fn has_analytic_ik(&self) -> bool {
        self.structure.shoulder_spherical && self.structure.wrist_decoupled
    }
}
