//! The canonical text of a syntax tree: what `a2ml fmt` prints.
//!
//! The law: for every text that parses, `parse_ast(format(parse_ast(text)))`
//! equals `parse_ast(text)`, comments included, and formatting is
//! idempotent. What the tree does not keep is printed one fixed way: `>` for
//! priority, `+Se` on the line of the action it precedes, statements of an
//! action in the order pre, add, del, contact, goal, path, duration, solver.
//! Comments go back beside the line of the node they were written with, and move with it: a statement that canonical
//! order moves past another takes its comments along, which is the one way
//! the comments' order can change.

use std::collections::BTreeMap;

use super::ast::{
    Action, ActionBody, Combine, Comment, Facts, Feature, File, Goal, Item, Name, Obstacle,
    Orientation, Path, Primitive, PrimitiveConstraint, Quantity, Scene, Segment, Setting,
    SettingValue, Settings, Shape, SolverStatement, Span, Start, Task, Value, Vector,
};
use crate::math::Real;

/// Spaces per indentation level.
const INDENT: usize = 2;

/// The columns a statement may fill before it is broken over lines.
pub const WIDTH: usize = 100;

/// Prints a syntax tree in the canonical layout: two-space indentation, one
/// statement per line, a blank line between blocks and where the source
/// had one or more (never two, none after a `{` or before a `}`), scene
/// obstacles aligned in columns, numbers in their shortest form that reads
/// back to the same `f64`, units and names as written.
///
/// A statement longer than [`WIDTH`] columns is broken: a goal before `>`,
/// then after each comma of its value lists; a path and a fact list after
/// each comma; a `start` state before each variable; continuation lines
/// indented two levels more. A segment too long, or holding a comment,
/// puts its primitives inside its braces on a line of their own, then one
/// primitive a line. A statement that holds a comment is broken at every
/// place, so that each comment stays at the end of the line it followed.
///
/// Comments come back beside the lines of their nodes. One on a line of
/// its own stays on a line of its own, at the indentation of the first node
/// that starts after it and just before it; one after code goes at the end
/// of the line that prints that code, one space after it. A line takes one
/// comment at its end: more after it, and those inside a line that cannot
/// be broken (a block's head, a value), follow it on lines of their own. A
/// comment after a node's first words (its keyword, a `+Tr`, or a `+Se`
/// before an action) on the same line follows the node's line. Comments
/// after a block's last node go before its closing brace, those after the
/// last item at the end.
pub fn format(file: &File) -> String {
    // A first pass learns which node each printed line stands for; the
    // comments are placed against those lines, then printed in a second.
    let mut layout = Printer::new(file, Placement::default());
    layout.file(file);
    let comments = Placement::new(&file.comments, layout.anchors);
    let mut printer = Printer::new(file, comments);
    printer.file(file);
    printer.finish()
}

/// The source text a printed line stands for: a statement whole, a block's
/// head to its `{`, or a block's `}`. A keyword or `+Tr` before the first
/// byte recorded here still belongs to the line; comments after it do too.
#[derive(Debug, Clone, Copy)]
struct Anchor {
    /// The first byte: what the line is known by.
    start: usize,
    /// One past the last byte.
    end: usize,
}

impl Anchor {
    /// A statement that runs from the start of `first` to the end of `last`.
    fn statement(first: Span, last: Span) -> Self {
        Self { start: first.start, end: last.end.max(first.end) }
    }

    /// A block's head, from `start` to its opening brace.
    fn open(start: usize, braces: Span) -> Self {
        Self { start, end: braces.start + 1 }
    }

    /// A block's closing brace.
    fn close(braces: Span) -> Self {
        Self { start: braces.end.saturating_sub(1), end: braces.end }
    }
}

/// Each comment assigned to a printed line, by the line's [`Anchor::start`].
#[derive(Default)]
struct Placement<'a> {
    /// Comments on lines of their own before the line.
    before: BTreeMap<usize, Vec<&'a Comment>>,
    /// Comments after the line: the first on the line itself if it followed
    /// code in the source, the others on lines of their own.
    after: BTreeMap<usize, Vec<&'a Comment>>,
    /// Comments after the last line.
    end: Vec<&'a Comment>,
}

impl<'a> Placement<'a> {
    /// Places `comments` against the printed lines, so that they come out
    /// in source order unless the lines do not.
    fn new(comments: &'a [Comment], mut anchors: Vec<Anchor>) -> Self {
        anchors.sort_by_key(|a| a.start);
        let mut placement = Self::default();
        // The line a comment after its first words went after: the comments
        // on lines of their own before that line follow it too, in order.
        let mut after_first_words: Option<usize> = None;
        for comment in comments {
            let at = comment.span.start;
            let first_after = anchors.partition_point(|a| a.start < at);
            let previous = first_after.checked_sub(1).map(|i| anchors[i]);
            let next = anchors.get(first_after).copied();
            let previous_end = previous.map_or(0, |a| a.end);
            let (list, anchor) = if previous.is_some_and(|a| at < a.end) {
                // Inside a line's text: after that line.
                (&mut placement.after, previous)
            } else if comment.own_line {
                match next {
                    Some(a) if after_first_words == Some(a.start) => (&mut placement.after, next),
                    _ => (&mut placement.before, next),
                }
            } else if comment.code_before > previous_end {
                // After the first words of the next line, such as a keyword
                // or `+Tr`, which its anchor does not cover.
                after_first_words = next.map(|a| a.start);
                (&mut placement.after, next)
            } else {
                (&mut placement.after, previous)
            };
            match anchor {
                Some(anchor) => list.entry(anchor.start).or_default().push(comment),
                None => placement.end.push(comment),
            }
        }
        placement
    }
}

/// Lines with indentation and the comments and blank lines that go between them.
struct Printer<'a> {
    out: String,
    depth: usize,
    /// Every comment of the file, for the statements that hold one.
    all_comments: &'a [Comment],
    /// The source's blank lines ([`super::ast::Layout`]).
    blank_lines: &'a [usize],
    /// The printed lines' nodes, in print order.
    anchors: Vec<Anchor>,
    /// The comments still to print.
    comments: Placement<'a>,
    /// Comments due on lines of their own before the next line.
    pending: Vec<&'a Comment>,
    /// One past the last source byte printed so far.
    last_end: usize,
    /// One past the last source byte of the lines printed so far, comments
    /// left out (the same in both passes).
    anchor_end: usize,
    /// A blank line is due before the next line, whatever the source had.
    want_blank: bool,
    /// The last line written opens a block, so no blank line follows it.
    at_open: bool,
    /// The next lines continue a statement, so no blank line goes between them.
    continuing: bool,
}

