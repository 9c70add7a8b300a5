//! The step QP's exact solver: Goldfarb and Idnani's dual active-set method (Math.
//! Programming 27, 1983) for min ½xᵀPx − cᵀx subject to a_k·x ≤ b_k, with P = LLᵀ positive
//! definite.
//!
//! In u = Lᵀx the objective is ½‖u − u₀‖² plus a constant (u₀ = L⁻¹c) and a constraint reads
//! ã_k·u ≤ b_k with ã_k = L⁻¹a_k: the problem is the Euclidean projection of u₀ onto a
//! polyhedron. The method starts at the unconstrained optimum and adds one violated
//! constraint at a time, keeping the active constraints' multipliers nonnegative (dual
//! feasibility) and their normals linearly independent (an orthonormal basis of their span is
//! refactored at every change: at most seven vectors of seven entries). Each added constraint
//! raises the objective, so no active set repeats and the method ends after finitely many
//! steps, at the optimum or at a violated constraint no step can satisfy (infeasible).

use nalgebra::{Cholesky, Const};

use crate::math::{DOF, Matrix7, Real, Vector7};

/// The Cholesky factor of the step QP's P.
pub(super) type Factor = Cholesky<Real, Const<DOF>>;

/// A constraint violated by less than this, relative to the size of its terms, counts as
/// held: rounding, not a violation.
const FEASIBILITY: Real = 1e-12;

/// A constraint whose normal lies within this fraction of its length of the active normals'
/// span is taken as dependent on them (the step cannot move the primal point).
const DEPENDENCE: Real = 1e-10;

/// Far more steps than the method takes (each adds or drops one of at most seven active
/// constraints, and every addition raises the objective): past this it is cycling on
/// rounding, and the problem is called degenerate.
const MAX_STEPS: usize = 100;

/// How the dual method ended.
// Returned by value once per step: boxing the solution would allocate at every binding step.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy)]
pub(super) enum Outcome {
    /// The optimum, with the constraints active there and their multipliers.
    Solved(Solution),
    /// A violated constraint that no point satisfying the active ones can satisfy: the
    /// constraints cannot all hold.
    Infeasible,
    /// Rounding broke an invariant (dependent active normals, a non-finite value, a cycle).
    Degenerate,
}

/// The QP's optimum.
#[derive(Debug, Clone, Copy)]
pub(super) struct Solution {
    /// The minimiser.
    pub x: Vector7,
    /// The constraints active at it (what the tests check the KKT conditions with).
    #[cfg_attr(not(test), allow(dead_code))]
    pub active: Active,
}

/// The active constraints: their indices (as [`Constraints::get`] numbers them), normals in
/// u (ã = L⁻¹a) and multipliers, at most [`DOF`] of them (they are independent).
#[derive(Debug, Clone, Copy)]
pub(super) struct Active {
    index: [usize; DOF],
    normal: [Vector7; DOF],
    lambda: [Real; DOF],
    len: usize,
}

impl Active {
    fn empty() -> Self {
        Self { index: [0; DOF], normal: [Vector7::zeros(); DOF], lambda: [0.0; DOF], len: 0 }
    }

    fn contains(&self, k: usize) -> bool {
        self.index[..self.len].contains(&k)
    }

    fn push(&mut self, k: usize, normal: Vector7, lambda: Real) -> Result<(), ()> {
        if self.len == DOF {
            return Err(());
        }
        self.index[self.len] = k;
        self.normal[self.len] = normal;
        self.lambda[self.len] = lambda;
        self.len += 1;
        Ok(())
    }

    fn remove(&mut self, j: usize) {
        for i in j..self.len - 1 {
            self.index[i] = self.index[i + 1];
            self.normal[i] = self.normal[i + 1];
            self.lambda[i] = self.lambda[i + 1];
        }
        self.len -= 1;
    }

