//! `tactex serve` over HTTP: a question answered with its progress streamed and its tactile
//! frames served, the same answer as `tactex ask`, bad requests answered with errors while the
//! server keeps serving, and the limit on questions at once.

use crate::serve_process::Server;
use serde_json::Value;
use std::io::{BufRead, BufReader, Read};
use std::process::Command;
use std::time::Duration;

fn agent() -> ureq::Agent {
    ureq::Agent::config_builder()
        .http_status_as_error(false)
        .timeout_global(Some(Duration::from_secs(600)))
        .build()
        .into()
}

fn get(url: &str) -> (u16, Vec<u8>) {
    let mut r = agent().get(url).call().expect("GET reaches the server");
    let mut body = Vec::new();
    r.body_mut()
        .as_reader()
        .read_to_end(&mut body)
        .expect("reads the body");
    (r.status().as_u16(), body)
}

fn post(url: &str, body: &str) -> (u16, Value) {
    let mut r = agent()
        .post(url)
        .header("Content-Type", "application/json")
        .send(body)
        .expect("POST reaches the server");
    let status = r.status().as_u16();
    let text = r.body_mut().read_to_string().expect("reads the body");
    let json = serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("status {status}: body is not JSON ({e}): {text}"));
    (status, json)
}

fn ask(server: &Server, prompt: &str) -> (u16, Value) {
    post(
        &format!("{}/api/ask", server.url),
        &serde_json::json!({ "prompt": prompt }).to_string(),
    )
}

/// Reads a question's event stream to its end: (event name, JSON data) in order.
fn events(server: &Server, id: u64) -> Vec<(String, Value)> {
    let r = agent()
        .get(&format!("{}/api/queries/{id}/events", server.url))
        .call()
        .expect("GET events");
    assert_eq!(r.status().as_u16(), 200);
    let mut out = Vec::new();
    let mut name = String::new();
    for line in BufReader::new(r.into_body().into_reader()).lines() {
        let line = line.expect("reads the stream");
        if let Some(n) = line.strip_prefix("event: ") {
            name = n.to_string();
        } else if let Some(d) = line.strip_prefix("data: ") {
            out.push((
                name.clone(),
                serde_json::from_str(d).expect("event data is JSON"),
            ));
        }
    }
    out
}

fn png_size(bytes: &[u8]) -> (u32, u32) {
    let image = image::load_from_memory_with_format(bytes, image::ImageFormat::Png).expect("a PNG");
    (image.width(), image.height())
}

