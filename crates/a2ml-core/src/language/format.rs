//! The canonical text of a syntax tree: what `a2ml fmt` prints.
//!
//! The law: for every text that parses, `parse_ast(format(parse_ast(text)))`
//! equals `parse_ast(text)`, and formatting is idempotent. Comments are not
//! in the tree, so they are dropped. What the tree does not keep is printed
//! one fixed way: `>` for priority, no `+Se`, statements of an action in the
//! order pre, add, del, goal, path, duration, solver.

use super::ast::{
    Action, ActionBody, Combine, Facts, Feature, File, Goal, GoalTerm, Item, Name, Obstacle, Path,
    Primitive, PrimitiveConstraint, Quantity, Scene, Segment, Setting, SettingValue, Settings,
    Shape, Start, Task, Value, Vector,
};
use crate::math::Real;

/// Spaces per indentation level.
const INDENT: usize = 2;

/// Prints a syntax tree in the canonical layout: two-space indentation, one
/// statement per line, a blank line between blocks, scene obstacles aligned
/// in columns, numbers in their shortest form that reads back to the same
/// `f64`, units and names as written. Comments are not in the tree and so
/// are not printed.
pub fn format(file: &File) -> String {
    let one_liner = |item: &Item| matches!(item, Item::Robot(_) | Item::Start(_));
    let mut p = Printer::default();
    let mut previous: Option<&Item> = None;
    for item in &file.items {
        // `robot` and `start` stay together as the header; blocks stand apart.
        if previous.is_some_and(|prev| !(one_liner(prev) && one_liner(item))) {
            p.blank();
        }
        match item {
            Item::Robot(path) => p.line(&format!("robot {}", string(path))),
            Item::Start(start) => p.line(&self::start(start)),
            Item::Scene(scene) => p.scene(scene),
            Item::Settings(settings) => p.settings(settings),
            Item::Task(task) => p.task(task),
        }
        previous = Some(item);
    }
    p.out
}

/// Lines with indentation.
#[derive(Default)]
struct Printer {
    out: String,
    depth: usize,
}

impl Printer {
    /// Writes one statement at the current depth. A `\n` inside `text` (see
    /// [`gap`]) continues the statement on a line indented two levels more.
    fn line(&mut self, text: &str) {
        for (i, part) in text.split('\n').enumerate() {
            let depth = if i == 0 { self.depth } else { self.depth + 2 };
            self.out.push_str(&" ".repeat(depth * INDENT));
            self.out.push_str(part);
            self.out.push('\n');
        }
    }

    fn blank(&mut self) {
        self.out.push('\n');
    }

    /// `head {`, the lines `body` writes, `}`; `head {}` when it writes none.
    fn block(&mut self, head: &str, body: impl FnOnce(&mut Self)) {
        let mark = self.out.len();
        self.line(&format!("{head} {{"));
        let open = self.out.len();
        self.depth += 1;
        body(self);
        self.depth -= 1;
        if self.out.len() == open {
            self.out.truncate(mark);
            self.line(&format!("{head} {{}}"));
        } else {
            self.line("}");
        }
    }

    fn scene(&mut self, scene: &Scene) {
        let name_width = scene.obstacles.iter().map(|o| width(&o.name.text)).max().unwrap_or(0);
        let shape_width =
            scene.obstacles.iter().map(|o| width(shape_keyword(&o.shape))).max().unwrap_or(0);
        self.block("scene", |p| {
            for obstacle in &scene.obstacles {
                p.line(&self::obstacle(obstacle, name_width, shape_width));
            }
        });
    }

    fn settings(&mut self, settings: &Settings) {
        self.block("settings", |p| {
            for Setting { name, value, .. } in &settings.entries {
                let value = match value {
                    SettingValue::Quantity(q) => quantity(q),
                    SettingValue::Word(word) => word.text.clone(),
                };
                p.line(&format!("{} {value}", name.text));
            }
        });
    }

    fn task(&mut self, task: &Task) {
        self.block(&format!("task {}", task.name.text), |p| {
            for facts in &task.init {
                p.line(&format!("init {}", self::facts(facts)));
            }
            for facts in &task.goal {
                p.line(&format!("goal {}", self::facts(facts)));
            }
            for (i, action) in task.actions.iter().enumerate() {
                if i > 0 || !task.init.is_empty() || !task.goal.is_empty() {
                    p.blank();
                }
                p.action(action);
            }
        });
    }

