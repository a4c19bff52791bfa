//! `trm view [MODEL|SPEC] [--posture P.json]… [--map FILE] [--traj T.csv|.json]
//! [--world W.ron] [--out scene.html]`: a JSON scene and a self-contained three.js page of a
//! robot, its world, a roadmap and a motion. The other commands' `--view` flags use
//! [`write_scene`].

use std::path::{Path, PathBuf};

use crate::support::scene::{posture_motors, write_scene};
use anyhow::{Context, Result};
use trm_collision::{CollisionModel, World};
use trm_kinematics::nalgebra::Isometry3;
use trm_kinematics::{ActiveSet, RobotModel};
use trm_roadmap::Roadmap;
use trm_tasks::Problem;
use trm_view::Scene;
use trm_wholebody::WholeBody;

/// Arguments of `view`.
#[derive(clap::Args)]
pub struct Args {
    /// A model (.urdf or .ron description), a task spec or a whole-body motion spec (its robot
    /// stands on its feet in its world); default: the map's spec, else the embedded iCub upper
    /// body.
    input: Option<PathBuf>,
    /// A posture file ("motors": {name: value}, as `solve --out` writes, or "q": [active
    /// values] with a spec); repeatable, one frame each.
    #[arg(long = "posture")]
    postures: Vec<PathBuf>,
    /// A roadmap file: its points (coloured by cost), edges and postures.
    #[arg(long)]
    map: Option<PathBuf>,
    /// A trajectory: CSV with a `time` (or `t`) column and motor-name columns (as `plan` and
    /// `stand-up` write), or `plan`'s JSON (with its task-space path).
    #[arg(long)]
    traj: Option<PathBuf>,
    /// World objects (RON, or a MoveIt planning scene .yaml, whose attached objects the robot
    /// holds), replacing the spec's.
    #[arg(long)]
    world: Option<PathBuf>,
    /// The page; the JSON scene is written beside it.
    #[arg(long, default_value = "target/view/scene.html")]
    pub out: PathBuf,
    /// Meshes for models that use them.
    #[command(flatten)]
    mesh: crate::MeshArgs,
}

/// What the scene is of: the robot, its active motors, a start posture and a world.
struct Subject {
    robot: RobotModel,
    active: Option<ActiveSet>,
    start: Vec<f64>,
    world: World,
    title: String,
    /// A whole-body motion spec: frames stand on its feet, in its ground frame.
    motion: Option<WholeBody>,
}

/// The top-level field names of a RON file (none when it does not parse as a struct): a task
/// spec has `costs`, a motion spec `phases`, a model description `urdf`.
fn ron_fields(text: &str) -> Vec<String> {
    match ron::from_str::<ron::Value>(text) {
        Ok(ron::Value::Map(map)) => map
            .keys()
            .filter_map(|k| match k {
                ron::Value::String(s) => Some(s.clone()),
                _ => None,
            })
            .collect(),
        _ => Vec::new(),
    }
}

fn subject(args: &Args, map: Option<&Roadmap>) -> Result<Subject> {
    let from_problem = |p: Problem, title: String| Subject {
        start: p.objective.active().to_motors(&p.start),
        active: Some(p.objective.active().clone()),
        world: p.objective.world().clone(),
        robot: p.robot,
        title,
        motion: None,
    };
    match (&args.input, map) {
        (Some(path), _) => {
            let title = path.display().to_string();
            let text = if path.extension().is_some_and(|e| e == "ron") {
                trm_io::read_input(path).with_context(|| format!("reading {}", path.display()))?
            } else {
                String::new()
            };
            let fields = ron_fields(&text);
            if fields.iter().any(|f| f == "costs") {
                Ok(from_problem(
                    Problem::load_with(path, &trm_taskmap::loaders())?,
                    title,
                ))
            } else if fields.iter().any(|f| f == "phases") {
                let motion = WholeBody::load(path)?;
                Ok(Subject {
                    robot: motion.model().clone(),
                    active: None,
                    start: motion.keyframes().0.to_vec(),
                    world: motion.ground_world().clone(),
                    title,
                    motion: Some(motion),
                })
            } else {
                let robot = crate::load_model(Some(path))?;
                Ok(Subject {
                    start: robot.home_motors(),
                    active: None,
                    world: World::new(),
                    robot,
                    title,
                    motion: None,
                })
            }
        }
        (None, Some(map)) => {
            let p = map.problem_with(&trm_taskmap::loaders()).with_context(|| {
                format!(
                    "{}: the spec stored in the map ({})",
                    args.map.as_deref().unwrap_or(Path::new("")).display(),
                    map.spec_path
                )
            })?;
            Ok(from_problem(p, format!("map of {}", map.spec_path)))
        }
        (None, None) => {
            let robot = trm_models::icub_upper_body();
            Ok(Subject {
                start: robot.home_motors(),
                active: None,
                world: World::new(),
                robot,
                title: "iCub upper body".into(),
                motion: None,
            })
        }
    }
}

