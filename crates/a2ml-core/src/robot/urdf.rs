//! URDF text to plain data, leniently as ROS and pinocchio read it: what a2ml
//! does not use (materials, textures, inertials, transmissions, gazebo and
//! ros2_control tags, unknown elements) is skipped, while everything it uses
//! (links, joints, origins, axes, limits, mimic tags, collision and visual
//! geometry) is checked strictly, each error naming the element and its line.
//! roxmltree enters the library here and nowhere else.

use std::collections::HashSet;

use super::RobotError;
use crate::math::{Isometry, Real, Rotation3, Translation3, Vector3};

/// A URDF document: its links and joints in file order.
#[derive(Debug, Clone)]
pub(crate) struct Document {
    pub name: String,
    pub links: Vec<Link>,
    pub joints: Vec<Joint>,
}

/// A `<link>` with the geometry a2ml can turn into capsules.
#[derive(Debug, Clone)]
pub(crate) struct Link {
    pub name: String,
    pub collisions: Vec<Geometry>,
    pub visuals: Vec<Geometry>,
}

/// One `<collision>` or `<visual>`: a shape placed in its link.
#[derive(Debug, Clone)]
pub(crate) struct Geometry {
    pub name: Option<String>,
    pub link_from_shape: Isometry,
    pub shape: Shape,
    /// Line of the element, for messages.
    pub line: u32,
}

/// The URDF shapes.
#[derive(Debug, Clone)]
pub(crate) enum Shape {
    Cylinder { radius: Real, length: Real },
    Capsule { radius: Real, length: Real },
    Sphere { radius: Real },
    Box { size: Vector3 },
    Mesh { filename: String, scale: Vector3 },
}

/// The URDF joint types.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum JointKind {
    Revolute,
    Continuous,
    Prismatic,
    Fixed,
    Floating,
    Planar,
    Spherical,
}

impl JointKind {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "revolute" => Self::Revolute,
            "continuous" => Self::Continuous,
            "prismatic" => Self::Prismatic,
            "fixed" => Self::Fixed,
            "floating" => Self::Floating,
            "planar" => Self::Planar,
            "spherical" => Self::Spherical,
            _ => return None,
        })
    }

    /// The URDF spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Revolute => "revolute",
            Self::Continuous => "continuous",
            Self::Prismatic => "prismatic",
            Self::Fixed => "fixed",
            Self::Floating => "floating",
            Self::Planar => "planar",
            Self::Spherical => "spherical",
        }
    }
}

/// A `<limit>` as written (URDF defaults for absent attributes: 0).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limit {
    pub lower: Real,
    pub upper: Real,
    pub velocity: Real,
    /// The a2ml extension attribute `a2ml_acceleration` (rad/s²), which ROS readers ignore.
    pub acceleration: Option<Real>,
}

/// A `<mimic>` tag: this joint follows `joint` as multiplier × q + offset.
#[derive(Debug, Clone)]
pub(crate) struct Mimic {
    pub joint: String,
}

/// A `<joint>`.
#[derive(Debug, Clone)]
pub(crate) struct Joint {
    pub name: String,
    pub kind: JointKind,
    pub parent: String,
    pub child: String,
    pub parent_from_joint: Isometry,
    /// The axis as written (default x), not yet normalised.
    pub axis: Vector3,
    pub limit: Option<Limit>,
    pub mimic: Option<Mimic>,
    pub line: u32,
}

/// Where an element sits, for messages: `line 12, <joint name="j1">`.
struct At<'a, 'input> {
    doc: &'a roxmltree::Document<'input>,
    node: roxmltree::Node<'a, 'input>,
}

impl At<'_, '_> {
    fn line(&self) -> u32 {
        self.doc.text_pos_at(self.node.range().start).row
    }

    fn describe(&self) -> String {
        let tag = self.node.tag_name().name();
        match self.node.attribute("name") {
            Some(name) => format!("line {}, <{tag} name=\"{name}\">", self.line()),
            None => format!("line {}, <{tag}>", self.line()),
        }
    }

    fn error(&self, what: impl std::fmt::Display) -> RobotError {
        RobotError::Urdf { path: None, message: format!("{}: {what}", self.describe()) }
    }
}

