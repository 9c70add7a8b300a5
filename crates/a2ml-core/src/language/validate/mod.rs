//! Syntax tree to [`Task`]: units to SI, every variable checked against its
//! space, segments checked for coverage, names resolved. Collects every
//! problem rather than stopping at the first. This file walks the file's
//! items (robot, start, scene, settings, task); one file per level below it:
//! [`action`] (facts, contacts, solver statements, STRIPS), [`constraint`]
//! (goals and paths), [`segment`] (explicit segments), [`scene`], [`settings`],
//! [`variables`] (state variables and their spaces) and [`values`] (units,
//! numbers, vectors, rotations, axes, targets).

mod action;
mod constraint;
mod scene;
mod segment;
mod settings;
mod values;
mod variables;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::ast::{self, Name, Span};
use super::bounds::{self, Limits};
use super::diagnostic::Diagnostic;
use super::task::*;
use crate::math::{DOF, JointVector, Real};
use values::Dimension;
use variables::list;

struct Checker<'a> {
    errors: Vec<Diagnostic>,
    base_dir: Option<&'a Path>,
    /// The text the spans point into (the seed is read from it: every u64, exactly).
    source: &'a str,
    limits: &'a Limits,
    /// Every duration written, in file order, for the sample limit.
    durations: Vec<(Span, Real)>,
    /// Where the rate is written.
    rate_span: Span,
    /// Every obstacle name the scene declares, shapes valid or not, so that
    /// a bad shape is not reported again at each `contact` naming it.
    obstacles: Vec<String>,
}

impl Checker<'_> {
    fn error(&mut self, span: Span, message: impl Into<String>) {
        self.errors.push(Diagnostic::new(span, message));
    }

    fn error_with_help(&mut self, span: Span, message: impl Into<String>, help: Option<String>) {
        let mut d = Diagnostic::new(span, message);
        d.help = help;
        self.errors.push(d);
    }

    fn robot(&mut self, name: &Name) -> Option<PathBuf> {
        let written = Path::new(&name.text);
        let resolved = match self.base_dir {
            Some(dir) if written.is_relative() => dir.join(written),
            _ => written.to_path_buf(),
        };
        if !resolved.is_file() {
            self.error(name.span, format!("robot file not found: {}", resolved.display()));
            return None;
        }
        Some(resolved)
    }

    fn start(&mut self, start: &ast::Start) -> Option<Start> {
        match start {
            ast::Start::Joints(v) => {
                let q = self.numbers(v, Dimension::Angle, DOF, "the start configuration")?;
                Some(Start::Joints(JointVector::from_column_slice(&q)))
            }
            ast::Start::State { entries, span } => {
                let names: Vec<Name> = entries.iter().map(|(n, _)| n.clone()).collect();
                let (vars, space) = self.variables(&names)?;
                let targets: Vec<Option<Target>> =
                    vars.iter().zip(entries).map(|(v, (_, x))| self.target(*v, x)).collect();
                let targets: Vec<Target> = targets.into_iter().collect::<Option<_>>()?;
                let space = space.unwrap_or(Space::Cpsa);
                let missing: Vec<Variable> =
                    space.variables().into_iter().filter(|v| !vars.contains(v)).collect();
                if !missing.is_empty() {
                    self.error(
                        *span,
                        format!(
                            "a start state in {} space also needs {}",
                            space.name(),
                            list(&missing)
                        ),
                    );
                    return None;
                }
                Some(Start::State(vars.into_iter().zip(targets).collect()))
            }
        }
    }
}