impl<'a> Printer<'a> {
    fn new(file: &'a File, comments: Placement<'a>) -> Self {
        Self {
            out: String::new(),
            depth: 0,
            all_comments: &file.comments,
            blank_lines: &file.layout.blank_lines,
            anchors: Vec::new(),
            comments,
            pending: Vec::new(),
            last_end: 0,
            anchor_end: 0,
            want_blank: false,
            at_open: false,
            continuing: false,
        }
    }

    fn file(&mut self, file: &File) {
        let one_liner = |item: &Item| matches!(item, Item::Robot(_) | Item::Start(_));
        let mut previous: Option<&Item> = None;
        for item in &file.items {
            // `robot` and `start` stay together as the header; blocks stand apart.
            if previous.is_some_and(|prev| !(one_liner(prev) && one_liner(item))) {
                self.blank();
            }
            match item {
                Item::Robot(line) => {
                    // The span is the last string's text; its closing quote follows.
                    let last = line.tip.as_ref().or(line.base.as_ref()).unwrap_or(&line.path);
                    let mut text = format!("robot {}", string(&line.path));
                    for (word, link) in [("base", &line.base), ("tip", &line.tip)] {
                        if let Some(link) = link {
                            text += &format!(" {word} {}", string(link));
                        }
                    }
                    self.line(
                        Anchor { start: line.path.span.start, end: last.span.end + 1 },
                        &text,
                    );
                }
                Item::Start(start) => {
                    let end = match start {
                        Start::Joints(q) => q.span.end,
                        Start::State { span, .. } => span.end,
                    };
                    self.statement(start_pieces(start), end);
                }
                Item::Scene(scene) => self.scene(scene),
                Item::Settings(settings) => self.settings(settings),
                Item::Task(task) => self.task(task),
            }
            previous = Some(item);
        }
    }

    /// The text, with the comments that come after the last line.
    fn finish(mut self) -> String {
        let placement = std::mem::take(&mut self.comments);
        self.pending.extend(placement.end);
        // Comments placed against a line that was not printed: there are
        // none, as both passes print the same lines, but none is ever lost.
        let mut unprinted: Vec<&Comment> =
            placement.before.into_values().chain(placement.after.into_values()).flatten().collect();
        unprinted.sort_by_key(|c| c.span.start);
        self.pending.extend(unprinted);
        self.own_lines(0);
        self.out
    }

    /// Whether the source has a blank line between the last text printed
    /// and `start`.
    fn blank_in_source(&self, start: usize) -> bool {
        let first = self.blank_lines.partition_point(|&b| b < self.last_end);
        self.blank_lines.get(first).is_some_and(|&b| b < start)
    }

    /// Writes the blank line due before source text from `start` to `end`,
    /// about to be printed: one if the canonical layout wants it or the
    /// source has one there (unless `kept` is false), never two, none at
    /// the start or right after a `{`.
    fn separate(&mut self, start: usize, end: usize, kept: bool) {
        let from_source = kept && !self.continuing && self.blank_in_source(start);
        if (self.want_blank || from_source) && !self.out.is_empty() && !self.at_open {
            self.out.push('\n');
        }
        self.want_blank = false;
        self.at_open = false;
        self.last_end = self.last_end.max(end);
    }

    /// Writes `text` as one line at `depth`.
    fn write(&mut self, depth: usize, text: &str) {
        self.out.push_str(&" ".repeat(depth * INDENT));
        self.out.push_str(text);
        self.out.push('\n');
    }

    /// Writes the pending comments, one a line, at `depth`.
    fn own_lines(&mut self, depth: usize) {
        for comment in std::mem::take(&mut self.pending) {
            self.separate(comment.span.start, comment.span.end, true);
            self.write(depth, &comment.text);
        }
    }

    /// Records the line of `anchor`, about to be written, writes the
    /// comments due before it at `depth` and the blank line due before it
    /// (a source blank line only if `kept`).
    fn comments_before(&mut self, anchor: Anchor, depth: usize, kept: bool) {
        self.anchors.push(anchor);
        self.anchor_end = self.anchor_end.max(anchor.end);
        let before = self.comments.before.remove(&anchor.start).unwrap_or_default();
        self.pending.extend(before);
        self.own_lines(depth);
        self.separate(anchor.start, anchor.end, kept);
    }

    /// Puts the first comment after the line of `anchor`, just written, at
    /// its end if it followed code in the source; the others wait for the
    /// next line, where a reread would place them too.
    fn comments_after(&mut self, anchor: Anchor) {
        let mut after = self.comments.after.remove(&anchor.start).unwrap_or_default().into_iter();
        match after.next() {
            Some(first) if !first.own_line => {
                self.out.pop();
                self.out.push(' ');
                self.out.push_str(&first.text);
                self.out.push('\n');
                self.last_end = self.last_end.max(first.span.end);
            }
            Some(first) => self.pending.push(first),
            None => {}
        }
        self.pending.extend(after);
    }

    /// Writes a statement of one piece.
    fn line(&mut self, anchor: Anchor, text: &str) {
        let piece = Piece::first(text.to_owned(), anchor.start);
        self.statement(vec![piece], anchor.end);
    }

    /// Writes a statement made of `pieces`, whose source ends at `end`: on
    /// one line if it fits in [`WIDTH`] columns and holds no comment, else
    /// broken before the pieces of the fewest levels that make it fit (all
    /// levels when it holds a comment, so that each comment stays on the
    /// line of the piece it follows). A `\n` inside a piece (see [`gap`])
    /// continues it on a line indented two levels more.
    fn statement(&mut self, pieces: Vec<Piece>, end: usize) {
        let deepest = pieces.iter().map(|p| p.level).max().unwrap_or(0);
        let needed = self.level_for_comments(&pieces);
        let level = (needed..=deepest).find(|&level| self.fits(&pieces, level)).unwrap_or(deepest);
        let lines = lines(&pieces, level);
        for (i, line) in lines.iter().enumerate() {
            let first = &pieces[line.start];
            let line_end = lines.get(i + 1).map_or(end, |next| pieces[next.start].start);
            let anchor = Anchor { start: first.start, end: line_end.max(first.start) };
            let depth = self.depth + first.indent;
            self.continuing = i > 0;
            // Comments before a closing brace belong inside its block.
            let comment_depth = if first.closes { depth + 1 } else { depth };
            self.comments_before(anchor, comment_depth, !first.closes);
            let text = joined(&pieces[line.clone()]);
            for (j, part) in text.split('\n').enumerate() {
                self.write(if j == 0 { depth } else { depth + 2 }, part);
            }
            self.comments_after(anchor);
        }
        self.continuing = false;
    }

