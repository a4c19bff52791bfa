//! Trajectory files: what trm writes reads back; malformed files are located errors.

use std::path::Path;

use trm_plan::Trajectory;

fn csv_error(text: &str) -> String {
    let arm = trm_models::planar_arm();
    match Trajectory::from_csv(text, Path::new("t.csv"), &arm) {
        Err(e) => e.to_string(),
        Ok(t) => panic!("accepted {text:?}: {t:?}"),
    }
}

fn json_error(text: &str) -> String {
    match Trajectory::from_json(text, Path::new("t.json")) {
        Err(e) => e.to_string(),
        Ok(t) => panic!("accepted {text:?}: {t:?}"),
    }
}

#[test]
fn what_is_written_reads_back() {
    let arm = trm_models::planar_arm();
    let t = Trajectory {
        names: vec!["joint1".into(), "joint2".into()],
        times: vec![0.0, 0.25, 0.5],
        positions: vec![vec![0.0, 0.1], vec![0.1, -0.2], vec![0.3, 1e-9]],
        velocities: Vec::new(),
        accelerations: Vec::new(),
        task_path: vec![vec![1.0, 2.0, 3.0]; 3],
    };
    let csv = Trajectory::from_csv(
        &t.to_csv(Path::new("t.csv")).unwrap(),
        Path::new("t.csv"),
        &arm,
    )
    .unwrap();
    assert_eq!(
        (csv.names, csv.times, csv.positions),
        (t.names.clone(), t.times.clone(), t.positions.clone())
    );
    assert_eq!(
        Trajectory::from_json(
            &t.to_json(Path::new("t.json")).unwrap(),
            Path::new("t.json")
        )
        .unwrap(),
        t
    );
}

#[test]
fn malformed_csv_is_a_located_error() {
    for (text, expected) in [
        ("", "t.csv:1: empty file"),
        ("joint1,joint2\n0,0\n", "t.csv:1: no `time` column"),
        (
            "time,x,y\n0,1,2\n",
            "t.csv:1: column 2 (`x`): unknown motor",
        ),
        ("time,phase\n0,1\n", "t.csv:1: no column names a motor"),
        ("time,joint1,jont2\n0,1,2\n", "t.csv:1: column 3 (`jont2`)"),
        (
            "time,joint1\n0,0\n0.1,0,7\n",
            "t.csv:3: 3 fields for 2 columns",
        ),
        ("time,joint1\n0,0\n\n-0.5,9\n", "t.csv:4: time is -0.5"),
        (
            "time,joint1\n0,0\n\n0.5,9\n",
            "t.csv:4: waypoint 1: `joint1` is 9, outside its limits",
        ),
        (
            "time,joint1,joint1\n0,0,0\n",
            "t.csv:1: motor `joint1` has two columns",
        ),
        ("time,joint1\n0,NaN\n", "t.csv:2: column 2"),
        ("time,joint1\n0,inf\n", "t.csv:2: column 2"),
        ("time,joint1\n0,0\n0.5\n", "t.csv:3: 1 fields for 2 columns"),
        ("time,joint1\n0,zero\n", "t.csv:2: column 2"),
        ("time,joint1\n1,0\n0.5,0\n", "t.csv:3: time"),
        ("time,joint1\n-inf,0\n", "t.csv:2: column 1"),
        (
            "time,joint1\n",
            "t.csv:2: the header is followed by no rows",
        ),
        (
            "time,joint1\n\n\n",
            "t.csv:2: the header is followed by no rows",
        ),
    ] {
        let e = csv_error(text);
        assert!(e.starts_with(expected), "{text:?}: {e}");
    }
}

#[test]
fn malformed_json_is_a_located_error() {
    for (text, expected) in [
        ("", "t.json"),
        ("{\"names\": [\"a\"], \"times\": [0", "t.json:1"),
        (
            "{\"names\": [\"a\"], \"times\": [0], \"positions\": [[null]], \"task_path\": []}",
            "t.json:1",
        ),
        (
            "{\"names\": [\"a\"], \"times\": [0, 1], \"positions\": [[0]], \"task_path\": []}",
            "2 times for 1 positions",
        ),
        (
            "{\"names\": [\"a\"], \"times\": [0], \"positions\": [[0, 1]], \"task_path\": []}",
            "positions[0] has 2 values for 1 names",
        ),
        (
            "{\"names\": [\"a\"], \"times\": [1, 0], \"positions\": [[0], [0]], \"task_path\": []}",
            "times[1]",
        ),
        (
            "{\"names\": \"a\", \"times\": [], \"positions\": [], \"task_path\": []}",
            "t.json:1",
        ),
        (
            "{\"names\": [\"a\"], \"times\": [0], \"times\": [1], \"positions\": [[0]], \"task_path\": []}",
            "`times` is given twice",
        ),
        (
            "{\"names\": [\"a\", \"a\"], \"times\": [0], \"positions\": [[0, 0]], \"task_path\": []}",
            "names[1]: `a` is named twice",
        ),
        (
            "{\"names\": [\"a\"], \"times\": [0], \"positions\": [[0]], \"task_path\": [[1], [2]]}",
            "task_path has 2 points for 1 waypoints",
        ),
        (
            "{\"names\": [\"a\"], \"times\": [], \"positions\": [], \"task_path\": []}",
            "no waypoints",
        ),
    ] {
        let e = json_error(text);
        assert!(e.contains(expected), "{text:?}: {e}");
    }
}

