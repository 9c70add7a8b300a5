//! RULA group A (McAtamney & Corlett 1993) for the arm, as the HAMP paper scores a robot
//! (METHODS.md §3.6): upper arm, lower arm, wrist and wrist twist per frame, Table A, and the
//! paper's sum upper + lower + wrist (its Fig. 10(d)). No neck, trunk or legs: a fixed-base
//! arm has none. The angles are read from the HAT state in {b}; docs/metrics.md defines them.
//!
//! Every band includes its lower bound: 20° of flexion scores 2, 45° scores 3, 90° scores 4.

use crate::kinematics::{ArmPose, KinematicsError, hat_state};
use crate::math::{Real, Vector3};
use crate::robot::Robot;

/// Which arm of a body the robot is (abduction and the midline are mirrored).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// A right arm: abduction towards -y_b.
    #[default]
    Right,
    /// A left arm: abduction towards +y_b.
    Left,
}

/// Project choices the RULA worksheet leaves to the assessor.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RulaOptions {
    /// Which arm.
    pub side: Side,
    /// y_b of the body's sagittal midplane (m); `None`: the URDF base link's origin.
    pub midline: Option<Real>,
    /// Lateral reach of W beyond S that counts as "out to the side" (m).
    pub side_reach: Real,
    /// Abduction beyond which the upper arm is "abducted" (rad).
    pub abduction: Real,
    /// |Wrist flexion| up to which the wrist is "neutral" (rad).
    pub wrist_neutral: Real,
    /// |Wrist deviation| beyond which the wrist is "bent from the midline" (rad).
    pub wrist_deviation: Real,
    /// Share of the forearm-roll range at either end where the twist scores 2.
    pub twist_end: Real,
}

impl Default for RulaOptions {
    fn default() -> Self {
        Self {
            side: Side::Right,
            midline: None,
            side_reach: 0.1,
            abduction: 20.0_f64.to_radians(),
            wrist_neutral: 5.0_f64.to_radians(),
            wrist_deviation: 10.0_f64.to_radians(),
            twist_end: 0.25,
        }
    }
}

/// The arm's posture in the terms RULA scores (rad, m).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct RulaAngles {
    /// Upper-arm flexion in the sagittal plane, arm hanging = 0, extension negative.
    pub upper_arm_flexion: Real,
    /// Upper-arm abduction in the frontal plane, away from the body positive.
    pub upper_arm_abduction: Real,
    /// Elbow flexion, 180° - θe.
    pub elbow_flexion: Real,
    /// Whether the hand works across the body's midline or out to the side.
    pub across_or_out: bool,
    /// Wrist flexion/extension: the finger direction's rotation about the arm-plane normal.
    pub wrist_flexion: Real,
    /// Radial/ulnar deviation: the finger direction's angle out of the arm plane.
    pub wrist_deviation: Real,
    /// Where the forearm-roll joint sits in its range: 0 at the middle, 1 at either end.
    pub twist: Real,
}

/// The scores of one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct RulaScores {
    /// Upper arm, 1-6 (with the abduction adjustment).
    pub upper_arm: u8,
    /// Lower arm, 1-3 (with the midline/side adjustment).
    pub lower_arm: u8,
    /// Wrist, 1-4 (with the deviation adjustment).
    pub wrist: u8,
    /// Wrist twist, 1-2.
    pub wrist_twist: u8,
    /// Table A: the posture score of group A, 1-9.
    pub table_a: u8,
    /// The HAMP paper's total: upper arm + lower arm + wrist.
    pub sum: u8,
}

/// RULA Table A, rows (upper arm 1-6 × lower arm 1-3), columns (wrist 1-4 × twist 1-2).
///
/// The disputed cells (METHODS.md §3.6) are decided here, after the original worksheet
/// (McAtamney & Corlett 1993, Table A) as commonly reproduced: (UA5, LA2, W3, WT2) = 7,
/// (UA2, LA3, W1, WT2) = 4, the row (UA4, LA2) = 4 4 4 4 4 5 5 5 and (UA6, LA1, W4, WT2) = 9.
const TABLE_A: [[u8; 8]; 18] = [
    [1, 2, 2, 2, 2, 3, 3, 3],
    [2, 2, 2, 2, 3, 3, 3, 3],
    [2, 3, 3, 3, 3, 3, 4, 4],
    [2, 3, 3, 3, 3, 4, 4, 4],
    [3, 3, 3, 3, 3, 4, 4, 4],
    [3, 4, 4, 4, 4, 4, 5, 5],
    [3, 3, 4, 4, 4, 4, 5, 5],
    [3, 4, 4, 4, 4, 4, 5, 5],
    [4, 4, 4, 4, 4, 5, 5, 5],
    [4, 4, 4, 4, 4, 5, 5, 5],
    [4, 4, 4, 4, 4, 5, 5, 5],
    [4, 4, 4, 5, 5, 5, 6, 6],
    [5, 5, 5, 5, 5, 6, 6, 7],
    [5, 6, 6, 6, 6, 7, 7, 7],
    [6, 6, 6, 7, 7, 7, 7, 8],
    [7, 7, 7, 7, 7, 8, 8, 9],
    [8, 8, 8, 8, 8, 9, 9, 9],
    [9, 9, 9, 9, 9, 9, 9, 9],
];

/// Table A at (upper arm, lower arm, wrist, twist), each clamped to the table's range.
pub fn table_a(upper_arm: u8, lower_arm: u8, wrist: u8, wrist_twist: u8) -> u8 {
    let ua = usize::from(upper_arm.clamp(1, 6)) - 1;
    let la = usize::from(lower_arm.clamp(1, 3)) - 1;
    let w = usize::from(wrist.clamp(1, 4)) - 1;
    let wt = usize::from(wrist_twist.clamp(1, 2)) - 1;
    TABLE_A[3 * ua + la][2 * w + wt]
}

