use super::*;
use crate::geometry::CameraIntrinsics;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

/// A scene camera above the table's front, looking at its middle: a turn of 142 degrees from
/// the base frame, towards the half turn where Tsai-Lenz's form grows.
fn true_camera() -> Pose {
    Pose::camera_looking_at(DVec3::new(0.05, -0.45, 0.65), DVec3::new(0.0, 0.05, 0.0)).unwrap()
}

/// A board 6 cm below the flange, turned a little on it.
fn true_board() -> Pose {
    Pose::new(
        DVec3::new(0.01, -0.02, 0.06),
        DQuat::from_euler(glam::EulerRot::XYZ, 0.1, -0.05, 0.3),
    )
}

/// `n` flange poses over the table, tool down, turned about x, y and z by up to 25 degrees.
fn flange_poses(n: usize) -> Vec<Pose> {
    (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let position = DVec3::new(
                0.1 * t.cos(),
                0.1 + 0.08 * t.sin(),
                0.25 + 0.03 * (2.0 * t).sin(),
            );
            let turn = DQuat::from_euler(
                glam::EulerRot::XYZ,
                0.35 * (3.0 * t).sin(),
                0.35 * (2.0 * t + 1.0).cos(),
                0.45 * t.sin(),
            );
            Pose::new(
                position,
                turn * DQuat::from_rotation_x(std::f64::consts::PI),
            )
        })
        .collect()
}

/// The stations the true camera and board give, the board's pose perturbed by `noise` (its
/// position's sigma in m and its rotation's in radians, per axis).
fn stations(flanges: &[Pose], noise: (f64, f64), seed: u64) -> Vec<Station> {
    stations_seen_by(&true_camera(), flanges, noise, seed)
}

/// `stations` for another camera.
fn stations_seen_by(camera: &Pose, flanges: &[Pose], noise: (f64, f64), seed: u64) -> Vec<Station> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let (pos, rot) = (
        Normal::new(0.0, noise.0.max(1e-300)).unwrap(),
        Normal::new(0.0, noise.1.max(1e-300)).unwrap(),
    );
    let board = true_board();
    flanges
        .iter()
        .map(|flange| {
            let seen = camera.inverse().compose(&flange.compose(&board));
            let jitter = DQuat::from_scaled_axis(DVec3::new(
                rot.sample(&mut rng),
                rot.sample(&mut rng),
                rot.sample(&mut rng),
            ));
            let shift = DVec3::new(
                pos.sample(&mut rng),
                pos.sample(&mut rng),
                pos.sample(&mut rng),
            );
            Station {
                flange_in_base: *flange,
                board_in_camera: Pose::new(seen.position + shift, jitter * seen.rotation),
            }
        })
        .collect()
}

/// Position error (mm) and rotation error (degrees) against the true camera.
fn errors(found: &Pose) -> (f64, f64) {
    errors_against(&true_camera(), found)
}

fn errors_against(truth: &Pose, found: &Pose) -> (f64, f64) {
    (
        1000.0 * (found.position - truth.position).length(),
        turn_deg(found.rotation.inverse() * truth.rotation),
    )
}

#[test]
fn noise_free_stations_give_the_true_camera_by_both_methods() {
    let stations = stations(&flange_poses(15), (0.0, 0.0), 1);
    for method in [HandEyeMethod::TsaiLenz, HandEyeMethod::ParkMartin] {
        let solution = solve_hand_eye(&stations, method).unwrap();
        let (mm, deg) = errors(&solution.camera_in_base);
        assert!(mm < 1e-6 && deg < 1e-6, "{method:?}: {mm} mm, {deg} deg");
        let board = true_board();
        assert!((solution.board_in_flange.position - board.position).length() < 1e-9);
        assert!(
            solution
                .residuals
                .iter()
                .all(|r| r.translation_mm < 1e-6 && r.rotation_deg < 1e-6)
        );
    }
}

