//! The `trm` command-line tool: `trm --help` lists the commands.

fn main() {
    trm::quiet_on_closed_pipes();
    trm::main_from(std::env::args_os())
}
