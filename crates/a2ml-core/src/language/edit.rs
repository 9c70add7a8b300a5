//! Tasks made from a task: the text with an action's goal values replaced, printed in canonical
//! form (comments kept), so that a sweep over targets needs no string templating and every
//! generated task is a file's text that validates, pickles and is attached to outputs as any.
//!
//! Entry point: [`with_goal`]. Values are in the task's frame (as its file writes them) and SI
//! units: positions in m, angles in rad.

use std::path::Path;

use super::ast::{self, ActionBody, Item, Name, Quantity, Span};
use super::{Diagnostics, Target, Variable, format, parse_ast};
use crate::math::UnitQuaternion;

/// Why a task's goal cannot be replaced.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EditError {
    /// The source does not parse.
    #[error("{0}")]
    Syntax(Diagnostics),
    /// No action of that name.
    #[error("the task has no action `{action}` (actions: {known})")]
    NoAction {
        /// The name asked for.
        action: String,
        /// The task's actions, comma-separated.
        known: String,
    },
    /// The action has no `goal` naming the variable (or is written as explicit segments).
    #[error("action `{action}` has no goal on {variable}: only a goal it states can be changed")]
    NoGoal {
        /// The action.
        action: String,
        /// The variable's symbol.
        variable: &'static str,
    },
}

/// `source` with the goal values of `action` replaced by `goals`, each variable's value where
/// the action's `goal` states it (a secondary goal's too), as canonical text.
///
/// # Errors
/// [`EditError`]: the text does not parse, no such action, or it states no goal on a variable.
pub fn with_goal(
    source: &str,
    path: Option<&Path>,
    action: &str,
    goals: &[(Variable, Target)],
) -> Result<String, EditError> {
    let mut file = parse_ast(source, path).map_err(EditError::Syntax)?;
    let actions: Vec<&mut ast::Action> = file
        .items
        .iter_mut()
        .filter_map(|item| match item {
            Item::Task(task) => Some(task.actions.iter_mut()),
            _ => None,
        })
        .flatten()
        .collect();
    let known = actions.iter().map(|a| a.name.text.clone()).collect::<Vec<_>>().join(", ");
    let Some(found) = actions.into_iter().find(|a| a.name.text == action) else {
        return Err(EditError::NoAction { action: action.to_owned(), known });
    };
    for (variable, target) in goals {
        let no_goal =
            || EditError::NoGoal { action: action.to_owned(), variable: variable.symbol() };
        let ActionBody::Constraints { goals: statements, .. } = &mut found.body else {
            return Err(no_goal());
        };
        let slots: Vec<&mut ast::Value> = statements
            .iter_mut()
            .flat_map(|g| g.terms.iter_mut())
            .flat_map(|term| {
                term.variables.iter().zip(term.values.iter_mut()).filter_map(|(name, value)| {
                    (Variable::from_name(&name.text) == Some(*variable)).then_some(value)
                })
            })
            .collect();
        if slots.is_empty() {
            return Err(no_goal());
        }
        for slot in slots {
            *slot = value(target, slot.span());
        }
    }
    Ok(format(&file))
}

/// A target as written text would give it: m, rad, or a unit quaternion.
fn value(target: &Target, span: Span) -> ast::Value {
    let unit = |text: &str| Some(Name { text: text.to_owned(), span });
    match target {
        Target::Position(p) => {
            ast::Value::Vector(ast::Vector { values: vec![p.x, p.y, p.z], unit: unit("m"), span })
        }
        Target::Rotation(r) => {
            let q = UnitQuaternion::from_rotation_matrix(r);
            ast::Value::Quat { wxyz: [q.w, q.i, q.j, q.k], span }
        }
        Target::Angle(a) => ast::Value::Quantity(Quantity { value: *a, unit: unit("rad"), span }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Rotation3, Vector3};

    /// Two actions on COMAN, the first with a CPSA goal and a HAT one after it.
    fn source() -> String {
        format!(
            "robot \"{}/../../robots/coman_right_arm.urdf\"\nstart [0, -20, 0, -60, 0, 10, 0] deg\n\
             # The target.\n\
             task t {{ action reach {{ goal Pw Ow = ([0.27, -0.1, 0.05] m, rpy(0, 0, 0) deg) \
             > θe = 90 deg }} action back {{ goal Pw = [0.2, -0.1, 0] }} }}\n",
            env!("CARGO_MANIFEST_DIR")
        )
    }

    #[test]
    fn goals_are_replaced_and_the_rest_kept() {
        let rotation = Rotation3::from_euler_angles(0.1, -0.2, 0.3);
        let goals = [
            (Variable::Pw, Target::Position(Vector3::new(0.25, -0.125, 0.0625))),
            (Variable::Ow, Target::Rotation(rotation)),
            (Variable::Elbow, Target::Angle(1.5)),
        ];
        let text = with_goal(&source(), None, "reach", &goals).expect("edited");
        assert!(text.contains("# The target."), "comments kept:\n{text}");
        let task = crate::language::parse(&text, None).expect("the edit validates");
        let original = crate::language::parse(&source(), None).expect("valid");
        let goal = |task: &crate::language::Task, index: usize| match &task.actions[index].body {
            crate::language::ActionBody::Constraints { goal: Some(g), .. } => g.clone(),
            _ => panic!("a goal"),
        };
        let edited = goal(&task, 0);
        assert_eq!(edited.primary.targets[0].1, goals[0].1);
        let Target::Rotation(r) = &edited.primary.targets[1].1 else { panic!("a rotation") };
        assert!((r.matrix() - rotation.matrix()).amax() < 1e-12);
        let secondary = edited.secondary.expect("the secondary goal stays secondary");
        assert_eq!(secondary.targets[0], (Variable::Elbow, Target::Angle(1.5)));
        assert_eq!(goal(&task, 1), goal(&original, 1), "the other action is untouched");
    }

    #[test]
    fn a_missing_action_or_goal_is_named() {
        let pw = [(Variable::Pw, Target::Position(Vector3::zeros()))];
        let err = with_goal(&source(), None, "fetch", &pw).expect_err("no such action");
        assert_eq!(err.to_string(), "the task has no action `fetch` (actions: reach, back)");
        let elbow = [(Variable::Elbow, Target::Angle(1.0))];
        let err = with_goal(&source(), None, "back", &elbow).expect_err("no goal");
        assert!(matches!(err, EditError::NoGoal { .. }), "{err}");
    }
}
