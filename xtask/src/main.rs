//! `cargo xtask <command>`: the repository's tooling (regenerating the iCub model) and thin
//! drivers of the paper studies (`trm-studies`, in studies/). Every other command is the `trm` tool's:
//! `cargo xtask build-map specs/reach.ron` runs `trm build-map specs/reach.ron`.

mod gen_icub;

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use clap::{Parser, Subcommand};
use trm_studies::{map_scaling, speedup, task_map_studies};

#[derive(Parser)]
#[command(
    name = "cargo xtask",
    bin_name = "cargo xtask",
    about = "trm's repository tooling; any other command is the trm tool's (listed below)",
    version
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Regenerate models/icub_upper_body.{urdf,ron} from the official iCub files in models/.
    GenIcub,
    /// Fig. 2 of the parallel paper: map-building time per thread count, and P's effect.
    Speedup(speedup::Args),
    /// How building, memory, kd-tree queries and map files scale with the map's size (to 10 000 points).
    MapScaling(map_scaling::Args),
    /// The task-map studies: a stick with an exact target vs its map; a basket handle at three places.
    TaskMapStudies(task_map_studies::Args),
    /// Any other command is the trm tool's (`trm --help`).
    #[command(external_subcommand)]
    Trm(Vec<OsString>),
}

fn main() {
    trm::quiet_on_closed_pipes();
    use clap::CommandFactory;
    let help = format!(
        "Commands of the trm tool (`cargo xtask COMMAND` runs `trm COMMAND`):\n{}",
        trm::command_list()
    );
    let cli: Cli = trm::parse_with(Cli::command().after_help(help), std::env::args_os());
    let result = match cli.command {
        Command::GenIcub => trm::run_staged(&[], &[models_dir()], || gen_icub::run(&models_dir())),
        Command::Speedup(a) => {
            trm::run_staged(&[], std::slice::from_ref(&a.out_dir), || speedup::run(&a))
        }
        Command::MapScaling(a) => trm::run_staged(&[], std::slice::from_ref(&a.out_dir), || {
            map_scaling::run(&a)
        }),
        Command::TaskMapStudies(a) => {
            trm::run_staged(&[], std::slice::from_ref(&a.out_dir), || {
                task_map_studies::run(&a)
            })
        }
        Command::Trm(rest) => trm::main_from(std::iter::once(OsString::from("trm")).chain(rest)),
    };
    trm::exit_with(result)
}

/// The repository's models/ directory.
fn models_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    dir.canonicalize().unwrap_or(dir)
}