    fn action(&mut self, action: &Action) {
        let mut head = format!("action {}", action.name.text);
        if let Some(description) = &action.description {
            head = format!("{head} {}", string(description));
        }
        if matches!(action.body, ActionBody::Explicit { .. }) {
            head.push_str(" explicit");
        }
        self.block(&head, |p| {
            for (keyword, list) in
                [("pre", &action.pre), ("add", &action.add), ("del", &action.del)]
            {
                for facts in list {
                    p.line(&format!("{keyword} {}", self::facts(facts)));
                }
            }
            match &action.body {
                ActionBody::Constraints { goals, paths, durations } => {
                    for g in goals {
                        p.line(&goal(g));
                    }
                    for path in paths {
                        p.line(&self::path(path));
                    }
                    for d in durations {
                        p.line(&format!("duration {}", quantity(d)));
                    }
                    p.solvers(action);
                }
                ActionBody::Explicit { segments } => {
                    // The grammar wants an explicit action's solver before its segments.
                    p.solvers(action);
                    for (i, s) in segments.iter().enumerate() {
                        let joint = if i == 0 { "" } else { "+Tr " };
                        p.line(&format!("{joint}{}", segment(s)));
                    }
                }
            }
        });
    }

    fn solvers(&mut self, action: &Action) {
        for solver in &action.solver {
            self.line(&format!("solver {}", solver.text));
        }
    }
}

/// Width of a name in columns (names may hold `θ`).
fn width(text: &str) -> usize {
    text.chars().count()
}

/// `text` padded with spaces to `width` columns.
fn pad(text: &str, columns: usize) -> String {
    format!("{text}{}", " ".repeat(columns.saturating_sub(width(text))))
}

/// A string in double quotes; the grammar keeps `"` and newlines out of it.
fn string(s: &Name) -> String {
    format!("\"{}\"", s.text)
}

/// The shortest decimal text that reads back to exactly `x` (Rust's `{}` and
/// `{:e}` both round-trip), in exponent form only for very large or small
/// magnitudes. An overflowed literal such as `1e400` reads as infinity and
/// is printed `1e999`, which reads back as infinity too.
fn number(x: Real) -> String {
    let magnitude = x.abs();
    if magnitude.is_infinite() {
        if x < 0.0 { "-1e999" } else { "1e999" }.to_owned()
    } else if magnitude != 0.0 && !(1e-4..1e15).contains(&magnitude) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

fn numbers(values: &[Real]) -> String {
    values.iter().map(|&v| number(v)).collect::<Vec<_>>().join(", ")
}

/// ` unit` (`°` without the space), or nothing.
fn unit(unit: Option<&Name>) -> String {
    match unit {
        Some(u) if u.text == "°" => u.text.clone(),
        Some(u) => format!(" {}", u.text),
        None => String::new(),
    }
}

/// What separates a value with this unit from a word, number, bracket or
/// brace after it on the same statement: a space, or a line break when the
/// unit is one the grammar does not know. The grammar reads such a word as
/// a (misspelt) unit only when none of those follows it on its line, so
/// `radius 5 cmm height 1` would read `cmm` as something else.
fn gap(unit: Option<&Name>) -> &'static str {
    const KNOWN: [&str; 10] = ["mm", "ms", "m", "cm", "s", "deg", "rad", "Hz", "%", "°"];
    match unit {
        Some(u) if !KNOWN.contains(&u.text.as_str()) => "\n",
        _ => " ",
    }
}

fn quantity(q: &Quantity) -> String {
    format!("{}{}", number(q.value), unit(q.unit.as_ref()))
}

fn vector(v: &Vector) -> String {
    format!("[{}]{}", numbers(&v.values), unit(v.unit.as_ref()))
}

