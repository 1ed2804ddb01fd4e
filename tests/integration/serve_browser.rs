//! The chat page end to end in a real browser: Debian's chromium, driven by playwright-core
//! (tests/browser/serve_page.mjs), opens `tactex serve`, asks a question, and checks the
//! answer, the detection overlay, the tactile frames, the hardness bars and the latency
//! table; the screenshot lands in the test's target directory. Without node, the npm
//! packages or chromium it fails; outside CI (CI=true) it is ignored unless asked for,
//! where `.ci/run` installs them.

use crate::serve_process::Server;
use std::path::Path;
use std::process::Command;

fn missing_tools() -> Option<String> {
    let browser = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/browser");
    if Command::new("node").arg("--version").output().is_err() {
        return Some("node is not installed".into());
    }
    if !browser.join("node_modules/playwright-core").is_dir() {
        return Some("playwright-core is not installed: npm ci --prefix tests/browser".into());
    }
    let chromium = std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
    if !Path::new(&chromium).is_file() {
        return Some(format!(
            "{chromium} is not installed (apt-get install chromium)"
        ));
    }
    None
}

#[test]
#[cfg_attr(
    not(ci),
    ignore = "needs chromium, Node.js and playwright-core (tests/browser), as .ci/run installs"
)]
fn the_page_shows_the_live_view_the_answer_and_the_tactile_frames() {
    if let Some(missing) = missing_tools() {
        panic!("the browser test cannot run: {missing}");
    }
    let server = Server::start(&[]);
    let screenshot = Path::new(env!("CARGO_TARGET_TMPDIR")).join("serve-page.png");
    let _ = std::fs::remove_file(&screenshot);
    let out = Command::new("node")
        .arg("tests/browser/serve_page.mjs")
        .arg(format!("{}/", server.url))
        .arg(&screenshot)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("runs node");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "browser test failed: {}{stdout}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(stdout.trim()).expect("the script prints one JSON line");
    assert!(
        report["answer"].as_str().unwrap().contains("softest"),
        "{report}"
    );
    let shot = image::open(&screenshot).expect("a screenshot PNG");
    assert!(shot.width() >= 1000 && shot.height() >= 600);
    eprintln!("screenshot: {}", screenshot.display());
    readme_screenshot_shows(&report["answer"], &screenshot);
}

/// README shows this test's screenshot, and beside it the answer the page gave then. The
/// answer is deterministic (the built-in scene and seed), so when the twin's answer changes
/// the stored one no longer matches and the test fails until the screenshot is made again:
/// `TACTEX_BLESS=1 cargo test --test integration serve_browser -- --include-ignored`
/// (the latency figures in it are the machine's of that run).
fn readme_screenshot_shows(answer: &serde_json::Value, screenshot: &Path) {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/results/serve");
    let stored = docs.join("screenshot.json");
    let now = serde_json::json!({ "question": "Which fruit is the softest?", "answer": answer });
    if std::env::var_os("TACTEX_BLESS").is_some() {
        // Three quarters of the page's width keeps README's image readable and its file small.
        let shot = image::open(screenshot).expect("a screenshot PNG");
        shot.resize(
            shot.width() * 3 / 4,
            shot.height() * 3 / 4,
            image::imageops::FilterType::Triangle,
        )
        .save(docs.join("screenshot.png"))
        .expect("writes the screenshot");
        std::fs::write(&stored, format!("{:#}\n", now)).expect("writes the answer");
        return;
    }
    let then: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&stored).expect("docs/results/serve/screenshot.json"),
    )
    .expect("JSON");
    assert_eq!(
        then, now,
        "README's screenshot (docs/results/serve) shows another answer than the page gives now; make it again with TACTEX_BLESS=1 (see this test's doc)"
    );
}
