//! Drawing [`PlotData`] with plotters' SVG backend: one function per kind of chart, laid out
//! top to bottom on one page, each returning the [`Panel`]s it drew.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::data::{JOINTS, PlotData, Runs};
use super::{Panel, Picture, PlotError, PlotKind};
use crate::language::{Obstacle, Shape};
use crate::math::{Real, Vector3};

/// Okabe–Ito, the colour-blind-safe palette, without its yellow (too pale on white): joint k
/// (and capsule k) is drawn in `PALETTE[k % 7]` in every plot.
pub const PALETTE: [(u8, u8, u8); 7] = [
    (0xE6, 0x9F, 0x00), // orange
    (0x56, 0xB4, 0xE9), // sky blue
    (0x00, 0x9E, 0x73), // bluish green
    (0x00, 0x72, 0xB2), // blue
    (0xD5, 0x5E, 0x00), // vermillion
    (0xCC, 0x79, 0xA7), // reddish purple
    (0x00, 0x00, 0x00), // black
];

/// The shade beyond a limit: a plain grey, so that a test can find it.
pub(crate) const LIMIT_SHADE: RGBColor = RGBColor(0xD0, 0xD0, 0xD0);
/// Limit lines and the safety distance.
const LIMIT_LINE: RGBColor = RGBColor(0xD5, 0x5E, 0x00);
/// Segment boundaries.
const BOUNDARY: RGBColor = RGBColor(0x80, 0x80, 0x80);
/// The light fill of the segments that feature a variable.
const SPAN_FILL: RGBColor = RGBColor(0xEE, 0xF4, 0xFA);
const GRID: RGBColor = RGBColor(0xE8, 0xE8, 0xE8);
const TEXT: RGBColor = RGBColor(0x20, 0x20, 0x20);

const WIDTH: u32 = 1000;
const FONT: &str = "sans-serif";
/// Most points drawn per line: more add bytes, not detail, at this width.
const MAX_POINTS: usize = 1200;
/// Header: caption line and one line per four segments of the key.
const LINE: u32 = 16;

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

fn colour(k: usize) -> RGBColor {
    let (r, g, b) = PALETTE[k % PALETTE.len()];
    RGBColor(r, g, b)
}

/// Draws the page for `kind`.
pub(super) fn picture(data: &PlotData, kind: PlotKind) -> Result<Picture, PlotError> {
    let kinds: Vec<PlotKind> = match kind {
        PlotKind::All => vec![
            PlotKind::Joints,
            PlotKind::Velocities,
            PlotKind::Featured,
            PlotKind::Distances,
            PlotKind::Wrist,
        ],
        one => vec![one],
    };
    let header = header_height(data);
    let heights: Vec<u32> = kinds.iter().map(|k| height(data, *k)).collect();
    let total = header + heights.iter().sum::<u32>();
    let mut svg = String::new();
    let mut panels = Vec::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, total)).into_drawing_area();
        let fail = |message: String| PlotError::Draw { kind: kind.name(), message };
        root.fill(&WHITE).map_err(|e| fail(e.to_string()))?;
        let (top, mut rest) = root.split_vertically(header);
        draw_header(&top, data).map_err(|e| fail(e.to_string()))?;
        for (k, h) in kinds.iter().zip(&heights) {
            let (area, below) = rest.split_vertically(*h);
            let drawn = match k {
                PlotKind::Joints => joints(&area, data),
                PlotKind::Velocities => velocities(&area, data),
                PlotKind::Featured => featured(&area, data),
                PlotKind::Distances => distances(&area, data),
                PlotKind::Wrist | PlotKind::All => wrist(&area, data),
            };
            panels.extend(drawn.map_err(|e| PlotError::Draw { kind: k.name(), message: e })?);
            rest = below;
        }
        root.present().map_err(|e| fail(e.to_string()))?;
    }
    Ok(Picture { svg, size: (WIDTH, total), panels })
}

