//! The arm's collision capsules, never silently absent. Per link, in order of
//! preference: the URDF's own capsules, cylinders and spheres; a capsule
//! enclosing each box; a capsule fitted to each mesh (collision meshes, else
//! visual ones) found through the package path; and wherever a part of the
//! arm (upper arm, forearm, hand) is left without them, a capsule around its
//! kinematic skeleton (S-E, E-W, W-tool). mesh-loader enters the library
//! here and nowhere else.

use std::path::{Path, PathBuf};

use super::structure::ArmStructure;
use super::urdf::{Document, Geometry, Shape};
use super::{Capsule, ChainLink, LinkRole, RobotError};
use crate::math::{DOF, Isometry, Matrix3, Real, Vector3};
use nalgebra::Point3;

/// Skeleton capsule radius when the user sets none (m): a human forearm's
/// radius with a margin, and of the order of the links of the 7-DoF arms
/// tried (iiwa, Panda, Sawyer, TIAGo).
pub const DEFAULT_SKELETON_RADIUS: Real = 0.06;

/// Where a capsule came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CapsuleSource {
    /// A URDF capsule, cylinder or sphere.
    Shape,
    /// Encloses a URDF box.
    Box,
    /// Fitted to the vertices of a URDF mesh.
    Mesh,
    /// Around the kinematic skeleton (no URDF geometry could be used).
    Skeleton,
}

impl CapsuleSource {
    /// The snake_case name used in outputs.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Shape => "shape",
            Self::Box => "box",
            Self::Mesh => "mesh",
            Self::Skeleton => "skeleton",
        }
    }
}

/// How the capsules are found when the URDF has no capsule shapes.
#[derive(Debug, Clone)]
pub struct GeometryOptions {
    /// Folders searched for `package://NAME/...` mesh files: each is either
    /// a package (its name is NAME) or holds packages; the CLI fills it from
    /// `--package-path`, `A2ML_PACKAGE_PATH` and `ROS_PACKAGE_PATH`.
    pub package_path: Vec<PathBuf>,
    /// Folder of the URDF file: relative mesh names start here, and its
    /// ancestors named NAME count as package NAME.
    pub urdf_dir: Option<PathBuf>,
    /// Radius of the skeleton capsules (m); `None` leaves parts without
    /// usable geometry uncovered, which `a2ml robot` reports and planning
    /// with obstacles refuses.
    pub skeleton_radius: Option<Real>,
    /// The SRDF whose `<disable_collisions>` pairs are not checked; a file beside the URDF
    /// with its name and the extension `.srdf` when none is given.
    pub srdf: Option<PathBuf>,
}

impl Default for GeometryOptions {
    fn default() -> Self {
        Self {
            package_path: Vec::new(),
            urdf_dir: None,
            skeleton_radius: Some(DEFAULT_SKELETON_RADIUS),
            srdf: None,
        }
    }
}

/// The S-E, E-W and W-tool segments, each in the moving frame that carries it.
pub(super) struct Skeleton {
    /// (role, frame, a, b) per part.
    parts: [(LinkRole, usize, Vector3, Vector3); 3],
}

impl Skeleton {
    /// From the structure and the zero-configuration frames (in the base
    /// link); `tip_in_frame7` is the tip link's origin.
    pub(super) fn new(
        s: &ArmStructure,
        frames_zero: &[Isometry; DOF + 1],
        tip_in_frame7: Vector3,
    ) -> Self {
        let in_frame = |k: usize, p: &Vector3| -> Vector3 {
            frames_zero[k].inverse_transform_point(&Point3::from(*p)).coords
        };
        let shoulder = s.shoulder_in_base_link;
        let elbow = s.elbow_zero + shoulder;
        let wrist = s.wrist_zero + shoulder;
        let mut tool = tip_in_frame7;
        let wrist7 = in_frame(7, &wrist);
        // A tip at the wrist centre still has a hand: reach a forearm's
        // tenth past W along the tool's offset, or along frame 7's z.
        if (tool - wrist7).norm() < 0.1 * s.forearm_length {
            tool = wrist7 + Vector3::z() * 0.1 * s.forearm_length;
        }
        Self {
            parts: [
                (LinkRole::UpperArm, 3, in_frame(3, &shoulder), s.elbow_in_frame3),
                (LinkRole::Forearm, 4, in_frame(4, &elbow), in_frame(4, &wrist)),
                (LinkRole::Hand, 7, wrist7, tool),
            ],
        }
    }
}

/// Why a link's geometry gave no capsule.
struct Missing {
    link: String,
    role: LinkRole,
    why: String,
}

