//! The `tandem` command line: `sim` runs a cell on virtual time, `check` validates a cell file.
//!
//! Exit codes: 0 success; 1 with `sim --strict`: the run finished but a command was rejected or
//! an alarm is pending; 2 the input is wrong (usage, config or script error); 3 IO error.

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
        _ => ExitCode::from(2),
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