    /// The active constraints' indices and multipliers.
    #[cfg_attr(not(test), allow(dead_code))]
    pub fn multipliers(&self) -> impl Iterator<Item = (usize, Real)> + '_ {
        self.index[..self.len].iter().copied().zip(self.lambda[..self.len].iter().copied())
    }
}

/// The step QP's constraints, each as a·x ≤ b: x_i ≤ upper_i (index i), −x_i ≤ −lower_i
/// (index 7 + i), then the rows (index 14 + r).
#[derive(Debug, Clone, Copy)]
pub(super) struct Constraints<'a> {
    pub lower: &'a Vector7,
    pub upper: &'a Vector7,
    pub rows: &'a [(Vector7, Real)],
}

impl Constraints<'_> {
    pub fn len(&self) -> usize {
        2 * DOF + self.rows.len()
    }

    /// Constraint `k` as (a, b).
    pub fn get(&self, k: usize) -> (Vector7, Real) {
        match k {
            k if k < DOF => (Vector7::ith(k, 1.0), self.upper[k]),
            k if k < 2 * DOF => (Vector7::ith(k - DOF, -1.0), -self.lower[k - DOF]),
            k => self.rows[k - 2 * DOF],
        }
    }

    /// By how much x violates constraint `k` (a·x − b), and the size of its terms, the scale
    /// its rounding is measured against.
    fn excess(&self, k: usize, x: &Vector7) -> (Real, Real) {
        // A bound's normal is ±e_i: its dot product and terms are x_i's alone (the zeros add
        // nothing), without the seven products.
        if k < DOF {
            let b = self.upper[k];
            return (x[k] - b, 1.0 + x[k].abs() + b.abs());
        }
        if k < 2 * DOF {
            let (i, b) = (k - DOF, -self.lower[k - DOF]);
            return (-x[i] - b, 1.0 + x[i].abs() + b.abs());
        }
        let (a, b) = self.get(k);
        let terms = a.iter().zip(x.iter()).map(|(a, x)| (a * x).abs()).sum::<Real>();
        (a.dot(x) - b, 1.0 + terms + b.abs())
    }

    /// The most violated constraint outside `active`, if any is violated beyond rounding.
    fn most_violated(&self, x: &Vector7, active: &Active) -> Option<(usize, Real)> {
        (0..self.len())
            .filter(|&k| !active.contains(k))
            .map(|k| (k, self.excess(k, x)))
            .filter(|(_, (excess, scale))| *excess > FEASIBILITY * scale)
            .map(|(k, (excess, _))| (k, excess))
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }
}

/// An orthonormal basis of the active normals' span, Q R = [ã_1 … ã_m] (Gram–Schmidt, each
/// vector orthogonalised twice, which keeps Q orthonormal to rounding).
struct Basis {
    q: [Vector7; DOF],
    r: Matrix7,
    len: usize,
}

impl Basis {
    /// `None` when the normals are dependent.
    fn of(active: &Active) -> Option<Self> {
        let mut basis = Self { q: [Vector7::zeros(); DOF], r: Matrix7::zeros(), len: 0 };
        for k in 0..active.len {
            let a = active.normal[k];
            let mut v = a;
            for _ in 0..2 {
                for i in 0..k {
                    let h = basis.q[i].dot(&v);
                    basis.r[(i, k)] += h;
                    v -= basis.q[i] * h;
                }
            }
            let length = v.norm();
            if length.is_nan() || length <= DEPENDENCE * a.norm() {
                return None;
            }
            basis.r[(k, k)] = length;
            basis.q[k] = v / length;
            basis.len = k + 1;
        }
        Some(basis)
    }

    /// Moves u by the least amount within the span that puts it back on every active
    /// constraint's edge, undoing the rounding that the steps accumulate: u += Q w with
    /// Rᵀw = b_A − Ñᵀu.
    fn settle(&self, u: &mut Vector7, active: &Active, constraints: &Constraints) {
        let mut w = [0.0; DOF];
        for i in 0..self.len {
            let residual = constraints.get(active.index[i]).1 - active.normal[i].dot(u);
            let head: Real = (0..i).map(|j| self.r[(j, i)] * w[j]).sum();
            w[i] = (residual - head) / self.r[(i, i)];
        }
        for (q, w) in self.q[..self.len].iter().zip(&w[..self.len]) {
            *u += q * *w;
        }
    }