/// The capsules of the chain's links, and a warning for each that is not a
/// URDF shape.
///
/// # Errors
/// [`RobotError::Urdf`] when a mesh file exists but cannot be read.
pub(super) fn build(
    urdf: &Document,
    links: &[ChainLink],
    skeleton: &Skeleton,
    options: &GeometryOptions,
) -> Result<(Vec<Capsule>, Vec<String>), RobotError> {
    let mut capsules = Vec::new();
    let mut missing: Vec<Missing> = Vec::new();
    let mut warnings = Vec::new();
    for chain_link in links {
        let Some(link) = urdf.links.iter().find(|l| l.name == chain_link.name) else { continue };
        let geometries = if link.collisions.is_empty() { &link.visuals } else { &link.collisions };
        let role = LinkRole::of_frame(chain_link.frame);
        for g in geometries {
            match capsule_of(g, options) {
                Ok(Some((a, b, radius, source))) => {
                    let frame_from_shape = chain_link.frame_from_link;
                    capsules.push(Capsule {
                        name: g.name.clone().unwrap_or_else(|| link.name.clone()),
                        link: link.name.clone(),
                        role,
                        frame: chain_link.frame,
                        a: frame_from_shape.transform_point(&Point3::from(a)).coords,
                        b: frame_from_shape.transform_point(&Point3::from(b)).coords,
                        radius,
                        source,
                    });
                }
                Ok(None) => {}
                Err(why) => missing.push(Missing {
                    link: link.name.clone(),
                    role,
                    why: format!("line {}: {why}", g.line),
                }),
            }
        }
    }
    let count = |source: CapsuleSource| capsules.iter().filter(|c| c.source == source).count();
    for (source, what) in
        [(CapsuleSource::Box, "enclose URDF boxes"), (CapsuleSource::Mesh, "are fitted to meshes")]
    {
        if count(source) > 0 {
            warnings.push(format!("{} capsules {what}, not the URDF's own shapes", count(source)));
        }
    }
    for m in &missing {
        warnings.push(format!("link `{}`: {}", m.link, m.why));
    }
    for &(role, frame, a, b) in &skeleton.parts {
        let covered =
            capsules.iter().any(|c| c.role == role && c.source != CapsuleSource::Skeleton);
        let gap = missing.iter().any(|m| m.role == role);
        if covered && !gap {
            continue;
        }
        let why = if covered { "has links without usable geometry" } else { "has no geometry" };
        match options.skeleton_radius {
            Some(radius) => {
                warnings.push(format!(
                    "the {} {why}: covered by a skeleton capsule of radius {radius} m",
                    role.as_str().replace('_', " ")
                ));
                capsules.push(Capsule {
                    name: format!("skeleton_{}", role.as_str()),
                    link: links
                        .iter()
                        .rev()
                        .find(|l| l.frame == frame)
                        .map(|l| l.name.clone())
                        .unwrap_or_default(),
                    role,
                    frame,
                    a,
                    b,
                    radius,
                    source: CapsuleSource::Skeleton,
                });
            }
            None => warnings.push(format!(
                "the {} {why}, and skeleton capsules are off: obstacles cannot be checked against it",
                role.as_str().replace('_', " ")
            )),
        }
    }
    Ok((capsules, warnings))
}

/// One geometry as a capsule (segment ends in the link frame, radius,
/// source); `Ok(None)` for a degenerate shape, `Err` with the reason when a
/// mesh cannot be used.
fn capsule_of(
    g: &Geometry,
    options: &GeometryOptions,
) -> Result<Option<(Vector3, Vector3, Real, CapsuleSource)>, String> {
    let place = |p: Vector3| g.link_from_shape.transform_point(&Point3::from(p)).coords;
    let along_z = |radius: Real, length: Real, source| {
        let half = Vector3::new(0.0, 0.0, 0.5 * length);
        Some((place(-half), place(half), radius, source))
    };
    Ok(match &g.shape {
        Shape::Cylinder { radius, length } | Shape::Capsule { radius, length } => {
            along_z(*radius, *length, CapsuleSource::Shape)
        }
        Shape::Sphere { radius } => along_z(*radius, 0.0, CapsuleSource::Shape),
        Shape::Box { size } => {
            // Along the longest side, the radius reaching the far edges.
            let k = size.imax();
            let others: Real = (0..3).filter(|&i| i != k).map(|i| size[i] * size[i]).sum();
            let radius = 0.5 * others.sqrt();
            let mut half = Vector3::zeros();
            half[k] = 0.5 * size[k];
            Some((place(-half), place(half), radius, CapsuleSource::Box))
        }
        Shape::Mesh { filename, scale } => {
            let path = resolve(filename, options)
                .ok_or_else(|| format!("mesh `{filename}` not found on the package path"))?;
            let vertices = read_vertices(&path)?;
            let points: Vec<Vector3> =
                vertices.iter().map(|v| place(v.component_mul(scale))).collect();
            fit_capsule(&points).map(|(a, b, r)| (a, b, r, CapsuleSource::Mesh))
        }
    }
    .filter(|(a, b, r, _)| {
        *r > 0.0 && a.iter().chain(b.iter()).all(|v| v.is_finite()) && r.is_finite()
    }))
}