    /// The level a statement must be broken at so that each comment it
    /// holds ends the line of the piece it follows: one before the last
    /// piece (one in the last goes after it), or one after the first words
    /// of its line, which goes at the end of its first line.
    fn level_for_comments(&self, pieces: &[Piece]) -> u8 {
        let (Some(first), Some(last)) = (pieces.first(), pieces.last()) else { return 0 };
        let from = self.all_comments.partition_point(|c| c.span.start < self.anchor_end);
        let inside = self.all_comments[from..].iter().take_while(|c| c.span.start < last.start);
        inside
            .filter(|c| {
                first.start < c.span.start
                    || (first.words_before
                        && !c.own_line
                        && c.code_after == first.start
                        && c.code_before > self.anchor_end)
            })
            .map(|c| {
                // The piece after the one the comment follows starts a line.
                let next = pieces.partition_point(|p| p.start <= c.span.start).max(1);
                pieces.get(next).map_or(0, |p| p.level)
            })
            .max()
            .unwrap_or(0)
    }

    /// Whether `pieces` broken at `level` fit in [`WIDTH`] columns.
    fn fits(&self, pieces: &[Piece], level: u8) -> bool {
        lines(pieces, level).into_iter().all(|line| {
            let indent = (self.depth + pieces[line.start].indent) * INDENT;
            let text = joined(&pieces[line.clone()]);
            text.split('\n').enumerate().all(|(j, part)| {
                indent + if j == 0 { 0 } else { 2 * INDENT } + width(part) <= WIDTH
            })
        })
    }

    fn blank(&mut self) {
        self.want_blank = true;
    }

    /// `head {`, the lines `body` writes, `}`; `head {}` when nothing, not
    /// even a comment, comes between the braces. The head's text starts at
    /// `start`.
    fn block(&mut self, head: &str, start: usize, braces: Span, body: impl FnOnce(&mut Self)) {
        let open = Anchor::open(start, braces);
        let close = Anchor::close(braces);
        self.comments_before(open, self.depth, true);
        let mark = self.out.len();
        let comment_after_brace = self.comments.after.contains_key(&open.start);
        self.write(self.depth, &format!("{head} {{"));
        self.at_open = true;
        self.comments_after(open);
        let inside = self.out.len();
        self.depth += 1;
        body(self);
        // Comments after the last node go inside the braces.
        self.comments_before(close, self.depth, false);
        self.depth -= 1;
        if self.out.len() == inside && !comment_after_brace {
            self.out.truncate(mark);
            self.write(self.depth, &format!("{head} {{}}"));
        } else {
            self.write(self.depth, "}");
        }
        self.at_open = false;
        self.comments_after(close);
    }

    fn scene(&mut self, scene: &Scene) {
        let name_width = scene.obstacles.iter().map(|o| width(&o.name.text)).max().unwrap_or(0);
        let shape_width =
            scene.obstacles.iter().map(|o| width(shape_keyword(&o.shape))).max().unwrap_or(0);
        self.block("scene", scene.span.start, scene.braces, |p| {
            for obstacle in &scene.obstacles {
                let anchor = Anchor::statement(obstacle.span, obstacle.span);
                p.line(anchor, &self::obstacle(obstacle, name_width, shape_width));
            }
        });
    }

    fn settings(&mut self, settings: &Settings) {
        self.block("settings", settings.span.start, settings.braces, |p| {
            for Setting { name, value, span } in &settings.entries {
                let value = match value {
                    SettingValue::Quantity(q) => quantity(q),
                    SettingValue::Word(word) => word.text.clone(),
                };
                p.line(Anchor::statement(*span, *span), &format!("{} {value}", name.text));
            }
        });
    }

    /// A fact-list statement: `init`, `goal`, `pre`, `add`, `del` or `contact`.
    fn facts(&mut self, keyword: &str, facts: &Facts) {
        self.statement(fact_pieces(keyword, facts), facts.span.end);
    }

