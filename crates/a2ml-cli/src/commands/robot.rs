//! `a2ml robot`: what a2ml reads from a URDF — the chain, its limits, the
//! shoulder/elbow/wrist structure and the capsules — and, with `--at`, the
//! arm's state at one configuration: hand pose, S/E/W, CPSA, HAT and the
//! feasible swivel intervals. The report is built once ([`RobotReport`],
//! whose field names are the JSON keys of docs/cli.md) and printed as a
//! table or as JSON. Positions are in {b} (origin at S) unless named otherwise.

use std::path::PathBuf;

use clap::Args;
use serde::Serialize;

use a2ml_core::Robot;
use a2ml_core::kinematics::{self, KinematicsError};
use a2ml_core::math::{DOF, JointVector, Real, Rotation3, Vector3};
use a2ml_core::robot::{Capsule, CapsuleSource, LinkRole};

use crate::error::CliError;
use crate::output::{
    self, COARSE, FINE, Table, deg, num, nums, quaternion, unsigned_zero, vec3, yes_no,
};

/// Joint values this close outside a limit (rad) still count as inside, so
/// that a limit typed in degrees does not warn for a rounding error.
const LIMIT_TOL: Real = 1e-9;

/// Arguments of `a2ml robot`.
#[derive(Debug, Args)]
#[command(after_help = "\
Examples:
  a2ml robot robots/iiwa14.urdf
  a2ml robot robots/iiwa14.urdf --at 0.3,0.5,-0.2,1.2,0.4,-0.6,0.1
  a2ml robot robots/iiwa14.urdf --at 10,20,0,60,0,-30,0 --deg --json
  a2ml robot robots/panda.urdf --tip panda_link7

Positions are in the base frame {b}: the axes of the base link, the origin at
the shoulder centre S. Quaternions are printed w, x, y, z.")]
pub struct RobotArgs {
    /// The URDF file of the arm.
    pub urdf: PathBuf,
    /// Which chain, and where its capsules come from.
    #[command(flatten)]
    pub arm: crate::args::ArmArgs,
    /// Also show the arm's state at this configuration: seven joint values,
    /// comma separated, in radians (degrees with --deg).
    #[arg(
        long,
        value_name = "Q1,...,Q7",
        value_parser = parse_configuration,
        allow_hyphen_values = true
    )]
    pub at: Option<Configuration>,
    /// Read the values of --at in degrees.
    #[arg(long, requires = "at")]
    pub deg: bool,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
}

/// Seven joint values as typed on the command line (unit not yet applied).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Configuration(pub [Real; DOF]);

/// Parses `q1,...,q7`: seven finite numbers separated by commas.
///
/// # Errors
/// A message naming the first bad item, or the count found.
pub fn parse_configuration(text: &str) -> Result<Configuration, String> {
    let items: Vec<&str> = text.split(',').map(str::trim).collect();
    let mut values = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let value: Real = match item.parse() {
            Ok(v) => v,
            Err(_) if item.is_empty() => return Err(format!("joint value {} is empty", i + 1)),
            Err(_) => return Err(format!("joint value {} (`{item}`) is not a number", i + 1)),
        };
        if !value.is_finite() {
            return Err(format!("joint value {} (`{item}`) is not a finite number", i + 1));
        }
        values.push(value);
    }
    let values: [Real; DOF] = values.try_into().map_err(|v: Vec<Real>| {
        format!("expected {DOF} comma-separated joint values, got {}", v.len())
    })?;
    Ok(Configuration(values))
}

/// Runs `a2ml robot`.
///
/// # Errors
/// [`CliError::Io`] when the URDF cannot be read, [`CliError::Input`] when it
/// holds no usable 7-joint arm or a link name is unknown.
pub fn run(args: &RobotArgs) -> Result<(), CliError> {
    let options = args.arm.options()?;
    // A device or a pipe would be read without end.
    if std::fs::metadata(&args.urdf).is_ok_and(|m| !m.is_file()) {
        let path = args.urdf.display();
        return Err(CliError::Input(format!("{path} is not a regular file, so not a URDF")));
    }
    let robot = Robot::from_urdf_file_with(&args.urdf, &options)?;
    let q = args.at.map(|Configuration(values)| {
        JointVector::from_fn(|i, _| if args.deg { values[i].to_radians() } else { values[i] })
    });
    let report = RobotReport::new(&robot, q.as_ref());
    output::emit(&report, args.json, &report.warnings, || report.to_text())
}