#[test]
fn a_camera_looking_straight_down_is_found_by_both_methods() {
    // A half turn about x from the base frame: Tsai-Lenz's [a + b]x are all singular there.
    let camera =
        Pose::camera_looking_at(DVec3::new(0.02, 0.05, 0.7), DVec3::new(0.02, 0.05, 0.0)).unwrap();
    let stations = stations_seen_by(&camera, &flange_poses(15), (0.0, 0.0), 1);
    for method in [HandEyeMethod::TsaiLenz, HandEyeMethod::ParkMartin] {
        let found = solve_hand_eye(&stations, method).unwrap().camera_in_base;
        let (mm, deg) = errors_against(&camera, &found);
        assert!(mm < 1e-6 && deg < 1e-6, "{method:?}: {mm} mm, {deg} deg");
    }
}

#[test]
fn fifteen_stations_with_board_pose_noise_place_the_camera_to_millimetres() {
    // Each board pose off by 0.5 mm and 0.05 degrees per axis (1 sigma): the size to measure
    // on the twin's renders once its camera sees a board.
    let noise = (0.0005, 0.05f64.to_radians());
    for method in [HandEyeMethod::TsaiLenz, HandEyeMethod::ParkMartin] {
        let (mut mms, mut degs) = (Vec::new(), Vec::new());
        for seed in 0..20 {
            let stations = stations(&flange_poses(15), noise, seed);
            let solution = solve_hand_eye(&stations, method).unwrap();
            let (mm, deg) = errors(&solution.camera_in_base);
            mms.push(mm);
            degs.push(deg);
            // Each station's residual is of the noise's size, not of an error in X.
            let median = {
                let mut r: Vec<f64> = solution
                    .residuals
                    .iter()
                    .map(|r| r.translation_mm)
                    .collect();
                r.sort_by(f64::total_cmp);
                r[r.len() / 2]
            };
            assert!(
                median < 3.0,
                "{method:?} seed {seed}: median residual {median} mm"
            );
        }
        mms.sort_by(f64::total_cmp);
        degs.sort_by(f64::total_cmp);
        let (median, worst) = ((mms[10], degs[10]), (mms[19], degs[19]));
        assert!(
            median.0 < 1.5 && median.1 < 0.1 && worst.0 < 2.5 && worst.1 < 0.25,
            "{method:?}: median {median:?}, worst {worst:?} (mm, degrees)"
        );
    }
}

#[test]
fn degenerate_station_sets_are_refused_with_what_is_missing() {
    let flanges = flange_poses(15);
    let two = stations(&flanges[..2], (0.0, 0.0), 1);
    assert_eq!(
        solve_hand_eye(&two, HandEyeMethod::ParkMartin),
        Err(HandEyeError::TooFewStations(2))
    );
    // Pure translations: the flange never turns.
    let shifted: Vec<Pose> = flanges
        .iter()
        .map(|f| Pose::new(f.position, flanges[0].rotation))
        .collect();
    for method in [HandEyeMethod::TsaiLenz, HandEyeMethod::ParkMartin] {
        assert_eq!(
            solve_hand_eye(&stations(&shifted, (0.0, 0.0), 1), method),
            Err(HandEyeError::NoRotation)
        );
    }
    // Turns about the vertical only (a SCARA's motions).
    let about_z: Vec<Pose> = (0..10)
        .map(|i| {
            Pose::new(
                DVec3::new(0.02 * i as f64, 0.1, 0.3),
                DQuat::from_rotation_z(0.2 * i as f64)
                    * DQuat::from_rotation_x(std::f64::consts::PI),
            )
        })
        .collect();
    for method in [HandEyeMethod::TsaiLenz, HandEyeMethod::ParkMartin] {
        assert_eq!(
            solve_hand_eye(&stations(&about_z, (0.0, 0.0), 1), method),
            Err(HandEyeError::OneAxis)
        );
    }
}

