//! A set solved with experience kept: one planner per family keeps every path RRT-Connect
//! finds, and later problems plan through them.

use trm_collision::CollisionModel;
use trm_kinematics::RobotModel;
use trm_moveit::{MotionPlanRequest, PlanningScene};
use trm_plan::rrt::{EdgeCheck, RrtOptions, path_length, rrt_connect, shortcut};

use crate::error::MbmError;
use crate::problems::Problem;
use crate::solve::{Outcome, invalid, joint_goal_only, problem_objective, scene_collision};

/// Solves `problems` with experience, as a robot that keeps what it learns: one planner per
/// family (`trm_plan::Planner` over no map), each problem planned through what the family's
/// earlier problems left behind (checked lazily in the new scene) and, where that does not
/// join start and goal, by RRT-Connect, whose path is then kept ([`trm_plan::Planner::add_path`]).
/// An outcome's note says how it was answered: `experience`, `straight` (the straight edge
/// from start to goal is free) or `RRT-Connect (path kept)`. The set is run `passes` times with the experience kept; `outcomes[pass][k]` answers
/// `problems[k]`; `done(pass, k)` is called after each. The problems of a family must share
/// the goal's joints and the start's other motors (an error names the first that does not).
pub fn solve_with_experience(
    robot: &RobotModel,
    collision: &CollisionModel,
    problems: &[Problem],
    options: &RrtOptions,
    passes: usize,
    mut done: impl FnMut(usize, usize),
) -> Result<Vec<Vec<Outcome>>, MbmError> {
    options.check()?;
    let mut outcomes = vec![vec![Outcome::default(); problems.len()]; passes];
    let mut families: Vec<&str> = problems.iter().map(|p| p.family.as_str()).collect();
    families.dedup();
    families.sort_unstable();
    families.dedup();
    for family in families {
        let members: Vec<usize> = (0..problems.len())
            .filter(|&k| problems[k].family == family)
            .collect();
        let first = MotionPlanRequest::load(&problems[members[0]].request)?;
        let (_, active, _) =
            problem_objective(robot, collision, &trm_collision::World::new(), &first)?;
        // every path kept so far: each planner of the family starts from them
        let mut kept: Vec<Vec<Vec<f64>>> = Vec::new();
        for (pass, results) in outcomes.iter_mut().enumerate() {
            let mut next = 0;
            while next < members.len() {
                // one planner per run of problems whose scenes allow the same collisions (each
                // problem is planned and checked with its own scene's matrix)
                let scene = PlanningScene::load(&problems[members[next]].scene)?;
                let (acm_collision, _) = scene_collision(collision, &scene)?;
                let acm = acm_collision.acm().clone();
                let (objective, _, _) =
                    problem_objective(robot, &acm_collision, &trm_collision::World::new(), &first)?;
                let mut planner = trm_plan::Planner::new(&objective, &[])?;
                for path in &kept {
                    planner.add_path(path)?;
                }
                while next < members.len() {
                    let k = members[next];
                    let p = &problems[k];
                    let scene = PlanningScene::load(&p.scene)?;
                    if scene_collision(collision, &scene)?.0.acm() != &acm {
                        break;
                    }
                    next += 1;
                    let request = MotionPlanRequest::load(&p.request)?;
                    joint_goal_only(&request, "experience runs")?;
                    let (other, other_active, mut start) = problem_objective(
                        robot,
                        collision,
                        &trm_collision::World::new(),
                        &request,
                    )?;
                    if other_active != active
                        || other.active().to_motors(&start) != objective.active().to_motors(&start)
                    {
                        return Err(MbmError::Invalid {
                            path: request.origin.clone(),
                            line: 0,
                            problem: format!(
                                "its goal's joints or its start's other motors differ from {}'s",
                                problems[members[0]].request.display()
                            ),
                            fix: "give a family whose problems share the robot's planning group and its other joints' values".into(),
                        });
                    }
                    planner.set_world(scene.to_world()?);
                    let mut goal = request.goal.positions.clone();
                    let outcome = &mut results[k];
                    if let Some(why) = invalid(robot, &active, &mut start, &mut goal, |q| {
                        planner.is_free(q)
                    }) {
                        outcome.note = why.into();
                        done(pass, k);
                        continue;
                    }
                    outcome.valid = true;
                    let began = std::time::Instant::now();
                    let rrt = RrtOptions {
                        max_seconds: options.max_seconds.or(request.planning_time),
                        ..options.clone()
                    };
                    let plan_options = trm_plan::PlanOptions {
                        resolution: options.resolution,
                        shortcuts: 0,
                        seed: options.seed,
                        exact_goal: false,
                        sampling: Some(rrt.clone()),
                        ..Default::default()
                    };
                    let found = match planner.plan(
                        &start,
                        &trm_plan::Goal::Configuration(goal.clone()),
                        &plan_options,
                    ) {
                        Ok(planned) if planned.stats.sampled.is_some() => Ok((
                            planned.waypoints,
                            planned.stats.sampled.map_or(0, |s| s.1),
                            None,
                        )),
                        Ok(planned) => {
                            // through experience: shortcut greedily, and checked at half the
                            // resolution as RRT-Connect's paths are; RRT-Connect where that fails
                            let world = planner.world().clone();
                            let mut checker = objective.world_checker(&world)?;
                            let mut path = planned.waypoints;
                            let mut rng =
                                <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(
                                    options.seed,
                                );
                            let edges = shortcut(
                                &mut path,
                                &RrtOptions {
                                    shortcuts: 0,
                                    ..options.clone()
                                },
                                &mut checker,
                                &mut rng,
                            );
                            let how = if planned.stats.retrieved {
                                "retrieved"
                            } else if planned.nodes.is_empty() {
                                "straight"
                            } else {
                                "experience"
                            };
                            // at half the resolution: the edges the shortcut found free and the
                            // planner's own (checked at the same points,
                            // `Planner::segment_free`) need only their midpoints
                            let r = options.resolution;
                            if path.windows(2).zip(&edges).all(|(w, e)| {
                                (*e != EdgeCheck::Piece || checker.edge_free(&w[0], &w[1], r))
                                    && checker.edge_midpoints_free(&w[0], &w[1], r)
                            }) {
                                Ok((path, checker.checks, Some(how)))
                            } else {
                                rrt_connect(&objective, &world, &start, &goal, &rrt)
                                    .map(|f| (f.path, checker.checks + f.checks, None))
                            }
                        }
                        Err(e) => Err(e),
                    };
                    match found {
                        Ok((path, checks, answered)) => {
                            outcome.solved = true;
                            outcome.seconds = began.elapsed().as_secs_f64();
                            outcome.length = path_length(&path);
                            outcome.waypoints = path.len();
                            outcome.checks = checks;
                            outcome.note = match answered {
                                Some(how) => how.into(),
                                None => {
                                    planner.add_path(&path)?;
                                    kept.push(path.clone());
                                    "RRT-Connect (path kept)".into()
                                }
                            };
                            outcome.path = path;
                        }
                        Err(e) => outcome.note = e.to_string(),
                    }
                    done(pass, k);
                }
            }
        }
    }
    Ok(outcomes)
}