/// Everything `a2ml robot` reports; its field names are the JSON keys.
#[derive(Debug, Serialize)]
pub struct RobotReport {
    /// URDF robot name.
    pub name: String,
    /// Base link of the chain.
    pub base_link: String,
    /// Tip link of the chain.
    pub tip_link: String,
    /// The seven joints, base to tip.
    pub joints: Vec<JointReport>,
    /// Shoulder, elbow and wrist structure.
    pub structure: StructureReport,
    /// Collision capsules of the chain's links.
    pub capsules: Vec<CapsuleReport>,
    /// The state at `--at`, `None` without it.
    pub state: Option<StateReport>,
    /// Joints of `--at` outside their limits, one message each.
    pub warnings: Vec<String>,
}

/// One joint and its limits.
#[derive(Debug, Serialize)]
pub struct JointReport {
    /// URDF joint name.
    pub name: String,
    /// Lower position limit (rad).
    pub lower: Real,
    /// Upper position limit (rad).
    pub upper: Real,
    /// Velocity limit (rad/s).
    pub velocity: Real,
    /// Lower position limit (deg).
    pub lower_deg: Real,
    /// Upper position limit (deg).
    pub upper_deg: Real,
    /// Velocity limit (deg/s).
    pub velocity_deg: Real,
}

/// The shoulder-elbow-wrist structure.
#[derive(Debug, Serialize)]
pub struct StructureReport {
    /// S in the base link (m).
    pub shoulder_in_base_link: [Real; 3],
    /// E at zero configuration in {b} (m).
    pub elbow_zero: [Real; 3],
    /// W at zero configuration in {b} (m).
    pub wrist_zero: [Real; 3],
    /// lu = |E - S| (m).
    pub upper_arm_length: Real,
    /// lf = |W - E| (m).
    pub forearm_length: Real,
    /// Distances between axes 3 and 4, and 4 and 5 (m).
    pub elbow_offsets: [Real; 2],
    /// Axes 1-3 meet in one point.
    pub shoulder_spherical: bool,
    /// Axes 5-7 meet in one point.
    pub wrist_spherical: bool,
    /// Joints 5-7 turn the hand without moving W.
    pub wrist_decoupled: bool,
    /// Spherical shoulder and wrist, no elbow offset.
    pub is_srs: bool,
    /// IK (and so the swivel intervals) has a closed form.
    pub has_analytic_ik: bool,
}

/// One collision capsule.
#[derive(Debug, Serialize)]
pub struct CapsuleReport {
    /// Collision name.
    pub name: String,
    /// Link carrying it.
    pub link: String,
    /// Part of the arm.
    pub role: LinkRole,
    /// Radius (m).
    pub radius: Real,
    /// Length of the segment, caps excluded (m).
    pub length: Real,
    /// Where it came from: a URDF shape, a box, a mesh or the skeleton.
    pub source: CapsuleSource,
}

/// The arm's state at one configuration, in {b}.
#[derive(Debug, Serialize)]
pub struct StateReport {
    /// The configuration (rad).
    pub q: [Real; DOF],
    /// The configuration (deg).
    pub q_deg: [Real; DOF],
    /// The hand frame {W}.
    pub hand: HandReport,
    /// Shoulder centre S (m); the origin of {b}.
    pub shoulder: [Real; 3],
    /// Elbow centre E (m).
    pub elbow: [Real; 3],
    /// Wrist centre W (m).
    pub wrist: [Real; 3],
    /// The CPSA state, `None` where it is singular.
    pub cpsa: Option<CpsaReport>,
    /// Why `cpsa` is `None`.
    pub cpsa_error: Option<String>,
    /// The HAT state, `None` where it is singular.
    pub hat: Option<HatReport>,
    /// Why `hat` is `None`.
    pub hat_error: Option<String>,
    /// Swivel angles keeping (Pw, Ow) within the joint limits, `None` when
    /// they cannot be computed.
    pub swivel_intervals: Option<Vec<IntervalReport>>,
    /// Why `swivel_intervals` is `None`.
    pub swivel_intervals_error: Option<String>,
}

/// The hand frame {W}: origin W, axes f, p, f × p.
#[derive(Debug, Serialize)]
pub struct HandReport {
    /// W (m).
    pub position: [Real; 3],
    /// Ow as a quaternion w, x, y, z.
    pub orientation: [Real; 4],
}

