use crate::math::Real;

/// Why a URDF could not become a [`super::Robot`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RobotError {
    /// The file does not exist.
    #[error("URDF file not found: {path}")]
    FileMissing {
        /// The path as given.
        path: String,
    },
    /// The file exists but cannot be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// The path as given.
        path: String,
        /// The OS message.
        message: String,
    },
    /// The document is not valid URDF.
    #[error("{}invalid URDF: {message}", path.as_deref().map(|p| format!("{p}: ")).unwrap_or_default())]
    Urdf {
        /// The file, when read from one.
        path: Option<String>,
        /// The parser's message.
        message: String,
    },
    /// The SRDF beside the URDF is malformed or names a link the URDF does not have.
    #[error(
        "{}{}invalid SRDF: {message}",
        path.as_deref().map(|p| format!("{p}: ")).unwrap_or_default(),
        line.map(|l| format!("line {l}: ")).unwrap_or_default()
    )]
    Srdf {
        /// The SRDF file, when read from one.
        path: Option<String>,
        /// The line of the element at fault, when one is.
        line: Option<u32>,
        /// What is wrong.
        message: String,
    },
    /// A link named by the user is not in the URDF.
    #[error("no link named `{name}`{}", did_you_mean.as_deref().map(|s| format!(" (did you mean `{s}`?)")).unwrap_or_default())]
    UnknownLink {
        /// The name asked for.
        name: String,
        /// The closest existing link name.
        did_you_mean: Option<String>,
    },
    /// The base link is not an ancestor of the tip link.
    #[error("link `{base}` is not an ancestor of `{tip}`, so there is no chain between them")]
    NotAncestor {
        /// Base link asked for.
        base: String,
        /// Tip link asked for.
        tip: String,
    },
    /// The chain between base and tip does not have 7 revolute joints.
    #[error(
        "the chain {base} -> {tip} has {found} revolute joints ({joints}); an anthropomorphic arm needs 7"
    )]
    NotSevenDof {
        /// Base link.
        base: String,
        /// Tip link.
        tip: String,
        /// Number of revolute joints found.
        found: usize,
        /// Their names, comma separated.
        joints: String,
    },
    /// No chain of the tree has exactly 7 moving joints.
    #[error(
        "no chain of exactly 7 moving joints in the URDF (longest has {longest}); choose one with \
         base and tip links (`--base`/`--tip`, or `robot \"...\" base \"...\" tip \"...\"`); \
         candidates: {candidates}"
    )]
    NoSevenDofChain {
        /// Moving joints on the longest chain.
        longest: usize,
        /// Runs of 7 revolute joints as base/tip pairs, `; ` separated.
        candidates: String,
    },
    /// Several different 7-joint chains: base and tip must be given.
    #[error(
        "several 7-joint chains; choose one with base and tip links (`--base`/`--tip`, or \
         `robot \"...\" base \"...\" tip \"...\"`); candidates: {candidates}"
    )]
    AmbiguousChain {
        /// Candidate base/tip pairs, `; ` separated.
        candidates: String,
    },
    /// A joint of the chain copies another joint's motion.
    #[error(
        "joint `{joint}` mimics `{follows}`: a2ml plans 7 independent joints, so a mimic joint \
         inside the chain is refused (mimic joints outside it, such as gripper fingers, are \
         ignored); choose a tip before it"
    )]
    MimicJoint {
        /// The mimic joint.
        joint: String,
        /// The joint it follows.
        follows: String,
    },
    /// A joint type that an arm chain cannot contain.
    #[error("joint `{joint}` is {kind}; an arm chain holds revolute and fixed joints only")]
    UnsupportedJoint {
        /// Joint name.
        joint: String,
        /// Its URDF type.
        kind: String,
    },
    /// A revolute joint without usable limits.
    #[error(
        "joint `{joint}` has no usable limits (lower {lower}, upper {upper}, velocity {velocity})"
    )]
    JointWithoutLimits {
        /// Joint name.
        joint: String,
        /// Lower limit read.
        lower: Real,
        /// Upper limit read.
        upper: Real,
        /// Velocity limit read.
        velocity: Real,
    },
    /// A joint's `a2ml_acceleration` is not a positive number (rad/s²).
    #[error("joint `{joint}`: a2ml_acceleration=\"{text}\" is not a positive number (rad/s²)")]
    InvalidAcceleration {
        /// Joint name.
        joint: String,
        /// The attribute's text.
        text: String,
    },
    /// The geometry is not that of a shoulder-elbow-wrist arm.
    #[error(
        "not a shoulder-elbow-wrist arm: {reason}; if the URDF holds such an arm, choose its \
         chain with other base and tip links"
    )]
    NotAnthropomorphic {
        /// What is wrong.
        reason: String,
    },
    /// Bad tool or vertical axes in the options.
    #[error("invalid option: {reason}")]
    InvalidOption {
        /// What is wrong.
        reason: String,
    },
}

impl RobotError {
    /// Adds the file path to errors that came from parsing its text.
    pub(crate) fn in_file(self, path: &std::path::Path) -> Self {
        match self {
            Self::Urdf { path: None, message } => {
                Self::Urdf { path: Some(path.display().to_string()), message }
            }
            other => other,
        }
    }

    /// Adds the SRDF file's path to errors that came from parsing its text.
    pub(crate) fn in_srdf(self, srdf: &std::path::Path) -> Self {
        match self {
            Self::Srdf { path: None, line, message } => {
                Self::Srdf { path: Some(srdf.display().to_string()), line, message }
            }
            other => other,
        }
    }
}
