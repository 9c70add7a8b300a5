//! Pictures of a plan as SVG (issue 18, DESIGN.md §6): joint positions against their limits,
//! velocities and accelerations, the featured variables against what was asked, the
//! clearance to each obstacle and the wrist path in three orthographic views.
//!
//! Entry points: [`plot_svg`] (one [`PlotKind`] or `all` on one page) and [`write_plot`].
//! [`PlotData`] is what the drawing reads, taken out of the plan once. plotters enters the
//! crate here only, with its SVG backend: text stays SVG `<text>`, so no font is loaded.
//! Times are the plan's seconds, angles are drawn in degrees, distances in m or mm as the
//! axes say; every joint keeps its Okabe–Ito colour across the plots.

mod data;
mod draw;

pub use data::{DistanceSeries, FeaturedPanel, PlotData, Runs, SegmentMark};
pub use draw::{PALETTE, outline};

use std::path::Path;

use crate::language::Task;
use crate::robot::Robot;
use crate::solve::Plan;

use super::OutputError;

/// Which picture to draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PlotKind {
    /// Joint positions with their limits shaded and the segment boundaries labelled.
    Joints,
    /// Joint velocities against their speed limits, and accelerations.
    Velocities,
    /// The featured variables of the segments against their references and goals.
    Featured,
    /// Distance of each arm capsule to each obstacle, with the safety distance.
    Distances,
    /// The wrist path in three orthographic views, with the obstacles' outlines.
    Wrist,
    /// Every picture above on one page.
    All,
}

impl PlotKind {
    /// Every kind with its command-line name.
    pub const NAMES: [(&'static str, PlotKind); 6] = [
        ("joints", Self::Joints),
        ("velocities", Self::Velocities),
        ("featured", Self::Featured),
        ("distances", Self::Distances),
        ("wrist", Self::Wrist),
        ("all", Self::All),
    ];

    /// The command-line name: `joints`, `velocities`, `featured`, `distances`, `wrist`, `all`.
    pub fn name(self) -> &'static str {
        Self::NAMES.iter().find(|(_, k)| *k == self).map_or("all", |(n, _)| n)
    }

    /// The kind of a command-line name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::NAMES.iter().find(|(n, _)| *n == name).map(|(_, k)| *k)
    }
}

/// Where one chart of a picture sits and what its axes span, so that a caller can place
/// marks on it (the report's current-time line) and a test can check what was drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// The chart's title.
    pub title: String,
    /// The kind of picture it belongs to (never `All`).
    pub kind: PlotKind,
    /// Whether x is the plan's time (s).
    pub timed: bool,
    /// Pixel columns of the x range's ends (left, right).
    pub x_pixels: (i32, i32),
    /// Pixel rows of the y range's ends (bottom, top).
    pub y_pixels: (i32, i32),
    /// Values at the left and right ends of x.
    pub x_range: (f64, f64),
    /// Values at the bottom and top ends of y.
    pub y_range: (f64, f64),
}

impl Panel {
    /// The pixel row of value `y`.
    pub fn row(&self, y: f64) -> f64 {
        let (b, t) = (f64::from(self.y_pixels.0), f64::from(self.y_pixels.1));
        b + (y - self.y_range.0) / (self.y_range.1 - self.y_range.0) * (t - b)
    }

    /// The pixel column of value `x`.
    pub fn column(&self, x: f64) -> f64 {
        let (l, r) = (f64::from(self.x_pixels.0), f64::from(self.x_pixels.1));
        l + (x - self.x_range.0) / (self.x_range.1 - self.x_range.0) * (r - l)
    }
}

/// A drawn picture: the SVG document and its charts.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    /// The SVG document.
    pub svg: String,
    /// Width and height (px).
    pub size: (u32, u32),
    /// Every chart, top to bottom.
    pub panels: Vec<Panel>,
}

/// Why a picture could not be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlotError {
    /// The plotting backend refused a drawing operation.
    #[error("cannot draw the {kind} plot: {message}")]
    Draw {
        /// The kind being drawn.
        kind: &'static str,
        /// The backend's message.
        message: String,
    },
}

/// Draws `kind` of `plan` (made from `task` on `robot`) as an SVG picture.
///
/// # Errors
/// [`PlotError::Draw`] when the backend refuses an operation.
pub fn plot_svg(
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    kind: PlotKind,
) -> Result<Picture, PlotError> {
    draw::picture(&PlotData::new(robot, task, plan), kind)
}

/// Draws `kind` from data already taken out of a plan.
///
/// # Errors
/// As [`plot_svg`].
pub fn plot_data_svg(data: &PlotData, kind: PlotKind) -> Result<Picture, PlotError> {
    draw::picture(data, kind)
}

/// Writes `kind` of the plot data as an SVG file, through a temporary file renamed into place.
///
/// # Errors
/// As [`write_plot`].
pub fn write_plot_data(path: &Path, data: &PlotData, kind: PlotKind) -> Result<(), OutputError> {
    let picture = plot_data_svg(data, kind).map_err(|e| OutputError::Plot {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    super::write_text(path, &picture.svg)
}

/// Writes `kind` of `plan` as an SVG file, through a temporary file renamed into place.
///
/// # Errors
/// [`OutputError::Plot`] when the picture cannot be drawn, [`OutputError::Io`] when the file
/// cannot be written; the target is then left untouched.
pub fn write_plot(
    path: &Path,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    kind: PlotKind,
) -> Result<(), OutputError> {
    write_plot_data(path, &PlotData::new(robot, task, plan), kind)
}
