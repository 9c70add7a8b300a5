//! Opt1 and Opt2 (paper eq. 5, 6, 13, 14; docs/design.md §4): the small
//! optimisations that reconcile constraints given in different spaces.
//!
//! Both work on the variables of one space. The fixed ones come from a goal
//! (Opt1) or from a path and its size (Opt2); the free ones are searched by
//! Levenberg-Marquardt with multistart, every candidate checked through the
//! CPSA <-> HAT mapping and IK within the joint limits, the end state kept
//! clear of the scene by [`OptOptions::clearance`] plus, where an end with that room
//! exists, what the goal tolerance lets the arm move ([`goal_margin`]), and off the limits
//! by [`OptOptions::limit_margin`]. A one-dimensional search over θsw first
//! samples the closed-form feasible swivel intervals.

use crate::collision::{CollisionModel, CollisionScene, min_distance};
use crate::kinematics::{
    CpsaState, HatState, KinematicsError, arm_pose, cpsa_state, cpsa_to_hat, hat_state,
    hat_to_cpsa, ik_cpsa, ik_cpsa_nearest, swivel_intervals,
};
use crate::language::{
    Axis, BodyAxis, Measure, PathConstraint, PathFeature, Space, Target, Variable,
};
use crate::math::{
    DOF, JointVector, PI, Real, Rotation3, Vector3, rotation_about, rotation_log, wrap_angle,
};
use crate::parallel;
use crate::profile::SemiEllipse;
use crate::robot::Robot;

/// The arm's state in both spaces at once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmState {
    /// (Pw, Ow, θsw).
    pub cpsa: CpsaState,
    /// (Os, θe, Ow).
    pub hat: HatState,
}

impl ArmState {
    /// The state of the arm at configuration `q`.
    ///
    /// # Errors
    /// Where either representation is singular.
    pub fn at(robot: &Robot, q: &JointVector) -> Result<Self, KinematicsError> {
        let pose = arm_pose(robot, q);
        Ok(Self { cpsa: cpsa_state(robot, &pose)?, hat: hat_state(&pose)? })
    }

    /// The value of one variable.
    pub fn value(&self, v: Variable) -> Target {
        match v {
            Variable::Pw => Target::Position(self.cpsa.pw),
            Variable::Ow => Target::Rotation(self.cpsa.ow),
            Variable::Swivel => Target::Angle(self.cpsa.swivel),
            Variable::Os => Target::Rotation(self.hat.shoulder_frame),
            Variable::Elbow => Target::Angle(self.hat.elbow_angle),
        }
    }

    /// The state whose variables of `space` take `values` (in the order of
    /// [`Space::variables`]), the other space following by the mapping.
    pub fn from_space(robot: &Robot, space: Space, values: &[Target; 3]) -> Option<Self> {
        match (space, values) {
            (Space::Cpsa, [Target::Position(pw), Target::Rotation(ow), Target::Angle(swivel)]) => {
                let cpsa = CpsaState { pw: *pw, ow: *ow, swivel: wrap_angle(*swivel) };
                // Beyond the annulus of lu and lf an arm with offsets may still reach:
                // its HAT state is then the real chain's, from IK.
                let hat = cpsa_to_hat(robot, &cpsa).ok().or_else(|| {
                    let q = *crate::kinematics::ik_cpsa(robot, &cpsa, None).ok()?.first()?;
                    crate::kinematics::hat_state(&crate::kinematics::arm_pose(robot, &q)).ok()
                })?;
                Some(Self { hat, cpsa })
            }
            (Space::Hat, [Target::Rotation(os), Target::Angle(elbow), Target::Rotation(ow)]) => {
                if !(0.0..=PI).contains(elbow) {
                    return None;
                }
                let hat = HatState { shoulder_frame: *os, elbow_angle: *elbow, ow: *ow };
                Some(Self { cpsa: hat_to_cpsa(robot, &hat).ok()?, hat })
            }
            _ => None,
        }
    }

    /// The values of `space`'s variables, in the order of [`Space::variables`].
    pub fn space_values(&self, space: Space) -> [Target; 3] {
        space.variables().map(|v| self.value(v))
    }
}

