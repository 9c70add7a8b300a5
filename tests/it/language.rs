//! The task language: a corpus of malformed files, each with the exact
//! location and message of its error, and no panics on arbitrary input.

use std::path::PathBuf;

use a2ml::language::{Diagnostics, format, load, parse, parse_ast};

fn malformed_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/malformed").join(format!("{name}.a2ml"))
}

fn diagnostics(name: &str) -> Diagnostics {
    let path = malformed_path(name);
    let text = std::fs::read_to_string(&path).expect("corpus file exists");
    match parse(&text, Some(&path)) {
        Ok(task) => panic!("{name}: expected an error, got a valid task `{}`", task.name),
        Err(d) => d,
    }
}

/// Asserts that `name` reports an error at line:column whose message
/// contains `message`, and that the rendering shows the location.
fn expect_error(name: &str, line: usize, column: usize, message: &str) {
    let d = diagnostics(name);
    let found = d.items.iter().any(|item| {
        d.line_col(item.span.start) == (line, column) && item.message.contains(message)
    });
    let rendered = d.to_string();
    assert!(found, "{name}: no error at {line}:{column} containing {message:?}; got:\n{rendered}");
    assert!(rendered.contains(&format!("{name}.a2ml:{line}:{column}")), "{rendered}");
    assert!(rendered.contains('^'), "{rendered}");
    snapshot_rendered(name, &rendered);
}

/// The whole rendering (every error, its location, caret and help) against
/// `snapshots/malformed/<name>.snap`, with the checkout's folder written
/// `[repo]` so that the snapshot holds on any machine. A mismatch fails the
/// test; `cargo insta review` (or `INSTA_UPDATE=always`) accepts a new one.
fn snapshot_rendered(name: &str, rendered: &str) {
    let portable = rendered.replace(env!("CARGO_MANIFEST_DIR"), "[repo]");
    insta::with_settings!({
        snapshot_path => "snapshots/malformed",
        prepend_module_to_snapshot => false,
        omit_expression => true,
    }, {
        insta::assert_snapshot!(name, portable);
    });
}

macro_rules! malformed {
    ($name:ident, $line:expr, $column:expr, $message:expr) => {
        #[test]
        fn $name() {
            expect_error(stringify!($name), $line, $column, $message);
        }
    };
}

mod malformed {
    use super::expect_error;

