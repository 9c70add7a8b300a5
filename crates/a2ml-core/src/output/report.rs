//! A plan as one self-contained HTML page (issue 18): the task text, its decomposition, the
//! per-segment table with statuses and warnings, the human-likeness measures (Fitts, HAMP
//! patterns, RULA, speed shape, jerk: `a2ml analyze`'s), every plot, the swivel map of each
//! segment the map solver planned, and the motion itself (the arm's capsules and the
//! obstacles in a front and a top view) played back with a play button and a time slider that
//! also marks the time on the plots.
//!
//! Entry points: [`report_html`], [`write_report`]. Nothing is fetched: styles, pictures and
//! the small script are inline; light and dark follow `prefers-color-scheme`.

use std::fmt::Write as _;
use std::path::Path;

use super::OutputError;
use super::plot::{Panel, PlotData, PlotError, PlotKind, plot_data_svg};
use crate::collision::arm_capsules;
use crate::kinematics::arm_pose;
use crate::language::{Obstacle, Task};
use crate::math::{Real, Vector3};
use crate::metrics::{self, MetricsOptions, ScoreSummary, Span, SpanMetrics};
use crate::robot::Robot;
use crate::solve::{Plan, SegmentReport};

/// Frames per second of the motion's playback data.
pub const MOTION_RATE: Real = 25.0;

/// The two views of the motion: (title, horizontal axis, vertical axis, their names).
const MOTION_VIEWS: [(&str, usize, usize, &str, &str); 2] =
    [("front (looking along −x)", 1, 2, "y", "z"), ("top (looking down −z)", 0, 1, "x", "y")];

/// What goes into a report besides the plan.
#[derive(Debug, Clone, Copy)]
pub struct ReportInput<'a> {
    /// The robot the plan was made for.
    pub robot: &'a Robot,
    /// The task, as validated.
    pub task: &'a Task,
    /// The task file's text.
    pub source: &'a str,
    /// The plan.
    pub plan: &'a Plan,
    /// The decomposition as `a2ml explain` prints it, if the caller has it.
    pub decomposition: Option<&'a str>,
}

/// The report as one HTML document.
///
/// # Errors
/// [`PlotError`] when a picture cannot be drawn.
pub fn report_html(input: &ReportInput) -> Result<String, PlotError> {
    let data = PlotData::new(input.robot, input.task, input.plan);
    let picture = plot_data_svg(&data, PlotKind::All)?;
    let plan = input.plan;
    let mut out = String::with_capacity(picture.svg.len() + 200_000);
    let title = format!("a2ml report: {}", plan.task);
    let _ = write!(
        out,
        "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<main>\n",
        escape(&title)
    );
    let _ = write!(
        out,
        "<h1>{}</h1>\n<p class=\"caption\">{}</p>\n",
        escape(&plan.task),
        escape(&data.caption)
    );
    summary(&mut out, input);
    segments_table(&mut out, &plan.segments);
    human_likeness(&mut out, input);
    motion(&mut out, input, &data);
    let _ = write!(
        out,
        "<section id=\"plots\">\n<h2>Plots</h2>\n<p>The grey line marks the time of the \
         motion above.</p>\n<div class=\"figure\">{}</div>\n</section>\n",
        with_time_marks(&picture.svg, &picture.panels)
    );
    swivel_maps(&mut out, plan)?;
    if let Some(text) = input.decomposition {
        let _ = write!(
            out,
            "<section id=\"decomposition\">\n<h2>Decomposition</h2>\n<pre>{}</pre>\n</section>\n",
            escape(text)
        );
    }
    let _ = write!(
        out,
        "<section id=\"task\">\n<h2>Task</h2>\n<pre>{}</pre>\n</section>\n",
        escape(input.source)
    );
    let _ = write!(
        out,
        "<footer>a2ml {}</footer>\n</main>\n<script>{SCRIPT}</script>\n</body>\n</html>\n",
        env!("CARGO_PKG_VERSION")
    );
    Ok(out)
}