/// Timed postures (time, motor values).
type Frames = Vec<(f64, Vec<f64>)>;

/// Frames and task-space path of a trajectory file (CSV or JSON).
fn trajectory(path: &Path, robot: &RobotModel, start: &[f64]) -> Result<(Frames, Vec<[f64; 3]>)> {
    let t = trm_plan::Trajectory::load(path, robot)?;
    let frames = t
        .motor_frames(robot, start)
        .with_context(|| format!("{}: names", path.display()))?;
    Ok((
        frames,
        t.task_path.iter().map(|p| trm_view::point3(p)).collect(),
    ))
}

/// Runs the command.
pub fn run(args: &Args) -> Result<()> {
    let map = match &args.map {
        Some(p) => Some(Roadmap::load(p).with_context(|| format!("loading {}", p.display()))?),
        None => None,
    };
    let mut s = subject(args, map.as_ref())?;
    let mut collision: CollisionModel = args.mesh.collision_model(&s.robot)?;
    if let Some(w) = &args.world {
        // a MoveIt scene's objects, and the ones the robot holds in it
        let scene = trm_moveit::load_scene(w, &collision)?;
        s.world = scene.world;
        for object in scene.attached {
            collision = collision
                .with_attached(object)
                .with_context(|| format!("{}: attached_collision_objects", w.display()))?;
        }
    }
    let mut scene = Scene::new(&s.title, &collision);
    scene.set_world(&s.world);
    let base = |motors: &[f64]| {
        s.motion
            .as_ref()
            .map_or_else(Isometry3::identity, |m| m.root_pose(motors))
    };
    for (i, p) in args.postures.iter().enumerate() {
        let motors = posture_motors(p, &s.robot, s.active.as_ref(), &s.start)?;
        scene.add_frame_at(i as f64, &motors, &base(&motors))?;
    }
    if let Some(t) = &args.traj {
        let (frames, path) = trajectory(t, &s.robot, &s.start)?;
        for (time, motors) in frames {
            scene.add_frame_at(time, &motors, &base(&motors))?;
        }
        scene.set_path(path);
    }
    if scene.frames.is_empty() {
        scene.add_frame_at(0.0, &s.start, &base(&s.start))?;
    }
    if let Some(map) = &map {
        let active = match &s.active {
            Some(a) if a.len() == map.active.len() => a.clone(),
            _ => s.robot.active_set(&map.active, &s.start)?,
        };
        scene.add_roadmap(map, &active)?;
    }
    write_scene(&scene, &args.out)
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_files_kind_comes_from_its_fields_not_its_comments() {
        let repo = crate::models_dir().join("..");
        let fields = |p: &str| super::ron_fields(&std::fs::read_to_string(repo.join(p)).unwrap());
        assert!(fields("specs/reach.ron").contains(&"costs".to_string()));
        assert!(fields("specs/wholebody/standup.ron").contains(&"phases".to_string()));
        let description = fields("models/icub_upper_body.ron");
        assert!(description.contains(&"urdf".to_string()), "{description:?}");
        assert!(!description.contains(&"costs".to_string()));
        // a comment naming a field is not a field
        let text = "// costs: see the spec\n(urdf: \"x.urdf\")";
        assert_eq!(super::ron_fields(text), ["urdf"]);
        assert!(super::ron_fields("not ron at all (").is_empty());
    }

    use std::path::{Path, PathBuf};
    use std::process::Command;

    use trm_collision::{CollisionModel, World};
    use trm_kinematics::nalgebra::Isometry3;
    use trm_view::Scene;

    /// 200 postures of the iCub around home.
    fn full_postures() -> Vec<Vec<f64>> {
        let model = trm_models::icub_upper_body();
        let home = model.home_motors();
        (0..200)
            .map(|i| {
                let mut q = home.clone();
                for (k, m) in model.motors().iter().enumerate() {
                    let wave = ((i * 7 + k * 13) as f64).sin() * 0.4;
                    q[k] = (q[k] + wave).clamp(m.limits.lower, m.limits.upper);
                }
                q
            })
            .collect()
    }

    /// A scene with everything: the iCub over 6 frames, a world, a 200-point map with edges, a path.
    fn full_scene() -> Scene {
        let model = trm_models::icub_upper_body();
        let collision = CollisionModel::new(&model).unwrap();
        let mut scene = Scene::new("browser test", &collision);
        let postures = full_postures();
        for (i, q) in postures.iter().take(6).enumerate() {
            scene.add_frame(0.2 * i as f64, q).unwrap();
        }
        let world = World::load(crate::models_dir().join("../specs/worlds/table.ron")).unwrap();
        scene.set_world(&world);
        let points: Vec<[f64; 3]> = (0..200)
            .map(|i| {
                let a = i as f64 * 0.1;
                [-0.3 + 0.1 * a.cos(), 0.2 * a.sin(), 0.1 + 0.001 * i as f64]
            })
            .collect();
        let cost = (0..200).map(|i| i as f64).collect();
        let edges = (0..199).map(|i| [i, i + 1]).collect();
        scene
            .set_map(points.clone(), cost, &postures, edges)
            .unwrap();
        scene.set_path(points[..50].to_vec());
        // a map in a moving world: from frame 1 on, the first object moves and the last is
        // gone; the map grows and some of it is blocked
        for (i, frame) in scene.frames.iter_mut().enumerate().skip(1) {
            let mut poses: Vec<Option<trm_view::Pose>> =
                scene.world.iter().map(|o| Some(o.pose)).collect();
            if let Some(Some(p)) = poses.first_mut() {
                p[2] += 0.01 * i as f64;
            }
            if let Some(last) = poses.last_mut() {
                *last = None;
            }
            frame.world = Some(poses);
            frame.map = Some(trm_view::FrameMap {
                nodes: 150 + 10 * i,
                edges: 140 + 10 * i,
                blocked: (0..5 * i).collect(),
                blocked_edges: (0..3 * i).collect(),
            });
        }
        scene
    }

    fn chromium() -> Option<PathBuf> {
        let path = std::env::var_os("TRM_CHROMIUM")
            .map(PathBuf::from)
            .unwrap_or_else(|| PathBuf::from("/usr/bin/chromium"));
        path.is_file().then_some(path)
    }

    /// Runs headless Chromium on `url`; a crash of the browser itself (seen once in a few
    /// dozen runs on a loaded machine) is retried twice with a fresh profile.
    fn headless(chromium: &Path, profile: &Path, extra: &[&str], url: &str) -> String {
        let mut last = String::new();
        for attempt in 0..3 {
            let dir = profile.join(attempt.to_string());
            let out = Command::new(chromium)
                .args([
                    "--headless",
                    "--no-sandbox",
                    "--disable-gpu",
                    "--use-angle=swiftshader",
                    "--enable-unsafe-swiftshader",
                    "--disable-quic",
                    "--no-first-run",
                    "--disable-background-networking",
                    "--disable-component-update",
                    "--disable-sync",
                    "--window-size=1024,768",
                    "--virtual-time-budget=10000",
                ])
                .arg(format!("--user-data-dir={}", dir.display()))
                .args(extra)
                .arg(url)
                .output()
                .expect("chromium runs");
            if out.status.success() {
                return String::from_utf8_lossy(&out.stdout).into_owned();
            }
            last = format!("{}: {}", out.status, String::from_utf8_lossy(&out.stderr));
        }
        panic!("chromium failed three times; last: {last}");
    }

    /// `scene`'s page, written as `target/ci-artefacts/NAME.html` and opened at `query` in
    /// headless Chromium with software WebGL: the report the page wrote (its counts and
    /// pixels), and its screenshot saved as `NAME.png`. `None` where Chromium or the built
    /// viewer bundle is missing; `.ci/run` installs both and sets TRM_BROWSER_TEST=1, which
    /// makes their absence a failure.
    fn open_in_browser(scene: &Scene, name: &str, query: &str) -> Option<serde_json::Value> {
        let repo = crate::models_dir().join("..");
        let bundle = trm_view::find_bundle(&repo).unwrap();
        let (Some(chromium), Some(bundle)) = (chromium(), bundle) else {
            assert!(
                !browser_required(),
                "TRM_BROWSER_TEST=1 but Chromium (/usr/bin/chromium or TRM_CHROMIUM) or viewer/dist/viewer.js is missing"
            );
            eprintln!("skipped: needs Chromium and `npm run build` in viewer/ (.ci/run does both)");
            return None;
        };
        let dir = repo.join("target/ci-artefacts");
        std::fs::create_dir_all(&dir).unwrap();
        let page = dir.join(format!("{name}.html"));
        std::fs::write(&page, scene.to_html(Some(&bundle)).unwrap()).unwrap();
        let url = format!("file://{}{query}", page.canonicalize().unwrap().display());
        let profile =
            std::env::temp_dir().join(format!("trm-chromium-{name}-{}", std::process::id()));
        let dom = headless(&chromium, &profile, &["--dump-dom"], &url);
        // the report is JSON in a script element, not text on the page
        let start = dom
            .find("<script id=\"trm-report\"")
            .expect("the page wrote its report");
        let json_start = dom[start..].find('>').unwrap() + start + 1;
        let json_end = dom[json_start..].find("</script>").unwrap() + json_start;
        let report: serde_json::Value = serde_json::from_str(&dom[json_start..json_end]).unwrap();
        let shot = dir.join(format!("{name}.png"));
        let arg = format!("--screenshot={}", shot.display());
        headless(&chromium, &profile, &[&arg], &url);
        assert!(std::fs::metadata(&shot).unwrap().len() > 10_000);
        let _ = std::fs::remove_dir_all(&profile);
        Some(report)
    }

    fn browser_required() -> bool {
        std::env::var_os("TRM_BROWSER_TEST").is_some_and(|v| v == "1")
    }

    /// Non-background pixels: some, not all.
    fn assert_drawn(report: &serde_json::Value) {
        let pixels = report["pixels"].as_f64().unwrap();
        let area = report["width"].as_f64().unwrap() * report["height"].as_f64().unwrap();
        assert!(pixels > 0.05 * area && pixels < 0.9 * area, "{report}");
    }

    /// The page, opened at a fixed frame in headless Chromium with software WebGL, reports what
    /// it drew; the report must match the scene.
    #[test]
    #[ignore = "starts a browser (Chromium, software WebGL); CI runs it with --ignored"]
    fn the_page_draws_the_scene_in_a_real_browser() {
        let scene = full_scene();
        let Some(report) = open_in_browser(&scene, "viewer", "?frame=3&pick=7") else {
            return;
        };
        let map = scene.map.as_ref().unwrap();
        assert_eq!(report["bodies"], scene.bodies.len());
        assert_eq!(report["links"], scene.links.len());
        assert_eq!(report["world"], scene.world.len());
        assert_eq!(report["points"], map.points.len());
        assert_eq!(report["edges"], map.edges.len());
        assert_eq!(report["path"], scene.path.len());
        assert_eq!(report["frames"], scene.frames.len());
        assert_eq!(report["frame"], 3);
        assert!(report["fk_error"].as_f64().unwrap() < 1e-5, "{report}");
        // a robot without visuals is shown by its collision shapes
        assert_eq!(report["visuals"], 0);
        assert_eq!(report["collision_shown"], true);
        // frame 3's moving world and map: one object hidden, 180 points drawn, 15 red
        let state = scene.frames[3].map.as_ref().unwrap();
        assert_eq!(report["objects_shown"], scene.world.len() - 1);
        assert_eq!(report["points_shown"], state.nodes);
        assert_eq!(report["points_blocked"], state.blocked.len());
        // ?pick=7 shows map point 7's posture, computed by the page: its last link is where
        // trm's kinematics puts it
        assert_eq!(report["picked"], 7);
        let model = trm_models::icub_upper_body();
        let mut poses = model.pose_buffer();
        let posture = full_postures()[7].clone();
        model.all_active().forward(&posture, &mut poses).unwrap();
        let want = poses.poses()[*scene.link_index.last().unwrap()]
            .translation
            .vector;
        let got = &report["picked_last_link"];
        for k in 0..3 {
            assert!(
                (got[k].as_f64().unwrap() - want[k]).abs() < 1e-5,
                "{got} vs {want}"
            );
        }
        assert_drawn(&report);
    }

    /// The Panda as it looks (example-robot-data's COLLADA visuals, in their colours) on a
    /// table sensed as a point cloud, beside a scene mesh, holding a box. The visual meshes
    /// come from PyPI's example-robot-data (`.ci/run` puts them under TRM_PANDA_VISUALS, a
    /// package path).
    #[test]
    #[ignore = "starts a browser (Chromium, software WebGL); CI runs it with --ignored"]
    fn the_page_shows_the_panda_as_it_looks_among_a_point_cloud() {
        let Some(visuals) = std::env::var_os("TRM_PANDA_VISUALS").map(PathBuf::from) else {
            assert!(
                !browser_required(),
                "TRM_BROWSER_TEST=1 but TRM_PANDA_VISUALS (a package path holding example-robot-data's Panda visual meshes) is not set"
            );
            eprintln!("skipped: set TRM_PANDA_VISUALS (.ci/run does)");
            return;
        };
        let models = crate::models_dir();
        let robot = trm_kinematics::RobotModel::load(models.join("panda/panda.ron")).unwrap();
        let options = trm_collision::CollisionOptions {
            package_paths: vec![visuals],
            ..Default::default()
        };
        let collision = CollisionModel::with_options(&robot, &options)
            .unwrap()
            .with_attached(trm_collision::AttachedObject {
                name: "box".into(),
                link: "panda_hand".into(),
                shapes: vec![(
                    trm_collision::Shape::Box {
                        size: [0.04, 0.04, 0.08],
                    },
                    Isometry3::translation(0.0, 0.0, 0.1),
                )],
                touch_links: vec!["panda_leftfinger".into(), "panda_rightfinger".into()],
            })
            .unwrap();
        let mut scene = Scene::new("Panda among a point cloud", &collision);
        assert!(
            scene.missing_visuals.is_empty(),
            "{:?}",
            scene.missing_visuals
        );
        scene.add_frame(0.0, &robot.home_motors()).unwrap();
        // a table, sensed: points on its surfaces, 8 mm apart
        let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(7);
        let table = trm_collision::Shape::Box {
            size: [0.6, 1.0, 0.04],
        };
        let mut points: Vec<[f64; 3]> = table
            .surface_samples(40_000, &mut rng)
            .iter()
            .map(|p| [p[0] + 0.55, p[1], p[2] - 0.02])
            .collect();
        points = trm_collision::thin_points(&points, 0.008);
        let mut world = World::new();
        world
            .add(
                "table (sensed)",
                trm_collision::Shape::Points {
                    points: points.clone(),
                    radius: 0.004,
                },
                Isometry3::identity(),
            )
            .unwrap();
        let (vertices, triangles) = bowl();
        world
            .add(
                "bowl (mesh)",
                trm_collision::Shape::Mesh {
                    vertices,
                    triangles,
                },
                Isometry3::translation(0.5, -0.3, 0.0),
            )
            .unwrap();
        scene.set_world(&world);
        let Some(report) = open_in_browser(&scene, "viewer-panda", "") else {
            return;
        };
        assert_eq!(report["visuals"], scene.visuals.len());
        let triangles: usize = scene
            .visuals
            .iter()
            .map(|v| match &v.shape {
                trm_collision::Shape::Mesh { triangles, .. } => triangles.len(),
                _ => 0,
            })
            .sum();
        assert!(triangles > 100_000, "{triangles}");
        assert_eq!(report["visual_triangles"], triangles);
        assert_eq!(report["look_shown"], true);
        assert_eq!(report["collision_shown"], false);
        assert_eq!(report["held"], 1);
        assert_eq!(report["cloud_points"], points.len());
        assert_eq!(report["objects_shown"], 2);
        assert!(report["fk_error"].as_f64().unwrap() < 1e-5, "{report}");
        assert_drawn(&report);
    }

    /// An open bowl: a hemisphere of triangles, 0.1 m across.
    fn bowl() -> trm_collision::mesh::Triangles {
        let (rings, sectors) = (6, 16);
        let mut vertices = vec![[0.0, 0.0, 0.0]];
        for r in 1..=rings {
            let a = std::f64::consts::FRAC_PI_2 * r as f64 / rings as f64;
            for s in 0..sectors {
                let b = std::f64::consts::TAU * s as f64 / sectors as f64;
                vertices.push([
                    0.1 * a.sin() * b.cos(),
                    0.1 * a.sin() * b.sin(),
                    0.1 - 0.1 * a.cos(),
                ]);
            }
        }
        let at = |r: u32, s: u32| {
            if r == 0 {
                0
            } else {
                1 + (r - 1) * sectors + s % sectors
            }
        };
        let mut triangles = Vec::new();
        for r in 0..rings {
            for s in 0..sectors {
                if r == 0 {
                    triangles.push([0, at(1, s), at(1, s + 1)]);
                } else {
                    triangles.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
                    triangles.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
                }
            }
        }
        (vertices, triangles)
    }

    #[test]
    fn a_robot_whose_visual_meshes_are_not_found_is_drawn_by_its_collision_shapes() {
        let dir = crate::test_dir("view-visuals");
        let out = dir.join("panda.html");
        let args = super::Args {
            input: Some(crate::models_dir().join("panda/panda.ron")),
            postures: vec![],
            map: None,
            traj: None,
            world: None,
            out: out.clone(),
            mesh: crate::MeshArgs::default(),
        };
        super::run(&args).unwrap();
        let scene = Scene::from_json(&std::fs::read_to_string(out.with_extension("json")).unwrap())
            .unwrap();
        // the Panda's 11 visuals name example-robot-data's COLLADA files, not shipped
        assert_eq!(
            scene.missing_visuals.len(),
            11,
            "{:?}",
            scene.missing_visuals
        );
        assert!(scene.missing_visuals[0].contains("link0.dae"));
        assert!(scene.visuals.is_empty() && !scene.bodies.is_empty());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn view_writes_the_page_and_the_scene_and_reads_trajectories() {
        let dir = crate::test_dir("view");
        let csv = dir.join("traj.csv");
        std::fs::write(
            &csv,
            "time,r_elbow,torso_pitch\n0,0.5,0\n0.1,0.6,0.1\n0.2,0.7,0.2\n",
        )
        .unwrap();
        let out = dir.join("scene.html");
        let args = super::Args {
            input: None,
            postures: vec![],
            map: None,
            traj: Some(csv.clone()),
            world: Some(crate::models_dir().join("../specs/worlds/table.ron")),
            out: out.clone(),
            mesh: crate::MeshArgs::default(),
        };
        super::run(&args).unwrap();
        let scene = Scene::from_json(&std::fs::read_to_string(out.with_extension("json")).unwrap())
            .unwrap();
        assert_eq!(scene.frames.len(), 3);
        assert_eq!(scene.world.len(), 4);
        assert!(std::fs::read_to_string(&out).unwrap().contains("trm-scene"));
        // a bad row names the file, line and column
        std::fs::write(&csv, "time,r_elbow\n0,0.5\n0.1,x\n").unwrap();
        let e = super::run(&args).unwrap_err().to_string();
        assert!(e.contains("traj.csv:3") && e.contains("column 2"), "{e}");
        // a column naming no motor says which names it could mean
        std::fs::write(&csv, "time,elbow\n0,0.5\n").unwrap();
        let e = super::run(&args).unwrap_err().to_string();
        assert!(e.contains("did you mean `r_elbow`"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