#[test]
fn the_symmetric_eigensolver_gives_each_pair() {
    let m = DMat3::from_cols(
        DVec3::new(4.0, 1.0, -2.0),
        DVec3::new(1.0, 3.0, 0.5),
        DVec3::new(-2.0, 0.5, 1.0),
    );
    let (values, vectors) = rotation_fit::symmetric_eigen(m);
    assert!(values[0] >= values[1] && values[1] >= values[2]);
    for (l, v) in values.iter().zip(vectors) {
        assert!((v.length() - 1.0).abs() < 1e-12);
        assert!((m * v - v * *l).length() < 1e-10, "{l} {v}");
    }
    assert!((values.iter().sum::<f64>() - 8.0).abs() < 1e-10);
}

/// A ChArUco board's inner corners: 6 x 4 at 30 mm, centred on the board's origin.
fn board_corners() -> Vec<DVec3> {
    (0..4)
        .flat_map(|j| {
            (0..6).map(move |i| DVec3::new(0.03 * (i as f64 - 2.5), 0.03 * (j as f64 - 1.5), 0.0))
        })
        .collect()
}

/// The corners the true camera sees at each station, each off by `pixel_sigma`.
fn corner_stations(flanges: &[Pose], pixel_sigma: f64, seed: u64) -> Vec<CornerStation> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
    let noise = Normal::new(0.0, pixel_sigma).unwrap();
    let intrinsics = CameraIntrinsics::default();
    let (camera, board) = (true_camera(), true_board());
    flanges
        .iter()
        .map(|flange| {
            let board_in_camera = camera.inverse().compose(&flange.compose(&board));
            let corners = board_corners()
                .into_iter()
                .map(|c| {
                    let (u, v) = intrinsics
                        .project(board_in_camera.transform_point(c))
                        .unwrap();
                    BoardCorner {
                        on_board_m: c,
                        seen_px: [u + noise.sample(&mut rng), v + noise.sample(&mut rng)],
                    }
                })
                .collect();
            CornerStation {
                flange_in_base: *flange,
                corners,
            }
        })
        .collect()
}

#[test]
fn refining_on_the_corners_places_the_camera_closer_than_its_park_martin_start() {
    let flanges = flange_poses(15);
    let intrinsics = CameraIntrinsics::default();
    let (mut closed, mut refined, mut rms) = (Vec::new(), Vec::new(), Vec::new());
    for seed in 0..10 {
        let start = solve_hand_eye(
            &stations(&flanges, (0.0005, 0.05f64.to_radians()), seed),
            HandEyeMethod::ParkMartin,
        )
        .unwrap();
        let corners = corner_stations(&flanges, 0.3, seed);
        let r = refine_on_corners(&corners, &intrinsics, &start).unwrap();
        closed.push(errors(&start.camera_in_base));
        refined.push(errors(&r.camera_in_base));
        rms.push(r.rms_px);
        assert_eq!(r.station_rms_px.len(), 15);
        assert!(
            r.converged,
            "seed {seed}: stopped at {} iterations",
            r.iterations
        );
    }
    let median = |v: &[(f64, f64)], k: usize| {
        let mut x: Vec<f64> = v.iter().map(|e| if k == 0 { e.0 } else { e.1 }).collect();
        x.sort_by(f64::total_cmp);
        x[x.len() / 2]
    };
    let (mm, deg) = (median(&refined, 0), median(&refined, 1));
    let (closed_mm, closed_deg) = (median(&closed, 0), median(&closed, 1));
    assert!(
        mm < 0.8 * closed_mm && deg < closed_deg,
        "refined {mm} mm {deg} deg, closed form {closed_mm} mm {closed_deg} deg"
    );
    assert!(mm < 1.0 && deg < 0.1);
    // The corners' noise is what is left: 0.3 px per coordinate, 0.42 px per corner.
    assert!(rms.iter().all(|r| (0.35..0.5).contains(r)), "{rms:?}");
}

#[test]
fn a_refinement_with_too_few_corners_is_refused() {
    let flanges = flange_poses(4);
    let start = solve_hand_eye(
        &stations(&flanges, (0.0, 0.0), 1),
        HandEyeMethod::ParkMartin,
    )
    .unwrap();
    let mut corners = corner_stations(&flanges, 0.0, 1);
    corners.iter_mut().for_each(|s| s.corners.truncate(2));
    assert_eq!(
        refine_on_corners(&corners, &CameraIntrinsics::default(), &start),
        Err(HandEyeError::TooFewCorners(8))
    );
}

