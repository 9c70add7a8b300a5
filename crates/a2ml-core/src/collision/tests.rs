use super::*;

const TOL: Real = 1e-9;

fn v(x: Real, y: Real, z: Real) -> Vector3 {
    Vector3::new(x, y, z)
}

/// The link used throughout: a vertical capsule from the origin to z = 1, r = 0.1.
fn link() -> Body {
    Body::capsule("link".into(), &v(0.0, 0.0, 0.0), &v(0.0, 0.0, 1.0), 0.1, Some(1))
}

fn obstacle(shape: Shape) -> Body {
    Body::from_obstacle(&Obstacle { name: "o".into(), shape })
}

fn query(link: &Body, shape: Shape) -> Proximity {
    proximity(link, &obstacle(shape), 10.0).expect("within prediction")
}

fn assert_close(a: &Vector3, b: &Vector3) {
    assert!((a - b).norm() < TOL, "{a:?} != {b:?}");
}

/// The reported points and normal agree with the distance.
fn assert_consistent(p: &Proximity) {
    assert!((p.normal.norm() - 1.0).abs() < TOL);
    assert_close(&(p.on_link - p.on_obstacle), &(p.normal * p.distance));
}

#[test]
fn capsule_sphere() {
    let p = query(&link(), Shape::Sphere { center: v(1.0, 0.0, 0.5), radius: 0.2 });
    assert!((p.distance - 0.7).abs() < TOL, "{p:?}");
    assert_close(&p.on_link, &v(0.1, 0.0, 0.5));
    assert_close(&p.on_obstacle, &v(0.8, 0.0, 0.5));
    assert_close(&p.normal, &v(-1.0, 0.0, 0.0));
    assert_consistent(&p);
}

#[test]
fn capsule_box_corner() {
    // The box spans [0.5, 1.5]² × [1.5, 2.5]; its corner (0.5, 0.5, 1.5) is
    // closest to the segment end (0, 0, 1).
    let p = query(
        &link(),
        Shape::Box {
            center: v(1.0, 1.0, 2.0),
            size: v(1.0, 1.0, 1.0),
            rotation: Rotation3::identity(),
        },
    );
    let gap = 0.75_f64.sqrt();
    assert!((p.distance - (gap - 0.1)).abs() < TOL, "{p:?}");
    assert_close(&p.on_obstacle, &v(0.5, 0.5, 1.5));
    let n = -v(0.5, 0.5, 0.5) / gap;
    assert_close(&p.normal, &n);
    assert_close(&p.on_link, &(v(0.0, 0.0, 1.0) - n * 0.1));
    assert_consistent(&p);
}

#[test]
fn capsule_box_face() {
    let p = query(
        &link(),
        Shape::Box {
            center: v(1.0, 0.0, 0.5),
            size: v(0.4, 2.0, 2.0),
            rotation: Rotation3::identity(),
        },
    );
    assert!((p.distance - 0.7).abs() < TOL, "{p:?}");
    assert_close(&p.normal, &v(-1.0, 0.0, 0.0));
    assert!((p.on_link.x - 0.1).abs() < TOL && (p.on_obstacle.x - 0.8).abs() < TOL);
    assert_consistent(&p);
}

#[test]
fn capsule_capsule_skew() {
    let p =
        query(&link(), Shape::Capsule { a: v(1.0, -1.0, 0.5), b: v(1.0, 1.0, 0.5), radius: 0.2 });
    assert!((p.distance - 0.7).abs() < TOL, "{p:?}");
    assert_close(&p.on_link, &v(0.1, 0.0, 0.5));
    assert_close(&p.on_obstacle, &v(0.8, 0.0, 0.5));
    assert_close(&p.normal, &v(-1.0, 0.0, 0.0));
    assert_consistent(&p);
}

