//! Motion patterns of the HAMP paper (Zhao, Wang & Xie; METHODS.md §3.1, §3.3): which of the
//! swivel Φ, the hand position P and the hand orientation O move in each frame, the
//! run-length string of those primitives (the HAMP, e.g. `ΦPO-PO`), per phase split at P's
//! speed peak, and the similarity indices between patterns (sim, simc, MPCSI).
//!
//! P is the wrist centre Pw (the paper uses the fingertip); O is the hand frame Ow; Φ is θsw.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::str::FromStr;

use crate::kinematics::CpsaState;
use crate::math::{Real, rotation_log, wrap_angle};

/// A frame's primitive: the set of elements moving in it, written in the order Φ, P, O.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Primitive {
    /// Φ, the swivel angle, moves.
    pub swivel: bool,
    /// P, the hand position, moves.
    pub position: bool,
    /// O, the hand orientation, moves.
    pub orientation: bool,
}

impl Primitive {
    /// The primitive of the elements given.
    pub const fn new(swivel: bool, position: bool, orientation: bool) -> Self {
        Self { swivel, position, orientation }
    }

    /// ΦPO: every element moves.
    pub const SWIVEL_POSITION_ORIENTATION: Self = Self::new(true, true, true);
    /// PO: the hand moves, the swivel does not.
    pub const POSITION_ORIENTATION: Self = Self::new(false, true, true);

    /// Whether no element moves (not a primitive of a pattern; a frame at rest).
    pub fn is_empty(self) -> bool {
        !(self.swivel || self.position || self.orientation)
    }
}

impl fmt::Display for Primitive {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (moves, symbol) in [(self.swivel, "Φ"), (self.position, "P"), (self.orientation, "O")]
        {
            if moves {
                f.write_str(symbol)?;
            }
        }
        Ok(())
    }
}

/// Why a pattern string cannot be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PatternError {
    /// A primitive is empty, repeats an element or names an unknown one.
    #[error(
        "`{text}` is not a motion primitive: write the moving elements in the order Φ (or \
         `phi`), P, O, e.g. `ΦPO` or `PO`"
    )]
    Primitive {
        /// The primitive as written.
        text: String,
    },
}

impl FromStr for Primitive {
    type Err = PatternError;

    /// `ΦPO`, `phiPO`, `PO`, `P`, …: the elements in the order Φ, P, O.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let bad = || PatternError::Primitive { text: text.to_owned() };
        let mut rest = text.trim();
        let mut primitive = Self::new(false, false, false);
        for prefix in ["Φ", "φ", "phi", "Phi", "PHI"] {
            if let Some(after) = rest.strip_prefix(prefix) {
                primitive.swivel = true;
                rest = after;
                break;
            }
        }
        if let Some(after) = rest.strip_prefix('P') {
            primitive.position = true;
            rest = after;
        }
        if let Some(after) = rest.strip_prefix('O') {
            primitive.orientation = true;
            rest = after;
        }
        if rest.is_empty() && !primitive.is_empty() { Ok(primitive) } else { Err(bad()) }
    }
}

/// A HAMP: the primitives of a motion in time order, adjacent ones different.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Hamp(pub Vec<Primitive>);

impl Hamp {
    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether the pattern has no primitive (nothing moved).
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl fmt::Display for Hamp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let tokens: Vec<String> = self.0.iter().map(Primitive::to_string).collect();
        f.write_str(&tokens.join("-"))
    }
}

impl FromStr for Hamp {
    type Err = PatternError;

    /// Primitives joined by `-` (`ΦPO-PO`); the empty string is the empty pattern.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        if text.trim().is_empty() {
            return Ok(Self::default());
        }
        text.split('-').map(str::parse).collect::<Result<_, _>>().map(Self)
    }
}

impl serde::Serialize for Primitive {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.to_string())
    }
}

impl serde::Serialize for Hamp {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.to_string())
    }
}

/// The speeds of the three elements at each frame.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize)]
pub struct ElementSpeeds {
    /// Frame times (s).
    pub times: Vec<Real>,
    /// s_P = |P'| (m/s).
    pub position: Vec<Real>,
    /// s_O = |ω| of the hand (rad/s).
    pub orientation: Vec<Real>,
    /// s_Φ = |Φ'| (rad/s); NaN where the swivel angle is undefined (counted as not moving).
    pub swivel: Vec<Real>,
}