#[test]
fn stations_that_are_not_poses_are_refused_by_index() {
    let flanges = flange_poses(5);
    let good = stations(&flanges, (0.0, 0.0), 1);
    let mut nan = good.clone();
    nan[3].board_in_camera.position.y = f64::NAN;
    let err = solve_hand_eye(&nan, HandEyeMethod::TsaiLenz).unwrap_err();
    assert!(
        matches!(&err, HandEyeError::BadStation { station: 3, what } if what.contains("board's pose")),
        "{err}"
    );
    let mut scaled = good.clone();
    scaled[1].flange_in_base.rotation *= 2.0;
    let err = solve_hand_eye(&scaled, HandEyeMethod::ParkMartin).unwrap_err();
    assert!(
        err.to_string()
            .starts_with("station 1: the flange's pose has a rotation quaternion of length 2"),
        "{err}"
    );
    // Rounding in a file is not a mistake: a quaternion off by 1e-5 is normalised.
    let mut rounded = good;
    rounded[2].flange_in_base.rotation *= 1.0 + 1e-5;
    let found = solve_hand_eye(&rounded, HandEyeMethod::ParkMartin).unwrap();
    let (mm, deg) = errors(&found.camera_in_base);
    assert!(mm < 1e-3 && deg < 1e-4, "{mm} mm {deg} deg");
}

#[test]
fn a_station_without_corners_or_with_a_nan_corner_is_refused() {
    let flanges = flange_poses(4);
    let start = solve_hand_eye(
        &stations(&flanges, (0.0, 0.0), 1),
        HandEyeMethod::ParkMartin,
    )
    .unwrap();
    let intrinsics = CameraIntrinsics::default();
    let mut corners = corner_stations(&flanges, 0.0, 1);
    corners[2].corners.clear();
    let err = refine_on_corners(&corners, &intrinsics, &start).unwrap_err();
    assert_eq!(err.to_string(), "station 2: no board corner was seen");
    let mut corners = corner_stations(&flanges, 0.0, 1);
    corners[0].corners[5].seen_px[1] = f64::INFINITY;
    let err = refine_on_corners(&corners, &intrinsics, &start).unwrap_err();
    assert_eq!(
        err.to_string(),
        "station 0: corner 5 is not a finite number"
    );
    let bad = CameraIntrinsics {
        fx: f64::NAN,
        ..intrinsics
    };
    let corners = corner_stations(&flanges, 0.0, 1);
    assert!(matches!(
        refine_on_corners(&corners, &bad, &start),
        Err(HandEyeError::BadIntrinsics(_))
    ));
}

/// The corners of the default ChArUco board seen from `board_in_camera`, each off by
/// `pixel_sigma`.
fn seen_board(board_in_camera: &Pose, pixel_sigma: f64, seed: u64) -> Vec<BoardCorner> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let noise = Normal::new(0.0, pixel_sigma.max(1e-300)).unwrap();
    let k = CameraIntrinsics::default();
    crate::charuco::CharucoBoard::default()
        .corners()
        .into_iter()
        .map(|c| {
            let (u, v) = k.project(board_in_camera.transform_point(c)).unwrap();
            BoardCorner {
                on_board_m: c,
                seen_px: [u + noise.sample(&mut rng), v + noise.sample(&mut rng)],
            }
        })
        .collect()
}

/// The corners' squared reprojection error through `pose` (px^2).
fn reprojection_sq(corners: &[BoardCorner], k: &CameraIntrinsics, pose: &Pose) -> f64 {
    corners
        .iter()
        .map(|c| {
            let (u, v) = k.project(pose.transform_point(c.on_board_m)).unwrap();
            (u - c.seen_px[0]).powi(2) + (v - c.seen_px[1]).powi(2)
        })
        .sum()
}

