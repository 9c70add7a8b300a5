//! `a2ml plot` and `a2ml report`: every example draws and reports; the report fetches
//! nothing and its segment table says what `a2ml plan --json` says.

use std::fs;
use std::path::{Path, PathBuf};

use super::{a2ml, example_path, scratch, stderr};

fn examples() -> Vec<PathBuf> {
    let folder: PathBuf = [env!("CARGO_MANIFEST_DIR"), "..", "..", "examples"].iter().collect();
    let mut files: Vec<PathBuf> = fs::read_dir(folder)
        .expect("examples folder")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "a2ml"))
        .collect();
    files.sort();
    files
}

fn stem(path: &Path) -> String {
    path.file_stem().expect("a file name").to_string_lossy().into_owned()
}

/// Every place the page refers outside itself: `http`, `src=`, `href=` not to `#`, `url(` not
/// to `#`, `@import`. The SVG namespace names a standard, nothing is fetched from it.
fn external_references(html: &str) -> Vec<String> {
    let mut found = Vec::new();
    let namespace = "http://www.w3.org/2000/svg";
    for (i, _) in html.match_indices("http") {
        if !html[i..].starts_with(namespace) {
            found.push(html[i..(i + 60).min(html.len())].to_owned());
        }
    }
    for pattern in ["src=", "@import", "<link", "<iframe", "<img"] {
        found.extend(
            html.match_indices(pattern).map(|(i, _)| html[i..(i + 40).min(html.len())].to_owned()),
        );
    }
    for pattern in ["href=\"", "url("] {
        for (i, _) in html.match_indices(pattern) {
            let rest = &html[i + pattern.len()..];
            if !rest.starts_with('#') {
                found.push(html[i..(i + 40).min(html.len())].to_owned());
            }
        }
    }
    found
}

#[test]
fn every_example_plots_and_reports() {
    let dir = scratch("plot", "every_example");
    let mut planned = 0;
    for path in examples() {
        let name = stem(&path);
        let svg = dir.join(format!("{name}.svg"));
        let html = dir.join(format!("{name}.html"));
        let file = path.to_string_lossy();
        let out = a2ml(&["plot", &file, "-o", &svg.to_string_lossy(), "--kind", "all"]);
        // Examples of a construct alone (no start) or of a solver still to come do not plan:
        // refused as `a2ml plan` refuses them, nothing written.
        let plan =
            a2ml(&["plan", &file, "--json", &dir.join(format!("{name}.json")).to_string_lossy()]);
        if plan.status.code() == Some(2) {
            assert_eq!(out.status.code(), Some(2), "{name}: {}", stderr(&out));
            assert!(!svg.exists());
            continue;
        }
        planned += 1;
        // 0, or 3 for a plan that misses a goal: the picture is written either way.
        let code = plan.status.code();
        assert!(matches!(code, Some(0 | 3)), "{name}: {}", stderr(&plan));
        assert_eq!(out.status.code(), code, "{name}: {}", stderr(&out));
        let picture = fs::read_to_string(&svg).expect("the picture is written");
        assert!(picture.starts_with("<svg") && picture.trim_end().ends_with("</svg>"), "{name}");
        let out = a2ml(&["report", &file, "-o", &html.to_string_lossy()]);
        assert_eq!(out.status.code(), code, "{name}: {}", stderr(&out));
        let page = fs::read_to_string(&html).expect("the report is written");
        assert!(page.starts_with("<!doctype html>") && page.trim_end().ends_with("</html>"));
        assert_eq!(external_references(&page), Vec::<String>::new(), "{name}");
        for section in
            ["summary", "segments", "human-likeness", "motion", "plots", "decomposition", "task"]
        {
            assert!(page.contains(&format!("<section id=\"{section}\">")), "{name}: {section}");
        }
        assert!(page.contains("prefers-color-scheme: dark"), "{name}: a dark style");
        assert!(page.contains("id=\"play\"") && page.contains("type=\"range\""), "{name}");
    }
    assert!(planned >= 20, "{planned} examples planned");
}