/// The segment key in lines of at most four entries.
fn key_lines(data: &PlotData) -> Vec<String> {
    data.segments
        .chunks(4)
        .map(|c| {
            let items: Vec<String> =
                c.iter().map(|s| format!("{} = {}", s.number, s.label)).collect();
            items.join("    ")
        })
        .collect()
}

fn header_height(data: &PlotData) -> u32 {
    2 * LINE + 8 + LINE * key_lines(data).len() as u32
}

fn height(data: &PlotData, kind: PlotKind) -> u32 {
    match kind {
        PlotKind::Joints => 4 * 220,
        PlotKind::Velocities => 7 * 150,
        PlotKind::Featured => 240 * data.featured.len().max(1) as u32,
        PlotKind::Distances => 240 * data.obstacles.len().max(1) as u32,
        PlotKind::Wrist | PlotKind::All => wrist_side() + 60,
    }
}

fn draw_header(area: &Area, data: &PlotData) -> Result<(), String> {
    let style = |size: u32| TextStyle::from((FONT, size).into_font()).color(&TEXT);
    area.draw_text(&data.caption, &style(16), (12, 8)).map_err(|e| e.to_string())?;
    let mut y = 8 + 2 * LINE as i32;
    area.draw_text("segments (boundaries numbered in the charts):", &style(12), (12, y - 6))
        .map_err(|e| e.to_string())?;
    for line in key_lines(data) {
        y += LINE as i32;
        area.draw_text(&line, &style(12), (24, y - 6)).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// At most [`MAX_POINTS`] of `points`, evenly spaced, the last kept.
fn thin(points: &[(Real, Real)]) -> Vec<(Real, Real)> {
    let step = points.len().div_ceil(MAX_POINTS).max(1);
    let mut out: Vec<(Real, Real)> = points.iter().step_by(step).copied().collect();
    if let (Some(last), Some(kept)) = (points.last(), out.last()) {
        if last != kept {
            out.push(*last);
        }
    }
    out
}

/// A line of a time chart.
struct Line<'a> {
    label: Option<String>,
    colour: RGBColor,
    dashed: bool,
    runs: &'a Runs,
}

/// A chart over the plan's time.
struct TimeChart<'a> {
    title: String,
    kind: PlotKind,
    y_desc: String,
    lines: Vec<Line<'a>>,
    /// Value ranges shaded across the whole time (beyond the limits).
    bands: Vec<(Real, Real)>,
    /// Horizontal lines: value, colour, label.
    levels: Vec<(Real, RGBColor, Option<String>)>,
    /// Time spans lightly filled.
    spans: Vec<(Real, Real)>,
    /// Short dashed targets: start, end, value, colour.
    targets: Vec<(Real, Real, Real, RGBColor)>,
    /// Values that must be inside the y range besides the lines.
    include: Vec<Real>,
    /// Widen the y range by this share of its span, both ends.
    pad: Real,
    /// Whether the chart draws its own legend (else the page explains the lines once).
    legend: bool,
}

impl<'a> TimeChart<'a> {
    fn new(title: String, kind: PlotKind, y_desc: &str) -> Self {
        Self {
            title,
            kind,
            y_desc: y_desc.to_owned(),
            lines: Vec::new(),
            bands: Vec::new(),
            levels: Vec::new(),
            spans: Vec::new(),
            targets: Vec::new(),
            include: Vec::new(),
            pad: 0.06,
            legend: true,
        }
    }

    /// The y range: every line, level, target and included value, padded; never empty.
    fn y_range(&self) -> (Real, Real) {
        let values = self
            .lines
            .iter()
            .flat_map(|l| l.runs.iter().flatten().map(|p| p.1))
            .chain(self.levels.iter().map(|l| l.0))
            .chain(self.targets.iter().map(|t| t.2))
            .chain(self.include.iter().copied())
            .filter(|v| v.is_finite());
        let (lo, hi) =
            values.fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
        if !lo.is_finite() {
            return (-1.0, 1.0);
        }
        let span = (hi - lo).max(1e-6 * lo.abs().max(1.0)).max(1e-9);
        (lo - self.pad * span, hi + self.pad * span)
    }
}