/// A CPSA state (Pw, Ow, θsw).
#[derive(Debug, Serialize)]
pub struct CpsaReport {
    /// Pw = W - S (m).
    pub pw: [Real; 3],
    /// Ow as a quaternion w, x, y, z.
    pub ow: [Real; 4],
    /// θsw (rad).
    pub swivel: Real,
    /// θsw (deg).
    pub swivel_deg: Real,
}

/// A HAT state (Os, θe, Ow) with the directions it is made of.
#[derive(Debug, Serialize)]
pub struct HatReport {
    /// Upper-arm direction r.
    pub r: [Real; 3],
    /// Arm-plane normal l.
    pub l: [Real; 3],
    /// Finger direction f.
    pub f: [Real; 3],
    /// Palm normal p.
    pub p: [Real; 3],
    /// Os = [r, l, r × l] as a quaternion w, x, y, z.
    pub shoulder_frame: [Real; 4],
    /// Ow = [f, p, f × p] as a quaternion w, x, y, z.
    pub ow: [Real; 4],
    /// θe = α, the angle at E between S and W (rad).
    pub elbow_angle: Real,
    /// θe = α (deg).
    pub elbow_angle_deg: Real,
}

/// A closed interval of swivel angles.
#[derive(Debug, Serialize)]
pub struct IntervalReport {
    /// Smallest angle (rad).
    pub lower: Real,
    /// Largest angle (rad).
    pub upper: Real,
    /// Smallest angle (deg).
    pub lower_deg: Real,
    /// Largest angle (deg).
    pub upper_deg: Real,
}

/// A value or, where the kinematics has none, the reason as text.
fn split<T, U>(
    result: Result<T, KinematicsError>,
    f: impl FnOnce(T) -> U,
) -> (Option<U>, Option<String>) {
    match result {
        Ok(value) => (Some(f(value)), None),
        Err(error) => (None, Some(error.to_string())),
    }
}

/// Column `i` of a rotation matrix.
fn column(m: &Rotation3, i: usize) -> [Real; 3] {
    let v: Vector3 = m.matrix().column(i).into();
    vec3(&v)
}

impl CapsuleReport {
    fn new(capsule: &Capsule) -> Self {
        Self {
            name: capsule.name.clone(),
            link: capsule.link.clone(),
            role: capsule.role,
            radius: capsule.radius,
            length: capsule.length(),
            source: capsule.source,
        }
    }
}

impl StateReport {
    fn new(robot: &Robot, q: &JointVector) -> Self {
        let pose = kinematics::arm_pose(robot, q);
        let (cpsa, cpsa_error) = split(kinematics::cpsa_state(robot, &pose), |s| CpsaReport {
            pw: vec3(&s.pw),
            ow: quaternion(&s.ow),
            swivel: unsigned_zero(s.swivel),
            swivel_deg: unsigned_zero(deg(s.swivel)),
        });
        let (hat, hat_error) = split(kinematics::hat_state(&pose), |s| HatReport {
            r: column(&s.shoulder_frame, 0),
            l: column(&s.shoulder_frame, 1),
            f: column(&s.ow, 0),
            p: column(&s.ow, 1),
            shoulder_frame: quaternion(&s.shoulder_frame),
            ow: quaternion(&s.ow),
            elbow_angle: s.elbow_angle,
            elbow_angle_deg: deg(s.elbow_angle),
        });
        let pw = pose.wrist - pose.shoulder;
        let (swivel_intervals, swivel_intervals_error) =
            split(kinematics::swivel_intervals(robot, &pw, &pose.hand), |intervals| {
                intervals
                    .iter()
                    .map(|i| IntervalReport {
                        lower: unsigned_zero(i.lower),
                        upper: unsigned_zero(i.upper),
                        lower_deg: unsigned_zero(deg(i.lower)),
                        upper_deg: unsigned_zero(deg(i.upper)),
                    })
                    .collect()
            });
        Self {
            q: std::array::from_fn(|i| unsigned_zero(q[i])),
            q_deg: std::array::from_fn(|i| unsigned_zero(deg(q[i]))),
            hand: HandReport { position: vec3(&pose.wrist), orientation: quaternion(&pose.hand) },
            shoulder: vec3(&pose.shoulder),
            elbow: vec3(&pose.elbow),
            wrist: vec3(&pose.wrist),
            cpsa,
            cpsa_error,
            hat,
            hat_error,
            swivel_intervals,
            swivel_intervals_error,
        }
    }
}

