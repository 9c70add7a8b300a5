//! The plan as one Parquet table, one row per output sample, for data sets of many plans.
//!
//! The columns are the same for every robot and task (joints numbered `q1`..`q7`, not named),
//! so the files of a batch concatenate into one table (`pandas.read_parquet("out/")`, polars'
//! `scan_parquet("out/*.parquet")`); the joint names, the robot and the rate go in the file's
//! key-value metadata. parquet enters the crate here only.

use std::io::Write;
use std::sync::Arc;

use ::parquet::basic::{Compression, ZstdLevel};
use ::parquet::column::writer::ColumnWriter;
use ::parquet::data_type::ByteArray;
use ::parquet::file::metadata::KeyValue;
use ::parquet::file::properties::WriterProperties;
use ::parquet::file::writer::SerializedFileWriter;
use ::parquet::schema::parser::parse_message_type;

use super::atomic::Failure;
use crate::collision::{CollisionScene, min_distance};
use crate::kinematics::{arm_pose, cpsa_state};
use crate::language::Task;
use crate::math::{DOF, Real, UnitQuaternion};
use crate::robot::Robot;
use crate::solve::Plan;

/// The values of one column, in sample order.
enum Values {
    /// UTF-8 text (`binary (STRING)`).
    Text(Vec<ByteArray>),
    /// 32-bit integers.
    Integer(Vec<i32>),
    /// Doubles, never null.
    Real(Vec<Real>),
    /// Doubles, null where the value does not exist (a singular swivel, no pair to measure).
    Nullable(Vec<Option<Real>>),
}

impl Values {
    /// The column's line in the Parquet message type.
    fn schema_line(&self, name: &str) -> String {
        match self {
            Values::Text(_) => format!("required binary {name} (STRING);"),
            Values::Integer(_) => format!("required int32 {name};"),
            Values::Real(_) => format!("required double {name};"),
            Values::Nullable(_) => format!("optional double {name};"),
        }
    }
}

/// Which segment each sample belongs to: the last one started at or before its time.
fn segment_of_samples(plan: &Plan) -> Vec<usize> {
    let mut index = 0;
    plan.trajectory
        .times()
        .iter()
        .map(|&t| {
            while index + 1 < plan.segments.len() && plan.segments[index + 1].start <= t {
                index += 1;
            }
            index
        })
        .collect()
}

/// The table's columns, in order: `task`, `action`, `action_index`, `segment` (within its
/// action, from 0), `t` (s), `q1`..`q7` (rad), `qd1`..`qd7` (rad/s), the wrist state in {b}:
/// `pw_x`, `pw_y`, `pw_z` (m), `ow_w`, `ow_x`, `ow_y`, `ow_z` (a unit quaternion, w ≥ 0),
/// `swivel` (rad, null where singular), then `clearance` (m: the smallest distance between
/// the arm and the obstacles of the sample's action, or between self pairs; null when there is
/// no pair).
fn columns(robot: &Robot, task: &Task, plan: &Plan, task_id: &str) -> Vec<(String, Values)> {
    let samples = plan.trajectory.len();
    let segments = segment_of_samples(plan);
    let task_b = task.in_base_frame(&robot.structure.shoulder_in_base_link);
    let scenes: Vec<CollisionScene> =
        (0..task_b.actions.len()).map(|a| CollisionScene::new(&task_b.action_scene(a))).collect();

    let mut wrist: Vec<Vec<_>> = (0..7).map(|_| Vec::with_capacity(samples)).collect();
    let mut swivel = Vec::with_capacity(samples);
    let mut clearance = Vec::with_capacity(samples);
    for (q, &segment) in plan.trajectory.positions().iter().zip(&segments) {
        let pose = arm_pose(robot, q);
        let pw = pose.wrist - pose.shoulder;
        let ow = UnitQuaternion::from_rotation_matrix(&pose.hand);
        let sign = if ow.w < 0.0 { -1.0 } else { 1.0 };
        let values = [pw.x, pw.y, pw.z, sign * ow.w, sign * ow.i, sign * ow.j, sign * ow.k];
        for (column, value) in wrist.iter_mut().zip(values) {
            column.push(value);
        }
        swivel.push(cpsa_state(robot, &pose).ok().map(|s| s.swivel));
        let scene = plan.segments.get(segment).and_then(|s| scenes.get(s.action_index));
        clearance.push(scene.and_then(|scene| min_distance(robot, &pose, scene)).map(|d| d.0));
    }

    let per_sample = |f: &dyn Fn(usize) -> ByteArray| (0..samples).map(f).collect::<Vec<_>>();
    let action = |i: usize| plan.segments.get(segments[i]);
    let mut columns = vec![
        ("task".to_owned(), Values::Text(per_sample(&|_| ByteArray::from(task_id)))),
        (
            "action".to_owned(),
            Values::Text(per_sample(&|i| ByteArray::from(action(i).map_or("", |s| &s.action)))),
        ),
        (
            "action_index".to_owned(),
            Values::Integer(
                (0..samples).map(|i| action(i).map_or(0, |s| to_i32(s.action_index))).collect(),
            ),
        ),
        (
            "segment".to_owned(),
            Values::Integer(
                (0..samples).map(|i| action(i).map_or(0, |s| to_i32(s.segment))).collect(),
            ),
        ),
        ("t".to_owned(), Values::Real(plan.trajectory.times().to_vec())),
    ];
    for (prefix, rows) in [("q", plan.trajectory.positions()), ("qd", plan.trajectory.velocities())]
    {
        for j in 0..DOF {
            let values = rows.iter().map(|row| row[j]).collect();
            columns.push((format!("{prefix}{}", j + 1), Values::Real(values)));
        }
    }
    let wrist_names = ["pw_x", "pw_y", "pw_z", "ow_w", "ow_x", "ow_y", "ow_z"];
    for (name, values) in wrist_names.into_iter().zip(wrist) {
        columns.push((name.to_owned(), Values::Real(values)));
    }
    columns.push(("swivel".to_owned(), Values::Nullable(swivel)));
    columns.push(("clearance".to_owned(), Values::Nullable(clearance)));
    columns
}