/// Draws a time chart with the segment boundaries; returns its panel.
fn time_chart(area: &Area, data: &PlotData, chart: &TimeChart) -> Result<Panel, String> {
    let (t0, t1) = data.time_range();
    let (y0, y1) = chart.y_range();
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let mut c = ChartBuilder::on(area)
        .margin(8)
        .margin_right(16)
        .caption(&chart.title, (FONT, 13).into_font().color(&TEXT))
        .x_label_area_size(32)
        .y_label_area_size(62)
        .build_cartesian_2d(t0..t1, y0..y1)
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc("time (s)")
        .y_desc(chart.y_desc.as_str())
        .label_style((FONT, 11).into_font().color(&TEXT))
        .axis_desc_style((FONT, 12).into_font().color(&TEXT))
        .bold_line_style(GRID)
        .light_line_style(TRANSPARENT)
        .x_labels(10)
        .y_labels(6)
        .draw()
        .map_err(|e| err(&e))?;
    for (a, b) in &chart.spans {
        c.draw_series(std::iter::once(Rectangle::new([(*a, y0), (*b, y1)], SPAN_FILL.filled())))
            .map_err(|e| err(&e))?;
    }
    let mut banded = false;
    for (a, b) in &chart.bands {
        let (a, b) = (a.clamp(y0, y1), b.clamp(y0, y1));
        let drawn = c
            .draw_series(std::iter::once(Rectangle::new([(t0, a), (t1, b)], LIMIT_SHADE.filled())))
            .map_err(|e| err(&e))?;
        if !banded {
            drawn.label("beyond the limit").legend(|(x, y)| {
                Rectangle::new([(x, y - 5), (x + 16, y + 5)], LIMIT_SHADE.filled())
            });
            banded = true;
        }
    }
    for s in &data.segments {
        c.draw_series(std::iter::once(PathElement::new(
            vec![(s.start, y0), (s.start, y1)],
            BOUNDARY.stroke_width(1),
        )))
        .map_err(|e| err(&e))?;
        let at = c.backend_coord(&(s.start, y1));
        c.plotting_area()
            .strip_coord_spec()
            .draw_text(
                &s.number.to_string(),
                &TextStyle::from((FONT, 11).into_font()).color(&BOUNDARY),
                (at.0 + 3, at.1 + 2),
            )
            .map_err(|e| err(&e))?;
    }
    for (value, colour, label) in &chart.levels {
        let colour = *colour;
        let points = [(t0, *value), (t1, *value)];
        let drawn = c
            .draw_series(DashedLineSeries::new(points, 8, 5, colour.stroke_width(1)))
            .map_err(|e| err(&e))?;
        if let Some(label) = label {
            drawn.label(label.as_str()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(1))
            });
        }
    }
    for (a, b, value, colour) in &chart.targets {
        let points = [(*a, *value), (*b, *value)];
        c.draw_series(DashedLineSeries::new(points, 3, 3, colour.stroke_width(2)))
            .map_err(|e| err(&e))?;
    }
    for line in &chart.lines {
        let colour = line.colour;
        let style = colour.stroke_width(if line.dashed { 1 } else { 2 });
        for (i, run) in line.runs.iter().enumerate() {
            let points = thin(run);
            let drawn = if line.dashed {
                c.draw_series(DashedLineSeries::new(points, 6, 4, style)).map_err(|e| err(&e))?
            } else {
                c.draw_series(LineSeries::new(points, style)).map_err(|e| err(&e))?
            };
            if let (0, Some(label)) = (i, &line.label) {
                let dashed = line.dashed;
                drawn.label(label.as_str()).legend(move |(x, y)| {
                    if dashed {
                        PathElement::new(vec![(x, y), (x + 6, y)], colour.stroke_width(1))
                    } else {
                        PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2))
                    }
                });
            }
        }
    }
    if chart.legend {
        c.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(GRID)
            .label_font((FONT, 11).into_font().color(&TEXT))
            .draw()
            .map_err(|e| err(&e))?;
    }
    let (left, bottom) = c.backend_coord(&(t0, y0));
    let (right, top) = c.backend_coord(&(t1, y1));
    Ok(Panel {
        title: chart.title.clone(),
        kind: chart.kind,
        timed: true,
        x_pixels: (left, right),
        y_pixels: (bottom, top),
        x_range: (t0, t1),
        y_range: (y0, y1),
    })
}