impl RobotReport {
    /// The report on `robot`, with its state at `q` when given.
    pub fn new(robot: &Robot, q: Option<&JointVector>) -> Self {
        let s = &robot.structure;
        let limit_warnings = q.map_or_else(Vec::new, |q| {
            robot
                .joints
                .iter()
                .enumerate()
                .filter(|(i, joint)| !joint.limits.contains(q[*i], LIMIT_TOL))
                .map(|(i, joint)| {
                    let l = &joint.limits;
                    format!(
                        "joint {} `{}` at {} rad ({}°) is outside its limits [{}, {}] rad",
                        i + 1,
                        joint.name,
                        num(q[i], FINE),
                        num(deg(q[i]), COARSE),
                        num(l.lower, FINE),
                        num(l.upper, FINE),
                    )
                })
                .collect()
        });
        Self {
            name: robot.name.clone(),
            base_link: robot.base_link.clone(),
            tip_link: robot.tip_link.clone(),
            joints: robot
                .joints
                .iter()
                .map(|j| JointReport {
                    name: j.name.clone(),
                    lower: j.limits.lower,
                    upper: j.limits.upper,
                    velocity: j.limits.velocity,
                    lower_deg: deg(j.limits.lower),
                    upper_deg: deg(j.limits.upper),
                    velocity_deg: deg(j.limits.velocity),
                })
                .collect(),
            structure: StructureReport {
                shoulder_in_base_link: vec3(&s.shoulder_in_base_link),
                elbow_zero: vec3(&s.elbow_zero),
                wrist_zero: vec3(&s.wrist_zero),
                upper_arm_length: s.upper_arm_length,
                forearm_length: s.forearm_length,
                elbow_offsets: s.elbow_offsets,
                shoulder_spherical: s.shoulder_spherical,
                wrist_spherical: s.wrist_spherical,
                wrist_decoupled: s.wrist_decoupled,
                is_srs: s.is_srs,
                has_analytic_ik: robot.has_analytic_ik(),
            },
            capsules: robot.capsules.iter().map(CapsuleReport::new).collect(),
            state: q.map(|q| StateReport::new(robot, q)),
            warnings: robot
                .geometry_warnings
                .iter()
                .map(|w| format!("collision geometry: {w}"))
                .chain(limit_warnings)
                .collect(),
        }
    }

    /// The report as aligned plain-text tables.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        let mut head = Table::new();
        head.title(format!("robot {}", self.name));
        head.note("chain", format!("{} -> {}, {DOF} joints", self.base_link, self.tip_link));
        head.render(&mut out);

        let mut joints = Table::with_header([
            "#",
            "joint",
            "lower (rad)",
            "upper (rad)",
            "velocity (rad/s)",
            "lower (°)",
            "upper (°)",
            "velocity (°/s)",
        ])
        .left_columns(2);
        joints.title("joints");
        for (i, j) in self.joints.iter().enumerate() {
            joints.row(
                (i + 1).to_string(),
                [
                    j.name.clone(),
                    num(j.lower, FINE),
                    num(j.upper, FINE),
                    num(j.velocity, FINE),
                    num(j.lower_deg, COARSE),
                    num(j.upper_deg, COARSE),
                    num(j.velocity_deg, COARSE),
                ],
            );
        }
        joints.render(&mut out);

        let mut t = Table::new();
        let s = &self.structure;
        t.title("structure");
        t.row(format!("S in {} (m)", self.base_link), nums(&s.shoulder_in_base_link, FINE));
        t.row("E at q = 0, in {b} (m)", nums(&s.elbow_zero, FINE));
        t.row("W at q = 0, in {b} (m)", nums(&s.wrist_zero, FINE));
        t.row("upper arm lu (m)", [num(s.upper_arm_length, FINE)]);
        t.row("forearm lf (m)", [num(s.forearm_length, FINE)]);
        t.row("elbow offsets (m)", nums(&s.elbow_offsets, FINE));
        t.row("shoulder spherical", [yes_no(s.shoulder_spherical)]);
        t.row("wrist spherical", [yes_no(s.wrist_spherical)]);
        t.row("wrist decoupled", [yes_no(s.wrist_decoupled)]);
        t.row("SRS (is_srs)", [yes_no(s.is_srs)]);
        t.row("analytic IK", [yes_no(s.has_analytic_ik)]);
        t.render(&mut out);

        let mut capsules =
            Table::with_header(["capsule", "link", "role", "source", "radius (m)", "length (m)"])
                .left_columns(4);
        capsules.title("capsules");
        if self.capsules.is_empty() {
            capsules.line("none (no usable URDF geometry, and skeleton capsules are off)");
        }
        for c in &self.capsules {
            capsules.row(
                c.name.clone(),
                [
                    c.link.clone(),
                    c.role.as_str().to_owned(),
                    c.source.as_str().to_owned(),
                    num(c.radius, FINE),
                    num(c.length, FINE),
                ],
            );
        }
        capsules.render(&mut out);

