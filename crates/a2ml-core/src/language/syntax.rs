//! Text to [`ast::File`] with pest; pest enters the library here and
//! nowhere else.

use pest::Parser as _;
use pest::iterators::Pair;

use super::ast::{self, Name, Span};
use super::diagnostic::Diagnostic;
use crate::math::Real;

#[derive(pest_derive::Parser)]
#[grammar = "../../../grammar/a2ml.pest"]
struct A2mlParser;

type Node<'a> = Pair<'a, Rule>;

/// Parses A2ML text into its syntax tree.
///
/// # Errors
/// The syntax error, located.
pub fn parse_file(text: &str) -> Result<ast::File, Diagnostic> {
    let mut pairs = A2mlParser::parse(Rule::file, text).map_err(syntax_error)?;
    let file = pairs.next().ok_or_else(|| Diagnostic::new(Span::default(), "empty input"))?;
    Ok(ast::File {
        items: file.into_inner().filter(|p| p.as_rule() != Rule::EOI).map(item).collect(),
        comments: comments(text),
        layout: ast::Layout { blank_lines: blank_lines(text) },
    })
}

/// The first byte of every line of `text` that holds only whitespace and
/// ends in a line break.
fn blank_lines(text: &str) -> Vec<usize> {
    let mut starts = Vec::new();
    let mut line_start = 0;
    for line in text.split_inclusive('\n') {
        if line.trim_matches(|c| c == '\n' || BLANK.contains(&c)).is_empty() && line.ends_with('\n')
        {
            starts.push(line_start);
        }
        line_start += line.len();
    }
    starts
}

/// The comments of a text that parses, in order.
///
/// A scan of the text rather than a non-silent `COMMENT` rule: pest would
/// put such comments among the inner pairs of whichever rule they fall in,
/// and every `inner.next()` below would have to step over them. The scan is
/// exact for a text that parses: outside comments, `#` and `/` occur only
/// inside strings, and a string runs from `"` to the next `"` on its line.
fn comments(text: &str) -> Vec<ast::Comment> {
    let mut found = Vec::new();
    let mut code_on_line = false;
    let mut code_end = 0;
    let mut chars = text.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        let starts_comment =
            c == '#' || (c == '/' && chars.peek().is_some_and(|&(_, next)| next == '/'));
        if starts_comment {
            let line_end = text[i..].find('\n').map_or(text.len(), |n| i + n);
            let comment = text[i..line_end].trim_end_matches(BLANK);
            found.push(ast::Comment {
                text: comment.to_owned(),
                own_line: !code_on_line,
                code_before: code_end,
                code_after: text.len(),
                span: Span { start: i, end: i + comment.len() },
            });
            while chars.next_if(|&(j, _)| j < line_end).is_some() {}
            continue;
        }
        match c {
            '\n' => code_on_line = false,
            c if BLANK.contains(&c) => {}
            '"' => {
                code_on_line = true;
                code_end = i + 1;
                while let Some((j, c)) = chars.next_if(|&(_, c)| c != '\n') {
                    code_end = j + c.len_utf8();
                    if c == '"' {
                        break;
                    }
                }
            }
            _ => {
                code_on_line = true;
                code_end = i + c.len_utf8();
            }
        }
    }
    // The code after each comment: the next byte that is neither
    // whitespace nor in a comment, found from the last comment back.
    let mut next_code = text.len();
    for i in (0..found.len()).rev() {
        let end = found[i].span.end;
        let rest = &text[end..];
        let skipped =
            rest.len() - rest.trim_start_matches(|c| c == '\n' || BLANK.contains(&c)).len();
        let after = end + skipped;
        if found.get(i + 1).is_none_or(|next| next.span.start != after) {
            next_code = after;
        }
        found[i].code_after = next_code;
    }
    found
}

/// The grammar's `WHITESPACE` but the line break.
const BLANK: [char; 4] = [' ', '\t', '\r', '\u{FEFF}'];

