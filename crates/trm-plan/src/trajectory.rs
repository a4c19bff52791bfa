//! Time parametrisation of a piecewise-linear joint path, and trajectory files.
//!
//! Two formats, one [`Trajectory`]:
//! * **CSV** ([`Trajectory::to_csv`], [`Trajectory::from_csv`]): a header `time,<motor names…>`
//!   then one row per waypoint (seconds, then motor values). The reader also takes a `t` column
//!   for the time and ignores columns that name no motor of the robot (so the whole-body CSV of
//!   `cargo xtask stand-up`, with its phase, CoM and ZMP columns, reads too); times must not
//!   decrease and every value must be a finite number.
//! * **JSON** ([`Trajectory::to_json`], [`Trajectory::from_json`]): the struct's fields, with the
//!   task-space path.

use std::path::Path;

use serde::{Deserialize, Serialize};
use trm_kinematics::RobotModel;

use crate::PlanError;

/// A timed joint trajectory (full motor vectors) with its task-space path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trajectory {
    /// Motor names, the columns of `positions`.
    pub names: Vec<String>,
    /// Time of each waypoint, seconds, from 0.
    pub times: Vec<f64>,
    /// Motor values at each waypoint.
    pub positions: Vec<Vec<f64>>,
    /// Task vector at each waypoint.
    pub task_path: Vec<Vec<f64>>,
}

impl Trajectory {
    /// CSV: `time,<names…>` then one row per waypoint.
    pub fn to_csv(&self) -> String {
        let mut out = format!("time,{}\n", self.names.join(","));
        for (t, q) in self.times.iter().zip(&self.positions) {
            let row: Vec<String> = q.iter().map(|v| format!("{v}")).collect();
            out.push_str(&format!("{t},{}\n", row.join(",")));
        }
        out
    }

    /// The trajectory as JSON (names, times, positions, task path).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a trajectory of numbers and names serialises")
    }

    /// Reads [`Trajectory::to_json`]'s output; `origin` names the text in errors. Checks that
    /// every row has one value per name and that times do not decrease.
    pub fn from_json(text: &str, origin: &Path) -> Result<Self, PlanError> {
        let t: Trajectory = serde_json::from_str(text).map_err(|e| {
            invalid(
                origin,
                e.line(),
                e.to_string(),
                "give a trajectory written by trm (`plan --out x.json`)",
            )
        })?;
        if t.times.len() != t.positions.len() {
            return Err(invalid(
                origin,
                0,
                format!(
                    "{} times for {} positions",
                    t.times.len(),
                    t.positions.len()
                ),
                "give one time per waypoint",
            ));
        }
        for (i, row) in t.positions.iter().enumerate() {
            if row.len() != t.names.len() {
                return Err(invalid(
                    origin,
                    0,
                    format!(
                        "positions[{i}] has {} values for {} names",
                        row.len(),
                        t.names.len()
                    ),
                    "give one value per name",
                ));
            }
        }
        check_times(&t.times, origin, |i| (0, format!("times[{i}]")))?;
        Ok(t)
    }

    /// Reads a CSV trajectory of `robot` (format in the [module docs](self)); `origin` names the
    /// text in errors, with line numbers. The task path is empty.
    ///
    /// ```
    /// use trm_plan::Trajectory;
    /// let arm = trm_models::planar_arm();
    /// let csv = "time,joint1,joint2,note\n0,0.0,0.1,start\n0.5,0.2,0.3,end\n";
    /// let t = Trajectory::from_csv(csv, "a.csv".as_ref(), &arm)?;
    /// assert_eq!((t.names.len(), t.positions[1][0]), (2, 0.2)); // `note` names no motor
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
        let columns: Vec<(usize, &str)> = header
            .iter()
            .enumerate()
            .filter(|(_, h)| robot.motor_index(h).is_ok())
            .map(|(c, h)| (c, *h))
            .collect();
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
            task_path: Vec::new(),
        };
        for (n, line) in lines.enumerate() {
            let line_no = n + 2;
            if line.trim().is_empty() {
                continue;
            }
            let fields: Vec<&str> = line.split(',').collect();
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
            t.times.push(number(time)?);
            t.positions.push(
                columns
                    .iter()
                    .map(|&(c, _)| number(c))
                    .collect::<Result<_, _>>()?,
            );
        }
        check_times(&t.times, origin, |i| (i + 2, "time".into()))?;
        Ok(t)
    }

    /// Reads a trajectory file of `robot`: JSON when the extension is `.json`, else CSV.
    pub fn load(path: impl AsRef<Path>, robot: &RobotModel) -> Result<Self, PlanError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| PlanError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            Self::from_json(&text, path)
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
    for i in 1..times.len() {
        if times[i] < times[i - 1] || !times[i].is_finite() {
            let (line, field) = at(i);
            return Err(invalid(
                origin,
                line,
                format!(
                    "{field} = {} comes before the previous {}",
                    times[i],
                    times[i - 1]
                ),
                "times must not decrease",
            ));
        }
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
