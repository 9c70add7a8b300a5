//! The pictures of a plan: every example draws and renders (resvg), and what is drawn sits
//! where the data says: a joint's limit bands at its limits, the joint's line at its
//! positions, the wrist path within its extents.

use std::path::{Path, PathBuf};

use a2ml::Robot;
use a2ml::language::{self, Shape, Task, Variable};
use a2ml::math::{Real, Vector3};
use a2ml::output::plot::{
    FeaturedPanel, PALETTE, Panel, Picture, PlotData, PlotKind, Runs, plot_data_svg, plot_svg,
};
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

#[test]
fn plotting_a_recording_draws_what_plotting_the_plan_draws() {
    let path = example("push_box_aside_coman.a2ml");
    let (robot, task, plan) = planned(&path);
    let source = std::fs::read_to_string(&path).expect("example reads");
    let mcap = Path::new(env!("CARGO_TARGET_TMPDIR")).join("plot-recording.mcap");
    a2ml::output::write_mcap(&mcap, &robot, &task, &source, &plan).expect("written");
    let recorded = a2ml::output::read_mcap(&mcap).expect("reads back");
    // The robot and the task as the recording carries them.
    let attached = Robot::from_urdf_str(
        recorded.urdf.as_deref().expect("a URDF"),
        &a2ml::robot::RobotOptions::default(),
    )
    .expect("the URDF loads");
    let scene = task.in_base_frame(&robot.structure.shoulder_in_base_link).scene;
    assert_eq!(recorded.obstacles, scene, "the scene as recorded");
    let from_recording = PlotData::recorded(&attached, &recorded.obstacles, &recorded);
    let from_plan = PlotData::new(&robot, &task, &plan);
    assert_eq!(from_recording.featured, from_plan.featured);
    assert_eq!(from_recording.distances, from_plan.distances);
    assert_eq!(from_recording.segments, from_plan.segments);
    let svg = plot_data_svg(&from_recording, PlotKind::All).expect("draws").svg;
    assert!(svg == plot_svg(&robot, &task, &plan, PlotKind::All).expect("draws").svg);
}

/// The featured panel of `variable`.
fn panel_of(data: &PlotData, variable: Variable) -> &FeaturedPanel {
    data.featured.iter().find(|p| p.variable == variable).expect("a featured panel")
}

/// The value of `runs` at time `t`, if a point is there.
fn at(runs: &Runs, t: Real) -> Option<Real> {
    runs.iter().flatten().find(|p| p.0 == t).map(|p| p.1)
}

#[test]
fn each_featured_variable_is_drawn_against_its_reference() {
    let (robot, task, plan) = planned(&example("construct_goal.a2ml"));
    let data = PlotData::new(&robot, &task, &plan);
    let featured: Vec<Variable> = data.featured.iter().map(|p| p.variable).collect();
    assert_eq!(featured, Variable::ALL, "every variable is featured by some goal");
    let times = plan.trajectory.times();
    for k in (0..times.len()).step_by(times.len() / 9) {
        let (t, r) = (times[k], &plan.references[k]);
        for (variable, value) in
            [(Variable::Swivel, r.state.swivel), (Variable::Elbow, r.state.elbow_angle)]
        {
            let drawn = at(&panel_of(&data, variable).reference[0].1, t);
            assert_eq!(drawn, value.map(Real::to_degrees), "{variable:?} at {t} s");
        }
        let pw = r.state.pw.expect("Pw is mapped from every HAT reference here");
        for (i, (_, runs)) in panel_of(&data, Variable::Pw).reference.iter().enumerate() {
            assert_eq!(at(runs, t), Some(pw[i]), "Pw[{i}] at {t} s");
        }
        // A rotation is drawn as its angle to the running segment's reference end while
        // that segment features it.
        let segment = &plan.segments[r.segment];
        for variable in [Variable::Ow, Variable::Os] {
            let drawn = at(&panel_of(&data, variable).reference[0].1, t);
            if !segment.focus.contains(&variable) {
                continue;
            }
            let end = &plan.reference_ends[r.segment];
            let (now, goal) = match variable {
                Variable::Ow => (r.state.ow, end.ow),
                _ => (r.state.shoulder_frame, end.shoulder_frame),
            };
            let expected = now.zip(goal).map(|(a, b)| a.angle_to(&b).to_degrees());
            let (drawn, expected) = (drawn.expect("drawn"), expected.expect("defined"));
            assert!(
                (drawn - expected).abs() < 1e-4,
                "{variable:?} at {t} s: {drawn} vs {expected}"
            );
        }
    }
    // The reference ends where the goal is: θsw's last featuring segment asks 75°.
    let swivel = panel_of(&data, Variable::Swivel);
    let last = swivel.targets.last().expect("a goal");
    assert!((last.2 - 75.0).abs() < 1e-9, "θsw goal {}°", last.2);
    let reference_end = swivel.reference[0].1.last().and_then(|r| r.last()).expect("drawn");
    assert!((reference_end.1 - 75.0).abs() < 1e-6, "the reference ends at the goal");
}

