//! The reference of a rotation, Ow or Os: a geodesic, a turn about a fixed axis, or a hold.

use super::{finite_rotation, signed_motion};
use crate::math::{Real, Rotation3, Vector3, rotation_about, rotation_log, skew};
use crate::profile::{BellProfile, ProfileError};

/// The path of a rotation reference (Ow or Os).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RotationPath {
    /// The rotation stays at the start (distance 0).
    Hold,
    /// R(t) = Rot(axis, s(t)) R0 about an axis fixed in {b}; the angle (rad) is the bell's
    /// distance. A goal's geodesic is this with axis = R0 log(R0ᵀ R1)/|log(R0ᵀ R1)|.
    About {
        /// Unit axis in {b}.
        axis: Vector3,
    },
}

/// The reference of a rotation Ow or Os in {b}: a geodesic to a goal, a rotation about a
/// fixed axis, or a hold. Its velocity is the angular velocity ω in {b} (`Ṙ = [ω]× R`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotationReference {
    start: Rotation3,
    path: RotationPath,
    bell: BellProfile,
}

impl RotationReference {
    /// The rotation kept at `start` for `duration` (s).
    ///
    /// # Errors
    /// Non-finite start or invalid duration.
    pub fn hold(start: Rotation3, duration: Real) -> Result<Self, ProfileError> {
        finite_rotation(&start, "start rotation")?;
        Ok(Self { start, path: RotationPath::Hold, bell: BellProfile::new(duration, 0.0)? })
    }

    /// The geodesic from `start` to `goal`: R(t) = R0 exp(fraction(t) log(R0ᵀ R1)), the
    /// rotation about the shortest axis by the geodesic angle in [0, π]; a hold when they
    /// coincide.
    ///
    /// # Errors
    /// Non-finite inputs or an invalid duration.
    pub fn goal(start: Rotation3, goal: Rotation3, duration: Real) -> Result<Self, ProfileError> {
        finite_rotation(&start, "start rotation")?;
        finite_rotation(&goal, "goal rotation")?;
        // The body-frame rotation vector φ = log(R0ᵀ R1). Since R0 exp(f [φ]×) R0ᵀ is the
        // rotation about R0 φ by f |φ|, the geodesic R0 exp(f [φ]×) turns about the fixed
        // axis R0 φ / |φ| of {b} by f |φ|.
        let phi = rotation_log(&(start.inverse() * goal));
        let angle = phi.norm();
        if angle == 0.0 {
            return Self::hold(start, duration);
        }
        let axis = start * (phi / angle);
        Ok(Self {
            start,
            path: RotationPath::About { axis },
            bell: BellProfile::new(duration, angle)?,
        })
    }

    /// The rotation turning about `axis` (normalised, in {b}) by the signed `angle` (rad):
    /// R(t) = Rot(axis, s(t)) R0.
    ///
    /// # Errors
    /// Non-finite inputs, a zero axis, or an invalid duration.
    pub fn about(
        start: Rotation3,
        axis: &Vector3,
        angle: Real,
        duration: Real,
    ) -> Result<Self, ProfileError> {
        finite_rotation(&start, "start rotation")?;
        let (axis, bell) = signed_motion(axis, angle, duration, ("angle", "axis"))?;
        Ok(Self { start, path: RotationPath::About { axis }, bell })
    }

    /// The rotation at t = 0.
    pub fn start(&self) -> Rotation3 {
        self.start
    }

    /// The path.
    pub fn path(&self) -> RotationPath {
        self.path
    }

    /// The speed profile (distance in rad).
    pub fn bell(&self) -> &BellProfile {
        &self.bell
    }

    /// The rotation at t = T.
    pub fn end(&self) -> Rotation3 {
        self.sample(self.bell.duration()).0
    }

    /// The rotation and its angular velocity (rad/s, in {b}) at t (s), clamped to [0, T].
    pub fn sample(&self, t: Real) -> (Rotation3, Vector3) {
        let r = self.at_distance(self.bell.progress(t));
        match self.path {
            RotationPath::Hold => (r, Vector3::zeros()),
            RotationPath::About { axis } => (r, axis * self.bell.speed(t)),
        }
    }

    /// The angle (rad, in (-π, π]) along the path of the path's rotation nearest to `r` (the
    /// smallest geodesic angle); 0 for a hold. With M = R R0ᵀ and a the axis,
    /// tr(Rot(a, s)ᵀ M) = aᵀMa + (tr M − aᵀMa) cos s − tr(\[a\]× M) sin s, largest at
    /// s = atan2(−tr(\[a\]× M), tr M − aᵀMa).
    pub fn nearest_distance(&self, r: &Rotation3) -> Real {
        match self.path {
            RotationPath::Hold => 0.0,
            RotationPath::About { axis } => {
                let m = r.matrix() * self.start.matrix().transpose();
                let along = axis.dot(&(m * axis));
                (-(skew(&axis) * m).trace()).atan2(m.trace() - along)
            }
        }
    }

    /// The rotation after turning by `s` (rad) along the path, not limited to the bell's
    /// distance.
    pub fn at_distance(&self, s: Real) -> Rotation3 {
        match self.path {
            RotationPath::Hold => self.start,
            RotationPath::About { axis } => {
                Rotation3::from_matrix_unchecked(rotation_about(&axis, s) * self.start.matrix())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::rot;
    use super::*;
    use crate::math::rotation_distance;

    #[test]
    fn geodesic_matches_the_exponential_form() {
        let r0 = rot(Vector3::new(0.3, -0.2, 0.9), 0.7);
        let r1 = rot(Vector3::new(-0.5, 0.4, 0.1), 2.1);
        let reference = RotationReference::goal(r0, r1, 1.5).expect("valid");
        let phi = rotation_log(&(r0.inverse() * r1));
        for t in [0.0, 0.2, 0.75, 1.1, 1.5] {
            let f = reference.bell().fraction(t);
            let expected = r0 * Rotation3::new(phi * f);
            let (r, omega) = reference.sample(t);
            assert!(rotation_distance(&r, &expected) < 1e-14, "t {t}");
            // ω in {b} = R0 φ f'(t).
            let expected_omega = r0 * phi * reference.bell().fraction_rate(t);
            assert!((omega - expected_omega).norm() < 1e-14);
        }
    }
}
