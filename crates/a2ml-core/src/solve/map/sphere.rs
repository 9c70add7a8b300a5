//! The elbow circle and the forbidden swivel interval of a sphere (METHODS.md §1.3 step 2).
//!
//! As θsw changes with Pw fixed, the arm turns rigidly about the S–W axis x. A segment lying
//! in a half-plane bounded by that axis (the upper arm S–E, the forearm E–W) keeps its
//! shape in (axial, radial) coordinates and only changes phase; its distance to a sphere
//! centre O is even in the phase difference δ and non-decreasing on [0, π], so a sphere
//! forbids one symmetric interval of phases (or none, or all).

use crate::kinematics::{KinematicsError, Singularity};
use crate::math::{PI, Real, Vector3};

/// The circle of elbow positions for a wrist position Pw (paper Fig. 3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElbowCircle {
    /// x = Pw/|Pw|, the S–W axis.
    pub x: Vector3,
    /// e1 = n × x: phase 0, the elbow-down half-plane (θsw = 0).
    pub e1: Vector3,
    /// e2 = n, the normal of the vertical plane through S and W.
    pub e2: Vector3,
    /// c_e = lu cos β: the circle centre's distance from S along x (m).
    pub centre: Real,
    /// ρ_e = lu sin β: the circle radius (m).
    pub radius: Real,
    /// d = |Pw| (m).
    pub reach: Real,
}

impl ElbowCircle {
    /// The circle of an arm with upper arm `lu` and forearm `lf` (m) reaching `pw`; `vertical`
    /// is z_b.
    ///
    /// # Errors
    /// [`KinematicsError::Unreachable`] outside |lu − lf| ≤ |Pw| ≤ lu + lf;
    /// [`Singularity::WristAboveShoulder`] when Pw is parallel to z_b.
    pub fn new(
        lu: Real,
        lf: Real,
        pw: &Vector3,
        vertical: &Vector3,
    ) -> Result<Self, KinematicsError> {
        let reach = pw.norm();
        if !(reach >= (lu - lf).abs() && reach <= lu + lf) {
            return Err(KinematicsError::Unreachable {
                distance: reach,
                min: (lu - lf).abs(),
                max: lu + lf,
            });
        }
        let m = vertical.cross(pw);
        if m.norm() < 1e-9 {
            return Err(KinematicsError::Singular(Singularity::WristAboveShoulder));
        }
        let (x, n) = (pw / reach, m.normalize());
        let cos_beta = ((lu * lu + reach * reach - lf * lf) / (2.0 * lu * reach)).clamp(-1.0, 1.0);
        let sin_beta = (1.0 - cos_beta * cos_beta).max(0.0).sqrt();
        Ok(Self { x, e1: n.cross(&x), e2: n, centre: lu * cos_beta, radius: lu * sin_beta, reach })
    }

    /// E(φ) = c_e x + ρ_e (cos φ e1 + sin φ e2); the project's swivel is θsw = −φ.
    pub fn elbow(&self, phi: Real) -> Vector3 {
        let (s, c) = phi.sin_cos();
        self.x * self.centre + (self.e1 * c + self.e2 * s) * self.radius
    }

    /// A point in (axial, radial, phase) coordinates about the S–W axis.
    pub fn cylindrical(&self, p: &Vector3) -> (Real, Real, Real) {
        let axial = p.dot(&self.x);
        let perp = p - self.x * axial;
        (axial, perp.norm(), perp.dot(&self.e2).atan2(perp.dot(&self.e1)))
    }
}

/// A capsule whose segment lies in a half-plane bounded by the S–W axis, in (axial, radial)
/// coordinates of its two ends (radial ≥ 0), with its radius (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxialCapsule {
    /// One end: (axial, radial) (m).
    pub a: (Real, Real),
    /// The other end (m).
    pub b: (Real, Real),
    /// Capsule radius (m).
    pub radius: Real,
}

/// What one sphere forbids of one capsule's phases at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HalfWidth {
    /// No phase collides.
    Empty,
    /// Phases within this half-width (rad, in (0, π)) of the sphere's phase collide.
    Within(Real),
    /// Every phase collides.
    Full,
}

/// The distance from a sphere centre at (axial, radial) = `centre`, phase 0, to the capsule's
/// segment turned to phase `delta`.
pub fn segment_distance(capsule: &AxialCapsule, centre: (Real, Real), delta: Real) -> Real {
    let (s, c) = delta.sin_cos();
    let at = |(h, r): (Real, Real)| Vector3::new(h, r * c, r * s);
    let (a, b, o) = (at(capsule.a), at(capsule.b), Vector3::new(centre.0, centre.1, 0.0));
    let ab = b - a;
    let length2 = ab.norm_squared();
    let t = if length2 > 0.0 { ((o - a).dot(&ab) / length2).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * t - o).norm()
}

/// The half-width of the phases at which `capsule` comes closer than `clearance` (m) to a
/// sphere of radius `sphere_radius` whose centre is at (axial, radial) = `centre`: the
/// METHODS.md §1.3 theorem with the root of g(δ) = distance − (r_o + ρ + clearance) found by
/// bisection to 1e-12 rad.
pub fn half_width(
    capsule: &AxialCapsule,
    centre: (Real, Real),
    sphere_radius: Real,
    clearance: Real,
) -> HalfWidth {
    let reach = sphere_radius + capsule.radius + clearance;
    let g = |delta: Real| segment_distance(capsule, centre, delta) - reach;
    if g(PI) < 0.0 {
        return HalfWidth::Full;
    }
    if g(0.0) >= 0.0 {
        return HalfWidth::Empty;
    }
    let (mut inside, mut outside) = (0.0, PI);
    while outside - inside > 1e-12 {
        let mid = 0.5 * (inside + outside);
        if g(mid) < 0.0 { inside = mid } else { outside = mid }
    }
    HalfWidth::Within(0.5 * (inside + outside))
}
