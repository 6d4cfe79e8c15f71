//! The node's retained run-time parameters (docs/parameters.md, "Retained"): the values
//! MC_WriteParameter changed through `tandem cmd` or the Zenoh command query, one record per
//! axis in `<retain_dir>/<cell name>/<node name>/parameters/<axis name>`, stored with
//! [`RetainStore::store`] (temporary file, fsync, rename, directory fsync: a node killed at any
//! moment leaves the previous record or the new one, whole).
//!
//! - The command thread ([`Retained`]) keeps each axis' changed values; after the cycle
//!   accepted a write it stores the axis' whole record again, off the cyclic path.
//! - At start ([`restore`], before the first cycle) each record is loaded and its values are
//!   applied together over the cell file's ([`Executive::restore_parameters`]). A record made
//!   under another configuration of the axis (its [`fingerprint`] differs: the cell file's
//!   axis changed) is void, as is a damaged one: reported, not used, replaced by the next
//!   write.
//!
//! Not retained: `Override.Velocity` (MC_SetOverride is not either), and writes of a script
//! (the script writes them again at each start).
//!
//! Record payload (text): the line `tandem run-time parameters 1`, the line
//! `fingerprint <16 hex digits>`, then one line `<tag> <value>` per changed tag.

use std::fmt;
use std::fmt::Write as _;
use std::sync::Arc;
use tandem_config::{AxisIndex, Cell};
use tandem_motion::objects::action::Action;
use tandem_motion::objects::axis::{axis_parameter, axis_parameter_number, AxisConfig, Command};
use tandem_rt::retain::RetainStore;
use tandem_runtime::exec::Executive;
use tracing::{error, info, warn};

/// The sub-directory of a node's retained data that holds the parameters.
pub(crate) const PARAMETERS: &str = "parameters";

/// The first line of a record.
const HEADER: &str = "tandem run-time parameters 1";

/// Written, but not retained.
const NOT_RETAINED: &str = "Override.Velocity";

/// The fingerprint of an axis configuration (FNV-1a, 64 bit, of its `Debug` text: every value
/// of the cell file's axis, floats in their exact shortest form).
pub(crate) fn fingerprint(cfg: &AxisConfig) -> u64 {
    let mut text = String::new();
    // Writing into a String cannot fail.
    let _ = write!(text, "{cfg:?}");
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// One axis' retained parameters.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ParamRecord {
    /// The [`fingerprint`] of the configuration the values were written under.
    pub(crate) fingerprint: u64,
    /// Parameter numbers and values, in the order first written.
    pub(crate) values: Vec<(u16, f64)>,
}

/// Why a record cannot be used.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum RecordProblem {
    /// Not UTF-8 text.
    NotText,
    /// The first line is not the header.
    Header,
    /// No valid fingerprint line.
    Fingerprint,
    /// Line `n` (1-based) is not `<known tag> <finite number>`.
    Line(usize),
}

impl fmt::Display for RecordProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotText => f.write_str("not text"),
            Self::Header => write!(f, "the first line is not `{HEADER}`"),
            Self::Fingerprint => f.write_str("line 2 is not `fingerprint <16 hex digits>`"),
            Self::Line(n) => write!(f, "line {n} is not `<tag> <finite number>` of a known tag"),
        }
    }
}

impl ParamRecord {
    /// An empty record for configuration `fingerprint`.
    pub(crate) fn new(fingerprint: u64) -> Self {
        Self {
            fingerprint,
            values: Vec::new(),
        }
    }

    /// Sets parameter `n` to `x` (replacing an earlier value).
    pub(crate) fn set(&mut self, n: u16, x: f64) {
        match self.values.iter_mut().find(|(k, _)| *k == n) {
            Some(v) => v.1 = x,
            None => self.values.push((n, x)),
        }
    }