fn value(v: &Value) -> String {
    match v {
        Value::Quantity(q) => quantity(q),
        Value::Vector(v) => vector(v),
        Value::Rpy { angles, unit: u, .. } => {
            format!("rpy({}){}", numbers(angles), unit(u.as_ref()))
        }
        Value::Quat { wxyz, .. } => format!("quat({})", numbers(wxyz)),
        Value::Axes { pairs: [(k1, v1), (k2, v2)], .. } => {
            format!("axes({}: {}, {}: {})", k1.text, vector(v1), k2.text, vector(v2))
        }
    }
}

fn value_unit(v: &Value) -> Option<&Name> {
    match v {
        Value::Quantity(q) => q.unit.as_ref(),
        Value::Vector(v) => v.unit.as_ref(),
        Value::Rpy { unit, .. } => unit.as_ref(),
        Value::Quat { .. } | Value::Axes { .. } => None,
    }
}

/// `v1, v2` inside parentheses the caller writes.
fn value_list(values: &[Value]) -> String {
    values.iter().map(value).collect::<Vec<_>>().join(", ")
}

fn names(names: &[Name]) -> String {
    names.iter().map(|n| n.text.as_str()).collect::<Vec<_>>().join(" ")
}

fn facts(facts: &Facts) -> String {
    if facts.names.is_empty() {
        "{}".to_owned()
    } else {
        let list: Vec<&str> = facts.names.iter().map(|n| n.text.as_str()).collect();
        format!("{{ {} }}", list.join(", "))
    }
}

fn start(start: &Start) -> String {
    match start {
        Start::Joints(q) => format!("start {}", vector(q)),
        Start::State { entries, .. } => {
            let mut text = "start".to_owned();
            let mut sep = " ";
            for (variable, v) in entries {
                text.push_str(&format!("{sep}{} {}", variable.text, value(v)));
                sep = if gap(value_unit(v)) == "\n" { "\n" } else { "  " };
            }
            text
        }
    }
}

fn shape_keyword(shape: &Shape) -> &str {
    match shape {
        Shape::Box { .. } => "box",
        Shape::Sphere { .. } => "sphere",
        Shape::Capsule { .. } => "capsule",
        Shape::Cylinder { .. } => "cylinder",
        Shape::Unknown(name) => &name.text,
    }
}

/// `name = shape args`, the name and the shape keyword padded to the
/// scene's columns.
fn obstacle(o: &Obstacle, name_width: usize, shape_width: usize) -> String {
    let args = match &o.shape {
        Shape::Box { at, size } => {
            format!("at {}{}size {}", vector(at), gap(at.unit.as_ref()), vector(size))
        }
        Shape::Sphere { at, radius } => {
            format!("at {}{}radius {}", vector(at), gap(at.unit.as_ref()), quantity(radius))
        }
        Shape::Capsule { from, to, radius } => format!(
            "from {}{}to {}{}radius {}",
            vector(from),
            gap(from.unit.as_ref()),
            vector(to),
            gap(to.unit.as_ref()),
            quantity(radius)
        ),
        Shape::Cylinder { at, radius, height } => format!(
            "at {}{}radius {}{}height {}",
            vector(at),
            gap(at.unit.as_ref()),
            quantity(radius),
            gap(radius.unit.as_ref()),
            quantity(height)
        ),
        Shape::Unknown(_) => String::new(),
    };
    let head = format!("{} = {}", pad(&o.name.text, name_width), shape_keyword(&o.shape));
    if args.is_empty() {
        head
    } else {
        format!("{} {args}", pad(&head, name_width + 3 + shape_width))
    }
}

fn goal(goal: &Goal) -> String {
    let terms: Vec<String> = goal.terms.iter().map(goal_term).collect();
    format!("goal {}", terms.join(" > "))
}

fn goal_term(term: &GoalTerm) -> String {
    let values = match term.values.as_slice() {
        [one] => value(one),
        many => format!("({})", value_list(many)),
    };
    format!("{} = {values}", names(&term.variables))
}

fn path(path: &Path) -> String {
    let items: Vec<String> = path
        .items
        .iter()
        .map(|item| format!("{} {}", names(&item.variables), feature(&item.feature, false)))
        .collect();
    let hardness = path.hardness.as_ref().map(|h| format!(" : {}", h.text)).unwrap_or_default();
    format!("path {}{hardness}", items.join(", "))
}

