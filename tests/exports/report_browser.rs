//! The run report in a real browser: `index.html` of a run with models is rendered by headless
//! Chromium from `file://`, with the network off. Checked: every image loaded
//! (`naturalWidth > 0`, read by a script in a test-only copy of the page and written into the
//! DOM that `--dump-dom` prints), the page logged nothing to the console (the real page has no
//! scripts, so any console line is an error, e.g. a blocked resource), and its screenshot is
//! not blank. Without a browser the test is skipped with a visible `skipped:` line
//! ([`common::skip`]); under CI (`CI` set) a missing browser is a failure.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use smithwalk::exports::plot::{PlotOptions, plot};
use smithwalk::setup::config::{Config, Model};

use crate::common;

/// Why the tests skip without a browser, and how to get one (`.ci/run` installs it under CI).
const NO_BROWSER: &str = "no chromium on PATH (Debian: apt-get install chromium)";

/// The first of Debian's and other distributions' Chromium commands on PATH.
fn browser() -> Option<PathBuf> {
    let names = ["chromium", "chromium-browser", "google-chrome", "google-chrome-stable"];
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path).flat_map(|dir| names.map(|n| dir.join(n))).find(|p| p.is_file())
}

/// Runs headless Chromium on `page` with `args`, in a fresh profile, killing it after 120 s.
fn chromium(browser: &Path, page: &Path, args: &[String]) -> Output {
    let profile = tempfile::tempdir().unwrap();
    let mut child = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=5000",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(args)
        .arg(format!("file://{}", page.display()))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start the browser");
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(120) {
            child.kill().unwrap();
            panic!("{} did not finish in 120 s", browser.display());
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    child.wait_with_output().unwrap()
}

/// The page's console messages in Chromium's log (`...:INFO:CONSOLE:12] "message", source: ...`).
fn console_lines(stderr: &[u8]) -> Vec<String> {
    String::from_utf8_lossy(stderr).lines().filter(|l| l.contains(":CONSOLE")).map(String::from).collect()
}

/// A script, put first in a test-only copy of the page, that records errors (script errors and
/// resources that failed, caught on their way down) and on `load` writes how many images there
/// are, which did not decode, and the errors into a `<pre id="smithwalk-check">`.
const CHECK: &str = r#"<script>
var smithwalkErrors = [];
window.addEventListener('error', function (e) {
  smithwalkErrors.push(e.target && e.target.src ? 'resource ' + e.target.src : String(e.message));
}, true);
console.error = function () { smithwalkErrors.push('console.error ' + Array.from(arguments).join(' ')); };
window.addEventListener('load', function () {
  var images = Array.from(document.images);
  var broken = images.filter(function (i) { return !(i.complete && i.naturalWidth > 0); })
                     .map(function (i) { return i.getAttribute('src'); });
  var out = document.createElement('pre');
  out.id = 'smithwalk-check';
  out.textContent = 'images=' + images.length + ' broken=' + JSON.stringify(broken) +
                    ' errors=' + JSON.stringify(smithwalkErrors);
  document.body.appendChild(out);
});
</script>"#;

#[test]
fn the_report_renders_in_chromium_with_every_image_and_no_error() {
    let dir = tempfile::tempdir().unwrap();
    let toml = "paths = 20000\nseed = 5\n[surface]\nalpha = 0.5\n[[material]]\nkind = \"conductor\"\n[[material]]\nkind = \"dielectric\"\neta = 1.5\n[incident]\ntheta_deg = [0, 45]\n[detector]\ncos_theta_bins = 8\nphi_bins = 16\nmax_order = 3\n";
    let config = Config::parse(toml).unwrap();
    let sim = smithwalk::simulate(&config, Some(2), false).unwrap();
    smithwalk::write_outputs(&sim, &config, dir.path()).unwrap();
    smithwalk::analysis::compare::compare(dir.path(), &[Model::Single, Model::HeitzNee], Some(20000), Some(2)).unwrap();
    plot(dir.path(), &PlotOptions::default()).unwrap();
    let index = dir.path().join("index.html");
    let html = std::fs::read_to_string(&index).unwrap();
    // Nothing to fetch from the network: no absolute URL anywhere in the page.
    for scheme in ["http:", "https:", "src=\"//", "href=\"//"] {
        assert!(!html.contains(scheme), "index.html refers to {scheme}");
    }
    let images = html.matches("<img ").count();
    assert!(images >= 10, "{images} images");

    let Some(browser) = browser() else {
        return common::skip("tests/exports/report_browser.rs", NO_BROWSER);
    };

    // Every image decoded and no script or resource error, read from the DOM.
    let check_page = dir.path().join("index_check.html");
    std::fs::write(&check_page, html.replacen("<head>", &format!("<head>{CHECK}"), 1)).unwrap();
    let dumped = chromium(&browser, &check_page, &["--dump-dom".into()]);
    let dom = String::from_utf8_lossy(&dumped.stdout);
    let report = dom
        .split("<pre id=\"smithwalk-check\">")
        .nth(1)
        .and_then(|rest| rest.split("</pre>").next())
        .unwrap_or_else(|| panic!("the check did not run; stderr:\n{}", String::from_utf8_lossy(&dumped.stderr)));
    assert_eq!(report, format!("images={images} broken=[] errors=[]"));

    // The real page: no console message, and a screenshot with content.
    let shot = dir.path().join("screenshot.png");
    let rendered =
        chromium(&browser, &index, &[format!("--screenshot={}", shot.display()), "--window-size=1280,1800".into()]);
    assert!(rendered.status.success(), "{}", String::from_utf8_lossy(&rendered.stderr));
    assert_eq!(console_lines(&rendered.stderr), Vec::<String>::new());
    let image = image::open(&shot).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (1280, 1800));
    let inked = image.pixels().filter(|p| p.0.iter().any(|&c| c < 200)).count() as f64;
    let colours: std::collections::BTreeSet<[u8; 3]> = image.pixels().map(|p| p.0).collect();
    assert!(inked / (1280.0 * 1800.0) > 0.02, "the screenshot is nearly blank: {inked} dark pixels");
    assert!(colours.len() > 50, "the screenshot has only {} colours", colours.len());
}

#[test]
fn a_console_error_and_a_missing_image_are_caught() {
    // The checks themselves, on a page that has both faults.
    let Some(browser) = browser() else {
        return common::skip("tests/exports/report_browser.rs (its self-check)", NO_BROWSER);
    };
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("bad.html");
    let html = "<!DOCTYPE html><html><head></head><body><img src=\"missing.png\"><script>console.error('boom')</script></body></html>";
    std::fs::write(&page, html).unwrap();
    assert_eq!(console_lines(&chromium(&browser, &page, &["--dump-dom".into()]).stderr).len(), 1);
    std::fs::write(&page, html.replacen("<head>", &format!("<head>{CHECK}"), 1)).unwrap();
    let dom = String::from_utf8_lossy(&chromium(&browser, &page, &["--dump-dom".into()]).stdout).into_owned();
    assert!(dom.contains("images=1 broken=[\"missing.png\"]"), "{dom}");
    assert!(dom.contains("console.error boom"), "{dom}");
}
