//! A set solved with experience kept: one planner per family keeps every path RRT-Connect
//! finds, and later problems plan through them.

use trm_kinematics::RobotModel;
use trm_plan::rrt::{RrtOptions, path_length};
use trm_plan::{Planner, Source};
use trm_tasks::Objective;

use crate::error::MbmError;
use crate::loaded::LoadedProblem;
use crate::solve::{Outcome, invalid, joint_goal_only, problem_objective};

/// Solves `problems` with experience, as a robot that keeps what it learns: one planner per
/// family (`trm_plan::Planner` over no map), each problem planned through what the family's
/// earlier problems left behind (checked lazily in the new scene) and, where that does not
/// join start and goal, by RRT-Connect, whose path is then kept
/// ([`trm_plan::Planner::add_path`]). An outcome's note says how it was answered: `experience`,
/// `straight` (the straight edge from start to goal is free), `retrieved` (a kept path whose
/// ends the problem repeats) or `RRT-Connect (path kept)`. The set is run `passes` times with
/// the experience kept; `outcomes[pass][k]` answers `problems[k]`; `done(pass, k)` is called
/// after each. The problems of a family must share the goal's joints and the start's other
/// motors (an error names the first that does not).
pub fn solve_with_experience(
    robot: &RobotModel,
    problems: &[LoadedProblem],
    options: &RrtOptions,
    passes: usize,
    mut done: impl FnMut(usize, usize),
) -> Result<Vec<Vec<Outcome>>, MbmError> {
    options.check()?;
    let mut outcomes = vec![vec![Outcome::default(); problems.len()]; passes];
    let mut families: Vec<&str> = problems.iter().map(|p| p.problem.family.as_str()).collect();
    families.sort_unstable();
    families.dedup();
    for family in families {
        let members: Vec<usize> = (0..problems.len())
            .filter(|&k| problems[k].problem.family == family)
            .collect();
        let mut run = FamilyRun::new(robot, problems, members)?;
        for (pass, results) in outcomes.iter_mut().enumerate() {
            run.pass(options, results, |k| done(pass, k))?;
        }
    }
    Ok(outcomes)
}

/// Which other problems' paths a problem plans through in [`solve_leave_one_out`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    /// The other problems of its family.
    Family,
    /// Every other problem of the set that moves the same motors from the same other values.
    Set,
}

/// Solves each of `problems` through the paths `paths[j]` found for the *other* problems
/// (leave-one-out: a problem never sees its own path) of its family or of the whole set
/// (`scope`), as a robot that has planned those before: a planner per set of moving motors
/// (and the others' values), kept across the problems as [`crate::Solver`] keeps them, given
/// each problem's matrix before its query and those paths in stack order (`leave_out`:
/// checked lazily in the problem's scene, the graph not rebuilt per problem), RRT-Connect
/// where they do not join start and goal; nothing is kept. `paths[k]` is empty for a problem
/// without a path; each problem is also solved afresh beside it ([`LeaveOneOut::fresh`]);
/// `done(k)` after each problem, in their order within each group of problems sharing paths.
/// Notes as in [`solve_with_experience`].
pub fn solve_leave_one_out(
    robot: &RobotModel,
    problems: &[LoadedProblem],
    paths: &[Vec<Vec<f64>>],
    scope: Scope,
    options: &RrtOptions,
    mut done: impl FnMut(usize),
) -> Result<LeaveOneOut, MbmError> {
    options.check()?;
    if paths.len() != problems.len() {
        return Err(MbmError::Invalid {
            path: Default::default(),
            line: 0,
            problem: format!("{} paths for {} problems", paths.len(), problems.len()),
            fix: "give one path (empty where none was found) per problem".into(),
        });
    }
    // the motors each problem moves and the values of the others: paths are shared only
    // between problems that agree on both
    let mut setups = Vec::with_capacity(problems.len());
    for p in problems {
        let (objective, active, start) = problem_objective(
            robot,
            &p.collision,
            &trm_collision::World::new(),
            &p.request,
        )?;
        setups.push((active, objective.active().to_motors(&start)));
    }
    // the problems that share their paths: the same setup, and the same family unless the
    // scope is the set
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for k in 0..problems.len() {
        let together = |g: &&mut Vec<usize>| {
            setups[g[0]] == setups[k]
                && (scope == Scope::Set
                    || problems[g[0]].problem.family == problems[k].problem.family)
        };
        match groups.iter_mut().find(together) {
            Some(group) => group.push(k),
            None => groups.push(vec![k]),
        }
    }
    // one planner per setup, kept across the problems as the plain run keeps its planners
    let mut planners: Vec<(&Setup, Planner)> = Vec::new();
    let mut outcomes = vec![Outcome::default(); problems.len()];
    let mut fresh = vec![Outcome::default(); problems.len()];
    let mut solver = crate::Solver::new(robot, &[]);
    let mut asked = 0;
    for group in &groups {
        let first = &problems[group[0]];
        let (objective, _, _) = problem_objective(
            robot,
            &first.own,
            &trm_collision::World::new(),
            &first.request,
        )?;
        let setup = &setups[group[0]];
        let at = match planners.iter().position(|(s, _)| *s == setup) {
            Some(at) => at,
            None => {
                planners.push((setup, Planner::new(&objective, &[])?));
                planners.len() - 1
            }
        };
        let planner = &mut planners[at].1;
        planner.forget_paths();
        leave_out(planner, group, paths, &mut |planner, k| {
            let mut run = FamilyRun::new(robot, problems, vec![k])?;
            run.keep = false;
            planner.set_collision(&problems[k].collision)?;
            // in turn first and second: the query second finds the problem's scene in the
            // caches
            if asked % 2 == 1 {
                fresh[k] = solver.solve(&problems[k], options)?;
            }
            outcomes[k] = run.plan(planner, &objective, k, options)?;
            if asked % 2 == 0 {
                fresh[k] = solver.solve(&problems[k], options)?;
            }
            asked += 1;
            done(k);
            Ok(())
        })?;
    }
    Ok(LeaveOneOut { outcomes, fresh })
}

