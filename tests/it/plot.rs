//! The pictures of a plan: every example draws and renders (resvg), and what is drawn sits
//! where the data says: a joint's limit bands at its limits, the joint's line at its
//! positions, the wrist path within its extents.

use std::path::{Path, PathBuf};

use a2ml::Robot;
use a2ml::language::{self, Task};
use a2ml::math::Real;
use a2ml::output::plot::{PALETTE, Panel, Picture, PlotKind, plot_svg};
use a2ml::solve::{self, Plan, PlanOptions, SolveError};
use resvg::tiny_skia::{Pixmap, Transform};
use resvg::usvg::{Options, Tree};

fn examples() -> Vec<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .expect("examples folder")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "a2ml"))
        .collect();
    files.sort();
    files
}

fn planned(path: &Path) -> (Robot, Task, Plan) {
    let name = path.display();
    let text = std::fs::read_to_string(path).expect("example reads");
    let task = language::parse(&text, Some(path)).expect("example is valid");
    let robot = Robot::from_urdf_file(&task.robot).unwrap_or_else(|e| panic!("{name}: {e}"));
    let plan = solve::plan(&robot, &task, &PlanOptions::default())
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    (robot, task, plan)
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples").join(name)
}

/// The picture rendered to pixels, at its own size.
fn render(picture: &Picture) -> Pixmap {
    let tree = Tree::from_str(&picture.svg, &Options::default()).expect("the SVG parses");
    let size = tree.size().to_int_size();
    assert_eq!((size.width(), size.height()), picture.size);
    let mut pixmap = Pixmap::new(size.width(), size.height()).expect("a pixmap");
    resvg::render(&tree, Transform::default(), &mut pixmap.as_mut());
    pixmap
}

fn rgb(pixmap: &Pixmap, x: i32, y: i32) -> (u8, u8, u8) {
    let p = pixmap.pixel(x as u32, y as u32).expect("inside").demultiply();
    (p.red(), p.green(), p.blue())
}

/// Share of pixels that are not white.
fn ink(pixmap: &Pixmap) -> Real {
    let inked =
        pixmap.pixels().iter().filter(|p| (p.red(), p.green(), p.blue()) != (255, 255, 255));
    inked.count() as Real / pixmap.pixels().len() as Real
}

fn close(a: (u8, u8, u8), b: (u8, u8, u8), tolerance: i32) -> bool {
    let d = |x: u8, y: u8| (i32::from(x) - i32::from(y)).abs();
    d(a.0, b.0) <= tolerance && d(a.1, b.1) <= tolerance && d(a.2, b.2) <= tolerance
}

#[test]
fn every_example_draws_every_plot_on_one_page_and_renders() {
    let mut drawn = 0;
    for path in examples() {
        let text = std::fs::read_to_string(&path).expect("example reads");
        let task = language::parse(&text, Some(&path)).expect("example is valid");
        let robot = Robot::from_urdf_file(&task.robot).expect("robot loads");
        let plan = match solve::plan(&robot, &task, &PlanOptions::default()) {
            Ok(plan) => plan,
            // Examples of a construct alone (no start) or of a solver still to come do not
            // plan; they are drawn once they do.
            Err(SolveError::UnsupportedSolver { .. } | SolveError::Decompose(_)) => continue,
            Err(e) => panic!("{}: {e}", path.display()),
        };
        drawn += 1;
        let picture = plot_svg(&robot, &task, &plan, PlotKind::All).expect("draws");
        let pixmap = render(&picture);
        let share = ink(&pixmap);
        assert!(share > 0.02, "{}: only {share} of the page is drawn", path.display());
        // 7 joints, 14 velocity and acceleration charts, 3 wrist views at least.
        let count = |kind| picture.panels.iter().filter(|p| p.kind == kind).count();
        assert_eq!(count(PlotKind::Joints), 7, "{}", path.display());
        assert_eq!(count(PlotKind::Velocities), 14, "{}", path.display());
        assert_eq!(count(PlotKind::Wrist), 3, "{}", path.display());
        assert_eq!(count(PlotKind::Distances), task.scene.len(), "{}", path.display());
        assert!(picture.svg.contains(&plan.task), "{}: the caption names the task", path.display());
        assert!(
            picture.svg.contains(&robot.name),
            "{}: the caption names the robot",
            path.display()
        );
    }
    assert!(drawn >= 20, "{drawn} of {} examples drawn", examples().len());
}

/// Rows of a column of the panel, inside its plotting area, that have `colour`.
fn rows_with(pixmap: &Pixmap, panel: &Panel, x: i32, colour: (u8, u8, u8)) -> Vec<i32> {
    (panel.y_pixels.1 + 1..panel.y_pixels.0)
        .filter(|y| close(rgb(pixmap, x, *y), colour, 6))
        .collect()
}

