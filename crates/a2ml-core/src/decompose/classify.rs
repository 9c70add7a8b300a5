//! The seven action types (paper fig. 3, docs/design.md §4): a table lookup on
//! an action's goal constraint GC and path constraint PC.
//!
//! Two cases the table leaves open are settled here:
//!
//! - **Ow alone.** Ow is in both spaces, so a goal or path on Ow alone takes
//!   the space of the constraint it meets: the path's or goal's space beside
//!   one goal, the space the other goal lacks in `G1 ≻ G2`, G1's space for a
//!   path beside two goals, and CPSA when nothing else decides. Alone it
//!   could be either: holding (Pw, θsw) or (Os, θe) keeps the same four
//!   joints still, so CPSA is the convention.
//! - **One goal and a path in the same space** on different variables do not
//!   conflict (the space's variables are independent): the goal is reached
//!   and the path kept in one segment, the rest held, whatever the hardness.
//!   This is reported as type **II** (one goal, reached exactly, one segment,
//!   no optimiser), with [`Classification::path_in_goal_space`] true.
//! - **A variable in a goal and in the path.** A soft path gives way to the
//!   goal: type V (or VII), as the paper's A6 (Ow in `Pw Ow` and in
//!   `Os θe Ow`). A hard path cannot both keep the variable and send it to
//!   the goal: out of the table, as the validator says for task files.
//!
//! With two goals the path always shares a space with one of them; Opt1
//! makes a whole configuration of them, so VI and VII apply either way.
//! A path without a goal is type I whether hard or soft: there is nothing
//! for it to give way to.

use std::fmt;

use super::DecomposeError;
use crate::language::{
    Action, ActionBody, Goal, GoalConstraint, PathConstraint, PathFeature, Primitive,
    PrimitiveConstraint, Space, Variable,
};
use crate::spelling::spelled;

/// The paper's action types (fig. 3).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
// The numeral in lower case (`iv`): snake_case would split it at every capital (`i_v`).
#[serde(rename_all = "lowercase")]
pub enum ActionType {
    /// One path, no goal.
    I,
    /// One goal, no path.
    II,
    /// Two prioritised goals `G1 ≻ G2` in different spaces.
    III,
    /// One goal and a hard path in another space.
    IV,
    /// One goal and a soft path.
    V,
    /// Two prioritised goals and a hard path.
    VI,
    /// Two prioritised goals and a soft path.
    VII,
}

impl ActionType {
    /// Every type, in order.
    pub const ALL: [ActionType; 7] = [
        ActionType::I,
        ActionType::II,
        ActionType::III,
        ActionType::IV,
        ActionType::V,
        ActionType::VI,
        ActionType::VII,
    ];

    /// 1 to 7.
    pub fn number(self) -> u8 {
        self as u8 + 1
    }

    /// The roman numeral, as the paper writes it in prose ("type IV"); the value is spelled
    /// [`Self::as_str`] (`iv`).
    pub fn numeral(self) -> &'static str {
        ["I", "II", "III", "IV", "V", "VI", "VII"][self as usize]
    }

    /// What characterises the type (GC and PC).
    pub fn description(self) -> &'static str {
        match self {
            ActionType::I => "one path constraint, no goal",
            ActionType::II => "one goal constraint, no path",
            ActionType::III => "two prioritised goals G1 ≻ G2 in different spaces",
            ActionType::IV => "one goal and a hard path in another space",
            ActionType::V => "one goal and a soft path",
            ActionType::VI => "two prioritised goals G1 ≻ G2 and a hard path",
            ActionType::VII => "two prioritised goals G1 ≻ G2 and a soft path",
        }
    }
}

spelled!(ActionType, "action type", ActionType::ALL);

/// An action's type with the space each of its constraints is placed in
/// (Ow-only constraints placed as the module documents).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Classification {
    /// The row of the table.
    pub action_type: ActionType,
    /// Space of G, or of G1 when two goals are prioritised.
    pub goal_space: Option<Space>,
    /// Space of G2.
    pub secondary_goal_space: Option<Space>,
    /// Space of the path.
    pub path_space: Option<Space>,
}

