//! State variables by name, and the one space a term or segment's variables
//! belong to.

use super::Checker;
use crate::language::ast::Name;
use crate::language::task::*;
use crate::names::did_you_mean;

fn variable_names() -> impl Iterator<Item = &'static str> {
    Variable::ALL.into_iter().flat_map(|v| [v.symbol(), v.ascii()])
}

pub(super) fn list(vars: &[Variable]) -> String {
    vars.iter().map(|v| v.symbol()).collect::<Vec<_>>().join(", ")
}

impl Checker<'_> {
    pub(super) fn variable(&mut self, name: &Name) -> Option<Variable> {
        let v = Variable::from_name(&name.text);
        if v.is_none() {
            let help = did_you_mean(&name.text, variable_names())
                .map(|s| format!("did you mean `{s}`?"))
                .or_else(|| Some("the state variables are Pw, Ow, θsw (sw), Os and θe (e)".into()));
            self.error_with_help(
                name.span,
                format!("unknown state variable `{}`", name.text),
                help,
            );
        }
        v
    }

    /// Variables of one term, distinct and of one space.
    pub(super) fn variables(&mut self, names: &[Name]) -> Option<(Vec<Variable>, Option<Space>)> {
        let mut vars = Vec::new();
        let mut ok = true;
        for n in names {
            match self.variable(n) {
                Some(v) if vars.contains(&v) => {
                    self.error(n.span, format!("{} is named twice", v.symbol()));
                    ok = false;
                }
                Some(v) => vars.push(v),
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        let space = self.space_of(names, &vars)?;
        Some((vars, space))
    }

    /// The one space of `vars` (None when only Ow); an error if mixed.
    pub(super) fn space_of(&mut self, names: &[Name], vars: &[Variable]) -> Option<Option<Space>> {
        let mut space: Option<(Space, Variable)> = None;
        for (n, v) in names.iter().zip(vars) {
            if let Some(s) = v.space() {
                match space {
                    Some((t, first)) if t != s => {
                        self.error(
                            n.span,
                            format!(
                                "{} belongs to {} space, but {} belongs to {} space; \
                                 one constraint covers one space",
                                v.symbol(),
                                s.name(),
                                first.symbol(),
                                t.name()
                            ),
                        );
                        return None;
                    }
                    None => space = Some((s, *v)),
                    _ => {}
                }
            }
        }
        Some(space.map(|(s, _)| s))
    }

    /// A segment's space, from its first variable that fixes one; a variable
    /// of the other space is named against the segment's variables.
    pub(super) fn segment_space(
        &mut self,
        names: &[Name],
        vars: &[Variable],
    ) -> Option<Option<Space>> {
        let mut space: Option<Space> = None;
        for (n, v) in names.iter().zip(vars) {
            match (space, v.space()) {
                (None, s) => space = s,
                (Some(t), Some(s)) if s != t => {
                    self.error(
                        n.span,
                        format!(
                            "{} belongs to {} space, but this segment is in {} space ({})",
                            v.symbol(),
                            s.name(),
                            t.name(),
                            list(&t.variables())
                        ),
                    );
                    return None;
                }
                _ => {}
            }
        }
        Some(space)
    }
}