/// How far a state is from goals, per component: metres for positions,
/// radians for rotations (as rotation vectors) and angles.
fn residuals(state: &ArmState, goals: &[(Variable, Target)], out: &mut Vec<Real>) {
    out.clear();
    for (v, target) in goals {
        match v.difference(target, &state.value(*v)) {
            Some(d) => out.extend(d.iter().take(v.dimension())),
            // The language types every target by its variable.
            None => out.push(Real::INFINITY),
        }
    }
}

/// The scalar error of a state against goals: the largest of the position
/// error (m), the geodesic rotation errors and the angle errors (rad).
pub fn goal_error(state: &ArmState, goals: &[(Variable, Target)]) -> Real {
    goals
        .iter()
        .map(|(v, target)| match v.distance(&state.value(*v), target) {
            Some(d) => d,
            None => Real::INFINITY,
        })
        .fold(0.0, Real::max)
}

/// Settings of Opt1 and Opt2.
#[derive(Debug, Clone)]
pub struct OptOptions {
    /// Starting points of the multistart (the first is the start state).
    pub starts: usize,
    /// Levenberg-Marquardt iterations per start.
    pub max_iterations: usize,
    /// Stop when the residual norm falls below this.
    pub tolerance: Real,
    /// Points along a hard path (besides its end) that must have IK within limits.
    pub path_checks: usize,
    /// Largest path size searched for a line (m) or a rotation (rad).
    pub max_path_size: Real,
    /// Samples of the feasible swivel range for a search over θsw alone.
    pub swivel_samples: usize,
    /// The safety distance (m): every arm capsule keeps it from the obstacles and from the
    /// other links at the end state, plus [`goal_margin`] where an end
    /// with that room exists.
    pub clearance: Real,
    /// The goal tolerance of the solvers that will reach the end state: position (m) and
    /// rotation or angle (rad), default 1 mm and 1°. An end chosen here is a free choice,
    /// not a user's goal, so it is kept far enough from the obstacles that every state a
    /// solver may stop in as reached still keeps the safety distance, and an RRT rooting
    /// its goal tree there has room for its conservative edge checks.
    pub goal_tolerance: (Real, Real),
    /// Smallest distance (rad) every joint keeps from its limits at the end
    /// state. An optimum often lies on a limit (a path as long as the arm
    /// allows); a solver that keeps its own margin from the limits, as the
    /// velocity QP does, could not reach it.
    pub limit_margin: Real,
}

impl Default for OptOptions {
    fn default() -> Self {
        Self {
            starts: 8,
            max_iterations: 80,
            tolerance: 1e-10,
            path_checks: 8,
            max_path_size: 1.0,
            swivel_samples: 72,
            clearance: 0.01,
            goal_tolerance: (
                Measure::Length.default_tolerance(),
                Measure::Angle.default_tolerance(),
            ),
            limit_margin: 1e-3,
        }
    }
}

/// What Opt1 or Opt2 found.
#[derive(Debug, Clone)]
pub struct OptSolution {
    /// The optimised end state.
    pub state: ArmState,
    /// A joint configuration reaching it within limits, nearest the start.
    pub q: JointVector,
    /// The size S of each path item (Opt2; empty for Opt1).
    pub sizes: Vec<Real>,
    /// [`goal_error`] of the secondary goals at the solution.
    pub residual: Real,
    /// How many candidate states were evaluated.
    pub evaluations: usize,
}

/// Why an optimisation found nothing.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OptError {
    /// The start configuration is singular in one of the spaces.
    #[error("the start configuration is singular: {0}")]
    SingularStart(KinematicsError),
    /// No candidate reachable within the joint limits was found.
    #[error("no reachable state within the joint limits satisfies the fixed constraints")]
    Infeasible,
    /// The constraints cannot be written in one space.
    #[error("{0}")]
    Unsupported(String),
}

