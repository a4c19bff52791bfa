//! Paths made trajectories: blended, timed within the motors' limits, with their task path.

use super::Planner;
use crate::PlanError;
use crate::trajectory::Trajectory;

impl Planner {
    /// [`Planner::trajectory`] of `waypoints`, or (while [`Planner::time_paths`] is off) the
    /// waypoints alone, untimed.
    pub(super) fn timed_if_asked(
        &mut self,
        waypoints: &[Vec<f64>],
        timing: &crate::Timing,
    ) -> Result<Trajectory, PlanError> {
        if self.time_paths {
            return self.trajectory(waypoints, timing);
        }
        Ok(Trajectory {
            names: self.active.model().motor_names(),
            times: Vec::new(),
            positions: waypoints.iter().map(|q| self.active.to_motors(q)).collect(),
            velocities: Vec::new(),
            accelerations: Vec::new(),
            task_path: Vec::new(),
        })
    }

    /// A path (active values, collision-checked) as a trajectory the robot can execute:
    /// corners blended where the blends are free in the current world, timed time-optimally
    /// within the motors' limits, sampled with velocities and accelerations
    /// ([`crate::timing::timed`]), with its task-space path where the planner has a task.
    pub fn trajectory(
        &mut self,
        waypoints: &[Vec<f64>],
        timing: &crate::Timing,
    ) -> Result<Trajectory, PlanError> {
        let resolution = match timing.resolution {
            Some(r) => r,
            None => self.rrt_options()?.resolution,
        };
        let active = self.active.clone();
        let checker = &mut self.checker;
        let mut trajectory =
            crate::timing::timed(&active, waypoints, timing, resolution, |a, b| {
                checker.segment_free(a, b, resolution)
            })?;
        if self.objective.task().is_some() {
            let samples: Vec<Vec<f64>> = trajectory
                .positions
                .iter()
                .map(|m| active.from_motors(m))
                .collect();
            trajectory.task_path = samples.iter().map(|q| self.task_of(q)).collect();
        }
        Ok(trajectory)
    }
}