/// A path feature; `in_call` puts a comma before the size, as inside
/// `.path(about r, 20 deg)`, where it reads as a second argument.
fn feature(feature: &Feature, in_call: bool) -> String {
    let size = |before: &str, size: &Option<Quantity>| {
        size.as_ref().map(|s| format!("{before}{}", quantity(s))).unwrap_or_default()
    };
    match feature {
        Feature::Line { direction, size: s } => {
            let before = if in_call { ", " } else { gap(direction.unit.as_ref()) };
            format!("line {}{}", vector(direction), size(before, s))
        }
        Feature::About { axis, size: s } => {
            format!("about {}{}", axis.text, size(if in_call { ", " } else { " " }, s))
        }
        Feature::By { size } => format!("by {}", quantity(size)),
        Feature::Hold => "hold".to_owned(),
    }
}

fn segment(segment: &Segment) -> String {
    let mut text = "segment".to_owned();
    let mut before_brace = " ";
    if let Some(d) = &segment.duration {
        text.push_str(&format!(" {}", quantity(d)));
        before_brace = gap(d.unit.as_ref());
    }
    let mut body = String::new();
    for (i, (combine, p)) in segment.primitives.iter().enumerate() {
        if i > 0 {
            body.push_str(match combine {
                Combine::Add => " +Pa ",
                Combine::Remove => " -Pa ",
            });
        }
        body.push_str(&primitive(p));
    }
    format!("{text}{before_brace}{{ {body} }}")
}

fn primitive(p: &Primitive) -> String {
    let variables = match p.variables.as_slice() {
        [one] => one.text.clone(),
        many => format!("({})", names(many)),
    };
    let constraint = match &p.constraint {
        None => String::new(),
        Some(PrimitiveConstraint::Goal(values)) => format!(".goal({})", value_list(values)),
        Some(PrimitiveConstraint::Path(f)) => format!(".path({})", feature(f, true)),
        Some(PrimitiveConstraint::Hold) => ".hold".to_owned(),
    };
    format!("{variables}{constraint}")
}

#[cfg(test)]
mod tests {
    use super::super::parse_ast;
    use super::*;

    /// Every construct of the language, written untidily, with comments.
    const EVERYTHING: &str = r#"
robot "../../robots/coman_right_arm.urdf"   # path relative to this file
start [0, -20, 0, -60, 0, 10, 0] deg

scene {
  table = box      at [0.45, 0, -0.30]  size [0.40, 0.80, 0.04]
  box_a = box      at [0.42, 0.06, -0.23] size [0.08, 0.08, 0.10]
  bar   = capsule  from [0.3, -0.3, 0.1] to [0.3, 0.3, 0.1] radius 0.02
  post  = cylinder at [0.37, 0.05, -0.5] radius 0.03 height 1.0
  ball  = sphere   at [0.3, 0.1, 0.0] radius 5 cm
}

settings { rate 100 Hz  solver auto  seed 7  transition 20 %  frame base }

task push_box_a_aside {
  init { holding, box_b_near_a }
  goal { box_a_aside, hand_empty }

  action drop "Drop the things in the hand" {
    pre { holding } add { hand_empty } del { holding }
    goal Pw Ow = ([0.25, -0.28, -0.05], rpy(180, 0, 90) deg) ≻ Os = axes(r: [0, 0, -1], l: [0, 1, 0])
    duration 2 s
  }
  action retract {
    pre { hand_empty, box_b_near_a } add { box_b_moved } del { box_b_near_a }
    goal Pw Ow = ([0.15, -0.25, 0.05], rpy(180, 0, 90) deg)
    path Os about z, θe hold : hard
  }
  +Se
  action push {
    solver qp
    pre { box_b_moved } add { box_a_aside }
    path Pw line [0, 1, 0] 0.12 m, Ow hold, θsw hold
  }
  action type_vii explicit {
    segment 1.2 s { Os.path(about r, 24.7 deg) +Pa (θe Ow).goal(100 deg, rpy(-15.5, -11.5, -104.6) deg) }
    +Tr segment 1.0 s { (Pw Ow).goal([0.27, -0.10, 0.05], axes(f: [1,0,0], p: [0,1,0])) +Pa θsw.hold }
    +Tr segment 0.8 s { (Pw Ow).hold +Pa θsw.goal(63.2 deg) }
    +Tr segment { (Pw Ow sw).hold -Pa sw +Pa sw.path(by 10 deg) }
  }
}
"#;