#[test]
fn a_question_streams_its_progress_and_ends_with_the_answer_ask_gives() {
    let server = Server::start(&[]);
    let (status, page) = get(&format!("{}/", server.url));
    assert_eq!(status, 200);
    assert!(String::from_utf8_lossy(&page).contains("<title>TactEx twin</title>"));

    let (status, scene) = get(&format!("{}/api/scene", server.url));
    assert_eq!(status, 200);
    let scene: Value = serde_json::from_slice(&scene).unwrap();
    let (status, view) = get(&format!("{}/api/view.png", server.url));
    assert_eq!(status, 200);
    assert_eq!(
        png_size(&view),
        (
            scene["view"]["width"].as_u64().unwrap() as u32,
            scene["view"]["height"].as_u64().unwrap() as u32
        )
    );

    let prompt = "Which fruit is the softest?";
    let (status, started) = ask(&server, prompt);
    assert_eq!(status, 202, "{started}");
    let id = started["id"].as_u64().unwrap();
    let events = events(&server, id);

    let (last, answer) = events.last().expect("some events");
    assert_eq!(last, "answer", "{answer}");
    let progress: Vec<&Value> = events
        .iter()
        .filter(|(n, _)| n == "progress")
        .map(|(_, v)| v)
        .collect();
    let started: Vec<&str> = progress
        .iter()
        .filter(|p| p["event"] == "stage_started")
        .map(|p| p["stage"].as_str().unwrap())
        .collect();
    assert_eq!(started, ["parse", "ground", "press", "hardness", "explain"]);
    let detected = progress
        .iter()
        .find(|p| p["event"] == "detected")
        .expect("a detected event");
    let sightings = detected["objects"].as_array().unwrap();
    let objects = answer["answer"]["objects"].as_array().unwrap();
    assert_eq!(sightings.len(), objects.len());
    assert!(!objects.is_empty());
    for (s, o) in sightings.iter().zip(objects) {
        assert_eq!(s["label"], o["label"]);
        let b: Vec<u64> = serde_json::from_value(s["bbox"].clone()).unwrap();
        assert!(
            b[0] <= b[2] && b[1] <= b[3] && b[2] < 640 && b[3] < 480,
            "{b:?}"
        );
    }
    let pressed = progress.iter().filter(|p| p["event"] == "pressed").count();
    assert_eq!(pressed, objects.len(), "one press per object");

    // The page's answer is `tactex ask`'s answer for the same scene and seed.
    let cli = Command::new(env!("CARGO_BIN_EXE_tactex"))
        .args(["ask", "--json", "--reproducible", prompt])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("runs tactex ask");
    assert!(cli.status.success());
    let cli: Value = serde_json::from_slice(&cli.stdout).unwrap();
    assert_eq!(answer["answer"]["answer"], cli["answer"]);
    assert_eq!(answer["answer"]["selected"], cli["selected"]);

    // Every touched object's frames: the reference and the press, at the sensor's size.
    let tactile = answer["tactile"].as_array().unwrap();
    assert_eq!(tactile.len(), objects.len());
    for (i, t) in tactile.iter().enumerate() {
        let frames = t["frames"].as_u64().expect("every object was touched");
        assert_eq!(frames, 9, "reference + 8 press frames");
        let frame = |f: &str| {
            let (status, png) = get(&format!(
                "{}/api/queries/{id}/objects/{i}/frames/{f}.png",
                server.url
            ));
            assert_eq!(status, 200, "frame {f}");
            assert_eq!(png_size(&png), (320, 240));
            image::load_from_memory(&png).unwrap().to_rgb8()
        };
        let (reference, deepest, imprint) = (
            frame("0"),
            frame(&(frames - 1).to_string()),
            frame("imprint"),
        );
        // The imprint is the deepest frame's difference from the reference, x4 about grey,
        // and the press shows in it.
        let mut moved = 0;
        for ((r, d), m) in reference
            .pixels()
            .zip(deepest.pixels())
            .zip(imprint.pixels())
        {
            for c in 0..3 {
                let want = (128 + 4 * (i32::from(d[c]) - i32::from(r[c]))).clamp(0, 255);
                assert_eq!(i32::from(m[c]), want);
            }
            moved += usize::from(m.0.iter().any(|&c| c.abs_diff(128) > 24));
        }
        assert!(moved > 1000, "object {i}: {moved} pixels show the press");
        let (status, _) = get(&format!(
            "{}/api/queries/{id}/objects/{i}/frames/{frames}.png",
            server.url
        ));
        assert_eq!(status, 404);
    }
}

