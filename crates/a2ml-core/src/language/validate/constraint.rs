//! An action's constraints: goals (one, or two ordered by `>`) and paths, and
//! what a path means next to the goal.

use super::Checker;
use super::values::Dimension;
use crate::language::ast::{self, Name};
use crate::language::task::*;
use crate::names::did_you_mean;

impl Checker<'_> {
    pub(super) fn goal_term(&mut self, term: &ast::GoalTerm) -> Option<Goal> {
        let Some((vars, space)) = self.variables(&term.variables) else {
            term.values.iter().for_each(|v| self.units_of(v));
            return None;
        };
        let targets = self.targets(&vars, &term.values, term.span)?;
        Some(Goal { targets: vars.into_iter().zip(targets).collect(), space, span: term.span })
    }

    pub(super) fn goal(&mut self, goal: &ast::Goal) -> Option<GoalConstraint> {
        let terms: Vec<Option<Goal>> = goal.terms.iter().map(|t| self.goal_term(t)).collect();
        let mut terms = terms.into_iter().collect::<Option<Vec<Goal>>>()?.into_iter();
        let primary = terms.next()?;
        let secondary = terms.next();
        if let Some(second) = &secondary {
            if let (Some(a), Some(b)) = (primary.space, second.space) {
                if a == b {
                    self.error(
                        second.span,
                        format!(
                            "both goals are in {} space; `>` orders goals of different spaces \
                             (write one goal `{}` for goals of one space)",
                            a.name(),
                            "V1 V2 = (v1, v2)"
                        ),
                    );
                    return None;
                }
            }
            if let Some((v, _)) =
                second.targets.iter().find(|(v, _)| primary.targets.iter().any(|(p, _)| p == v))
            {
                self.error(second.span, format!("{} appears in both goals", v.symbol()));
                return None;
            }
        }
        Some(GoalConstraint { primary, secondary })
    }

    /// A feature for `vars`, checking that each variable can keep it.
    pub(super) fn feature(
        &mut self,
        vars: &[Variable],
        names: &[Name],
        feature: &ast::Feature,
    ) -> Option<PathFeature> {
        let (allowed, what): (&[Variable], &str) = match feature {
            ast::Feature::Line { .. } => (&[Variable::Pw], "`line` moves Pw"),
            ast::Feature::About { .. } => {
                (&[Variable::Pw, Variable::Ow, Variable::Os], "`about` turns Pw, Ow or Os")
            }
            ast::Feature::By { .. } => {
                (&[Variable::Swivel, Variable::Elbow], "`by` changes θsw or θe")
            }
            ast::Feature::Arc { .. } => (&[Variable::Pw], "`arc` moves Pw"),
            ast::Feature::Hold => (&Variable::ALL, ""),
        };
        for (v, n) in vars.iter().zip(names) {
            if !allowed.contains(v) {
                self.error(n.span, format!("{what}, not {}", v.symbol()));
                return None;
            }
        }
        Some(match feature {
            ast::Feature::Line { direction, size } => PathFeature::Line {
                direction: self.direction(direction, "the line direction")?,
                length: match size {
                    Some(q) => Some(self.positive(q, Dimension::Length, "the line length")?),
                    None => None,
                },
            },
            ast::Feature::About { axis, size } => PathFeature::About {
                axis: self.axis(axis)?,
                angle: match size {
                    Some(q) => {
                        Some(self.positive(q, Dimension::Angle, "the angle about an axis")?)
                    }
                    None => None,
                },
            },
            ast::Feature::By { size } => {
                let angle = self.quantity(size, Dimension::Angle)?;
                if angle == 0.0 {
                    self.error(size.span, "`by` needs a non-zero angle (use `hold` to keep it)");
                    return None;
                }
                PathFeature::By { angle }
            }
            ast::Feature::Arc { through } => PathFeature::Arc {
                through: self.vector3(through, Dimension::Length, "the arc's point")?,
                to: None,
            },
            ast::Feature::Hold => PathFeature::Hold,
        })
    }

    pub(super) fn path(&mut self, path: &ast::Path) -> Option<PathConstraint> {
        let mut items = Vec::new();
        let mut all_vars: Vec<Variable> = Vec::new();
        let mut all_names: Vec<Name> = Vec::new();
        let mut ok = true;
        for item in &path.items {
            let Some((vars, _)) = self.variables(&item.variables) else {
                ok = false;
                continue;
            };
            for (v, n) in vars.iter().zip(&item.variables) {
                if all_vars.contains(v) {
                    self.error(n.span, format!("{} is constrained twice in this path", v.symbol()));
                    ok = false;
                }
            }
            all_vars.extend(&vars);
            all_names.extend(item.variables.iter().cloned());
            match self.feature(&vars, &item.variables, &item.feature) {
                Some(feature) => items.push(PathItem { variables: vars, feature }),
                None => ok = false,
            }
        }
        let hard = match &path.hardness {
            None => Some(true),
            Some(h) if h.text == "hard" => Some(true),
            Some(h) if h.text == "soft" => Some(false),
            Some(h) => {
                let help =
                    did_you_mean(&h.text, ["hard", "soft"]).map(|s| format!("did you mean `{s}`?"));
                self.error_with_help(
                    h.span,
                    format!("expected `hard` or `soft`, found `{}`", h.text),
                    help,
                );
                None
            }
        };
        let space = if ok { self.space_of(&all_names, &all_vars)? } else { None };
        let hard = hard?;
        ok.then_some(PathConstraint { items, space, hard, span: path.span })
    }

    /// What a path means next to the goal: without one, nothing can size an
    /// open path or be given way to by a soft one; with one, a variable
    /// cannot be both held to a hard path and sent to a goal.
    pub(super) fn path_against_goal(
        &mut self,
        ast_path: &ast::Path,
        path: &PathConstraint,
        goal: Option<&GoalConstraint>,
        no_goal: bool,
    ) {
        if no_goal {
            for (item, ast_item) in path.items.iter().zip(&ast_path.items) {
                if matches!(
                    item.feature,
                    PathFeature::Line { length: None, .. } | PathFeature::About { angle: None, .. }
                ) {
                    self.error(
                        ast_item.span,
                        "without a goal nothing can compute this path's size: give it (e.g. `0.1 m`, `30 deg`)",
                    );
                }
            }
            if let (false, Some(h)) = (path.hard, &ast_path.hardness) {
                self.error(h.span, "a soft path gives way to a goal, but this action has none");
            }
        }
        // A soft path may give way to a goal on the same variable (types V, VII).
        let Some(goal) = goal.filter(|_| path.hard) else { return };
        let goal_vars: Vec<Variable> = goal
            .primary
            .targets
            .iter()
            .chain(goal.secondary.iter().flat_map(|g| &g.targets))
            .map(|(v, _)| *v)
            .collect();
        for (item, ast_item) in path.items.iter().zip(&ast_path.items) {
            // An arc ends at the goal: it is the way there, not a conflict with it.
            if matches!(item.feature, PathFeature::Arc { .. }) {
                continue;
            }
            for (v, n) in item.variables.iter().zip(&ast_item.variables) {
                if goal_vars.contains(v) {
                    self.error(
                        n.span,
                        format!(
                            "{} has both a goal and a path constraint in this action",
                            v.symbol()
                        ),
                    );
                }
            }
        }
    }
}

