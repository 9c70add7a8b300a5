//! An explicit segment: its primitives, `-Pa` removals, and its coverage of one
//! space.

use super::Checker;
use super::variables::list;
use crate::language::ast::{self, Name};
use crate::language::task::*;

/// A group of an explicit segment: names as written, variables, constraint.
type Group = (Vec<Name>, Vec<Variable>, Option<PrimitiveConstraint>);

impl Checker<'_> {
    /// A segment's primitives. `-Pa` binds to the group just before it
    /// (paper eq. 4: MP− = complete primitive −Pa MP), so the complement
    /// may come first or last; a bare group is allowed right before `-Pa`
    /// and holds its remaining variables.
    pub(super) fn segment(&mut self, segment: &ast::Segment) -> Option<Segment> {
        // (names, variables, constraint) per group, after removals.
        let mut groups: Vec<Group> = Vec::new();
        let mut ok = true;
        let prims = &segment.primitives;
        for (k, (combine, p)) in prims.iter().enumerate() {
            let Some((vars, _)) = self.variables(&p.variables) else {
                ok = false;
                continue;
            };
            let next_removes = prims.get(k + 1).is_some_and(|(c, _)| *c == ast::Combine::Remove);
            match (combine, &p.constraint) {
                (ast::Combine::Add, None) if !next_removes => {
                    self.error(
                        p.span,
                        "a primitive needs `.goal(..)`, `.path(..)` or `.hold` \
                         (a bare group may only stand before `-Pa`)",
                    );
                    ok = false;
                }
                (ast::Combine::Add, None) => {
                    groups.push((p.variables.clone(), vars, Some(PrimitiveConstraint::Hold)));
                }
                (ast::Combine::Add, Some(c)) => {
                    let constraint = match c {
                        ast::PrimitiveConstraint::Goal(values) => {
                            self.targets(&vars, values, p.span).map(PrimitiveConstraint::Goal)
                        }
                        ast::PrimitiveConstraint::Path(f) => {
                            let feature = self.feature(&vars, &p.variables, f);
                            if let Some(
                                PathFeature::Line { length: None, .. }
                                | PathFeature::About { angle: None, .. },
                            ) = feature
                            {
                                self.error(
                                    p.span,
                                    "a path in an explicit segment needs its size: nothing computes it here",
                                );
                                ok = false;
                            }
                            feature.map(PrimitiveConstraint::Path)
                        }
                        ast::PrimitiveConstraint::Hold => Some(PrimitiveConstraint::Hold),
                    };
                    ok &= constraint.is_some();
                    groups.push((p.variables.clone(), vars, constraint));
                }
                (ast::Combine::Remove, Some(_)) => {
                    self.error(p.span, "`-Pa` removes variables: write them without a constraint");
                    ok = false;
                }
                (ast::Combine::Remove, None) => {
                    let Some((names, group, constraint)) = groups.last_mut() else {
                        self.error(p.span, "`-Pa` needs a group before it to remove from");
                        ok = false;
                        continue;
                    };
                    for (v, n) in vars.iter().zip(&p.variables) {
                        let Some(i) = group.iter().position(|s| s == v) else {
                            self.error(
                                n.span,
                                format!(
                                    "{} is not in the group before `-Pa`, so it cannot be removed",
                                    v.symbol()
                                ),
                            );
                            ok = false;
                            continue;
                        };
                        group.remove(i);
                        names.remove(i);
                        if let Some(PrimitiveConstraint::Goal(t)) = constraint {
                            t.remove(i);
                        }
                    }
                }
            }
        }
        if !ok {
            return None;
        }
        let mut primitives: Vec<Primitive> = Vec::new();
        let mut names: Vec<Name> = Vec::new();
        let mut vars_seen: Vec<Variable> = Vec::new();
        for (group_names, vars, constraint) in groups {
            for (v, n) in vars.iter().zip(&group_names) {
                if vars_seen.contains(v) {
                    self.error(n.span, format!("{} is already driven in this segment", v.symbol()));
                    ok = false;
                }
            }
            vars_seen.extend(&vars);
            names.extend(group_names);
            if let (Some(constraint), false) = (constraint, vars.is_empty()) {
                primitives.push(Primitive { variables: vars, constraint });
            }
        }
        if !ok {
            return None;
        }
        let space = match self.segment_space(&names, &vars_seen)? {
            Some(s) => s,
            None => {
                self.error(
                    segment.span,
                    "a segment covers a whole space: Pw, Ow, θsw (CPSA) or Os, θe, Ow (HAT)",
                );
                return None;
            }
        };
        let missing: Vec<Variable> =
            space.variables().into_iter().filter(|v| !vars_seen.contains(v)).collect();
        if !missing.is_empty() {
            self.error(
                segment.span,
                format!(
                    "this {} segment does not drive {}: a segment covers {} exactly once",
                    space.name(),
                    list(&missing),
                    list(&space.variables())
                ),
            );
            return None;
        }
        let duration = match &segment.duration {
            Some(q) => Some(self.duration(q, "a segment's duration")?),
            None => None,
        };
        Some(Segment { space, duration, primitives })
    }
}