    malformed!(bad_token, 4, 31, "expected");
    malformed!(solver_no_such_segment, 4, 20, "has 2 segments (MS1, MS2): there is no MS3");
    malformed!(solver_not_a_segment, 5, 12, "`S1` is not a segment");
    malformed!(missing_brace, 6, 1, "expected `+Se` or `action`");
    malformed!(unterminated_string, 1, 7, "expected");
    malformed!(missing_equals, 4, 13, "expected `=` or a state variable");
    malformed!(empty_vector, 4, 16, "expected a number");
    malformed!(bad_number, 4, 18, "expected");
    malformed!(no_actions, 3, 1, "expected `action`");
    malformed!(unknown_top_level, 2, 1, "expected");
    malformed!(priority_without_goal, 5, 3, "expected");
    malformed!(bad_path_hardness_colon, 5, 3, "expected");
    malformed!(unknown_variable, 4, 10, "unknown state variable `θs`");
    malformed!(unknown_variable_ascii, 4, 10, "unknown state variable `Pv`");
    malformed!(unknown_unit, 4, 18, "unknown unit `degs`");
    malformed!(wrong_dimension, 4, 18, "`cm` is a length");
    malformed!(position_in_degrees, 4, 31, "`deg` is an angle");
    malformed!(unknown_axis, 4, 19, "unknown axis `w`");
    malformed!(unknown_shape, 3, 7, "unknown shape `sphre`");
    malformed!(unknown_setting, 2, 12, "unknown setting `rat`");
    malformed!(unknown_solver, 5, 12, "unknown solver `rrtt`");
    malformed!(unknown_hardness, 4, 36, "expected `hard` or `soft`");
    malformed!(unknown_frame, 2, 18, "`base` or `root`");
    malformed!(mixed_spaces_goal, 4, 13, "Os belongs to HAT space, but Pw belongs to CPSA space");
    malformed!(mixed_spaces_path, 4, 35, "θe belongs to HAT space");
    malformed!(priority_inside_one_space, 4, 33, "both goals are in CPSA space");
    malformed!(same_variable_both_goals, 4, 30, "Ow appears in both goals");
    malformed!(variable_twice, 4, 13, "Pw is named twice");
    malformed!(value_count, 4, 10, "2 variables (Pw, Ow) but 1 value");
    malformed!(wrong_value_kind, 4, 15, "Ow is a rotation");
    malformed!(vector_length, 4, 15, "Pw needs 3 numbers, but 2 are given");
    malformed!(line_on_angle, 4, 10, "`line` moves Pw, not θsw");
    malformed!(by_on_position, 4, 10, "`by` changes θsw or θe, not Pw");
    malformed!(arc_on_rotation, 5, 10, "`arc` moves Pw, not Ow");
    malformed!(arc_without_pw_goal, 5, 10, "`arc` runs from the start to the action's Pw goal");
    malformed!(zero_line_direction, 4, 18, "the line direction must not be zero");
    malformed!(negative_path_size, 4, 28, "the line length must be positive");
    malformed!(zero_by, 4, 17, "`by` needs a non-zero angle");
    malformed!(axes_not_orthogonal, 4, 15, "must be orthogonal, but they are 45.0° apart");
    malformed!(axes_wrong_names, 4, 20, "Os is given by axes `r` and `l`, not `f`");
    malformed!(zero_quaternion, 4, 15, "a quaternion must not be zero");
    malformed!(no_goal_no_path, 3, 10, "has neither a goal nor a path");
    malformed!(two_goals, 5, 5, "an action has one `goal`");
    malformed!(negative_duration, 5, 14, "the duration must be positive");
    malformed!(incomplete_segment, 4, 5, "does not drive θsw");
    malformed!(
        mixed_segment,
        4,
        31,
        "θe belongs to HAT space, but this segment is in CPSA space (Pw, Ow, θsw)"
    );
    malformed!(repeated_in_segment, 4, 40, "θsw is already driven in this segment");
    malformed!(remove_absent, 4, 36, "θsw is not in the group before `-Pa`");
    malformed!(bare_primitive, 4, 19, "a primitive needs `.goal(..)`");
    malformed!(ow_only_segment, 4, 5, "a segment covers a whole space");
    malformed!(duplicate_obstacle, 4, 3, "obstacle `post` is declared twice");
    malformed!(negative_radius, 3, 37, "the radius must be positive");
    malformed!(shape_rotation_not_a_rotation, 3, 61, "the shape's orientation is a rotation");
    malformed!(shape_zero_axis, 3, 62, "the axis must not be zero");
    malformed!(start_wrong_count, 2, 7, "the start configuration needs 7 numbers, but 3 are given");
    malformed!(start_state_incomplete, 2, 7, "also needs Ow");
    malformed!(missing_robot_file, 1, 8, "robot file not found");
    malformed!(robot_empty_tip, 1, 39, "a link name cannot be empty");
    malformed!(no_robot, 1, 1, "the file names no robot");
    malformed!(several_errors, 2, 12, "unknown setting `rat`");
    malformed!(unknown_unit_and_variable, 4, 18, "unknown unit `degs`");
    malformed!(
        path_without_size_or_goal,
        4,
        10,
        "without a goal nothing can compute this path's size"
    );
    malformed!(
        soft_path_without_goal,
        4,
        45,
        "a soft path gives way to a goal, but this action has none"
    );
    malformed!(goal_and_hard_path_same_variable, 5, 10, "Pw has both a goal and a path constraint");
    malformed!(explicit_path_without_size, 4, 19, "a path in an explicit segment needs its size");
    malformed!(transition_bare_percent, 2, 23, "the transition overlap is between 0 and 100 %");
    malformed!(remove_without_group, 4, 59, "θsw is not in the group before `-Pa`");
    malformed!(duplicate_action, 4, 10, "action `a` is declared twice");
    malformed!(strips_unknown_fact, 6, 11, "fact `holdin` is never true");
    malformed!(strips_goal_unreachable, 4, 10, "fact `box_aside` is never true");
    malformed!(strips_init_without_goal, 3, 8, "also needs a `goal { .. }`");
    malformed!(bad_seed, 2, 17, "the seed is a whole number from 0 to 18446744073709551615");
    malformed!(unknown_contact, 5, 15, "unknown obstacle `box_aa`");
    malformed!(contact_without_scene, 5, 15, "unknown obstacle `box_a`");
    malformed!(duplicate_contact, 5, 22, "obstacle `box_a` is listed twice");
    malformed!(contact_twice, 6, 13, "`contact` is given twice");
}