/// Runs of one joint's values, scaled.
fn joint_runs(data: &PlotData, values: &[crate::math::JointVector], k: usize, scale: Real) -> Runs {
    vec![data.times.iter().zip(values).map(|(t, v)| (*t, v[k] * scale)).collect()]
}

/// Seven charts of q (deg), the range beyond each limit shaded.
fn joints(area: &Area, data: &PlotData) -> Result<Vec<Panel>, String> {
    let cells = area.split_evenly((4, 2));
    let mut panels = Vec::new();
    for (k, cell) in cells.iter().enumerate().take(JOINTS) {
        let runs = joint_runs(data, &data.q, k, Real::to_degrees(1.0));
        let (lower, upper) = (data.lower[k].to_degrees(), data.upper[k].to_degrees());
        let name = data.joint_names.get(k).map_or("?", String::as_str);
        let mut chart =
            TimeChart::new(format!("joint {} {name}: position", k + 1), PlotKind::Joints, "q (°)");
        chart.include = vec![lower, upper];
        chart.pad = 0.1;
        chart.legend = false;
        let (y0, y1) = chart.y_range_with(&runs);
        chart.bands = vec![(y0, lower), (upper, y1)];
        chart.lines.push(Line {
            label: Some("q".into()),
            colour: colour(k),
            dashed: false,
            runs: &runs,
        });
        panels.push(time_chart(cell, data, &chart)?);
    }
    if let Some(cell) = cells.get(JOINTS) {
        legend_cell(cell, data)?;
    }
    Ok(panels)
}

impl TimeChart<'_> {
    /// The y range once `runs` is drawn too.
    fn y_range_with(&self, runs: &Runs) -> (Real, Real) {
        let probe = TimeChart {
            lines: vec![Line { label: None, colour: BLACK, dashed: false, runs }],
            ..TimeChart::new(String::new(), self.kind, "")
        };
        let mut with = probe;
        with.include = self.include.clone();
        with.levels = self.levels.iter().map(|l| (l.0, l.1, None)).collect();
        with.pad = self.pad;
        with.y_range()
    }
}