/// Parses `text` into a [`Document`].
///
/// # Errors
/// [`RobotError::Urdf`] for malformed XML, a missing `<robot>`, duplicate
/// link or joint names, a joint naming an absent link, a link with two
/// parents, numbers that are not finite or not as many as the attribute
/// needs, negative sizes, or an unknown joint type; the message names the
/// element and its line.
pub(crate) fn parse(text: &str) -> Result<Document, RobotError> {
    let doc = roxmltree::Document::parse(text)
        .map_err(|e| RobotError::Urdf { path: None, message: e.to_string() })?;
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(At { doc: &doc, node: root }.error("the root element must be <robot>"));
    }
    let name = root.attribute("name").unwrap_or_default().to_owned();
    let mut links = Vec::new();
    let mut joints = Vec::new();
    for node in root.children().filter(roxmltree::Node::is_element) {
        let at = At { doc: &doc, node };
        match node.tag_name().name() {
            "link" => links.push(link(&at)?),
            "joint" => joints.push(joint(&at)?),
            // Materials, transmissions, gazebo and control tags, anything else.
            _ => {}
        }
    }
    check_names(&doc, root, &links, &joints)?;
    Ok(Document { name, links, joints })
}

fn check_names(
    doc: &roxmltree::Document<'_>,
    root: roxmltree::Node<'_, '_>,
    links: &[Link],
    joints: &[Joint],
) -> Result<(), RobotError> {
    let element = |tag: &str, name: &str| {
        root.children()
            .find(|n| n.has_tag_name(tag) && n.attribute("name") == Some(name))
            .map(|node| At { doc, node })
    };
    let fail = |tag: &str, name: &str, what: String| match element(tag, name) {
        Some(at) => at.error(what),
        None => RobotError::Urdf { path: None, message: what },
    };
    let mut link_names = HashSet::new();
    for l in links {
        if !link_names.insert(l.name.as_str()) {
            let line = root
                .children()
                .filter(|n| n.has_tag_name("link") && n.attribute("name") == Some(&l.name))
                .nth(1)
                .map(|node| At { doc, node }.describe())
                .unwrap_or_default();
            return Err(RobotError::Urdf {
                path: None,
                message: format!("{line}: a second link named `{}`", l.name),
            });
        }
    }
    let mut joint_names = HashSet::new();
    let mut children = HashSet::new();
    for j in joints {
        let at = || At { doc, node: node_at_line(root, "joint", &j.name, j.line) };
        if !joint_names.insert(j.name.as_str()) {
            return Err(at().error(format!("a second joint named `{}`", j.name)));
        }
        for (role, l) in [("parent", &j.parent), ("child", &j.child)] {
            if !link_names.contains(l.as_str()) {
                return Err(at().error(format!("its {role} link `{l}` is not defined")));
            }
        }
        if j.parent == j.child {
            return Err(at().error(format!("link `{}` is its own parent", j.child)));
        }
        if !children.insert(j.child.as_str()) {
            return Err(at().error(format!("link `{}` already has a parent joint", j.child)));
        }
    }
    for j in joints {
        if let Some(m) = &j.mimic {
            if !joint_names.contains(m.joint.as_str()) {
                return Err(fail(
                    "joint",
                    &j.name,
                    format!("<mimic> follows joint `{}`, which is not defined", m.joint),
                ));
            }
        }
    }
    Ok(())
}

/// The `tag` element named `name` starting at `line` (duplicates share names).
fn node_at_line<'a, 'input>(
    root: roxmltree::Node<'a, 'input>,
    tag: &str,
    name: &str,
    line: u32,
) -> roxmltree::Node<'a, 'input> {
    let doc = root.document();
    root.children()
        .filter(|n| n.has_tag_name(tag) && n.attribute("name") == Some(name))
        .find(|n| doc.text_pos_at(n.range().start).row == line)
        .unwrap_or(root)
}

fn required<'a>(at: &At<'a, '_>, attribute: &str) -> Result<&'a str, RobotError> {
    at.node.attribute(attribute).ok_or_else(|| at.error(format!("missing `{attribute}` attribute")))
}

fn name_of(at: &At<'_, '_>) -> Result<String, RobotError> {
    let name = required(at, "name")?;
    if name.trim().is_empty() {
        return Err(at.error("empty `name`"));
    }
    Ok(name.to_owned())
}

/// A finite number; `what` names the attribute.
fn number(at: &At<'_, '_>, what: &str, s: &str) -> Result<Real, RobotError> {
    match s.trim().parse::<Real>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(at.error(format!("`{what}` is `{}`, not a finite number", s.trim()))),
        Err(_) => Err(at.error(format!("`{what}` is `{}`, not a number", s.trim()))),
    }
}

