//! Shoulder, elbow and wrist centres found from the joint axes at zero
//! configuration (docs/design.md §2).

use std::ops::Mul;

use crate::math::{DOF, Matrix3, Real, Rotation3, Vector3, projector};

/// Axes closer than this fraction of the arm's length lu + lf are taken to
/// meet: the analytic IK then solves the idealised arm and a Newton polish
/// makes the answer exact for the real chain.
pub const MEET_TOL_RELATIVE: Real = 1e-6;

/// Beyond this fraction of the limb it belongs to, a shoulder or wrist whose
/// axes miss one point is no shoulder or wrist (a torso or gripper joint in
/// the chain).
const NEAR_POINT_RELATIVE: Real = 0.35;

/// Below this fraction of the longer limb, the shorter is not a limb (the
/// chain starts or ends one joint off).
const SHORTEST_LIMB_RELATIVE: Real = 0.2;

/// The shoulder-elbow-wrist structure of an arm.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ArmStructure {
    /// S in the base link at zero configuration (m); the origin of {b}.
    pub shoulder_in_base_link: Vector3,
    /// E in {b} at zero configuration (m).
    pub elbow_zero: Vector3,
    /// W in {b} at zero configuration (m).
    pub wrist_zero: Vector3,
    /// lu = |E - S| (m).
    pub upper_arm_length: Real,
    /// lf = |W - E| at zero configuration (m).
    pub forearm_length: Real,
    /// Distances between axes 3 and 4, and between axes 4 and 5 (m).
    pub elbow_offsets: [Real; 2],
    /// Axes 1-3 meet in one point.
    pub shoulder_spherical: bool,
    /// Axes 5-7 meet in one point.
    pub wrist_spherical: bool,
    /// W lies on axes 5 and 6, so joints 5-7 turn the hand without moving
    /// W (true for every spherical wrist, and for Panda's W56).
    pub wrist_decoupled: bool,
    /// Spherical shoulder and wrist and no elbow offset.
    pub is_srs: bool,
    /// RMS distance of S from axes 1-3 (m).
    pub shoulder_residual: Real,
    /// RMS distance of W from the axes it was fitted to (m).
    pub wrist_residual: Real,
    /// The largest distance (m) by which S misses axes 1-3 or W misses axes
    /// 5-6 where the analytic IK takes them to meet; above 1e-9 its answers
    /// are polished by Newton on the real chain.
    pub idealisation: Real,
    /// Axis directions in {b} at zero configuration.
    pub axes_zero: [Vector3; DOF],
    /// A point of each axis in {b} at zero configuration.
    pub axis_points_zero: [Vector3; DOF],
    /// Ow at zero configuration.
    pub hand_zero: Rotation3,
    /// E in moving frame 3 (it moves with joints 1-3 only).
    pub elbow_in_frame3: Vector3,
    /// W in moving frame 6.
    pub wrist_in_frame6: Vector3,
}

/// The point nearest to all `lines` (point, unit direction) in the least
/// squares sense, and the RMS distance from it; `None` if the lines are all
/// parallel.
pub fn least_squares_point(lines: &[(Vector3, Vector3)]) -> Option<(Vector3, Real)> {
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for (p, d) in lines {
        let m = projector(d);
        a += m;
        b += m * p;
    }
    let x = a.try_inverse().filter(|inv| inv.iter().all(|v| v.is_finite()))? * b;
    let sq: Real = lines.iter().map(|(p, d)| (projector(d) * (x - p)).norm_squared()).sum();
    Some((x, (sq / lines.len() as Real).sqrt()))
}

/// The shortest distance between two lines (point, unit direction).
pub fn line_distance(p1: &Vector3, d1: &Vector3, p2: &Vector3, d2: &Vector3) -> Real {
    let n = d1.cross(d2);
    let w = p2 - p1;
    if n.norm() < 1e-12 { (w - d1 * d1.dot(&w)).norm() } else { w.dot(&n).abs() / n.norm() }
}

/// The point of line (p, d) nearest to `x`.
pub(crate) fn nearest_on_line(p: &Vector3, d: &Vector3, x: &Vector3) -> Vector3 {
    p + d * d.dot(&(x - p))
}

/// Where two lines meet, if they do (not parallel, closer than `tol`).
fn intersection(
    p1: &Vector3,
    d1: &Vector3,
    p2: &Vector3,
    d2: &Vector3,
    tol: Real,
) -> Option<Vector3> {
    if d1.cross(d2).norm() < 1e-9 || line_distance(p1, d1, p2, d2) > tol {
        return None;
    }
    least_squares_point(&[(*p1, *d1), (*p2, *d2)]).map(|(x, _)| x)
}