/// The braces of a block: from the `{` that comes next after `from`, past
/// whitespace and comments, to the end of `node`, which is its `}`.
fn braces(node: &Node<'_>, from: usize) -> Span {
    let text = node.as_span().get_input();
    let mut start = from;
    loop {
        let rest = &text[start..];
        let code = rest.trim_start_matches(|c| c == '\n' || BLANK.contains(&c));
        start += rest.len() - code.len();
        if !code.starts_with(['#', '/']) {
            return Span { start, end: node.as_span().end() };
        }
        start += code.find('\n').unwrap_or(code.len());
    }
}

/// What a rule is called in messages.
fn describe(rule: &Rule) -> String {
    use Rule::*;
    match rule {
        EOI => "end of file",
        robot => "`robot`",
        robot_base => "`base \"link\"`",
        robot_tip => "`tip \"link\"`",
        start => "`start`",
        scene => "`scene`",
        settings => "`settings`",
        task => "`task`",
        action => "`action`",
        name | ident => "a name",
        string | string_body => "a string in double quotes",
        number => "a number",
        quantity => "a number",
        unit => "a unit",
        vector => "a vector like [0.1, 0.2, 0.3]",
        value | values => "a value (number, vector or rotation)",
        rpy => "rpy(roll, pitch, yaw)",
        quat => "quat(w, x, y, z)",
        axes => "axes(f: [..], p: [..])",
        variable | variables | primitive_vars => "a state variable (Pw, Ow, θsw, Os, θe)",
        axis => "an axis (x, y, z, -x, -y, -z, r, l, f, p)",
        obstacle => "an obstacle `name = shape ...`",
        shape => "a shape (box, sphere, capsule, cylinder)",
        setting => "a setting `name value`",
        facts => "a fact list `{ a, b }`",
        init => "`init`",
        task_goal => "`goal { facts }`",
        se => "`+Se`",
        tr => "`+Tr`",
        pa => "`+Pa` or `-Pa`",
        constraint_body => "an action body `{ ... }`",
        explicit_body => "`explicit { segment ... }`",
        goal => "`goal`",
        goal_term => "`variables = values`",
        equals => "`=`",
        priority => "`>`",
        path => "`path`",
        path_item => "`variables feature`",
        hardness => "`hard` or `soft`",
        feature => "a path feature (line, about, by, hold)",
        line => "`line [direction] length`",
        about => "`about axis angle`",
        by => "`by angle`",
        hold => "`hold`",
        duration => "`duration`",
        solver => "`solver`",
        pre => "`pre`",
        add => "`add`",
        del => "`del`",
        contact => "`contact`",
        segment => "`segment`",
        primitive => "a primitive like Pw.goal([..])",
        goal_call => "`.goal(values)`",
        path_call => "`.path(feature)`",
        start_state | start_entry => "a start state `Pw [..] Ow .. θsw ..`",
        axis_pair => "`name: [vector]`",
        _ => return format!("{rule:?}"),
    }
    .to_owned()
}

fn syntax_error(error: pest::error::Error<Rule>) -> Diagnostic {
    let span = match error.location {
        pest::error::InputLocation::Pos(p) => Span { start: p, end: p },
        pest::error::InputLocation::Span((s, e)) => Span { start: s, end: e },
    };
    let message = match &error.variant {
        pest::error::ErrorVariant::ParsingError { positives, negatives } => {
            let mut expected: Vec<String> = positives.iter().map(describe).collect();
            expected.sort();
            expected.dedup();
            let list = match expected.as_slice() {
                [] => String::new(),
                [one] => one.clone(),
                [init @ .., last] => format!("{} or {last}", init.join(", ")),
            };
            if !list.is_empty() {
                format!("expected {list}")
            } else if !negatives.is_empty() {
                let unexpected: Vec<String> = negatives.iter().map(describe).collect();
                format!("unexpected {}", unexpected.join(", "))
            } else {
                "syntax error".to_owned()
            }
        }
        pest::error::ErrorVariant::CustomError { message } => message.clone(),
    };
    Diagnostic::new(span, message)
}