/// Counts far below 2³¹ (segments, actions) as a Parquet int32.
fn to_i32(n: usize) -> i32 {
    i32::try_from(n).unwrap_or(i32::MAX)
}

/// The key-value metadata: what the columns leave out.
fn metadata(robot: &Robot, plan: &Plan) -> Vec<KeyValue> {
    let joint_names = serde_json::to_string(&plan.joint_names).unwrap_or_default();
    [
        ("a2ml.version", env!("CARGO_PKG_VERSION").to_owned()),
        ("a2ml.task", plan.task.clone()),
        ("a2ml.robot", robot.name.clone()),
        ("a2ml.joint_names", joint_names),
        ("a2ml.rate", plan.rate.to_string()),
    ]
    .into_iter()
    .map(|(key, value)| KeyValue::new(key.to_owned(), value))
    .collect()
}

fn failure(e: ::parquet::errors::ParquetError) -> Failure {
    match e {
        ::parquet::errors::ParquetError::External(inner) => {
            Failure::Io(std::io::Error::other(inner.to_string()))
        }
        other => Failure::Parquet(other.to_string()),
    }
}

/// Writes the table of [`columns`] as one row group, zstd-compressed.
pub(super) fn write<W: Write + Send>(
    out: W,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    task_id: &str,
) -> Result<(), Failure> {
    let columns = columns(robot, task, plan, task_id);
    let lines: Vec<String> = columns.iter().map(|(name, v)| v.schema_line(name)).collect();
    let schema = parse_message_type(&format!("message a2ml_plan {{ {} }}", lines.join(" ")))
        .map_err(failure)?;
    let properties = WriterProperties::builder()
        .set_compression(Compression::ZSTD(ZstdLevel::default()))
        .set_key_value_metadata(Some(metadata(robot, plan)))
        .set_created_by(format!("a2ml {}", env!("CARGO_PKG_VERSION")))
        .build();
    let mut writer =
        SerializedFileWriter::new(out, Arc::new(schema), Arc::new(properties)).map_err(failure)?;
    let mut group = writer.next_row_group().map_err(failure)?;
    let mut values = columns.into_iter().map(|(_, v)| v);
    while let Some(mut column) = group.next_column().map_err(failure)? {
        let written = match (column.untyped(), values.next()) {
            (ColumnWriter::ByteArrayColumnWriter(w), Some(Values::Text(v))) => {
                w.write_batch(&v, None, None)
            }
            (ColumnWriter::Int32ColumnWriter(w), Some(Values::Integer(v))) => {
                w.write_batch(&v, None, None)
            }
            (ColumnWriter::DoubleColumnWriter(w), Some(Values::Real(v))) => {
                w.write_batch(&v, None, None)
            }
            (ColumnWriter::DoubleColumnWriter(w), Some(Values::Nullable(v))) => {
                let present: Vec<Real> = v.iter().flatten().copied().collect();
                let levels: Vec<i16> = v.iter().map(|x| i16::from(x.is_some())).collect();
                w.write_batch(&present, Some(&levels), None)
            }
            // The schema is made from the columns in their order, so this is a bug.
            _ => Err(::parquet::errors::ParquetError::General(
                "a column does not match its schema".to_owned(),
            )),
        };
        written.map_err(failure)?;
        column.close().map_err(failure)?;
    }
    group.close().map_err(failure)?;
    writer.close().map_err(failure)?;
    Ok(())
}