/// The eighth cell of the joint grid: which colour is which joint.
fn legend_cell(area: &Area, data: &PlotData) -> Result<(), String> {
    let style = TextStyle::from((FONT, 12).into_font()).color(&TEXT);
    area.draw_text("joints (the same colours in every plot):", &style, (20, 16))
        .map_err(|e| e.to_string())?;
    for (k, name) in data.joint_names.iter().enumerate().take(JOINTS) {
        let y = 40 + 20 * k as i32;
        area.draw(&PathElement::new(vec![(24, y), (48, y)], colour(k).stroke_width(3)))
            .map_err(|e| e.to_string())?;
        area.draw_text(&format!("{} {name}", k + 1), &style, (56, y - 6))
            .map_err(|e| e.to_string())?;
    }
    let y = 40 + 20 * JOINTS as i32;
    area.draw(&Rectangle::new([(24, y - 5), (48, y + 5)], LIMIT_SHADE.filled()))
        .map_err(|e| e.to_string())?;
    area.draw_text("beyond a position or speed limit", &style, (56, y - 6))
        .map_err(|e| e.to_string())?;
    let y = y + 20;
    area.draw(&PathElement::new(vec![(24, y), (48, y)], LIMIT_LINE.stroke_width(1)))
        .map_err(|e| e.to_string())?;
    area.draw_text("speed limit (velocity charts)", &style, (56, y - 6))
        .map_err(|e| e.to_string())?;
    let y = y + 20;
    area.draw(&PathElement::new(vec![(24, y - 6), (24, y + 6)], BOUNDARY.stroke_width(1)))
        .map_err(|e| e.to_string())?;
    area.draw_text("segment boundary, numbered as in the header", &style, (56, y - 6))
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// Per joint: q' against ± the speed limit (rad/s), and q'' (rad/s²).
fn velocities(area: &Area, data: &PlotData) -> Result<Vec<Panel>, String> {
    let cells = area.split_evenly((JOINTS, 2));
    let mut panels = Vec::new();
    for k in 0..JOINTS {
        let name = data.joint_names.get(k).map_or("?", String::as_str);
        let speed = data.speed[k];
        let runs = joint_runs(data, &data.qd, k, 1.0);
        if let Some(cell) = cells.get(2 * k) {
            let mut chart = TimeChart::new(
                format!("joint {} {name}: velocity", k + 1),
                PlotKind::Velocities,
                "q' (rad/s)",
            );
            chart.levels =
                vec![(speed, LIMIT_LINE, Some("speed limit".into())), (-speed, LIMIT_LINE, None)];
            chart.pad = 0.1;
            chart.legend = false;
            let (y0, y1) = chart.y_range_with(&runs);
            chart.bands = vec![(y0, -speed), (speed, y1)];
            chart.lines.push(Line {
                label: Some("q'".into()),
                colour: colour(k),
                dashed: false,
                runs: &runs,
            });
            panels.push(time_chart(cell, data, &chart)?);
        }
        let runs = joint_runs(data, &data.qdd, k, 1.0);
        if let Some(cell) = cells.get(2 * k + 1) {
            let mut chart = TimeChart::new(
                format!("joint {} {name}: acceleration", k + 1),
                PlotKind::Velocities,
                "q'' (rad/s²)",
            );
            chart.include = vec![0.0];
            chart.legend = false;
            chart.lines.push(Line {
                label: Some("q''".into()),
                colour: colour(k),
                dashed: false,
                runs: &runs,
            });
            panels.push(time_chart(cell, data, &chart)?);
        }
    }
    Ok(panels)
}

/// One chart per featured variable: the plan solid, the reference dashed, goals dotted.
fn featured(area: &Area, data: &PlotData) -> Result<Vec<Panel>, String> {
    if data.featured.is_empty() {
        return note(area, "no segment features a variable");
    }
    let cells = area.split_evenly((data.featured.len(), 1));
    let mut panels = Vec::new();
    for (panel, cell) in data.featured.iter().zip(&cells) {
        let title = format!(
            "{}: planned (solid), reference (dashed), goal (dotted); featuring segments shaded",
            panel.variable.symbol()
        );
        let mut chart = TimeChart::new(title, PlotKind::Featured, &panel.axis);
        chart.spans = panel.spans.clone();
        for (k, (name, runs)) in panel.actual.iter().enumerate() {
            chart.lines.push(Line {
                label: Some(name.clone()),
                colour: colour(k),
                dashed: false,
                runs,
            });
        }
        for (k, (name, runs)) in panel.reference.iter().enumerate() {
            let label = Some(format!("{name} reference"));
            chart.lines.push(Line { label, colour: colour(k), dashed: true, runs });
        }
        chart.targets = panel.targets.iter().map(|(a, b, v, k)| (*a, *b, *v, colour(*k))).collect();
        panels.push(time_chart(cell, data, &chart)?);
    }
    Ok(panels)
}

/// One chart per obstacle: each moving capsule's distance (mm), the safety distance dashed.
fn distances(area: &Area, data: &PlotData) -> Result<Vec<Panel>, String> {
    if data.obstacles.is_empty() {
        return note(area, "no obstacle in the scene: no clearance to show");
    }
    let cells = area.split_evenly((data.obstacles.len(), 1));
    let mm: Vec<(usize, String, Runs)> = data
        .distances
        .iter()
        .map(|d| {
            let runs =
                d.runs.iter().map(|r| r.iter().map(|(t, v)| (*t, v * 1e3)).collect()).collect();
            (d.capsule_index, format!("{}|{}", d.obstacle, d.capsule), runs)
        })
        .collect();
    let mut panels = Vec::new();
    for (obstacle, cell) in data.obstacles.iter().zip(&cells) {
        let title =
            format!("clearance to `{}` (a gap: the action touches it on purpose)", obstacle.name);
        let mut chart = TimeChart::new(title, PlotKind::Distances, "distance (mm)");
        let safety = data.safety_distance * 1e3;
        chart.levels = vec![(safety, LIMIT_LINE, Some(format!("safety distance {safety:.0} mm")))];
        chart.include = vec![0.0];
        let prefix = format!("{}|", obstacle.name);
        for (k, name, runs) in &mm {
            if let Some(capsule) = name.strip_prefix(&prefix) {
                chart.lines.push(Line {
                    label: Some(capsule.to_owned()),
                    colour: colour(*k),
                    dashed: false,
                    runs,
                });
            }
        }
        let (y0, _) = chart.y_range();
        chart.bands = vec![(y0, 0.0)];
        panels.push(time_chart(cell, data, &chart)?);
    }
    Ok(panels)
}

/// A centred note where a chart would be.
fn note(area: &Area, text: &str) -> Result<Vec<Panel>, String> {
    let (w, h) = area.dim_in_pixel();
    let style = TextStyle::from((FONT, 13).into_font()).color(&TEXT);
    area.draw_text(text, &style, (w as i32 / 2 - 150, h as i32 / 2)).map_err(|e| e.to_string())?;
    Ok(Vec::new())
}

/// Margins of an orthographic view: around, its title above, its label areas (px).
const MARGIN: u32 = 8;
const VIEW_TITLE: u32 = 28;
const VIEW_X_LABELS: u32 = 32;
const VIEW_Y_LABELS: u32 = 48;

/// Side of one orthographic view, label areas and caption included.
fn wrist_side() -> u32 {
    WIDTH / 3
}

/// The three views: (title, index of the horizontal and vertical axis, their names).
const VIEWS: [(&str, usize, usize, &str, &str); 3] = [
    ("top view (looking down -z)", 0, 1, "x (m)", "y (m)"),
    ("front view (looking along -x)", 1, 2, "y (m)", "z (m)"),
    ("side view (looking along +y)", 0, 2, "x (m)", "z (m)"),
];

/// The wrist path (planned solid, reference dashed) in three views with the obstacles'
/// outlines, at one scale in both axes of a view.
fn wrist(area: &Area, data: &PlotData) -> Result<Vec<Panel>, String> {
    let (top, bottom) = area.split_vertically(wrist_side());
    let cells = top.split_evenly((1, 3));
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let mut panels = Vec::new();
    for ((title, h, v, hx, vx), cell) in VIEWS.iter().zip(&cells) {
        let points =
            |p: &[Vector3]| -> Vec<(Real, Real)> { p.iter().map(|p| (p[*h], p[*v])).collect() };
        let planned = points(&data.wrist);
        let reference = points(&data.wrist_reference);
        let outlines: Vec<Vec<(Real, Real)>> =
            data.obstacles.iter().flat_map(|o| outline(o, *h, *v)).collect();
        let (w, h_px) = cell.dim_in_pixel();
        let plot_w = Real::from(w.saturating_sub(2 * MARGIN + VIEW_Y_LABELS).max(1));
        let plot_h = Real::from(h_px.saturating_sub(VIEW_TITLE + MARGIN + VIEW_X_LABELS).max(1));
        let ((x0, x1), (y0, y1)) = equal_scale_range(
            planned.iter().chain(&reference).chain(outlines.iter().flatten()),
            plot_w / plot_h,
        );
        cell.draw_text(
            title,
            &TextStyle::from((FONT, 13).into_font()).color(&TEXT),
            (VIEW_Y_LABELS as i32, 8),
        )
        .map_err(|e| err(&e))?;
        let mut c = ChartBuilder::on(cell)
            .margin(MARGIN)
            .margin_top(VIEW_TITLE)
            .x_label_area_size(VIEW_X_LABELS)
            .y_label_area_size(VIEW_Y_LABELS)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| err(&e))?;
        c.configure_mesh()
            .x_desc(*hx)
            .y_desc(*vx)
            .label_style((FONT, 11).into_font().color(&TEXT))
            .axis_desc_style((FONT, 12).into_font().color(&TEXT))
            .bold_line_style(GRID)
            .light_line_style(TRANSPARENT)
            .x_labels(5)
            .y_labels(5)
            .draw()
            .map_err(|e| err(&e))?;
        for o in &outlines {
            c.draw_series(std::iter::once(Polygon::new(o.clone(), LIMIT_SHADE.mix(0.6).filled())))
                .map_err(|e| err(&e))?;
            let mut closed = o.clone();
            if let Some(first) = o.first() {
                closed.push(*first);
            }
            c.draw_series(std::iter::once(PathElement::new(closed, BOUNDARY.stroke_width(1))))
                .map_err(|e| err(&e))?;
        }
        c.draw_series(DashedLineSeries::new(thin(&reference), 6, 4, colour(0).stroke_width(1)))
            .map_err(|e| err(&e))?;
        c.draw_series(LineSeries::new(thin(&planned), colour(3).stroke_width(2)))
            .map_err(|e| err(&e))?;
        if let (Some(start), Some(end)) = (planned.first(), planned.last()) {
            c.draw_series([
                Circle::new(*start, 4, colour(2).filled()),
                Circle::new(*end, 4, colour(4).filled()),
            ])
            .map_err(|e| err(&e))?;
        }
        let (left, bottom) = c.backend_coord(&(x0, y0));
        let (right, top) = c.backend_coord(&(x1, y1));
        panels.push(Panel {
            title: (*title).to_owned(),
            kind: PlotKind::Wrist,
            timed: false,
            x_pixels: (left, right),
            y_pixels: (bottom, top),
            x_range: (x0, x1),
            y_range: (y0, y1),
        });
    }
    wrist_legend(&bottom)?;
    Ok(panels)
}

