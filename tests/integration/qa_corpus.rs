//! The hostile-input corpus (tests/qa/cli.toml): every command-line input QA found wrong,
//! with the class of outcome it must have now. One case per input, each in a folder of
//! its own; a case that panics, hangs, exits with another class or names the wrong thing
//! fails, and the failures are listed together.

use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[derive(Deserialize)]
struct Corpus {
    case: Vec<Case>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    why: String,
    args: Vec<String>,
    outcome: Outcome,
    #[serde(default)]
    names: Option<String>,
    #[serde(default)]
    not_names: Option<String>,
    #[serde(default)]
    absent: Option<String>,
    #[serde(default)]
    files: BTreeMap<String, String>,
    #[serde(default)]
    dirs: Vec<String>,
}

#[derive(Deserialize, PartialEq)]
#[serde(rename_all = "lowercase")]
enum Outcome {
    Ok,
    Refused,
}

/// A hang is a failure: no case of the corpus takes this long on CI's two cores.
const LIMIT: Duration = Duration::from_secs(60);

/// What is wrong with the case's outcome, if anything.
fn check(case: &Case) -> Option<String> {
    let root = env!("CARGO_MANIFEST_DIR");
    let tmp = tempfile::tempdir().unwrap();
    let fill = |s: &str| {
        s.replace("{tmp}", tmp.path().to_str().unwrap())
            .replace("{fots}", &format!("{root}/tests/fixtures/fots"))
    };
    for (name, text) in &case.files {
        std::fs::write(tmp.path().join(name), fill(text)).unwrap();
    }
    for dir in &case.dirs {
        std::fs::create_dir_all(tmp.path().join(dir)).unwrap();
    }
    let args: Vec<String> = case.args.iter().map(|a| fill(a)).collect();
    let mut child = Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(&args)
        .current_dir(root)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs tactex");
    // Drained on threads: a case that prints much would otherwise block on a full pipe.
    let (mut out, mut err) = (child.stdout.take().unwrap(), child.stderr.take().unwrap());
    let stdout = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut out, &mut s).ok();
        s
    });
    let stderr = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut err, &mut s).ok();
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > LIMIT {
            let _ = child.kill();
            return Some(format!("still running after {} s", LIMIT.as_secs()));
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let (stdout, stderr) = (stdout.join().unwrap(), stderr.join().unwrap());
    if stderr.contains("panicked") {
        return Some(format!("panicked: {stderr}"));
    }
    let said = format!("{stdout}{stderr}");
    let wrong = match case.outcome {
        Outcome::Ok if !status.success() => Some(format!("failed: {stderr}")),
        Outcome::Ok => None,
        Outcome::Refused if status.code() != Some(1) => {
            Some(format!("exit {:?}, not 1: {stderr}", status.code()))
        }
        Outcome::Refused if !stdout.is_empty() => Some(format!("printed on stdout: {stdout}")),
        Outcome::Refused
            if !(stderr.starts_with("error: ") && stderr.trim().lines().count() == 1) =>
        {
            Some(format!("not one 'error: ' line: {stderr}"))
        }
        Outcome::Refused => None,
    };
    wrong
        .or_else(|| {
            let names = case.names.as_deref()?;
            (!said.contains(names)).then(|| format!("does not name '{names}': {said}"))
        })
        .or_else(|| {
            let not = case.not_names.as_deref()?;
            said.contains(not).then(|| format!("names '{not}': {said}"))
        })
        .or_else(|| {
            let absent = fill(case.absent.as_deref()?);
            Path::new(&absent)
                .exists()
                .then(|| format!("left {absent} behind"))
        })
}

#[test]
fn every_input_qa_found_wrong_has_its_outcome() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/qa/cli.toml");
    let corpus: Corpus = toml::from_str(&std::fs::read_to_string(&path).unwrap())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(corpus.case.len() >= 20, "{} cases", corpus.case.len());
    let describe = |c: &Case| format!("tactex {} ({})", c.args.join(" "), c.why);
    // Two at a time: the cases are processes, and CI has two cores.
    let (a, b) = corpus.case.split_at(corpus.case.len() / 2);
    let run = |cases: &[Case]| -> Vec<String> {
        cases
            .iter()
            .filter_map(|c| check(c).map(|why| format!("{}: {why}", describe(c))))
            .collect()
    };
    let wrong: Vec<String> = std::thread::scope(|s| {
        let first = s.spawn(|| run(a));
        let mut w = run(b);
        w.extend(first.join().unwrap());
        w
    });
    assert!(
        wrong.is_empty(),
        "{} of {} cases:\n{}",
        wrong.len(),
        corpus.case.len(),
        wrong.join("\n")
    );
}
