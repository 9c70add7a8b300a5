//! Scalar type, aliases and the few geometric helpers every stage shares.
//!
//! Points and free vectors are both [`Vector3`]; rotations are matrices
//! ([`Rotation3`]) because the kinematics multiplies far more than it stores.

use nalgebra::{SMatrix, SVector};

/// The scalar type of the whole library.
pub type Real = f64;
/// Number of joints of an anthropomorphic arm.
pub const DOF: usize = 7;
/// A 3-vector: a point or a direction.
pub type Vector3 = nalgebra::Vector3<Real>;
/// A 3x3 matrix.
pub type Matrix3 = nalgebra::Matrix3<Real>;
/// A rotation stored as an orthonormal matrix.
pub type Rotation3 = nalgebra::Rotation3<Real>;
/// A unit quaternion (used for output: w, x, y, z).
pub type UnitQuaternion = nalgebra::UnitQuaternion<Real>;
/// A translation.
pub type Translation3 = nalgebra::Translation3<Real>;
/// A rigid transform with a matrix rotation, `parent_from_child`.
pub type Isometry = nalgebra::IsometryMatrix3<Real>;
/// Joint positions or velocities of the 7 joints.
pub type JointVector = SVector<Real, DOF>;
/// The geometric Jacobian: linear velocity (rows 0-2) and angular velocity (rows 3-5).
pub type Jacobian6x7 = SMatrix<Real, 6, DOF>;
/// A point (or direction) Jacobian.
pub type Jacobian3x7 = SMatrix<Real, 3, DOF>;
/// A square task Jacobian (J_cs or J_tr).
pub type Matrix7 = SMatrix<Real, DOF, DOF>;
/// A 7-vector in a task space: CPSA [Pw, ω_w, θsw] or HAT [ω_s, θe, ω_w].
pub type Vector7 = SVector<Real, DOF>;

/// π, spelled once.
pub const PI: Real = std::f64::consts::PI;

/// Rotation matrix about the unit `axis` by `angle` (Rodrigues).
#[inline]
pub fn rotation_about(axis: &Vector3, angle: Real) -> Matrix3 {
    let (s, c) = angle.sin_cos();
    rotation_from_sin_cos(axis, s, c)
}

/// [`rotation_about`] for an angle whose sine `s` and cosine `c` are at hand (IK has them
/// from the root it solved for): the same matrix, bit for bit, without the trigonometry.
pub fn rotation_from_sin_cos(axis: &Vector3, s: Real, c: Real) -> Matrix3 {
    let t = 1.0 - c;
    let (x, y, z) = (axis.x, axis.y, axis.z);
    Matrix3::new(
        t * x * x + c,
        t * x * y - s * z,
        t * x * z + s * y,
        t * x * y + s * z,
        t * y * y + c,
        t * y * z - s * x,
        t * x * z - s * y,
        t * y * z + s * x,
        t * z * z + c,
    )
}

/// The skew-symmetric matrix with `[v]× w = v × w`.
#[inline]
pub fn skew(v: &Vector3) -> Matrix3 {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Wraps an angle into (-π, π].
#[inline]
pub fn wrap_angle(a: Real) -> Real {
    // `rem_euclid` of a value already in [0, 2π) is that value, bit for bit; IK wraps
    // thousands of such angles per plan, and the remainder is a software `fmod`.
    let shifted = a + PI;
    let turned =
        if (0.0..2.0 * PI).contains(&shifted) { shifted } else { shifted.rem_euclid(2.0 * PI) };
    let w = turned - PI;
    if w <= -PI { w + 2.0 * PI } else { w }
}

/// (R - Rᵀ)/2 as a vector: sin θ times the rotation axis.
#[inline]
fn skew_part(m: &Matrix3) -> Vector3 {
    0.5 * Vector3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)])
}

/// The angle of a rotation in [0, π], accurate near 0 and π alike (the
/// usual acos of the trace loses half the digits near 0).
#[inline]
pub fn rotation_angle(r: &Rotation3) -> Real {
    let m = r.matrix();
    skew_part(m).norm().atan2(0.5 * (m.trace() - 1.0))
}