    /// The payload.
    pub(crate) fn encode(&self) -> Vec<u8> {
        let mut s = format!("{HEADER}\nfingerprint {:016x}\n", self.fingerprint);
        for &(n, x) in &self.values {
            if let Some(e) = axis_parameter(n) {
                // Writing into a String cannot fail; `{x:?}` is the exact shortest form.
                let _ = writeln!(s, "{} {x:?}", e.key);
            }
        }
        s.into_bytes()
    }

    /// A payload back; every line must be whole.
    pub(crate) fn decode(bytes: &[u8]) -> Result<Self, RecordProblem> {
        let text = std::str::from_utf8(bytes).map_err(|_| RecordProblem::NotText)?;
        let mut lines = text.lines();
        if lines.next() != Some(HEADER) {
            return Err(RecordProblem::Header);
        }
        let fingerprint = lines
            .next()
            .and_then(|l| l.strip_prefix("fingerprint "))
            .filter(|h| h.len() == 16)
            .and_then(|h| u64::from_str_radix(h, 16).ok())
            .ok_or(RecordProblem::Fingerprint)?;
        let mut record = Self::new(fingerprint);
        for (i, line) in lines.enumerate() {
            let bad = RecordProblem::Line(i + 3);
            let (tag, value) = line.split_once(' ').ok_or(bad)?;
            let n = axis_parameter_number(tag).ok_or(bad)?;
            let x: f64 = value.parse().map_err(|_| bad)?;
            if !x.is_finite() {
                return Err(bad);
            }
            record.set(n, x);
        }
        Ok(record)
    }
}

/// Opens (creating it) the directory of node `n`'s parameter records, if it has axes and a
/// retain directory; a directory that cannot be opened is reported (nothing is retained).
pub(crate) fn open(cell: &Cell, n: usize) -> Option<Arc<RetainStore>> {
    if !cell.axes.iter().any(|a| a.node == n) {
        return None;
    }
    let dir = cell.node_retain_dir(n)?.join(PARAMETERS);
    match RetainStore::open(&dir) {
        Ok(store) => Some(Arc::new(store)),
        Err(e) => {
            error!("{e}: run-time parameters are neither restored nor retained");
            None
        }
    }
}

/// The usable record of axis `i`, if any (a damaged or void one is reported here).
fn load(cell: &Cell, i: usize, store: &RetainStore) -> Option<ParamRecord> {
    let a = cell.axes.get(i)?;
    let name = a.name.as_str();
    let file = store.path(name);
    let file = file.display();
    let bytes = match store.load(name) {
        Ok(Some(b)) => b,
        Ok(None) => return None,
        Err(e) => {
            error!(
                axis = name,
                "axis {name}: {e}; its run-time parameters are the cell file's"
            );
            return None;
        }
    };
    let record = match ParamRecord::decode(&bytes) {
        Ok(r) => r,
        Err(p) => {
            error!(
                axis = name,
                "axis {name}: retained parameters {file}: {p}; not used"
            );
            return None;
        }
    };
    let now = fingerprint(&a.config);
    if record.fingerprint != now {
        warn!(
            axis = name,
            "axis {name}: the run-time parameters in {file} were written under another \
             configuration of the axis (fingerprint {:#018x}, now {now:#018x}): void, the cell \
             file's values apply",
            record.fingerprint
        );
        return None;
    }
    Some(record)
}

/// Applies each owned axis' retained parameters over the cell file's, before the first cycle.
pub(crate) fn restore(
    exec: &mut Executive<'_>,
    cell: &Cell,
    n: usize,
    store: Option<&RetainStore>,
) {
    let Some(store) = store else {
        return;
    };
    for i in (0..cell.axes.len()).filter(|i| cell.axes[*i].node == n) {
        let Some(record) = load(cell, i, store) else {
            continue;
        };
        let name = cell.axes[i].name.as_str();
        match exec.restore_parameters(AxisIndex(i), &record.values) {
            Ok(()) => info!(
                axis = name,
                count = record.values.len(),
                "axis {name}: {} run-time parameter(s) restored from {}",
                record.values.len(),
                store.path(name).display()
            ),
            Err((p, id)) => error!(
                axis = name,
                "axis {name}: retained parameter {} refused ({id}): none of the record's \
                 values applied",
                axis_parameter(p).map_or("?", |e| e.key)
            ),
        }
    }
}

