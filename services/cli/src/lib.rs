//! The `tandem` command line: `up` starts and supervises a host's nodes, `status`, `watch` and
//! `cmd` work on a running cell, `sim` runs a cell on virtual time, `check` validates a cell
//! file.
//!
//! Exit codes ([`CliError::exit_code`]): 0 success; 1 the command failed (`cmd`: rejected with
//! an ErrorID, or the job ended in error or was aborted; `sim --strict`: a command was rejected
//! or an alarm is pending); 2 the input is wrong (usage, config, script or command error); 3 the
//! cell is not reachable (a node not running, a timeout) or an IO error of `sim`; 4 an iceoryx2
//! error.
//!
//! What a command prints for its user (tables, the live view, `cmd`'s outcome, `sim`'s log and
//! summary, `error: ...`) goes to the writers given to [`run`]. Diagnostics (what `up`'s
//! supervision does: a node started, crashed with its reason, restarted) go through `tracing`
//! to stderr, as text or JSON (`--log-format`), filtered by `TANDEM_LOG` or `RUST_LOG`.
//!
//! ```no_run
//! // `tandem check config/line.toml`, its output captured.
//! let args = ["tandem", "check", "config/line.toml"].map(std::ffi::OsString::from);
//! let (mut out, mut err) = (Vec::new(), Vec::new());
//! let code = tandem_cli::run(args.to_vec(), &mut out, &mut err);
//! assert_eq!(code, std::process::ExitCode::SUCCESS, "{}", String::from_utf8_lossy(&err));
//! ```