impl ElementSpeeds {
    /// The speeds of a sampled CPSA trajectory by central differences (one-sided at the ends),
    /// the orientation's by the rotation between neighbouring frames, the swivel's wrapped.
    pub fn of_cpsa(times: &[Real], states: &[CpsaState]) -> Self {
        let n = times.len().min(states.len());
        let mut speeds = Self { times: times[..n].to_vec(), ..Self::default() };
        for k in 0..n {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n.saturating_sub(1)));
            let dt = times[b] - times[a];
            if b == a || dt <= 0.0 {
                speeds.position.push(0.0);
                speeds.orientation.push(0.0);
                speeds.swivel.push(0.0);
                continue;
            }
            let (from, to) = (&states[a], &states[b]);
            speeds.position.push((to.pw - from.pw).norm() / dt);
            speeds.orientation.push(rotation_log(&(to.ow * from.ow.inverse())).norm() / dt);
            speeds.swivel.push(wrap_angle(to.swivel - from.swivel).abs() / dt);
        }
        speeds
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// Whether there is no frame.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }
}

/// When an element counts as moving (METHODS.md §3.1; the paper gives no thresholds, these
/// are the project's): `s_X(k) > max(absolute_X, relative · max_k s_X(k))`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PatternOptions {
    /// η, the share of the element's peak speed below which it rests.
    pub relative: Real,
    /// ε_abs for P (m/s).
    pub position_speed: Real,
    /// ε_abs for O (rad/s).
    pub orientation_speed: Real,
    /// ε_abs for Φ (rad/s).
    pub swivel_speed: Real,
    /// Runs shorter than this many frames merge into their longer neighbour.
    pub min_run_frames: usize,
}

impl Default for PatternOptions {
    fn default() -> Self {
        Self {
            relative: 0.05,
            position_speed: 0.01,
            orientation_speed: 2.0_f64.to_radians(),
            swivel_speed: 2.0_f64.to_radians(),
            min_run_frames: 3,
        }
    }
}

/// One primitive held over consecutive frames.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Run {
    /// The primitive.
    pub primitive: Primitive,
    /// First frame.
    pub first: usize,
    /// Last frame (inclusive).
    pub last: usize,
    /// Its duration: time of the frame after `last` (or of `last`) minus time of `first` (s).
    pub duration: Real,
}

/// A pattern with the runs it is made of.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Pattern {
    /// The HAMP string.
    pub hamp: Hamp,
    /// Its runs, in time order.
    pub runs: Vec<Run>,
}

/// The patterns of a motion: whole and per phase (split at the peak of P's speed).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Phases {
    /// The movement window: first and last frame where P moves; `None` if it never does.
    pub window: Option<(usize, usize)>,
    /// The frame of P's peak speed (the end of phase 1 and the start of phase 2).
    pub peak: Option<usize>,
    /// The whole motion's pattern.
    pub whole: Pattern,
    /// Phase 1: from the window's start to the peak.
    pub phase1: Pattern,
    /// Phase 2: from the peak to the window's end.
    pub phase2: Pattern,
    /// R_Φ: frames with Φ moving inside the window over the window's frames (0 without one).
    pub swivel_ratio: Real,
}

fn peak(values: &[Real]) -> Real {
    values.iter().copied().filter(|v| v.is_finite()).fold(0.0, Real::max)
}

fn moving(values: &[Real], absolute: Real, relative: Real) -> Vec<bool> {
    let threshold = absolute.max(relative * peak(values));
    values.iter().map(|&v| v > threshold).collect()
}

/// Each frame's primitive (possibly empty: nothing moves), thresholds from `options`.
pub fn frame_primitives(speeds: &ElementSpeeds, options: &PatternOptions) -> Vec<Primitive> {
    let swivel = moving(&speeds.swivel, options.swivel_speed, options.relative);
    let position = moving(&speeds.position, options.position_speed, options.relative);
    let orientation = moving(&speeds.orientation, options.orientation_speed, options.relative);
    (0..speeds.len()).map(|k| Primitive::new(swivel[k], position[k], orientation[k])).collect()
}

fn run_duration(times: &[Real], first: usize, last: usize) -> Real {
    let end = times.get(last + 1).unwrap_or(&times[last]);
    end - times[first]
}

