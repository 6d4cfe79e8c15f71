//! `tandem-gateway`: thin main over [`tandem_gateway::run`].
//!
//! Exit codes: 0 stopped cleanly; 2 the cell or host is wrong; 1 it could not run.

use clap::{Arg, Command};
use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let m = Command::new("tandem-gateway")
        .about("The gateway of one host of a tandem cell: leading values between iceoryx2 and Zenoh, commands in, telemetry out")
        .arg(Arg::new("cell").required(true).value_parser(clap::value_parser!(PathBuf)))
        .arg(Arg::new("host").long("host").help("This host's name in the cell (default: its only host)"))
        .arg(
            Arg::new("duration")
                .long("duration")
                .value_parser(clap::value_parser!(f64))
                .help("Stop after this many seconds (default: SIGINT/SIGTERM)"),
        )
        .get_matches();
    let o = tandem_gateway::Options {
        cell: m.get_one::<PathBuf>("cell").cloned().unwrap_or_default(),
        host: m.get_one::<String>("host").cloned(),
        duration_s: m.get_one::<f64>("duration").copied(),
    };
    match tandem_gateway::run(&o) {
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tandem-gateway: error: {e}");
            ExitCode::from(tandem_node::exit_code(&e))
        }
    }
}