    const EVERYTHING_CANONICAL: &str = r#"robot "../../robots/coman_right_arm.urdf"
start [0, -20, 0, -60, 0, 10, 0] deg

scene {
  table = box      at [0.45, 0, -0.3] size [0.4, 0.8, 0.04]
  box_a = box      at [0.42, 0.06, -0.23] size [0.08, 0.08, 0.1]
  bar   = capsule  from [0.3, -0.3, 0.1] to [0.3, 0.3, 0.1] radius 0.02
  post  = cylinder at [0.37, 0.05, -0.5] radius 0.03 height 1
  ball  = sphere   at [0.3, 0.1, 0] radius 5 cm
}

settings {
  rate 100 Hz
  solver auto
  seed 7
  transition 20 %
  frame base
}

task push_box_a_aside {
  init { holding, box_b_near_a }
  goal { box_a_aside, hand_empty }

  action drop "Drop the things in the hand" {
    pre { holding }
    add { hand_empty }
    del { holding }
    goal Pw Ow = ([0.25, -0.28, -0.05], rpy(180, 0, 90) deg) > Os = axes(r: [0, 0, -1], l: [0, 1, 0])
    duration 2 s
  }

  action retract {
    pre { hand_empty, box_b_near_a }
    add { box_b_moved }
    del { box_b_near_a }
    goal Pw Ow = ([0.15, -0.25, 0.05], rpy(180, 0, 90) deg)
    path Os about z, θe hold : hard
  }

  action push {
    pre { box_b_moved }
    add { box_a_aside }
    path Pw line [0, 1, 0] 0.12 m, Ow hold, θsw hold
    solver qp
  }

  action type_vii explicit {
    segment 1.2 s { Os.path(about r, 24.7 deg) +Pa (θe Ow).goal(100 deg, rpy(-15.5, -11.5, -104.6) deg) }
    +Tr segment 1 s { (Pw Ow).goal([0.27, -0.1, 0.05], axes(f: [1, 0, 0], p: [0, 1, 0])) +Pa θsw.hold }
    +Tr segment 0.8 s { (Pw Ow).hold +Pa θsw.goal(63.2 deg) }
    +Tr segment { (Pw Ow sw).hold -Pa sw +Pa sw.path(by 10 deg) }
  }
}
"#;

    /// Checks the two laws on `text` and returns its canonical form.
    fn canonical(text: &str) -> String {
        let tree = parse_ast(text, None).unwrap_or_else(|d| panic!("input parses:\n{d}"));
        let printed = format(&tree);
        let reparsed = parse_ast(&printed, None)
            .unwrap_or_else(|d| panic!("canonical form parses:\n{d}\n--- printed:\n{printed}"));
        assert_eq!(reparsed, tree, "same tree after printing:\n{printed}");
        assert_eq!(format(&reparsed), printed, "idempotent");
        printed
    }

    #[test]
    fn every_construct_round_trips() {
        assert_eq!(canonical(EVERYTHING), EVERYTHING_CANONICAL);
    }

    #[test]
    fn canonical_text_is_a_fixed_point() {
        assert_eq!(canonical(EVERYTHING_CANONICAL), EVERYTHING_CANONICAL);
    }

    #[test]
    fn comments_and_layout_go() {
        let text = "// header\nrobot   \"a.urdf\" # trailing\n\n\n  start [ 0,0 , 0,0,0,0,0 ]rad\n";
        assert_eq!(canonical(text), "robot \"a.urdf\"\nstart [0, 0, 0, 0, 0, 0, 0] rad\n");
        assert_eq!(canonical(""), "");
        assert_eq!(canonical("# only a comment\n"), "");
    }

