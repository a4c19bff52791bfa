//! Reading one YAML file's fields with errors that name the file and the line.

use std::fmt::Write as _;
use std::path::Path;

use trm_kinematics::nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

use crate::error::MoveItError;
use crate::yaml::{self, Node};

/// Reads fields of one file, naming the file and line in errors.
pub(crate) struct Reader<'a> {
    pub(crate) origin: &'a Path,
}

impl Reader<'_> {
    pub(crate) fn err(
        &self,
        line: usize,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> MoveItError {
        MoveItError::Invalid {
            path: self.origin.to_path_buf(),
            line,
            problem: problem.into(),
            fix: fix.into(),
        }
    }

    pub(crate) fn parse(&self, text: &str) -> Result<Node, MoveItError> {
        let doc = yaml::parse(text).map_err(|p| {
            self.err(
                p.line,
                format!("not readable YAML: {}", p.problem),
                "write the message as ROS's YAML layout does",
            )
        })?;
        if !matches!(doc.value, yaml::Value::Map(_)) {
            return Err(self.err(
                doc.line,
                format!("the document is {}", doc.kind()),
                "give a mapping of the message's fields",
            ));
        }
        Ok(doc)
    }

    pub(crate) fn field<'n>(
        &self,
        node: &'n Node,
        key: &str,
        what: &str,
    ) -> Result<&'n Node, MoveItError> {
        node.get(key).ok_or_else(|| {
            self.err(
                node.line,
                format!("{what} has no `{key}`"),
                format!("give `{key}`"),
            )
        })
    }

    pub(crate) fn seq<'n>(&self, node: &'n Node, what: &str) -> Result<&'n [Node], MoveItError> {
        node.items().ok_or_else(|| {
            self.err(
                node.line,
                format!("{what} is {}, not a list", node.kind()),
                format!("give {what} as a list"),
            )
        })
    }

    pub(crate) fn text(&self, node: &Node, what: &str) -> Result<String, MoveItError> {
        node.scalar().map(str::to_string).ok_or_else(|| {
            self.err(
                node.line,
                format!("{what} is {}", node.kind()),
                format!("give {what} as a string"),
            )
        })
    }

    pub(crate) fn number(&self, node: &Node, what: &str) -> Result<f64, MoveItError> {
        node.scalar()
            .and_then(|s| s.trim().parse::<f64>().ok())
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                self.err(
                    node.line,
                    format!(
                        "{what} is `{}`, not a finite number",
                        node.scalar().unwrap_or(node.kind())
                    ),
                    "give a finite number",
                )
            })
    }

    /// The scaling factor `key` of `node`: absent or 0 is `None` (the full limits), else a
    /// number in (0, 1].
    pub(crate) fn factor(&self, node: &Node, key: &str) -> Result<Option<f64>, MoveItError> {
        let Some(f) = node.get(key) else {
            return Ok(None);
        };
        let v = self.number(f, key)?;
        if !(0.0..=1.0).contains(&v) {
            return Err(self.err(
                f.line,
                format!("{key} is {v}"),
                "give a factor in (0, 1] (0: the full limits)",
            ));
        }
        Ok((v > 0.0).then_some(v))
    }

    pub(crate) fn numbers(&self, node: &Node, what: &str) -> Result<Vec<f64>, MoveItError> {
        self.seq(node, what)?
            .iter()
            .enumerate()
            .map(|(i, n)| self.number(n, &format!("{what}[{i}]")))
            .collect()
    }

    /// `[x, y, z]` or `{x:, y:, z:}` (and `w` for quaternions).
    pub(crate) fn vector(
        &self,
        node: &Node,
        what: &str,
        keys: &[&str],
    ) -> Result<Vec<f64>, MoveItError> {
        let values = if node.items().is_some() {
            self.numbers(node, what)?
        } else {
            keys.iter()
                .map(|k| self.number(self.field(node, k, what)?, &format!("{what}.{k}")))
                .collect::<Result<_, _>>()?
        };
        if values.len() != keys.len() {
            return Err(self.err(
                node.line,
                format!("{what} has {} values", values.len()),
                format!("give {} values ({})", keys.len(), keys.join(", ")),
            ));
        }
        Ok(values)
    }

    pub(crate) fn pose(&self, node: &Node, what: &str) -> Result<Isometry3<f64>, MoveItError> {
        let p = match node.get("position") {
            Some(p) => self.vector(p, &format!("{what}.position"), &["x", "y", "z"])?,
            None => vec![0.0; 3],
        };
        let rotation = match node.get("orientation") {
            Some(o) => self.quaternion(o, &format!("{what}.orientation"))?,
            None => UnitQuaternion::identity(),
        };
        Ok(Isometry3::from_parts(
            Translation3::new(p[0], p[1], p[2]),
            rotation,
        ))
    }

    /// A `geometry_msgs/Quaternion` (x, y, z, w), of norm 1 within 10 %.
    pub(crate) fn quaternion(
        &self,
        node: &Node,
        what: &str,
    ) -> Result<UnitQuaternion<f64>, MoveItError> {
        let q = self.vector(node, what, &["x", "y", "z", "w"])?;
        let quaternion = Quaternion::new(q[3], q[0], q[1], q[2]);
        let norm = quaternion.norm();
        if !(0.9..=1.1).contains(&norm) {
            return Err(self.err(
                node.line,
                format!("{what} has norm {norm:.4}"),
                "give a unit quaternion [x, y, z, w]",
            ));
        }
        Ok(UnitQuaternion::new_normalize(quaternion))
    }
}

/// A file's text, as every trm reader reads input (regular files, size-limited).
pub(crate) fn read(path: &Path) -> Result<String, MoveItError> {
    trm_io::read_input(path).map_err(|source| MoveItError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// A YAML double-quoted string.
pub(crate) fn quote(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}
