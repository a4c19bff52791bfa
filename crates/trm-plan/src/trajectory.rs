//! Time parametrisation of a piecewise-linear joint path, and trajectory files.
//!
//! Two formats, one [`Trajectory`]:
//! * **CSV** ([`Trajectory::to_csv`], [`Trajectory::from_csv`]): a header `time,<motor names…>`
//!   then one row per waypoint (seconds, then motor values). The reader also takes a `t` column
//!   for the time and skips the extra columns of the whole-body CSV of `cargo xtask stand-up`
//!   ([`WHOLE_BODY_COLUMNS`]: phase, CoM and ZMP), so that file reads too; any other column must
//!   name a motor of the robot. Times start at 0 or later and never decrease; every value is a
//!   finite number within its motor's limits.
//! * **JSON** ([`Trajectory::to_json`], [`Trajectory::from_json`]): the struct's fields, with the
//!   task-space path.

use std::path::Path;

use serde::{Deserialize, Serialize};
use trm_kinematics::{ActiveSet, RobotModel};

use crate::PlanError;

/// Columns of the whole-body CSV (`cargo xtask stand-up`) that name no motor; the CSV reader
/// skips them.
pub const WHOLE_BODY_COLUMNS: &[&str] = &[
    "phase",
    "com_x",
    "com_z",
    "com_desired_x",
    "com_desired_z",
    "zmp_x",
];

/// A timed joint trajectory (full motor vectors) with its task-space path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Trajectory {
    /// Motor names, the columns of `positions`.
    pub names: Vec<String>,
    /// Time of each waypoint, seconds, from 0.
    pub times: Vec<f64>,
    /// Motor values at each waypoint.
    pub positions: Vec<Vec<f64>>,
    /// Motor velocities at each waypoint (empty: not given; a timed plan gives them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub velocities: Vec<Vec<f64>>,
    /// Motor accelerations at each waypoint (empty: not given).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub accelerations: Vec<Vec<f64>>,
    /// Task vector at each waypoint.
    pub task_path: Vec<Vec<f64>>,
}

impl Trajectory {
    /// A path of `active`'s motors (active values per waypoint) as full motor vectors, timed by
    /// [`time_parametrise`] at `speed` rad/s for every moving motor (stopping at each waypoint;
    /// no velocities, no task path): how an optimised motion's postures are written out.
    pub fn at_joint_speed(active: &ActiveSet, path: &[Vec<f64>], speed: f64) -> Self {
        Trajectory {
            names: active.model().motor_names(),
            times: time_parametrise(path, &vec![speed; active.len()], None),
            positions: path.iter().map(|q| active.to_motors(q)).collect(),
            velocities: Vec::new(),
            accelerations: Vec::new(),
            task_path: Vec::new(),
        }
    }

    /// CSV: `time,<names…>` then one row per waypoint (shortest exact decimals). Refuses what
    /// the reader refuses ([`Trajectory::check`]); `path` names the file it is for.
    pub fn to_csv(&self, path: &Path) -> Result<String, PlanError> {
        self.check(path)?;
        let mut out = format!("time,{}\n", self.names.join(","));
        for (t, q) in self.times.iter().zip(&self.positions) {
            let row: Vec<String> = q.iter().map(|v| format!("{v}")).collect();
            out.push_str(&format!("{t},{}\n", row.join(",")));
        }
        Ok(out)
    }

    /// The trajectory as JSON (names, times, positions, task path). Refuses what the reader
    /// refuses ([`Trajectory::check`]); `path` names the file it is for.
    pub fn to_json(&self, path: &Path) -> Result<String, PlanError> {
        self.check(path)?;
        serde_json::to_string_pretty(self).map_err(|e| {
            invalid(
                path,
                0,
                e.to_string(),
                "report this: a checked trajectory serialises",
            )
        })
    }

    /// Reads [`Trajectory::to_json`]'s output; `origin` names the text in errors. Checks it as
    /// [`Trajectory::check`] does.
    pub fn from_json(text: &str, origin: &Path) -> Result<Self, PlanError> {
        let t: Trajectory = trm_io::check_unique_keys(text)
            .and_then(|()| serde_json::from_str(text))
            .map_err(|e| {
                invalid(
                    origin,
                    e.line(),
                    e.to_string(),
                    "give a trajectory written by trm (`plan --out x.json`)",
                )
            })?;
        t.check(origin)?;
        Ok(t)
    }