fn span(node: &Node<'_>) -> Span {
    let s = node.as_span();
    Span { start: s.start(), end: s.end() }
}

fn name(node: Node<'_>) -> Name {
    Name { span: span(&node), text: node.as_str().to_owned() }
}

fn string(node: Node<'_>) -> Name {
    let body = node.into_inner().next();
    match body {
        Some(b) => name(b),
        None => Name { text: String::new(), span: Span::default() },
    }
}

fn number(node: &Node<'_>) -> Real {
    // The grammar only lets digits, a sign, a point and an exponent through.
    node.as_str().parse().unwrap_or(Real::NAN)
}

fn quantity(node: Node<'_>) -> ast::Quantity {
    let sp = span(&node);
    let mut inner = node.into_inner();
    let value = inner.next().map(|n| number(&n)).unwrap_or(Real::NAN);
    ast::Quantity { value, unit: inner.next().map(name), span: sp }
}

fn vector(node: Node<'_>) -> ast::Vector {
    let sp = span(&node);
    let mut values = Vec::new();
    let mut unit = None;
    for n in node.into_inner() {
        match n.as_rule() {
            Rule::number => values.push(number(&n)),
            _ => unit = Some(name(n)),
        }
    }
    ast::Vector { values, unit, span: sp }
}

fn value(node: Node<'_>) -> ast::Value {
    let node = node.into_inner().next().expect("value has one child");
    let sp = span(&node);
    match node.as_rule() {
        Rule::quantity => ast::Value::Quantity(quantity(node)),
        Rule::vector => ast::Value::Vector(vector(node)),
        Rule::rpy => {
            let mut angles = [0.0; 3];
            let mut unit = None;
            let mut i = 0;
            for n in node.into_inner() {
                if n.as_rule() == Rule::number {
                    angles[i] = number(&n);
                    i += 1;
                } else {
                    unit = Some(name(n));
                }
            }
            ast::Value::Rpy { angles, unit, span: sp }
        }
        Rule::quat => {
            let mut wxyz = [0.0; 4];
            for (i, n) in node.into_inner().enumerate() {
                wxyz[i] = number(&n);
            }
            ast::Value::Quat { wxyz, span: sp }
        }
        _ => {
            let mut pairs = node.into_inner().map(|pair| {
                let mut inner = pair.into_inner();
                let key = inner.next().map(name).expect("axis pair has a name");
                let dir = inner.next().map(vector).expect("axis pair has a vector");
                (key, dir)
            });
            let first = pairs.next().expect("axes has two pairs");
            let second = pairs.next().expect("axes has two pairs");
            ast::Value::Axes { pairs: [first, second], span: sp }
        }
    }
}

fn values(node: Node<'_>) -> Vec<ast::Value> {
    node.into_inner().map(value).collect()
}

fn variables(node: Node<'_>) -> Vec<Name> {
    node.into_inner().map(name).collect()
}

fn facts(node: Node<'_>) -> ast::Facts {
    let sp = span(&node);
    ast::Facts { names: node.into_inner().map(name).collect(), span: sp }
}

