//! The `tandem` command line: `up` starts and supervises a host's nodes, `status`, `watch` and
//! `cmd` work on a running cell, `sim` runs a cell on virtual time, `check` validates a cell
//! file.
//!
//! Exit codes: 0 success; 1 the command failed (`cmd`: rejected with an ErrorID, or the job
//! ended in error or was aborted; `sim --strict`: a command was rejected or an alarm is
//! pending); 2 the input is wrong (usage, config, script or command error); 3 the cell is not
//! reachable (a node not running, a timeout) or an IO error of `sim`; 4 an iceoryx2 error.

pub mod live;

use clap::{Arg, ArgAction, Command};
use std::ffi::OsString;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

fn cli() -> Command {
    Command::new("tandem")
        .about("tandem: a motion controller for machines that span several controllers")
        .subcommand_required(true)
        .arg_required_else_help(true)
        .subcommand(
            Command::new("sim")
                .about("Run a cell on virtual time with a script; write a CSV trace")
                .arg(Arg::new("cell").required(true).value_parser(clap::value_parser!(PathBuf)))
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
                ),
        )
        .subcommand(
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
                ),
        )
        .subcommand(
            Command::new("status")
                .about("One snapshot of the running nodes of this host: axes and node health (with --zenoh: of every host, through the gateways)")
                .arg(cell_arg())
                .arg(Arg::new("host").long("host"))
                .arg(zenoh_arg()),
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
        .subcommand(
            Command::new("cmd")
                .about("Send an instruction to an object of a running node: tandem cmd <node>/<object> <instruction> [--param value]... [--wait]")
                .arg(cell_arg())
                .arg(zenoh_arg())
                .arg(Arg::new("target").required(true).help("<node>/<object>"))
                .arg(Arg::new("instruction").required(true).help("e.g. MC_MoveAbsolute, MoveVelocity, gear_in"))
                .arg(
                    Arg::new("params")
                        .num_args(0..)
                        .allow_hyphen_values(true)
                        .trailing_var_arg(true)
                        .help("--param value pairs (the script's parameter names); --wait follows the job; --timeout <s> (default 60)"),
                ),
        )
        .subcommand(
            Command::new("check")
                .about("Validate a cell file; errors name file, line and key")
                .arg(Arg::new("cell").required(true).value_parser(clap::value_parser!(PathBuf))),
        )
}

/// Runs the command line `args` (with the program name first).
pub fn run(args: Vec<OsString>, out: &mut impl Write, err: &mut impl Write) -> ExitCode {
    let m = match cli().try_get_matches_from(args) {
        Ok(m) => m,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = write!(
                if e.use_stderr() {
                    err as &mut dyn Write
                } else {
                    out as &mut dyn Write
                },
                "{}",
                e.render()
            );
            return ExitCode::from(code);
        }
    };
    match m.subcommand() {
        Some(("check", sub)) => {
            let Some(path) = sub.get_one::<PathBuf>("cell") else {
                return ExitCode::from(2);
            };
            match tandem_config::load(path) {
                Ok(cell) => {
                    let _ = writeln!(
                        out,
                        "{}: cell `{}` is valid: {} node(s), {} axis/axes, {} external encoder(s), {} output cam(s), {} cam track(s), {} measuring input(s)",
                        path.display(),
                        cell.name,
                        cell.nodes.len(),
                        cell.axes.len(),
                        cell.encoders.len(),
                        cell.output_cams.len(),
                        cell.cam_tracks.len(),
                        cell.measuring_inputs.len()
                    );
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    let _ = writeln!(err, "error: {e}");
                    ExitCode::from(2)
                }
            }
        }
        Some(("sim", sub)) => sim(sub, out, err),
        Some((name, sub)) => match running(name, sub, out) {
            Ok(()) => ExitCode::SUCCESS,
            Err(live::Fail(code, message)) => {
                let _ = writeln!(err, "error: {message}");
                ExitCode::from(code)
            }
        },
        _ => ExitCode::from(2),
    }
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

fn cell_arg() -> Arg {
    Arg::new("cell")
        .long("cell")
        .value_parser(clap::value_parser!(PathBuf))
        .help("The cell file (default: $TANDEM_CELL)")
}

