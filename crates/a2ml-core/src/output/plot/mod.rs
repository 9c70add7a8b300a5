//! Pictures of a plan as SVG (issue 18, DESIGN.md §6): joint positions against their limits,
//! velocities and accelerations, the featured variables against what was asked, the
//! clearance to each obstacle and the wrist path in three orthographic views.
//!
//! Entry points: [`plot_svg`] (one [`PlotKind`] or `all` on one page) and [`write_plot`].
//! [`PlotData`] is what the drawing reads, taken out of the plan once. plotters enters the
//! crate here only, with its SVG backend: text stays SVG `<text>`, so no font is loaded.
//! Times are the plan's seconds, angles are drawn in degrees, distances in m or mm as the
//! axes say; every joint keeps its Okabe–Ito colour across the plots. A picture is written as
//! SVG or, by the file's extension, as PNG ([`png`]: resvg with an embedded font).

mod data;
mod draw;
mod png;

pub use data::{DistanceSeries, FeaturedPanel, PlotData, Runs, SegmentMark};
pub use draw::{PALETTE, outline};
pub use png::{MAX_WIDTH, png, scaled_size};

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
    /// The width asked for is out of range.
    #[error("a picture is 1 to {max} pixels wide, not {width}")]
    Size {
        /// The width asked for (px).
        width: u32,
        /// The widest picture drawn (px).
        max: u32,
    },
}

/// The file format of a picture.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// An SVG document (text, scalable).
    Svg,
    /// A PNG image (pixels), rendered from the SVG.
    Png,
}

impl ImageFormat {
    /// The format a file name asks for: PNG for `.png` (any case), else SVG.
    pub fn of_path(path: &Path) -> Self {
        if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
            Self::Png
        } else {
            Self::Svg
        }
    }
}

/// The picture's SVG document `width` pixels wide (as drawn when `None`), its height in
/// proportion; the drawing scales with it through the document's `viewBox`.
///
/// # Errors
/// [`PlotError::Size`] as [`scaled_size`].
pub fn svg_sized(picture: &Picture, width: Option<u32>) -> Result<String, PlotError> {
    let (w, h) = scaled_size(picture, width)?;
    if (w, h) == picture.size {
        return Ok(picture.svg.clone());
    }
    let (own_w, own_h) = picture.size;
    let root = format!("<svg width=\"{own_w}\" height=\"{own_h}\"");
    match picture.svg.strip_prefix(&root) {
        Some(rest) if picture.svg[..picture.svg.find('>').unwrap_or(0)].contains("viewBox") => {
            Ok(format!("<svg width=\"{w}\" height=\"{h}\"{rest}"))
        }
        _ => Err(PlotError::Draw {
            kind: "svg",
            message: "the document has no sized root with a viewBox to scale".to_owned(),
        }),
    }
}

/// The picture as the bytes of a file of `format`, `width` pixels wide (as drawn when `None`).
///
/// # Errors
/// As [`svg_sized`] and [`png`].
pub fn encode(
    picture: &Picture,
    format: ImageFormat,
    width: Option<u32>,
) -> Result<Vec<u8>, PlotError> {
    match format {
        ImageFormat::Svg => svg_sized(picture, width).map(String::into_bytes),
        ImageFormat::Png => png(picture, width),
    }
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

/// Writes `kind` of the plot data as an SVG or PNG file (by `path`'s extension, see
/// [`ImageFormat::of_path`]) `width` pixels wide (as drawn when `None`), through a temporary
/// file renamed into place.
///
/// # Errors
/// As [`write_plot`].
pub fn write_plot_data(
    path: &Path,
    data: &PlotData,
    kind: PlotKind,
    width: Option<u32>,
) -> Result<(), OutputError> {
    let failed = |e: PlotError| OutputError::Plot {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let picture = plot_data_svg(data, kind).map_err(failed)?;
    let bytes = encode(&picture, ImageFormat::of_path(path), width).map_err(failed)?;
    super::write_bytes(path, &bytes)
}

/// Writes `kind` of `plan` as an SVG or PNG file, as [`write_plot_data`].
///
/// # Errors
/// [`OutputError::Plot`] when the picture cannot be drawn or the width is out of range,
/// [`OutputError::Io`] when the file cannot be written; the target is then left untouched.
pub fn write_plot(
    path: &Path,
    robot: &Robot,
    task: &Task,
    plan: &Plan,
    kind: PlotKind,
    width: Option<u32>,
) -> Result<(), OutputError> {
    write_plot_data(path, &PlotData::new(robot, task, plan), kind, width)
}
