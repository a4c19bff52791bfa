//! A problem set: a folder of families of MoveIt scenes and requests, or a `.tar.bz2` of one
//! (as VAMP ships them), unpacked into a temporary folder.

use std::path::{Path, PathBuf};

use crate::error::MbmError;

/// One problem of a set.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct Problem {
    /// Family (the folder's name).
    pub family: String,
    /// Number (from the file names).
    pub index: u32,
    /// The scene file.
    pub scene: PathBuf,
    /// The request file.
    pub request: PathBuf,
}

/// A problem set opened from a folder or a `.tar.bz2`/`.tar` of one (unpacked into a fresh
/// temporary folder, at most [`trm_io::MAX_INPUT_BYTES`] in all, removed when the set
/// is dropped; `tar` refuses entries that would land outside it).
pub struct ProblemSet {
    /// The problems, sorted by family and number.
    pub problems: Vec<Problem>,
    unpacked: Option<PathBuf>,
    root: PathBuf,
}

impl Drop for ProblemSet {
    fn drop(&mut self) {
        if let Some(dir) = &self.unpacked {
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

impl ProblemSet {
    /// Opens `path`: a folder of family folders (or holding one folder of them, as VAMP's
    /// archives do), or an archive of one.
    pub fn open(path: &Path) -> Result<Self, MbmError> {
        let unpacked = if path.is_file() {
            Some(unpack(path)?)
        } else {
            None
        };
        let mut set = ProblemSet {
            problems: Vec::new(),
            root: PathBuf::new(),
            unpacked,
        };
        set.root = set_root(set.unpacked.as_deref().unwrap_or(path));
        set.problems = find_problems(&set.root)?;
        Ok(set)
    }

    /// The folder holding the family folders (inside the unpacked archive, for an archive).
    pub fn root(&self) -> &Path {
        &self.root
    }
}

fn unpack(archive: &Path) -> Result<PathBuf, MbmError> {
    let bad = |problem: String| MbmError::Invalid {
        path: archive.to_path_buf(),
        line: 0,
        problem,
        fix: "give a MotionBenchMaker set: a folder, or a .tar.bz2 of one as VAMP ships them"
            .into(),
    };
    let dir = std::env::temp_dir().join(format!(
        "trm-mbm-{}-{}",
        std::process::id(),
        UNPACKED.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
    ));
    let io = |path: &Path, source| MbmError::Io {
        path: path.to_path_buf(),
        source,
    };
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).map_err(|e| io(&dir, e))?;
    let result = (|| {
        let file = std::fs::File::open(archive).map_err(|e| io(archive, e))?;
        let name = archive.to_string_lossy();
        let reader: Box<dyn std::io::Read> = if name.ends_with(".bz2") || name.ends_with(".tbz2") {
            Box::new(bzip2::read::BzDecoder::new(file))
        } else {
            Box::new(file)
        };
        let mut tar = tar::Archive::new(reader);
        let mut total = 0u64;
        for entry in tar
            .entries()
            .map_err(|e| bad(format!("not a tar archive ({e})")))?
        {
            let mut entry = entry.map_err(|e| bad(format!("a damaged archive entry ({e})")))?;
            total += entry.size();
            if total > trm_io::MAX_INPUT_BYTES {
                return Err(bad(format!(
                    "unpacks to more than {} bytes",
                    trm_io::MAX_INPUT_BYTES
                )));
            }
            entry
                .unpack_in(&dir)
                .map_err(|e| bad(format!("an entry could not be unpacked ({e})")))?;
        }
        Ok(())
    })();
    match result {
        Ok(()) => Ok(dir),
        Err(e) => {
            let _ = std::fs::remove_dir_all(&dir);
            Err(e)
        }
    }
}

static UNPACKED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// `dir`, or its one subfolder when it holds nothing else and no scene.
fn set_root(dir: &Path) -> PathBuf {
    let entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    match entries.as_slice() {
        [only] if only.is_dir() && !only.join("scene0001.yaml").exists() => only.clone(),
        _ => dir.to_path_buf(),
    }
}

/// The problems under `dir` (its folders' `sceneNNNN.yaml` with their `requestNNNN.yaml`),
/// sorted by family and number. A scene without its request is an error naming it.
pub fn find_problems(dir: &Path) -> Result<Vec<Problem>, MbmError> {
    let io = |path: &Path, source| MbmError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut problems = Vec::new();
    let mut folders: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    folders.sort();
    for folder in folders {
        let family = folder
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        for entry in std::fs::read_dir(&folder).map_err(|e| io(&folder, e))? {
            let path = entry.map_err(|e| io(&folder, e))?.path();
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().to_string())
                .unwrap_or_default();
            let Some(number) = name
                .strip_prefix("scene")
                .and_then(|n| n.strip_suffix(".yaml"))
            else {
                continue;
            };
            let Ok(index) = number.parse::<u32>() else {
                continue;
            };
            let request = folder.join(format!("request{number}.yaml"));
            if !request.is_file() {
                return Err(MbmError::Invalid {
                    path: path.clone(),
                    line: 0,
                    problem: format!("no {} beside it", request.display()),
                    fix: "give every scene its request (MotionBenchMaker writes them in pairs)"
                        .into(),
                });
            }
            problems.push(Problem {
                family: family.clone(),
                index,
                scene: path,
                request,
            });
        }
    }
    problems.sort();
    if problems.is_empty() {
        return Err(MbmError::Invalid {
            path: dir.to_path_buf(),
            line: 0,
            problem: "no sceneNNNN.yaml in any folder".into(),
            fix: "give the folder that holds one folder per problem family (MotionBenchMaker's layout)".into(),
        });
    }
    Ok(problems)
}

impl ProblemSet {
    /// Keeps the problems of `families` (all when empty; a family the set lacks is an error
    /// naming those it has) and at most `per_family` of each, in order.
    pub fn select(
        &mut self,
        families: &[String],
        per_family: Option<usize>,
    ) -> Result<(), MbmError> {
        for f in families {
            if !self.problems.iter().any(|p| &p.family == f) {
                let known: std::collections::BTreeSet<&str> =
                    self.problems.iter().map(|p| p.family.as_str()).collect();
                return Err(MbmError::InvalidOptions {
                    what: format!("family `{f}`"),
                    problem: format!(
                        "is not in this set\n  fix: give some of {}",
                        known.into_iter().collect::<Vec<_>>().join(", ")
                    ),
                });
            }
        }
        if !families.is_empty() {
            self.problems.retain(|p| families.contains(&p.family));
        }
        if let Some(n) = per_family {
            let mut count = std::collections::BTreeMap::<String, usize>::new();
            self.problems.retain(|p| {
                let c = count.entry(p.family.clone()).or_default();
                *c += 1;
                *c <= n
            });
        }
        Ok(())
    }
}

/// RRT-Connect's settings for a set: the robot's
/// ([`RrtOptions::for_robot`](trm_plan::rrt::RrtOptions::for_robot): its description's, else
/// sized by its lever arms) for the motors the set's first request plans for (the defaults
/// for an empty set).
pub fn rrt_options_for(
    robot: &trm_kinematics::RobotModel,
    collision: &trm_collision::CollisionModel,
    problems: &[Problem],
) -> Result<trm_plan::rrt::RrtOptions, MbmError> {
    let Some(first) = problems.first() else {
        return Ok(trm_plan::rrt::RrtOptions::default());
    };
    let request = trm_moveit::MotionPlanRequest::load(&first.request)?;
    let active = request.active_set(robot, &robot.neutral_motors())?;
    Ok(trm_plan::rrt::RrtOptions::for_robot(collision, &active)?)
}