#[test]
fn a_boards_pose_is_found_from_its_corners() {
    let k = CameraIntrinsics::default();
    let poses = [
        Pose::new(DVec3::new(-0.1, -0.07, 0.6), DQuat::IDENTITY),
        Pose::new(
            DVec3::new(-0.05, 0.02, 0.8),
            DQuat::from_euler(glam::EulerRot::XYZ, 0.6, -0.4, 2.5),
        ),
    ];
    for truth in poses {
        let found = board_pose_from_corners(&seen_board(&truth, 0.0, 1), &k).unwrap();
        let (mm, deg) = errors_against(&truth, &found.board_in_camera);
        assert!(mm < 1e-6 && deg < 1e-6, "{mm} mm {deg} deg");
        assert!(found.rms_px < 1e-6);
        // Through 0.3 px of corner noise the fit explains the corners at least as well as
        // the truth does (a least-squares minimum); a board seen face on fixes its tilt
        // weakly (foreshortening is second order), so its pose moves by about a degree,
        // which is why hand-eye refines on the corners rather than on these poses.
        let seen = seen_board(&truth, 0.3, 2);
        let noisy = board_pose_from_corners(&seen, &k).unwrap();
        let truth_rms = (reprojection_sq(&seen, &k, &truth) / seen.len() as f64).sqrt();
        assert!(
            noisy.rms_px <= truth_rms + 1e-9,
            "{} > {truth_rms}",
            noisy.rms_px
        );
        let (mm, deg) = errors_against(&truth, &noisy.board_in_camera);
        assert!(mm < 5.0 && deg < 2.0, "{mm} mm {deg} deg");
    }
}

#[test]
fn a_pose_from_too_few_or_collinear_corners_is_refused() {
    let k = CameraIntrinsics::default();
    let truth = Pose::new(DVec3::new(-0.1, -0.07, 0.6), DQuat::IDENTITY);
    let corners = seen_board(&truth, 0.0, 1);
    assert_eq!(
        board_pose_from_corners(&corners[..5], &k),
        Err(HandEyeError::TooFewBoardCorners(5))
    );
    // The board's first row of corners: six on one line.
    assert_eq!(
        board_pose_from_corners(&corners[..6], &k),
        Err(HandEyeError::CornersOnALine)
    );
    let mut nan = corners.clone();
    nan[3].seen_px[0] = f64::NAN;
    assert_eq!(
        board_pose_from_corners(&nan, &k),
        Err(HandEyeError::BoardCornersNotFinite)
    );
}

/// A plan for the default board under a camera looking down from 0.7 m over the table.
fn plan_request(stations: usize) -> StationRequest {
    StationRequest {
        camera_in_base: Pose::camera_looking_at(DVec3::new(0.0, 0.0, 0.7), DVec3::ZERO).unwrap(),
        intrinsics: CameraIntrinsics::default(),
        board: crate::charuco::CharucoBoard::default(),
        margin_mm: 10.0,
        board_in_tool: true_board(),
        stations,
    }
}

#[test]
fn planned_stations_show_the_whole_board_and_turn_about_every_axis() {
    let request = plan_request(15);
    let tools = plan_stations(&request, |_| true).unwrap();
    assert_eq!(tools.len(), 15);
    assert_eq!(
        tools,
        plan_stations(&request, |_| true).unwrap(),
        "deterministic"
    );
    let k = request.intrinsics;
    let (w_mm, h_mm) = request.board.size_mm();
    let mut stations = Vec::new();
    for tool in &tools {
        let board_in_camera = request
            .camera_in_base
            .inverse()
            .compose(&tool.compose(&request.board_in_tool));
        for (x, y) in [
            (-10.0, -10.0),
            (w_mm + 10.0, h_mm + 10.0),
            (-10.0, h_mm + 10.0),
        ] {
            let p = board_in_camera.transform_point(DVec3::new(x, y, 0.0) * 1e-3);
            let (u, v) = k.project(p).expect("in front of the camera");
            assert!(u > 0.0 && u < k.width as f64 && v > 0.0 && v < k.height as f64);
        }
        // The printed face (-z of the board) looks at the camera.
        let facing = (board_in_camera.rotation * DVec3::NEG_Z).dot(-board_in_camera.position);
        assert!(facing > 0.0);
        stations.push(Station {
            flange_in_base: *tool,
            board_in_camera,
        });
    }
    // Exact stations give the camera back: the plan is not degenerate.
    let found = solve_hand_eye(&stations, HandEyeMethod::ParkMartin).unwrap();
    let (mm, deg) = errors_against(&request.camera_in_base, &found.camera_in_base);
    assert!(mm < 1e-6 && deg < 1e-6, "{mm} mm {deg} deg");
}