/// The rotation vector (axis × angle) of `r`, angle in [0, π].
pub fn rotation_log(r: &Rotation3) -> Vector3 {
    let m = r.matrix();
    let v = skew_part(m);
    let (s, c) = (v.norm(), 0.5 * (m.trace() - 1.0));
    let angle = s.atan2(c);
    if c > -0.9 {
        // θ/sin θ is well conditioned here, including θ -> 0.
        return if s < 1e-300 { Vector3::zeros() } else { v * (angle / s) };
    }
    // Near π the axis comes from the symmetric part: k kᵀ = (sym(R) - c I) / (1 - c).
    let kk = (0.5 * (m + m.transpose()) - Matrix3::identity() * c) / (1.0 - c);
    let i = (0..3).max_by(|&a, &b| kk[(a, a)].total_cmp(&kk[(b, b)])).unwrap_or(0);
    let mut k: Vector3 = kk.column(i) / kk[(i, i)].max(1e-300).sqrt();
    if k.dot(&v) < 0.0 {
        k = -k;
    }
    k.normalize() * angle
}

/// The geodesic angle between two rotations.
#[inline]
pub fn rotation_distance(a: &Rotation3, b: &Rotation3) -> Real {
    rotation_angle(&(a.inverse() * b))
}

/// Projection of `v` onto the plane orthogonal to the unit `n`.
#[inline]
pub fn reject(v: &Vector3, n: &Vector3) -> Vector3 {
    v - n * n.dot(v)
}

/// `I - n nᵀ` for a unit `n`.
#[inline]
pub fn projector(n: &Vector3) -> Matrix3 {
    Matrix3::identity() - n * n.transpose()
}

/// The solutions θ in (-π, π] of `a cos θ + b sin θ = c` (none, one or two).
pub fn solve_trig(a: Real, b: Real, c: Real) -> Few<Real, 2> {
    // Coefficients here are lengths and products of arm dimensions: no overflow risk, and
    // sqrt is several times faster than hypot.
    let mut roots = Few::new(0.0);
    let rho = (a * a + b * b).sqrt();
    if rho < 1e-14 {
        return roots;
    }
    let ratio = c / rho;
    if ratio.abs() > 1.0 + 1e-12 {
        return roots;
    }
    let phi = b.atan2(a);
    let delta = ratio.clamp(-1.0, 1.0).acos();
    if delta < 1e-12 {
        roots.push(wrap_angle(phi));
    } else {
        roots.push(wrap_angle(phi + delta));
        roots.push(wrap_angle(phi - delta));
    }
    roots
}

/// At most `N` values, kept inline: IK finds a few roots and placements per call, and a
/// heap allocation for each was a measurable share of a call. Reads as a slice.
#[derive(Debug, Clone, Copy)]
pub struct Few<T: Copy, const N: usize> {
    items: [T; N],
    len: usize,
}

impl<T: Copy, const N: usize> Few<T, N> {
    /// None yet; `fill` only occupies the unused places.
    pub const fn new(fill: T) -> Self {
        Self { items: [fill; N], len: 0 }
    }

    /// Appends `value`.
    ///
    /// # Panics
    /// When `N` values are already there: the callers push at most `N` by construction
    /// (roots of one trigonometric equation, one placement per root).
    pub fn push(&mut self, value: T) {
        self.items[self.len] = value;
        self.len += 1;
    }
}

impl<T: Copy, const N: usize> std::ops::Deref for Few<T, N> {
    type Target = [T];

    fn deref(&self) -> &[T] {
        &self.items[..self.len]
    }
}

impl<T: Copy, const N: usize> IntoIterator for Few<T, N> {
    type Item = T;
    type IntoIter = std::iter::Take<std::array::IntoIter<T, N>>;

    fn into_iter(self) -> Self::IntoIter {
        self.items.into_iter().take(self.len)
    }
}

