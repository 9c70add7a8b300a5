//! A map and its profile in the compact form a plan keeps and a picture draws: each column's
//! blocked cells as runs of one label, and the profile at about two points per column.

use super::grid::{Cell, SwivelMap};
use super::profile::SwivelProfile;
use crate::math::{PI, Real};

/// Cells `first .. first + count` of map column `column` all carry `cell` (never
/// [`Cell::Free`]: a cell no run covers is free).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct CellRun {
    /// The column (index into [`MapSummary::times`]).
    pub column: u32,
    /// The run's first angle cell.
    pub first: u32,
    /// How many cells it covers (≥ 1).
    pub count: u32,
    /// What forbids them.
    pub cell: Cell,
}

/// What the swivel map solver computed for one segment: its grid of free and blocked cells
/// and the profile it chose, in the segment's own time as solved.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MapSummary {
    /// Column times from the segment's start (s), as in [`SwivelMap::times`].
    pub times: Vec<Real>,
    /// Angle cells over the full turn: cell j covers [−π + jΔθ, −π + (j+1)Δθ), Δθ = 2π / n.
    pub angle_steps: usize,
    /// Obstacle names, in the order [`Cell::Obstacle`] counts.
    pub obstacles: Vec<String>,
    /// The blocked cells, column by column, each column's runs in increasing angle.
    pub runs: Vec<CellRun>,
    /// The columns the wrist pose rules out as a whole: (column, why).
    pub faults: Vec<(usize, String)>,
    /// The chosen profile: (time from the segment's start (s), θsw (rad, unwrapped)), at
    /// about two points per map column and at both ends; empty without a profile.
    pub profile: Vec<(Real, Real)>,
}

impl MapSummary {
    /// The summary of `map` and of `profile`, if there is one.
    pub fn new(map: &SwivelMap, profile: Option<&SwivelProfile>) -> Self {
        let n = map.angles.len();
        let mut runs = Vec::new();
        for i in 0..map.times.len() {
            let mut j = 0;
            while j < n {
                let cell = map.cell(i, j);
                let mut k = j + 1;
                while k < n && map.cell(i, k) == cell {
                    k += 1;
                }
                if cell != Cell::Free {
                    runs.push(CellRun {
                        column: i as u32,
                        first: j as u32,
                        count: (k - j) as u32,
                        cell,
                    });
                }
                j = k;
            }
        }
        let faults = map
            .faults
            .iter()
            .enumerate()
            .filter_map(|(i, f)| f.as_ref().map(|f| (i, f.describe())))
            .collect();
        Self {
            times: map.times.clone(),
            angle_steps: n,
            obstacles: map.obstacles.clone(),
            runs,
            faults,
            profile: profile.map(|p| thinned(p, 2 * map.times.len())).unwrap_or_default(),
        }
    }

    /// Angle cell width (rad).
    pub fn angle_step(&self) -> Real {
        2.0 * PI / self.angle_steps.max(1) as Real
    }

    /// The label of column `i`, angle cell `j`.
    pub fn cell(&self, i: usize, j: usize) -> Cell {
        let (i, j) = (i as u32, j as u32);
        self.runs
            .iter()
            .find(|r| r.column == i && (r.first..r.first.saturating_add(r.count)).contains(&j))
            .map_or(Cell::Free, |r| r.cell)
    }

    /// The duration the map spans (s).
    pub fn duration(&self) -> Real {
        self.times.last().copied().unwrap_or(0.0)
    }
}

/// The profile's (t, θsw) at every k-th sample so that about `points` remain, the last
/// sample always kept: the figure is a line over a few hundred pixels.
fn thinned(profile: &SwivelProfile, points: usize) -> Vec<(Real, Real)> {
    let times = profile.trajectory.times();
    let count = times.len().min(profile.swivel.len());
    if count == 0 {
        return Vec::new();
    }
    let stride = count.div_ceil(points.max(1)).max(1);
    let mut out: Vec<(Real, Real)> =
        (0..count).step_by(stride).map(|k| (times[k], profile.swivel[k])).collect();
    if (count - 1) % stride != 0 {
        out.push((times[count - 1], profile.swivel[count - 1]));
    }
    out
}