#[test]
fn json_trajectories_are_checked_against_the_robot() {
    let arm = trm_models::planar_arm();
    let dir = std::env::temp_dir().join(format!("trm-traj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (text, expected) in [
        (
            "{\"names\": [\"joint9\"], \"times\": [0], \"positions\": [[0]], \"task_path\": []}",
            "names[0]: unknown motor `joint9`",
        ),
        (
            "{\"names\": [\"joint1\"], \"times\": [0], \"positions\": [[7]], \"task_path\": []}",
            "waypoint 0: `joint1` is 7, outside its limits",
        ),
    ] {
        let path = dir.join("t.json");
        std::fs::write(&path, text).unwrap();
        let e = Trajectory::load(&path, &arm).unwrap_err().to_string();
        assert!(e.contains(expected) && e.contains("t.json"), "{e}");
    }
}

#[test]
fn writers_refuse_what_readers_refuse() {
    let t = Trajectory {
        names: vec!["joint1".into()],
        times: vec![0.0, f64::INFINITY],
        positions: vec![vec![0.0], vec![0.1]],
        velocities: Vec::new(),
        accelerations: Vec::new(),
        task_path: vec![],
    };
    for e in [
        t.to_csv(Path::new("out.csv")).unwrap_err(),
        t.to_json(Path::new("out.json")).unwrap_err(),
    ] {
        assert!(e.to_string().contains("times[1] is inf"), "{e}");
    }
}

#[test]
fn a_missing_file_is_an_error_naming_it() {
    let arm = trm_models::planar_arm();
    let e = Trajectory::load("/nonexistent/t.csv", &arm)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("/nonexistent/t.csv:"), "{e}");
}

/// A value as a careless writer might produce it: ordinary, at a limit, past it, non-finite.
fn value() -> impl proptest::strategy::Strategy<Value = f64> {
    use proptest::prelude::*;
    prop_oneof![
        8 => -3.0..3.0f64,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(-1e300),
    ]
}

proptest::proptest! {
    /// Whatever a trajectory holds, its writers either refuse it or write what the readers read
    /// back unchanged (CSV: names, times and positions; JSON: everything).
    #[test]
    fn every_trajectory_written_reads_back(
        rows in proptest::collection::vec((value(), value(), value()), 0..6),
        task in proptest::bool::ANY,
    ) {
        let arm = trm_models::planar_arm();
        let mut time = 0.0;
        let t = Trajectory {
            names: vec!["joint1".into(), "joint2".into()],
            times: rows.iter().map(|r| { time += r.0.abs(); if r.0.is_nan() { r.0 } else { time } }).collect(),
            positions: rows.iter().map(|r| vec![r.1, r.2]).collect(),
            velocities: Vec::new(),
            accelerations: Vec::new(),
            task_path: if task { rows.iter().map(|r| vec![r.1, 0.0, r.2]).collect() } else { vec![] },
        };
        let (csv_path, json_path) = (Path::new("t.csv"), Path::new("t.json"));
        match t.to_csv(csv_path) {
            Ok(csv) => {
                // what the writer accepts, the reader takes unless the robot's limits refuse it
                match Trajectory::from_csv(&csv, csv_path, &arm) {
                    Ok(back) => proptest::prop_assert_eq!(
                        (back.names, back.times, back.positions),
                        (t.names.clone(), t.times.clone(), t.positions.clone())
                    ),
                    Err(e) => proptest::prop_assert!(e.to_string().contains("outside its limits"), "{e}"),
                }
            }
            Err(_) => proptest::prop_assert!(t.check(csv_path).is_err()),
        }
        match t.to_json(json_path) {
            Ok(json) => proptest::prop_assert_eq!(Trajectory::from_json(&json, json_path).unwrap(), t),
            Err(_) => proptest::prop_assert!(t.check(json_path).is_err()),
        }
    }
}