    /// Checks the trajectory's shape: names given once, one time and one value per name at
    /// every waypoint, a task path empty or one finite vector per waypoint of one dimension,
    /// finite values, times from 0 up that never decrease. `origin` names the file in errors.
    pub fn check(&self, origin: &Path) -> Result<(), PlanError> {
        if self.times.is_empty() && self.positions.is_empty() {
            return Err(invalid(
                origin,
                0,
                "no waypoints".into(),
                "give at least one waypoint (a motion holds two or more)",
            ));
        }
        for (i, name) in self.names.iter().enumerate() {
            if self.names[..i].contains(name) {
                return Err(invalid(
                    origin,
                    0,
                    format!("names[{i}]: `{name}` is named twice"),
                    "name every motor once",
                ));
            }
        }
        if self.times.len() != self.positions.len() {
            return Err(invalid(
                origin,
                0,
                format!(
                    "{} times for {} positions",
                    self.times.len(),
                    self.positions.len()
                ),
                "give one time per waypoint",
            ));
        }
        for (what, rows) in [
            ("velocities", &self.velocities),
            ("accelerations", &self.accelerations),
        ] {
            if !rows.is_empty() && rows.len() != self.times.len() {
                return Err(invalid(
                    origin,
                    0,
                    format!("{} {what} for {} times", rows.len(), self.times.len()),
                    "give one row per waypoint, or none",
                ));
            }
        }
        for (what, rows) in [
            ("positions", &self.positions),
            ("velocities", &self.velocities),
            ("accelerations", &self.accelerations),
        ] {
            for (i, row) in rows.iter().enumerate() {
                if row.len() != self.names.len() {
                    return Err(invalid(
                        origin,
                        0,
                        format!(
                            "{what}[{i}] has {} values for {} names",
                            row.len(),
                            self.names.len()
                        ),
                        "give one value per name",
                    ));
                }
                if let Some(k) = row.iter().position(|v| !v.is_finite()) {
                    return Err(invalid(
                        origin,
                        0,
                        format!("{what}[{i}][{k}] is {}", row[k]),
                        "give finite values",
                    ));
                }
            }
        }
        if !self.task_path.is_empty() {
            let dim = self.task_path[0].len();
            if self.task_path.len() != self.times.len() {
                return Err(invalid(
                    origin,
                    0,
                    format!(
                        "task_path has {} points for {} waypoints",
                        self.task_path.len(),
                        self.times.len()
                    ),
                    "give one task vector per waypoint, or none",
                ));
            }
            for (i, t) in self.task_path.iter().enumerate() {
                if t.len() != dim || t.iter().any(|v| !v.is_finite()) {
                    return Err(invalid(
                        origin,
                        0,
                        format!("task_path[{i}] = {t:?} is not {dim} finite numbers"),
                        "give task vectors of one dimension",
                    ));
                }
            }
        }
        check_times(&self.times, origin, |i| (0, format!("times[{i}]")))
    }

    /// Checks the trajectory against `robot`: every name is a motor (with suggestions), every
    /// value within its motor's limits. `origin` names the file; `line(i)` gives waypoint `i`'s
    /// line in it (0 when unknown).
    pub fn check_robot(
        &self,
        robot: &RobotModel,
        origin: &Path,
        line: impl Fn(usize) -> usize,
    ) -> Result<(), PlanError> {
        let motors: Vec<usize> = self
            .names
            .iter()
            .enumerate()
            .map(|(i, n)| {
                robot.motor_index(n).map_err(|e| {
                    invalid(
                        origin,
                        0,
                        format!("names[{i}]: {e}"),
                        "use the model's motor names (`cargo xtask model-info`)",
                    )
                })
            })
            .collect::<Result<_, _>>()?;
        for (i, row) in self.positions.iter().enumerate() {
            for (&m, &v) in motors.iter().zip(row) {
                let motor = &robot.motors()[m];
                motor.limits.check(v).map_err(|problem| {
                    invalid(
                        origin,
                        line(i),
                        format!("waypoint {i}: `{}` {problem}", motor.name),
                        "keep every motor within its limits (`cargo xtask model-info`)",
                    )
                })?;
            }
        }
        Ok(())
    }

