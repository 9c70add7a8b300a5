//! Bell speed profiles (eq. 9), reference paths and QP weight schedules, docs/design.md §4-5;
//! the joining of segments (appendix A) lives beside the trajectory it joins, in
//! [`crate::trajectory::join`].
//!
//! Entry points: [`BellProfile`]; [`Reference`], built from a goal or a path feature and sampled
//! as (value, velocity) at t; [`WeightSchedule`]. Time t is in s from the start of the primitive
//! or segment; values and velocities are in {b}, angular velocities spatial (`Ṙ = [ω]× R`).

mod arc;
mod bell;
mod error;
mod reference;
mod weights;

pub use arc::SemiEllipse;
pub use bell::BellProfile;
pub use error::ProfileError;
pub use reference::{
    AngleReference, BodyFrames, PositionPath, PositionReference, Reference, RotationPath,
    RotationReference, Sample, resolve_axis,
};
pub use weights::{Role, WeightOptions, WeightSchedule};
