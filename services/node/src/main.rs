//! `tandem-node`: thin main over [`tandem_node::run`].
//!
//! Exit codes: 0 stopped cleanly (signal or end of duration); 2 the cell, node or script is
//! wrong; 1 the node could not run (iceoryx2 resources, threads); 3 its EtherCAT segment cannot
//! be opened, does not reach OP or does not match the cell file. Diagnostics go to stderr
//! through `tracing` (`--log-format text|json`, filtered by `TANDEM_LOG` or `RUST_LOG`,
//! default `info`).

use clap::{Arg, Command};
use std::path::PathBuf;
use std::process::ExitCode;
use tandem_rt::diag::{self, LogFormat};

fn main() -> ExitCode {
    let m = Command::new("tandem-node")
        .about("One node of a tandem cell: its technology objects on the real clock, leading values over iceoryx2")
        .arg(Arg::new("cell").required(true).value_parser(clap::value_parser!(PathBuf)))
        .arg(Arg::new("node").long("node").required(true).help("The node's name in the cell"))
        .arg(
            Arg::new("epoch-ns")
                .long("epoch-ns")
                .value_parser(clap::value_parser!(i64))
                .help("Cell clock time of cycle 0 (ns, CLOCK_REALTIME); default: the next whole second"),
        )
        .arg(Arg::new("script").long("script").value_parser(clap::value_parser!(PathBuf)))
        .arg(
            Arg::new("duration")
                .long("duration")
                .value_parser(clap::value_parser!(f64))
                .help("Stop after this many seconds of engine time (default: the script's duration)"),
        )
        .arg(Arg::new("trace").long("trace").value_parser(clap::value_parser!(PathBuf)))
        .arg(Arg::new("log").long("log").value_parser(clap::value_parser!(PathBuf)))
        .arg(
            Arg::new("log-format")
                .long("log-format")
                .value_parser(["text", "json"])
                .default_value("text")
                .help("Diagnostics on stderr: text lines or one JSON object per line (filter: TANDEM_LOG or RUST_LOG)"),
        )
        .get_matches();
    let format = m
        .get_one::<String>("log-format")
        .and_then(|f| LogFormat::parse(f))
        .unwrap_or_default();
    diag::init("info", format);
    let o = tandem_node::Options {
        cell: m.get_one::<PathBuf>("cell").cloned().unwrap_or_default(),
        node: m.get_one::<String>("node").cloned().unwrap_or_default(),
        epoch_ns: m.get_one::<i64>("epoch-ns").copied(),
        script: m.get_one::<PathBuf>("script").cloned(),
        duration_s: m.get_one::<f64>("duration").copied(),
        trace: m.get_one::<PathBuf>("trace").cloned(),
        log: m.get_one::<PathBuf>("log").cloned(),
    };
    match tandem_node::run(&o) {
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            let code = e.exit_code();
            tracing::error!(node = %o.node, exit_code = code, "{e}");
            ExitCode::from(code)
        }
    }
}
