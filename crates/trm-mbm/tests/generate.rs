//! MotionBenchMaker-like sets generated for the iCub from a task spec: every family yields a
//! problem whose start and goal are free and apart, the files read back as a set that
//! RRT-Connect solves with free paths, a seed gives the same files, bad settings are errors.

use std::path::Path;

use trm_mbm::generate::{SetOptions, generate, write_set};
use trm_mbm::{ProblemSet, Verdict, certify_path, solve};
use trm_moveit::{MotionPlanRequest, PlanningScene};
use trm_plan::rrt::RrtOptions;

fn spec() -> trm_tasks::spec::Problem {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    trm_tasks::spec::Problem::load(root.join("specs/mbm/icub_reach.ron")).unwrap()
}

fn options() -> SetOptions {
    SetOptions {
        per_family: 1,
        facing: [-1.0, 0.0],
        ..Default::default()
    }
}

#[test]
fn generated_icub_problems_are_valid_and_solved() {
    let spec = spec();
    let set = generate(&spec, &options(), |_, _| {}).unwrap();
    assert_eq!(set.len(), 3);
    let dir = std::env::temp_dir().join(format!("trm-generated-{}", std::process::id()));
    write_set(&dir, &set).unwrap();
    let problems = ProblemSet::open(&dir).unwrap();
    assert_eq!(problems.problems.len(), 3);
    let collision = spec.objective.collision().clone();
    for p in &problems.problems {
        let scene = PlanningScene::load(&p.scene).unwrap();
        let request = MotionPlanRequest::load(&p.request).unwrap();
        assert_eq!(request.goal.names.len(), 10, "torso and right arm");
        let outcome = solve(
            &spec.robot,
            &collision,
            &scene,
            &request,
            &RrtOptions {
                certified: true,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(
            outcome.valid && outcome.solved,
            "{} {}: {}",
            p.family,
            p.index,
            outcome.note
        );
        assert!(
            certify_path(&spec.robot, &collision, &scene, &request, &outcome.path).unwrap()
                == Verdict::Proved
        );
        // the straight motion is not the answer everywhere: the path bends or is long
        assert!(
            outcome.length > 0.5,
            "{} {}: start and goal too close",
            p.family,
            p.index
        );
    }
    // the same seed, the same files
    let again = generate(&spec, &options(), |_, _| {}).unwrap();
    for (a, b) in set.iter().zip(&again) {
        assert_eq!(a.scene.to_yaml().unwrap(), b.scene.to_yaml().unwrap());
        assert_eq!(a.request.to_yaml().unwrap(), b.request.to_yaml().unwrap());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_generation_settings_are_errors() {
    let spec = spec();
    for (options, says) in [
        (
            SetOptions {
                per_family: 0,
                ..options()
            },
            "per_family",
        ),
        (
            SetOptions {
                families: vec!["kitchen".into()],
                ..options()
            },
            "`kitchen` is not one of table, shelf, cage",
        ),
        (
            SetOptions {
                facing: [0.0, 0.0],
                ..options()
            },
            "facing",
        ),
        (
            SetOptions {
                tolerance: f64::NAN,
                ..options()
            },
            "tolerance",
        ),
        (
            SetOptions {
                center: Some([f64::INFINITY, 0.0, 0.0]),
                ..options()
            },
            "center",
        ),
        // scenes 5 m away: nothing is reachable
        (
            SetOptions {
                center: Some([-5.0, 0.0, 0.0]),
                tries: 2,
                ..options()
            },
            "no collision-free start and goal",
        ),
    ] {
        let e = generate(&spec, &options, |_, _| {})
            .unwrap_err()
            .to_string();
        assert!(e.contains(says), "{e}");
    }
}