    /// Of a normal n: its part orthogonal to the span, z = n − QQᵀn (the direction the
    /// primal point moves in), and r = R⁻¹Qᵀn (the rate at which the active multipliers fall
    /// as the new one rises).
    fn split(&self, n: &Vector7) -> (Vector7, [Real; DOF]) {
        let mut z = *n;
        let mut coefficients = [0.0; DOF];
        for (i, q) in self.q[..self.len].iter().enumerate() {
            coefficients[i] = q.dot(n);
            z -= q * coefficients[i];
        }
        let mut r = [0.0; DOF];
        for i in (0..self.len).rev() {
            let tail: Real = (i + 1..self.len).map(|j| self.r[(i, j)] * r[j]).sum();
            r[i] = (coefficients[i] - tail) / self.r[(i, i)];
        }
        (z, r)
    }
}

/// The minimiser of ½xᵀPx − cᵀx subject to `constraints`, P given by its Cholesky factor.
///
/// When no constraint is violated at the unconstrained minimiser P⁻¹c, that is the answer,
/// as it was computed (`cholesky.solve(c)`).
pub(super) fn solve(cholesky: &Factor, c: &Vector7, constraints: &Constraints) -> Outcome {
    let l = cholesky.l_dirty();
    let mut x = cholesky.solve(c);
    let Some(mut u) = l.solve_lower_triangular(c) else { return Outcome::Degenerate };
    let mut active = Active::empty();
    let mut basis = Basis { q: [Vector7::zeros(); DOF], r: Matrix7::zeros(), len: 0 };
    let mut steps = 0;
    while steps < MAX_STEPS {
        let Some((p, mut violation)) = constraints.most_violated(&x, &active) else {
            return if x.iter().all(|v| v.is_finite()) {
                Outcome::Solved(Solution { x, active })
            } else {
                Outcome::Degenerate
            };
        };
        let (a, b) = constraints.get(p);
        let Some(normal) = l.solve_lower_triangular(&a) else { return Outcome::Degenerate };
        // The new constraint's multiplier, raised from 0 until it is satisfied.
        let mut added = 0.0;
        loop {
            steps += 1;
            if steps > MAX_STEPS {
                return Outcome::Degenerate;
            }
            let (z, r) = basis.split(&normal);
            let zz = z.norm_squared();
            let moves = zz.sqrt() > DEPENDENCE * normal.norm();
            // The full step satisfies the new constraint; a partial step stops where an
            // active multiplier reaches zero, and that constraint leaves.
            let full = if moves { violation.max(0.0) / zz } else { Real::INFINITY };
            let (partial, leaving) = (0..active.len)
                .filter(|&j| r[j] > 0.0)
                .map(|j| (active.lambda[j].max(0.0) / r[j], j))
                .fold((Real::INFINITY, 0), |best, s| if s.0 < best.0 { s } else { best });
            let t = full.min(partial);
            if !t.is_finite() {
                return Outcome::Infeasible;
            }
            if moves {
                u -= z * t;
            }
            for (lambda, r) in active.lambda[..active.len].iter_mut().zip(&r) {
                *lambda -= t * r;
            }
            added += t;
            if full <= partial {
                if active.push(p, normal, added).is_err() {
                    return Outcome::Degenerate;
                }
            } else {
                active.remove(leaving);
            }
            let Some(refactored) = Basis::of(&active) else { return Outcome::Degenerate };
            basis = refactored;
            basis.settle(&mut u, &active, constraints);
            let Some(moved) = l.tr_solve_lower_triangular(&u) else {
                return Outcome::Degenerate;
            };
            x = moved;
            if full <= partial {
                break;
            }
            violation = a.dot(&x) - b;
        }
    }
    Outcome::Degenerate
}