    fn task(&mut self, task: &Task) {
        self.block(&format!("task {}", task.name.text), task.span.start, task.braces, |p| {
            for facts in &task.init {
                p.facts("init", facts);
            }
            for facts in &task.goal {
                p.facts("goal", facts);
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
        let se = if action.sequential { "+Se " } else { "" };
        let mut head = format!("{se}action {}", action.name.text);
        if let Some(description) = &action.description {
            head = format!("{head} {}", string(description));
        }
        if matches!(action.body, ActionBody::Explicit { .. }) {
            head.push_str(" explicit");
        }
        self.block(&head, action.span.start, action.braces, |p| {
            for (keyword, list) in [
                ("pre", &action.pre),
                ("add", &action.add),
                ("del", &action.del),
                ("contact", &action.contact),
            ] {
                for facts in list {
                    p.facts(keyword, facts);
                }
            }
            match &action.body {
                ActionBody::Constraints { goals, paths, durations } => {
                    for g in goals {
                        let end = g.terms.last().map_or(g.span, |t| t.span).end;
                        p.statement(goal_pieces(g), end);
                    }
                    for path in paths {
                        let last = match (&path.hardness, path.items.last()) {
                            (Some(hardness), _) => hardness.span,
                            (None, Some(item)) => item.span,
                            (None, None) => path.span,
                        };
                        p.statement(path_pieces(path), last.end.max(path.span.end));
                    }
                    for d in durations {
                        p.line(
                            Anchor::statement(d.span, d.span),
                            &format!("duration {}", quantity(d)),
                        );
                    }
                    p.solvers(action);
                }
                ActionBody::Explicit { segments } => {
                    // The grammar wants an explicit action's solver before its segments.
                    p.solvers(action);
                    for (i, s) in segments.iter().enumerate() {
                        p.statement(segment_pieces(s, i > 0), s.braces.end);
                    }
                }
            }
        });
    }

    fn solvers(&mut self, action: &Action) {
        for statement in &action.solver {
            let end = statement.entries.last().map_or(statement.span, |e| e.span).end;
            self.statement(solver_pieces(statement), end);
        }
    }
}

/// A part of a statement: printed after the one before it on the same
/// line, or at the start of a line of its own when the statement is broken
/// at its level.
#[derive(Debug, Clone)]
struct Piece {
    text: String,
    /// Where its source text starts.
    start: usize,
    /// What joins it to the piece before it on one line.
    joint: &'static str,
    /// 0 for the first piece; a statement breaks before its pieces of level
    /// 1 first, then before those of level 2 too.
    level: u8,
    /// Indentation levels past the statement's, when it starts a line.
    indent: usize,
    /// It is the closing brace of a block printed as a statement (a segment).
    closes: bool,
    /// Words of its line come before `start` (a `+Tr`, a keyword before braces).
    words_before: bool,
}

impl Piece {
    fn first(text: String, start: usize) -> Self {
        Self { text, start, joint: "", level: 0, indent: 0, closes: false, words_before: false }
    }

    /// A piece after a space, breaking at `level`, indented two levels more
    /// than its statement when it starts a line: a continuation.
    fn then(text: String, start: usize, level: u8) -> Self {
        Self { text, start, joint: " ", level, indent: 2, closes: false, words_before: false }
    }
}

/// The lines of `pieces` broken at `level`, as ranges of pieces.
fn lines(pieces: &[Piece], level: u8) -> Vec<std::ops::Range<usize>> {
    let mut lines: Vec<std::ops::Range<usize>> = Vec::new();
    for (i, piece) in pieces.iter().enumerate() {
        match lines.last_mut() {
            Some(line) if piece.level == 0 || piece.level > level => line.end = i + 1,
            _ => lines.push(i..i + 1),
        }
    }
    lines
}

/// The text of pieces on one line.
fn joined(pieces: &[Piece]) -> String {
    let mut text = String::new();
    for (i, piece) in pieces.iter().enumerate() {
        if i > 0 {
            text.push_str(piece.joint);
        }
        text.push_str(&piece.text);
    }
    text
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

fn shape_keyword(shape: &Shape) -> &str {
    match shape {
        Shape::Box { .. } => "box",
        Shape::Sphere { .. } => "sphere",
        Shape::Capsule { .. } | Shape::CapsuleAt { .. } => "capsule",
        Shape::Cylinder { .. } => "cylinder",
        Shape::Unknown(name) => &name.text,
    }
}

/// ` rotation ..` or ` axis [..]` after an argument whose unit is `before`; nothing without.
fn orientation(o: Option<&Orientation>, before: Option<&Name>) -> String {
    match o {
        None => String::new(),
        Some(Orientation::Rotation(v)) => format!("{}rotation {}", gap(before), value(v)),
        Some(Orientation::Axis(v)) => format!("{}axis {}", gap(before), vector(v)),
    }
}

/// `name = shape args`, the name and the shape keyword padded to the
/// scene's columns.
fn obstacle(o: &Obstacle, name_width: usize, shape_width: usize) -> String {
    let args = match &o.shape {
        Shape::Box { at, size, orientation: o } => format!(
            "at {}{}size {}{}",
            vector(at),
            gap(at.unit.as_ref()),
            vector(size),
            orientation(o.as_ref(), size.unit.as_ref())
        ),
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
        Shape::CapsuleAt { at, radius, height, orientation: o }
        | Shape::Cylinder { at, radius, height, orientation: o } => format!(
            "at {}{}radius {}{}height {}{}",
            vector(at),
            gap(at.unit.as_ref()),
            quantity(radius),
            gap(radius.unit.as_ref()),
            quantity(height),
            orientation(o.as_ref(), height.unit.as_ref())
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
        Feature::Arc { through } => format!("arc through {}", vector(through)),
        Feature::Hold => "hold".to_owned(),
    }
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

/// `keyword { a, b }`, breaking after each comma.
fn fact_pieces(keyword: &str, facts: &Facts) -> Vec<Piece> {
    let count = facts.names.len();
    if count == 0 {
        let piece = Piece::first(format!("{keyword} {{}}"), facts.span.start);
        return vec![Piece { words_before: true, ..piece }];
    }
    facts
        .names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let open = if i == 0 { format!("{keyword} {{ ") } else { String::new() };
            let close = if i + 1 == count { " }" } else { "," };
            let text = format!("{open}{}{close}", name.text);
            if i == 0 {
                Piece { words_before: true, ..Piece::first(text, facts.span.start) }
            } else {
                Piece::then(text, name.span.start, 1)
            }
        })
        .collect()
}

/// `start [..]`, or `start V v  W w ..`, breaking before each variable.
fn start_pieces(start: &Start) -> Vec<Piece> {
    match start {
        Start::Joints(q) => vec![Piece::first(format!("start {}", vector(q)), q.span.start)],
        Start::State { entries, span } => {
            let mut pieces: Vec<Piece> = Vec::new();
            for (variable, v) in entries {
                let text = format!("{} {}", variable.text, value(v));
                match pieces.last() {
                    None => pieces.push(Piece::first(format!("start {text}"), span.start)),
                    Some(_) => pieces.push(Piece::then(text, variable.span.start, 1)),
                }
            }
            // After a unit the grammar does not know, the next entry goes on
            // a line of its own (see [`gap`]).
            for i in 1..pieces.len() {
                let (_, before) = &entries[i - 1];
                pieces[i].joint = if gap(value_unit(before)) == "\n" { "\n" } else { "  " };
            }
            pieces
        }
    }
}

/// `goal A = a > B = (b1, b2)`: breaking before `>` first, then after each
/// comma of a value list.
fn goal_pieces(goal: &Goal) -> Vec<Piece> {
    let mut pieces: Vec<Piece> = Vec::new();
    for (t, term) in goal.terms.iter().enumerate() {
        let head = if t == 0 { "goal " } else { "> " };
        let variables = format!("{head}{} = ", names(&term.variables));
        let term_start = if t == 0 { goal.span.start } else { term.span.start };
        let push = |pieces: &mut Vec<Piece>, text: String, start: usize, level: u8| {
            pieces.push(if pieces.is_empty() {
                Piece::first(text, start)
            } else {
                Piece::then(text, start, level)
            });
        };
        match term.values.as_slice() {
            [one] => push(&mut pieces, format!("{variables}{}", value(one)), term_start, 1),
            many => {
                for (i, v) in many.iter().enumerate() {
                    let close = if i + 1 == many.len() { ")" } else { "," };
                    if i == 0 {
                        push(
                            &mut pieces,
                            format!("{variables}({}{close}", value(v)),
                            term_start,
                            1,
                        );
                    } else {
                        push(&mut pieces, format!("{}{close}", value(v)), v.span().start, 2);
                    }
                }
            }
        }
    }
    pieces
}

/// `solver qp` or `solver MS1 rrt, MS2 qp`, breaking after each comma.
fn solver_pieces(statement: &SolverStatement) -> Vec<Piece> {
    let count = statement.entries.len();
    statement
        .entries
        .iter()
        .enumerate()
        .map(|(i, entry)| {
            let mut text = match &entry.segment {
                Some(segment) => format!("{} {}", segment.text, entry.solver.text),
                None => entry.solver.text.clone(),
            };
            if i + 1 < count {
                text.push(',');
            }
            if i == 0 {
                Piece::first(format!("solver {text}"), statement.span.start)
            } else {
                Piece::then(text, entry.span.start, 1)
            }
        })
        .collect()
}

/// `path item, item : hard`, breaking after each comma.
fn path_pieces(path: &Path) -> Vec<Piece> {
    let count = path.items.len();
    let hardness = path.hardness.as_ref().map(|h| format!(" : {}", h.text)).unwrap_or_default();
    path.items
        .iter()
        .enumerate()
        .map(|(i, item)| {
            let mut text = format!("{} {}", names(&item.variables), feature(&item.feature, false));
            if i + 1 == count {
                text.push_str(&hardness);
            } else {
                text.push(',');
            }
            if i == 0 {
                Piece::first(format!("path {text}"), path.span.start)
            } else {
                Piece::then(text, item.span.start, 1)
            }
        })
        .collect()
}

/// `[+Tr ]segment D { P +Pa P }`: broken, its primitives go inside the
/// braces on a line of their own, then one a line.
fn segment_pieces(segment: &Segment, after_another: bool) -> Vec<Piece> {
    let mut head = if after_another { "+Tr segment" } else { "segment" }.to_owned();
    let mut before_brace = " ";
    if let Some(d) = &segment.duration {
        head.push_str(&format!(" {}", quantity(d)));
        before_brace = gap(d.unit.as_ref());
    }
    let first = Piece::first(format!("{head}{before_brace}{{"), segment.span.start);
    let mut pieces = vec![Piece { words_before: after_another, ..first }];
    for (i, (combine, p)) in segment.primitives.iter().enumerate() {
        let operator = match (i, combine) {
            (0, _) => "",
            (_, Combine::Add) => "+Pa ",
            (_, Combine::Remove) => "-Pa ",
        };
        let level = if i == 0 { 1 } else { 2 };
        let text = format!("{operator}{}", primitive(p));
        pieces.push(Piece { indent: 1, ..Piece::then(text, p.span.start, level) });
    }
    let close = segment.braces.end.saturating_sub(1);
    pieces.push(Piece { indent: 0, closes: true, ..Piece::then("}".to_owned(), close, 1) });
    pieces
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
    contact { box_a,ball }
  }
  action type_vii explicit {
    contact {bar} solver rrt
    segment 1.2 s { Os.path(about r, 24.7 deg) +Pa (θe Ow).goal(100 deg, rpy(-15.5, -11.5, -104.6) deg) }
    +Tr segment 1.0 s { (Pw Ow).goal([0.27, -0.10, 0.05], axes(f: [1,0,0], p: [0,1,0])) +Pa θsw.hold }
    +Tr segment 0.8 s { (Pw Ow).hold +Pa θsw.goal(63.2 deg) }
    +Tr segment { (Pw Ow sw).hold -Pa sw +Pa sw.path(by 10 deg) }
  }
}
"#;

    const EVERYTHING_CANONICAL: &str = r#"robot "../../robots/coman_right_arm.urdf" # path relative to this file
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
    goal Pw Ow = ([0.25, -0.28, -0.05], rpy(180, 0, 90) deg)
        > Os = axes(r: [0, 0, -1], l: [0, 1, 0])
    duration 2 s
  }

  action retract {
    pre { hand_empty, box_b_near_a }
    add { box_b_moved }
    del { box_b_near_a }
    goal Pw Ow = ([0.15, -0.25, 0.05], rpy(180, 0, 90) deg)
    path Os about z, θe hold : hard
  }

  +Se action push {
    pre { box_b_moved }
    add { box_a_aside }
    contact { box_a, ball }
    path Pw line [0, 1, 0] 0.12 m, Ow hold, θsw hold
    solver qp
  }

  action type_vii explicit {
    contact { bar }
    solver rrt
    segment 1.2 s {
      Os.path(about r, 24.7 deg) +Pa (θe Ow).goal(100 deg, rpy(-15.5, -11.5, -104.6) deg)
    }
    +Tr segment 1 s {
      (Pw Ow).goal([0.27, -0.1, 0.05], axes(f: [1, 0, 0], p: [0, 1, 0])) +Pa θsw.hold
    }
    +Tr segment 0.8 s { (Pw Ow).hold +Pa θsw.goal(63.2 deg) }
    +Tr segment { (Pw Ow sw).hold -Pa sw +Pa sw.path(by 10 deg) }
  }
}
"#;