/// The free parameters of a search: offsets of some variables of one space
/// (positions in m, rotation vectors, angles) and path sizes.
#[derive(Clone)]
struct Search<'a> {
    robot: &'a Robot,
    start_q: JointVector,
    start: ArmState,
    space: Space,
    free: Vec<Variable>,
    /// (item index, lower, upper) of each searched path size.
    sized: Vec<(usize, Real, Real)>,
    path: Option<&'a PathConstraint>,
    fixed: Vec<(Variable, Target)>,
    goals: &'a [(Variable, Target)],
    options: &'a OptOptions,
    scene: Option<&'a CollisionScene>,
    /// The scene's collision model, for the motion bound of [`Search::clear`].
    model: Option<&'a CollisionModel>,
    /// The last configuration whose clearance was measured, and that clearance (m).
    measured: Option<(JointVector, Real)>,
    /// The distance (m) the end state keeps: the safety distance, with [`goal_margin`] where
    /// an end with that room exists.
    kept: Real,
    evaluations: usize,
    /// Whether each evaluation checks the points along a hard path, or only the end
    /// (the first pass; its winner is checked afterwards).
    check_path: bool,
}

/// A body axis at the start state, or a fixed one.
fn axis_vector(axis: &Axis, start: &ArmState) -> Vector3 {
    match axis {
        Axis::Base(v) => *v,
        Axis::Body(body, sign) => {
            let (frame, column) = match body {
                BodyAxis::R => (start.hat.shoulder_frame, 0),
                BodyAxis::L => (start.hat.shoulder_frame, 1),
                BodyAxis::F => (start.cpsa.ow, 0),
                BodyAxis::P => (start.cpsa.ow, 1),
            };
            frame.matrix().column(column) * *sign
        }
    }
}

/// The value of `v`, starting at `start`, after a path feature of size `s`.
pub fn along_path(v: Variable, feature: &PathFeature, s: Real, start: &ArmState) -> Target {
    let value = start.value(v);
    match (feature, value) {
        (PathFeature::Line { direction, .. }, Target::Position(p)) => {
            Target::Position(p + direction * s)
        }
        (PathFeature::About { axis, .. }, Target::Position(p)) => {
            Target::Position(rotation_about(&axis_vector(axis, start), s) * p)
        }
        (PathFeature::About { axis, .. }, Target::Rotation(r)) => Target::Rotation(
            Rotation3::from_matrix_unchecked(rotation_about(&axis_vector(axis, start), s)) * r,
        ),
        (PathFeature::By { .. }, Target::Angle(a)) => Target::Angle(a + s),
        // s is the eccentric angle, π at the arc's end.
        (PathFeature::Arc { through, to: Some(to) }, Target::Position(p)) => {
            Target::Position(SemiEllipse::through(p, *to, *through).map_or(*to, |e| e.at(s)))
        }
        _ => value,
    }
}