/// Whether `angle` (rad) is at least `degrees`, the band edges compared in radians so that a
/// posture given in degrees lands in the band its number says.
fn at_least(angle: Real, degrees: Real) -> bool {
    angle >= degrees.to_radians()
}

/// Upper arm: -20°..20° → 1, extension past 20° → 2, 20°..45° → 2, 45°..90° → 3, 90°+ → 4;
/// +1 when abducted.
pub fn upper_arm_score(angles: &RulaAngles, options: &RulaOptions) -> u8 {
    let flexion = angles.upper_arm_flexion;
    let base = if !at_least(flexion, -20.0) {
        2
    } else if !at_least(flexion, 20.0) {
        1
    } else if !at_least(flexion, 45.0) {
        2
    } else if !at_least(flexion, 90.0) {
        3
    } else {
        4
    };
    base + u8::from(angles.upper_arm_abduction > options.abduction)
}

/// Lower arm: 60°..100° of elbow flexion → 1, else 2; +1 across the midline or out to the side.
pub fn lower_arm_score(angles: &RulaAngles) -> u8 {
    let flexion = angles.elbow_flexion;
    let base = if at_least(flexion, 60.0) && !at_least(flexion, 100.0) { 1 } else { 2 };
    base + u8::from(angles.across_or_out)
}

/// Wrist: neutral → 1, up to 15° → 2, 15°+ → 3; +1 when deviated.
pub fn wrist_score(angles: &RulaAngles, options: &RulaOptions) -> u8 {
    let flexion = angles.wrist_flexion.abs();
    let base = if flexion <= options.wrist_neutral {
        1
    } else if !at_least(flexion, 15.0) {
        2
    } else {
        3
    };
    base + u8::from(angles.wrist_deviation.abs() > options.wrist_deviation)
}

/// Wrist twist: 2 within [`RulaOptions::twist_end`] of either end of the range, else 1.
pub fn wrist_twist_score(angles: &RulaAngles, options: &RulaOptions) -> u8 {
    if angles.twist >= 1.0 - 2.0 * options.twist_end { 2 } else { 1 }
}

/// All scores of a posture.
pub fn scores(angles: &RulaAngles, options: &RulaOptions) -> RulaScores {
    let upper_arm = upper_arm_score(angles, options);
    let lower_arm = lower_arm_score(angles);
    let wrist = wrist_score(angles, options);
    let wrist_twist = wrist_twist_score(angles, options);
    RulaScores {
        upper_arm,
        lower_arm,
        wrist,
        wrist_twist,
        table_a: table_a(upper_arm, lower_arm, wrist, wrist_twist),
        sum: upper_arm + lower_arm + wrist,
    }
}

/// Index of the forearm-roll joint: joint 5, the first after the elbow.
const FOREARM_ROLL: usize = 4;

/// The RULA angles of the arm at `pose` (DESIGN.md §3 vectors, docs/metrics.md).
///
/// # Errors
/// [`KinematicsError::Singular`] when the arm is straight (the arm plane is undefined).
pub fn rula_angles(
    robot: &Robot,
    pose: &ArmPose,
    q_roll: Real,
    options: &RulaOptions,
) -> Result<RulaAngles, KinematicsError> {
    let hat = hat_state(pose)?;
    let os = hat.shoulder_frame.matrix();
    let r: Vector3 = os.column(0).into();
    let l: Vector3 = os.column(1).into();
    let u = (pose.wrist - pose.elbow).normalize();
    let z = robot.vertical;
    // The sagittal and frontal axes: x_b forward, y_b left, projected off the vertical.
    let forward = (Vector3::x() - z * z.x).normalize();
    let left = z.cross(&forward);
    let outward = match options.side {
        Side::Right => -left,
        Side::Left => left,
    };
    let down = -r.dot(&z);
    let midline = options.midline.unwrap_or(-robot.structure.shoulder_in_base_link.y);
    let lateral = pose.wrist.dot(&left);
    let (across, out) = match options.side {
        Side::Right => (lateral > midline, -lateral > options.side_reach),
        Side::Left => (lateral < midline, lateral > options.side_reach),
    };
    // The finger direction in the forearm frame [u, l, u × l]: flexion turns it about l,
    // deviation tilts it out of the arm plane.
    let f: Vector3 = hat.ow.matrix().column(0).into();
    let k = u.cross(&l);
    let limits = &robot.joints[FOREARM_ROLL].limits;
    let half_range = 0.5 * (limits.upper - limits.lower);
    let twist =
        if half_range > 0.0 { ((q_roll - limits.middle()) / half_range).abs() } else { 0.0 };
    Ok(RulaAngles {
        upper_arm_flexion: r.dot(&forward).atan2(down),
        upper_arm_abduction: r.dot(&outward).atan2(down),
        elbow_flexion: std::f64::consts::PI - hat.elbow_angle,
        across_or_out: across || out,
        wrist_flexion: (-f.dot(&k)).atan2(f.dot(&u)),
        wrist_deviation: f.dot(&l).clamp(-1.0, 1.0).asin(),
        twist: twist.min(1.0),
    })
}

/// The RULA angles and scores of configuration `q`.
///
/// # Errors
/// As [`rula_angles`].
pub fn rula_at(
    robot: &Robot,
    q: &crate::math::JointVector,
    options: &RulaOptions,
) -> Result<(RulaAngles, RulaScores), KinematicsError> {
    let pose = crate::kinematics::arm_pose(robot, q);
    let angles = rula_angles(robot, &pose, q[FOREARM_ROLL], options)?;
    Ok((angles, scores(&angles, options)))
}