/// The cells of each row of the segment table: (text, data-value).
fn table_rows(html: &str) -> Vec<Vec<(String, Option<f64>)>> {
    let start = html.find("<table class=\"segments\">").expect("the segment table");
    let body = &html[start..];
    let body = &body[body.find("<tbody>").expect("a body")..body.find("</tbody>").expect("an end")];
    body.split("<tr>")
        .skip(1)
        .map(|row| {
            row.split("<td")
                .skip(1)
                .map(|cell| {
                    let open_end = cell.find('>').expect("a cell");
                    let attributes = &cell[..open_end];
                    let text = &cell[open_end + 1..cell.find("</td>").expect("a cell end")];
                    let value = attributes.split("data-value=\"").nth(1).map(|v| {
                        v[..v.find('"').expect("quoted")].parse::<f64>().expect("a number")
                    });
                    (text.to_owned(), value)
                })
                .collect()
        })
        .collect()
}

#[test]
fn the_report_table_says_what_plan_json_says() {
    for name in ["push_box_aside_coman.a2ml", "type_iv_forward_bar.a2ml", "construct_scene.a2ml"] {
        let dir = scratch("plot", &format!("table_{name}"));
        let file = example_path(name);
        let json = dir.join("plan.json");
        let html = dir.join("report.html");
        let out = a2ml(&["plan", &file, "--json", &json.to_string_lossy()]);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let out = a2ml(&["report", &file, "-o", &html.to_string_lossy()]);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
        let plan: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(&json).expect("json")).expect("JSON");
        let rows = table_rows(&fs::read_to_string(&html).expect("html"));
        let segments = plan["segments"].as_array().expect("segments");
        assert_eq!(rows.len(), segments.len(), "{name}");
        for (row, s) in rows.iter().zip(segments) {
            let number = |key: &str| s[key].as_f64().expect("a number");
            assert_eq!(row[0].0, s["action"].as_str().expect("action"), "{name}");
            assert_eq!(row[1].0, (s["segment"].as_u64().expect("index") + 1).to_string());
            assert_eq!(row[2].0, s["action_type"].as_str().unwrap_or("-"), "{name}: type");
            assert_eq!(row[3].0, s["pattern"].as_str().expect("pattern"), "{name}: pattern");
            assert_eq!(row[4].0, s["space"].as_str().expect("space"), "{name}: space");
            assert_eq!(row[5].0, s["solver"].as_str().expect("solver"));
            assert_eq!(row[6].1, Some(number("start")), "{name}: start");
            assert_eq!(row[7].1, Some(number("end")), "{name}: end");
            match s["clearance"].as_object() {
                Some(c) => {
                    let mm = c["distance"].as_f64().expect("distance") * 1e3;
                    assert_eq!(row[9].1, Some(mm), "{name}: clearance");
                    assert_eq!(row[9].0, format!("{mm:.1}"));
                }
                None => assert_eq!(row[9].0, "-"),
            }
            let margin = number("limit_margin").to_degrees();
            assert_eq!(row[10].1, Some(margin), "{name}: limit margin");
            let reached = s["reached"].as_bool().expect("reached");
            let kept = s["path_kept"].as_bool().expect("path_kept");
            assert_eq!(
                row[11].0.starts_with("ok"),
                reached && kept,
                "{name}: status {}",
                row[11].0
            );
        }
        let warnings = plan["warnings"].as_array().expect("warnings");
        let page = fs::read_to_string(&html).expect("html");
        for w in warnings {
            let text = w["message"]
                .as_str()
                .expect("a warning")
                .replace('&', "&amp;")
                .replace('<', "&lt;");
            let text = text.replace('>', "&gt;").replace('"', "&quot;").replace('\'', "&#39;");
            assert!(page.contains(&format!("<li>{text}</li>")), "{name}: warning {text}");
        }
    }
}

#[test]
fn an_unknown_kind_is_refused_with_the_kinds_listed() {
    let out =
        a2ml(&["plot", &example_path("construct_path_line.a2ml"), "-o", "x.svg", "--kind", "pie"]);
    assert_eq!(out.status.code(), Some(2));
    let message = stderr(&out);
    assert!(message.contains("joints") && message.contains("wrist"), "{message}");
}