/// What [`solve_leave_one_out`] found: each problem through the other problems' paths, and
/// the same problem solved afresh right before or after it, in turn ([`crate::Solver`], no
/// paths), so that a machine's changing speed weighs on both alike, and so does the head
/// start the second query of a problem gets from the first (its scene in the caches).
#[derive(Debug, Clone)]
pub struct LeaveOneOut {
    /// Through the other problems' paths, one per problem.
    pub outcomes: Vec<Outcome>,
    /// Afresh, beside each of them.
    pub fresh: Vec<Outcome>,
}

/// Asks `query` for each problem of `group` with the paths of every other one of them (not
/// empty) kept by `planner` besides what it keeps already: the group halved, each half asked
/// with the other half's paths kept ([`Planner::add_path`]) and then forgotten
/// ([`Planner::forget_last_path`]), down to single problems. Every path is kept about log₂ of
/// the group's size times, and the planner changes by a few paths between most queries, as a
/// planner in use does, instead of being rebuilt for each.
fn leave_out(
    planner: &mut Planner,
    group: &[usize],
    paths: &[Vec<Vec<f64>>],
    query: &mut dyn FnMut(&mut Planner, usize) -> Result<(), MbmError>,
) -> Result<(), MbmError> {
    if let [k] = group {
        return query(planner, *k);
    }
    let (left, right) = group.split_at(group.len() / 2);
    for (half, other) in [(left, right), (right, left)] {
        let mut kept = 0;
        for &j in other.iter().filter(|&&j| !paths[j].is_empty()) {
            planner.add_path(&paths[j])?;
            kept += 1;
        }
        leave_out(planner, half, paths, query)?;
        for _ in 0..kept {
            planner.forget_last_path();
        }
    }
    Ok(())
}

/// The motors a problem moves and the values of the others (problems share paths only when
/// theirs agree).
type Setup = (Vec<usize>, Vec<f64>);

/// One family's problems and the paths its planners keep, pass after pass.
struct FamilyRun<'a> {
    robot: &'a RobotModel,
    problems: &'a [LoadedProblem],
    /// The family's problems (indices into `problems`), in order.
    members: Vec<usize>,
    /// The motors the family's goals move.
    active: Vec<usize>,
    /// Every path kept so far: each planner of the family starts from them.
    kept: Vec<Vec<Vec<f64>>>,
    /// Whether paths RRT-Connect finds are kept.
    keep: bool,
}

impl<'a> FamilyRun<'a> {
    fn new(
        robot: &'a RobotModel,
        problems: &'a [LoadedProblem],
        members: Vec<usize>,
    ) -> Result<Self, MbmError> {
        let first = &problems[members[0]];
        let (_, active, _) = problem_objective(
            robot,
            &first.collision,
            &trm_collision::World::new(),
            &first.request,
        )?;
        Ok(FamilyRun {
            robot,
            problems,
            members,
            active,
            kept: Vec::new(),
            keep: true,
        })
    }

    /// One pass over the family: one planner per run of problems whose scenes allow the same
    /// collisions (each problem is planned and checked with its own scene's matrix).
    fn pass(
        &mut self,
        options: &RrtOptions,
        results: &mut [Outcome],
        mut done: impl FnMut(usize),
    ) -> Result<(), MbmError> {
        let first = &self.problems[self.members[0]];
        let mut next = 0;
        while next < self.members.len() {
            let acm = self.problems[self.members[next]].collision.acm().clone();
            let (objective, _, _) = problem_objective(
                self.robot,
                &self.problems[self.members[next]].own,
                &trm_collision::World::new(),
                &first.request,
            )?;
            let mut planner = Planner::new(&objective, &[])?;
            planner.set_collision(&self.problems[self.members[next]].collision)?;
            for path in &self.kept {
                planner.add_path(path)?;
            }
            while next < self.members.len() {
                let k = self.members[next];
                if self.problems[k].collision.acm() != &acm {
                    break;
                }
                next += 1;
                results[k] = self.plan(&mut planner, &objective, k, options)?;
                done(k);
            }
        }
        Ok(())
    }