/// Exactly three finite numbers separated by whitespace.
fn triple(at: &At<'_, '_>, what: &str, s: &str) -> Result<Vector3, RobotError> {
    let words: Vec<&str> = s.split_whitespace().collect();
    if words.len() != 3 {
        return Err(at.error(format!(
            "`{what}` is `{}`: it needs three numbers, found {} words",
            s.trim(),
            words.len()
        )));
    }
    let mut v = Vector3::zeros();
    for (k, w) in words.iter().enumerate() {
        v[k] = number(at, what, w)?;
    }
    Ok(v)
}

fn optional_number(at: &At<'_, '_>, attribute: &str) -> Result<Option<Real>, RobotError> {
    at.node.attribute(attribute).map(|s| number(at, attribute, s)).transpose()
}

fn child<'a, 'input>(at: &At<'a, 'input>, tag: &str) -> Option<At<'a, 'input>> {
    at.node.children().find(|n| n.has_tag_name(tag)).map(|node| At { doc: at.doc, node })
}

/// `<origin xyz rpy>`; identity when absent.
fn origin(at: &At<'_, '_>) -> Result<Isometry, RobotError> {
    let Some(o) = child(at, "origin") else { return Ok(Isometry::identity()) };
    let xyz = o.node.attribute("xyz").map(|s| triple(&o, "xyz", s)).transpose()?;
    let rpy = o.node.attribute("rpy").map(|s| triple(&o, "rpy", s)).transpose()?;
    let (xyz, rpy) = (xyz.unwrap_or_default(), rpy.unwrap_or_default());
    Ok(Isometry::from_parts(
        Translation3::new(xyz.x, xyz.y, xyz.z),
        Rotation3::from_euler_angles(rpy.x, rpy.y, rpy.z),
    ))
}

fn link(at: &At<'_, '_>) -> Result<Link, RobotError> {
    let name = name_of(at)?;
    let geometries = |tag: &str| -> Result<Vec<Geometry>, RobotError> {
        at.node
            .children()
            .filter(|n| n.has_tag_name(tag))
            .map(|node| geometry(&At { doc: at.doc, node }))
            .collect::<Result<Vec<_>, _>>()
            .map(|v| v.into_iter().flatten().collect())
    };
    Ok(Link { name, collisions: geometries("collision")?, visuals: geometries("visual")? })
}

/// A `<collision>` or `<visual>`; `None` when it has no `<geometry>` shape.
fn geometry(at: &At<'_, '_>) -> Result<Option<Geometry>, RobotError> {
    let link_from_shape = origin(at)?;
    let Some(g) = child(at, "geometry") else { return Ok(None) };
    let Some(node) = g.node.children().find(roxmltree::Node::is_element) else {
        return Err(g.error("<geometry> holds no shape"));
    };
    let s = At { doc: at.doc, node };
    let size = |attribute: &str| -> Result<Real, RobotError> {
        let v = number(&s, attribute, required(&s, attribute)?)?;
        if v < 0.0 {
            return Err(s.error(format!("`{attribute}` is negative ({v})")));
        }
        Ok(v)
    };
    let shape = match node.tag_name().name() {
        "cylinder" => Shape::Cylinder { radius: size("radius")?, length: size("length")? },
        "capsule" => Shape::Capsule { radius: size("radius")?, length: size("length")? },
        "sphere" => Shape::Sphere { radius: size("radius")? },
        "box" => {
            let size = triple(&s, "size", required(&s, "size")?)?;
            if size.iter().any(|v| *v < 0.0) {
                return Err(s.error("a box size is negative"));
            }
            Shape::Box { size }
        }
        "mesh" => Shape::Mesh {
            filename: required(&s, "filename")?.to_owned(),
            scale: s
                .node
                .attribute("scale")
                .map(|v| triple(&s, "scale", v))
                .transpose()?
                .unwrap_or(Vector3::new(1.0, 1.0, 1.0)),
        },
        other => return Err(s.error(format!("unknown shape <{other}>"))),
    };
    Ok(Some(Geometry {
        name: at.node.attribute("name").map(str::to_owned),
        link_from_shape,
        shape,
        line: at.line(),
    }))
}