    #[test]
    fn start_state_and_rarer_forms() {
        let text = "start Pw [0.2, -0.1, -0.2] Ow quat(1, 0, 0, 0) sw 30°
scene { }
settings {}
task t { init {} action a { } action b \"\" explicit { solver rrt segment { Pw.hold } } }
task u { action c { path Ow about -z, Pw line [1, 0, 0] : soft goal e = (1 rad) duration 200 ms } }";
        assert_eq!(
            canonical(text),
            "start Pw [0.2, -0.1, -0.2]  Ow quat(1, 0, 0, 0)  sw 30°

scene {}

settings {}

task t {
  init {}

  action a {}

  action b \"\" explicit {
    solver rrt
    segment { Pw.hold }
  }
}

task u {
  action c {
    goal e = 1 rad
    path Ow about -z, Pw line [1, 0, 0] : soft
    duration 200 ms
  }
}
"
        );
    }

    #[test]
    fn features_keep_their_sizes() {
        let text = "task t { action a {
  path Os about r 10 deg, Pw line [0, 0, 1] 5 cm
}
action b explicit { segment 2 s { (Pw Ow).path(line [0, 1, 0] 0.1) +Pa θsw.path(about l) } } }";
        let printed = canonical(text);
        assert!(printed.contains("path Os about r 10 deg, Pw line [0, 0, 1] 5 cm\n"), "{printed}");
        assert!(printed.contains("(Pw Ow).path(line [0, 1, 0], 0.1) +Pa θsw.path(about l)"));
    }

    /// Every variant of [`EVERYTHING`] with one word left out, or with one
    /// line break turned into a space, that still parses keeps the laws.
    #[test]
    fn near_variants_round_trip() {
        let words: Vec<&str> = EVERYTHING.split(' ').collect();
        let mut parsed = 0;
        for i in 0..words.len() {
            let mut fewer = words.clone();
            fewer.remove(i);
            let text = fewer.join(" ");
            if parse_ast(&text, None).is_ok() {
                canonical(&text);
                parsed += 1;
            }
        }
        for (i, _) in EVERYTHING.match_indices('\n') {
            let text = format!("{} {}", &EVERYTHING[..i], &EVERYTHING[i + 1..]);
            if parse_ast(&text, None).is_ok() {
                canonical(&text);
                parsed += 1;
            }
        }
        assert!(parsed > 50, "only {parsed} variants parse");
    }

    #[test]
    fn misspelt_units_survive() {
        // Unknown unit words are units only at the end of a line.
        let text = "start Pw [0.2, -0.1, -0.2] mx
  Ow rpy(0, 90, 0) dgr
  sw 30 deg
scene { post = cylinder at [0, 0, 0] mx
  radius 3 cmm
  height 1 m }
task t { action a { path Pw line [0, 1, 0] mx
  2 cm }
  action b explicit { segment 2 sec
  { Pw.hold } } }";
        let printed = canonical(text);
        assert!(printed.contains("start Pw [0.2, -0.1, -0.2] mx\n    Ow rpy(0, 90, 0) dgr\n"));
    }

    #[test]
    fn obstacles_align_per_scene() {
        let text = "scene { a = sphere at [0, 0, 0] radius 1 long_name = box at [1, 1, 1] size [1, 1, 1] }";
        assert_eq!(
            canonical(text),
            "scene {\n  a         = sphere at [0, 0, 0] radius 1\n  long_name = box    at [1, 1, 1] size [1, 1, 1]\n}\n"
        );
    }

    #[test]
    fn numbers_read_back_exactly() {
        for (x, text) in [
            (0.1, "0.1"),
            (100.0, "100"),
            (-0.0, "-0"),
            (1e-7, "1e-7"),
            (2.5e20, "2.5e20"),
            (0.000_15, "0.00015"),
            (f64::INFINITY, "1e999"),
            (f64::NEG_INFINITY, "-1e999"),
        ] {
            assert_eq!(number(x), text);
        }
        // Random bit patterns through the grammar and back.
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..2000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let x = Real::from_bits(state);
            if x.is_nan() {
                continue;
            }
            let text = format!("settings {{ v {} }}", number(x));
            let tree = parse_ast(&text, None).unwrap_or_else(|d| panic!("{text}: {d}"));
            let Item::Settings(s) = &tree.items[0] else { panic!("settings") };
            let SettingValue::Quantity(q) = &s.entries[0].value else { panic!("a number") };
            assert_eq!(q.value.to_bits(), x.to_bits(), "{text}");
        }
    }
}