#[test]
fn a_plan_out_of_reach_or_of_the_wrong_size_is_refused() {
    assert!(matches!(
        plan_stations(&plan_request(15), |_| false),
        Err(HandEyeError::StationsOutOfReach {
            planned: 0,
            asked: 15,
            out_of_reach: 1..,
            ..
        })
    ));
    assert_eq!(
        plan_stations(&plan_request(2), |_| true),
        Err(HandEyeError::StationCount(2))
    );
    assert_eq!(
        plan_stations(&plan_request(MAX_STATIONS + 1), |_| true),
        Err(HandEyeError::StationCount(MAX_STATIONS + 1))
    );
}

/// A sighting of the planned station `tool`: every corner projected exactly, or none.
fn sighting(request: &StationRequest, tool: &Pose, seen: bool) -> StationSighting {
    let board_in_camera = request
        .camera_in_base
        .inverse()
        .compose(&tool.compose(&request.board_in_tool));
    let corners = match seen {
        true => request
            .board
            .corners()
            .iter()
            .map(|p| {
                let (u, v) = request
                    .intrinsics
                    .project(board_in_camera.transform_point(*p))
                    .unwrap();
                BoardCorner {
                    on_board_m: *p,
                    seen_px: [u, v],
                }
            })
            .collect(),
        false => Vec::new(),
    };
    StationSighting {
        tool_in_base: *tool,
        markers: if seen { 17 } else { 0 },
        corners,
        image: None,
    }
}

#[test]
fn stations_without_the_board_are_left_out_and_too_few_seen_is_refused() {
    let request = plan_request(8);
    let tools = plan_stations(&request, |_| true).unwrap();
    let sightings: Vec<_> = tools
        .iter()
        .enumerate()
        .map(|(i, t)| sighting(&request, t, i % 2 == 0))
        .collect();
    let run = solve_sightings(&sightings, &request.intrinsics).unwrap();
    let left_out: Vec<usize> = run
        .stations
        .iter()
        .filter(|s| s.unseen.is_some())
        .map(|s| s.station)
        .collect();
    assert_eq!(left_out, vec![1, 3, 5, 7]);
    let (mm, deg) = errors_against(&request.camera_in_base, &run.refined.camera_in_base);
    assert!(mm < 1e-4 && deg < 1e-4, "{mm} mm {deg} deg");
    assert!(run.stations[0].refined_rms_px.unwrap() < 1e-3);

    let mostly_unseen: Vec<_> = tools
        .iter()
        .enumerate()
        .map(|(i, t)| sighting(&request, t, i < 2))
        .collect();
    assert!(matches!(
        solve_sightings(&mostly_unseen, &request.intrinsics),
        Err(HandEyeError::BoardUnseen {
            seen: 2,
            stations: 8
        })
    ));
}

#[test]
fn tsai_lenz_finds_a_camera_turned_a_half_turn_about_the_base_z() {
    // Its view along the base's +z, its x along -x: a half turn about z, the rotation none of
    // the offsets about x and y takes away from a half turn.
    let camera = Pose::new(
        DVec3::new(0.05, 0.1, 0.2),
        DQuat::from_rotation_z(std::f64::consts::PI),
    );
    let stations = stations_seen_by(&camera, &flange_poses(12), (0.0, 0.0), 1);
    let found = solve_hand_eye(&stations, HandEyeMethod::TsaiLenz).unwrap();
    let (mm, deg) = errors_against(&camera, &found.camera_in_base);
    assert!(mm < 1e-6 && deg < 1e-6, "{mm} mm {deg} deg");
}
