//! The scene: obstacles, their shapes and orientations.

use std::collections::HashMap;

use super::Checker;
use super::values::Dimension;
use crate::language::ast::{self, Span};
use crate::language::task::*;
use crate::math::{PI, Rotation3, Vector3};
use crate::names::did_you_mean;

const SHAPES: [&str; 4] = ["box", "sphere", "capsule", "cylinder"];

impl Checker<'_> {
    pub(super) fn scene(&mut self, scene: &ast::Scene) -> Vec<Obstacle> {
        let mut seen: HashMap<&str, Span> = HashMap::new();
        let mut out = Vec::new();
        for o in &scene.obstacles {
            if seen.insert(&o.name.text, o.name.span).is_some() {
                self.error(o.name.span, format!("obstacle `{}` is declared twice", o.name.text));
                continue;
            }
            let shape = match &o.shape {
                ast::Shape::Box { at, size, orientation } => (|| {
                    let center = self.vector3(at, Dimension::Length, "the centre");
                    let size = self.vector3(size, Dimension::Length, "the size");
                    let rotation = self.orientation(orientation.as_ref());
                    let (center, size, rotation) = (center?, size?, rotation?);
                    if size.iter().any(|s| *s <= 0.0) {
                        self.error(o.span, "a box's size must be positive in x, y and z");
                        return None;
                    }
                    Some(Shape::Box { center, size, rotation })
                })(),
                ast::Shape::Sphere { at, radius } => (|| {
                    Some(Shape::Sphere {
                        center: self.vector3(at, Dimension::Length, "the centre")?,
                        radius: self.positive(radius, Dimension::Length, "the radius")?,
                    })
                })(),
                ast::Shape::Capsule { from, to, radius } => (|| {
                    Some(Shape::Capsule {
                        a: self.vector3(from, Dimension::Length, "the start")?,
                        b: self.vector3(to, Dimension::Length, "the end")?,
                        radius: self.positive(radius, Dimension::Length, "the radius")?,
                    })
                })(),
                ast::Shape::CapsuleAt { at, radius, height, orientation } => (|| {
                    let center = self.vector3(at, Dimension::Length, "the centre");
                    let radius = self.positive(radius, Dimension::Length, "the radius");
                    let height = self.positive(height, Dimension::Length, "the height");
                    let rotation = self.orientation(orientation.as_ref());
                    let half = rotation? * Vector3::z() * (0.5 * height?);
                    let center = center?;
                    Some(Shape::Capsule { a: center - half, b: center + half, radius: radius? })
                })(),
                ast::Shape::Cylinder { at, radius, height, orientation } => (|| {
                    let center = self.vector3(at, Dimension::Length, "the centre");
                    let radius = self.positive(radius, Dimension::Length, "the radius");
                    let height = self.positive(height, Dimension::Length, "the height");
                    let rotation = self.orientation(orientation.as_ref());
                    Some(Shape::Cylinder {
                        center: center?,
                        radius: radius?,
                        height: height?,
                        rotation: rotation?,
                    })
                })(),
                ast::Shape::Unknown(name) => {
                    let help =
                        did_you_mean(&name.text, SHAPES).map(|s| format!("did you mean `{s}`?"));
                    self.error_with_help(
                        name.span,
                        format!("unknown shape `{}` (box, sphere, capsule, cylinder)", name.text),
                        help,
                    );
                    None
                }
            };
            if let Some(shape) = shape {
                out.push(Obstacle { name: o.name.text.clone(), shape });
            }
        }
        out
    }

    /// A shape's rotation: the identity without an orientation; for an `axis`, the shortest
    /// turn taking z onto it (half a turn about x for -z).
    pub(super) fn orientation(
        &mut self,
        orientation: Option<&ast::Orientation>,
    ) -> Option<Rotation3> {
        match orientation {
            None => Some(Rotation3::identity()),
            Some(ast::Orientation::Rotation(value)) => {
                self.rotation(value, ["x", "y"], "the shape's orientation")
            }
            Some(ast::Orientation::Axis(vector)) => {
                let axis = self.direction(vector, "the axis")?;
                Some(
                    Rotation3::rotation_between(&Vector3::z(), &axis)
                        .unwrap_or_else(|| Rotation3::from_axis_angle(&Vector3::x_axis(), PI)),
                )
            }
        }
    }
}