#[test]
fn cylinder_is_vertical() {
    // Lying along y, this cylinder's underside would be at z = 1.9, not 1.5.
    let p = query(
        &link(),
        Shape::Cylinder {
            center: v(0.0, 0.0, 2.0),
            radius: 0.1,
            height: 1.0,
            rotation: Rotation3::identity(),
        },
    );
    assert!((p.distance - 0.4).abs() < TOL, "{p:?}");
    assert_close(&p.on_link, &v(0.0, 0.0, 1.1));
    assert_close(&p.normal, &v(0.0, 0.0, -1.0));
    assert!((p.on_obstacle.z - 1.5).abs() < TOL && p.on_obstacle.xy().norm() <= 0.1 + TOL);
    assert_consistent(&p);
}

#[test]
fn capsule_cylinder_side() {
    let center = v(1.0, 1.0, 0.5);
    let p = query(
        &link(),
        Shape::Cylinder { center, radius: 0.3, height: 0.4, rotation: Rotation3::identity() },
    );
    assert!((p.distance - (2.0_f64.sqrt() - 0.4)).abs() < TOL, "{p:?}");
    assert_close(&p.normal, &(-v(1.0, 1.0, 0.0) / 2.0_f64.sqrt()));
    assert!(((p.on_obstacle - center).xy().norm() - 0.3).abs() < TOL);
    assert!((p.on_obstacle.z - 0.5).abs() <= 0.2 + TOL);
    assert!((p.on_link.xy().norm() - 0.1).abs() < TOL);
    assert_consistent(&p);
}

#[test]
fn rotated_box_corner_points_at_the_link() {
    // A unit cube turned 45° about z and then about the new x by atan(1/√2), so that its
    // diagonal from corner (-½, -½, -½) points along -x: that corner, at √3/2 from the centre,
    // is the box's nearest point to the link.
    let turn = Rotation3::rotation_between(&v(-1.0, -1.0, -1.0), &v(-1.0, 0.0, 0.0))
        .expect("not opposite");
    let center = v(2.0, 0.0, 0.5);
    let p = query(&link(), Shape::Box { center, size: v(1.0, 1.0, 1.0), rotation: turn });
    let corner = 2.0 - 0.75_f64.sqrt();
    assert!((p.distance - (corner - 0.1)).abs() < TOL, "{p:?}");
    assert_close(&p.on_obstacle, &v(corner, 0.0, 0.5));
    assert_close(&p.normal, &v(-1.0, 0.0, 0.0));
    assert_consistent(&p);
}

#[test]
fn cylinder_turns_with_its_rotation() {
    // The vertical case's cylinder laid along x: its side, not its cap, faces the link.
    let rotation = Rotation3::from_axis_angle(&Vector3::y_axis(), FRAC_PI_2);
    let p = query(
        &link(),
        Shape::Cylinder { center: v(0.0, 0.0, 2.0), radius: 0.1, height: 1.0, rotation },
    );
    assert!((p.distance - 0.8).abs() < TOL, "{p:?}");
    assert_close(&p.on_link, &v(0.0, 0.0, 1.1));
    assert_close(&p.on_obstacle, &v(0.0, 0.0, 1.9));
    assert_consistent(&p);
}

#[test]
fn penetration_is_negative() {
    let p = query(&link(), Shape::Sphere { center: v(0.05, 0.0, 0.5), radius: 0.2 });
    assert!((p.distance + 0.25).abs() < TOL, "{p:?}");
    assert_close(&p.normal, &v(-1.0, 0.0, 0.0));

    // The segment lies inside the box, 0.05 from its -x face.
    let p = query(
        &link(),
        Shape::Box {
            center: v(0.2, 0.0, 0.5),
            size: v(0.5, 4.0, 4.0),
            rotation: Rotation3::identity(),
        },
    );
    assert!((p.distance + 0.15).abs() < 1e-9, "{p:?}");
    assert_close(&p.normal, &v(-1.0, 0.0, 0.0));
    assert_consistent(&p);
}

#[test]
fn prediction_filters_far_pairs() {
    let o = obstacle(Shape::Sphere { center: v(1.0, 0.0, 0.5), radius: 0.2 });
    assert!(proximity(&link(), &o, 0.69).is_none());
    assert!(proximity(&link(), &o, 0.71).is_some());
    assert!(bounding_gap(&link(), &o) <= 0.7);
}
