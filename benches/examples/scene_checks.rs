//! The check of free configurations in MotionBenchMaker's scenes, where the world part costs:
//! random configurations of each problem's scene (seed = the problem's place in the set) kept
//! where the exact model finds them free, checked by the single-precision screen in blocks of
//! [`FAST_LANES`] (interleaved rounds, median of the rounds), optionally beside VAMP on the same
//! configurations in the same scenes:
//!
//! ```sh
//! cargo run --release -p trm-benches --example scene_checks -- \
//!     benches/mbm/fetch_problems.tar.bz2 models/fetch-mbm/fetch_spherized.ron 10 7 \
//!     target/peers/vamp-mbm
//! ```
//!
//! Arguments: the problem set, the model, the problems per family (default 10), the rounds
//! (default 7) and VAMP's program (`benches/peers/vamp/build.sh`; the model's name and joints
//! must be VAMP's robot's). Prints the time per free configuration per family and over the set,
//! and whether the screen agreed with the exact model on every configuration. With VAMP, trm is
//! also timed in the world as VAMP sees it ([`trm_mbm::vamp_world`]: cylinders as capsules, in
//! the box family as boxes), and each round runs trm's passes and then VAMP's. Every round also
//! times both with the robot alone (the same configurations in an empty world: FK and
//! self-collision), so that the world's part and the robot's are compared apart.

use std::collections::BTreeMap;
use std::io::{BufReader, Write};
use std::path::Path;
use std::time::Instant;

use trm_benches::{median, positive, random_configurations};
use trm_collision::fast::{FAST_LANES, FastChecker, FastWorld};
use trm_collision::{CollisionModel, World};
use trm_kinematics::RobotModel;
use trm_mbm::{LoadedProblem, ProblemSet, peer_objects, vamp_world};
use trm_tasks::Objective;

fn main() {
    trm_benches::exit_on_error(run);
}

/// One problem's scene: its family, checker, worlds (compiled and exact; as trm plans in it,
/// as VAMP sees it, and empty: the robot alone) and free configurations (whole blocks).
struct Scene {
    family: String,
    fast: FastChecker,
    worlds: [(FastWorld, World); 3],
    free: Vec<f64>,
}

/// What each round times, in [`Times`]' order: trm in its world, trm in the world as VAMP sees
/// it, VAMP, trm with the robot alone, VAMP with the robot alone.
const PASSES: usize = 5;

/// [`PASSES`]' indices.
const TRM: usize = 0;
const TRM_SEEN: usize = 1;
const VAMP: usize = 2;
const TRM_ALONE: usize = 3;
const VAMP_ALONE: usize = 4;

