//! The commands that need no running cell: `check` validates a cell file, `sim` runs a cell
//! on virtual time.

use crate::error::CliError;
use std::io::Write;
use std::path::{Path, PathBuf};

/// `tandem check`: loads the cell file and says what it holds.
pub fn check(path: &Path, out: &mut impl Write) -> Result<(), CliError> {
    let cell = tandem_config::load(path)?;
    outln!(
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
    Ok(())
}

/// How `sim` runs.
#[derive(Debug, Clone)]
pub struct SimOptions {
    /// The cell file.
    pub cell: PathBuf,
    /// The script of timed instructions.
    pub script: PathBuf,
    /// The CSV trace to write.
    pub trace: PathBuf,
    /// Fail (exit 1) when a command was rejected or an alarm is pending at the end.
    pub strict: bool,
    /// Do not print job events and alarms.
    pub quiet: bool,
}

/// `tandem sim`: runs the cell with the script, writes the trace, prints the log (unless
/// quiet) to `out` and the summary to `err`.
pub fn sim(o: &SimOptions, out: &mut impl Write, err: &mut impl Write) -> Result<(), CliError> {
    let cell = tandem_config::load(&o.cell)?;
    let script = tandem_config::script::load(&o.script, &cell)?;
    let file = std::fs::File::create(&o.trace).map_err(|source| CliError::CreateTrace {
        path: o.trace.clone(),
        source,
    })?;
    let mut trace = std::io::BufWriter::new(file);
    let mut sink = std::io::sink();
    let log: &mut dyn Write = if o.quiet { &mut sink } else { out };
    let s = tandem_runtime::sim::run(&cell, &script, &mut trace, &mut LogAdapter(log))
        .map_err(|e| CliError::Sim(e.into()))?;
    trace.flush().map_err(|e| CliError::Sim(e.into()))?;
    outln!(
        err,
        "tandem sim: {} rows written to {}; {} command(s), {} rejected; {} axis/axes with a pending alarm",
        s.rows,
        o.trace.display(),
        s.commands,
        s.rejected,
        s.axes_in_alarm
    );
    if o.strict && (s.rejected > 0 || s.axes_in_alarm > 0) {
        return Err(CliError::Strict {
            rejected: s.rejected,
            axes_in_alarm: s.axes_in_alarm,
        });
    }
    Ok(())
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