    /// [`EVERYTHING`] with comments of every kind in every kind of place.
    const COMMENTED: &str = r#"# header comment
// second header line

robot "../../robots/coman_right_arm.urdf"   # path relative to this file
start [0, -20, 0, -60, 0, 10, 0] deg   // joints

# the obstacles
scene {   # opening
  table = box      at [0.45, 0, -0.30]  size [0.40, 0.80, 0.04]   # the table
  # a box on it
  box_a = box      at [0.42, 0.06, -0.23] size [0.08, 0.08, 0.10]
  bar   = capsule  from [0.3, -0.3, 0.1]
                   to [0.3, 0.3, 0.1]   # inside an obstacle
                   radius 0.02
  post  = cylinder at [0.37, 0.05, -0.5] radius 0.03 height 1.0
  ball  = sphere   at [0.3, 0.1, 0.0] radius 5 cm
  # after the last obstacle
}   # closing

settings { rate 100 Hz  solver auto  # two on a line
  seed 7  transition 20 %  frame base
  // end of settings
}

task push_box_a_aside {   # the task
  init { holding, box_b_near_a }
  # the goal facts
  goal { box_a_aside,   # first
         hand_empty }

  # drops
  action drop "Drop the # things // in the hand" {
    pre { holding } add { hand_empty } del { holding }   # three on a line
    goal Pw Ow = ([0.25, -0.28, -0.05], rpy(180, 0, 90) deg)   # first goal
         ≻ Os = axes(r: [0, 0, -1], l: [0, 1, 0])                 # second goal
    duration 2 s
  }   # end of drop
  action retract {
    pre { hand_empty, box_b_near_a } add { box_b_moved } del { box_b_near_a }
    goal Pw Ow = ([0.15, -0.25, 0.05], rpy(180, 0, 90) deg)
    path Os about z,   # about z
         # then
         θe hold : hard
    # end of retract
  }
  +Se   # sequential
  action push {
    pre { box_b_moved } add { box_a_aside }
    contact { box_a }   # pushed
    path Pw line [0, 1, 0] 0.12 m, Ow hold, θsw hold
    solver qp   # the solver
  }
  action type_vii   # header
  explicit {
    // before the first segment
    segment 1.2 s {   # first segment
      Os.path(about r, 24.7 deg)
      # parallel
      +Pa (θe Ow).goal(100 deg, rpy(-15.5, -11.5, -104.6) deg) }
    +Tr segment 1.0 s { (Pw Ow).goal([0.27, -0.10, 0.05], axes(f: [1,0,0], p: [0,1,0])) +Pa θsw.hold }
    # third
    +Tr segment 0.8 s { (Pw Ow).hold +Pa θsw.goal(63.2 deg) }
    +Tr segment { (Pw Ow sw).hold -Pa sw +Pa sw.path(by 10 deg) }   // last
  }
  action empty { # nothing yet
  }
  action empty_too {
    // to do
  }
}
# the end
"#;