/// S, E, W and the structure flags from the zero-configuration axes given in
/// the base link; `frames_zero[k]` is moving frame k at zero configuration.
pub(crate) fn analyse(
    axes: &[Vector3; DOF],
    points: &[Vector3; DOF],
    frames_zero: &[crate::math::Isometry; DOF + 1],
    hand_zero: Rotation3,
) -> Result<ArmStructure, String> {
    let line = |i: usize| (points[i], axes[i]);
    let (shoulder, shoulder_residual) = least_squares_point(&[line(0), line(1), line(2)])
        .ok_or("the first three joint axes are parallel")?;
    let (wrist_fit, wrist_fit_residual) = least_squares_point(&[line(4), line(5), line(6)])
        .ok_or("the last three joint axes are parallel")?;
    let elbow = nearest_on_line(&points[3], &axes[3], &shoulder);
    let tol = MEET_TOL_RELATIVE * ((elbow - shoulder).norm() + (wrist_fit - elbow).norm());
    let shoulder_spherical = shoulder_residual < tol;

    let (wrist, wrist_residual, wrist_spherical) = if wrist_fit_residual < tol {
        (wrist_fit, wrist_fit_residual, true)
    } else if let Some(w) = intersection(&points[4], &axes[4], &points[5], &axes[5], tol)
        .or_else(|| intersection(&points[5], &axes[5], &points[6], &axes[6], tol))
    {
        // A partial wrist (Panda's 5∩6, the human U-joint 6∩7) is a
        // better centre than the least-squares point of all three.
        (w, 0.0, false)
    } else {
        (wrist_fit, wrist_fit_residual, false)
    };

    let upper_arm_length = (elbow - shoulder).norm();
    let forearm_length = (wrist - elbow).norm();
    if upper_arm_length < 1e-6 || forearm_length < 1e-6 {
        return Err(format!(
            "degenerate limb lengths (upper arm {upper_arm_length:.6} m, forearm {forearm_length:.6} m)"
        ));
    }
    let (short, long) =
        (upper_arm_length.min(forearm_length), upper_arm_length.max(forearm_length));
    if short < SHORTEST_LIMB_RELATIVE * long {
        return Err(format!(
            "a segment far too short (upper arm {upper_arm_length:.4} m, forearm \
             {forearm_length:.4} m): the chain likely starts or ends one joint off"
        ));
    }
    if shoulder_residual > NEAR_POINT_RELATIVE * upper_arm_length {
        return Err(format!(
            "no shoulder: the first three axes miss one point by {shoulder_residual:.4} m (RMS) \
             against an upper arm of {upper_arm_length:.4} m (a torso joint in the chain?)"
        ));
    }
    if wrist_residual > NEAR_POINT_RELATIVE * forearm_length {
        return Err(format!(
            "no wrist: the last three axes miss one point by {wrist_residual:.4} m (RMS) \
             against a forearm of {forearm_length:.4} m (a gripper joint in the chain?)"
        ));
    }
    let elbow_offsets = [
        line_distance(&points[2], &axes[2], &points[3], &axes[3]),
        line_distance(&points[3], &axes[3], &points[4], &axes[4]),
    ];
    let wrist_miss = [4, 5]
        .iter()
        .map(|&i| projector(&axes[i]).mul(&(wrist - points[i])).norm())
        .fold(0.0, Real::max);
    let wrist_decoupled = wrist_miss < tol;
    let idealisation = shoulder_residual.max(wrist_miss);
    let is_srs = shoulder_spherical && wrist_spherical && elbow_offsets.iter().all(|o| *o < tol);

    // Everything below is in {b}: the base link shifted so that S is the origin.
    let axes_zero = *axes;
    let axis_points_zero = points.map(|p| p - shoulder);
    let elbow_zero = elbow - shoulder;
    let wrist_zero = wrist - shoulder;
    let elbow_in_frame3 = frames_zero[3].inverse_transform_point(&elbow.into()).coords;
    let wrist_in_frame6 = frames_zero[6].inverse_transform_point(&wrist.into()).coords;

    Ok(ArmStructure {
        shoulder_in_base_link: shoulder,
        elbow_zero,
        wrist_zero,
        upper_arm_length,
        forearm_length,
        elbow_offsets,
        shoulder_spherical,
        wrist_spherical,
        wrist_decoupled,
        is_srs,
        shoulder_residual,
        wrist_residual,
        idealisation,
        axes_zero,
        axis_points_zero,
        hand_zero,
        elbow_in_frame3,
        wrist_in_frame6,
    })
}
