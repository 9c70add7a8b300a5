//! The MotionBenchMaker problems of tests/data/mbm, read into a2ml's types; shared by
//! `tests/it/mbm.rs` and `benches/mbm.rs`.

use a2ml::language::{Obstacle, Shape};
use a2ml::math::{JointVector, Real, UnitQuaternion, Vector3};

/// The scenes of tests/data/mbm, 100 problems each.
pub const SCENES: [&str; 7] = [
    "bookshelf_small",
    "bookshelf_tall",
    "bookshelf_thin",
    "box",
    "cage",
    "table_pick",
    "table_under_pick",
];

/// A problem: start, goals and obstacles in {b} (S is 0.333 m above `panda_link0`).
pub struct Problem {
    pub start: JointVector,
    pub goals: Vec<JointVector>,
    pub obstacles: Vec<Obstacle>,
}

fn numbers(v: &serde_json::Value) -> Vec<Real> {
    v.as_array().expect("array").iter().map(|x| x.as_f64().expect("number")).collect()
}

fn obstacle(o: &serde_json::Value) -> Obstacle {
    let p = numbers(&o["position"]);
    let center = Vector3::new(p[0], p[1], p[2] - 0.333);
    let q = numbers(&o["orientation_quat_xyzw"]);
    let rotation =
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]))
            .to_rotation_matrix();
    let shape = match o["type"].as_str().expect("type") {
        "box" => Shape::Box {
            center,
            size: Vector3::from_column_slice(&numbers(&o["half_extents"])) * 2.0,
            rotation,
        },
        "cylinder" => Shape::Cylinder {
            center,
            radius: o["radius"].as_f64().expect("radius"),
            height: o["length"].as_f64().expect("length"),
            rotation,
        },
        "sphere" => Shape::Sphere { center, radius: o["radius"].as_f64().expect("radius") },
        other => panic!("unknown obstacle type {other}"),
    };
    Obstacle { name: o["name"].as_str().expect("name").to_owned(), shape }
}

/// The problems of scene `name` (a file of tests/data/mbm).
pub fn problems(name: &str) -> Vec<Problem> {
    let path = format!("{}/tests/data/mbm/{name}.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("the scene is in the repository");
    let data: serde_json::Value = serde_json::from_str(&text).expect("json");
    data["problems"]
        .as_array()
        .expect("problems")
        .iter()
        .map(|p| Problem {
            start: JointVector::from_column_slice(&numbers(&p["start"])),
            goals: p["goals"]
                .as_array()
                .expect("goals")
                .iter()
                .map(|g| JointVector::from_column_slice(&numbers(g)))
                .collect(),
            obstacles: p["obstacles"].as_array().expect("obstacles").iter().map(obstacle).collect(),
        })
        .collect()
}