    /// Reads a CSV trajectory of `robot` (as [`Trajectory::to_csv`] writes it); `origin` names the
    /// text in errors, with line numbers. The task path is empty.
    ///
    /// ```
    /// use trm_plan::Trajectory;
    /// let arm = trm_models::planar_arm();
    /// let csv = "time,joint1,joint2,phase\n0,0.0,0.1,0\n0.5,0.2,0.3,1\n";
    /// let t = Trajectory::from_csv(csv, "a.csv".as_ref(), &arm)?;
    /// assert_eq!((t.names.len(), t.positions[1][0]), (2, 0.2)); // `phase` is skipped
    /// let typo = "time,joint1,jiont2\n0,0,0\n";
    /// let e = Trajectory::from_csv(typo, "c.csv".as_ref(), &arm).unwrap_err().to_string();
    /// assert!(e.contains("joint2"), "{e}"); // did you mean
    /// let late = "time,joint1\n1,0\n0.5,0\n";
    /// let e = Trajectory::from_csv(late, "b.csv".as_ref(), &arm).unwrap_err().to_string();
    /// assert!(e.starts_with("b.csv:3:"), "{e}");
    /// # Ok::<(), trm_plan::PlanError>(())
    /// ```
    pub fn from_csv(text: &str, origin: &Path, robot: &RobotModel) -> Result<Self, PlanError> {
        let mut lines = text.lines();
        let header: Vec<&str> = lines
            .next()
            .ok_or_else(|| {
                invalid(
                    origin,
                    1,
                    "empty file".into(),
                    "write a header `time,<motor names…>`",
                )
            })?
            .split(',')
            .map(str::trim)
            .collect();
        let time = header
            .iter()
            .position(|h| *h == "time" || *h == "t")
            .ok_or_else(|| {
                invalid(
                    origin,
                    1,
                    "no `time` column".into(),
                    "name the time column `time`",
                )
            })?;
        let mut columns: Vec<(usize, &str)> = Vec::new();
        for (c, h) in header.iter().enumerate() {
            if c == time || WHOLE_BODY_COLUMNS.contains(h) {
                continue;
            }
            robot.motor_index(h).map_err(|e| {
                invalid(
                    origin,
                    1,
                    format!("column {} (`{h}`): {e}", c + 1),
                    "name every column after a motor (`cargo xtask model-info`), or `time`",
                )
            })?;
            columns.push((c, h));
        }
        if columns.is_empty() {
            return Err(invalid(
                origin,
                1,
                format!("no column names a motor of {}", robot.name()),
                &format!(
                    "name columns after motors, e.g. `{}`",
                    robot.motors().first().map_or("", |m| m.name.as_str())
                ),
            ));
        }
        for (i, (_, name)) in columns.iter().enumerate() {
            if columns[..i].iter().any(|(_, n)| n == name) {
                return Err(invalid(
                    origin,
                    1,
                    format!("motor `{name}` has two columns"),
                    "keep one column per motor",
                ));
            }
        }
        let mut t = Trajectory {
            names: columns.iter().map(|(_, n)| n.to_string()).collect(),
            times: Vec::new(),
            positions: Vec::new(),
            velocities: Vec::new(),
            accelerations: Vec::new(),
            task_path: Vec::new(),
        };
        let mut line_of = Vec::new();
        for (n, line) in lines.enumerate() {
            let line_no = n + 2;
            if line.trim().is_empty() {
                continue;
            }
            let fields: Vec<&str> = line.split(',').collect();
            if fields.len() != header.len() {
                return Err(invalid(
                    origin,
                    line_no,
                    format!("{} fields for {} columns", fields.len(), header.len()),
                    "give one value per column of the header",
                ));
            }
            let number = |c: usize| -> Result<f64, PlanError> {
                fields
                    .get(c)
                    .and_then(|f| f.trim().parse::<f64>().ok())
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        invalid(
                            origin,
                            line_no,
                            format!("column {} (`{}`) is not a finite number", c + 1, header[c]),
                            "write finite numbers",
                        )
                    })
            };
            line_of.push(line_no);
            t.times.push(number(time)?);
            t.positions.push(
                columns
                    .iter()
                    .map(|&(c, _)| number(c))
                    .collect::<Result<_, _>>()?,
            );
        }
        if t.times.is_empty() {
            return Err(invalid(
                origin,
                2,
                "the header is followed by no rows".into(),
                "add one row per waypoint: the time, then a value per motor column",
            ));
        }
        check_times(&t.times, origin, |i| (line_of[i], "time".into()))?;
        t.check_robot(robot, origin, |i| line_of[i])?;
        Ok(t)
    }

    /// Reads a trajectory file of `robot`: JSON when the extension is `.json`, else CSV.
    pub fn load(path: impl AsRef<Path>, robot: &RobotModel) -> Result<Self, PlanError> {
        let path = path.as_ref();
        let text = trm_io::read_input(path).map_err(|source| PlanError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            let t = Self::from_json(&text, path)?;
            t.check_robot(robot, path, |_| 0)?;
            Ok(t)
        } else {
            Self::from_csv(&text, path, robot)
        }
    }

    /// Full motor vectors of `robot` at every waypoint: `start` (one value per motor) with the
    /// trajectory's named motors set. Unknown names get suggestions.
    pub fn motor_frames(
        &self,
        robot: &RobotModel,
        start: &[f64],
    ) -> Result<Vec<(f64, Vec<f64>)>, PlanError> {
        let columns: Vec<usize> = self
            .names
            .iter()
            .map(|n| robot.motor_index(n))
            .collect::<Result<_, _>>()?;
        Ok(self
            .times
            .iter()
            .zip(&self.positions)
            .map(|(time, q)| {
                let mut motors = start.to_vec();
                for (&c, v) in columns.iter().zip(q) {
                    motors[c] = *v;
                }
                (*time, motors)
            })
            .collect())
    }
}