        if let Some(state) = &self.state {
            state.render(&mut out);
        }
        out
    }
}

impl StateReport {
    /// Appends the state's tables: configuration and points, CPSA, HAT,
    /// swivel intervals.
    fn render(&self, out: &mut String) {
        // One table for the three first sections, so that their numbers align.
        let mut t = Table::new();
        t.title("state at q, in {b}");
        t.row("q (rad)", nums(&self.q, FINE));
        t.row("q (°)", nums(&self.q_deg, COARSE));
        t.row("hand position W (m)", nums(&self.hand.position, FINE));
        t.row("hand Ow (w, x, y, z)", nums(&self.hand.orientation, FINE));
        t.row("S (m)", nums(&self.shoulder, FINE));
        t.row("E (m)", nums(&self.elbow, FINE));
        t.row("W (m)", nums(&self.wrist, FINE));

        t.title("CPSA (Pw, Ow, θsw)");
        match (&self.cpsa, &self.cpsa_error) {
            (Some(c), _) => {
                t.row("Pw (m)", nums(&c.pw, FINE));
                t.row("Ow (w, x, y, z)", nums(&c.ow, FINE));
                t.row("θsw (rad, °)", [num(c.swivel, FINE), num(c.swivel_deg, COARSE)]);
            }
            (None, error) => t.line(error.as_deref().unwrap_or("undefined")),
        }

        t.title("HAT (Os, θe, Ow)");
        match (&self.hat, &self.hat_error) {
            (Some(h), _) => {
                t.row("r upper arm", nums(&h.r, FINE));
                t.row("l arm-plane normal", nums(&h.l, FINE));
                t.row("f finger", nums(&h.f, FINE));
                t.row("p palm normal", nums(&h.p, FINE));
                t.row("Os (w, x, y, z)", nums(&h.shoulder_frame, FINE));
                t.row("Ow (w, x, y, z)", nums(&h.ow, FINE));
                t.row(
                    "θe = α (rad, °)",
                    [num(h.elbow_angle, FINE), num(h.elbow_angle_deg, COARSE)],
                );
            }
            (None, error) => t.line(error.as_deref().unwrap_or("undefined")),
        }
        t.render(out);

        let mut t =
            Table::with_header(["#", "lower (rad)", "upper (rad)", "lower (°)", "upper (°)"]);
        t.title("swivel intervals at this (Pw, Ow), within the joint limits");
        let intervals = match (&self.swivel_intervals, &self.swivel_intervals_error) {
            (Some(intervals), _) => intervals.as_slice(),
            (None, error) => {
                t.line(format!("not available: {}", error.as_deref().unwrap_or("unknown reason")));
                &[]
            }
        };
        if self.swivel_intervals.as_ref().is_some_and(Vec::is_empty) {
            t.line("none: no swivel angle keeps every joint within its limits");
        }
        let swivel = self.cpsa.as_ref().map(|c| c.swivel);
        for (k, i) in intervals.iter().enumerate() {
            let mut cells = vec![
                num(i.lower, FINE),
                num(i.upper, FINE),
                num(i.lower_deg, COARSE),
                num(i.upper_deg, COARSE),
            ];
            if swivel.is_some_and(|s| s >= i.lower && s <= i.upper) {
                cells.push("<- θsw".to_owned());
            }
            t.row((k + 1).to_string(), cells);
        }
        t.render(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn configuration_parses_seven_numbers() {
        let c = parse_configuration("0.3, 0.5,-0.2,1.2,0.4,-0.6,1e-1").expect("valid");
        assert_eq!(c.0, [0.3, 0.5, -0.2, 1.2, 0.4, -0.6, 0.1]);
    }

    #[test]
    fn configuration_errors_name_the_item() {
        let e = |s| parse_configuration(s).expect_err("invalid");
        assert_eq!(e("1,2,3"), "expected 7 comma-separated joint values, got 3");
        assert_eq!(e("1,2,x,4,5,6,7"), "joint value 3 (`x`) is not a number");
        assert_eq!(e("1,,3,4,5,6,7"), "joint value 2 is empty");
        assert_eq!(e("1,2,3,4,5,6,inf"), "joint value 7 (`inf`) is not a finite number");
    }
}
