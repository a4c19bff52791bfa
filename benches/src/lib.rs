//! Shared inputs for trm's criterion benches (`cargo bench -p trm-benches`). The suites are in
//! `benches/benches/`.

use nalgebra::Isometry3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trm_collision::{CollisionModel, Shape, World};
use trm_kinematics::ActiveSet;

/// A table with a box on it and a shelf board above, in front of a Panda at the origin: the
/// point-cloud benches' scene as primitives.
pub fn table_scene() -> World {
    let mut world = World::new();
    for (name, size, xyz) in [
        ("table", [0.8, 1.2, 0.05], [0.6, 0.0, 0.2]),
        ("box", [0.15, 0.1, 0.2], [0.5, 0.2, 0.325]),
        ("board", [0.3, 0.8, 0.02], [0.55, 0.0, 0.8]),
    ] {
        let pose = Isometry3::translation(xyz[0], xyz[1], xyz[2]);
        world.add(name, Shape::Box { size }, pose).expect("valid");
    }
    world
}

/// [`table_scene`] as a camera would give it: `per_object` seeded points on each object's
/// surface, points of 2.5 mm.
pub fn sampled_table_scene(per_object: usize) -> World {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut world = World::new();
    for o in table_scene().objects() {
        let points = o.shape().surface_samples(per_object, &mut rng);
        let cloud = Shape::Points {
            points,
            radius: 0.0025,
        };
        world.add(o.name(), cloud, *o.pose()).expect("valid");
    }
    world
}

/// `n` seeded uniform samples within the bounds of `active`.
pub fn random_configurations(active: &ActiveSet, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| active.random(&mut rng)).collect()
}

/// Queries of [`FAST_LANES`](trm_collision::fast::FAST_LANES) spheres, as a robot's spheres
/// put them where they are in `configurations` (taken eight at a time): per block
/// and sphere of `collision` (a sphere model), the sphere's centre in each configuration and
/// its radius.
pub fn sphere_queries(
    collision: &CollisionModel,
    active: &ActiveSet,
    configurations: &[Vec<f64>],
) -> Vec<(Vec<[f64; 3]>, f64)> {
    let (mut pose, mut placed) = (active.model().pose_buffer(), collision.placed_bodies());
    let mut queries = Vec::new();
    for block in configurations.chunks(trm_collision::fast::FAST_LANES) {
        let mut spheres: Vec<(Vec<[f64; 3]>, f64)> = Vec::new();
        for q in block {
            active.forward_unchecked(q, &mut pose);
            collision.place(&pose, &mut placed);
            for (b, aabb) in placed.body_boxes().enumerate() {
                if spheres.len() <= b {
                    spheres.push((Vec::new(), aabb.half_extents().x));
                }
                spheres[b].0.push(aabb.center().coords.into());
            }
        }
        queries.extend(spheres);
    }
    queries
}

/// The median of `values` (the upper one of an even count), sorting them in place.
///
/// # Panics
/// If `values` is empty.
pub fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// A command-line count: `text` as a positive whole number, else an error naming `what`.
pub fn positive(text: &str, what: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(v) if v > 0 => Ok(v),
        _ => Err(format!("{what}: `{text}` is not a positive whole number")),
    }
}

/// A peer's program (`benches/peers/vamp`'s) started with piped input and output: the child,
/// its input and its output's lines.
pub type Peer = (
    std::process::Child,
    std::process::ChildStdin,
    std::io::Lines<std::io::BufReader<std::process::ChildStdout>>,
);

/// Starts VAMP's program `program` ([`Peer`]), or says how to build it.
pub fn start_vamp(program: &str) -> Result<Peer, String> {
    use std::io::BufRead;
    use std::process::{Command, Stdio};
    let mut child = Command::new(program)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("{program}: {e} (build it with benches/peers/vamp/build.sh)"))?;
    let (Some(input), Some(output)) = (child.stdin.take(), child.stdout.take()) else {
        let _ = child.kill();
        let _ = child.wait();
        return Err(format!("{program}: no pipes"));
    };
    Ok((child, input, std::io::BufReader::new(output).lines()))
}

/// Runs an example's `run`, printing its error and exiting with status 2 when it fails.
pub fn exit_on_error(run: impl FnOnce() -> Result<(), String>) {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}