impl Trajectory {
    /// The trajectory as a ROS 2 `trajectory_msgs/msg/JointTrajectory` in YAML for a controller
    /// of `robot` ([`trm_kinematics::ros::joint_trajectory_yaml`]): the URDF joints a
    /// controller commands, through the couplings, with the trajectory's velocities and
    /// accelerations (zero velocity and no accelerations where it has none: a motion that stops
    /// at each waypoint). Motors the trajectory does not name keep their neutral values.
    /// Refuses what the readers refuse; `path` names the file it is for.
    pub fn to_ros_yaml(&self, robot: &RobotModel, path: &Path) -> Result<String, PlanError> {
        self.check(path)?;
        self.check_robot(robot, path, |_| 0)?;
        let frames = self.motor_frames(robot, &robot.neutral_motors())?;
        let motors: Vec<Vec<f64>> = frames.into_iter().map(|(_, q)| q).collect();
        let zero = vec![0.0; robot.motors().len()];
        let full = |rows: &[Vec<f64>]| -> Result<Option<Vec<Vec<f64>>>, PlanError> {
            if rows.is_empty() {
                return Ok(None);
            }
            let as_positions = Trajectory {
                positions: rows.to_vec(),
                velocities: Vec::new(),
                accelerations: Vec::new(),
                ..self.clone()
            };
            let frames = as_positions.motor_frames(robot, &zero)?;
            Ok(Some(frames.into_iter().map(|(_, q)| q).collect()))
        };
        let (velocities, accelerations) = (full(&self.velocities)?, full(&self.accelerations)?);
        trm_kinematics::ros::joint_trajectory_yaml(
            robot,
            &self.times,
            &motors,
            velocities.as_deref(),
            accelerations.as_deref(),
        )
        .map_err(|e| invalid(path, 0, e.to_string(), "write a trajectory of this robot"))
    }
}

fn invalid(origin: &Path, line: usize, problem: String, fix: &str) -> PlanError {
    PlanError::InvalidTrajectory {
        path: origin.to_path_buf(),
        line,
        problem,
        fix: fix.to_string(),
    }
}

fn check_times(
    times: &[f64],
    origin: &Path,
    at: impl Fn(usize) -> (usize, String),
) -> Result<(), PlanError> {
    for (i, &t) in times.iter().enumerate() {
        let problem = if !t.is_finite() || t < 0.0 {
            format!("is {t}")
        } else if i > 0 && t < times[i - 1] {
            format!("= {t} comes before the previous {}", times[i - 1])
        } else {
            continue;
        };
        let (line, field) = at(i);
        return Err(invalid(
            origin,
            line,
            format!("{field} {problem}"),
            "give finite times from 0 up that never decrease",
        ));
    }
    Ok(())
}

/// Waypoint times for a path through `waypoints` (active values) that stops at every waypoint:
/// each segment takes the longest time any joint needs to cover its change at velocity
/// `velocity[i]` (and, when given, with a trapezoidal profile at acceleration `acceleration[i]`).
pub fn time_parametrise(
    waypoints: &[Vec<f64>],
    velocity: &[f64],
    acceleration: Option<&[f64]>,
) -> Vec<f64> {
    let mut times = Vec::with_capacity(waypoints.len());
    let mut t = 0.0;
    times.push(0.0);
    for w in waypoints.windows(2) {
        let mut duration: f64 = 0.0;
        for i in 0..w[0].len() {
            let d = (w[1][i] - w[0][i]).abs();
            let v = velocity[i];
            let need = match acceleration {
                None => d / v,
                Some(a) => {
                    let a = a[i];
                    if d >= v * v / a {
                        d / v + v / a
                    } else {
                        2.0 * (d / a).sqrt()
                    }
                }
            };
            duration = duration.max(need);
        }
        t += duration;
        times.push(t);
    }
    times
}
