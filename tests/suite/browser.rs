//! The HTML report in a real browser: headless Chromium (Debian's
//! `chromium`, installed by `.ci/setup`) opens a generated page.
//!
//! Chromium is driven by its own headless flags, no driver crate:
//! `--dump-dom` gives the DOM after the page's script has run, whose
//! `#status` line the viewer writes once the scene is drawn (the step shown,
//! a digest of the module positions, the findings highlighted, the console
//! errors it caught); `--screenshot` gives the pixels;
//! `--enable-logging=stderr` gives the console, where uncaught errors show.
//! The viewer reads the step to show from the URL hash (`#step=K`).
//!
//! Without a browser the tests print why they skip: they never pass
//! silently. Set `RECONFCHECK_CHROMIUM` to use another binary.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common;

/// The browser to run, or why there is none.
fn chromium() -> Result<PathBuf, String> {
    if let Ok(p) = std::env::var("RECONFCHECK_CHROMIUM") {
        return Ok(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    for name in ["chromium", "chromium-browser", "google-chrome", "chrome"] {
        for dir in std::env::split_paths(&path) {
            let p = dir.join(name);
            if p.is_file() {
                return Ok(p);
            }
        }
    }
    Err("no chromium, chromium-browser or google-chrome on PATH \
         (run .ci/setup, which installs Debian's chromium, or set RECONFCHECK_CHROMIUM)"
        .into())
}

/// Skips the calling test, saying why, when there is no browser.
macro_rules! browser_or_skip {
    () => {
        match chromium() {
            Ok(b) => b,
            Err(why) => {
                eprintln!("SKIPPED {}: {why}", module_path!());
                println!("SKIPPED: {why}");
                return;
            }
        }
    };
}

/// Runs headless Chromium on `url` with `extra` flags; returns (stdout,
/// stderr). A run over two minutes is a failure.
fn run_chromium(browser: &Path, url: &str, extra: &[String]) -> (String, String) {
    let profile = tempdir(&format!("profile-{}", extra.len()));
    let out = std::fs::File::create(profile.with_extension("out")).unwrap();
    let err = std::fs::File::create(profile.with_extension("err")).unwrap();
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--no-first-run",
            "--disable-extensions",
            "--hide-scrollbars",
            "--enable-unsafe-swiftshader",
            "--use-angle=swiftshader",
            "--enable-logging=stderr",
            "--v=0",
            "--window-size=1280,1100",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(url)
        .stdin(Stdio::null())
        .stdout(out)
        .stderr(err)
        .spawn()
        .expect("chromium starts");
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("chromium did not finish in 120 s on {url}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    (
        std::fs::read_to_string(profile.with_extension("out")).unwrap(),
        std::fs::read_to_string(profile.with_extension("err")).unwrap(),
    )
}

fn tempdir(name: &str) -> PathBuf {
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    common::scratch("browser", &format!("{name}-{k}"))
}

/// The page of the obstacle walk (one step whose rotation cuts a fixed
/// module), certified with every check and the catom model.
fn colliding_page() -> PathBuf {
    static PAGE: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    PAGE.get_or_init(|| {
        let schedule = common::scratch("browser", "walk.json");
        common::walk_with_obstacle(&schedule, true);
        let page = common::scratch("browser", "walk.html");
        let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/catom-3.6mm.toml");
        let o = common::bin()
            .arg("certify")
            .arg(&schedule)
            .args(["--no-progress", "--model"])
            .arg(&model)
            .arg("--html")
            .arg(&page)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{o:?}");
        page
    })
    .clone()
}

/// The `#status` line of the page at `#step=K`, and the console output.
fn status_at(browser: &Path, page: &Path, step: usize) -> (String, String) {
    status_with(browser, page, &format!("step={step}"))
}

/// The `#status` line of the page opened with the URL fragment `hash`
/// (`step=K`, `play=N`), and the console output.
fn status_with(browser: &Path, page: &Path, hash: &str) -> (String, String) {
    let url = format!("file://{}#{hash}", page.display());
    let (dom, console) = run_chromium(browser, &url, &["--dump-dom".to_string()]);
    let start = dom
        .find("<div id=\"status\">")
        .expect("the page has a status line")
        + 17;
    let end = start + dom[start..].find("</div>").unwrap();
    (dom[start..end].to_string(), console)
}

fn field<'a>(status: &'a str, key: &str) -> &'a str {
    status
        .split(' ')
        .find_map(|p| p.strip_prefix(&format!("{key}=")))
        .unwrap_or_else(|| panic!("no {key} in the status: {status}"))
}

/// Console lines that report an error: uncaught exceptions, or errors the
/// page logged (chromium prints every console message with its text).
fn console_errors(console: &str) -> Vec<&str> {
    console
        .lines()
        .filter(|l| l.contains("CONSOLE") && (l.contains("Uncaught") || l.contains("Error")))
        .collect()
}

#[test]
fn the_report_page_loads_with_no_console_errors() {
    let browser = browser_or_skip!();
    let (status, console) = status_at(&browser, &colliding_page(), 0);
    assert!(
        status.starts_with("ready "),
        "the viewer finished: {status}\n{console}"
    );
    assert_eq!(field(&status, "errors"), "0", "{status}");
    assert!(console_errors(&console).is_empty(), "{console}");
}