impl Classification {
    /// Type II with a path beside its goal, in the goal's space: no conflict,
    /// the path is kept in parallel with the goal and the rest held.
    pub fn path_in_goal_space(&self) -> bool {
        self.action_type == ActionType::II && self.path_space.is_some()
    }
}

impl fmt::Display for Classification {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.path_in_goal_space() {
            write!(f, "type II: one goal, with a path in the goal's space (no conflict: rest held)")
        } else {
            write!(f, "type {}: {}", self.action_type.numeral(), self.action_type.description())
        }
    }
}

/// An action's constraints that fit no row of the table.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub enum Combination {
    /// Neither a goal nor a path.
    Nothing,
    /// A goal or a path on no variable.
    NoVariables {
        /// "goal" or "path".
        constraint: &'static str,
    },
    /// `G1 ≻ G2` with both goals in one space.
    GoalsInOneSpace {
        /// That space.
        space: Space,
    },
    /// `G1 ≻ G2` with a variable in both.
    VariableInBothGoals {
        /// The variable.
        variable: Variable,
    },
    /// A variable in a goal and in a hard path.
    VariableInGoalAndHardPath {
        /// The variable.
        variable: Variable,
    },
}

impl fmt::Display for Combination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Combination::Nothing => write!(f, "it has neither a goal nor a path"),
            Combination::NoVariables { constraint } => {
                write!(f, "its {constraint} constrains no variable")
            }
            Combination::GoalsInOneSpace { space } => write!(
                f,
                "its two prioritised goals are both in {} space (one goal can hold them both)",
                space.name()
            ),
            Combination::VariableInBothGoals { variable } => {
                write!(f, "{} is in both of its prioritised goals", variable.symbol())
            }
            Combination::VariableInGoalAndHardPath { variable } => write!(
                f,
                "{} is in a goal and in a hard path (a path on it must be soft to give way)",
                variable.symbol()
            ),
        }
    }
}

/// The type of an action from its goal and path constraints; `None` for an
/// explicit action, whose segments are given.
///
/// # Errors
/// [`DecomposeError::OutOfTable`] for constraints outside the table (see
/// [`Combination`]); [`DecomposeError::MissingPathSize`] for a path without
/// size where no optimiser chooses it (types I and II).
pub fn classify(action: &Action) -> Result<Option<Classification>, DecomposeError> {
    let ActionBody::Constraints { goal, path, .. } = &action.body else {
        return Ok(None);
    };
    let out_of_table =
        |combination| DecomposeError::OutOfTable { action: action.name.clone(), combination };
    let goals: Vec<&Goal> =
        goal.iter().flat_map(|g| std::iter::once(&g.primary).chain(&g.secondary)).collect();
    if goals.iter().any(|g| g.targets.is_empty()) {
        return Err(out_of_table(Combination::NoVariables { constraint: "goal" }));
    }
    if let Some(p) = path {
        if p.items.iter().all(|i| i.variables.is_empty()) {
            return Err(out_of_table(Combination::NoVariables { constraint: "path" }));
        }
        let in_goal = |v: &Variable| goals.iter().any(|g| g.targets.iter().any(|(w, _)| w == v));
        let shared = p.items.iter().flat_map(|i| &i.variables).find(|v| in_goal(v));
        if let (true, Some(&variable)) = (p.hard, shared) {
            return Err(out_of_table(Combination::VariableInGoalAndHardPath { variable }));
        }
    }
    let classification = match (goal, path) {
        (None, None) => return Err(out_of_table(Combination::Nothing)),
        (None, Some(p)) => Classification {
            action_type: ActionType::I,
            goal_space: None,
            secondary_goal_space: None,
            path_space: Some(p.space.unwrap_or(Space::Cpsa)),
        },
        (Some(GoalConstraint { primary, secondary: None }), path) => {
            one_goal(primary, path.as_ref())
        }
        (Some(GoalConstraint { primary, secondary: Some(secondary) }), path) => {
            let (first, second) = prioritised_spaces(primary, secondary).map_err(out_of_table)?;
            let action_type = match path {
                None => ActionType::III,
                Some(p) if p.hard => ActionType::VI,
                Some(_) => ActionType::VII,
            };
            Classification {
                action_type,
                goal_space: Some(first),
                secondary_goal_space: Some(second),
                path_space: path.as_ref().map(|p| p.space.unwrap_or(first)),
            }
        }
    };
    if let (Some(p), ActionType::I | ActionType::II) = (path, classification.action_type) {
        check_sizes(action, p)?;
    }
    Ok(Some(classification))
}

