//! The property each fuzz target checks, one function per file reader: whatever the input, the
//! reader returns a value or a located error — never a panic, a hang or a stack overflow — and
//! what it reads, its writer writes and it reads back unchanged.
//!
//! `fuzz/fuzz_targets/*` call these with libFuzzer's inputs (`fuzz/run.sh`, nightly);
//! `tests/replay.rs` calls them with the seed files of `fuzz/seeds.txt` and seeded mutations of
//! them, in the quick test suite on stable. A failed property panics.

use std::path::Path;
use std::sync::LazyLock;

use trm_kinematics::{ModelDescription, RobotModel};

/// How a target takes its input.
#[derive(Clone, Copy)]
pub enum Check {
    /// UTF-8 text (libFuzzer's inputs that are not UTF-8 are skipped).
    Text(fn(&str)),
    /// Raw bytes.
    Bytes(fn(&[u8])),
}

impl Check {
    /// Runs the check on `data` (text checks skip data that is not UTF-8).
    pub fn run(self, data: &[u8]) {
        match self {
            Check::Text(check) => {
                if let Ok(text) = std::str::from_utf8(data) {
                    check(text);
                }
            }
            Check::Bytes(check) => check(data),
        }
    }
}

/// Every fuzz target: its name (the file `fuzz/fuzz_targets/NAME.rs`) and its check.
pub const TARGETS: &[(&str, Check)] = &[
    ("urdf", Check::Text(urdf)),
    ("model_description", Check::Text(model_description)),
    ("task_spec", Check::Text(task_spec)),
    ("world", Check::Text(world)),
    ("motion_spec", Check::Text(motion_spec)),
    ("taskmap_spec", Check::Text(taskmap_spec)),
    ("map", Check::Text(map)),
    ("checkpoint", Check::Bytes(checkpoint)),
    ("taskmap", Check::Text(taskmap)),
    ("scene", Check::Text(scene)),
    ("configurations", Check::Text(configurations)),
    ("posture", Check::Text(posture)),
    ("trajectory_csv", Check::Text(trajectory_csv)),
    ("trajectory_json", Check::Text(trajectory_json)),
    ("srdf", Check::Text(srdf)),
    ("mesh", Check::Bytes(mesh)),
    ("moveit", Check::Text(moveit)),
    ("points", Check::Bytes(points)),
];

/// The iCub upper body with its description, loaded once.
static ICUB: LazyLock<RobotModel> = LazyLock::new(trm_models::icub_upper_body);

/// The iCub upper-body URDF without a description, parsed once.
static BARE_ICUB: LazyLock<RobotModel> = LazyLock::new(|| {
    RobotModel::from_urdf_str(trm_models::ICUB_UPPER_BODY_URDF, "icub_upper_body.urdf")
        .expect("the embedded URDF loads")
});

/// URDF text → a model, which can be evaluated at its mid-range posture.
pub fn urdf(text: &str) {
    if let Ok(model) = RobotModel::from_urdf_str(text, "fuzz.urdf") {
        let motors: Vec<f64> = model
            .motors()
            .iter()
            .map(|m| 0.5 * (m.limits.lower.max(-1e3) + m.limits.upper.min(1e3)))
            .collect();
        let _ = model.forward_motors(&motors, &mut model.pose_buffer());
    }
}

/// Model description (RON) → applied to the bare iCub URDF.
pub fn model_description(text: &str) {
    if let Ok(description) = ModelDescription::from_ron(text, "fuzz.ron") {
        let _ = BARE_ICUB.with_description(&description, Some((text, "fuzz.ron")));
    }
}

/// Task spec (RON) → a problem; relative paths resolve against the repository's specs/.
pub fn task_spec(text: &str) {
    let base = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../specs"));
    let _ = trm_tasks::Problem::from_ron(text, "fuzz.ron", base);
}

/// World (RON) → a world.
pub fn world(text: &str) {
    let _ = trm_collision::World::from_ron(text, "fuzz.ron");
}