fn joint(at: &At<'_, '_>) -> Result<Joint, RobotError> {
    let name = name_of(at)?;
    let kind_text = required(at, "type")?;
    let kind = JointKind::parse(kind_text)
        .ok_or_else(|| at.error(format!("unknown joint type `{kind_text}`")))?;
    let link_of = |tag: &str| -> Result<String, RobotError> {
        let c = child(at, tag).ok_or_else(|| at.error(format!("missing <{tag}>")))?;
        Ok(required(&c, "link")?.to_owned())
    };
    let axis = match child(at, "axis") {
        Some(a) => triple(&a, "xyz", required(&a, "xyz")?)?,
        None => Vector3::x(),
    };
    let limit = child(at, "limit")
        .map(|l| -> Result<Limit, RobotError> {
            Ok(Limit {
                lower: optional_number(&l, "lower")?.unwrap_or(0.0),
                upper: optional_number(&l, "upper")?.unwrap_or(0.0),
                velocity: optional_number(&l, "velocity")?.unwrap_or(0.0),
                acceleration: optional_number(&l, super::acceleration::ATTRIBUTE)?,
            })
        })
        .transpose()?;
    let mimic = child(at, "mimic")
        .map(|m| -> Result<Mimic, RobotError> {
            optional_number(&m, "multiplier")?;
            optional_number(&m, "offset")?;
            Ok(Mimic { joint: required(&m, "joint")?.to_owned() })
        })
        .transpose()?;
    Ok(Joint {
        name,
        kind,
        parent: link_of("parent")?,
        child: link_of("child")?,
        parent_from_joint: origin(at)?,
        axis,
        limit,
        mimic,
        line: at.line(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arm(joint_origin: &str) -> String {
        format!(
            r#"<robot name="r">
  <material name="m"><texture/></material>
  <link name="a"><visual><geometry><box size="1 2 3"/></geometry></visual></link>
  <link name="b"/>
  <gazebo reference="a"><anything/></gazebo>
  <joint name="j" type="revolute">
    <parent link="a"/><child link="b"/>
    <origin {joint_origin}/>
    <limit lower="-1" upper="1" velocity="2"/>
  </joint>
  <transmission name="t"><type>x</type></transmission>
</robot>"#
        )
    }

    fn message(text: &str) -> String {
        match parse(text) {
            Err(RobotError::Urdf { message, .. }) => message,
            other => panic!("expected an error, got {other:?}"),
        }
    }

    #[test]
    fn ignores_what_it_does_not_use() {
        let doc = parse(&arm(r#"xyz="0 0 0.5""#)).expect("lenient");
        assert_eq!(doc.links.len(), 2);
        assert_eq!(doc.joints[0].parent_from_joint.translation.vector.z, 0.5);
        assert!(matches!(doc.links[0].visuals[0].shape, Shape::Box { .. }));
    }

    #[test]
    fn junk_and_non_finite_numbers_are_located() {
        let m = message(&arm(r#"xyz="0 0.33 abc""#));
        assert!(m.contains("line 8") && m.contains("<origin>") && m.contains("abc"), "{m}");
        let m = message(&arm(r#"xyz="0 0.33 0 7""#));
        assert!(m.contains("three numbers, found 4"), "{m}");
        let m = message(&arm(r#"rpy="0 NaN 0""#));
        assert!(m.contains("not a finite number"), "{m}");
        let m = message(&arm(r#"rpy="0 inf 0""#));
        assert!(m.contains("not a finite number"), "{m}");
    }

    #[test]
    fn duplicates_and_missing_links_are_refused() {
        let text = arm("").replace(r#"<link name="b"/>"#, r#"<link name="b"/><link name="b"/>"#);
        let m = message(&text);
        assert!(m.contains("second link named `b`") && m.contains("line 4"), "{m}");
        let text = arm("").replace(r#"<child link="b"/>"#, r#"<child link="c"/>"#);
        assert!(message(&text).contains("child link `c` is not defined"));
        let twice = arm("").replace(
            "<transmission",
            r#"<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint><transmission"#,
        );
        assert!(message(&twice).contains("second joint named `j`"));
    }

    #[test]
    fn bad_shapes_are_refused() {
        let text =
            arm("").replace(r#"<box size="1 2 3"/>"#, r#"<cylinder radius="-1" length="1"/>"#);
        assert!(message(&text).contains("`radius` is negative"));
        let text = arm("").replace(r#"<box size="1 2 3"/>"#, r#"<sphere radius="nan"/>"#);
        assert!(message(&text).contains("not a finite number"));
    }
}