/// Types II, IV and V.
fn one_goal(goal: &Goal, path: Option<&PathConstraint>) -> Classification {
    let Some(path) = path else {
        return Classification {
            action_type: ActionType::II,
            goal_space: Some(goal.space.unwrap_or(Space::Cpsa)),
            secondary_goal_space: None,
            path_space: None,
        };
    };
    let (goal_space, path_space) = match (goal.space, path.space) {
        (Some(g), Some(p)) => (g, p),
        (Some(g), None) => (g, g),
        (None, Some(p)) => (p, p),
        (None, None) => (Space::Cpsa, Space::Cpsa),
    };
    // Only a soft path shares a variable with the goal (checked above).
    let shared =
        goal.targets.iter().any(|(v, _)| path.items.iter().any(|item| item.variables.contains(v)));
    let action_type = if goal_space == path_space && !shared {
        ActionType::II
    } else if path.hard {
        ActionType::IV
    } else {
        ActionType::V
    };
    Classification {
        action_type,
        goal_space: Some(goal_space),
        secondary_goal_space: None,
        path_space: Some(path_space),
    }
}

fn other(space: Space) -> Space {
    match space {
        Space::Cpsa => Space::Hat,
        Space::Hat => Space::Cpsa,
    }
}

/// The spaces of G1 and G2; an Ow-only goal takes the space the other lacks.
fn prioritised_spaces(first: &Goal, second: &Goal) -> Result<(Space, Space), Combination> {
    if let Some((variable, _)) =
        second.targets.iter().find(|(v, _)| first.targets.iter().any(|(w, _)| w == v))
    {
        return Err(Combination::VariableInBothGoals { variable: *variable });
    }
    match (first.space, second.space) {
        (Some(a), Some(b)) if a == b => Err(Combination::GoalsInOneSpace { space: a }),
        (Some(a), Some(b)) => Ok((a, b)),
        (Some(a), None) => Ok((a, other(a))),
        (None, Some(b)) => Ok((other(b), b)),
        // Two Ow-only goals share Ow, caught above.
        (None, None) => Err(Combination::VariableInBothGoals { variable: Variable::Ow }),
    }
}

/// Without a conflicting goal nothing chooses a path's size: it must be given.
fn check_sizes(action: &Action, path: &PathConstraint) -> Result<(), DecomposeError> {
    for item in &path.items {
        let line = match item.feature {
            PathFeature::Line { length: None, .. } => true,
            PathFeature::About { angle: None, .. } => false,
            _ => continue,
        };
        return Err(DecomposeError::MissingPathSize {
            action: action.name.clone(),
            variable: item.variables.first().copied().unwrap_or(Variable::Pw),
            line,
        });
    }
    Ok(())
}

/// A segment's pattern (paper §5.3): path and hold primitives only,
/// goal primitives only, or both.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SegmentPattern {
    /// 1: `MP^p +Pa MP^-p`, every primitive a path (hold is a path, P = void).
    Path = 1,
    /// 2: `MP^g +Pa MP^-g`, every primitive a goal.
    Goal = 2,
    /// 3: `MP^p +Pa MP^-g`, paths and goals.
    Mixed = 3,
}

spelled!(
    SegmentPattern,
    "segment pattern",
    [SegmentPattern::Path, SegmentPattern::Goal, SegmentPattern::Mixed]
);

impl SegmentPattern {
    /// 1, 2 or 3.
    pub fn number(self) -> u8 {
        self as u8
    }
}