/// Whole-body motion spec (RON) → a spec whose names are checked against the iCub.
pub fn motion_spec(text: &str) {
    if let Ok(spec) = trm_wholebody::MotionSpec::from_ron(text, "fuzz.ron") {
        let _ = spec.check_names(&ICUB, "fuzz.ron", text);
    }
}

/// Task-map spec (RON) → a spec.
pub fn taskmap_spec(text: &str) {
    let _ = trm_taskmap::TaskMapSpec::from_ron(text, "fuzz.ron", Path::new("."));
}

/// Roadmap file (JSON): a map that reads is written back and reads again unchanged.
pub fn map(text: &str) {
    let path = Path::new("fuzz.map.json");
    if let Ok(map) = trm_roadmap::Roadmap::from_json(text, path) {
        let _ = map.summary();
        let written = map.to_json(path).expect("a map that reads is written");
        let again = trm_roadmap::Roadmap::from_json(&written, path).expect("and reads back");
        assert_eq!(map, again);
    }
}

/// Map-build checkpoint (binary): `content` framed with a valid header and checksum, so that
/// the fuzzer reaches the decoder; a checkpoint that reads is written back and reads again.
pub fn checkpoint(content: &[u8]) {
    let path = Path::new("fuzz.checkpoint");
    // the header alone: the framing of an empty value, without its checksum
    let empty = trm_kinematics::binary_bytes(
        path,
        &(),
        trm_roadmap::CHECKPOINT_FORMAT,
        trm_roadmap::CHECKPOINT_VERSION,
    )
    .expect("a header");
    let mut bytes = empty[..empty.len() - 4].to_vec();
    bytes.extend_from_slice(content);
    bytes.extend(crc32fast::hash(&bytes).to_le_bytes());
    if let Ok(checkpoint) = trm_roadmap::Checkpoint::from_bytes(&bytes, path) {
        let written = checkpoint
            .to_bytes(path)
            .expect("a checkpoint that reads is written");
        let again = trm_roadmap::Checkpoint::from_bytes(&written, path).expect("and reads back");
        assert_eq!(format!("{checkpoint:?}"), format!("{again:?}"));
    }
}

/// Task map file (JSON): written back and read again unchanged.
pub fn taskmap(text: &str) {
    let path = Path::new("fuzz.taskmap.json");
    if let Ok(map) = trm_taskmap::TaskMap::from_json(text, path) {
        let written = map.to_json(path).expect("a task map that reads is written");
        let again = trm_taskmap::TaskMap::from_json(&written, path).expect("and reads back");
        assert_eq!(map.points, again.points);
    }
}

/// Viewer scene (JSON): written back and read again.
pub fn scene(text: &str) {
    if let Ok(scene) = trm_view::Scene::from_json(text) {
        let written = scene.to_json().expect("a scene that reads is written");
        trm_view::Scene::from_json(&written).expect("and reads back");
    }
}

/// Configurations file (JSON) → joint vectors of the iCub.
pub fn configurations(text: &str) {
    let path = Path::new("fuzz.json");
    if let Ok(file) = trm_kinematics::ConfigurationsFile::from_json(text, path) {
        let _ = file.joint_vectors(&ICUB, path);
    }
}

/// Posture file (JSON) → the iCub's motors; a posture that applies is written back unchanged.
pub fn posture(text: &str) {
    let path = Path::new("fuzz.json");
    let Ok(file) = trm_kinematics::PostureFile::from_json(text, path) else {
        return;
    };
    let robot = &*ICUB;
    let start = vec![0.0; robot.motors().len()];
    let active = robot.all_active();
    if file.to_motors(robot, Some(&active), &start, path).is_ok() {
        let written = file.to_json(path).expect("a posture that reads is written");
        let again = trm_kinematics::PostureFile::from_json(&written, path).expect("reads back");
        assert_eq!(file.motors, again.motors);
        assert_eq!(file.q, again.q);
    }
}