/// Writes one line of user output. A failed write (stdout closed: `tandem status | head`) is
/// dropped: it must not turn into another error or hide the command's exit code.
macro_rules! outln {
    ($out:expr) => {
        $crate::output::write($out, format_args!("\n"))
    };
    ($out:expr, $($arg:tt)*) => {
        $crate::output::write($out, format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// Writes user output without a newline (see [`outln`]).
macro_rules! out {
    ($out:expr, $($arg:tt)*) => {
        $crate::output::write($out, format_args!($($arg)*))
    };
}

pub mod certs;
pub mod cmd;
pub mod error;
pub mod ethercat;
pub mod live;
pub mod offline;
mod output;
pub mod remote;
pub mod up;

pub use error::CliError;

use clap::{Arg, ArgAction, Command};
use std::ffi::OsString;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use tandem_rt::diag::{self, LogFormat};

/// The diagnostics filter of `up` when neither `TANDEM_LOG` nor `RUST_LOG` is set: its
/// supervision events at `info`; Zenoh's own logging off.
const UP_LOG: &str = "info,zenoh=off";
/// The diagnostics filter of the other commands: warnings and errors only, so their output is
/// what they print.
const QUIET_LOG: &str = "warn,zenoh=off";

fn cli() -> Command {
    Command::new("tandem")
        .about("tandem: a motion controller for machines that span several controllers")
        .subcommand_required(true)
        .arg_required_else_help(true)
        .arg(
            Arg::new("log-format")
                .long("log-format")
                .global(true)
                .value_parser(["text", "json"])
                .help("Diagnostics on stderr as text lines or one JSON object per line (filter: TANDEM_LOG or RUST_LOG)"),
        )
        .subcommand(sim_command())
        .subcommand(up_command())
        .subcommand(
            Command::new("status")
                .about("One snapshot of the running nodes of this host: axes and node health (with --zenoh: of every host, through the gateways)")
                .arg(cell_arg())
                .arg(Arg::new("host").long("host"))
                .arg(zenoh_arg())
                .args(tls_args()),
        )
        .subcommand(
            Command::new("watch")
                .about("Live table of the running axes, optionally filtered by a pattern (node/axis substring)")
                .arg(cell_arg())
                .arg(Arg::new("host").long("host"))
                .arg(Arg::new("pattern"))
                .arg(
                    Arg::new("count")
                        .long("count")
                        .value_parser(clap::value_parser!(u64))
                        .help("Stop after this many refreshes (4 per second)"),
                ),
        )
        .subcommand(cmd_command())
        .subcommand(certs_command())
        .subcommand(ethercat_command())
        .subcommand(
            Command::new("check")
                .about("Validate a cell file; errors name file, line and key")
                .arg(Arg::new("cell").required(true).value_parser(clap::value_parser!(PathBuf))),
        )
}

/// `tandem sim`'s arguments.
fn sim_command() -> Command {
    Command::new("sim")
        .about("Run a cell on virtual time with a script; write a CSV trace")
        .arg(
            Arg::new("cell")
                .required(true)
                .value_parser(clap::value_parser!(PathBuf)),
        )
        .arg(
            Arg::new("script")
                .long("script")
                .required(true)
                .value_parser(clap::value_parser!(PathBuf))
                .help("Script of timed instructions (TOML)"),
        )
        .arg(
            Arg::new("trace")
                .long("trace")
                .required(true)
                .value_parser(clap::value_parser!(PathBuf))
                .help("CSV file to write (every signal of every axis, every cycle)"),
        )
        .arg(
            Arg::new("strict")
                .long("strict")
                .action(ArgAction::SetTrue)
                .help("Exit with 1 if a command was rejected or an alarm is pending at the end"),
        )
        .arg(
            Arg::new("quiet")
                .long("quiet")
                .short('q')
                .action(ArgAction::SetTrue)
                .help("Do not print job events and alarms"),
        )
}

/// `tandem up`'s arguments.
fn up_command() -> Command {
    Command::new("up")
        .about("Start this host's nodes of a cell, supervise them (restart on a crash), stop them on Ctrl-C")
        .arg(Arg::new("cell").required(true).value_parser(clap::value_parser!(PathBuf)))
        .arg(Arg::new("host").long("host").help("The host whose nodes to start (default: the cell's only host)"))
        .arg(
            Arg::new("script")
                .long("script")
                .value_parser(clap::value_parser!(PathBuf))
                .help("Script of timed instructions, applied by each node to its objects on the cell clock"),
        )
        .arg(
            Arg::new("record")
                .long("record")
                .value_parser(clap::value_parser!(PathBuf))
                .help("Directory for each node's CSV trace and log (<node>.csv, <node>.log)"),
        )
        .arg(
            Arg::new("duration")
                .long("duration")
                .value_parser(clap::value_parser!(f64))
                .help("Stop at this engine time in seconds, counted from the epoch (default: the script's duration, else Ctrl-C)"),
        )
        .arg(
            Arg::new("no-view")
                .long("no-view")
                .action(ArgAction::SetTrue)
                .help("Print events as they happen instead of the live table"),
        )
        .arg(
            Arg::new("epoch-ns")
                .long("epoch-ns")
                .value_parser(clap::value_parser!(i64))
                .help("Cell clock time of cycle 0 (ns since 1970, CLOCK_REALTIME); every host of a cell must start with the same (default: the next whole second plus one)"),
        )
        .arg(
            Arg::new("no-gateway")
                .long("no-gateway")
                .action(ArgAction::SetTrue)
                .help("Do not start the host's gateway (no Zenoh: nothing crosses to other hosts or observers)"),
        )
}

/// `tandem ethercat`'s arguments.
fn ethercat_command() -> Command {
    Command::new("ethercat")
        .about("EtherCAT segments")
        .subcommand_required(true)
        .subcommand(
            Command::new("scan")
                .about("List the SubDevices on a network interface (position, identity, name, PDO sizes, DC support); needs CAP_NET_RAW")
                .arg(Arg::new("interface").required(true)),
        )
}

/// `tandem cmd`'s arguments.
fn cmd_command() -> Command {
    Command::new("cmd")
        .about("Send an instruction to an object of a running node: tandem cmd <node>/<object> <instruction> [--param value]... [--wait]")
        .arg(cell_arg())
        .arg(zenoh_arg())
        .args(tls_args())
        .arg(Arg::new("target").required(true).help("<node>/<object>"))
        .arg(Arg::new("instruction").required(true).help("e.g. MC_MoveAbsolute, MoveVelocity, gear_in"))
        .arg(
            Arg::new("params")
                .num_args(0..)
                .allow_hyphen_values(true)
                .trailing_var_arg(true)
                .help("--param value pairs (the script's parameter names); --wait follows the job; --timeout <s> (default 60)"),
        )
}

/// Runs the command line `args` (with the program name first).
pub fn run(args: Vec<OsString>, out: &mut impl Write, err: &mut impl Write) -> ExitCode {
    let m = match cli().try_get_matches_from(args) {
        Ok(m) => m,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let to: &mut dyn Write = if e.use_stderr() { err } else { out };
            out!(to, "{}", e.render());
            return ExitCode::from(code);
        }
    };
    let Some((name, sub)) = m.subcommand() else {
        return ExitCode::from(2);
    };
    let format = m
        .get_one::<String>("log-format")
        .and_then(|f| LogFormat::parse(f))
        .unwrap_or_default();
    // Only the first call of a process installs a subscriber (the tests run many commands in
    // one process); later ones keep it, which is what they need.
    let _ = diag::init(if name == "up" { UP_LOG } else { QUIET_LOG }, format);
    match dispatch(name, sub, format, out, err) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if e.is_printed() {
                outln!(err, "error: {e}");
            }
            ExitCode::from(e.exit_code())
        }
    }
}