/// A write to retain once the cycle accepted it: axis name, parameter number, value.
pub(crate) fn write_of(axis: &str, action: &Action) -> Option<(String, u16, f64)> {
    match action {
        Action::Command(Command::WriteParameter { parameter, value }) => axis_parameter(*parameter)
            .filter(|e| e.key != NOT_RETAINED)
            .map(|_| (axis.to_owned(), *parameter, *value)),
        _ => None,
    }
}

/// The command thread's side: each axis' record as last stored.
#[derive(Debug)]
pub(crate) struct Retained {
    store: Option<Arc<RetainStore>>,
    records: Vec<(String, ParamRecord)>,
}

impl Retained {
    /// The records of node `n`'s axes as found at start (void or damaged ones start empty).
    pub(crate) fn load(cell: &Cell, n: usize, store: Option<Arc<RetainStore>>) -> Self {
        let mut records = Vec::new();
        if let Some(s) = &store {
            for (i, a) in cell.axes.iter().enumerate().filter(|(_, a)| a.node == n) {
                let r =
                    load_quietly(cell, i, s).unwrap_or(ParamRecord::new(fingerprint(&a.config)));
                records.push((a.name.clone(), r));
            }
        }
        Self { store, records }
    }

    /// Retains an accepted write: the axis' whole record is stored again (a failure is
    /// reported with the file; the record keeps what it had).
    pub(crate) fn record(&mut self, (axis, n, x): (String, u16, f64)) {
        let Some(store) = &self.store else {
            return;
        };
        let Some((_, r)) = self.records.iter_mut().find(|(a, _)| *a == axis) else {
            return;
        };
        r.set(n, x);
        match store.store(&axis, &r.encode()) {
            Ok(()) => info!(
                axis,
                "axis {axis}: {} = {x:?} retained in {}",
                axis_parameter(n).map_or("?", |e| e.key),
                store.path(&axis).display()
            ),
            Err(e) => error!(axis, "{e}: the parameter is not retained"),
        }
    }
}