/// Trajectory CSV for the iCub: written back and read again unchanged.
pub fn trajectory_csv(text: &str) {
    let robot = &*ICUB;
    let path = Path::new("fuzz.csv");
    if let Ok(t) = trm_plan::Trajectory::from_csv(text, path, robot) {
        let written = t.to_csv(path).expect("a trajectory that reads is written");
        let again = trm_plan::Trajectory::from_csv(&written, path, robot).expect("reads back");
        assert_eq!(
            (t.names, t.times, t.positions),
            (again.names, again.times, again.positions)
        );
    }
}

/// Trajectory JSON: written back and read again unchanged, then checked against the iCub.
pub fn trajectory_json(text: &str) {
    let path = Path::new("fuzz.json");
    if let Ok(t) = trm_plan::Trajectory::from_json(text, path) {
        let written = t.to_json(path).expect("a trajectory that reads is written");
        let again = trm_plan::Trajectory::from_json(&written, path).expect("reads back");
        assert_eq!(t, again);
        let _ = t.check_robot(&ICUB, path, |_| 0);
    }
}

/// SRDF → a model description for the bare iCub; what it reads, it writes and reads back.
pub fn srdf(text: &str) {
    if let Ok(srdf) = trm_kinematics::srdf::Srdf::parse(text, "fuzz.srdf") {
        if let Ok((description, _)) = srdf.to_description(&BARE_ICUB, &ModelDescription::default())
        {
            let _ = BARE_ICUB.clone().with_description(&description, None);
        }
        let again = trm_kinematics::srdf::Srdf::parse(&srdf.to_xml(), "again.srdf");
        assert!(again.is_ok(), "{again:?}");
    }
}

/// Mesh bytes (the first byte picks STL, OBJ or COLLADA) → a finite convex hull.
pub fn mesh(data: &[u8]) {
    let Some((&kind, bytes)) = data.split_first() else {
        return;
    };
    let name = ["fuzz.stl", "fuzz.obj", "fuzz.dae"][usize::from(kind % 3)];
    if let Ok(hull) =
        trm_collision::mesh::convex_hull_of_mesh_bytes(bytes, Path::new(name), [1.0, 1.0, 1.0])
    {
        assert!(hull.len() >= 4 && hull.iter().flatten().all(|c| c.is_finite()));
    }
    // read for drawing (a viewer's visuals): parts whose triangles name their own vertices
    if let Ok(parts) = trm_collision::mesh::parts_of_mesh_bytes(bytes, Path::new(name), [1.0; 3]) {
        for part in parts {
            let n = part.vertices.len();
            assert!(part.vertices.iter().flatten().all(|c| c.is_finite()));
            assert!(part.triangles.iter().flatten().all(|&i| (i as usize) < n));
        }
    }
}

/// Point-cloud bytes (PLY or PCD; the first byte picks the format) → finite points or an
/// error, never a panic.
pub fn points(data: &[u8]) {
    let Some((&kind, bytes)) = data.split_first() else {
        return;
    };
    let name = ["fuzz.ply", "fuzz.pcd"][usize::from(kind % 2)];
    if let Ok(read) = trm_io::parse_points(bytes, Path::new(name)) {
        assert!(!read.points.is_empty());
        assert!(read.points.iter().flatten().all(|c| c.is_finite()));
    }
}

/// MoveIt PlanningScene YAML: a scene that reads is written and read back with the same objects
/// and allowed collisions; the text is also read as a MotionPlanRequest.
pub fn moveit(text: &str) {
    use trm_moveit::{MotionPlanRequest, PlanningScene};
    if let Ok(scene) = PlanningScene::parse(text, Path::new("fuzz.yaml")) {
        let _ = scene.to_world();
        let written = scene.to_yaml().expect("a scene that reads is written");
        let again = PlanningScene::parse(&written, Path::new("again.yaml"))
            .expect("what the writer writes, the reader reads");
        assert_eq!(again.objects.len(), scene.objects.len());
        assert_eq!(again.allowed_collisions, scene.allowed_collisions);
        assert_eq!(again.attached, scene.attached);
    }
    let _ = MotionPlanRequest::parse(text, Path::new("fuzz.yaml"));
}
