//! The time × swivel map as an SVG figure, drawn as the paper's are (time horizontal, swivel
//! vertical, one colour per obstacle's forbidden region, the profile as a line), from the
//! [`MapSummary`] a plan keeps: `a2ml map` and the report draw the same figure.

use plotters::prelude::*;

use crate::math::{PI, Real};
use crate::solve::map::{Cell, MapSummary};

/// Pixel size of the figure.
const SIZE: (u32, u32) = (900, 560);

/// Obstacle colours, in order; they repeat past the last.
const OBSTACLE_COLOURS: [RGBColor; 6] = [
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];
const LIMITS: RGBColor = RGBColor(190, 190, 190);
const SELF_COLLISION: RGBColor = RGBColor(227, 119, 194);
const FAULT: RGBColor = RGBColor(60, 60, 60);

fn colour(cell: Cell) -> Option<RGBColor> {
    match cell {
        Cell::Free => None,
        Cell::Limits => Some(LIMITS),
        Cell::SelfCollision => Some(SELF_COLLISION),
        Cell::Obstacle(k) => Some(OBSTACLE_COLOURS[k as usize % OBSTACLE_COLOURS.len()]),
    }
}

/// Degrees in [−180, 180) of an angle in radians.
fn wrapped_degrees(a: Real) -> Real {
    ((a + PI).rem_euclid(2.0 * PI) - PI).to_degrees()
}

/// The figure of a map and its profile (if it has one), titled `title`, as an SVG document.
/// Time is the segment's own, from its start (s), as the map solver solved it.
///
/// # Errors
/// A message when plotters fails to lay the figure out.
pub fn swivel_map_svg(map: &MapSummary, title: &str) -> Result<String, String> {
    let mut svg = String::new();
    draw(&mut svg, map, title).map_err(|e| e.to_string())?;
    Ok(svg)
}

fn draw(svg: &mut String, map: &MapSummary, title: &str) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::with_string(svg, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let duration = map.duration().max(1e-9);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(0.0..duration, -180.0..180.0)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("t (s)")
        .y_desc("swivel angle θsw (deg)")
        .y_labels(9)
        .draw()?;
    // Each column's cell spans half a time step either side; a run of one label is one box.
    let nt = map.times.len();
    let half = |i: usize| {
        let before = if i > 0 { map.times[i - 1] } else { map.times[i] };
        let after = if i + 1 < nt { map.times[i + 1] } else { map.times[i] };
        (0.5 * (before + map.times[i]), 0.5 * (map.times[i] + after))
    };
    let step = map.angle_step().to_degrees();
    let faulty: Vec<usize> = map.faults.iter().map(|(i, _)| *i).filter(|i| *i < nt).collect();
    let mut boxes: Vec<Rectangle<(Real, Real)>> = faulty
        .iter()
        .map(|&i| {
            let (t0, t1) = half(i);
            Rectangle::new([(t0, -180.0), (t1, 180.0)], FAULT.filled())
        })
        .collect();
    for run in map.runs.iter().filter(|r| (r.column as usize) < nt) {
        let i = run.column as usize;
        if faulty.contains(&i) {
            continue;
        }
        if let Some(c) = colour(run.cell) {
            let (t0, t1) = half(i);
            let a0 = -180.0 + Real::from(run.first) * step;
            let a1 = -180.0 + Real::from(run.first.saturating_add(run.count)) * step;
            boxes.push(Rectangle::new([(t0, a0), (t1, a1)], c.filled()));
        }
    }
    chart.draw_series(boxes)?;
    // The legend: one entry per obstacle that forbids something, then limits and self.
    let labelled = |cell: Cell| map.runs.iter().any(|r| r.cell == cell);
    for (k, name) in map.obstacles.iter().enumerate() {
        if labelled(Cell::Obstacle(k as u16)) {
            let c = OBSTACLE_COLOURS[k % OBSTACLE_COLOURS.len()];
            legend_entry(&mut chart, name, c)?;
        }
    }
    if labelled(Cell::Limits) {
        legend_entry(&mut chart, "joint limits", LIMITS)?;
    }
    if labelled(Cell::SelfCollision) {
        legend_entry(&mut chart, "self-collision", SELF_COLLISION)?;
    }
    if !faulty.is_empty() {
        legend_entry(&mut chart, "path infeasible", FAULT)?;
    }
    if let (Some(&(t_start, start)), Some(&(t_end, end))) =
        (map.profile.first(), map.profile.last())
    {
        // The profile, broken where it wraps through ±180°.
        let mut pieces: Vec<Vec<(Real, Real)>> = vec![Vec::new()];
        for &(t, a) in &map.profile {
            let p = (t, wrapped_degrees(a));
            let jumped = pieces
                .last()
                .and_then(|piece| piece.last())
                .is_some_and(|last| (p.1 - last.1).abs() > 180.0);
            if jumped {
                pieces.push(Vec::new());
            }
            if let Some(piece) = pieces.last_mut() {
                piece.push(p);
            }
        }
        for (k, piece) in pieces.into_iter().enumerate() {
            let series = chart.draw_series(LineSeries::new(piece, BLACK.stroke_width(2)))?;
            if k == 0 {
                series.label("swivel profile").legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], BLACK.stroke_width(2))
                });
            }
        }
        chart
            .draw_series([Circle::new((t_start, wrapped_degrees(start)), 6, BLACK.filled())])?
            .label("start")
            .legend(|(x, y)| Circle::new((x + 8, y), 5, BLACK.filled()));
        chart
            .draw_series([TriangleMarker::new((t_end, wrapped_degrees(end)), 7, BLACK.filled())])?
            .label("end")
            .legend(|(x, y)| TriangleMarker::new((x + 8, y), 6, BLACK.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

fn legend_entry(
    chart: &mut Chart<'_, '_>,
    name: &str,
    colour: RGBColor,
) -> Result<(), Box<dyn std::error::Error>> {
    // An empty series carries the legend entry.
    chart
        .draw_series(std::iter::empty::<Rectangle<(Real, Real)>>())?
        .label(name)
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], colour.filled()));
    Ok(())
}