fn wrist_legend(area: &Area) -> Result<(), String> {
    let style = TextStyle::from((FONT, 12).into_font()).color(&TEXT);
    let items: [(&str, RGBColor, bool); 3] = [
        ("planned Pw", colour(3), false),
        ("reference Pw", colour(0), true),
        ("obstacle outline", BOUNDARY, false),
    ];
    for (i, (label, c, dashed)) in items.iter().enumerate() {
        let x = 60 + 220 * i as i32;
        let line = if *dashed { vec![(x, 20), (x + 8, 20)] } else { vec![(x, 20), (x + 24, 20)] };
        area.draw(&PathElement::new(line, c.stroke_width(2))).map_err(|e| e.to_string())?;
        area.draw_text(label, &style, (x + 32, 14)).map_err(|e| e.to_string())?;
    }
    let markers = [("start", colour(2)), ("end", colour(4))];
    for (i, (label, c)) in markers.iter().enumerate() {
        let x = 720 + 110 * i as i32;
        area.draw(&Circle::new((x, 20), 4, c.filled())).map_err(|e| e.to_string())?;
        area.draw_text(label, &style, (x + 10, 14)).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// A range around the points with `aspect` = x span / y span, so that a chart whose plotting
/// area has that width / height draws both axes at one scale; padded.
fn equal_scale_range<'p>(
    points: impl Iterator<Item = &'p (Real, Real)>,
    aspect: Real,
) -> ((Real, Real), (Real, Real)) {
    let mut lo = (Real::INFINITY, Real::INFINITY);
    let mut hi = (Real::NEG_INFINITY, Real::NEG_INFINITY);
    for (x, y) in points.filter(|(x, y)| x.is_finite() && y.is_finite()) {
        lo = (lo.0.min(*x), lo.1.min(*y));
        hi = (hi.0.max(*x), hi.1.max(*y));
    }
    if !lo.0.is_finite() {
        lo = (-0.5, -0.5);
        hi = (0.5, 0.5);
    }
    let half_y = 0.55 * ((hi.0 - lo.0) / aspect).max(hi.1 - lo.1).max(0.05);
    let half_x = half_y * aspect;
    let centre = (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1));
    ((centre.0 - half_x, centre.0 + half_x), (centre.1 - half_y, centre.1 + half_y))
}

