//! trm as a library, from outside its workspace:
//!
//! 1. build a roadmap from our own spec and save it;
//! 2. load it back, rebuild its task from the spec it carries, plan to a task-space point and
//!    write the trajectory (CSV and JSON) and the start and goal postures;
//! 3. run a Table III comparison of optimisers on our posture spec;
//! 4. plug in our own cost (keep the right forearm above a plane) and our own optimiser (a
//!    compass search) into NGIK on the same spec.
//!
//! `cargo run --manifest-path examples/library-user/Cargo.toml -- OUT_DIR`

use std::error::Error;
use std::path::{Path, PathBuf};

use rand::{Rng, RngExt, SeedableRng};
use trm_kinematics::{FrameId, PostureFile};
use trm_optim::{OptimError, Optimizer, Population, Start, State};
use trm_plan::{Goal, PlanOptions, Planner, Trajectory};
use trm_roadmap::{BuildOptions, Builder, Roadmap};
use trm_tasks::{Comparison, Context, Cost, Problem};

/// Our own cost: squared height of a frame below a plane, zero above it.
#[derive(Debug)]
struct StayAbove {
    frame: FrameId,
    height: f64,
}

impl Cost for StayAbove {
    fn label(&self) -> String {
        format!("stay above z = {}", self.height)
    }
    fn eval(&self, ctx: &Context) -> f64 {
        let z = ctx.poses.pose(self.frame).translation.z;
        (self.height - z).max(0.0).powi(2)
    }
}

/// Our own optimiser: a compass (pattern) search — try ± step along one randomly chosen
/// coordinate per generation, keep what improves, halve the step after every coordinate failed
/// in a row. Not in trm-optim; it only has to implement `Optimizer`.
struct CompassSearch {
    state: State,
    current: Vec<f64>,
    current_f: f64,
    step: f64,
    failures: usize,
    candidates: Population,
}

impl CompassSearch {
    fn new(start: &Start) -> Result<Self, OptimError> {
        let steps = start.check()?; // validates the start, gives the initial step per coordinate
        Ok(CompassSearch {
            state: State::new(start, 2),
            current: start.mean.clone(),
            current_f: f64::INFINITY,
            step: steps.iter().copied().fold(0.0, f64::max),
            failures: 0,
            candidates: Population::from_candidates(&[&start.mean, &start.mean]),
        })
    }
}