impl Search<'_> {
    fn parameters(&self) -> usize {
        self.free.iter().map(|v| v.dimension()).sum::<usize>() + self.sized.len()
    }

    /// The state of the search's space at fraction `f` of the way from the
    /// start, for parameters `x`.
    fn values(&self, x: &[Real], fraction: Real) -> [Target; 3] {
        let mut values = self.start.space_values(self.space);
        let vars = self.space.variables();
        let mut k = 0;
        for v in &self.free {
            let i = vars.iter().position(|w| w == v).unwrap_or(0);
            values[i] = match values[i] {
                Target::Position(p) => {
                    Target::Position(p + Vector3::new(x[k], x[k + 1], x[k + 2]) * fraction)
                }
                Target::Rotation(r) => {
                    let delta = Vector3::new(x[k], x[k + 1], x[k + 2]) * fraction;
                    Target::Rotation(Rotation3::new(delta) * r)
                }
                Target::Angle(a) => Target::Angle(a + x[k] * fraction),
            };
            k += v.dimension();
        }
        for (v, t) in &self.fixed {
            if let Some(i) = vars.iter().position(|w| w == v) {
                values[i] = interpolate(&values[i], t, fraction, *v);
            }
        }
        if let Some(path) = self.path {
            let mut sizes = self.sizes(x).into_iter();
            for item in &path.items {
                let s = sizes.next().unwrap_or(0.0) * fraction;
                for v in &item.variables {
                    if let Some(i) = vars.iter().position(|w| w == v) {
                        values[i] = along_path(*v, &item.feature, s, &self.start);
                    }
                }
            }
        }
        values
    }

    /// The size S of every path item for parameters `x`.
    fn sizes(&self, x: &[Real]) -> Vec<Real> {
        let Some(path) = self.path else { return Vec::new() };
        let offset = self.free.iter().map(|v| v.dimension()).sum::<usize>();
        path.items
            .iter()
            .enumerate()
            .map(|(i, item)| match (&item.feature, self.sized.iter().position(|(j, ..)| *j == i)) {
                (_, Some(k)) => {
                    let (_, lo, hi) = self.sized[k];
                    x[offset + k].clamp(lo, hi)
                }
                (PathFeature::Line { length, .. }, None) => length.unwrap_or(0.0),
                (PathFeature::About { angle, .. }, None) => angle.unwrap_or(0.0),
                (PathFeature::By { angle }, None) => *angle,
                (PathFeature::Arc { .. }, None) => PI,
                (PathFeature::Hold, None) => 0.0,
            })
            .collect()
    }

    /// The reachable end state and its IK, or `None` when it or a point
    /// along the way is unreachable within the joint limits.
    fn evaluate(&mut self, x: &[Real]) -> Option<(ArmState, JointVector)> {
        self.evaluations += 1;
        let end = ArmState::from_space(self.robot, self.space, &self.values(x, 1.0))?;
        let margin = self.options.limit_margin;
        // The in-limit branch nearest the start that keeps the margin: the nearest alone
        // (ik_cpsa's first solution, without the others) unless it misses the margin.
        let nearest = ik_cpsa_nearest(self.robot, &end.cpsa, &self.start_q).ok()?;
        let q = if self.robot.within_limits(&nearest, -margin) {
            nearest
        } else {
            ik_cpsa(self.robot, &end.cpsa, Some(&self.start_q))
                .ok()?
                .into_iter()
                .find(|q| self.robot.within_limits(q, -margin))?
        };
        if !self.clear(&q) {
            return None;
        }
        if self.check_path && !self.path_reachable(x, &q) {
            return None;
        }
        Some((end, q))
    }

    /// Whether every checked point along a hard path has IK within the limits. Only a hard
    /// path must stay reachable all along; elsewhere the solver chooses the way and only the
    /// end has to be reachable.
    fn path_reachable(&self, x: &[Real], q: &JointVector) -> bool {
        let checks = if self.path.is_some_and(|p| p.hard) { self.options.path_checks } else { 0 };
        (1..=checks).all(|k| {
            let f = k as Real / (self.options.path_checks + 1) as Real;
            // Only reachability along the way: how the arm gets round an
            // obstacle between the ends is the solver's choice (RRT).
            ArmState::from_space(self.robot, self.space, &self.values(x, f))
                // Only whether a solution exists: the nearest alone answers that, as the full
                // solve would (the same success, the same error).
                .is_some_and(|mid| ik_cpsa_nearest(self.robot, &mid.cpsa, q).is_ok())
        })
    }

    /// Whether the arm at `q` keeps the clearance from the scene and itself. The search
    /// evaluates configurations close to one another (finite differences, small steps): one
    /// whose distance is bounded from below by the last one measured
    /// ([`crate::collision::clearance_bound`]) at the clearance or more is clear without
    /// measuring.
    fn clear(&mut self, q: &JointVector) -> bool {
        let Some(scene) = self.scene else { return true };
        if let (Some(model), Some((at, distance))) = (self.model, &self.measured) {
            let bound = crate::collision::clearance_bound(model, *distance, at, q);
            if bound > 0.0 && bound >= self.kept {
                return true;
            }
        }
        // The exact closed form decides unless it is within what parry may be off by of the
        // clearance kept; parry's answer is the one the plan's checks give.
        if let Some(model) = self.model {
            let exact = crate::collision::clearance(model, q);
            let slack = crate::collision::MEASURE_SLACK;
            if exact > 0.0 && (exact - slack >= self.kept || exact + slack < self.kept) {
                self.measured = Some((*q, exact));
                return exact >= self.kept;
            }
        }
        match min_distance(self.robot, &arm_pose(self.robot, q), scene) {
            Some((d, ..)) => {
                self.measured = Some((*q, d));
                d >= self.kept
            }
            None => true,
        }
    }

    fn residual(&mut self, x: &[Real], out: &mut Vec<Real>) -> Option<(ArmState, JointVector)> {
        let found = self.evaluate(x)?;
        residuals(&found.0, self.goals, out);
        Some(found)
    }

    /// Levenberg-Marquardt from `x0` with a central-difference Jacobian.
    fn minimise(
        &mut self,
        mut x: Vec<Real>,
        abandoned: &dyn Fn() -> bool,
    ) -> Option<(Vec<Real>, ArmState, JointVector, Real)> {
        let n = x.len();
        let mut r = Vec::new();
        let (mut state, mut q) = self.residual(&x, &mut r)?;
        let mut cost: Real = r.iter().map(|v| v * v).sum();
        let mut lambda = 1e-3;
        let (mut rp, mut rm) = (Vec::new(), Vec::new());
        for _ in 0..self.options.max_iterations {
            if cost.sqrt() < self.options.tolerance || n == 0 {
                break;
            }
            if abandoned() {
                return None;
            }
            let m = r.len();
            let mut jac = nalgebra::DMatrix::<Real>::zeros(m, n);
            for j in 0..n {
                let h = 1e-6;
                let (mut xp, mut xm) = (x.clone(), x.clone());
                xp[j] += h;
                xm[j] -= h;
                let plus = self.residual(&xp, &mut rp).is_some();
                let minus = self.residual(&xm, &mut rm).is_some();
                // At the edge of the reachable set, a one-sided difference
                // still shows the way back in.
                let (a, b, width) = match (plus, minus) {
                    (true, true) => (&rp, &rm, 2.0 * h),
                    (true, false) => (&rp, &r, h),
                    (false, true) => (&r, &rm, h),
                    (false, false) => continue,
                };
                for i in 0..m {
                    jac[(i, j)] = (a[i] - b[i]) / width;
                }
            }
            let rv = nalgebra::DVector::from_column_slice(&r);
            let jt = jac.transpose();
            let mut improved = false;
            while lambda < 1e8 {
                let a = &jt * &jac + nalgebra::DMatrix::<Real>::identity(n, n) * lambda;
                // Gauss-Newton on r(x + δ) ≈ r + J δ, damped.
                let Some(step) = a.cholesky().map(|c| c.solve(&(-(&jt * &rv)))) else {
                    lambda *= 10.0;
                    continue;
                };
                let trial: Vec<Real> = x.iter().zip(step.iter()).map(|(a, b)| a + b).collect();
                let mut rt = Vec::new();
                if let Some((s, qt)) = self.residual(&trial, &mut rt) {
                    let c: Real = rt.iter().map(|v| v * v).sum();
                    if c < cost {
                        (x, r, state, q, cost) = (trial, rt, s, qt, c);
                        lambda = (lambda * 0.1).max(1e-12);
                        improved = true;
                        break;
                    }
                }
                lambda *= 10.0;
            }
            if !improved {
                break;
            }
        }
        Some((x, state, q, goal_error(&state, self.goals)))
    }

    /// Deterministic starting points: the start state, then spread offsets.
    fn start_points(&self) -> Vec<Vec<Real>> {
        let n = self.parameters();
        let mut out = vec![self.initial()];
        for k in 1..self.options.starts {
            let mut x = self.initial();
            let mut i = 0;
            for v in &self.free {
                for d in 0..v.dimension() {
                    let u = halton(k, i + d) * 2.0 - 1.0;
                    // A position spreads over a hand's reach (0.15 m); a rotation or an angle
                    // over most of a half turn, shared among its rows.
                    x[i + d] = match v.measure() {
                        Measure::Length => 0.15 * u,
                        Measure::Angle => 0.9 * PI * u / (v.dimension() as Real).sqrt(),
                    };
                }
                i += v.dimension();
            }
            for (j, (_, lo, hi)) in self.sized.iter().enumerate() {
                x[i + j] = lo + halton(k, i + j) * (hi - lo);
            }
            debug_assert_eq!(x.len(), n);
            out.push(x);
        }
        out
    }

    /// The start state itself: free variables unchanged, open sizes zero
    /// (always reachable, so the first descent has somewhere to begin).
    fn initial(&self) -> Vec<Real> {
        vec![0.0; self.parameters()]
    }

    /// Starts read off the goals: a whole state of the other space, its
    /// unknowns taken from the start (θsw, if unknown, swept round), mapped
    /// into the search's space, where the free variables and path sizes are
    /// measured.
    fn goal_starts(&self) -> Vec<Vec<Real>> {
        let other = other(self.space);
        let vars = other.variables();
        let known = |v: Variable| self.goals.iter().find(|(g, _)| *g == v).map(|(_, t)| *t);
        let sweep: Vec<Option<Real>> = if other == Space::Cpsa && known(Variable::Swivel).is_none()
        {
            (0..12).map(|k| Some(-PI + k as Real * PI / 6.0)).collect()
        } else {
            vec![None]
        };
        let mut out = Vec::new();
        for swivel in sweep {
            let values = vars.map(|v| match (v, swivel) {
                (Variable::Swivel, Some(a)) => Target::Angle(a),
                _ => known(v).unwrap_or_else(|| self.start.value(v)),
            });
            let Some(candidate) = ArmState::from_space(self.robot, other, &values) else {
                continue;
            };
            out.push(self.offsets_to(&candidate));
        }
        out
    }

    /// The parameters that move the start towards `candidate`.
    fn offsets_to(&self, candidate: &ArmState) -> Vec<Real> {
        let mut x = Vec::with_capacity(self.parameters());
        for v in &self.free {
            match v.difference(&candidate.value(*v), &self.start.value(*v)) {
                Some(d) => x.extend(d.iter().take(v.dimension())),
                None => x.extend(std::iter::repeat_n(0.0, v.dimension())),
            }
        }
        let items = self.path.map(|p| p.items.as_slice()).unwrap_or(&[]);
        for (i, lo, hi) in &self.sized {
            let item = &items[*i];
            let v = item.variables[0];
            let size = match (&item.feature, self.start.value(v), candidate.value(v)) {
                (PathFeature::Line { direction, .. }, Target::Position(a), Target::Position(b)) => {
                    (b - a).dot(direction)
                }
                (PathFeature::About { axis, .. }, Target::Rotation(a), Target::Rotation(b)) => {
                    rotation_log(&(b * a.inverse())).dot(&axis_vector(axis, &self.start))
                }
                (PathFeature::About { axis, .. }, Target::Position(a), Target::Position(b)) => {
                    let w = axis_vector(axis, &self.start);
                    let (ap, bp) = (a - w * w.dot(&a), b - w * w.dot(&b));
                    w.dot(&ap.cross(&bp)).atan2(ap.dot(&bp))
                }
                _ => 0.0,
            };
            x.push(size.clamp(*lo, *hi));
        }
        x
    }

    /// [`Self::solve`] keeping `margin` beyond the safety distance, or, where no end has
    /// that room, the safety distance alone: an end at the safety distance is still better
    /// than none (a solver may then have to approach it slowly).
    fn solve_with_room(self, margin: Real) -> Result<OptSolution, OptError> {
        let mut roomy = self.clone();
        roomy.kept += margin;
        match roomy.solve() {
            Err(OptError::Infeasible) if margin > 0.0 => self.solve(),
            found => found,
        }
    }

    fn solve(mut self) -> Result<OptSolution, OptError> {
        let mut starts = self.start_points();
        starts.splice(1..1, self.goal_starts());
        if self.free == [Variable::Swivel] && self.sized.is_empty() {
            starts.extend(self.swivel_starts());
        }
        // Checking the points along a hard path costs path_checks IKs per evaluation; the
        // optimum usually keeps the path reachable anyway. So search checking the ends only,
        // take the best result whose path checks out, and search again with every evaluation
        // checked only when none does.
        let hard = self.path.is_some_and(|p| p.hard) && self.options.path_checks > 0;
        self.check_path = !hard;
        let mut found = self.multistart(&starts);
        if hard {
            found.retain(|(x, _, q, _)| self.path_reachable(x, q));
            if found.is_empty() {
                self.check_path = true;
                found = self.multistart(&starts);
            }
        }
        let (x, state, q, residual) = found.into_iter().next().ok_or(OptError::Infeasible)?;
        Ok(OptSolution { sizes: self.sizes(&x), state, q, residual, evaluations: self.evaluations })
    }

    /// The local optimum from each start, best first, stopping at the first that meets the
    /// tolerance.
    ///
    /// Each start is searched on its own, from no measured clearance, so that the starts are
    /// searched side by side on the thread pool, begun in order; a start after one that met
    /// the tolerance is not begun, or its search stops at its next iteration and is thrown
    /// away, and the results are read in order, so that the optima and the count of
    /// evaluations are those of searching one start after the other.
    fn multistart(
        &mut self,
        starts: &[Vec<Real>],
    ) -> Vec<(Vec<Real>, ArmState, JointVector, Real)> {
        let searched = parallel::in_turn_until(starts, |_, x0, abandoned| {
            let mut search = Search { measured: None, evaluations: 0, ..self.clone() };
            let local = search.minimise(x0.clone(), abandoned);
            let met = local.as_ref().is_some_and(|l| l.3 < self.options.tolerance);
            ((local, search.evaluations), met)
        });
        let mut found = Vec::new();
        // Every start up to the first that met the tolerance was searched.
        for (local, evaluations) in searched {
            self.evaluations += evaluations;
            let Some(local) = local else { continue };
            let met = local.3 < self.options.tolerance;
            found.push(local);
            if met {
                break;
            }
        }
        // Stable: among equal residuals the earlier start wins.
        found.sort_by(|a, b| a.3.total_cmp(&b.3));
        found
    }

    /// θsw offsets spread over the feasible swivel intervals at the fixed
    /// wrist pose, so that the search does not start in an infeasible gap.
    fn swivel_starts(&mut self) -> Vec<Vec<Real>> {
        let values = self.values(&[0.0], 1.0);
        let (Target::Position(pw), Target::Rotation(ow), Target::Angle(sw0)) =
            (values[0], values[1], values[2])
        else {
            return Vec::new();
        };
        let Ok(intervals) = swivel_intervals(self.robot, &pw, &ow) else { return Vec::new() };
        let total: Real = intervals.iter().map(|i| i.upper - i.lower).sum();
        let n = self.options.swivel_samples.max(1);
        let mut samples: Vec<(Real, Vec<Real>)> = Vec::new();
        let mut r = Vec::new();
        for k in 0..n {
            let mut along = (k as Real + 0.5) / n as Real * total;
            let Some(theta) = intervals.iter().find_map(|i| {
                let w = i.upper - i.lower;
                if along <= w {
                    Some(i.lower + along)
                } else {
                    along -= w;
                    None
                }
            }) else {
                continue;
            };
            let x = vec![wrap_angle(theta - sw0)];
            if self.residual(&x, &mut r).is_some() {
                samples.push((r.iter().map(|v| v * v).sum(), x));
            }
        }
        samples.sort_by(|a, b| a.0.total_cmp(&b.0));
        samples.into_iter().take(3).map(|(_, x)| x).collect()
    }
}