/// Points around a circle.
fn circle(centre: (Real, Real), radius: Real) -> Vec<(Real, Real)> {
    (0..48)
        .map(|i| {
            let a = std::f64::consts::TAU * i as Real / 48.0;
            (centre.0 + radius * a.cos(), centre.1 + radius * a.sin())
        })
        .collect()
}

/// The outline of an obstacle projected on the plane of axes `h` and `v` (a capsule as the
/// hull of its end circles).
pub fn outline(o: &Obstacle, h: usize, v: usize) -> Vec<Vec<(Real, Real)>> {
    let at = |p: &Vector3| (p[h], p[v]);
    match &o.shape {
        Shape::Box { center, size, rotation } => {
            let corners =
                (0..8).map(|k| {
                    let corner = Vector3::from_fn(|i, _| {
                        if k >> i & 1 == 1 { 0.5 * size[i] } else { -0.5 * size[i] }
                    });
                    at(&(center + rotation * corner))
                });
            vec![hull(corners.collect())]
        }
        Shape::Sphere { center, radius } => vec![circle(at(center), *radius)],
        Shape::Cylinder { center, radius, height, rotation } => {
            // The hull of the two rims.
            let rims = (0..96).map(|k| {
                let a = std::f64::consts::TAU * (k % 48) as Real / 48.0;
                let z = if k < 48 { -0.5 * height } else { 0.5 * height };
                let local = Vector3::new(radius * a.cos(), radius * a.sin(), z);
                at(&(center + rotation * local))
            });
            vec![hull(rims.collect())]
        }
        Shape::Capsule { a, b, radius } => vec![stadium(at(a), at(b), *radius)],
    }
}

