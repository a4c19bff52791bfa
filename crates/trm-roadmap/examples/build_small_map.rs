//! A small task-relevant roadmap of the iCub's right palm (60 points, parallel E-TRM), its
//! edges, a summary, and the map file written and read back.
//!
//! `cargo run -p trm-roadmap --example build_small_map [-- OUT.map.json]`

use trm_roadmap::{BuildOptions, Roadmap, RoadmapError};

const SPEC: &str = r#"(
    model: "icub_upper_body",
    active: ["torso", "right_arm"],
    costs: [(weight: 0.1, cost: HomePosture()), (weight: 1.0, cost: Collision())],
    task: Some(Position(part: "r_palm_center")),
    solver: (seed: 0),
    map: Some((spacing: 0.04, construct_weight: 10.0, smoothness: 0.01, failure_limit: 20,
        max_points: 60, first_search: (60, 0.15), later_search: (20, 0.03), searches: 2,
        edge_neighbours: 6)),
)"#;

fn main() -> Result<(), RoadmapError> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "target/small.map.json".into());
    let problem = trm_tasks::Problem::from_ron(SPEC, "<example>", std::path::Path::new("."))?;
    // built, then connected (the spec's 6 neighbours, edges checked every 0.05 rad)
    let map = trm_roadmap::Builder::new(&problem, &BuildOptions::default())
        .connected()
        .run(|p| eprint!("\r{} / {} points", p.points, p.target))?;
    eprintln!();
    map.save(&out)?;
    let back = Roadmap::load(&out)?;
    let s = back.summary();
    println!(
        "{out}: {} points, {} edges, {} components, spacing mean {:.3} m, coverage {:?}",
        s.points,
        s.edges,
        s.components,
        s.spacing.map_or(0.0, |x| x.0),
        s.coverage
    );
    Ok(())
}