/// A page of part of a schedule (`--steps 3-`) opens at its first step;
/// a step in the URL still wins.
#[test]
fn a_span_page_opens_at_its_first_checked_step() {
    let browser = browser_or_skip!();
    let page = common::scratch("browser", "span.html");
    let o = common::bin()
        .arg("certify")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/walk-fcc.json"))
        .args(["--no-progress", "--lattice-only", "--steps", "3-", "--html"])
        .arg(&page)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let (status, console) = status_with(&browser, &page, "");
    assert_eq!(field(&status, "step"), "3", "{status}\n{console}");
    let (status, _) = status_at(&browser, &page, 1);
    assert_eq!(field(&status, "step"), "1", "{status}");
}

#[test]
fn the_step_slider_changes_the_scene() {
    let browser = browser_or_skip!();
    let page = colliding_page();
    let (before, _) = status_at(&browser, &page, 0);
    let (after, _) = status_at(&browser, &page, 1);
    assert_eq!(field(&before, "step"), "0");
    assert_eq!(field(&after, "step"), "1");
    assert_ne!(
        field(&before, "scene"),
        field(&after, "scene"),
        "step 1 moves a module"
    );
}

#[test]
fn a_violation_is_highlighted_at_its_step_and_not_before() {
    let browser = browser_or_skip!();
    let page = colliding_page();
    let (before, _) = status_at(&browser, &page, 0);
    let (at, _) = status_at(&browser, &page, 1);
    assert_eq!(field(&before, "highlighted"), "0");
    assert_eq!(field(&at, "highlighted"), "1", "{at}");
    assert_ne!(field(&at, "markers"), "0", "{at}");
}

#[test]
fn the_b_study_page_replays_its_failing_b_and_plays_step_by_step() {
    let browser = browser_or_skip!();
    let page = tempdir("study").with_extension("html");
    common::branch_study_page(&page, 6, 7);
    let (status, console) = status_with(&browser, &page, "step=0&play=5");
    assert!(status.starts_with("ready "), "{status}\n{console}");
    assert_eq!(field(&status, "errors"), "0", "{status}");
    assert!(console_errors(&console).is_empty(), "{console}");
    // Five steps played from the start, each drawn, and timed.
    assert_eq!(field(&status, "step"), "5", "{status}");
    let ms: f64 = field(&status, "play_ms_per_step").parse().unwrap();
    assert!(ms.is_finite() && ms >= 0.0, "{status}");
    let (start, _) = status_at(&browser, &page, 0);
    assert_ne!(field(&start, "scene"), field(&status, "scene"));
    // Every step of so small a run has its load map: step 5 draws its
    // connectors.
    let connectors: usize = field(&status, "loadmap").parse().unwrap();
    assert!(connectors > 0, "{status}");
    // The study's table and curves are in kPa, as their headings say: b = 7
    // needs 106.2 kPa under the rigid hinge (its utilisation 1.062 at the
    // model's 100 kPa).
    let (dom, _) = run_chromium(
        &browser,
        &format!("file://{}", page.display()),
        &["--dump-dom".to_string()],
    );
    assert!(
        dom.contains("<td>106.2"),
        "no 106.2 kPa cell in the study's table"
    );
}

/// RGBA pixels of a PNG screenshot of the page at `#step=K`.
#[cfg(feature = "render")]
fn screenshot(browser: &Path, page: &Path, step: usize) -> resvg::tiny_skia::Pixmap {
    let png = tempdir("shot").with_extension("png");
    let url = format!("file://{}#step={step}", page.display());
    run_chromium(browser, &url, &[format!("--screenshot={}", png.display())]);
    resvg::tiny_skia::Pixmap::load_png(&png).expect("chromium wrote a PNG screenshot")
}

/// Pixels of the markers' colour (pure magenta: blocking cells, witness
/// points), which only the legend's swatch shares.
#[cfg(feature = "render")]
fn marker_pixels(p: &resvg::tiny_skia::Pixmap) -> usize {
    p.pixels()
        .iter()
        .filter(|c| c.red() > 220 && c.green() < 60 && c.blue() > 220)
        .count()
}

#[cfg(feature = "render")]
#[test]
fn a_screenshot_shows_the_scene_and_the_violation_at_its_step() {
    let browser = browser_or_skip!();
    let page = colliding_page();
    let at = screenshot(&browser, &page, 1);
    // Not blank: many colours, and a large part of the page drawn in
    // neither the page's white nor the scene's background.
    let colours: std::collections::HashSet<[u8; 3]> = at
        .pixels()
        .iter()
        .map(|c| [c.red(), c.green(), c.blue()])
        .collect();
    assert!(colours.len() > 200, "{} colours", colours.len());
    let drawn = at
        .pixels()
        .iter()
        .filter(|c| {
            let (r, g, b) = (c.red() as i32, c.green() as i32, c.blue() as i32);
            r + g + b < 600 && (r - 244).abs() + (g - 246).abs() + (b - 248).abs() > 12
        })
        .count();
    assert!(drawn > 20_000, "{drawn} pixels drawn");
    let before = screenshot(&browser, &page, 0);
    // The legend's swatch is magenta too: the markers add to it.
    let (marked, unmarked) = (marker_pixels(&at), marker_pixels(&before));
    assert!(
        marked > unmarked + 20,
        "the collision is marked at step 1: {marked} against {unmarked} magenta pixels at step 0"
    );
    assert!(
        unmarked < 200,
        "at step 0 only the legend is magenta: {unmarked}"
    );
}