impl Checker<'_> {
    /// An `arc` runs from the action's start to its Pw goal: the goal's Pw becomes the arc's
    /// end and leaves the goal (which keeps its other variables, or goes when it had none).
    /// The goal must be a single one with Pw in it.
    pub(super) fn arc_to_goal(
        &mut self,
        ast_path: &ast::Path,
        path: &mut PathConstraint,
        goal: &mut Option<GoalConstraint>,
    ) {
        for (item, ast_item) in path.items.iter_mut().zip(&ast_path.items) {
            let PathFeature::Arc { to, .. } = &mut item.feature else { continue };
            let single = goal.as_mut().filter(|g| g.secondary.is_none());
            let Some(g) =
                single.filter(|g| g.primary.targets.iter().any(|(v, _)| *v == Variable::Pw))
            else {
                self.error(
                    ast_item.span,
                    "`arc` runs from the start to the action's Pw goal: give one goal with Pw \
                     in it (no `>`)",
                );
                continue;
            };
            let k = g.primary.targets.iter().position(|(v, _)| *v == Variable::Pw);
            if let Some((_, Target::Position(end))) = k.map(|k| g.primary.targets.remove(k)) {
                *to = Some(end);
            }
            if g.primary.targets.is_empty() {
                *goal = None;
            } else if g.primary.targets.iter().all(|(v, _)| *v == Variable::Ow) {
                // Ow alone belongs to no one space: it takes the path's (classify).
                g.primary.space = None;
            }
        }
    }
}