/// The convex hull of `points`, counter-clockwise (Andrew's monotone chain).
fn hull(mut points: Vec<(Real, Real)>) -> Vec<(Real, Real)> {
    points.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let turn = |o: (Real, Real), a: (Real, Real), b: (Real, Real)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut out: Vec<(Real, Real)> = Vec::with_capacity(points.len() + 1);
    for pass in [false, true] {
        let start = out.len();
        let ordered: Box<dyn Iterator<Item = &(Real, Real)>> =
            if pass { Box::new(points.iter().rev()) } else { Box::new(points.iter()) };
        for &p in ordered {
            while out.len() >= start + 2 && turn(out[out.len() - 2], out[out.len() - 1], p) <= 1e-15
            {
                out.pop();
            }
            out.push(p);
        }
        // Each chain's last point starts the other.
        out.pop();
    }
    out
}

/// The outline of a segment thickened by `radius`: two half circles joined.
fn stadium(a: (Real, Real), b: (Real, Real), radius: Real) -> Vec<(Real, Real)> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let heading = if dx.hypot(dy) < 1e-12 { 0.0 } else { dy.atan2(dx) };
    let half = |centre: (Real, Real), from: Real| {
        (0..=24).map(move |i| {
            let a = from + std::f64::consts::PI * i as Real / 24.0;
            (centre.0 + radius * a.cos(), centre.1 + radius * a.sin())
        })
    };
    let quarter = std::f64::consts::FRAC_PI_2;
    half(b, heading - quarter).chain(half(a, heading + quarter)).collect()
}