/// Runs subcommand `name` with its arguments `m`.
fn dispatch(
    name: &str,
    m: &clap::ArgMatches,
    format: LogFormat,
    out: &mut impl Write,
    err: &mut impl Write,
) -> Result<(), CliError> {
    let host = m.get_one::<String>("host").map(String::as_str);
    match name {
        "check" => offline::check(required(m, "cell")?, out),
        "ethercat" => match m.subcommand() {
            Some(("scan", s)) => {
                let interface = s
                    .get_one::<String>("interface")
                    .ok_or(CliError::Missing("interface"))?;
                ethercat::print(&ethercat::scan(interface)?, out)
            }
            _ => Err(CliError::Missing("ethercat subcommand")),
        },
        "certs" => certs::certs(
            &certs::CertsOptions {
                cell: required(m, "cell")?.clone(),
                out: m.get_one::<PathBuf>("out").cloned(),
                days: m.get_one::<u32>("days").copied().unwrap_or(365),
            },
            out,
        ),
        "sim" => offline::sim(&sim_options(m)?, out, err),
        "up" => {
            let cell = required(m, "cell")?;
            up::up(cell, &up_options(m, format), out)
        }
        "status" => {
            let cell = live::cell_path(m.get_one::<PathBuf>("cell"))?;
            match zenoh_endpoints(m) {
                Some(e) => remote::status_zenoh(&cell, &e, &tls(m), out),
                None => live::status(&cell, host, out),
            }
        }
        "watch" => live::watch(
            &live::cell_path(m.get_one::<PathBuf>("cell"))?,
            host,
            m.get_one::<String>("pattern").map(String::as_str),
            m.get_one::<u64>("count").copied(),
            out,
        ),
        "cmd" => {
            let cell = live::cell_path(m.get_one::<PathBuf>("cell"))?;
            let request = cmd_request(m)?;
            match zenoh_endpoints(m) {
                Some(e) => remote::cmd_zenoh(&cell, &e, &tls(m), &request, out),
                None => cmd::cmd(&cell, &request, out),
            }
        }
        _ => Err(CliError::UnknownCommand(name.to_string())),
    }
}

/// A required path argument (clap checked it is there).
fn required<'a>(m: &'a clap::ArgMatches, name: &'static str) -> Result<&'a PathBuf, CliError> {
    m.get_one::<PathBuf>(name).ok_or(CliError::Missing(name))
}

/// `tandem sim`'s options from its arguments.
fn sim_options(m: &clap::ArgMatches) -> Result<offline::SimOptions, CliError> {
    Ok(offline::SimOptions {
        cell: required(m, "cell")?.clone(),
        script: required(m, "script")?.clone(),
        trace: required(m, "trace")?.clone(),
        strict: m.get_flag("strict"),
        quiet: m.get_flag("quiet"),
    })
}

/// `tandem up`'s options from its arguments.
fn up_options(m: &clap::ArgMatches, format: LogFormat) -> up::UpOptions {
    up::UpOptions {
        host: m.get_one::<String>("host").cloned(),
        script: m.get_one::<PathBuf>("script").cloned(),
        record: m.get_one::<PathBuf>("record").cloned(),
        view: !m.get_flag("no-view") && std::io::IsTerminal::is_terminal(&std::io::stdout()),
        duration_s: m.get_one::<f64>("duration").copied(),
        gateway: !m.get_flag("no-gateway"),
        epoch_ns: m.get_one::<i64>("epoch-ns").copied(),
        log_format: format,
    }
}