/// Runs of identical primitives over `frames[first..=last]`, before any merging.
fn raw_runs(labels: &[Primitive], first: usize, last: usize) -> Vec<Run> {
    let mut runs: Vec<Run> = Vec::new();
    for (k, &primitive) in labels.iter().enumerate().take(last + 1).skip(first) {
        match runs.last_mut() {
            Some(run) if run.primitive == primitive => run.last = k,
            _ => runs.push(Run { primitive, first: k, last: k, duration: 0.0 }),
        }
    }
    runs
}

/// Merges identical neighbours into one run.
fn coalesce(runs: Vec<Run>) -> Vec<Run> {
    let mut out: Vec<Run> = Vec::with_capacity(runs.len());
    for run in runs {
        match out.last_mut() {
            Some(before) if before.primitive == run.primitive => before.last = run.last,
            _ => out.push(run),
        }
    }
    out
}

/// Absorbs every empty run and every run shorter than `min_frames` into its longer
/// neighbour, shortest first, so that a flicker of a threshold does not add a primitive.
fn merge_short(mut runs: Vec<Run>, min_frames: usize) -> Vec<Run> {
    let frames = |r: &Run| r.last + 1 - r.first;
    loop {
        runs = coalesce(runs);
        if runs.len() < 2 {
            break;
        }
        let shortest = runs
            .iter()
            .enumerate()
            .filter(|(_, r)| r.primitive.is_empty() || frames(r) < min_frames)
            .min_by_key(|(_, r)| (!r.primitive.is_empty(), frames(r)))
            .map(|(i, _)| i);
        let Some(i) = shortest else { break };
        let left = i.checked_sub(1).map(|j| frames(&runs[j]));
        let right = runs.get(i + 1).map(frames);
        let into = match (left, right) {
            (Some(l), Some(r)) => {
                if l >= r {
                    i - 1
                } else {
                    i + 1
                }
            }
            (Some(_), None) => i - 1,
            _ => i + 1,
        };
        runs[i].primitive = runs[into].primitive;
    }
    runs.retain(|r| !r.primitive.is_empty());
    runs
}

/// The pattern of `labels[first..=last]`: runs merged as [`PatternOptions::min_run_frames`]
/// says, durations from `times`.
pub fn pattern_of(
    labels: &[Primitive],
    times: &[Real],
    first: usize,
    last: usize,
    options: &PatternOptions,
) -> Pattern {
    if labels.is_empty() || first > last || last >= labels.len() {
        return Pattern { hamp: Hamp::default(), runs: Vec::new() };
    }
    let mut runs = merge_short(raw_runs(labels, first, last), options.min_run_frames);
    for run in &mut runs {
        run.duration = run_duration(times, run.first, run.last);
    }
    Pattern { hamp: Hamp(runs.iter().map(|r| r.primitive).collect()), runs }
}

/// The whole-motion and per-phase patterns of a motion (paper §2.2): frames labelled, the
/// movement window where P moves, split at P's peak speed.
pub fn extract(speeds: &ElementSpeeds, options: &PatternOptions) -> Phases {
    let labels = frame_primitives(speeds, options);
    let empty = Pattern { hamp: Hamp::default(), runs: Vec::new() };
    let first = labels.iter().position(|p| p.position);
    let last = labels.iter().rposition(|p| p.position);
    let (Some(first), Some(last)) = (first, last) else {
        return Phases {
            window: None,
            peak: None,
            whole: empty.clone(),
            phase1: empty.clone(),
            phase2: empty,
            swivel_ratio: 0.0,
        };
    };
    let peak = (first..=last)
        .max_by(|&a, &b| speeds.position[a].total_cmp(&speeds.position[b]))
        .unwrap_or(first);
    let swivel_frames = labels[first..=last].iter().filter(|p| p.swivel).count();
    let times = &speeds.times;
    Phases {
        window: Some((first, last)),
        peak: Some(peak),
        whole: pattern_of(&labels, times, first, last, options),
        phase1: pattern_of(&labels, times, first, peak, options),
        phase2: pattern_of(&labels, times, peak, last, options),
        swivel_ratio: swivel_frames as Real / (last + 1 - first) as Real,
    }
}