#[test]
fn a_joints_limit_bands_sit_at_its_limits_and_its_line_at_its_positions() {
    let (robot, task, plan) = planned(&example("type_iv_forward_bar.a2ml"));
    let picture = plot_svg(&robot, &task, &plan, PlotKind::Joints).expect("draws");
    let pixmap = render(&picture);
    for joint in [0, 3] {
        let panel = &picture.panels[joint];
        assert!(panel.title.contains(&plan.joint_names[joint]), "{}", panel.title);
        let (lower, upper) = (robot.lower()[joint].to_degrees(), robot.upper()[joint].to_degrees());
        assert!(panel.y_range.0 < lower && upper < panel.y_range.1);
        // A column near the right end, clear of the legend on the left of it? The legend sits
        // upper right, so look a tenth in from the left, past the first boundary label.
        let x = panel.x_pixels.0 + (panel.x_pixels.1 - panel.x_pixels.0) / 10;
        let shade = (0xD0, 0xD0, 0xD0);
        let rows = rows_with(&pixmap, panel, x, shade);
        let below: Vec<i32> =
            rows.iter().copied().filter(|y| f64::from(*y) > panel.row(lower) - 0.5).collect();
        let above: Vec<i32> =
            rows.iter().copied().filter(|y| f64::from(*y) < panel.row(upper) + 0.5).collect();
        assert!(!below.is_empty() && !above.is_empty(), "joint {joint}: both bands are drawn");
        let lower_edge = *below.iter().min().expect("rows") as f64;
        let upper_edge = *above.iter().max().expect("rows") as f64;
        assert!(
            (lower_edge - panel.row(lower)).abs() <= 1.5,
            "joint {joint}: lower band edge at row {lower_edge}, limit at {}",
            panel.row(lower)
        );
        assert!(
            (upper_edge - panel.row(upper)).abs() <= 1.5,
            "joint {joint}: upper band edge at row {upper_edge}, limit at {}",
            panel.row(upper)
        );
        // Nothing shaded between the limits.
        assert!(
            rows.iter().all(|y| f64::from(*y) > panel.row(lower) - 1.5
                || f64::from(*y) < panel.row(upper) + 1.5)
        );
        // The joint's line passes through q at a few times.
        let (r, g, b) = PALETTE[joint];
        for k in [plan.trajectory.len() / 3, 2 * plan.trajectory.len() / 3] {
            let t = plan.trajectory.times()[k];
            let q = plan.trajectory.positions()[k][joint].to_degrees();
            let column = panel.column(t).round() as i32;
            let hits = rows_with(&pixmap, panel, column, (r, g, b));
            assert!(
                hits.iter().any(|y| (f64::from(*y) - panel.row(q)).abs() <= 2.5),
                "joint {joint} at {t} s: q {q}° at row {}, line at rows {hits:?}",
                panel.row(q)
            );
        }
    }
}

#[test]
fn the_wrist_path_is_drawn_within_its_extents_in_the_top_view() {
    let (robot, task, plan) = planned(&example("construct_path_line.a2ml"));
    let picture = plot_svg(&robot, &task, &plan, PlotKind::Wrist).expect("draws");
    let pixmap = render(&picture);
    let top = &picture.panels[0];
    let wrist: Vec<(Real, Real)> = plan
        .trajectory
        .positions()
        .iter()
        .map(|q| {
            let w = a2ml::kinematics::arm_pose(&robot, q).wrist;
            (w.x, w.y)
        })
        .collect();
    let (min_x, max_x) = wrist
        .iter()
        .fold((Real::INFINITY, Real::NEG_INFINITY), |(a, b), p| (a.min(p.0), b.max(p.0)));
    // The planned path's colour stays within its extent (its 2 px width aside) and spans it
    // but for the markers drawn over its ends.
    let (r, g, b) = PALETTE[3];
    let columns: Vec<i32> = (top.x_pixels.0 + 1..top.x_pixels.1)
        .filter(|x| !rows_with(&pixmap, top, *x, (r, g, b)).is_empty())
        .collect();
    let (first, last) =
        (*columns.first().expect("drawn") as f64, *columns.last().expect("drawn") as f64);
    assert!(
        first >= top.column(min_x) - 2.0 && first <= top.column(min_x) + 6.0,
        "left end {first}, data {}",
        top.column(min_x)
    );
    assert!(
        last <= top.column(max_x) + 2.0 && last >= top.column(max_x) - 6.0,
        "right end {last}, data {}",
        top.column(max_x)
    );
    // The start (green) and end (vermillion) markers are centred on the path's ends.
    let centroid = |colour: (u8, u8, u8)| {
        let mut hits = Vec::new();
        for x in top.x_pixels.0 + 1..top.x_pixels.1 {
            for y in rows_with(&pixmap, top, x, colour) {
                hits.push((f64::from(x) + 0.5, f64::from(y) + 0.5));
            }
        }
        assert!(hits.len() > 10, "a marker of {colour:?}");
        let n = hits.len() as f64;
        (hits.iter().map(|h| h.0).sum::<f64>() / n, hits.iter().map(|h| h.1).sum::<f64>() / n)
    };
    for (point, colour) in [(wrist[0], PALETTE[2]), (wrist[wrist.len() - 1], PALETTE[4])] {
        let (cx, cy) = centroid(colour);
        let (px, py) = (top.column(point.0), top.row(point.1));
        assert!(
            (cx - px).abs() <= 1.5 && (cy - py).abs() <= 1.5,
            "marker at ({cx}, {cy}), point at ({px}, {py})"
        );
    }
    // Both axes of a view at one scale.
    let sx = (top.x_pixels.1 - top.x_pixels.0) as f64 / (top.x_range.1 - top.x_range.0);
    let sy = (top.y_pixels.0 - top.y_pixels.1) as f64 / (top.y_range.1 - top.y_range.0);
    assert!((sx / sy - 1.0).abs() < 0.02, "x {sx} px/m, y {sy} px/m");
}