    /// Problem `k` planned through the planner's experience, its path kept when RRT-Connect
    /// found it.
    fn plan(
        &mut self,
        planner: &mut Planner,
        objective: &Objective,
        k: usize,
        options: &RrtOptions,
    ) -> Result<Outcome, MbmError> {
        let problem = &self.problems[k];
        let (mut start, mut goal) = self.start_and_goal(problem, objective)?;
        planner.set_world(problem.world.clone());
        let mut outcome = Outcome::default();
        if let Some(why) = invalid(self.robot, &self.active, &mut start, &mut goal, planner) {
            outcome.note = why;
            return Ok(outcome);
        }
        outcome.valid = true;
        let rrt = RrtOptions {
            max_seconds: options.max_seconds.or(problem.request.planning_time),
            ..options.clone()
        };
        match planner.connect(&start, &goal, &rrt) {
            Ok(found) => {
                outcome.solved = true;
                outcome.seconds = found.seconds;
                outcome.simplify_seconds = found.simplify_seconds;
                outcome.length = path_length(&found.path);
                outcome.waypoints = found.path.len();
                outcome.checks = found.checks;
                outcome.note = match found.source {
                    Source::Sampled if self.keep => {
                        planner.add_path(&found.path)?;
                        self.kept.push(found.path.clone());
                        "RRT-Connect (path kept)".into()
                    }
                    Source::Sampled => "RRT-Connect".into(),
                    Source::Graph => "experience".into(),
                    other => other.name().into(),
                };
                outcome.path = found.path;
            }
            Err(e) => outcome.note = e.to_string(),
        }
        Ok(outcome)
    }

    /// The start and goal of `problem` (active values), refused when its goal is not joints,
    /// or its goal's joints or its start's other motors differ from those of the planner's
    /// `objective`.
    fn start_and_goal(
        &self,
        problem: &LoadedProblem,
        objective: &Objective,
    ) -> Result<(Vec<f64>, Vec<f64>), MbmError> {
        let request = &problem.request;
        joint_goal_only(request, "experience runs")?;
        let (other, other_active, start) = problem_objective(
            self.robot,
            &problem.collision,
            &trm_collision::World::new(),
            request,
        )?;
        if other_active != self.active
            || other.active().to_motors(&start) != objective.active().to_motors(&start)
        {
            return Err(MbmError::Invalid {
                path: request.origin.clone(),
                line: 0,
                problem: format!(
                    "its goal's joints or its start's other motors differ from {}'s",
                    self.problems[self.members[0]].problem.request.display()
                ),
                fix: "give a family whose problems share the robot's planning group and its other joints' values".into(),
            });
        }
        Ok((start, request.goal.positions.clone()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each problem of a group is asked with exactly the other problems' paths kept (those
    /// not empty), and the planner ends as it began.
    #[test]
    fn each_problem_is_asked_with_every_other_path_and_never_its_own() {
        let robot = trm_models::icub_upper_body();
        let home = robot.posture("home").expect("shipped posture").to_vec();
        let arm = ["r_shoulder_pitch", "r_shoulder_roll", "r_elbow"];
        let active = robot.active_set(&arm, &home).expect("shipped motors");
        let collision = trm_collision::CollisionModel::new(&robot).expect("shipped model");
        let objective = Objective::new(active, collision, trm_collision::World::new());
        let mut planner = Planner::new(&objective, &[]).expect("valid objective");
        let before = vec![vec![0.1, 0.2, 0.3], vec![0.2, 0.2, 0.3]];
        planner.add_path(&before).expect("finite");
        for n in [1, 2, 5, 11] {
            // problem j's path: two waypoints of its own (none for every third problem)
            let paths: Vec<Vec<Vec<f64>>> = (0..n)
                .map(|j| match j % 3 {
                    2 => Vec::new(),
                    _ => vec![
                        vec![0.01 * j as f64, -0.3, 0.5],
                        vec![0.5, 0.01 * j as f64, 0.2],
                    ],
                })
                .collect();
            let group: Vec<usize> = (0..n).collect();
            let mut asked = Vec::new();
            leave_out(&mut planner, &group, &paths, &mut |planner, k| {
                let mut kept = planner.kept_paths();
                assert_eq!(kept.remove(0), before, "problem {k}");
                let mut others: Vec<Vec<Vec<f64>>> = (0..n)
                    .filter(|&j| j != k && !paths[j].is_empty())
                    .map(|j| paths[j].clone())
                    .collect();
                let order = |a: &Vec<Vec<f64>>, b: &Vec<Vec<f64>>| a[0][0].total_cmp(&b[0][0]);
                kept.sort_by(order);
                others.sort_by(order);
                assert_eq!(kept, others, "problem {k} of {n}");
                asked.push(k);
                Ok(())
            })
            .expect("no error");
            assert_eq!(asked, group);
            assert_eq!(planner.kept_paths(), vec![before.clone()]);
        }
    }
}