/// As [`load`], without reporting (the cyclic thread's [`restore`] reports).
fn load_quietly(cell: &Cell, i: usize, store: &RetainStore) -> Option<ParamRecord> {
    let a = cell.axes.get(i)?;
    let bytes = store.load(&a.name).ok()??;
    ParamRecord::decode(&bytes)
        .ok()
        .filter(|r| r.fingerprint == fingerprint(&a.config))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use super::*;
    use std::io::{BufRead, BufReader, Write};
    use std::os::unix::process::ExitStatusExt;
    use std::path::Path;
    use std::process::{Command as Process, Stdio};
    use std::sync::mpsc::{self, RecvTimeoutError};
    use std::time::{Duration, Instant};

    /// Set in the child: the directory it writes to.
    const WRITER_ENV: &str = "TANDEM_PARAMETERS_KILL_WRITER_DIR";
    const AXIS: &str = "x";
    const TIMEOUT: Duration = Duration::from_secs(30);
    /// Parameters written with the same value `k` in record `k`: a torn record would mix them.
    const TAGS: [&str; 6] = [
        "DynamicLimits.MaxAcceleration",
        "DynamicLimits.MaxDeceleration",
        "DynamicDefaults.Velocity",
        "FollowingError.MaxValue",
        "PositioningMonitoring.Window",
        "StandstillSignal.MinDwellTime",
    ];

    fn record(k: u64) -> ParamRecord {
        let mut r = ParamRecord::new(0x0123_4567_89ab_cdef);
        for t in TAGS {
            r.set(axis_parameter_number(t).unwrap(), k as f64 + 0.125);
        }
        r
    }

    /// The record's counter, `None` if its values differ.
    fn counter(r: &ParamRecord) -> Option<u64> {
        let first = r.values.first()?.1;
        let whole = r.values.len() == TAGS.len() && r.values.iter().all(|v| v.1 == first);
        whole.then_some((first - 0.125) as u64)
    }

    #[test]
    fn a_record_round_trips_and_damage_is_named() {
        let mut r = record(7);
        r.set(
            axis_parameter_number("PositionLimits_SW.Active").unwrap(),
            1.0,
        );
        r.set(
            axis_parameter_number("Homing.HomePosition").unwrap(),
            -0.1 + 0.2,
        );
        let bytes = r.encode();
        assert_eq!(ParamRecord::decode(&bytes), Ok(r.clone()));
        let text = String::from_utf8(bytes).unwrap();
        let cut = &text.as_bytes()[..text.len() - 3];
        assert!(ParamRecord::decode(cut).is_err() || ParamRecord::decode(cut) != Ok(r));
        let bad = text.replace("DynamicLimits.MaxAcceleration", "DynamicLimits.Nonsense");
        assert_eq!(
            ParamRecord::decode(bad.as_bytes()),
            Err(RecordProblem::Line(3))
        );
        assert_eq!(ParamRecord::decode(b"junk"), Err(RecordProblem::Header));
        let a = AxisConfig::example(0.001);
        let mut b = a.clone();
        assert_eq!(fingerprint(&a), fingerprint(&b));
        b.limits.max_jerk *= 2.0;
        assert_ne!(fingerprint(&a), fingerprint(&b));
    }

    /// The example cell with its retained data in a fresh directory of its own.
    fn example_cell(tag: &str) -> (Cell, std::path::PathBuf) {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let mut cell = tandem_config::load(&root.join("config/example-cell.toml")).unwrap();
        let dir = std::env::temp_dir().join(format!("tandem_params_{tag}_{}", std::process::id()));
        // A leftover of an earlier run with the same pid may or may not exist.
        let _ = std::fs::remove_dir_all(&dir);
        cell.retain_dir = dir.clone();
        (cell, dir)
    }

    /// An accepted write is stored; at the next start it is applied over the cell file's
    /// value; under another configuration of the axis the record is void.
    #[test]
    fn a_retained_write_is_restored_and_void_under_another_configuration() {
        let (cell, dir) = example_cell("restore");
        let n = cell.node("main").unwrap();
        let slide = cell.axes.iter().position(|a| a.name == "slide").unwrap();
        let jerk = axis_parameter_number("DynamicLimits.MaxJerk").unwrap();
        let ovr = axis_parameter_number("Override.Velocity").unwrap();
        let store = open(&cell, n).unwrap();
        let mut retained = Retained::load(&cell, n, Some(Arc::clone(&store)));
        let write = |parameter, value| {
            write_of(
                "slide",
                &Action::Command(Command::WriteParameter { parameter, value }),
            )
        };
        retained.record(write(jerk, 60_000.0).unwrap());
        assert_eq!(write(ovr, 50.0), None, "the override is not retained");
        let mut exec = Executive::new(&cell, Some(n)).unwrap();
        assert_eq!(exec.read_parameter("slide", jerk), Ok(100_000.0));
        restore(&mut exec, &cell, n, Some(&store));
        assert_eq!(exec.read_parameter("slide", jerk), Ok(60_000.0));
        // The record survives a second write of another tag, whole.
        let window = axis_parameter_number("PositioningMonitoring.Window").unwrap();
        retained.record(write(window, 0.5).unwrap());
        let again = Retained::load(&cell, n, Some(Arc::clone(&store)));
        let r = &again.records.iter().find(|(a, _)| a == "slide").unwrap().1;
        assert_eq!(r.values, vec![(jerk, 60_000.0), (window, 0.5)]);
        // Another configuration of the slide: the record is void, the cell file's value holds.
        let mut changed = cell.clone();
        changed.axes[slide].config.limits.max_velocity = 400.0;
        let mut exec = Executive::new(&changed, Some(n)).unwrap();
        restore(&mut exec, &changed, n, Some(&store));
        assert_eq!(exec.read_parameter("slide", jerk), Ok(100_000.0));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn write_forever(dir: &Path) -> ! {
        let store = RetainStore::open(dir).unwrap();
        let mut k = match store.load(AXIS).unwrap() {
            Some(p) => counter(&ParamRecord::decode(&p).unwrap()).expect("whole"),
            None => 0,
        };
        let mut out = std::io::stdout().lock();
        loop {
            k += 1;
            store.store(AXIS, &record(k).encode()).unwrap();
            writeln!(out, "stored {k}").unwrap();
            out.flush().unwrap();
        }
    }

    /// A parameter record survives `kill -9` of its writer at any moment: a child stores
    /// records `k` = 1, 2, ... (every value `k`) and reports each; killed with SIGKILL 1..=20 ms
    /// after its first store, the record loaded afterwards decodes whole, with the last
    /// reported `k` or the one after (the store in flight, if its rename happened).
    #[test]
    fn a_parameter_record_survives_kill_9_of_its_writer() {
        if let Some(dir) = std::env::var_os(WRITER_ENV) {
            write_forever(Path::new(&dir));
        }
        let dir = std::env::temp_dir().join(format!("tandem_params_kill_{}", std::process::id()));
        // A leftover of an earlier run with the same pid may or may not exist.
        let _ = std::fs::remove_dir_all(&dir);
        let mut previous = 0u64;
        for delay_ms in 1..=20u64 {
            let mut child = Process::new(std::env::current_exe().unwrap())
                .args([
                    "--exact",
                    "parameters::tests::a_parameter_record_survives_kill_9_of_its_writer",
                    "--nocapture",
                    "--test-threads=1",
                ])
                .env(WRITER_ENV, &dir)
                .stdin(Stdio::null())
                .stdout(Stdio::piped())
                .stderr(Stdio::inherit())
                .spawn()
                .unwrap();
            let stdout = child.stdout.take().unwrap();
            let (tx, rx) = mpsc::channel();
            let reader = std::thread::spawn(move || {
                for line in BufReader::new(stdout).lines() {
                    let Ok(line) = line else { break };
                    if let Some(k) = line.strip_prefix("stored ").and_then(|n| n.parse().ok()) {
                        if tx.send(k).is_err() {
                            break;
                        }
                    }
                }
            });
            let mut reported: u64 = rx.recv_timeout(TIMEOUT).expect("a first store");
            std::thread::sleep(Duration::from_millis(delay_ms));
            tandem_rt::send_signal(child.id(), libc::SIGKILL).unwrap();
            let deadline = Instant::now() + TIMEOUT;
            let status = loop {
                if let Some(s) = child.try_wait().unwrap() {
                    break s;
                }
                assert!(Instant::now() < deadline, "the writer did not end");
                std::thread::sleep(Duration::from_millis(1));
            };
            assert_eq!(status.signal(), Some(libc::SIGKILL), "{status}");
            loop {
                match rx.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
                    Ok(k) => reported = reported.max(k),
                    Err(RecvTimeoutError::Disconnected) => break,
                    Err(RecvTimeoutError::Timeout) => panic!("the writer's stdout did not end"),
                }
            }
            reader.join().unwrap();
            let store = RetainStore::open(&dir).unwrap();
            let payload = store.load(AXIS).unwrap().expect("a record");
            let r = ParamRecord::decode(&payload)
                .unwrap_or_else(|p| panic!("kill after {delay_ms} ms: {p}"));
            let k = counter(&r).unwrap_or_else(|| panic!("torn record: {r:?}"));
            assert!(
                k == reported || k == reported + 1,
                "kill after {delay_ms} ms: loaded {k}, last reported {reported}"
            );
            assert!(k > previous, "each writer stored at least once");
            previous = k;
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
