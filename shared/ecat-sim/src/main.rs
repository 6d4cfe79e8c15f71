//! `tandem-ecat-sim`: a virtual EtherCAT segment on a network interface (see
//! `tandem_ecat_sim::net`).

use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match tandem_ecat_sim::net::run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tandem-ecat-sim: {e}");
            ExitCode::FAILURE
        }
    }
}