/// Distance from `p` to an axis-aligned box, a sphere or an upright cylinder (negative
/// inside), by the shapes' own formulas.
fn distance_to(p: &Vector3, shape: &Shape) -> Real {
    match shape {
        Shape::Box { center, size, .. } => {
            let d = (p - center).abs() - size * 0.5;
            let outside = d.map(|x| x.max(0.0)).norm();
            outside + d.max().min(0.0)
        }
        Shape::Sphere { center, radius, .. } => (p - center).norm() - radius,
        Shape::Cylinder { center, radius, height, .. } => {
            let radial = (p - center).xy().norm() - radius;
            let axial = (p.z - center.z).abs() - 0.5 * height;
            let outside = Vector3::new(radial.max(0.0), axial.max(0.0), 0.0).norm();
            outside + radial.max(axial).min(0.0)
        }
        Shape::Capsule { a, b, radius, .. } => segment_distance(p, a, b) - radius,
    }
}

fn segment_distance(p: &Vector3, a: &Vector3, b: &Vector3) -> Real {
    let ab = b - a;
    let s = if ab.norm_squared() > 0.0 {
        ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * s)).norm()
}

#[test]
fn the_recorded_distances_are_the_distances_of_the_capsules_to_the_obstacles() {
    let (robot, task, plan) = planned(&example("push_box_aside_coman.a2ml"));
    let scene = task.in_base_frame(&robot.structure.shoulder_in_base_link).scene;
    let moving = robot.capsules.iter().filter(|c| c.role != a2ml::robot::LinkRole::Base).count();
    assert_eq!(plan.distances.len(), moving * scene.len(), "every moving capsule, every obstacle");
    let n = plan.trajectory.len();
    let mut checked = 0;
    for k in [0, n / 5, 2 * n / 5, 3 * n / 5, 4 * n / 5, n - 1] {
        let q = plan.trajectory.positions()[k];
        let capsules =
            a2ml::collision::arm_capsules(&robot, &a2ml::kinematics::arm_pose(&robot, &q));
        let t = plan.trajectory.times()[k];
        let running = plan.segments.iter().rev().find(|s| s.start <= t).expect("a segment");
        let contact = &task.actions[running.action_index].contact;
        for d in &plan.distances {
            let value = d.distance[k];
            if contact.contains(&d.obstacle) {
                assert_eq!(value, None, "{} is touched on purpose at {t} s", d.obstacle);
                continue;
            }
            let value = value.expect("measured");
            let capsule = &capsules[d.capsule_index];
            let obstacle = scene.iter().find(|o| o.name == d.obstacle).expect("an obstacle");
            // The capsule as its axis sampled every 0.05 mm, each point's distance less the
            // radius; exact where the capsule is clear of the obstacle.
            let steps = ((capsule.b - capsule.a).norm() / 5e-5).ceil().max(1.0) as usize;
            let independent = (0..=steps)
                .map(|i| {
                    let p = capsule.a + (capsule.b - capsule.a) * (i as Real / steps as Real);
                    distance_to(&p, &obstacle.shape)
                })
                .fold(Real::INFINITY, Real::min)
                - capsule.radius;
            if independent > 0.0 {
                assert!(
                    (value - independent).abs() < 1e-5,
                    "{} to {} at {t} s: {value} recorded, {independent} measured",
                    d.capsule,
                    d.obstacle
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 20, "{checked} pairs checked");
}

#[test]
fn one_distance_pass_gives_the_per_obstacle_distances_and_the_clearance() {
    use a2ml::collision::{CollisionScene, DistanceOptions, distances};
    use a2ml::trajectory::{distance_pass, min_clearance};
    for name in ["push_box_aside_coman.a2ml", "construct_scene.a2ml", "swivel_map_spheres.a2ml"] {
        let (robot, task, plan) = planned(&example(name));
        let scene = task.in_base_frame(&robot.structure.shoulder_in_base_link).scene;
        assert!(!scene.is_empty(), "{name} has obstacles");
        // Touching the first obstacle during the first third, as a contact action would.
        let third = plan.trajectory.len() / 3;
        let touched = |sample: usize, obstacle: &str| sample < third && obstacle == scene[0].name;
        let pass = distance_pass(&plan.trajectory, &robot, &scene, touched);
        // Each obstacle on its own: the query per sample and obstacle the pass replaces.
        let options = DistanceOptions { influence: 1e3 };
        for (k, q) in plan.trajectory.positions().iter().enumerate() {
            let pose = a2ml::kinematics::arm_pose(&robot, q);
            for series in &pass.distances {
                let obstacle = scene.iter().find(|o| o.name == series.obstacle).expect("named");
                let alone = CollisionScene::new(std::slice::from_ref(obstacle));
                let expected = if touched(k, &obstacle.name) {
                    None
                } else {
                    distances(&robot, &pose, &alone, &options)
                        .into_iter()
                        .find(|p| p.obstacle_frame.is_none() && p.link == series.capsule)
                        .map(|p| p.distance)
                };
                // The pass's closed forms against parry's GJK, which may stop up to
                // MEASURE_SLACK above the exact distance.
                let slack = a2ml::collision::MEASURE_SLACK;
                let agrees = match (series.distance[k], expected) {
                    (Some(found), Some(parrys)) => {
                        found <= parrys + 1e-9 && found >= parrys - slack
                    }
                    (found, parrys) => found == parrys,
                };
                assert!(
                    agrees,
                    "{name}: {} at sample {k}: {:?} against parry's {expected:?}",
                    series.capsule, series.distance[k]
                );
            }
        }
        // Without contact, its clearance is the bounding-sphere search's, to the bit.
        let untouched = distance_pass(&plan.trajectory, &robot, &scene, |_, _| false);
        let searched = min_clearance(&plan.trajectory, &robot, &CollisionScene::new(&scene));
        assert_eq!(untouched.clearance, searched, "{name}");
        // With contact, the touched samples leave out that obstacle and nothing else.
        let clearance = pass.clearance.expect("pairs are measured");
        let smallest = pass
            .distances
            .iter()
            .flat_map(|s| s.distance.iter().flatten().copied())
            .fold(Real::INFINITY, Real::min);
        assert!(clearance.distance <= smallest, "{name}: self pairs count too");
        assert_eq!(untouched.distances.len(), pass.distances.len());
    }
}

#[test]
fn the_plan_keeps_the_swivel_map_its_solver_computed() {
    use a2ml::decompose::DecomposeOptions;
    use a2ml::language::SolverChoice;
    use a2ml::solve::map::{Cell, MapOptions, MapSummary, segment_map};
    let (robot, task, plan) = planned(&example("swivel_map_spheres.a2ml"));
    let mapped: Vec<usize> = (0..plan.segments.len())
        .filter(|&k| plan.segments[k].solver == SolverChoice::Map)
        .collect();
    assert!(!mapped.is_empty(), "the example is solved by the map");
    let kept: Vec<usize> = plan.swivel_maps.iter().map(|m| m.segment).collect();
    assert_eq!(kept, mapped, "one map per segment the map solved");
    // The first segment starts where the decomposition starts: `a2ml map`'s map is the plan's.
    let first = &plan.swivel_maps[0];
    let report = &plan.segments[first.segment];
    let options = MapOptions {
        safety_distance: PlanOptions::default().safety_distance,
        ..MapOptions::default()
    };
    let fresh = segment_map(
        &robot,
        &task,
        &report.action,
        report.segment,
        &DecomposeOptions::default(),
        &options,
    )
    .expect("the map builds");
    let profile = fresh.profile.as_ref().expect("a profile");
    assert_eq!(first.map, MapSummary::new(&fresh.map, Some(profile)));
    // The runs give every cell back, free ones included.
    let summary = &first.map;
    assert_eq!(summary.angle_steps, fresh.map.angles.len());
    let mut blocked = 0;
    for i in 0..fresh.map.times.len() {
        for j in 0..fresh.map.angles.len() {
            assert_eq!(summary.cell(i, j), fresh.map.cell(i, j), "cell ({i}, {j})");
            blocked += usize::from(fresh.map.cell(i, j) != Cell::Free);
        }
    }
    assert!(blocked > 0, "the spheres block some cells");
    assert!(summary.runs.len() < blocked, "runs are fewer than the cells they cover");
    // The profile kept is the solver's, thinned: its ends and points on it.
    let (times, swivel) = (profile.trajectory.times(), &profile.swivel);
    assert_eq!(summary.profile.first(), Some(&(times[0], swivel[0])));
    assert_eq!(summary.profile.last(), Some(&(times[times.len() - 1], swivel[swivel.len() - 1])));
    assert!(summary.profile.len() <= 2 * summary.times.len() + 1);
    for &(t, a) in &summary.profile {
        let k = times.iter().position(|s| *s == t).expect("a sample's time");
        assert_eq!(swivel[k], a);
    }
}

#[test]
fn the_report_draws_the_swivel_map_of_each_segment_the_map_solved() {
    use a2ml::output::report::{ReportInput, report_html};
    let (robot, task, plan) = planned(&example("swivel_map_spheres.a2ml"));
    let input =
        ReportInput { robot: &robot, task: &task, source: "", plan: &plan, decomposition: None };
    let html = report_html(&input).expect("the report");
    let section = &html[html.find("<section id=\"swivel-maps\">").expect("a map section")..];
    let section = &section[..section.find("</section>").expect("its end")];
    assert_eq!(section.matches("<figure class=\"map\"").count(), plan.swivel_maps.len());
    for name in ["sphere1", "swivel profile", "swivel angle θsw (deg)"] {
        assert!(section.contains(name), "the map figure shows {name}");
    }
    // The figure is `a2ml map`'s, scaled to the page.
    let entry = &plan.swivel_maps[0];
    let s = &plan.segments[entry.segment];
    let title = format!("{} — action {}, segment {}", plan.task, s.action, s.segment + 1);
    let figure = a2ml::output::swivel_map_svg(&entry.map, &title).expect("draws");
    let body = &figure[figure.find('>').expect("the root") + 1..];
    assert!(section.contains(body), "the report embeds the map figure");
    // A plan the map did not solve has no such section.
    let (robot, task, plan) = planned(&example("construct_scene.a2ml"));
    assert!(plan.swivel_maps.is_empty());
    let input =
        ReportInput { robot: &robot, task: &task, source: "", plan: &plan, decomposition: None };
    assert!(!report_html(&input).expect("the report").contains("swivel-maps"));
}

#[test]
fn a_png_picture_decodes_at_the_size_asked_with_its_text_drawn() {
    use a2ml::output::plot::{ImageFormat, encode, write_plot};
    let (robot, task, plan) = planned(&example("type_iv_forward_bar.a2ml"));
    let picture = plot_svg(&robot, &task, &plan, PlotKind::Joints).expect("draws");
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("joints.png");
    write_plot(&path, &robot, &task, &plan, PlotKind::Joints, Some(640)).expect("written");
    let bytes = std::fs::read(&path).expect("read back");
    assert_eq!(bytes[..8], *b"\x89PNG\r\n\x1a\n");
    let image = Pixmap::decode_png(&bytes).expect("decodes");
    let height = (f64::from(picture.size.1) * 640.0 / f64::from(picture.size.0)).round() as u32;
    assert_eq!((image.width(), image.height()), (640, height));
    let share = ink(&image);
    assert!(share > 0.02, "only {share} of the image is drawn");
    // At its own size, the shapes are the SVG's (rendered here without any font) and the text
    // comes on top: more ink, and every pixel the fontless render inks is inked too.
    let own = Pixmap::decode_png(&encode(&picture, ImageFormat::Png, None).expect("encodes"))
        .expect("decodes");
    let fontless = render(&picture);
    assert_eq!((own.width(), own.height()), picture.size);
    assert!(ink(&own) > ink(&fontless) + 0.002, "{} vs {}", ink(&own), ink(&fontless));
    let white = |p: &resvg::tiny_skia::PremultipliedColorU8| {
        (p.red(), p.green(), p.blue()) == (255, 255, 255)
    };
    let lost = own
        .pixels()
        .iter()
        .zip(fontless.pixels())
        .filter(|(with_text, shapes)| white(with_text) && !white(shapes))
        .count();
    assert_eq!(lost, 0, "every pixel the shapes ink stays inked under the text");
    // An SVG asked at a width keeps its drawing and scales it.
    let svg = encode(&picture, ImageFormat::Svg, Some(500)).expect("scales");
    let svg = String::from_utf8(svg).expect("text");
    let scaled = Tree::from_str(&svg, &Options::default()).expect("parses").size().to_int_size();
    let expected = (f64::from(picture.size.1) * 500.0 / f64::from(picture.size.0)).round() as u32;
    assert_eq!((scaled.width(), scaled.height()), (500, expected));
    assert!(write_plot(&path, &robot, &task, &plan, PlotKind::Joints, Some(0)).is_err());
}
