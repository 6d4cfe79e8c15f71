//! `tandem-gateway`: thin main over [`tandem_gateway::run`].
//!
//! Exit codes ([`tandem_gateway::GatewayError::exit_code`]): 0 stopped cleanly; 2 the cell or
//! host is wrong; 1 it could not run. Diagnostics go to stderr through `tracing`, as text or
//! JSON (`--log-format`), filtered by `TANDEM_LOG` or `RUST_LOG` (default: the gateway's own
//! events at `info`, Zenoh's silent).

use clap::{Arg, Command};
use std::path::PathBuf;
use std::process::ExitCode;
use tandem_rt::diag::{self, LogFormat};

/// The filter when neither `TANDEM_LOG` nor `RUST_LOG` is set.
const DEFAULT_LOG: &str = "info,zenoh=off";

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
        .arg(
            Arg::new("log-format")
                .long("log-format")
                .value_parser(["text", "json"])
                .default_value("text")
                .help("Diagnostics on stderr as text lines or one JSON object per line (filter: TANDEM_LOG or RUST_LOG)"),
        )
        .get_matches();
    let format = m
        .get_one::<String>("log-format")
        .and_then(|f| LogFormat::parse(f))
        .unwrap_or_default();
    // A second subscriber cannot exist in this process: the result only says whether it was set.
    let _ = diag::init(DEFAULT_LOG, format);
    let o = tandem_gateway::Options {
        cell: m.get_one::<PathBuf>("cell").cloned().unwrap_or_default(),
        host: m.get_one::<String>("host").cloned(),
        duration_s: m.get_one::<f64>("duration").copied(),
    };
    match tandem_gateway::run(&o) {
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!(exit_code = e.exit_code(), "{e}");
            ExitCode::from(e.exit_code())
        }
    }
}