    const COMMENTED_CANONICAL: &str = r#"# header comment
// second header line

robot "../../robots/coman_right_arm.urdf" # path relative to this file
start [0, -20, 0, -60, 0, 10, 0] deg // joints

# the obstacles
scene { # opening
  table = box      at [0.45, 0, -0.3] size [0.4, 0.8, 0.04] # the table
  # a box on it
  box_a = box      at [0.42, 0.06, -0.23] size [0.08, 0.08, 0.1]
  bar   = capsule  from [0.3, -0.3, 0.1] to [0.3, 0.3, 0.1] radius 0.02 # inside an obstacle
  post  = cylinder at [0.37, 0.05, -0.5] radius 0.03 height 1
  ball  = sphere   at [0.3, 0.1, 0] radius 5 cm
  # after the last obstacle
} # closing

settings {
  rate 100 Hz
  solver auto # two on a line
  seed 7
  transition 20 %
  frame base
  // end of settings
}

task push_box_a_aside { # the task
  init { holding, box_b_near_a }
  # the goal facts
  goal { box_a_aside, # first
      hand_empty }

  # drops
  action drop "Drop the # things // in the hand" {
    pre { holding }
    add { hand_empty }
    del { holding } # three on a line
    goal Pw Ow = ([0.25, -0.28, -0.05], rpy(180, 0, 90) deg) # first goal
        > Os = axes(r: [0, 0, -1], l: [0, 1, 0]) # second goal
    duration 2 s
  } # end of drop

  action retract {
    pre { hand_empty, box_b_near_a }
    add { box_b_moved }
    del { box_b_near_a }
    goal Pw Ow = ([0.15, -0.25, 0.05], rpy(180, 0, 90) deg)
    path Os about z, # about z
        # then
        θe hold : hard
    # end of retract
  }

  +Se action push { # sequential
    pre { box_b_moved }
    add { box_a_aside }
    contact { box_a } # pushed
    path Pw line [0, 1, 0] 0.12 m, Ow hold, θsw hold
    solver qp # the solver
  }

  action type_vii explicit { # header
    // before the first segment
    segment 1.2 s { # first segment
      Os.path(about r, 24.7 deg)
      # parallel
      +Pa (θe Ow).goal(100 deg, rpy(-15.5, -11.5, -104.6) deg)
    }
    +Tr segment 1 s {
      (Pw Ow).goal([0.27, -0.1, 0.05], axes(f: [1, 0, 0], p: [0, 1, 0])) +Pa θsw.hold
    }
    # third
    +Tr segment 0.8 s { (Pw Ow).hold +Pa θsw.goal(63.2 deg) }
    +Tr segment { (Pw Ow sw).hold -Pa sw +Pa sw.path(by 10 deg) } // last
  }

  action empty { # nothing yet
  }

  action empty_too {
    // to do
  }
}
# the end
"#;

    /// Checks the laws on `text` and returns its canonical form: the printed
    /// text reads back to the same items and comments and prints the same.
    /// Comments keep their order unless statements they go with are put in
    /// canonical order.
    fn canonical(text: &str) -> String {
        let tree = parse_ast(text, None).unwrap_or_else(|d| panic!("input parses:\n{d}"));
        let printed = format(&tree);
        let reparsed = parse_ast(&printed, None)
            .unwrap_or_else(|d| panic!("canonical form parses:\n{d}\n--- printed:\n{printed}"));
        if comment_order_kept(&tree) {
            assert_eq!(reparsed, tree, "same tree after printing:\n{printed}");
        } else {
            assert_eq!(reparsed.items, tree.items, "same items after printing:\n{printed}");
            let texts = |file: &File| {
                let mut texts: Vec<String> = file.comments.iter().map(|c| c.text.clone()).collect();
                texts.sort();
                texts
            };
            assert_eq!(texts(&reparsed), texts(&tree), "same comments after printing:\n{printed}");
        }
        assert_eq!(format(&reparsed), printed, "idempotent");
        printed
    }

    /// Whether printing keeps the comments in order: no task or action that
    /// has its statements out of print order holds a comment.
    fn comment_order_kept(file: &File) -> bool {
        let increasing = |spans: Vec<Span>| spans.windows(2).all(|w| w[0].start < w[1].start);
        let facts = |lists: &[&Vec<Facts>]| -> Vec<Span> {
            lists.iter().flat_map(|list| list.iter().map(|f| f.span)).collect()
        };
        let uncommented = |extent: Span| {
            !file.comments.iter().any(|c| (extent.start..extent.end).contains(&c.span.start))
        };
        file.items.iter().all(|item| {
            let Item::Task(task) = item else { return true };
            let actions_kept = task.actions.iter().all(|action| {
                let mut spans = facts(&[&action.pre, &action.add, &action.del, &action.contact]);
                if let ActionBody::Constraints { goals, paths, durations } = &action.body {
                    spans.extend(goals.iter().map(|g| g.span));
                    spans.extend(paths.iter().map(|p| p.span));
                    spans.extend(durations.iter().map(|d| d.span));
                }
                spans.extend(action.solver.iter().map(|s| s.span));
                increasing(spans) || uncommented(action.braces)
            });
            actions_kept
                && (increasing(facts(&[&task.init, &task.goal])) || uncommented(task.braces))
        })
    }