/// Validates a parsed file. `base_dir` is the task file's folder, against
/// which the robot path is resolved.
pub(super) fn validate(
    file: &ast::File,
    source: &str,
    base_dir: Option<&Path>,
    limits: &Limits,
) -> Result<Task, Vec<Diagnostic>> {
    let mut c = Checker {
        errors: Vec::new(),
        base_dir,
        source,
        limits,
        durations: Vec::new(),
        rate_span: Span::default(),
        obstacles: Vec::new(),
    };
    let mut robot: Option<PathBuf> = None;
    let mut robot_chain: (Option<Name>, Option<Name>) = (None, None);
    let (mut seen_robot, mut start, mut scene, mut settings) = (false, None, Vec::new(), None);
    let mut tasks: Vec<&ast::Task> = Vec::new();
    let mut seen_start = false;
    let mut seen_scene = false;
    for item in &file.items {
        match item {
            ast::Item::Robot(line) => {
                if seen_robot {
                    c.error(line.path.span, "a file names one `robot`");
                }
                seen_robot = true;
                robot = c.robot(&line.path).or(robot);
                for link in [&line.base, &line.tip].into_iter().flatten() {
                    if link.text.trim().is_empty() {
                        c.error(link.span, "a link name cannot be empty");
                    }
                }
                robot_chain = (line.base.clone(), line.tip.clone());
            }
            ast::Item::Start(s) => {
                if seen_start {
                    let span = match s {
                        ast::Start::Joints(v) => v.span,
                        ast::Start::State { span, .. } => *span,
                    };
                    c.error(span, "a file has one `start`");
                }
                seen_start = true;
                start = c.start(s);
            }
            ast::Item::Scene(s) => {
                if seen_scene {
                    c.error(s.span, "a file has one `scene`");
                }
                seen_scene = true;
                c.obstacles.extend(s.obstacles.iter().map(|o| o.name.text.clone()));
                scene.extend(c.scene(s));
            }
            ast::Item::Settings(s) => {
                if settings.is_some() {
                    c.error(s.span, "a file has one `settings`");
                }
                settings = Some(c.settings(s));
            }
            ast::Item::Task(t) => tasks.push(t),
        }
    }
    if !seen_robot {
        c.error(Span::default(), "the file names no robot: add `robot \"path/to/arm.urdf\"`");
    }
    for extra in tasks.iter().skip(1) {
        c.error(extra.name.span, "a file holds one `task`");
    }
    let Some(task) = tasks.first() else {
        c.error(Span { start: 0, end: 0 }, "the file has no `task`");
        return Err(c.errors);
    };
    let mut action_names: HashMap<&str, Span> = HashMap::new();
    for a in &task.actions {
        if action_names.insert(&a.name.text, a.name.span).is_some() {
            c.error(a.name.span, format!("action `{}` is declared twice", a.name.text));
        }
    }
    let actions: Vec<Action> = task.actions.iter().filter_map(|a| c.action(a)).collect();
    c.segment_limit(task);
    let rate = settings.as_ref().map_or(Settings::default().rate, |s| s.rate);
    if let Some(d) = bounds::check_samples(&c.durations, (c.rate_span, rate), c.limits) {
        c.errors.push(d);
    }
    let init = c.facts(&task.init, "init");
    let goal = c.facts(&task.goal, "goal");
    let planned = !task.init.is_empty() || !task.goal.is_empty();
    if planned {
        if task.init.is_empty() {
            c.error(task.goal[0].span, "a task with a `goal { .. }` also needs `init { .. }`");
        }
        if task.goal.is_empty() {
            c.error(task.init[0].span, "a task with `init { .. }` also needs a `goal { .. }`");
        }
        c.strips(task, &init);
    }
    c.errors.sort_by_key(|d| (d.span.start, d.span.end));
    if !c.errors.is_empty() {
        return Err(c.errors);
    }
    Ok(Task {
        name: task.name.text.clone(),
        robot: robot.unwrap_or_default(),
        robot_base: robot_chain.0.map(|n| n.text),
        robot_tip: robot_chain.1.map(|n| n.text),
        start,
        scene,
        settings: settings.unwrap_or_default(),
        init: planned.then_some(init),
        goal: planned.then_some(goal),
        actions,
    })
}