/// The table as the bytes of a Parquet file (for Python's `Plan.to_arrow`).
pub(super) fn to_bytes(
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    task_id: &str,
) -> Result<Vec<u8>, Failure> {
    let mut bytes = Vec::new();
    write(&mut bytes, robot, task, plan, task_id)?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use ::parquet::file::reader::{FileReader, SerializedFileReader};
    use ::parquet::record::Field;

    use super::*;
    use crate::collision::CollisionScene;
    use crate::solve::PlanOptions;

    /// The example of `examples/construct_scene.a2ml`: a reach among five obstacles.
    fn scene_plan() -> (Robot, Task, Plan) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/construct_scene.a2ml");
        let task = crate::language::load(&path).expect("the example is valid");
        let robot = task.load_robot(&crate::RobotOptions::default()).expect("its robot");
        let plan = crate::solve::plan(&robot, &task, &PlanOptions::default()).expect("planned");
        (robot, task, plan)
    }

    #[test]
    fn the_table_reads_back_one_row_per_sample() {
        let (robot, task, plan) = scene_plan();
        let path =
            std::env::temp_dir().join(format!("a2ml-parquet-{}.parquet", std::process::id()));
        super::super::write_parquet(&path, &robot, &task, &plan, "scene-7").expect("written");
        let bytes = to_bytes(&robot, &task, &plan, "scene-7").expect("encoded");
        assert_eq!(std::fs::read(&path).expect("readable"), bytes, "the file is the bytes");
        let file = std::fs::File::open(&path).expect("readable");
        let reader = SerializedFileReader::new(file).expect("a Parquet file");
        std::fs::remove_file(&path).ok();
        let metadata = reader.metadata().file_metadata();
        assert_eq!(metadata.num_rows(), plan.trajectory.len() as i64);
        let joint_names = metadata
            .key_value_metadata()
            .and_then(|kv| kv.iter().find(|kv| kv.key == "a2ml.joint_names").cloned())
            .and_then(|kv| kv.value)
            .expect("joint names");
        assert_eq!(joint_names, serde_json::to_string(&plan.joint_names).expect("json"));

        let scene = CollisionScene::new(
            &task.in_base_frame(&robot.structure.shoulder_in_base_link).action_scene(0),
        );
        let rows = reader.get_row_iter(None).expect("rows");
        for (i, row) in rows.enumerate() {
            let row = row.expect("a row");
            let field = |name: &str| {
                row.get_column_iter().find(|(n, _)| n.as_str() == name).map(|(_, f)| f.clone())
            };
            let real = |name: &str| match field(name) {
                Some(Field::Double(x)) => x,
                other => panic!("{name}: {other:?}"),
            };
            assert_eq!(field("task"), Some(Field::Str("scene-7".into())));
            assert_eq!(field("action"), Some(Field::Str("reach_over_table".into())));
            assert_eq!(real("t"), plan.trajectory.times()[i]);
            let q = plan.trajectory.positions()[i];
            for j in 0..DOF {
                assert_eq!(real(&format!("q{}", j + 1)), q[j]);
                assert_eq!(real(&format!("qd{}", j + 1)), plan.trajectory.velocities()[i][j]);
            }
            // The wrist state and the clearance, recomputed independently of the writer.
            let pose = arm_pose(&robot, &q);
            let pw = pose.wrist - pose.shoulder;
            assert_eq!([real("pw_x"), real("pw_y"), real("pw_z")], [pw.x, pw.y, pw.z]);
            let ow =
                nalgebra::Quaternion::new(real("ow_w"), real("ow_x"), real("ow_y"), real("ow_z"));
            let ow = UnitQuaternion::from_quaternion(ow);
            assert!(real("ow_w") >= 0.0);
            // Entry by entry: angle_to takes an acos, NaN just above 1.
            let gap = (ow.to_rotation_matrix().matrix() - pose.hand.matrix()).amax();
            assert!(gap < 1e-12, "row {i}: the quaternion is {gap} off the hand's rotation");
            let expected = min_distance(&robot, &pose, &scene).expect("obstacles").0;
            assert!((real("clearance") - expected).abs() < 1e-12, "row {i}");
            assert!(real("clearance") >= plan.safety_distance - 1e-4, "row {i} is clear");
        }
    }
}