/// A plan in a notebook: its caption, the segment table and the joint plot, as one HTML
/// fragment that scales to the cell.
///
/// # Errors
/// [`PlotError`] when the joint plot cannot be drawn.
pub fn notebook_html(robot: &Robot, task: &Task, plan: &Plan) -> Result<String, PlotError> {
    let data = PlotData::new(robot, task, plan);
    let picture = plot_data_svg(&data, PlotKind::Joints)?;
    let mut out = format!(
        "<div class=\"a2ml-plan\"><p><strong>{}</strong> — {} s, {} samples, {}</p>\n",
        escape(&data.caption),
        fixed(plan.trajectory.duration(), 3),
        plan.trajectory.len(),
        if plan.reached() { "every goal reached" } else { "a goal missed or a hard path left" }
    );
    segments_table(&mut out, &plan.segments);
    let _ = write!(
        out,
        "<div style=\"background:#fff;max-width:1000px\">{}</div></div>",
        responsive(&picture.svg).replacen("class=\"plot\"", "style=\"width:100%;height:auto\"", 1)
    );
    Ok(out)
}

/// Writes the report through a temporary file renamed into place.
///
/// # Errors
/// [`OutputError::Plot`] when a picture cannot be drawn, [`OutputError::Io`] when the file
/// cannot be written; the target is then left untouched.
pub fn write_report(path: &Path, input: &ReportInput) -> Result<(), OutputError> {
    let html = report_html(input).map_err(|e| OutputError::Plot {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    super::write_text(path, &html)
}

/// Text safe inside HTML elements and attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// `ok`, `stalled`, `missed` or `off path`, with `auto`'s reason to go on from the QP.
pub fn status(s: &SegmentReport) -> String {
    let outcome = if !s.path_kept {
        "off path"
    } else if s.reached {
        "ok"
    } else if s.stalled {
        "stalled"
    } else {
        "missed"
    };
    s.fallback.map_or_else(|| outcome.to_owned(), |why| format!("{outcome} ({why})"))
}

/// The plan's outcome in a sentence and its warnings.
fn summary(out: &mut String, input: &ReportInput) {
    let plan = input.plan;
    let verdict = if plan.reached() {
        "<strong class=\"ok\">Every segment reached its goals and kept its hard path.</strong>"
    } else {
        "<strong class=\"bad\">Some segment missed its goal or left its hard path.</strong>"
    };
    let _ = write!(
        out,
        "<section id=\"summary\">\n<h2>Summary</h2>\n<p>{verdict} {} s of motion, {} samples at \
         {} Hz, {} segments; safety distance {} mm.</p>\n",
        fixed(plan.trajectory.duration(), 3),
        plan.trajectory.len(),
        plan.rate,
        plan.segments.len(),
        fixed(plan.safety_distance * 1e3, 1),
    );
    if plan.warnings.is_empty() {
        out.push_str("<p>No warnings.</p>\n");
    } else {
        out.push_str("<h3>Warnings</h3>\n<ul class=\"warnings\">\n");
        for w in &plan.warnings {
            let _ = writeln!(out, "<li>{}</li>", escape(&w.to_string()));
        }
        out.push_str("</ul>\n");
    }
    out.push_str("</section>\n");
}

/// `x` with `decimals` decimals, never `-0.0`.
fn fixed(x: Real, decimals: usize) -> String {
    let text = format!("{:.decimals$}", x + 0.0);
    if text.starts_with('-') && text[1..].chars().all(|c| c == '0' || c == '.') {
        text[1..].to_owned()
    } else {
        text
    }
}

/// A number cell: the value shown to `decimals`, the exact value in `data-value`.
fn number_cell(value: Real, decimals: usize) -> String {
    format!("<td class=\"n\" data-value=\"{value:?}\">{}</td>", fixed(value, decimals))
}

/// The per-segment table, one row per segment.
pub fn segments_table(out: &mut String, segments: &[SegmentReport]) {
    out.push_str(
        "<section id=\"segments\">\n<h2>Segments</h2>\n<div class=\"scroll\">\n\
         <table class=\"segments\">\n<thead><tr><th>action</th><th>segment</th><th>type</th>\
         <th>pattern</th><th>space</th><th>solver</th><th>start (s)</th><th>end (s)</th>\
         <th>final errors</th><th>clearance (mm)</th><th>limit margin (°)</th>\
         <th>status</th></tr></thead>\n<tbody>\n",
    );
    for s in segments {
        let errors: Vec<String> =
            s.errors.iter().map(|e| e.variable.error_text(e.error, 2)).collect();
        let clearance = s.clearance.as_ref().map_or_else(
            || "<td class=\"n\">-</td>".to_owned(),
            |c| number_cell(c.distance * 1e3, 1),
        );
        let status = status(s);
        let class = if status.starts_with("ok") { "ok" } else { "bad" };
        let _ = writeln!(
            out,
            "<tr><td>{}</td><td class=\"n\">{}</td><td>{}</td><td>{}</td><td>{}</td>\
             <td>{}</td>{}{}<td>{}</td>{clearance}{}<td class=\"{class}\">{}</td></tr>",
            escape(&s.action),
            s.segment + 1,
            s.action_type.map_or("-", |t| t.as_str()),
            s.pattern,
            s.space,
            s.solver,
            number_cell(s.start, 3),
            number_cell(s.end, 3),
            escape(&errors.join(", ")),
            number_cell(s.limit_margin.to_degrees(), 2),
            escape(&status),
        );
    }
    out.push_str("</tbody>\n</table>\n</div>\n</section>\n");
}

/// `mean / max` of a score, or `-` where no frame was scored.
fn score(s: Option<ScoreSummary>) -> String {
    s.map_or_else(|| "-".to_owned(), |s| format!("{} / {}", fixed(s.mean, 2), s.max))
}

/// One row of the human-likeness table.
fn measures_row(out: &mut String, m: &SpanMetrics) {
    let hamp =
        |h: &metrics::pattern::Hamp| if h.is_empty() { "-".to_owned() } else { h.to_string() };
    let _ = writeln!(
        out,
        "<tr><td>{}</td>{}{}<td>{}</td><td>{}</td>{}<td class=\"n\">{}</td>\
         <td class=\"n\">{}</td>{}{}<td class=\"n\">{}</td>{}</tr>",
        escape(&m.span.label),
        number_cell(m.fitts.duration, 3),
        number_cell(m.fitts.ratio, 2),
        escape(&hamp(&m.patterns.phase1.hamp)),
        escape(&hamp(&m.patterns.phase2.hamp)),
        number_cell(m.patterns.swivel_ratio, 2),
        score(m.rula),
        score(m.rula_sum),
        number_cell(m.wrist_speed.peak_time_ratio, 2),
        number_cell(m.wrist_speed.symmetry, 2),
        m.speed_peaks,
        number_cell(m.wrist_jerk, 1),
    );
}

/// The human-likeness measures of each segment and of the whole motion, as `a2ml analyze`
/// gives them.
fn human_likeness(out: &mut String, input: &ReportInput) {
    let spans = Span::of_plan(input.plan);
    let analysis =
        metrics::analyze(input.robot, &input.plan.trajectory, &spans, &MetricsOptions::default());
    out.push_str(
        "<section id=\"human-likeness\">\n<h2>Human-likeness</h2>\n<p>Per segment (docs/metrics.md): \
         T against Fitts' law, the HAMP patterns of the two phases and the swivel share R_Φ, \
         RULA (arm and wrist score A; upper arm + lower arm + wrist) mean / max, the wrist \
         speed's peak time over T and symmetry, its peaks (1 is human-like) and normalised \
         jerk.</p>\n<div class=\"scroll\">\n<table class=\"measures\">\n<thead><tr><th>span</th>\
         <th>T (s)</th><th>×Fitts</th><th>HAMP 1</th><th>HAMP 2</th><th>R_Φ</th><th>RULA A</th>\
         <th>UA+LA+W</th><th>peak t/T</th><th>symmetry</th><th>peaks</th><th>jerk</th></tr>\
         </thead>\n<tbody>\n",
    );
    for m in analysis.segments.iter().chain(std::iter::once(&analysis.whole)) {
        measures_row(out, m);
    }
    out.push_str("</tbody>\n</table>\n</div>\n</section>\n");
}

/// The swivel map of every segment the map solver planned: the figure `a2ml map` draws, from
/// what the plan kept of the map.
fn swivel_maps(out: &mut String, plan: &Plan) -> Result<(), PlotError> {
    if plan.swivel_maps.is_empty() {
        return Ok(());
    }
    out.push_str(
        "<section id=\"swivel-maps\">\n<h2>Swivel maps</h2>\n<p>Each segment the swivel map \
         solved: time from the segment's start as solved (s) against the swivel angle; coloured \
         cells are forbidden (by an obstacle, the joint limits or self-collision), the line is \
         the profile the planner chose through the free ones.</p>\n",
    );
    for entry in &plan.swivel_maps {
        let Some(s) = plan.segments.get(entry.segment) else { continue };
        let title = format!("{} — action {}, segment {}", plan.task, s.action, s.segment + 1);
        let svg = super::swivel_map_svg(&entry.map, &title)
            .map_err(|message| PlotError::Draw { kind: "swivel map", message })?;
        let slowed = if s.slowed_down > 1.0 {
            format!(
                " The plan slowed this segment by ×{} to keep the joint limits.",
                fixed(s.slowed_down, 3)
            )
        } else {
            String::new()
        };
        let free = 100.0
            - 100.0 * entry.map.runs.iter().map(|r| Real::from(r.count)).sum::<Real>()
                / entry.map.times.len().saturating_mul(entry.map.angle_steps).max(1) as Real;
        let _ = writeln!(
            out,
            "<figure class=\"map\" data-segment=\"{}\"><figcaption>{} — {} × {} cells, {} % free, \
             plan time {} s to {} s.{slowed}</figcaption><div class=\"figure\">{}</div></figure>",
            entry.segment,
            escape(&title),
            entry.map.times.len(),
            entry.map.angle_steps,
            fixed(free, 1),
            fixed(s.start, 3),
            fixed(s.end, 3),
            responsive(&svg),
        );
    }
    out.push_str("</section>\n");
    Ok(())
}

/// The plot page with a time mark (a vertical line) in each timed chart, placed by the script.
fn with_time_marks(svg: &str, panels: &[Panel]) -> String {
    let mut marks = String::new();
    for p in panels.iter().filter(|p| p.timed) {
        let _ = write!(
            marks,
            "<line class=\"now\" x1=\"{x}\" x2=\"{x}\" y1=\"{}\" y2=\"{}\" data-x0=\"{}\" \
             data-x1=\"{}\" data-t0=\"{:?}\" data-t1=\"{:?}\"/>",
            p.y_pixels.1,
            p.y_pixels.0,
            p.x_pixels.0,
            p.x_pixels.1,
            p.x_range.0,
            p.x_range.1,
            x = p.x_pixels.0,
        );
    }
    let svg = responsive(svg);
    match svg.rfind("</svg>") {
        Some(end) => format!("{}{marks}{}", &svg[..end], &svg[end..]),
        None => svg,
    }
}

/// The SVG scaled to its container: a viewBox from its size, the fixed size dropped.
fn responsive(svg: &str) -> String {
    let Some(open_end) = svg.find('>') else { return svg.to_owned() };
    let open = &svg[..open_end];
    if open.contains("viewBox") {
        return svg.to_owned();
    }
    let attribute = |name: &str| {
        let key = format!("{name}=\"");
        let start = open.find(&key)? + key.len();
        let len = open[start..].find('"')?;
        Some(open[start..start + len].to_owned())
    };
    match (attribute("width"), attribute("height")) {
        (Some(w), Some(h)) => {
            let open = open.replacen(&format!("width=\"{w}\""), "", 1).replacen(
                &format!("height=\"{h}\""),
                "",
                1,
            );
            format!("{open} viewBox=\"0 0 {w} {h}\" class=\"plot\"{}", &svg[open_end..])
        }
        _ => svg.to_owned(),
    }
}

/// The motion: both views as SVG with one element per capsule, the frames as JSON for the
/// script, and the controls.
fn motion(out: &mut String, input: &ReportInput, data: &PlotData) {
    let (robot, plan) = (input.robot, input.plan);
    let (t0, t1) = (plan.trajectory.start(), plan.trajectory.end());
    let count = (((t1 - t0) * MOTION_RATE).ceil() as usize).max(1);
    let times: Vec<Real> = (0..=count).map(|i| (t0 + i as Real / MOTION_RATE).min(t1)).collect();
    // Per frame, per capsule: both ends (m, {b}).
    let frames: Vec<Vec<(Vector3, Vector3)>> = times
        .iter()
        .map(|&t| {
            let (q, _) = plan.trajectory.sample(t);
            arm_capsules(robot, &arm_pose(robot, &q)).into_iter().map(|c| (c.a, c.b)).collect()
        })
        .collect();
    let radii: Vec<Real> = robot.capsules.iter().map(|c| c.radius).collect();
    out.push_str(
        "<section id=\"motion\">\n<h2>Motion</h2>\n<p>The arm's collision capsules and the \
         obstacles, in {b} (m).</p>\n<div class=\"views\">\n",
    );
    for (view, (title, h, v, hx, vx)) in MOTION_VIEWS.iter().enumerate() {
        let bounds = view_bounds(&frames, &radii, &data.obstacles, &data.wrist, *h, *v);
        let first = frames.first().map_or(&[][..], Vec::as_slice);
        view_svg(out, view, title, (*h, *v), (hx, vx), bounds, &radii, first, data);
    }
    out.push_str(
        "</div>\n<div class=\"controls\"><button id=\"play\" type=\"button\">play</button>",
    );
    let _ = writeln!(
        out,
        "<input id=\"time\" type=\"range\" min=\"0\" max=\"{count}\" value=\"0\" step=\"1\" \
         aria-label=\"time\"><output id=\"clock\">{} s</output></div>",
        fixed(t0, 2)
    );
    // Frames: t, then x y z of both ends of every capsule, rounded to 0.1 mm.
    out.push_str("<script type=\"application/json\" id=\"frames\">{\"t\":[");
    let numbers = |out: &mut String, values: &mut dyn Iterator<Item = Real>| {
        let mut first = true;
        for v in values {
            if !first {
                out.push(',');
            }
            first = false;
            let _ = write!(out, "{}", (v * 1e4).round() / 1e4 + 0.0);
        }
    };
    numbers(out, &mut times.iter().copied());
    out.push_str("],\"ends\":[");
    for (i, frame) in frames.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        out.push('[');
        numbers(out, &mut frame.iter().flat_map(|(a, b)| [a.x, a.y, a.z, b.x, b.y, b.z]));
        out.push(']');
    }
    out.push_str("]}</script>\n</section>\n");
}

/// The view's extent (min h, min v, max h, max v) over every frame, obstacle and the wrist
/// path, padded.
fn view_bounds(
    frames: &[Vec<(Vector3, Vector3)>],
    radii: &[Real],
    obstacles: &[Obstacle],
    wrist: &[Vector3],
    h: usize,
    v: usize,
) -> (Real, Real, Real, Real) {
    let mut b = (Real::INFINITY, Real::INFINITY, Real::NEG_INFINITY, Real::NEG_INFINITY);
    let mut grow = |x: Real, y: Real, r: Real| {
        b = (b.0.min(x - r), b.1.min(y - r), b.2.max(x + r), b.3.max(y + r));
    };
    for frame in frames {
        for ((a, e), r) in frame.iter().zip(radii) {
            grow(a[h], a[v], *r);
            grow(e[h], e[v], *r);
        }
    }
    for o in obstacles {
        for ring in super::plot::outline(o, h, v) {
            for (x, y) in ring {
                grow(x, y, 0.0);
            }
        }
    }
    for p in wrist {
        grow(p[h], p[v], 0.0);
    }
    if !b.0.is_finite() {
        return (-1.0, -1.0, 1.0, 1.0);
    }
    let pad = 0.05 * (b.2 - b.0).max(b.3 - b.1).max(0.1);
    (b.0 - pad, b.1 - pad, b.2 + pad, b.3 + pad)
}

/// One view: obstacles, the planned wrist path, one round-capped line per capsule (an
/// orthographic capsule is exactly that), and a 10 cm scale bar.
#[allow(clippy::too_many_arguments)]
fn view_svg(
    out: &mut String,
    view: usize,
    title: &str,
    (h, v): (usize, usize),
    (hx, vx): (&str, &str),
    (x0, y0, x1, y1): (Real, Real, Real, Real),
    radii: &[Real],
    first: &[(Vector3, Vector3)],
    data: &PlotData,
) {
    // SVG's y runs down: the group flips v.
    let _ = write!(
        out,
        "<figure class=\"view\"><figcaption>{} — {hx} right, {vx} up</figcaption>\
         <svg viewBox=\"{:.4} {:.4} {:.4} {:.4}\" role=\"img\" aria-label=\"{}\">\
         <g transform=\"scale(1,-1)\">",
        escape(title),
        x0,
        -y1,
        x1 - x0,
        y1 - y0,
        escape(title)
    );
    let width = (x1 - x0).max(y1 - y0);
    for o in &data.obstacles {
        for ring in super::plot::outline(o, h, v) {
            let points: Vec<String> = ring.iter().map(|(x, y)| format!("{x:.4},{y:.4}")).collect();
            let _ = write!(
                out,
                "<polygon class=\"obstacle\" points=\"{}\"><title>{}</title></polygon>",
                points.join(" "),
                escape(&o.name)
            );
        }
    }
    let path: Vec<String> =
        data.wrist.iter().step_by(2).map(|p| format!("{:.4},{:.4}", p[h], p[v])).collect();
    let _ = write!(
        out,
        "<polyline class=\"wrist\" points=\"{}\" stroke-width=\"{:.4}\"/>",
        path.join(" "),
        width / 300.0
    );
    for (k, (r, name)) in radii.iter().zip(&data.capsules).enumerate() {
        let (cr, cg, cb) = super::plot::PALETTE[k % super::plot::PALETTE.len()];
        // At the first frame, so that the view shows the arm before the script runs.
        let (a, b) = first.get(k).copied().unwrap_or_default();
        let _ = write!(
            out,
            "<line class=\"capsule\" data-view=\"{view}\" data-capsule=\"{k}\" \
             x1=\"{:.4}\" y1=\"{:.4}\" x2=\"{:.4}\" y2=\"{:.4}\" \
             stroke=\"rgb({cr},{cg},{cb})\" stroke-width=\"{:.4}\"><title>{}</title></line>",
            a[h],
            a[v],
            b[h],
            b[v],
            2.0 * r,
            escape(name)
        );
    }
    let bar_y = y0 + 0.04 * (y1 - y0);
    let bar_x = x0 + 0.04 * (x1 - x0);
    let _ = writeln!(
        out,
        "<line class=\"scale\" x1=\"{bar_x:.4}\" y1=\"{bar_y:.4}\" x2=\"{:.4}\" y2=\"{bar_y:.4}\" \
         stroke-width=\"{:.4}\"/></g></svg></figure>",
        bar_x + 0.1,
        width / 150.0
    );
}

const STYLE: &str = r#"
:root { color-scheme: light dark; --bg: #ffffff; --fg: #1d1d1f; --muted: #5f6368;
  --line: #d9d9de; --card: #f6f7f9; --ok: #007a5a; --bad: #c2410c; --obstacle: #b9bcc4;
  --wrist: #0072b2; --now: #6b7280; }
@media (prefers-color-scheme: dark) {
  :root { --bg: #15171a; --fg: #e8eaed; --muted: #a0a4ab; --line: #3a3d43; --card: #1f2226;
    --ok: #3fcf9b; --bad: #ff8a4c; --obstacle: #5b606a; --wrist: #56b4e9; --now: #9ca3af; }
}
* { box-sizing: border-box; }
body { margin: 0; background: var(--bg); color: var(--fg);
  font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; }
main { max-width: 1040px; margin: 0 auto; padding: 12px 14px 40px; }
h1 { font-size: 1.5rem; margin: 0.4em 0 0.1em; }
h2 { font-size: 1.15rem; margin: 1.6em 0 0.5em; border-bottom: 1px solid var(--line); }
.caption, footer { color: var(--muted); }
.ok { color: var(--ok); } .bad { color: var(--bad); }
.scroll { overflow-x: auto; }
table { border-collapse: collapse; width: 100%; font-size: 0.88rem; }
th, td { padding: 4px 8px; border-bottom: 1px solid var(--line); text-align: left;
  white-space: nowrap; }
td.n { text-align: right; font-variant-numeric: tabular-nums; }
pre { background: var(--card); padding: 10px; overflow-x: auto; font-size: 0.8rem;
  border-radius: 6px; }
.figure { background: #ffffff; border-radius: 6px; padding: 4px; }
.map { margin: 0 0 14px; } .map figcaption { color: var(--muted); font-size: 0.85rem; }
svg.plot { width: 100%; height: auto; display: block; }
.now { stroke: #6b7280; stroke-width: 1.5; stroke-dasharray: 4 3; }
.views { display: grid; grid-template-columns: repeat(auto-fit, minmax(280px, 1fr)); gap: 12px; }
.view { margin: 0; background: var(--card); border-radius: 6px; padding: 6px; }
.view svg { width: 100%; height: auto; max-height: 70vh; display: block; }
.view figcaption { color: var(--muted); font-size: 0.85rem; }
.obstacle { fill: var(--obstacle); fill-opacity: 0.6; stroke: var(--muted); stroke-width: 0.002; }
.wrist { fill: none; stroke: var(--wrist); stroke-opacity: 0.7; }
.capsule { stroke-linecap: round; stroke-opacity: 0.85; }
.scale { stroke: var(--fg); }
.controls { display: flex; gap: 10px; align-items: center; margin: 10px 0; }
.controls input { flex: 1; }
button { font: inherit; padding: 4px 14px; border-radius: 6px; border: 1px solid var(--line);
  background: var(--card); color: var(--fg); }
"#;

const SCRIPT: &str = r#"
(function () {
  var data = JSON.parse(document.getElementById('frames').textContent);
  var slider = document.getElementById('time'), clock = document.getElementById('clock');
  var button = document.getElementById('play');
  var views = [[1, 2], [0, 1]];
  var lines = Array.prototype.slice.call(document.querySelectorAll('line.capsule'));
  var marks = Array.prototype.slice.call(document.querySelectorAll('line.now'));
  function show(i) {
    var ends = data.ends[i], t = data.t[i];
    lines.forEach(function (line) {
      var v = views[+line.dataset.view], k = 6 * (+line.dataset.capsule);
      line.setAttribute('x1', ends[k + v[0]]); line.setAttribute('y1', ends[k + v[1]]);
      line.setAttribute('x2', ends[k + 3 + v[0]]); line.setAttribute('y2', ends[k + 3 + v[1]]);
    });
    marks.forEach(function (m) {
      var d = m.dataset, x0 = +d.x0, x1 = +d.x1, t0 = +d.t0, t1 = +d.t1;
      var x = x0 + (t - t0) / (t1 - t0) * (x1 - x0);
      m.setAttribute('x1', x); m.setAttribute('x2', x);
    });
    clock.textContent = t.toFixed(2) + ' s';
  }
  var playing = false, started = 0, from = 0;
  function step(now) {
    if (!playing) { return; }
    var t = data.t[from] + (now - started) / 1000, i = +slider.value;
    while (i + 1 < data.t.length && data.t[i + 1] <= t) { i++; }
    slider.value = i; show(i);
    if (i + 1 >= data.t.length) { playing = false; button.textContent = 'play'; return; }
    requestAnimationFrame(step);
  }
  button.addEventListener('click', function () {
    playing = !playing; button.textContent = playing ? 'pause' : 'play';
    if (playing) {
      if (+slider.value + 1 >= data.t.length) { slider.value = 0; }
      from = +slider.value; started = performance.now(); requestAnimationFrame(step);
    }
  });
  slider.addEventListener('input', function () { playing = false; button.textContent = 'play'; show(+slider.value); });
  show(0);
})();
"#;