fn halton(k: usize, dim: usize) -> Real {
    const PRIMES: [usize; 10] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29];
    let base = PRIMES[dim % PRIMES.len()];
    let (mut f, mut r, mut n) = (1.0, 0.0, k);
    while n > 0 {
        f /= base as Real;
        r += f * (n % base) as Real;
        n /= base;
    }
    r
}

/// Between a start value and a fixed target, by `fraction`.
fn interpolate(from: &Target, to: &Target, fraction: Real, v: Variable) -> Target {
    match (from, to) {
        (Target::Position(a), Target::Position(b)) => Target::Position(a + (b - a) * fraction),
        (Target::Rotation(a), Target::Rotation(b)) => {
            Target::Rotation(Rotation3::new(rotation_log(&(b * a.inverse())) * fraction) * a)
        }
        (Target::Angle(a), Target::Angle(b)) => {
            Target::Angle(a + v.angle_difference(*b, *a) * fraction)
        }
        _ => *to,
    }
}

/// The space all `goals` can be written in, if any.
fn space_of(goals: &[(Variable, Target)]) -> Option<Space> {
    goals.iter().find_map(|(v, _)| v.space())
}

/// Opt1(G1, G2) (paper eq. 5, 13): with G1's variables fixed at their
/// goals, the other variables of G1's space chosen so that G2 is met as
/// well as possible.
///
/// # Errors
/// [`OptError`]: a singular start, no reachable candidate, or a G1 whose
/// space is not fixed by its variables.
pub fn opt1(
    robot: &Robot,
    g1: &[(Variable, Target)],
    g2: &[(Variable, Target)],
    start: &JointVector,
    scene: Option<&CollisionScene>,
    options: &OptOptions,
) -> Result<OptSolution, OptError> {
    let space = space_of(g1)
        .or_else(|| space_of(g2).map(other))
        .ok_or_else(|| OptError::Unsupported("Opt1 needs goals in two spaces".into()))?;
    let start_state = ArmState::at(robot, start).map_err(OptError::SingularStart)?;
    let free = space.variables().into_iter().filter(|v| !g1.iter().any(|(f, _)| f == v)).collect();
    let model = scene.map(|s| CollisionModel::new(robot, s));
    Search {
        robot,
        start_q: *start,
        start: start_state,
        space,
        free,
        sized: Vec::new(),
        path: None,
        fixed: g1.to_vec(),
        goals: g2,
        options,
        scene,
        model: model.as_ref(),
        measured: None,
        kept: options.clearance,
        evaluations: 0,
        check_path: true,
    }
    .solve_with_room(goal_margin(robot, options.goal_tolerance))
}