/// Distance between the segments p1–q1 and p2–q2 (Ericson, Real-Time Collision Detection
/// §5.1.9).
pub fn segment_segment_distance(p1: &Vector3, q1: &Vector3, p2: &Vector3, q2: &Vector3) -> Real {
    let (s, t) = segment_segment_closest(p1, q1, p2, q2);
    ((p1 + (q1 - p1) * s) - (p2 + (q2 - p2) * t)).norm()
}

/// The parameters (s, t) in [0, 1]² of the closest points p1 + s (q1 − p1) and
/// p2 + t (q2 − p2) of two segments (Ericson, Real-Time Collision Detection, 5.1.9); for
/// parallel segments one of the closest pairs.
pub fn segment_segment_closest(
    p1: &Vector3,
    q1: &Vector3,
    p2: &Vector3,
    q2: &Vector3,
) -> (Real, Real) {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.norm_squared(), d2.norm_squared(), d2.dot(&r));
    let tiny = Real::MIN_POSITIVE;
    if a <= tiny && e <= tiny {
        (0.0, 0.0)
    } else if a <= tiny {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= tiny {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denominator = a * e - b * b;
            // Parallel segments: any s works; start from p1.
            let s = if denominator > 0.0 {
                ((b * f - c * e) / denominator).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t = (b * s + f) / e;
            if t < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s, t)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rodrigues_matches_nalgebra() {
        let axis = Vector3::new(0.3, -0.5, 0.8).normalize();
        let ours = rotation_about(&axis, 1.234);
        let theirs = Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), 1.234);
        assert!((ours - theirs.matrix()).norm() < 1e-14);
    }

    #[test]
    fn rotation_log_is_accurate_at_small_and_large_angles() {
        let axis = Vector3::new(0.2, 0.9, -0.4).normalize();
        for angle in [0.0, 1e-12, 2e-6, 0.3, 2.5, PI - 1e-7, PI] {
            let r = Rotation3::from_matrix_unchecked(rotation_about(&axis, angle));
            let log = rotation_log(&r);
            assert!(
                (log - axis * angle).norm() < 1e-13
                    || (angle == PI && (log + axis * angle).norm() < 1e-13),
                "angle {angle}: {log:?}"
            );
            assert!((rotation_angle(&r) - angle).abs() < 1e-15 * angle.max(1.0) * 10.0);
        }
    }

    #[test]
    fn wrap_is_half_open() {
        assert_eq!(wrap_angle(PI), PI);
        assert_eq!(wrap_angle(-PI), PI);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-15);
    }

    #[test]
    fn trig_roots_satisfy_equation() {
        for (a, b, c) in [(1.0, 2.0, 0.5), (-0.3, 0.1, 0.2), (0.0, 1.0, -1.0)] {
            let roots = solve_trig(a, b, c);
            assert!(!roots.is_empty());
            for t in roots {
                assert!((a * t.cos() + b * t.sin() - c).abs() < 1e-12);
            }
        }
        assert!(solve_trig(1.0, 0.0, 2.0).is_empty());
    }

    #[test]
    fn wrap_angle_fast_path_keeps_the_bits_of_the_remainder() {
        // In [0, 2π) after the shift, the remainder is the value itself: the fast path must
        // give what the remainder gives, bit for bit, on both sides of every boundary.
        let general = |a: Real| {
            let w = (a + PI).rem_euclid(2.0 * PI) - PI;
            if w <= -PI { w + 2.0 * PI } else { w }
        };
        let mut a: Real = -7.0;
        while a < 7.0 {
            for x in [a, -PI, PI, PI.next_down(), (-PI).next_up(), 0.0, -0.0] {
                assert_eq!(wrap_angle(x).to_bits(), general(x).to_bits(), "{x}");
            }
            a += 1e-3;
        }
    }

    #[test]
    fn few_reads_as_the_values_pushed() {
        let mut few: Few<Real, 2> = Few::new(0.0);
        assert!(few.is_empty());
        few.push(1.5);
        few.push(-2.0);
        assert_eq!(&few[..], &[1.5, -2.0]);
        assert_eq!(few.into_iter().collect::<Vec<_>>(), vec![1.5, -2.0]);
    }
}