/// `up`, `status`, `watch`, `cmd`.
fn running(name: &str, m: &clap::ArgMatches, out: &mut impl Write) -> Result<(), live::Fail> {
    let host = m.get_one::<String>("host").map(String::as_str);
    match name {
        "up" => {
            let cell = m
                .get_one::<PathBuf>("cell")
                .ok_or_else(|| live::Fail(2, "a cell file is required".into()))?;
            let o = live::UpOptions {
                host: host.map(str::to_string),
                script: m.get_one::<PathBuf>("script").cloned(),
                record: m.get_one::<PathBuf>("record").cloned(),
                view: !m.get_flag("no-view")
                    && std::io::IsTerminal::is_terminal(&std::io::stdout()),
                duration_s: m.get_one::<f64>("duration").copied(),
                gateway: !m.get_flag("no-gateway"),
                epoch_ns: m.get_one::<i64>("epoch-ns").copied(),
            };
            live::up(cell, &o, out)
        }
        "status" => {
            let cell = live::cell_path(m.get_one::<PathBuf>("cell"))?;
            match zenoh_endpoints(m) {
                Some(e) => live::status_zenoh(&cell, &e, out),
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
                        timeout = std::time::Duration::from_secs_f64(v.ok_or_else(|| {
                            live::Fail(2, "--timeout needs a number of seconds > 0".into())
                        })?);
                    }
                    _ => words.push(w),
                }
            }
            let line = format!("{target} {instruction} {}", words.join(" "));
            let parsed = tandem_config::script::split_command(&line)
                .map_err(|m| live::Fail(2, m.to_string()))?;
            live::cmd(
                &cell,
                &target,
                &instruction,
                &parsed.params,
                wait,
                timeout,
                out,
            )
        }
        _ => Err(live::Fail(2, format!("unknown command `{name}`"))),
    }
}

fn sim(m: &clap::ArgMatches, out: &mut impl Write, err: &mut impl Write) -> ExitCode {
    let (Some(cell_path), Some(script_path), Some(trace_path)) = (
        m.get_one::<PathBuf>("cell"),
        m.get_one::<PathBuf>("script"),
        m.get_one::<PathBuf>("trace"),
    ) else {
        return ExitCode::from(2);
    };
    let cell = match tandem_config::load(cell_path) {
        Ok(c) => c,
        Err(e) => {
            let _ = writeln!(err, "error: {e}");
            return ExitCode::from(2);
        }
    };
    let src = match std::fs::read_to_string(script_path) {
        Ok(s) => s,
        Err(e) => {
            let _ = writeln!(err, "error: {}: cannot read: {e}", script_path.display());
            return ExitCode::from(2);
        }
    };
    let script =
        match tandem_config::script::parse_cell(&script_path.display().to_string(), &src, &cell) {
            Ok(s) => s,
            Err(e) => {
                let _ = writeln!(err, "error: {e}");
                return ExitCode::from(2);
            }
        };
    let file = match std::fs::File::create(trace_path) {
        Ok(f) => f,
        Err(e) => {
            let _ = writeln!(err, "error: {}: cannot create: {e}", trace_path.display());
            return ExitCode::from(3);
        }
    };
    let mut trace = std::io::BufWriter::new(file);
    let quiet = m.get_flag("quiet");
    let mut sink = std::io::sink();
    let log: &mut dyn Write = if quiet { &mut sink } else { out };
    let result = tandem_runtime::sim::run(&cell, &script, &mut trace, &mut LogAdapter(log))
        .and_then(|s| {
            trace.flush()?;
            Ok(s)
        });
    match result {
        Ok(s) => {
            let _ = writeln!(
                err,
                "tandem sim: {} rows written to {}; {} command(s), {} rejected; {} axis/axes with a pending alarm",
                s.rows,
                trace_path.display(),
                s.commands,
                s.rejected,
                s.axes_in_alarm
            );
            if m.get_flag("strict") && (s.rejected > 0 || s.axes_in_alarm > 0) {
                ExitCode::from(1)
            } else {
                ExitCode::SUCCESS
            }
        }
        Err(e) => {
            let _ = writeln!(err, "error: {e}");
            ExitCode::from(3)
        }
    }
}

/// `&mut dyn Write` as a sized `Write`.
struct LogAdapter<'a>(&'a mut dyn Write);

impl Write for LogAdapter<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()
    }
}