#[test]
fn every_corpus_file_has_a_test() {
    let here = include_str!("language.rs");
    // rustfmt may break a long macro call over lines.
    let compact: String = here.chars().filter(|c| !c.is_whitespace()).collect();
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/malformed");
    for entry in std::fs::read_dir(dir).expect("corpus folder") {
        let path = entry.expect("entry").path();
        let stem = path.file_stem().and_then(|s| s.to_str()).expect("utf-8 name").to_owned();
        assert!(compact.contains(&format!("malformed!({stem},")), "{stem}.a2ml has no test");
    }
}

/// Every shipped example validates and survives `fmt`: print, parse, and
/// the same syntax tree comes back; printing again changes nothing.
#[test]
fn examples_validate_and_round_trip_through_fmt() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut count = 0;
    let folders = ["examples", "examples/paper"].map(|f| root.join(f));
    for entry in folders.iter().flat_map(|d| std::fs::read_dir(d).expect("examples folder")) {
        let path = entry.expect("entry").path();
        if path.extension().and_then(|e| e.to_str()) != Some("a2ml") {
            continue;
        }
        count += 1;
        if let Err(e) = load(&path) {
            panic!("{} does not validate:\n{e}", path.display());
        }
        let text = std::fs::read_to_string(&path).expect("readable");
        let tree = parse_ast(&text, Some(&path)).expect("parses");
        let printed = format(&tree);
        let again = parse_ast(&printed, Some(&path)).unwrap_or_else(|e| {
            panic!("{}: fmt output does not parse:\n{e}\n{printed}", path.display())
        });
        assert_eq!(again, tree, "{}: fmt changed the syntax tree", path.display());
        assert_eq!(format(&again), printed, "{}: fmt is not idempotent", path.display());
        // The printed form means the same task.
        let task = parse(&printed, Some(&path)).expect("printed form validates");
        assert_eq!(task, load(&path).expect("validates"), "{}", path.display());
    }
    assert!(count >= 20, "only {count} examples");
}

#[test]
fn several_errors_are_all_reported() {
    let d = diagnostics("several_errors");
    assert!(d.items.len() >= 3, "{d}");
    assert!(d.to_string().ends_with(&format!("{} errors", d.items.len())));
}

#[test]
fn independent_problems_of_one_statement_are_all_reported() {
    let d = diagnostics("unknown_unit_and_variable");
    let messages: Vec<&str> = d.items.iter().map(|i| i.message.as_str()).collect();
    for expected in [
        "unknown state variable `θs`",
        "unknown unit `degs`",
        "found `medium`",
        "Os belongs to HAT",
    ] {
        assert!(
            messages.iter().any(|m| m.contains(expected)),
            "{expected:?} missing: {messages:?}"
        );
    }
}