/// The file a URDF mesh name points to, if it exists.
fn resolve(filename: &str, options: &GeometryOptions) -> Option<PathBuf> {
    if let Some(rest) = filename.strip_prefix("package://") {
        let (package, inner) = rest.split_once('/')?;
        let ancestors = options.urdf_dir.iter().flat_map(|d| d.ancestors()).map(Path::to_path_buf);
        return options
            .package_path
            .iter()
            .flat_map(|dir| [dir.join(package).join(inner), named(dir, package, inner)])
            .chain(ancestors.map(|dir| named(&dir, package, inner)))
            .find(|p| p.is_file());
    }
    let path = Path::new(filename.strip_prefix("file://").unwrap_or(filename));
    let path = match &options.urdf_dir {
        Some(dir) if path.is_relative() => dir.join(path),
        _ => path.to_path_buf(),
    };
    path.is_file().then_some(path)
}

/// `dir/inner` when `dir` is the package itself, else a path that is no file.
fn named(dir: &Path, package: &str, inner: &str) -> PathBuf {
    if dir.file_name().is_some_and(|n| n == package) { dir.join(inner) } else { PathBuf::new() }
}

fn read_vertices(path: &Path) -> Result<Vec<Vector3>, String> {
    let scene = mesh_loader::Loader::default()
        .load(path)
        .map_err(|e| format!("mesh {} cannot be read: {e}", path.display()))?;
    let vertices: Vec<Vector3> = scene
        .meshes
        .iter()
        .flat_map(|m| m.vertices.iter())
        .map(|v| Vector3::new(Real::from(v[0]), Real::from(v[1]), Real::from(v[2])))
        .collect();
    if vertices.is_empty() || vertices.iter().any(|v| !v.iter().all(|c| c.is_finite())) {
        return Err(format!("mesh {} has no usable vertices", path.display()));
    }
    Ok(vertices)
}

/// The capsule around `points` along their principal axis: the segment
/// spans their projections, the radius is the largest distance from the
/// axis, and each end is pulled in as far as the end caps still hold every
/// point. `None` for no points.
pub(crate) fn fit_capsule(points: &[Vector3]) -> Option<(Vector3, Vector3, Real)> {
    let n = points.len() as Real;
    let centre = points.iter().sum::<Vector3>() / n;
    let covariance = points
        .iter()
        .map(|p| (p - centre) * (p - centre).transpose())
        .fold(Matrix3::zeros(), |a, m| a + m);
    let eigen = covariance.symmetric_eigen();
    let axis: Vector3 = eigen.eigenvectors.column(eigen.eigenvalues.imax()).into();
    let axis = axis.try_normalize(1e-12).unwrap_or(Vector3::z());
    let along = |p: &Vector3| axis.dot(&(p - centre));
    let radial = |p: &Vector3| (p - centre - axis * along(p)).norm();
    let radius = points.iter().map(radial).fold(0.0, Real::max);
    let (t_min, t_max) = points
        .iter()
        .map(along)
        .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), t| (lo.min(t), hi.max(t)));
    if !t_min.is_finite() {
        return None;
    }
    // A point at (t, ρ) stays inside the cap centred at t_end when
    // |t - t_end|² + ρ² ≤ r²: the largest pull-in every point allows.
    let reach = |p: &Vector3| (radius * radius - radial(p).powi(2)).max(0.0).sqrt();
    let half = 0.5 * (t_max - t_min);
    let pull_low = points.iter().map(|p| along(p) - t_min + reach(p)).fold(half, Real::min);
    let pull_high = points.iter().map(|p| t_max - along(p) + reach(p)).fold(half, Real::min);
    let a = centre + axis * (t_min + pull_low.max(0.0));
    let b = centre + axis * (t_max - pull_high.max(0.0));
    Some((a, b, radius))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn distance_to_segment(p: &Vector3, a: &Vector3, b: &Vector3) -> Real {
        let ab = b - a;
        let t = if ab.norm_squared() > 0.0 {
            (ab.dot(&(p - a)) / ab.norm_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p - (a + ab * t)).norm()
    }

    #[test]
    fn fitted_capsule_holds_every_vertex_and_is_tight() {
        // A box 0.4 x 0.1 x 0.06 turned off the axes: the capsule lies along
        // its long side.
        let turn = crate::math::Rotation3::from_euler_angles(0.3, -0.7, 1.1);
        let mut points = Vec::new();
        for i in 0..=8 {
            for &y in &[-0.05, 0.05] {
                for &z in &[-0.03, 0.03] {
                    let x = -0.2 + 0.05 * Real::from(i);
                    points.push(turn * Vector3::new(x, y, z) + Vector3::new(1.0, 2.0, 3.0));
                }
            }
        }
        let (a, b, r) = fit_capsule(&points).expect("points");
        for p in &points {
            assert!(distance_to_segment(p, &a, &b) <= r + 1e-12);
        }
        let long = (turn * Vector3::x()).dot(&(b - a)).abs();
        assert!((r - (0.05_f64.hypot(0.03))).abs() < 1e-9, "radius {r}");
        assert!(long > 0.4 - 2.0 * r - 1e-9 && long < 0.4, "length {long}");
    }
}