#[test]
fn a_picture_into_a_missing_folder_is_an_io_error() {
    let dir = scratch("plot", "missing_folder");
    let svg = dir.join("no").join("such").join("x.svg");
    let out =
        a2ml(&["plot", &example_path("construct_path_line.a2ml"), "-o", &svg.to_string_lossy()]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert!(!svg.exists());
}

#[test]
fn a_plan_recording_plots_as_its_task_does() {
    let dir = scratch("plot", "recording");
    let file = example_path("type_iv_forward_bar.a2ml");
    let mcap = dir.join("plan.mcap");
    let out = a2ml(&["plan", &file, "-o", &mcap.to_string_lossy()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let (from_task, from_plan) = (dir.join("task.svg"), dir.join("plan.svg"));
    let out = a2ml(&["plot", &file, "-o", &from_task.to_string_lossy()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let out = a2ml(&["plot", &mcap.to_string_lossy(), "-o", &from_plan.to_string_lossy()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let (a, b) =
        (fs::read_to_string(from_task).expect("svg"), fs::read_to_string(from_plan).expect("svg"));
    assert!(a == b, "the recording draws the same picture");
    // Not a plan: refused as input.
    let other = dir.join("not.mcap");
    fs::write(&other, "not an mcap").expect("written");
    let out = a2ml(&["plot", &other.to_string_lossy(), "-o", &dir.join("x.svg").to_string_lossy()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
}

/// Width and height of a PNG file, from its IHDR chunk.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert_eq!(bytes[..8], *b"\x89PNG\r\n\x1a\n", "a PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR");
    let word = |at: usize| u32::from_be_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    (word(16), word(20))
}

#[test]
fn a_png_name_writes_a_png_image_at_the_width_asked() {
    let dir = scratch("plot", "png");
    let file = example_path("construct_path_line.a2ml");
    let (png, svg) = (dir.join("joints.png"), dir.join("joints.svg"));
    let out = a2ml(&["plot", &file, "-o", &svg.to_string_lossy(), "--kind", "joints"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let out = a2ml(&["plot", &file, "-o", &png.to_string_lossy(), "--kind", "joints"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    // As drawn: the SVG's own size.
    let text = fs::read_to_string(&svg).expect("svg");
    let attribute = |name: &str| -> u32 {
        let at = text.find(&format!("{name}=\"")).expect("sized") + name.len() + 2;
        text[at..at + text[at..].find('"').expect("quoted")].parse().expect("a number")
    };
    let own = (attribute("width"), attribute("height"));
    assert_eq!(png_size(&fs::read(&png).expect("png")), own);
    let out = a2ml(&["plot", &file, "-o", &png.to_string_lossy(), "--width", "480"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let (w, h) = png_size(&fs::read(&png).expect("png"));
    assert_eq!(w, 480);
    assert!(h > 100, "the whole page in proportion: {h} px");
    // A width no picture has is refused before anything is planned, nothing written.
    for width in ["0", "100000"] {
        let other = dir.join(format!("w{width}.png"));
        let out = a2ml(&["plot", &file, "-o", &other.to_string_lossy(), "--width", width]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert!(stderr(&out).contains("--width"), "{}", stderr(&out));
        assert!(!other.exists());
    }
}

#[test]
fn the_report_shows_the_swivel_map_of_a_map_segment() {
    let dir = scratch("plot", "report_map");
    let html = dir.join("report.html");
    let file = example_path("swivel_map_spheres.a2ml");
    // Exit 3: the map releases the start's held θsw to pass the sphere (tests/cli/examples.rs),
    // and the report is written all the same.
    let out = a2ml(&["report", &file, "-o", &html.to_string_lossy()]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    let page = fs::read_to_string(&html).expect("the report");
    assert!(page.contains("<section id=\"swivel-maps\">"));
    assert!(page.contains("<figure class=\"map\" data-segment=\"0\">"));
    assert_eq!(external_references(&page), Vec::<String>::new());
    let json = dir.join("plan.json");
    let out = a2ml(&["plan", &file, "--json", &json.to_string_lossy()]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    let plan: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(&json).expect("json")).expect("JSON");
    let maps = plan["swivel_maps"].as_array().expect("the plan keeps its maps");
    assert_eq!(maps.len(), 1);
    assert_eq!(maps[0]["segment"], 0);
    assert_eq!(maps[0]["angle_steps"], 360);
    assert!(!maps[0]["runs"].as_array().expect("runs").is_empty());
}