/// LANGUAGE.md's complement form and the paper's order (MS = MP +Pa MP−)
/// both read: `-Pa` binds to the group just before it.
#[test]
fn complement_may_come_first_or_last() {
    let robot = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("robots/coman_right_arm.urdf");
    let head = format!("robot \"{}\"\ntask t {{ action a explicit {{\n", robot.display());
    let segments = [
        "segment 1 s { (Pw Ow θsw) -Pa θsw +Pa θsw.goal(1 rad) }",
        "segment 1 s { θsw.goal(1 rad) +Pa (Pw Ow θsw).hold -Pa θsw }",
        "segment 1 s { (Pw Ow).hold +Pa θsw.goal(1 rad) }",
    ];
    let tasks: Vec<_> = segments
        .iter()
        .map(|s| parse(&format!("{head}{s}\n}} }}\n"), None).unwrap_or_else(|e| panic!("{s}: {e}")))
        .collect();
    for task in &tasks {
        let a2ml::language::ActionBody::Explicit(segs) = &tasks[0].actions[0].body else {
            panic!("explicit")
        };
        let a2ml::language::ActionBody::Explicit(other) = &task.actions[0].body else {
            panic!("explicit")
        };
        let mut mine: Vec<_> = segs[0].primitives.iter().map(|p| format!("{:?}", p)).collect();
        let mut theirs: Vec<_> = other[0].primitives.iter().map(|p| format!("{:?}", p)).collect();
        mine.sort();
        theirs.sort();
        assert_eq!(mine, theirs);
    }
}

#[test]
fn did_you_mean_suggests_close_names() {
    let cases = [
        ("unknown_variable", "θsw"),
        ("unknown_unit", "deg"),
        ("unknown_shape", "sphere"),
        ("unknown_setting", "rate"),
        ("unknown_solver", "rrt"),
        ("transition_bare_percent", "20 %"),
        ("strips_unknown_fact", "holding"),
        ("unknown_contact", "box_a"),
    ];
    for (name, suggestion) in cases {
        let d = diagnostics(name);
        let help: Vec<&str> = d.items.iter().filter_map(|i| i.help.as_deref()).collect();
        assert!(
            help.iter().any(|h| h.contains(&format!("`{suggestion}`"))),
            "{name}: no suggestion of {suggestion}: {help:?}"
        );
    }
}

/// `contact` names obstacles of the scene, and the action's scene leaves
/// them out; other actions keep the whole scene.
#[test]
fn contact_leaves_obstacles_out_of_the_action_scene() {
    let robot = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("robots/coman_right_arm.urdf");
    let text = format!(
        "robot \"{}\"
scene {{ a = sphere at [0.3, 0, 0] radius 0.05  b = sphere at [0.3, 0.2, 0] radius 0.05 }}
task t {{
  action push {{ contact {{ b }} path Pw line [0, 1, 0] 0.1 m, Ow hold, θsw hold }}
  action both explicit {{ contact {{ b, a }} segment {{ (Pw Ow θsw).hold }} }}
  action none {{ path θsw by 10 deg, Pw hold, Ow hold }}
}}
",
        robot.display()
    );
    let task = parse(&text, None).unwrap_or_else(|e| panic!("{e}"));
    let scene =
        |i: usize| -> Vec<String> { task.action_scene(i).into_iter().map(|o| o.name).collect() };
    assert_eq!(task.actions[0].contact, ["b"]);
    assert_eq!(scene(0), ["a"]);
    assert_eq!(task.actions[1].contact, ["b", "a"]);
    assert!(scene(1).is_empty());
    assert!(task.actions[2].contact.is_empty());
    assert_eq!(scene(2), ["a", "b"]);
    // Without a scene, the help says there is nothing to name.
    let d = diagnostics("contact_without_scene");
    assert!(d.items.iter().any(|i| i.help.as_deref().is_some_and(|h| h.contains("no obstacles"))));
}

mod no_panic {
    use super::*;
    use proptest::prelude::*;