/// `tandem cmd`'s request from its arguments: the target, the instruction, `--param value`
/// pairs, `--wait` and `--timeout <s>`.
fn cmd_request(m: &clap::ArgMatches) -> Result<cmd::CmdRequest, CliError> {
    let target = m.get_one::<String>("target").cloned().unwrap_or_default();
    let instruction = m
        .get_one::<String>("instruction")
        .cloned()
        .unwrap_or_default();
    let rest: Vec<String> = m
        .get_many::<String>("params")
        .map(|v| v.cloned().collect())
        .unwrap_or_default();
    let mut wait = false;
    let mut timeout = std::time::Duration::from_secs(60);
    let mut words = Vec::new();
    let mut it = rest.into_iter();
    while let Some(w) = it.next() {
        match w.as_str() {
            "--wait" => wait = true,
            "--timeout" => {
                let v = it
                    .next()
                    .and_then(|x| x.parse::<f64>().ok())
                    .filter(|x| *x > 0.0);
                timeout = std::time::Duration::from_secs_f64(
                    v.ok_or(CliError::Usage("--timeout needs a number of seconds > 0"))?,
                );
            }
            _ => words.push(w),
        }
    }
    let line = format!("{target} {instruction} {}", words.join(" "));
    let parsed = tandem_config::script::split_command(&line).map_err(CliError::command)?;
    Ok(cmd::CmdRequest {
        target,
        instruction,
        params: parsed.params,
        wait,
        timeout,
    })
}

fn zenoh_arg() -> Arg {
    Arg::new("zenoh")
        .long("zenoh")
        .action(ArgAction::Append)
        .value_name("ENDPOINT")
        .help("Go through the cell's gateways over Zenoh, from any machine of the cell network: a gateway endpoint (tcp/10.0.0.1:7447; repeat for more), or `scout` to find them by multicast scouting. Give it before <node>/<object>")
}

/// The `--zenoh` endpoints, or `None` without `--zenoh`.
fn zenoh_endpoints(m: &clap::ArgMatches) -> Option<Vec<String>> {
    m.value_source("zenoh")?;
    Some(
        m.get_many::<String>("zenoh")
            .map(|v| v.filter(|e| *e != "scout").cloned().collect())
            .unwrap_or_default(),
    )
}

/// `tandem certs`'s arguments.
fn certs_command() -> Command {
    Command::new("certs")
        .about("Create the cell's CA and the certificates of its hosts, operators and observers for [security] mode = \"mtls\" (docs/security.md)")
        .arg(Arg::new("cell").required(true).value_parser(clap::value_parser!(PathBuf)))
        .arg(
            Arg::new("out")
                .long("out")
                .value_parser(clap::value_parser!(PathBuf))
                .help("Directory to write into (default: the directory of the cell's [security] ca); it must not hold a CA yet"),
        )
        .arg(
            Arg::new("days")
                .long("days")
                .value_parser(clap::value_parser!(u32).range(1..=3650))
                .help("Validity of the certificates in days (default 365)"),
        )
}

/// `--ca`, `--cert`, `--key`: the client certificate of `--zenoh` for a cell in mTLS mode.
fn tls_args() -> [Arg; 3] {
    let path = |name: &'static str, help: &'static str| {
        Arg::new(name)
            .long(name)
            .value_parser(clap::value_parser!(PathBuf))
            .help(help)
    };
    [
        path("ca", "With --zenoh on an mTLS cell: the cell CA's certificate (default: $TANDEM_CA, else the cell's [security] ca)"),
        path("cert", "With --zenoh on an mTLS cell: an operator's or observer's certificate (default: $TANDEM_CERT)"),
        path("key", "With --zenoh on an mTLS cell: its private key (default: $TANDEM_KEY)"),
    ]
}

/// The `--ca`, `--cert`, `--key` given.
fn tls(m: &clap::ArgMatches) -> remote::TlsArgs {
    remote::TlsArgs {
        ca: m.get_one::<PathBuf>("ca").cloned(),
        cert: m.get_one::<PathBuf>("cert").cloned(),
        key: m.get_one::<PathBuf>("key").cloned(),
    }
}

fn cell_arg() -> Arg {
    Arg::new("cell")
        .long("cell")
        .value_parser(clap::value_parser!(PathBuf))
        .help("The cell file (default: $TANDEM_CELL)")
}