impl Optimizer for CompassSearch {
    fn name(&self) -> &'static str {
        "compass-search"
    }
    fn dim(&self) -> usize {
        self.current.len()
    }
    fn ask(&mut self, rng: &mut dyn Rng) -> &Population {
        let axis = rng.random_range(0..self.current.len());
        for (c, sign) in self.candidates.iter_mut().zip([1.0, -1.0]) {
            c.copy_from_slice(&self.current);
            c[axis] += sign * self.step;
            self.state.clamp(c);
        }
        self.state.asked(2);
        &self.candidates
    }
    fn tell(&mut self, fitness: &[f64]) -> Result<(), OptimError> {
        self.state.told(&self.candidates, fitness)?;
        let (best, f) = if fitness[0] <= fitness[1] { (0, fitness[0]) } else { (1, fitness[1]) };
        if f < self.current_f {
            self.current.copy_from_slice(&self.candidates[best]);
            self.current_f = f;
            self.failures = 0;
        } else {
            self.failures += 1;
            if self.failures >= self.current.len() {
                self.step *= 0.5;
                self.failures = 0;
            }
        }
        Ok(())
    }
    fn mean(&self) -> &[f64] {
        &self.current
    }
    fn spread(&self) -> f64 {
        self.step
    }
    fn state(&self) -> &State {
        &self.state
    }
    fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let out = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "target/library-user".into()));
    let specs = Path::new(env!("CARGO_MANIFEST_DIR")).join("specs");
    let spec = specs.join("right_hand.ron");
    std::fs::create_dir_all(&out)?;

    // 1. build a map from our spec
    let problem = Problem::load(&spec)?;
    let map = trm_roadmap::Builder::new(&problem, &BuildOptions::default()).connected().run(|_| {})?;
    let map_file = out.join("right_hand.map.json");
    map.save(&map_file)?;
    let summary = map.summary();
    println!(
        "map: {} points, {} edges, {} components, mean spacing {:.3} m",
        summary.points,
        summary.edges,
        summary.components,
        summary.spacing.map_or(0.0, |s| s.0)
    );

    // 2. load it, rebuild its task, plan, write trajectory and postures
    let map = Roadmap::load(&map_file)?;
    let problem = map.problem()?;
    let mut planner = Planner::new(&problem.objective, &[&map])?;
    // the map point farthest (in task space) from where the start posture puts the palm
    let mut scratch = problem.objective.scratch();
    let from = problem.objective.task_value(&problem.start, &mut scratch);
    let far = |t: &[f64]| t.iter().zip(&from).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
    let target = map
        .points
        .iter()
        .max_by(|a, b| far(&a.t).total_cmp(&far(&b.t)))
        .expect("a map has points")
        .t
        .clone();
    let plan = planner.plan(
        &problem.start,
        &Goal::TaskPoint { t: target.clone(), tolerance: 0.03 },
        &PlanOptions::default(),
    )?;
    let csv = out.join("plan.csv");
    trm_kinematics::write_atomic(&csv, plan.trajectory.to_csv(&csv)?.as_bytes())?;
    let json = out.join("plan.json");
    trm_kinematics::write_atomic(&json, plan.trajectory.to_json(&json)?.as_bytes())?;
    let back = Trajectory::load(&csv, &problem.robot)?;
    assert_eq!(back.positions.len(), plan.trajectory.positions.len());
    let robot = &problem.robot;
    let active = problem.objective.active();
    let last = plan.trajectory.motor_frames(robot, &active.to_motors(&problem.start))?;
    let goal_motors = &last.last().expect("a plan has waypoints").1;
    PostureFile::from_motors(robot, &active.to_motors(&problem.start))?
        .with("what", "start")
        .save(out.join("start.posture.json"))?;
    PostureFile::from_motors(robot, goal_motors)?
        .with("what", "goal")
        .with("task_target", target.clone())
        .save(out.join("goal.posture.json"))?;
    let reread = PostureFile::load(out.join("goal.posture.json"))?
        .to_motors(robot, None, &robot.neutral_motors(), &out.join("goal.posture.json"))?;
    assert_eq!(&reread, goal_motors);
    println!(
        "plan: {} map nodes, {} waypoints after shortcutting, {:.2} s, to within {:.3} m of {:?}",
        plan.stats.path_nodes,
        plan.trajectory.times.len(),
        plan.trajectory.times.last().copied().unwrap_or(0.0),
        {
            let t = plan.trajectory.task_path.last().expect("a task path");
            t.iter().zip(&target).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt()
        },
        target
    );

    // 3. Table III on our own posture spec
    let reach_spec = specs.join("reach_point.ron");
    let reach = Problem::load(&reach_spec)?;
    let comparison = Comparison {
        algorithms: vec!["xnes".into(), "cmaes".into(), "simplex".into()],
        runs: 3,
        max_evaluations: 3_000,
        no_improvement: 1_500,
        ..Default::default()
    };
    let result = comparison.run(&[("reach_point.ron", &reach)])?;
    std::fs::write(out.join("table.md"), result.to_markdown())?;
    for algo in &comparison.algorithms {
        let s = result.summary(0, algo).expect("runs of every algorithm");
        println!("table III: {algo:<8} cost {:.4} ± {:.4}, {}/{} collision-free", s.cost.0, s.cost.1, s.collision_free, s.runs);
    }

    // 4. our own cost and optimiser in NGIK: reach a point, keep the elbow above the table top
    let mut problem = Problem::load(&reach_spec)?;
    let elbow = problem.robot.frame_id("r_forearm")?;
    problem.objective.add(20.0, Box::new(StayAbove { frame: elbow, height: -0.05 }))?;
    let solver = problem.spec.solver.clone();
    let start = trm_tasks::solver_start(&problem.objective, &problem.start, &solver)?;
    let mut mine = CompassSearch::new(&start)?;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let solution = trm_tasks::solve_with(&problem.objective, &problem.start, &mut mine, &mut rng)?;
    let ours = solution.breakdown.iter().find(|t| t.label.starts_with("stay above")).expect("our term");
    println!(
        "own optimiser + own cost: cost {:.4} after {} evaluations (stopped: {:?}), our term {:.2e}, collision-free {}",
        solution.cost, solution.evaluations, solution.reasons, ours.value, solution.collision_free
    );
    Ok(())
}