fn first_inner(node: Node<'_>) -> Node<'_> {
    node.into_inner().next().expect("grammar guarantees a child")
}

fn item(node: Node<'_>) -> ast::Item {
    match node.as_rule() {
        Rule::robot => {
            let mut inner = node.into_inner();
            let path = inner.next().map(string).expect("grammar guarantees a path");
            let (mut base, mut tip) = (None, None);
            for part in inner {
                let link = Some(string(first_inner(part.clone())));
                match part.as_rule() {
                    Rule::robot_base => base = link,
                    _ => tip = link,
                }
            }
            ast::Item::Robot(ast::RobotLine { path, base, tip })
        }
        Rule::start => ast::Item::Start(start(first_inner(node))),
        Rule::scene => {
            let sp = span(&node);
            let braces = braces(&node, sp.start + "scene".len());
            ast::Item::Scene(ast::Scene {
                obstacles: node.into_inner().map(obstacle).collect(),
                span: sp,
                braces,
            })
        }
        Rule::settings => {
            let sp = span(&node);
            let braces = braces(&node, sp.start + "settings".len());
            ast::Item::Settings(ast::Settings {
                entries: node.into_inner().map(setting).collect(),
                span: sp,
                braces,
            })
        }
        _ => ast::Item::Task(task(node)),
    }
}

fn start(node: Node<'_>) -> ast::Start {
    match node.as_rule() {
        Rule::vector => ast::Start::Joints(vector(node)),
        _ => {
            let sp = span(&node);
            let entries = node
                .into_inner()
                .map(|entry| {
                    let mut inner = entry.into_inner();
                    let var = inner.next().map(name).expect("entry has a variable");
                    let val = inner.next().map(value).expect("entry has a value");
                    (var, val)
                })
                .collect();
            ast::Start::State { entries, span: sp }
        }
    }
}

fn obstacle(node: Node<'_>) -> ast::Obstacle {
    let sp = span(&node);
    let mut inner = node.into_inner();
    let obstacle_name = inner.next().map(name).expect("obstacle has a name");
    let shape_node = first_inner(inner.next().expect("obstacle has a shape"));
    let rule = shape_node.as_rule();
    let parts: Vec<Node<'_>> = shape_node.into_inner().collect();
    let mut vectors = parts.iter().filter(|p| p.as_rule() == Rule::vector).cloned().map(vector);
    // `capsule from [..] to [..]` rather than `capsule at [..]`.
    let ends = parts.iter().filter(|p| p.as_rule() == Rule::vector).count() == 2;
    let mut quantities =
        parts.iter().filter(|p| p.as_rule() == Rule::quantity).cloned().map(quantity);
    let mut v = || vectors.next().expect("grammar gives the shape's vectors");
    let mut q = || quantities.next().expect("grammar gives the shape's quantities");
    let orientation = parts.iter().find(|p| p.as_rule() == Rule::orientation).map(|node| {
        let node = first_inner(node.clone());
        let rule = node.as_rule();
        let inner = first_inner(node);
        match rule {
            Rule::shape_rotation => ast::Orientation::Rotation(value(inner)),
            _ => ast::Orientation::Axis(vector(inner)),
        }
    });
    let shape = match rule {
        Rule::box_shape => ast::Shape::Box { at: v(), size: v(), orientation },
        Rule::sphere_shape => ast::Shape::Sphere { at: v(), radius: q() },
        Rule::capsule_shape if ends => ast::Shape::Capsule { from: v(), to: v(), radius: q() },
        Rule::capsule_shape => {
            ast::Shape::CapsuleAt { at: v(), radius: q(), height: q(), orientation }
        }
        Rule::cylinder_shape => {
            ast::Shape::Cylinder { at: v(), radius: q(), height: q(), orientation }
        }
        _ => ast::Shape::Unknown(name(parts[0].clone())),
    };
    ast::Obstacle { name: obstacle_name, shape, span: sp }
}

fn setting(node: Node<'_>) -> ast::Setting {
    let sp = span(&node);
    let mut inner = node.into_inner();
    let setting_name = inner.next().map(name).expect("setting has a name");
    let v = inner.next().expect("setting has a value");
    let value = match v.as_rule() {
        Rule::quantity => ast::SettingValue::Quantity(quantity(v)),
        _ => ast::SettingValue::Word(name(v)),
    };
    ast::Setting { name: setting_name, value, span: sp }
}

fn task(node: Node<'_>) -> ast::Task {
    let mut inner = node.clone().into_inner();
    let task_name = inner.next().map(name).expect("task has a name");
    let mut out = ast::Task {
        span: task_name.span,
        braces: braces(&node, task_name.span.end),
        name: task_name,
        init: Vec::new(),
        goal: Vec::new(),
        actions: Vec::new(),
    };
    let mut sequential = false;
    for n in inner {
        match n.as_rule() {
            Rule::init => out.init.push(facts(first_inner(n))),
            Rule::task_goal => out.goal.push(facts(first_inner(n))),
            Rule::action => {
                out.actions.push(ast::Action { sequential, ..action(n) });
                sequential = false;
            }
            // Actions are sequential whether or not `+Se` is written.
            _ => sequential = true,
        }
    }
    out
}

fn action(node: Node<'_>) -> ast::Action {
    let mut inner = node.into_inner();
    let action_name = inner.next().map(name).expect("action has a name");
    let mut out = ast::Action {
        span: action_name.span,
        braces: Span::default(),
        name: action_name,
        description: None,
        sequential: false,
        pre: Vec::new(),
        add: Vec::new(),
        del: Vec::new(),
        contact: Vec::new(),
        solver: Vec::new(),
        body: ast::ActionBody::Constraints {
            goals: Vec::new(),
            paths: Vec::new(),
            durations: Vec::new(),
        },
    };
    for n in inner {
        match n.as_rule() {
            Rule::string => out.description = Some(string(n)),
            Rule::constraint_body => {
                out.braces = span(&n);
                let (mut goals, mut paths, mut durations) = (Vec::new(), Vec::new(), Vec::new());
                for s in n.into_inner() {
                    match s.as_rule() {
                        Rule::goal => goals.push(goal(s)),
                        Rule::path => paths.push(path(s)),
                        Rule::duration => durations.push(quantity(first_inner(s))),
                        _ => common_statement(&mut out, s),
                    }
                }
                out.body = ast::ActionBody::Constraints { goals, paths, durations };
            }
            _ => {
                out.braces = braces(&n, span(&n).start + "explicit".len());
                let mut segments = Vec::new();
                for s in n.into_inner() {
                    match s.as_rule() {
                        Rule::segment => segments.push(segment(s)),
                        Rule::tr => {}
                        _ => common_statement(&mut out, s),
                    }
                }
                out.body = ast::ActionBody::Explicit { segments };
            }
        }
    }
    out
}

fn common_statement(action: &mut ast::Action, node: Node<'_>) {
    match node.as_rule() {
        Rule::pre => action.pre.push(facts(first_inner(node))),
        Rule::add => action.add.push(facts(first_inner(node))),
        Rule::del => action.del.push(facts(first_inner(node))),
        Rule::contact => action.contact.push(facts(first_inner(node))),
        _ => action.solver.push(solver_statement(node)),
    }
}

fn solver_statement(node: Node<'_>) -> ast::SolverStatement {
    let whole = span(&node);
    let keyword = Span { start: whole.start, end: whole.start + "solver".len() };
    let entries = node
        .into_inner()
        .map(|entry| {
            let entry_span = span(&entry);
            let mut names: Vec<Name> = entry.into_inner().map(name).collect();
            let solver = names.pop().expect("an entry names a solver");
            ast::SolverEntry { segment: names.pop(), solver, span: entry_span }
        })
        .collect();
    ast::SolverStatement { entries, span: keyword }
}

fn goal(node: Node<'_>) -> ast::Goal {
    let sp = span(&node);
    let terms = node
        .into_inner()
        .filter(|n| n.as_rule() == Rule::goal_term)
        .map(|term| {
            let tsp = span(&term);
            let mut inner = term.into_inner();
            let vars = inner.next().map(variables).unwrap_or_default();
            let vals = inner.find(|n| n.as_rule() == Rule::values).map(values).unwrap_or_default();
            ast::GoalTerm { variables: vars, values: vals, span: tsp }
        })
        .collect();
    ast::Goal { terms, span: Span { start: sp.start, end: sp.start + "goal".len() } }
}

fn path(node: Node<'_>) -> ast::Path {
    let sp = span(&node);
    let mut items = Vec::new();
    let mut hardness = None;
    for n in node.into_inner() {
        match n.as_rule() {
            Rule::path_item => {
                let isp = span(&n);
                let mut inner = n.into_inner();
                let vars = inner.next().map(variables).unwrap_or_default();
                let feat = feature(first_inner(inner.next().expect("path item has a feature")));
                items.push(ast::PathItem { variables: vars, feature: feat, span: isp });
            }
            _ => hardness = Some(name(n)),
        }
    }
    ast::Path { items, hardness, span: Span { start: sp.start, end: sp.start + "path".len() } }
}

fn feature(node: Node<'_>) -> ast::Feature {
    let rule = node.as_rule();
    let mut inner = node.into_inner();
    match rule {
        Rule::line => ast::Feature::Line {
            direction: inner.next().map(vector).expect("line has a direction"),
            size: inner.next().map(quantity),
        },
        Rule::about => ast::Feature::About {
            axis: inner.next().map(name).expect("about has an axis"),
            size: inner.next().map(quantity),
        },
        Rule::by => ast::Feature::By { size: inner.next().map(quantity).expect("by has a size") },
        Rule::arc => {
            ast::Feature::Arc { through: inner.next().map(vector).expect("arc has a point") }
        }
        _ => ast::Feature::Hold,
    }
}

fn segment(node: Node<'_>) -> ast::Segment {
    let sp = span(&node);
    let mut duration = None;
    let mut primitives = Vec::new();
    let mut combine = ast::Combine::Add;
    for n in node.clone().into_inner() {
        match n.as_rule() {
            Rule::quantity => duration = Some(quantity(n)),
            Rule::pa => {
                combine = if n.as_str() == "-Pa" { ast::Combine::Remove } else { ast::Combine::Add }
            }
            _ => primitives.push((combine, primitive(n))),
        }
    }
    let keyword = Span { start: sp.start, end: sp.start + "segment".len() };
    let before_brace = duration.as_ref().map_or(keyword.end, |d| d.span.end);
    ast::Segment { duration, primitives, span: keyword, braces: braces(&node, before_brace) }
}

fn primitive(node: Node<'_>) -> ast::Primitive {
    let sp = span(&node);
    let mut inner = node.into_inner();
    let vars = inner.next().map(variables).unwrap_or_default();
    let constraint = inner.next().map(|c| match c.as_rule() {
        Rule::goal_call => ast::PrimitiveConstraint::Goal(c.into_inner().map(value).collect()),
        Rule::path_call => ast::PrimitiveConstraint::Path(feature(first_inner(c))),
        _ => ast::PrimitiveConstraint::Hold,
    });
    ast::Primitive { variables: vars, constraint, span: sp }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_are_found_outside_strings() {
        let text = "\u{FEFF}# one\r\nrobot \"a#b//c\" // two  \n  // three\nstart [0]#four";
        let found = comments(text);
        let summary: Vec<(&str, bool, usize)> =
            found.iter().map(|c| (c.text.as_str(), c.own_line, c.code_before)).collect();
        let after_string = text.find("c\"").expect("string") + 2;
        let after_vector = text.find("[0]").expect("vector") + 3;
        assert_eq!(
            summary,
            [
                ("# one", true, 0),
                ("// two", false, after_string),
                ("// three", true, after_string),
                ("#four", false, after_vector),
            ]
        );
        assert_eq!(&text[found[3].span.start..found[3].span.end], "#four");
        assert!(comments("robot \"x\" / 2").is_empty());
    }

    #[test]
    fn braces_skip_comments_before_the_opening_one() {
        let text = "task t # a { b\n  // {\n  { action a { goal Pw = [0, 0, 0] } }";
        let file = parse_file(text).expect("parses");
        let ast::Item::Task(task) = &file.items[0] else { panic!("a task") };
        assert_eq!(task.braces.start, text.find("{ action").expect("brace"));
        assert_eq!(task.braces.end, text.len());
        assert_eq!(task.actions[0].braces.start, text.find("{ goal").expect("brace"));
        assert_eq!(task.actions[0].braces.end, text.len() - 2);
    }
}