/// Levenshtein distance between two patterns over primitive tokens (unit costs).
pub fn levenshtein(a: &Hamp, b: &Hamp) -> usize {
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, x) in a.0.iter().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, y) in b.0.iter().enumerate() {
            let substitute = diagonal + usize::from(x != y);
            diagonal = row[j + 1];
            row[j + 1] = substitute.min(row[j] + 1).min(row[j + 1] + 1);
        }
    }
    row[b.len()]
}

/// sim(h, s) = (n + m - d(h, s)) / (n + m) (paper eq. 3); 1 for two empty patterns.
pub fn similarity(h: &Hamp, s: &Hamp) -> Real {
    let total = h.len() + s.len();
    if total == 0 {
        return 1.0;
    }
    (total - levenshtein(h, s)) as Real / total as Real
}

/// A connection type of a pattern: an adjacent pair `X-Y`, or `X-` for a one-primitive
/// pattern (METHODS.md §3.3, the reading chosen there).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Connection {
    /// The first primitive.
    pub from: Primitive,
    /// The next one; `None` for a one-primitive pattern.
    pub to: Option<Primitive>,
}

impl fmt::Display for Connection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.to {
            Some(to) => write!(f, "{}-{to}", self.from),
            None => write!(f, "{}-", self.from),
        }
    }
}

/// The connection types of `h` with repetition: its k - 1 adjacent pairs, or one `X-`.
pub fn connections(h: &Hamp) -> Vec<Connection> {
    match h.0.as_slice() {
        [] => Vec::new(),
        [only] => vec![Connection { from: *only, to: None }],
        many => many.windows(2).map(|w| Connection { from: w[0], to: Some(w[1]) }).collect(),
    }
}

/// A population of patterns with their shares of all samples (e.g. 0.412 for 41.2 %).
pub type Population = [(Hamp, Real)];

/// f_L: the frequency of each connection type over a population (paper eq. 2),
/// Σ_i N_ij f_i / Σ_i N_ci f_i.
pub fn connection_frequencies(population: &Population) -> BTreeMap<Connection, Real> {
    let mut counts: BTreeMap<Connection, Real> = BTreeMap::new();
    let mut total = 0.0;
    for (hamp, share) in population {
        for connection in connections(hamp) {
            *counts.entry(connection).or_insert(0.0) += share;
            total += share;
        }
    }
    if total > 0.0 {
        counts.values_mut().for_each(|v| *v /= total);
    }
    counts
}

/// simc(h, s) = (m + n - (1 - f_h) Σ_j a_j f_Lj) / (m + n) (paper eq. 4): h the target
/// pattern with share `target_share` (f_h), s the original, a_j = 1 for the connection types
/// in the symmetric difference of the two patterns' type sets (METHODS.md §3.3's reading).
pub fn connection_similarity(
    h: &Hamp,
    s: &Hamp,
    target_share: Real,
    frequencies: &BTreeMap<Connection, Real>,
) -> Real {
    let total = (h.len() + s.len()) as Real;
    if total == 0.0 {
        return 1.0;
    }
    let (of_h, of_s): (BTreeSet<_>, BTreeSet<_>) =
        (connections(h).into_iter().collect(), connections(s).into_iter().collect());
    let changed: Real =
        of_h.symmetric_difference(&of_s).map(|c| frequencies.get(c).copied().unwrap_or(0.0)).sum();
    (total - (1.0 - target_share) * changed) / total
}

/// The share of `h` in `population` (0 when absent).
pub fn share_of(h: &Hamp, population: &Population) -> Real {
    population.iter().filter(|(p, _)| p == h).map(|(_, share)| share).sum()
}

/// MPCSI (paper eqs. 5-6): for each candidate h_l, the mean of simc(h_l, s_k) over the
/// samples s_k, with f_h and f_L taken from `population`.
pub fn mpcsi(candidates: &[Hamp], samples: &[Hamp], population: &Population) -> Vec<Real> {
    let frequencies = connection_frequencies(population);
    candidates
        .iter()
        .map(|h| {
            let f_h = share_of(h, population);
            let sum: Real =
                samples.iter().map(|s| connection_similarity(h, s, f_h, &frequencies)).sum();
            if samples.is_empty() { 0.0 } else { sum / samples.len() as Real }
        })
        .collect()
}