/// The pattern of a segment's primitives; `None` for no primitives.
pub fn segment_pattern(primitives: &[Primitive]) -> Option<SegmentPattern> {
    let is_goal = |p: &Primitive| matches!(p.constraint, PrimitiveConstraint::Goal(_));
    let goals = primitives.iter().filter(|p| is_goal(p)).count();
    match (goals, primitives.len() - goals) {
        (0, 0) => None,
        (0, _) => Some(SegmentPattern::Path),
        (_, 0) => Some(SegmentPattern::Goal),
        _ => Some(SegmentPattern::Mixed),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::language::{ActionBody, PathItem, Target, ast::Span};
    use crate::math::{Rotation3, Vector3};

    fn goal(vars: &[Variable]) -> Goal {
        let targets = vars
            .iter()
            .map(|v| {
                let t = match v {
                    Variable::Pw => Target::Position(Vector3::new(0.3, -0.1, 0.0)),
                    Variable::Ow | Variable::Os => Target::Rotation(Rotation3::identity()),
                    Variable::Swivel | Variable::Elbow => Target::Angle(1.0),
                };
                (*v, t)
            })
            .collect();
        Goal { targets, space: vars.iter().find_map(|v| v.space()), span: Span::default() }
    }

    fn path(items: &[(&[Variable], PathFeature)], hard: bool) -> PathConstraint {
        PathConstraint {
            items: items
                .iter()
                .map(|(vars, feature)| PathItem { variables: vars.to_vec(), feature: *feature })
                .collect(),
            space: items.iter().flat_map(|(vs, _)| vs.iter()).find_map(|v| v.space()),
            hard,
            span: Span::default(),
        }
    }

    fn action(goals: &[&[Variable]], path: Option<PathConstraint>) -> Action {
        let mut goals = goals.iter().map(|vs| goal(vs));
        let goal = goals.next().map(|primary| GoalConstraint { primary, secondary: goals.next() });
        Action {
            name: "act".into(),
            description: None,
            pre: Vec::new(),
            add: Vec::new(),
            del: Vec::new(),
            contact: Vec::new(),
            solver: None,
            segment_solvers: Vec::new(),
            body: ActionBody::Constraints { goal, path, duration: None },
            span: Span::default(),
        }
    }

    fn class(a: &Action) -> Classification {
        classify(a).expect("classifies").expect("constraints")
    }

    use PathFeature::Hold;
    use Variable::{Elbow, Os, Ow, Pw, Swivel};

    #[test]
    fn numbers_and_numerals() {
        let numbers: Vec<u8> = ActionType::ALL.iter().map(|t| t.number()).collect();
        assert_eq!(numbers, [1, 2, 3, 4, 5, 6, 7]);
        // The value is spelled in lower case; prose writes the paper's numeral.
        assert_eq!(ActionType::VII.to_string(), "vii");
        assert_eq!(ActionType::VII.numeral(), "VII");
    }

    #[test]
    fn an_ow_only_goal_alone_is_placed_in_cpsa() {
        let c = class(&action(&[&[Ow]], None));
        assert_eq!((c.action_type, c.goal_space), (ActionType::II, Some(Space::Cpsa)));
    }

    #[test]
    fn an_ow_only_path_takes_the_goal_space() {
        let c = class(&action(&[&[Pw]], Some(path(&[(&[Ow], Hold)], true))));
        assert_eq!(c.action_type, ActionType::II);
        assert!(c.path_in_goal_space());
        assert_eq!(c.path_space, Some(Space::Cpsa));
        let c = class(&action(&[&[Os, Elbow]], Some(path(&[(&[Ow], Hold)], false))));
        assert_eq!((c.action_type, c.path_space), (ActionType::II, Some(Space::Hat)));
    }

    #[test]
    fn an_ow_only_goal_takes_the_path_space() {
        let p = path(&[(&[Os], Hold), (&[Elbow], Hold)], true);
        let c = class(&action(&[&[Ow]], Some(p)));
        assert_eq!((c.action_type, c.goal_space), (ActionType::II, Some(Space::Hat)));
    }

    #[test]
    fn ow_in_goal_and_soft_path_gives_way() {
        let c = class(&action(&[&[Ow]], Some(path(&[(&[Ow], Hold)], false))));
        assert_eq!((c.action_type, c.goal_space), (ActionType::V, Some(Space::Cpsa)));
        let c = class(&action(&[&[Pw, Ow]], Some(path(&[(&[Ow], Hold)], false))));
        assert_eq!(c.action_type, ActionType::V);
        // The paper's A6: Ow in a CPSA goal and a soft HAT path.
        let p = path(&[(&[Os], Hold), (&[Elbow], Hold), (&[Ow], Hold)], false);
        let c = class(&action(&[&[Pw, Ow]], Some(p)));
        assert_eq!(c.action_type, ActionType::V);
        assert_eq!((c.goal_space, c.path_space), (Some(Space::Cpsa), Some(Space::Hat)));
    }

    #[test]
    fn a_shared_variable_in_one_space_conflicts() {
        let line = PathFeature::Line { direction: Vector3::y(), length: None };
        let c = class(&action(&[&[Pw]], Some(path(&[(&[Pw], line)], false))));
        assert_eq!(c.action_type, ActionType::V);
    }

    #[test]
    fn an_ow_only_goal_in_a_priority_takes_the_other_space() {
        let c = class(&action(&[&[Ow], &[Pw]], None));
        assert_eq!(c.action_type, ActionType::III);
        assert_eq!((c.goal_space, c.secondary_goal_space), (Some(Space::Hat), Some(Space::Cpsa)));
        let c = class(&action(&[&[Os, Elbow], &[Ow]], Some(path(&[(&[Ow], Hold)], false))));
        assert_eq!(c.action_type, ActionType::VII);
        assert_eq!(c.secondary_goal_space, Some(Space::Cpsa));
        assert_eq!(c.path_space, Some(Space::Hat));
    }

    #[test]
    fn out_of_table() {
        let err = |a: &Action| match classify(a) {
            Err(DecomposeError::OutOfTable { combination, .. }) => combination,
            other => panic!("expected out of table, got {other:?}"),
        };
        assert_eq!(err(&action(&[], None)), Combination::Nothing);
        assert_eq!(
            err(&action(&[&[Pw], &[Swivel]], None)),
            Combination::GoalsInOneSpace { space: Space::Cpsa }
        );
        assert_eq!(
            err(&action(&[&[Pw, Ow], &[Os, Ow]], None)),
            Combination::VariableInBothGoals { variable: Ow }
        );
        assert_eq!(err(&action(&[&[]], None)), Combination::NoVariables { constraint: "goal" });
        assert_eq!(
            err(&action(&[&[Pw, Ow]], Some(path(&[(&[Ow], Hold)], true)))),
            Combination::VariableInGoalAndHardPath { variable: Ow }
        );
        assert_eq!(
            err(&action(&[&[Pw], &[Elbow]], Some(path(&[(&[Os], Hold), (&[Elbow], Hold)], true)))),
            Combination::VariableInGoalAndHardPath { variable: Elbow }
        );
        let message = classify(&action(&[], None)).expect_err("empty").to_string();
        assert_eq!(
            message,
            "action `act`: it has neither a goal nor a path, which fits none of the seven action \
             types"
        );
    }

    #[test]
    fn a_path_without_size_needs_a_conflict() {
        let about =
            PathFeature::About { axis: crate::language::Axis::Base(Vector3::z()), angle: None };
        let a = action(&[], Some(path(&[(&[Os], about)], true)));
        let err = classify(&a).expect_err("no size");
        assert_eq!(
            err,
            DecomposeError::MissingPathSize { action: "act".into(), variable: Os, line: false }
        );
        assert!(err.to_string().contains("the path on Os has no size"), "{err}");
        // Beside a goal in the other space, Opt2 chooses it.
        let a = action(&[&[Pw, Ow]], Some(path(&[(&[Os], about)], true)));
        assert_eq!(class(&a).action_type, ActionType::IV);
    }

    #[test]
    fn patterns() {
        let hold = |v| Primitive { variables: vec![v], constraint: PrimitiveConstraint::Hold };
        let goal = |v| Primitive {
            variables: vec![v],
            constraint: PrimitiveConstraint::Goal(vec![Target::Angle(0.5)]),
        };
        let by = |v| Primitive {
            variables: vec![v],
            constraint: PrimitiveConstraint::Path(PathFeature::By { angle: 0.5 }),
        };
        assert_eq!(segment_pattern(&[by(Swivel), hold(Pw), hold(Ow)]), Some(SegmentPattern::Path));
        assert_eq!(segment_pattern(&[goal(Swivel), goal(Pw)]), Some(SegmentPattern::Goal));
        assert_eq!(segment_pattern(&[goal(Swivel), hold(Pw)]), Some(SegmentPattern::Mixed));
        assert_eq!(segment_pattern(&[]), None);
        assert_eq!(SegmentPattern::Mixed.number(), 3);
    }
}