    /// The comment texts of `text`, in order.
    fn comment_texts(text: &str) -> Vec<String> {
        let tree = parse_ast(text, None).unwrap_or_else(|d| panic!("input parses:\n{d}"));
        tree.comments.into_iter().map(|c| c.text).collect()
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
    fn layout_goes_comments_stay() {
        let text =
            "// header\nrobot   \"a.urdf\" # trailing  \r\n\n\n  start [ 0,0 , 0,0,0,0,0 ]rad\n";
        assert_eq!(
            canonical(text),
            "// header\nrobot \"a.urdf\" # trailing\n\nstart [0, 0, 0, 0, 0, 0, 0] rad\n"
        );
        assert_eq!(canonical(""), "");
        assert_eq!(canonical("# only a comment\n"), "# only a comment\n");
        assert_eq!(canonical("\u{FEFF}  # one\n\n\n// two"), "# one\n\n// two\n");
    }

    #[test]
    fn solvers_per_segment_round_trip() {
        assert_eq!(
            canonical("task t { action a { goal θsw = 1 solver qp,MS2   rrt # why\n } }"),
            "task t {\n  action a {\n    goal θsw = 1\n    solver qp, MS2 rrt # why\n  }\n}\n"
        );
    }

    #[test]
    fn blank_lines_stay_one_at_most() {
        let text = "robot \"a.urdf\"\n\n\n\nstart [0, 0, 0, 0, 0, 0, 0]\ntask t {\n\n  action a {\n    goal Pw = [0, 0, 0]\n\n\n    # then\n    path Ow hold\n\n  }\n}\n";
        assert_eq!(
            canonical(text),
            "robot \"a.urdf\"\n\nstart [0, 0, 0, 0, 0, 0, 0]\n\ntask t {\n  action a {\n    goal Pw = [0, 0, 0]\n\n    # then\n    path Ow hold\n  }\n}\n"
        );
    }

    #[test]
    fn long_statements_break_at_the_fewest_places() {
        let values = "([0.25, -0.28, -0.05], rpy(180, 0, 90) deg)";
        let os = "axes(r: [0.544, -0.824, -0.161], l: [0.3, 0.37, -0.879])";
        let text = format!("task t {{ action a {{ goal Pw Ow = {values} > Os = {os} }} }}");
        let printed = canonical(&text);
        assert!(
            printed.contains(&format!("    goal Pw Ow = {values}\n        > Os = {os}\n")),
            "{printed}"
        );
        // Every line fits, and a line too long even at the first level
        // breaks the value lists too.
        let long = "[0.250000001, -0.280000001, -0.050000001]";
        let text = format!(
            "task t {{ action a {{ goal Pw Ow θsw = ({long}, rpy(180.000001, 0.000001, 90.000001) deg, 63.2 deg) }} }}"
        );
        let printed = canonical(&text);
        assert!(printed.lines().all(|l| l.chars().count() <= WIDTH), "{printed}");
        assert!(
            printed.contains(&format!("    goal Pw Ow θsw = ({long},\n        rpy(")),
            "{printed}"
        );
        let names: Vec<String> = (0..20).map(|i| format!("fact_number_{i}")).collect();
        let text = format!(
            "task t {{ init {{ {0} }} goal {{ {0} }} action a {{ goal θsw = 1 }} }}",
            names.join(", ")
        );
        let printed = canonical(&text);
        assert!(printed.lines().all(|l| l.chars().count() <= WIDTH), "{printed}");
        assert!(printed.contains("  init { fact_number_0,\n      fact_number_1,\n"), "{printed}");
        let text = "task t { action a explicit { segment 1 s { Pw.goal([0.179, 0.101, -0.165]) +Pa Ow.goal(rpy(-17.7, -6.2, 46.2) deg) +Pa θsw.goal(22.9 deg) } } }";
        assert_eq!(
            canonical(text),
            "task t {\n  action a explicit {\n    segment 1 s {\n      Pw.goal([0.179, 0.101, -0.165]) +Pa Ow.goal(rpy(-17.7, -6.2, 46.2) deg) +Pa θsw.goal(22.9 deg)\n    }\n  }\n}\n"
        );
    }

    #[test]
    fn comments_everywhere_round_trip() {
        assert_eq!(canonical(COMMENTED), COMMENTED_CANONICAL);
        assert_eq!(canonical(COMMENTED_CANONICAL), COMMENTED_CANONICAL);
    }

    #[test]
    fn own_line_comments_go_before_the_next_node() {
        let text = "# robot\nrobot \"a.urdf\"\n\n\n# start\nstart [0, 0, 0, 0, 0, 0, 0]
# scene, after the blank line
scene { # obstacles
# a
a = sphere at [0, 0, 0] radius 1 }
task t {
# init
init { x } goal { y }
# first action
action a { goal Pw = [0, 0, 0]
# path, then duration
path Ow hold duration 1 s }
# second action
action b { goal θsw = 1 } }";
        assert_eq!(
            canonical(text),
            "# robot
robot \"a.urdf\"

# start
start [0, 0, 0, 0, 0, 0, 0]

# scene, after the blank line
scene { # obstacles
  # a
  a = sphere at [0, 0, 0] radius 1
}

task t {
  # init
  init { x }
  goal { y }

  # first action
  action a {
    goal Pw = [0, 0, 0]
    # path, then duration
    path Ow hold
    duration 1 s
  }

  # second action
  action b {
    goal θsw = 1
  }
}
"
        );
    }

    #[test]
    fn trailing_comments_follow_their_line() {
        let text = "robot \"a.urdf\" // robot
scene { a = box at [0, 0, 0] size [1, 1, 1] # box
  b = sphere at [1, 1, 1]   # a comment inside a node
    radius 1 }   # scene
task t { action a { goal Pw = [0, 0, 0] # goal
  path Ow hold,   # Ow
    θsw hold      # θsw
} # a
+Se  # after +Se
action b { goal Ow = rpy(0, 0, 0) } } # t";
        assert_eq!(
            canonical(text),
            "robot \"a.urdf\" // robot

scene {
  a = box    at [0, 0, 0] size [1, 1, 1] # box
  b = sphere at [1, 1, 1] radius 1 # a comment inside a node
} # scene

task t {
  action a {
    goal Pw = [0, 0, 0] # goal
    path Ow hold, # Ow
        θsw hold # θsw
  } # a

  +Se action b { # after +Se
    goal Ow = rpy(0, 0, 0)
  }
} # t
"
        );
    }

    #[test]
    fn trailing_comment_after_a_statement_over_several_lines() {
        // An unknown unit ends its line, so the statement takes two.
        let text = "scene { post = cylinder at [0, 0, 0] radius 3 cmm # post\n height 1 m }";
        assert_eq!(
            canonical(text),
            "scene {\n  post = cylinder at [0, 0, 0] radius 3 cmm\n      height 1 m # post\n}\n"
        );
    }

    #[test]
    fn comments_at_the_end_of_blocks_and_of_the_file() {
        let text = "scene {
  a = sphere at [0, 0, 0] radius 1
  # end of scene
}
settings {
  # nothing set
}
task t {
  action a {
  }
  action b explicit {
    segment { Pw.hold }
    # end of b
  }
  # end of t
}
// end of file
# really";
        assert_eq!(
            canonical(text),
            "scene {
  a = sphere at [0, 0, 0] radius 1
  # end of scene
}

settings {
  # nothing set
}

task t {
  action a {}

  action b explicit {
    segment { Pw.hold }
    # end of b
  }
  # end of t
}
// end of file
# really
"
        );
        // A comment keeps an empty block open, whether on the brace's line
        // or its own.
        assert_eq!(canonical("scene { # none yet\n}"), "scene { # none yet\n}\n");
        assert_eq!(canonical("scene {} # none yet"), "scene {} # none yet\n");
        assert_eq!(
            canonical("task t { action a { // to do\n // later\n} }"),
            "task t {
  action a { // to do
    // later
  }
}
"
        );
    }

    #[test]
    fn comments_inside_settings_segments_and_explicit_actions() {
        let text = "settings { rate 100 Hz # fast
  # seeded
  seed 7 }