/// The farthest any point of the arm's capsules moves when the state changes within
/// `tolerance` (m, rad): the position error, plus the rotation error times the arm's
/// reach from the shoulder (a rotation of Os, Ow or θsw by ε moves a point at distance ρ
/// from its centre by at most ερ).
pub fn goal_margin(robot: &Robot, tolerance: (Real, Real)) -> Real {
    tolerance.0 + tolerance.1 * arm_reach(robot)
}

/// The farthest a point of the arm's capsules can be from the shoulder in any
/// configuration: along the chain S -> E -> W -> the point, each leg measured at the zero
/// configuration (its length does not change where the joint axes meet at S, E and W).
fn arm_reach(robot: &Robot) -> Real {
    let pose = arm_pose(robot, &JointVector::zeros());
    let (upper, fore) = ((pose.elbow - pose.shoulder).norm(), (pose.wrist - pose.elbow).norm());
    let frame_reach = |frame: usize, p: Vector3| match frame {
        0..=3 => (p - pose.shoulder).norm(),
        4 | 5 => upper + (p - pose.elbow).norm(),
        _ => upper + fore + (p - pose.wrist).norm(),
    };
    robot
        .capsules
        .iter()
        .flat_map(|c| {
            let frame = pose.frames[c.frame.min(DOF)];
            [frame * nalgebra::Point3::from(c.a), frame * nalgebra::Point3::from(c.b)]
                .map(|p| frame_reach(c.frame, p.coords) + c.radius)
        })
        .fold(upper + fore, Real::max)
}