/// Per family, each round's seconds and the configurations timed.
type Times = BTreeMap<String, (Vec<f64>, usize)>;

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        return Err("usage: scene_checks PROBLEMS MODEL [PER_FAMILY] [ROUNDS] [VAMP]".into());
    }
    let per_family = args.get(2).map_or(Ok(10), |r| positive(r, "PER_FAMILY"))?;
    let rounds = args.get(3).map_or(Ok(7), |r| positive(r, "ROUNDS"))?;
    let robot = RobotModel::load(&args[1]).map_err(|e| e.to_string())?;
    let collision = CollisionModel::new(&robot).map_err(|e| e.to_string())?;
    let mut set = ProblemSet::open(Path::new(&args[0])).map_err(|e| e.to_string())?;
    set.select(&[], Some(per_family))
        .map_err(|e| e.to_string())?;
    let loaded = LoadedProblem::load_all(&collision, &set.problems).map_err(|e| e.to_string())?;
    let d = robot.all_active().len();
    let width = FAST_LANES * d;
    let mut scenes = Vec::new();
    let mut disagreements = 0;
    for (k, p) in loaded.iter().enumerate() {
        let objective = Objective::new(robot.all_active(), p.collision.clone(), p.world.clone());
        let mut fast = FastChecker::new(objective.collision(), objective.active().clone())
            .map_err(|e| e.to_string())?;
        let world = fast.model().world(&p.world);
        let mut scratch = objective.scratch();
        let mut free = Vec::new();
        for q in random_configurations(objective.active(), 512, k as u64) {
            let truth = objective.is_collision_free_in(&q, &p.world, &mut scratch);
            disagreements += usize::from(fast.all_free_unchecked(&q, &p.world, &world) != truth);
            if truth {
                free.extend(q);
            }
        }
        free.truncate(free.len() / width * width);
        let seen = vamp_world(&p.world, &p.problem.family);
        let (seen_fast, empty) = (fast.model().world(&seen), World::new());
        let worlds = [
            (world, p.world.clone()),
            (seen_fast, seen),
            (fast.model().world(&empty), empty),
        ];
        scenes.push(Scene {
            family: p.problem.family.clone(),
            fast,
            worlds,
            free,
        });
    }
    let total: usize = scenes.iter().map(|s| s.free.len() / d).sum();
    if total == 0 {
        return Err(format!(
            "{}: no block of free configurations in the scenes of {} problems (an empty set, \
             or scenes that fill the robot's reach)",
            args[0],
            scenes.len()
        ));
    }
    let mut vamp = match args.get(4) {
        Some(program) => Some(Vamp::start(program, &robot, &loaded, &scenes, d, rounds)?),
        None => None,
    };
    // per pass (PASSES): per family its rounds
    let mut times: [Times; PASSES] = Default::default();
    for _ in 0..rounds {
        for (pass, w) in [(TRM, 0), (TRM_SEEN, 1), (TRM_ALONE, 2)] {
            if pass == TRM_SEEN && vamp.is_none() {
                continue;
            }
            let mut this = BTreeMap::<String, f64>::new();
            for scene in &mut scenes {
                let (compiled, exact) = &scene.worlds[w];
                let began = Instant::now();
                for block in scene.free.chunks(width) {
                    std::hint::black_box(scene.fast.all_free_unchecked(block, exact, compiled));
                }
                *this.entry(scene.family.clone()).or_default() += began.elapsed().as_secs_f64();
            }
            record(&mut times[pass], this);
        }
        if let Some(vamp) = &mut vamp {
            // the scenes with their objects, then the same scenes empty
            let per_scene = vamp.round()?;
            let (full, alone) = per_scene.split_at(scenes.len());
            for (pass, part) in [(VAMP, full), (VAMP_ALONE, alone)] {
                let mut this = BTreeMap::<String, f64>::new();
                for (scene, ns) in scenes.iter().zip(part) {
                    *this.entry(scene.family.clone()).or_default() +=
                        ns * 1e-9 * (scene.free.len() / d) as f64;
                }
                record(&mut times[pass], this);
            }
        }
    }
    for family_times in &mut times {
        for scene in &scenes {
            if let Some(entry) = family_times.get_mut(&scene.family) {
                entry.1 += scene.free.len() / d;
            }
        }
    }
    println!(
        "{} with {}: free configurations of {per_family} problems per family, blocks of \
         {FAST_LANES}, median of {rounds} rounds (ns per configuration{})",
        args[0],
        args[1],
        if vamp.is_some() {
            "; trm in its world, trm in the world as VAMP sees it, VAMP, and the median over \
             the rounds of the first's ratio to VAMP's; then the robot alone, in an empty world, \
             trm and VAMP; and the world's part, each round's difference of the two"
        } else {
            "; then the robot alone, in an empty world"
        }
    );
    let per_config =
        |entry: &(Vec<f64>, usize)| median(&mut entry.0.clone()) / entry.1 as f64 * 1e9;
    let families: Vec<String> = times[0].keys().cloned().collect();
    let mut rows: Vec<(String, [Option<f64>; PASSES])> = families
        .iter()
        .map(|f| {
            (
                f.clone(),
                std::array::from_fn(|w| times[w].get(f).map(per_config)),
            )
        })
        .collect();
    let all = |family_times: &Times| -> Option<f64> {
        if family_times.is_empty() {
            return None;
        }
        let mut sums: Vec<f64> = (0..rounds)
            .map(|r| family_times.values().map(|(t, _)| t[r]).sum())
            .collect();
        Some(median(&mut sums) / total as f64 * 1e9)
    };
    rows.push(("all".into(), std::array::from_fn(|w| all(&times[w]))));
    // a pass's seconds in round r (the family's, or all of them)
    let side = |family: &str, w: usize, r: usize| -> f64 {
        match times[w].get(family) {
            Some((t, _)) => t[r],
            None => times[w].values().map(|(t, _)| t[r]).sum(),
        }
    };
    // ratios round by round (both sides ran in the same round), the median of those: the
    // machine's speed drifts between rounds
    let ratio = |ours: &dyn Fn(usize) -> f64, theirs: &dyn Fn(usize) -> f64| {
        let mut ratios: Vec<f64> = (0..rounds).map(|r| ours(r) / theirs(r)).collect();
        median(&mut ratios)
    };
    for (family, row) in &rows {
        let n = times[TRM].get(family).map_or(total, |e| e.1);
        let per = |seconds: f64| seconds / n as f64 * 1e9;
        match row {
            [
                Some(ours),
                Some(seen),
                Some(theirs),
                Some(alone),
                Some(vamp_alone),
            ] => {
                let whole = ratio(&|r| side(family, TRM, r), &|r| side(family, VAMP, r));
                let robot = ratio(&|r| side(family, TRM_ALONE, r), &|r| {
                    side(family, VAMP_ALONE, r)
                });
                let world = |w: usize, alone: usize| {
                    let mut parts: Vec<f64> = (0..rounds)
                        .map(|r| per(side(family, w, r) - side(family, alone, r)))
                        .collect();
                    median(&mut parts)
                };
                println!(
                    "  {family}: {ours:.1}, {seen:.1}, {theirs:.1} ({whole:.2}×); alone \
                     {alone:.1}, {vamp_alone:.1} ({robot:.2}×); the world's part {:.1}, {:.1} \
                     ({n} configurations)",
                    world(TRM, TRM_ALONE),
                    world(VAMP, VAMP_ALONE),
                );
            }
            [Some(ours), _, _, Some(alone), _] => {
                println!("  {family}: {ours:.1}; alone {alone:.1} ns per configuration ({n})")
            }
            _ => {}
        }
    }
    println!("  the screen and the exact model differ on {disagreements} configurations");
    if let Some(vamp) = vamp {
        let free = vamp.finish(scenes.len())?;
        println!(
            "  VAMP finds {free} of the {total} configurations free (its spheres and its world: \
             cylinders as capsules)"
        );
    }
    Ok(())
}