#[test]
fn bad_requests_get_error_responses_and_the_server_keeps_serving() {
    let server = Server::start(&["--max-prompt-chars", "80"]);
    let url = format!("{}/api/ask", server.url);
    let cases: [(&str, u16, &str); 5] = [
        ("not json", 400, "request body"),
        (
            r#"{"prompt": "Which fruit is the softest?", "x": 1}"#,
            400,
            "unknown field",
        ),
        (r#"{"prompt": "   "}"#, 422, "empty"),
        (r#"{"prompt": "hello there"}"#, 422, "no known fruit"),
        (
            &format!(
                r#"{{"prompt": "Which fruit is the softest{}?"}}"#,
                " really".repeat(10)
            ),
            422,
            "the limit is 80",
        ),
    ];
    for (body, want, says) in cases {
        let (status, reply) = post(&url, body);
        assert_eq!(status, want, "{body}: {reply}");
        let message = reply["error"].as_str().expect("an error message");
        assert!(message.contains(says), "{body}: {message}");
        assert!(!message.contains('\n'), "one line: {message}");
    }
    // A body far beyond a question is refused before it is read.
    let huge = format!(r#"{{"prompt": "{}"}}"#, "a".repeat(100_000));
    let r = agent()
        .post(&url)
        .header("Content-Type", "application/json")
        .send(&huge)
        .expect("POST reaches the server");
    assert_eq!(r.status().as_u16(), 413);
    let text = r.into_body().read_to_string().unwrap();
    let reply: Value = serde_json::from_str(&text).expect("413 answered as JSON");
    assert!(reply["error"].as_str().unwrap().contains("16384 bytes"));

    // Only JSON bodies, and only from this server's page or from clients without an Origin:
    // a page elsewhere cannot queue questions (a form posts text/plain without preflight).
    let host = server.url.trim_start_matches("http://").to_string();
    let question = r#"{"prompt": "hello"}"#;
    for (content_type, origin, want, says) in [
        ("text/plain", None, 415, "application/json"),
        (
            "application/x-www-form-urlencoded",
            None,
            415,
            "application/json",
        ),
        (
            "application/json",
            Some("http://evil.example".to_string()),
            403,
            "Origin",
        ),
        ("application/json", Some("null".to_string()), 403, "Origin"),
        // Past both checks: the prompt itself is what is wrong.
        (
            "application/json",
            Some(format!("http://{host}")),
            422,
            "no known fruit",
        ),
        (
            "application/json; charset=utf-8",
            None,
            422,
            "no known fruit",
        ),
    ] {
        let mut request = agent().post(&url).header("Content-Type", content_type);
        if let Some(origin) = &origin {
            request = request.header("Origin", origin);
        }
        let mut r = request.send(question).expect("POST reaches the server");
        let status = r.status().as_u16();
        let reply: Value = serde_json::from_str(&r.body_mut().read_to_string().unwrap())
            .expect("an error as JSON");
        assert_eq!(status, want, "{content_type} {origin:?}: {reply}");
        assert!(
            reply["error"].as_str().unwrap().contains(says),
            "{content_type} {origin:?}: {reply}"
        );
    }
    // URLs that do not parse and methods a route has not: JSON errors like the rest.
    for (path, want) in [
        ("/api/queries/abc/events", 400),
        ("/api/queries/1/objects/x/frames/0.png", 400),
        ("/api/ask", 405),
    ] {
        let (status, body) = get(&format!("{}{path}", server.url));
        assert_eq!(status, want, "{path}");
        let reply: Value = serde_json::from_slice(&body).expect("an error as JSON");
        assert!(reply["error"].is_string(), "{path}: {reply}");
    }

    for (path, what) in [
        ("/api/queries/999/events", "question 999"),
        ("/api/queries/999/objects/0/frames/0.png", "question 999"),
        ("/nowhere", "no such page"),
    ] {
        let (status, body) = get(&format!("{}{path}", server.url));
        assert_eq!(status, 404, "{path}");
        assert!(String::from_utf8_lossy(&body).contains(what), "{path}");
    }
    let (status, _) = get(&format!("{}/api/scene", server.url));
    assert_eq!(status, 200, "still serving");
}

#[test]
fn a_question_beyond_the_limit_at_once_is_refused_until_one_finishes() {
    let server = Server::start(&["--max-queries", "1"]);
    let (first, started) = ask(&server, "How hard is the banana?");
    assert_eq!(first, 202);
    let (second, refused) = ask(&server, "How hard is the mango?");
    assert_eq!(second, 429, "{refused}");
    assert!(refused["error"].as_str().unwrap().contains("busy"));
    let events = events(&server, started["id"].as_u64().unwrap());
    assert_eq!(events.last().unwrap().0, "answer");
    // The slot is given back when the question is done; the event stream can end a moment
    // before that.
    let mut status = 0;
    for _ in 0..50 {
        status = ask(&server, "How hard is the banana?").0;
        if status != 429 {
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    assert_eq!(status, 202);
}

#[test]
fn a_missing_scene_or_a_taken_port_is_a_one_line_error() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    for (args, says) in [
        (
            vec!["serve", "--scene", "no/such/scene.toml"],
            "no/such/scene.toml",
        ),
        (vec!["serve", "--port", port.as_str()], "cannot listen"),
        (vec!["serve", "--max-queries", "0"], "--max-queries"),
        (
            vec!["serve", "--max-prompt-chars", "0"],
            "--max-prompt-chars",
        ),
        // A config the template never reads is refused rather than silently ignored.
        (
            vec!["serve", "--llm-config", "no/such/llm.toml"],
            "--llm-config no/such/llm.toml",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_tactex"))
            .args(&args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .expect("runs tactex");
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    }
}
