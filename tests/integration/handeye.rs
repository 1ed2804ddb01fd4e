//! `tactex handeye` on the twin: the scene camera misplaced by a known error, found again
//! from the board the arm holds (issue 48's bar: 1 mm and 0.1 degree from 15 stations), and
//! refusals that name what is wrong and write nothing.

use crate::cli::tactex;

#[cfg(feature = "opencv")]
#[test]
fn handeye_finds_a_misplaced_twin_camera_from_fifteen_stations() {
    let dir = tempfile::tempdir().unwrap();
    let calib = dir.path().join("calib.toml");
    let frames = dir.path().join("frames");
    let out = tactex(&[
        "handeye",
        "--backend",
        "twin",
        "--poses",
        "15",
        "--camera-error-mm",
        "20",
        "--camera-error-deg",
        "2",
        "--out",
        calib.to_str().unwrap(),
        "--frames",
        frames.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let solvers = report["solvers"].as_array().unwrap();
    assert_eq!(solvers.len(), 3);
    for s in solvers {
        let (mm, deg) = (
            s["error_mm"].as_f64().unwrap(),
            s["error_deg"].as_f64().unwrap(),
        );
        assert!(mm < 1.0 && deg < 0.1, "{}: {mm} mm {deg} deg", s["method"]);
    }
    assert_eq!(report["fit"]["stations_used"], 15);
    // The file holds the refined camera, as the report does.
    let file: toml::Value = toml::from_str(&std::fs::read_to_string(&calib).unwrap()).unwrap();
    let position = file["camera"]["position_m"].as_array().unwrap();
    assert_eq!(position.len(), 3);
    assert_eq!(
        position[2].as_float().unwrap(),
        report["camera"]["position_m"][2].as_f64().unwrap()
    );
    assert!(frames.join("station-14.png").is_file());
}

#[test]
fn handeye_refuses_bad_inputs_by_name_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let calib = dir.path().join("calib.toml");
    let bad_board = dir.path().join("board.toml");
    std::fs::write(&bad_board, "squares_x = 7\nsquares_y = 5\nsquare_mm = 30.0\nmarker_mm = 40.0\ndictionary = \"DICT_5X5_100\"\n").unwrap();
    let out_flag = calib.to_str().unwrap();
    for (args, says) in [
        (vec!["--poses", "2"], "--poses"),
        (vec!["--poses", "101"], "--poses"),
        (vec!["--camera-error-mm=-1"], "--camera-error-mm"),
        (vec!["--camera-error-deg", "nan"], "--camera-error-deg"),
        (vec!["--board", bad_board.to_str().unwrap()], "board.toml"),
        (vec!["--board", "no-such-board.toml"], "no-such-board.toml"),
        (vec!["--scene", "no-such-scene.toml"], "no-such-scene.toml"),
    ] {
        let mut all = vec!["handeye", "--out", out_flag];
        all.extend(args.iter().copied());
        let out = tactex(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} was accepted");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(!calib.exists(), "{args:?} wrote {}", calib.display());
    }
}
