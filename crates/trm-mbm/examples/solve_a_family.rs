//! MotionBenchMaker problems solved the way the benchmark solves them: the set read (a folder,
//! or a `.tar.bz2` as VAMP ships them), each problem prepared once, solved by RRT-Connect,
//! every path re-checked one configuration at a time, then the set run again with the
//! experience kept; the field's per-family table for both.
//!
//! ```sh
//! cargo run --release -p trm-mbm --example solve_a_family
//! ```

use std::path::Path;

use trm_mbm::{Benchmark, BenchmarkOptions, ProblemSet, benchmark};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    // the Panda of VAMP's spheres, and a few of MotionBenchMaker's box problems
    let robot =
        trm_kinematics::RobotModel::load(here.join("../../models/panda-mbm/panda_spherized.ron"))?;
    let collision = trm_collision::CollisionModel::new(&robot)?;
    let set = ProblemSet::open(&here.join("tests/fixtures/mbm"))?;
    let options = BenchmarkOptions {
        verify: true,
        experience_passes: 1,
        ..Default::default()
    };
    let Benchmark {
        runs, experience, ..
    } = benchmark(
        &robot,
        &collision,
        &set.problems,
        &options,
        |stage, done, total, p| eprintln!("{stage}: {done}/{total} ({} {})", p.family, p.index),
    )?;
    println!(
        "{}",
        trm_mbm::markdown_table(runs.iter().map(|r| (r.family.as_str(), &r.outcome)))
    );
    println!(
        "with experience:\n{}",
        trm_mbm::markdown_table(
            experience[0]
                .iter()
                .map(|r| (r.family.as_str(), &r.outcome))
        )
    );
    // every solved path proved free in continuous motion
    assert!(
        runs.iter()
            .all(|r| r.verified.is_none_or(|v| v == trm_mbm::Verdict::Proved))
    );
    Ok(())
}
