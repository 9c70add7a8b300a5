//! An action: its facts, contacts, solver statement and body; the task's
//! segment limit and STRIPS check.

use super::Checker;
use crate::language::ast;
use crate::language::task::*;
use crate::names::did_you_mean;

impl Checker<'_> {
    pub(super) fn facts(&mut self, lists: &[ast::Facts], what: &str) -> Vec<String> {
        if let Some(extra) = lists.get(1) {
            self.error(extra.span, format!("`{what}` is given twice"));
        }
        let mut out: Vec<String> = Vec::new();
        for n in lists.iter().flat_map(|f| &f.names) {
            if out.contains(&n.text) {
                self.error(n.span, format!("fact `{}` is listed twice", n.text));
            } else {
                out.push(n.text.clone());
            }
        }
        out
    }

    /// The obstacles of an action's `contact`: declared in the scene, each
    /// named once.
    pub(super) fn contact(&mut self, lists: &[ast::Facts]) -> Vec<String> {
        if let Some(extra) = lists.get(1) {
            self.error(extra.span, "`contact` is given twice; list every obstacle in one");
        }
        let mut out: Vec<String> = Vec::new();
        for n in lists.iter().flat_map(|f| &f.names) {
            if out.contains(&n.text) {
                self.error(n.span, format!("obstacle `{}` is listed twice", n.text));
                continue;
            }
            if !self.obstacles.contains(&n.text) {
                let declared = self.obstacles.iter().map(String::as_str);
                let help = did_you_mean(&n.text, declared)
                    .map(|s| format!("did you mean `{s}`?"))
                    .unwrap_or_else(|| match self.obstacles.as_slice() {
                        [] => "the file declares no obstacles".to_owned(),
                        names => format!("the scene declares {}", names.join(", ")),
                    });
                self.error_with_help(
                    n.span,
                    format!(
                        "unknown obstacle `{}`: `contact` names obstacles of the scene",
                        n.text
                    ),
                    Some(help),
                );
            }
            out.push(n.text.clone());
        }
        out
    }

    pub(super) fn action(&mut self, a: &ast::Action) -> Option<Action> {
        let pre = self.facts(&a.pre, "pre");
        let add = self.facts(&a.add, "add");
        let del = self.facts(&a.del, "del");
        let contact = self.contact(&a.contact);
        if let Some(extra) = a.solver.get(1) {
            self.error(extra.span, "`solver` is given twice");
        }
        let segments = match &a.body {
            ast::ActionBody::Explicit { segments } => Some(segments.len()),
            ast::ActionBody::Constraints { .. } => None,
        };
        let (solver, segment_solvers) = match a.solver.first() {
            Some(statement) => self.solver_statement(statement, &a.name.text, segments),
            None => (None, Vec::new()),
        };
        let body = match &a.body {
            ast::ActionBody::Constraints { goals, paths, durations } => {
                for g in goals.iter().skip(1) {
                    self.error(g.span, "an action has one `goal`; order two goals with `>` in it");
                }
                for p in paths.iter().skip(1) {
                    self.error(
                        p.span,
                        "an action has one `path`; list several variables in it with `,`",
                    );
                }
                for d in durations.iter().skip(1) {
                    self.error(d.span, "`duration` is given twice");
                }
                if goals.is_empty() && paths.is_empty() {
                    self.error(
                        a.name.span,
                        format!("action `{}` has neither a goal nor a path", a.name.text),
                    );
                }
                let mut goal = goals.first().map(|g| self.goal(g));
                let mut path = paths.first().map(|p| self.path(p));
                if let (Some(ast_path), Some(Some(pc))) = (paths.first(), &mut path) {
                    self.path_against_goal(
                        ast_path,
                        pc,
                        goal.as_ref().and_then(|g| g.as_ref()),
                        goals.is_empty(),
                    );
                    // A goal with errors of its own says nothing about the arc.
                    match goal.as_mut() {
                        Some(goal) if goal.is_none() => {}
                        Some(goal) => self.arc_to_goal(ast_path, pc, goal),
                        None => self.arc_to_goal(ast_path, pc, &mut None),
                    }
                }
                let duration = durations.first().map(|d| self.duration(d, "the duration"));
                ActionBody::Constraints {
                    goal: goal.flatten(),
                    path: path.flatten(),
                    duration: duration.flatten(),
                }
            }
            ast::ActionBody::Explicit { segments } => {
                let segs: Vec<Option<Segment>> = segments.iter().map(|s| self.segment(s)).collect();
                ActionBody::Explicit(segs.into_iter().flatten().collect())
            }
        };
        Some(Action {
            name: a.name.text.clone(),
            description: a.description.as_ref().map(|d| d.text.clone()),
            pre,
            add,
            del,
            contact,
            solver,
            segment_solvers,
            body,
            span: a.name.span,
        })
    }

    /// An action's `solver` statement: the solver of its segments and those
    /// of single segments, `MS1` the first. `segments` is the number of an
    /// explicit action's segments; an action decomposed has its segments
    /// checked by the decomposition.
    pub(super) fn solver_statement(
        &mut self,
        statement: &ast::SolverStatement,
        action: &str,
        segments: Option<usize>,
    ) -> (Option<SolverChoice>, Vec<SegmentSolver>) {
        let mut whole = None;
        let mut seen_whole = false;
        let mut single: Vec<SegmentSolver> = Vec::new();
        for entry in &statement.entries {
            let solver = self.solver(&entry.solver);
            let Some(segment) = &entry.segment else {
                if seen_whole {
                    self.error(
                        entry.span,
                        "one solver for the whole action; name the segment of the others (`MS2 rrt`)",
                    );
                }
                seen_whole = true;
                whole = whole.or(solver);
                continue;
            };
            let index = segment
                .text
                .strip_prefix("MS")
                .and_then(|k| k.parse::<usize>().ok())
                .filter(|&k| k >= 1 && !segment.text[2..].starts_with('0'));
            let Some(k) = index else {
                self.error(
                    segment.span,
                    format!(
                        "`{}` is not a segment: segments are named MS1, MS2, ... in their action",
                        segment.text
                    ),
                );
                continue;
            };
            if let Some(count) = segments.filter(|&count| k > count) {
                let names: Vec<String> = (1..=count).map(|i| format!("MS{i}")).collect();
                self.error(
                    segment.span,
                    format!(
                        "action `{action}` has {count} segment{} ({}): there is no {}",
                        if count == 1 { "" } else { "s" },
                        names.join(", "),
                        segment.text
                    ),
                );
            } else if single.iter().any(|s| s.segment == k - 1) {
                self.error(segment.span, format!("{} has a solver already", segment.text));
            } else if let Some(solver) = solver {
                single.push(SegmentSolver { segment: k - 1, solver, span: entry.span });
            }
        }
        (whole, single)
    }

    /// The actions and their written segments against [`Limits::max_segments`] (each action
    /// is at least one segment): an error at the action that crosses the limit.
    pub(super) fn segment_limit(&mut self, task: &ast::Task) {
        let mut segments = 0usize;
        for a in &task.actions {
            segments = segments.saturating_add(match &a.body {
                ast::ActionBody::Explicit { segments, .. } => segments.len().max(1),
                _ => 1,
            });
            if segments > self.limits.max_segments {
                self.error(
                    a.name.span,
                    format!(
                        "the task has more than {} segments by this action (raise the limit \
                         with --max-segments)",
                        self.limits.max_segments
                    ),
                );
                return;
            }
        }
    }

    /// STRIPS: every fact an action needs or deletes, and every goal fact,
    /// is in `init` or added by some action.
    pub(super) fn strips(&mut self, task: &ast::Task, init: &[String]) {
        let mut known: Vec<&str> = init.iter().map(String::as_str).collect();
        for a in &task.actions {
            known.extend(a.add.iter().flat_map(|f| &f.names).map(|n| n.text.as_str()));
        }
        let needed = task
            .actions
            .iter()
            .flat_map(|a| a.pre.iter().chain(&a.del))
            .chain(&task.goal)
            .flat_map(|f| &f.names);
        for n in needed {
            if !known.contains(&n.text.as_str()) {
                let help = did_you_mean(&n.text, known.iter().copied())
                    .map(|s| format!("did you mean `{s}`?"));
                self.error_with_help(
                    n.span,
                    format!(
                        "fact `{}` is never true: it is not in `init` and no action adds it",
                        n.text
                    ),
                    help,
                );
            }
        }
    }
}