fn other(space: Space) -> Space {
    match space {
        Space::Cpsa => Space::Hat,
        Space::Hat => Space::Cpsa,
    }
}

/// Opt2(G, P) (paper eq. 6, 14): the sizes of the path items left open and
/// the goals of the path space's other variables, chosen so that the goals
/// `g` (in any space) are met as well as possible at the end of the path.
///
/// # Errors
/// As [`opt1`].
pub fn opt2(
    robot: &Robot,
    g: &[(Variable, Target)],
    path: &PathConstraint,
    start: &JointVector,
    scene: Option<&CollisionScene>,
    options: &OptOptions,
) -> Result<OptSolution, OptError> {
    let path_vars: Vec<Variable> =
        path.items.iter().flat_map(|i| i.variables.iter().copied()).collect();
    let space = path.space.or_else(|| space_of(g).map(other)).ok_or_else(|| {
        OptError::Unsupported("Opt2 needs the path or the goal to fix a space".into())
    })?;
    let start_state = ArmState::at(robot, start).map_err(OptError::SingularStart)?;
    let free = space.variables().into_iter().filter(|v| !path_vars.contains(v)).collect();
    let sized = path
        .items
        .iter()
        .enumerate()
        .filter_map(|(i, item)| match item.feature {
            PathFeature::Line { length: None, .. } => Some((i, 0.0, options.max_path_size)),
            PathFeature::About { angle: None, .. } => Some((i, 0.0, options.max_path_size.max(PI))),
            _ => None,
        })
        .collect();
    let model = scene.map(|s| CollisionModel::new(robot, s));
    Search {
        robot,
        start_q: *start,
        start: start_state,
        space,
        free,
        sized,
        path: Some(path),
        fixed: Vec::new(),
        goals: g,
        options,
        scene,
        model: model.as_ref(),
        measured: None,
        kept: options.clearance,
        evaluations: 0,
        check_path: true,
    }
    .solve_with_room(goal_margin(robot, options.goal_tolerance))
}
