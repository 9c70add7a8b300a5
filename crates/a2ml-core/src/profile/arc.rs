//! The semi-elliptic wrist path of `path Pw arc through P` (paper §6.3, fig. 12): half an
//! ellipse from the start to the goal through a given point, parameterised by its eccentric
//! angle φ ∈ [0, π] (φ = 0 at the start, π at the goal), which is the path's distance for the
//! bell profile.

use super::ProfileError;
use crate::math::{PI, Real, Vector3};

/// Half an ellipse from `start` to `end`: X(φ) = C − a cos φ + b sin φ, with C the chord's
/// middle, a half the chord and b the semi-axis perpendicular to it (m, {b}). Past [0, π] the
/// formula goes on round the whole ellipse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SemiEllipse {
    centre: Vector3,
    half_chord: Vector3,
    bulge: Vector3,
}

impl SemiEllipse {
    /// The semi-ellipse from `start` to `end` through `through`: its plane holds the three
    /// points and its axes are the chord and the direction normal to it in that plane.
    ///
    /// # Errors
    /// [`ProfileError::NonFinite`] for non-finite points, [`ProfileError::DegenerateArc`]
    /// when start and end coincide, when `through` lies on the chord's line, or when it does
    /// not lie strictly between the ends along the chord (no half ellipse on that chord
    /// passes through it).
    pub fn through(start: Vector3, end: Vector3, through: Vector3) -> Result<Self, ProfileError> {
        for (p, what) in [(start, "arc start"), (end, "arc end"), (through, "arc point")] {
            if !p.iter().all(|x| x.is_finite()) {
                return Err(ProfileError::NonFinite { what });
            }
        }
        let centre = (start + end) * 0.5;
        let half_chord = (end - start) * 0.5;
        let half = half_chord.norm();
        let degenerate = |reason: &'static str| Err(ProfileError::DegenerateArc { reason });
        if half < 1e-9 {
            return degenerate("its start and goal coincide");
        }
        let axis = half_chord / half;
        let d = through - centre;
        let along = d.dot(&axis);
        let normal = d - axis * along;
        if normal.norm() < 1e-9 * (1.0 + d.norm()) {
            return degenerate("the point lies on the line from the start to the goal");
        }
        // X(φp) = through: C − a cos φp + b sin φp, so cos φp = −along / |a|.
        let cos = -along / half;
        if cos.abs() >= 1.0 - 1e-9 {
            return degenerate("the point does not lie between the start and the goal along it");
        }
        let sin = (1.0 - cos * cos).sqrt();
        Ok(Self { centre, half_chord, bulge: normal / sin })
    }

    /// X(φ) (m, {b}).
    pub fn at(&self, phi: Real) -> Vector3 {
        self.centre - self.half_chord * phi.cos() + self.bulge * phi.sin()
    }

    /// dX/dφ (m/rad).
    pub fn tangent(&self, phi: Real) -> Vector3 {
        self.half_chord * phi.sin() + self.bulge * phi.cos()
    }

    /// The start of the arc, X(0).
    pub fn start(&self) -> Vector3 {
        self.at(0.0)
    }

    /// The end of the arc, X(π).
    pub fn end(&self) -> Vector3 {
        self.at(PI)
    }

    /// The farthest point of the arc from its chord, X(π/2).
    pub fn apex(&self) -> Vector3 {
        self.at(0.5 * PI)
    }

    /// The φ (in (−π, π]) of the ellipse's point nearest to `p`: the eccentric angle of p's
    /// projection on the ellipse's plane, then Newton on d/dφ |X(φ) − p|² = 0.
    pub fn nearest(&self, p: &Vector3) -> Real {
        let d = p - self.centre;
        let x = -d.dot(&self.half_chord) / self.half_chord.norm_squared();
        let y = d.dot(&self.bulge) / self.bulge.norm_squared();
        let mut phi = y.atan2(x);
        for _ in 0..20 {
            let (r, t) = (self.at(phi) - p, self.tangent(phi));
            let second = self.half_chord * phi.cos() - self.bulge * phi.sin();
            let (f, df) = (t.dot(&r), second.dot(&r) + t.norm_squared());
            // Newton only where the squared distance is convex; else a gradient step.
            let step = if df > 1e-12 { f / df } else { f / t.norm_squared().max(1e-12) };
            let step = step.clamp(-0.5, 0.5);
            phi -= step;
            if step.abs() < 1e-13 {
                break;
            }
        }
        crate::math::wrap_angle(phi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc() -> SemiEllipse {
        let (a, b) = (Vector3::new(0.18, 0.1, -0.16), Vector3::new(0.27, -0.1, 0.05));
        SemiEllipse::through(a, b, Vector3::new(0.15, 0.0, -0.02)).expect("an arc")
    }

    #[test]
    fn runs_from_start_through_the_point_to_the_end() {
        let (a, b, p) = (
            Vector3::new(0.18, 0.1, -0.16),
            Vector3::new(0.27, -0.1, 0.05),
            Vector3::new(0.15, 0.0, -0.02),
        );
        let e = SemiEllipse::through(a, b, p).expect("an arc");
        assert!((e.start() - a).norm() < 1e-12 && (e.end() - b).norm() < 1e-12);
        let phi = e.nearest(&p);
        assert!((e.at(phi) - p).norm() < 1e-10, "{phi}");
        assert!(phi > 0.0 && phi < PI);
    }

    #[test]
    fn nearest_is_the_nearest_point_and_the_tangent_its_derivative() {
        let e = arc();
        for k in 0..50 {
            let phi = -3.0 + 0.12 * k as Real;
            let (h, t) = (1e-6, e.tangent(phi));
            let numeric = (e.at(phi + h) - e.at(phi - h)) / (2.0 * h);
            assert!((numeric - t).norm() < 1e-8);
            // A point off the curve along the normal in the plane comes back to φ.
            let normal = (e.bulge.cross(&e.half_chord)).cross(&t).normalize();
            let off = e.at(phi) + normal * 0.005;
            let found = e.nearest(&off);
            let d = (e.at(found) - off).norm();
            let brute = (0..20000)
                .map(|i| (e.at(-PI + i as Real * 2.0 * PI / 20000.0) - off).norm())
                .fold(Real::INFINITY, Real::min);
            assert!(d <= brute + 1e-9, "{phi}: {d} against {brute}");
        }
    }

    #[test]
    fn degenerate_arcs_are_errors() {
        let (a, b) = (Vector3::zeros(), Vector3::x());
        for p in [Vector3::new(0.5, 0.0, 0.0), Vector3::new(1.5, 0.1, 0.0)] {
            assert!(matches!(
                SemiEllipse::through(a, b, p),
                Err(ProfileError::DegenerateArc { .. })
            ));
        }
        assert!(SemiEllipse::through(a, a, Vector3::y()).is_err());
        assert!(SemiEllipse::through(a, b, Vector3::new(Real::NAN, 0.0, 0.0)).is_err());
    }
}
