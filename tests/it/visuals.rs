//! The shipped URDFs draw what a2ml collides with: every capsule has a visual cylinder with
//! its collision's origin and size and two visual spheres at its ends, in the same link (a
//! collision sphere, a capsule of length zero, is drawn as that sphere).

use a2ml::math::{Isometry, Vector3};
use urdf_rs::Geometry;

use crate::common::{ROBOTS, load};

#[test]
fn every_capsule_is_drawn_as_a_cylinder_and_two_end_spheres() {
    for name in ROBOTS {
        let robot = load(name);
        let urdf = urdf_rs::read_from_string(&robot.urdf).expect("the URDF parses");
        assert!(!robot.capsules.is_empty(), "{name}");
        for capsule in &robot.capsules {
            let link = urdf.links.iter().find(|l| l.name == capsule.link).expect("its link");
            let visual = |suffix: &str| {
                let wanted = format!("{}{suffix}", capsule.name);
                link.visual
                    .iter()
                    .find(|v| v.name.as_deref() == Some(wanted.as_str()))
                    .unwrap_or_else(|| panic!("{name}: no visual {wanted} on {}", link.name))
            };
            let collision = link
                .collision
                .iter()
                .find(|c| c.name.as_deref() == Some(capsule.name.as_str()))
                .expect("its collision");
            let body = visual("");
            assert_eq!(body.origin.xyz.0, collision.origin.xyz.0, "{name} {}", capsule.name);
            assert_eq!(body.origin.rpy.0, collision.origin.rpy.0, "{name} {}", capsule.name);
            // A collision sphere is a capsule of length zero: drawn as the sphere it is.
            if let Geometry::Sphere { radius } = body.geometry {
                assert_eq!(radius, capsule.radius, "{name} {}", capsule.name);
                assert!(
                    (capsule.b - capsule.a).norm() < 1e-12,
                    "{name}: {} is a sphere",
                    capsule.name
                );
                continue;
            }
            let Geometry::Cylinder { radius, length } = body.geometry else {
                panic!("{name}: {} is drawn as a cylinder", capsule.name)
            };
            assert_eq!(radius, capsule.radius, "{name} {}", capsule.name);
            assert!((length - (capsule.b - capsule.a).norm()).abs() < 1e-9);
            // The capsule's ends in its link, from the model a2ml collides with.
            let frame_from_link = robot
                .links
                .iter()
                .find(|l| l.name == capsule.link)
                .map(|l| l.frame_from_link)
                .expect("the link is in the chain");
            let link_from_frame: Isometry = frame_from_link.inverse();
            let ends = [capsule.a, capsule.b].map(|p| link_from_frame.transform_point(&p.into()));
            for suffix in ["_end_a", "_end_b"] {
                let cap = visual(suffix);
                let Geometry::Sphere { radius } = cap.geometry else {
                    panic!("{name}: {}{suffix} is a sphere", capsule.name)
                };
                assert_eq!(radius, capsule.radius);
                let at = Vector3::from(cap.origin.xyz.0);
                let gap = ends.iter().map(|e| (e.coords - at).norm()).fold(f64::INFINITY, f64::min);
                assert!(
                    gap < 1e-6,
                    "{name}: {}{suffix} is {gap} m off the capsule's end",
                    capsule.name
                );
            }
        }
    }
}