task t { action a # the action
  explicit { # segments follow
  pre { x,
        # y is not needed
        z }
  solver qp // the solver
  # first segment
  segment 1 s {
    # inside, before the first primitive
    Pw.hold   # hold
    +Pa Ow.hold
  }
  +Tr segment { (Pw Ow θsw).hold } } }";
        assert_eq!(
            canonical(text),
            "settings {
  rate 100 Hz # fast
  # seeded
  seed 7
}

task t {
  action a explicit { # the action
    # segments follow
    pre { x,
        # y is not needed
        z }
    solver qp // the solver
    # first segment
    segment 1 s {
      # inside, before the first primitive
      Pw.hold # hold
      +Pa Ow.hold
    }
    +Tr segment { (Pw Ow θsw).hold }
  }
}
"
        );
    }

    #[test]
    fn both_styles_and_strings() {
        let text =
            "robot \"a#b//c.urdf\" #a // b\n//c # d\ntask t { action a \"# not // a comment\" {} }";
        let tree = parse_ast(text, None).expect("parses");
        let comments: Vec<(&str, bool)> =
            tree.comments.iter().map(|c| (c.text.as_str(), c.own_line)).collect();
        assert_eq!(comments, [("#a // b", false), ("//c # d", true)]);
        let Item::Robot(super::super::ast::RobotLine { path, .. }) = &tree.items[0] else {
            panic!("robot")
        };
        assert_eq!(path.text, "a#b//c.urdf");
        assert_eq!(
            canonical(text),
            "robot \"a#b//c.urdf\" #a // b\n\n//c # d\ntask t {\n  action a \"# not // a comment\" {}\n}\n"
        );
        // One slash is not a comment, and does not parse.
        assert!(parse_ast("robot \"a.urdf\" / no", None).is_err());
    }

    #[test]
    fn comments_move_with_statements_put_in_order() {
        let text = "task t { goal { y } # the goal
  init { x } # the start
  action a {
    solver qp # why qp
    path Pw hold # the path
    del { x } # the del
  } }";
        let printed = canonical(text);
        assert_eq!(
            printed,
            "task t {
  init { x } # the start
  goal { y } # the goal

  action a {
    del { x } # the del
    path Pw hold # the path
    solver qp # why qp
  }
}
"
        );
        assert_eq!(
            comment_texts(&printed),
            ["# the start", "# the goal", "# the del", "# the path", "# why qp"]
        );
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

    /// Every variant of [`EVERYTHING`] and [`COMMENTED`] with one word left
    /// out, or with one line break turned into a space, that still parses
    /// keeps the laws.
    #[test]
    fn near_variants_round_trip() {
        for source in [EVERYTHING, COMMENTED] {
            let words: Vec<&str> = source.split(' ').collect();
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
            for (i, _) in source.match_indices('\n') {
                let text = format!("{} {}", &source[..i], &source[i + 1..]);
                if parse_ast(&text, None).is_ok() {
                    canonical(&text);
                    parsed += 1;
                }
            }
            assert!(parsed > 50, "only {parsed} variants parse");
        }
    }

    /// A comment put in place of any space or line break of [`EVERYTHING`],
    /// [`COMMENTED`] or [`MISSPELT`], ending a line or on a line of its own;
    /// one at every line break at once; or several at random places: each
    /// variant that still parses keeps the laws and the comment.
    #[test]
    fn added_comments_round_trip() {
        let comment = |i: usize, own_line: bool| {
            if own_line { format!("\n  // added {i}\n") } else { format!(" # added {i}\n") }
        };
        let mut state: u64 = 0x2545_F491_4F6C_DD1D;
        let mut random = move |below: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            usize::try_from(state % below as u64).expect("below a usize")
        };
        for source in [EVERYTHING, COMMENTED, MISSPELT] {
            let spaces: Vec<(usize, usize)> =
                source.match_indices([' ', '\n']).map(|(i, s)| (i, s.len())).collect();
            let mut parsed = 0;
            for &(i, len) in &spaces {
                for own_line in [false, true] {
                    let text =
                        format!("{}{}{}", &source[..i], comment(i, own_line), &source[i + len..]);
                    if parse_ast(&text, None).is_err() {
                        continue;
                    }
                    let printed = canonical(&text);
                    // After a comment, a trailing one only lengthens it.
                    let kept = comment_texts(&printed);
                    assert!(kept.iter().any(|t| t.ends_with(&format!("added {i}"))), "{printed}");
                    parsed += 1;
                }
            }
            assert!(parsed > 100, "only {parsed} variants parse");
            for style in ["  # everywhere", "\n# everywhere"] {
                canonical(&source.replace('\n', &format!("{style}\n")));
            }
            for _ in 0..200 {
                let mut text = source.to_owned();
                let mut picked: Vec<(usize, usize)> =
                    (0..2 + random(3)).map(|_| spaces[random(spaces.len())]).collect();
                picked.sort_unstable();
                picked.dedup();
                for &(i, len) in picked.iter().rev() {
                    text.replace_range(i..i + len, &comment(i, random(2) == 0));
                }
                if parse_ast(&text, None).is_ok() {
                    canonical(&text);
                }
            }
        }
    }

    /// Unknown unit words, which are units only at the end of a line.
    const MISSPELT: &str = "start Pw [0.2, -0.1, -0.2] mx
  Ow rpy(0, 90, 0) dgr
  sw 30 deg
scene { post = cylinder at [0, 0, 0] mx
  radius 3 cmm
  height 1 m }
task t { action a { path Pw line [0, 1, 0] mx
  2 cm }
  action b explicit { segment 2 sec
  { Pw.hold } } }";

    #[test]
    fn misspelt_units_survive() {
        let printed = canonical(MISSPELT);
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