/// Adds one round's seconds per family.
fn record(times: &mut Times, round: BTreeMap<String, f64>) {
    for (family, t) in round {
        times.entry(family).or_default().0.push(t);
    }
}

/// VAMP's program in its `scenes` mode, a round at a time.
struct Vamp {
    child: std::process::Child,
    input: std::process::ChildStdin,
    output: std::io::Lines<BufReader<std::process::ChildStdout>>,
    program: String,
}

impl Vamp {
    /// Starts `program` and hands it every scene's objects and free configurations.
    fn start(
        program: &str,
        robot: &RobotModel,
        loaded: &[LoadedProblem],
        scenes: &[Scene],
        d: usize,
        rounds: usize,
    ) -> Result<Vamp, String> {
        let active = robot.all_active();
        let names: Vec<&str> = active.names().collect();
        // every scene twice: with its objects, then empty (the robot alone)
        let mut text = format!(
            "trm-mbm-problems 1\nrobot {}\nscenes\njoints {d} {}\n{}\n",
            robot.name(),
            names.join(" "),
            2 * scenes.len()
        );
        for alone in [false, true] {
            for (p, scene) in loaded.iter().zip(scenes) {
                text.push_str(&format!("scene {}\n", scene.family));
                if alone {
                    text.push_str("objects 0\n");
                } else {
                    text.push_str(&peer_objects(&p.scene).map_err(|e| e.to_string())?);
                }
                text.push_str(&format!("configurations {}\n", scene.free.len() / d));
                for q in scene.free.chunks(d) {
                    let values: Vec<String> = q.iter().map(|v| v.to_string()).collect();
                    text.push_str(&values.join(" "));
                    text.push('\n');
                }
            }
        }
        text.push_str(&format!("rounds {rounds}\n"));
        let (child, mut input, output) = trm_benches::start_vamp(program)?;
        input
            .write_all(text.as_bytes())
            .and_then(|()| input.flush())
            .map_err(|e| format!("{program}: {e}"))?;
        Ok(Vamp {
            child,
            input,
            output,
            program: program.into(),
        })
    }

    /// The next line VAMP prints, which must start with `word`: the rest's fields.
    fn line(&mut self, word: &str) -> Result<Vec<String>, String> {
        let line = self
            .output
            .next()
            .ok_or_else(|| format!("{}: ended before `{word}` (see its message)", self.program))?
            .map_err(|e| format!("{}: {e}", self.program))?;
        let mut fields = line.split_whitespace();
        if fields.next() != Some(word) {
            return Err(format!(
                "{}: expected `{word} …`, read `{line}`",
                self.program
            ));
        }
        Ok(fields.map(str::to_owned).collect())
    }

    /// The next round's times, ns per configuration, one per scene handed to it (VAMP runs
    /// it while this process waits).
    fn round(&mut self) -> Result<Vec<f64>, String> {
        writeln!(self.input, "next")
            .and_then(|()| self.input.flush())
            .map_err(|e| format!("{}: {e}", self.program))?;
        let fields = self.line("round")?;
        fields
            .iter()
            .map(|f| {
                let ns = f.split('/').next().unwrap_or(f);
                ns.parse::<f64>()
                    .map_err(|e| format!("{}: `{f}` in a round: {e}", self.program))
            })
            .collect()
    }

    /// How many configurations VAMP finds free in the first `scenes` scenes handed to it
    /// (those with their objects), then waits for it to end.
    fn finish(mut self, scenes: usize) -> Result<usize, String> {
        let fields = self.line("free")?;
        let free = fields
            .iter()
            .take(scenes)
            .map(|f| f.parse::<usize>().map_err(|e| format!("`{f}`: {e}")))
            .sum::<Result<usize, String>>()?;
        drop(self.input);
        let _ = self.child.wait();
        Ok(free)
    }
}
