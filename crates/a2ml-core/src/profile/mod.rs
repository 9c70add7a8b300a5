//! Bell speed profiles (eq. 9), reference paths, QP weight schedules and the joining of
//! segments (appendix A), docs/design.md §4-5.
//!
//! Entry points: [`BellProfile`]; [`Reference`], built from a goal or a path feature and sampled
//! as (value, velocity) at t; [`WeightSchedule`]; [`Transition`] with [`join_transitional`]
//! (+Tr) and [`join_sequential`] (+Se). Time t is in s from the start of the primitive or
//! segment; values and velocities are in {b}, angular velocities spatial (`Ṙ = [ω]× R`).

mod arc;
mod bell;
mod error;
mod join;
mod reference;
mod weights;

pub use arc::SemiEllipse;
pub use bell::BellProfile;
pub use error::ProfileError;
pub use join::{
    JointSample, SequentialOptions, Transition, TransitionOptions, check_sequential,
    join_sequential, join_transitional,
};
pub use reference::{
    AngleReference, BodyFrames, PositionPath, PositionReference, Reference, RotationPath,
    RotationReference, Sample, resolve_axis,
};
pub use weights::{Role, WeightOptions, WeightSchedule};