    /// Fragments of real A2ML, so that random sequences reach deep rules.
    const TOKENS: &[&str] = &[
        "robot",
        "\"../../robots/coman_right_arm.urdf\"",
        "start",
        "scene",
        "settings",
        "task",
        "action",
        "explicit",
        "segment",
        "goal",
        "path",
        "duration",
        "solver",
        "init",
        "pre",
        "add",
        "del",
        "contact",
        "hold",
        "line",
        "about",
        "by",
        "hard",
        "soft",
        "box",
        "sphere",
        "capsule",
        "cylinder",
        "at",
        "size",
        "from",
        "to",
        "radius",
        "height",
        "rpy",
        "quat",
        "axes",
        "Pw",
        "Ow",
        "θsw",
        "Os",
        "θe",
        "sw",
        "e",
        "x",
        "-z",
        "r",
        "f",
        "p",
        "{",
        "}",
        "(",
        ")",
        "[",
        "]",
        ",",
        ":",
        "=",
        ">",
        "≻",
        ".",
        "+Pa",
        "-Pa",
        "+Tr",
        "+Se",
        "0",
        "-1.5",
        "30",
        "1e3",
        "deg",
        "rad",
        "m",
        "cm",
        "mm",
        "s",
        "ms",
        "%",
        "Hz",
        "°",
        "name",
        "\n",
        "#c\n",
        " ",
    ];

    proptest! {
        #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

        #[test]
        fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
            let text = String::from_utf8_lossy(&bytes);
            let _ = parse_ast(&text, None);
            let _ = parse(&text, None);
        }

        #[test]
        fn token_soup_never_panics(picks in proptest::collection::vec(0..TOKENS.len(), 0..120)) {
            let text: String = picks.iter().map(|&i| TOKENS[i]).collect::<Vec<_>>().join(" ");
            let path = super::malformed_path("soup");
            if let Err(d) = parse(&text, Some(&path)) {
                // Rendering must not panic either, whatever the spans.
                let _ = d.to_string();
            }
        }
    }
}

/// The formatter's laws on every example and every file of the malformed
/// corpus that parses (a semantic error is no reason not to format):
/// `fmt(fmt(x)) == fmt(x)`, `parse(fmt(x)) == parse(x)` modulo spans and
/// layout, the same comment texts (as a multiset, since canonical order may
/// move a statement with its comments), and no line past the width unless
/// one piece alone is longer. A file that does not parse is refused.
#[test]
fn fmt_laws_over_the_examples_and_the_malformed_corpus() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut formatted = 0;
    let mut refused = 0;
    for folder in ["examples", "examples/paper", "tests/malformed"] {
        for entry in std::fs::read_dir(root.join(folder)).expect("folder") {
            let path = entry.expect("entry").path();
            if path.extension().and_then(|e| e.to_str()) != Some("a2ml") {
                continue;
            }
            let text = std::fs::read_to_string(&path).expect("readable");
            let Ok(tree) = parse_ast(&text, Some(&path)) else {
                refused += 1;
                continue;
            };
            formatted += 1;
            let printed = format(&tree);
            let again = parse_ast(&printed, Some(&path)).unwrap_or_else(|e| {
                panic!("{}: fmt output does not parse:\n{e}\n{printed}", path.display())
            });
            assert_eq!(again.items, tree.items, "{}: fmt changed the meaning", path.display());
            let texts = |file: &a2ml::language::ast::File| {
                let mut texts: Vec<String> = file.comments.iter().map(|c| c.text.clone()).collect();
                texts.sort();
                texts
            };
            assert_eq!(texts(&again), texts(&tree), "{}: comments", path.display());
            assert_eq!(format(&again), printed, "{}: fmt is not idempotent", path.display());
            for line in printed.lines() {
                let code =
                    line.split(" #").next().unwrap_or(line).split(" //").next().unwrap_or(line);
                let is_comment = line.trim_start().starts_with(['#', '/']);
                let scene_row = line.contains(" = ") && !line.trim_start().starts_with("goal");
                assert!(
                    is_comment || scene_row || code.chars().count() <= a2ml::language::WIDTH,
                    "{}: line too long:\n{line}",
                    path.display()
                );
            }
        }
    }
    assert!(formatted >= 60, "only {formatted} files formatted");
    assert!(refused >= 5, "only {refused} files refused");
}
