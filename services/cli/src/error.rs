//! Why a `tandem` command failed, with its exit code.

use std::fmt;
use std::path::PathBuf;
use std::time::Duration;
use tandem_config::ConfigError;
use tandem_motion::catalog::error_id::ErrorId;
use tandem_protocol::ipc::IpcError;

/// A boxed error from another crate, kept as the source.
pub type Source = Box<dyn std::error::Error + Send + Sync>;

/// A failure of a `tandem` command.
///
/// Exit codes ([`CliError::exit_code`]): 1 the command failed (`cmd`: rejected with an ErrorID,
/// or the job ended in error or was aborted; `sim --strict`: a command was rejected or an alarm
/// is pending); 2 the input is wrong (usage, config, script or command error); 3 the cell is not
/// reachable (a node not running, a timeout) or an IO error of `sim`; 4 an iceoryx2 error (or
/// Zenoh, or a program that cannot be started); 5 `up`: another `tandem up` supervises the cell
/// on this host.
#[derive(Debug)]
pub enum CliError {
    /// A required argument is missing (clap checks them first, so this is a safeguard).
    Missing(&'static str),
    /// An argument has a wrong value.
    Usage(&'static str),
    /// `status`, `watch` or `cmd` without `--cell` and without `$TANDEM_CELL`.
    NoCell,
    /// A subcommand this program does not have.
    UnknownCommand(String),
    /// The cell file, or a script, is wrong (file, line, key and problem).
    Config(ConfigError),
    /// The recording directory of `up --record` could not be created.
    RecordDir {
        /// The directory.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The trace file of `sim` could not be created.
    CreateTrace {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The simulation stopped on an error (writing its trace or log).
    Sim(Source),
    /// `sim --strict`: a command was rejected or an axis has a pending alarm. Its summary line
    /// already said so, so it is not printed again.
    Strict {
        /// Commands rejected.
        rejected: usize,
        /// Axes with a pending alarm at the end.
        axes_in_alarm: usize,
    },
    /// `--host` names no host of the cell.
    UnknownHost {
        /// The cell's name.
        cell: String,
        /// The host asked for.
        host: String,
        /// The cell's hosts.
        hosts: Vec<String>,
    },
    /// The cell has several hosts and `--host` was not given.
    HostRequired {
        /// The cell's name.
        cell: String,
        /// The cell's hosts.
        hosts: Vec<String>,
    },
    /// `up` on a host without nodes.
    NoNodesHere,
    /// Another `tandem up` supervises this cell on this host (it holds the lock file).
    AlreadySupervised {
        /// The cell's name.
        cell: String,
        /// The host.
        host: String,
        /// The lock file.
        path: PathBuf,
        /// The running `up`'s process id, as it wrote it into the lock file.
        pid: Option<u32>,
    },
    /// The supervisor's lock file could not be created or locked.
    Lock {
        /// The lock file.
        path: PathBuf,
        /// Why.
        source: tandem_rt::LockError,
    },
    /// An iceoryx2 node or service could not be opened.
    Ipc(IpcError),
    /// An iceoryx2 port could not be created or used.
    IpcPort {
        /// What was being done (`telemetry of leaders`, `sending the command`).
        what: String,
        /// What iceoryx2 said.
        source: Source,
    },
    /// `status`: nodes of the host are not running.
    NotRunning {
        /// The nodes not running.
        nodes: Vec<String>,
        /// The cell file (for the hint to start them).
        cell: PathBuf,
    },
    /// `cmd`: the target is not `<node>/<object>`.
    Target(String),
    /// `cmd`: no node of that name.
    UnknownNode {
        /// The node asked for.
        node: String,
        /// The cell's nodes.
        nodes: Vec<String>,
    },
    /// `cmd`: the instruction or a parameter is not understood (checked before sending).
    Command(Source),
    /// `cmd`: the node has no command server.
    NodeNotRunning {
        /// The node.
        node: String,
        /// The cell file (for the hint to start it).
        cell: PathBuf,
    },
    /// `cmd`: the node did not answer in time.
    NoAnswer {
        /// The node.
        node: String,
        /// How long it was given.
        within: Duration,
    },
    /// `cmd`: the object rejected the instruction; its running job goes on.
    Rejected {
        /// `<node>/<object>`.
        target: String,
        /// The instruction as given.
        instruction: String,
        /// The ErrorID's code.
        error_id: u32,
        /// The node's words.
        message: String,
    },
    /// `cmd`: the node did not understand the command.
    Invalid(String),
    /// `cmd`: the node's command queue was full.
    Busy(String),
    /// `cmd`: a reply outcome this program does not know.
    UnknownOutcome(u32),
    /// `cmd --wait`: the job was aborted.
    JobAborted {
        /// The job.
        job: u32,
    },
    /// `cmd --wait`: the job ended in error.
    JobError {
        /// The job.
        job: u32,
        /// Its ErrorID's code.
        error_id: u32,
    },
    /// `cmd --wait`: the job did not end within the timeout.
    JobTimeout {
        /// The job.
        job: u32,
        /// The timeout.
        timeout: Duration,
    },
    /// `up`: a node or the gateway exited with 2: it refused its configuration.
    Refused {
        /// The node (or `gateway <host>`).
        name: String,
        /// How it exited.
        status: std::process::ExitStatus,
    },
    /// `up`: `tandem-node` or `tandem-gateway` could not be started.
    CannotStart {
        /// The node (or `gateway <host>`).
        name: String,
        /// The program tried.
        program: PathBuf,
        /// Whether it is the gateway (which `--no-gateway` leaves out).
        gateway: bool,
        /// What the OS said.
        source: std::io::Error,
    },
    /// The async runtime of `--zenoh` could not be started.
    Runtime(std::io::Error),
    /// `--zenoh`: what the client said.
    Client(tandem_client::ClientError),
    /// `status --zenoh`: hosts whose gateways are not alive.
    HostsUnreachable(Vec<String>),
    /// `certs`: a key or certificate could not be made.
    CertGen {
        /// Which (`the CA`, `host:h1`).
        what: String,
        /// What rcgen said.
        source: rcgen::Error,
    },
    /// `certs`: a file could not be written.
    CertWrite {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// `certs`: the output directory has a CA already; a new one would orphan every certificate
    /// it signed.
    CertsExist(PathBuf),
    /// `--cert` without `--key` (or the reverse), or a client certificate without the CA.
    TlsIncomplete(&'static str),
    /// `ethercat scan`: the raw socket on the interface could not be opened (no such
    /// interface, or no CAP_NET_RAW).
    EtherCatSocket {
        /// The network interface.
        interface: String,
        /// What the OS said.
        source: std::io::Error,
    },
    /// `ethercat scan`: what ethercrab said.
    EtherCat {
        /// The network interface.
        interface: String,
        /// ethercrab's error.
        source: ethercrab::error::Error,
    },
    /// `ethercat scan`: the scan did not finish in time.
    EtherCatTimeout {
        /// The network interface.
        interface: String,
        /// How long it was given.
        within: Duration,
    },
}

impl CliError {
    /// The process exit code: 1 the command failed, 2 the input is wrong, 3 the cell is not
    /// reachable (or `sim` could not write), 4 an iceoryx2, Zenoh or process error, 5 another
    /// `tandem up` supervises the cell on this host.
    pub fn exit_code(&self) -> u8 {
        use tandem_client::ClientError as C;
        match self {
            Self::Strict { .. }
            | Self::Rejected { .. }
            | Self::JobAborted { .. }
            | Self::JobError { .. } => 1,
            Self::Missing(_)
            | Self::Usage(_)
            | Self::NoCell
            | Self::UnknownCommand(_)
            | Self::Config(_)
            | Self::RecordDir { .. }
            | Self::UnknownHost { .. }
            | Self::HostRequired { .. }
            | Self::NoNodesHere
            | Self::Target(_)
            | Self::UnknownNode { .. }
            | Self::Command(_)
            | Self::Invalid(_)
            | Self::Refused { .. }
            | Self::CertsExist(_)
            | Self::TlsIncomplete(_) => 2,
            Self::CreateTrace { .. }
            | Self::Sim(_)
            | Self::NotRunning { .. }
            | Self::NodeNotRunning { .. }
            | Self::NoAnswer { .. }
            | Self::Busy(_)
            | Self::JobTimeout { .. }
            | Self::HostsUnreachable(_)
            | Self::CertWrite { .. }
            | Self::EtherCatSocket { .. }
            | Self::EtherCat { .. }
            | Self::EtherCatTimeout { .. } => 3,
            Self::Ipc(_)
            | Self::IpcPort { .. }
            | Self::UnknownOutcome(_)
            | Self::CannotStart { .. }
            | Self::Runtime(_)
            | Self::CertGen { .. }
            | Self::Lock { .. } => 4,
            Self::AlreadySupervised { .. } => 5,
            Self::Client(e) => match e {
                C::Rejected { .. } | C::JobFailed { .. } => 1,
                C::Invalid(_) | C::Certificate { .. } | C::Sender(_) => 2,
                C::Timeout { .. } | C::Unreachable(_) => 3,
                C::Zenoh(_) | C::Malformed(_) => 4,
            },
        }
    }

    /// Whether `run` prints this error (`error: ...`); `sim --strict`'s summary already said
    /// what failed.
    pub fn is_printed(&self) -> bool {
        !matches!(self, Self::Strict { .. })
    }

    /// An iceoryx2 port that could not be created or used, for `map_err`.
    pub(crate) fn port<E>(what: impl Into<String>) -> impl FnOnce(E) -> Self
    where
        E: std::error::Error + Send + Sync + 'static,
    {
        let what = what.into();
        move |e| Self::IpcPort {
            what,
            source: Box::new(e),
        }
    }

    /// A command the config crate's parser refused, for `map_err`.
    pub(crate) fn command<E: Into<Source>>(e: E) -> Self {
        Self::Command(e.into())
    }
}

/// An ErrorID by its code: `16#8003 IllegalVelocity`, or the bare hex code of an unknown one.
fn error_id(code: u32) -> String {
    u16::try_from(code)
        .ok()
        .and_then(ErrorId::from_code)
        .map_or(format!("16#{code:04X}"), |e| e.to_string())
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Missing(name) => write!(f, "a {name} argument is required"),
            Self::Usage(m) => f.write_str(m),
            Self::NoCell => f.write_str("which cell? give --cell <cell.toml> or set TANDEM_CELL"),
            Self::EtherCatSocket { interface, source } => {
                write!(f, "cannot open a raw socket on {interface}: {source}")
            }
            Self::EtherCat { interface, source } => {
                write!(f, "EtherCAT on {interface}: {source}")
            }
            Self::EtherCatTimeout { interface, within } => {
                write!(f, "EtherCAT on {interface}: no answer within {within:?}")
            }
            Self::UnknownCommand(name) => write!(f, "unknown command `{name}`"),
            Self::Config(e) => write!(f, "{e}"),
            Self::RecordDir { path, source } => write!(f, "{}: {source}", path.display()),
            Self::CreateTrace { path, source } => {
                write!(f, "{}: cannot create: {source}", path.display())
            }
            Self::Sim(e) => write!(f, "{e}"),
            Self::CertGen { what, source } => write!(f, "{what}: {source}"),
            Self::CertWrite { path, source } => {
                write!(f, "{}: cannot write: {source}", path.display())
            }
            Self::CertsExist(p) => write!(
                f,
                "{} exists: a new CA would orphan every certificate the old one signed; \
                 give another --out, or remove it on purpose",
                p.display()
            ),
            Self::TlsIncomplete(m) => f.write_str(m),
            Self::Strict {
                rejected,
                axes_in_alarm,
            } => write!(
                f,
                "--strict: {rejected} command(s) rejected, {axes_in_alarm} axis/axes with a pending alarm"
            ),
            _ => self.fmt_running(f),
        }
    }
}

impl CliError {
    /// The errors of the commands on a running cell (`up`, `status`, `watch`, `cmd`).
    fn fmt_running(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::UnknownHost { cell, host, hosts } => write!(
                f,
                "no host `{host}` in cell `{cell}`; it has: {}",
                hosts.join(", ")
            ),
            Self::HostRequired { cell, hosts } => write!(
                f,
                "cell `{cell}` has several hosts ({}): say which with --host",
                hosts.join(", ")
            ),
            Self::NoNodesHere => f.write_str("this host has no nodes"),
            Self::AlreadySupervised {
                cell,
                host,
                path,
                pid,
            } => write!(
                f,
                "cell `{cell}` on host `{host}` is already supervised by tandem up{} (lock {}); \
                 stop that one first (a second set of processes would serve the same services)",
                pid.map_or(String::new(), |p| format!(", pid {p}")),
                path.display()
            ),
            Self::Lock { path, source } => {
                write!(f, "cannot lock {}: {source}", path.display())
            }
            Self::Ipc(e) => write!(f, "{e}"),
            Self::IpcPort { what, source } => write!(f, "{what}: {source}"),
            Self::NotRunning { nodes, cell } => write!(
                f,
                "not running: {} (start them with `tandem up {}`)",
                nodes.join(", "),
                cell.display()
            ),
            Self::Target(target) => write!(
                f,
                "`{target}`: address an object as <node>/<object>, e.g. followers/feed"
            ),
            Self::UnknownNode { node, nodes } => {
                write!(f, "no node `{node}`; the cell has: {}", nodes.join(", "))
            }
            Self::Command(e) => write!(f, "{e}"),
            Self::NodeNotRunning { node, cell } => write!(
                f,
                "node `{node}` is not running (no command server); start it with `tandem up {}`",
                cell.display()
            ),
            Self::NoAnswer { node, within } => {
                write!(f, "node `{node}` did not answer within {within:?}")
            }
            Self::Rejected {
                target,
                instruction,
                error_id: id,
                message,
            } => write!(
                f,
                "{target} {instruction}: rejected with {}: {message}; the running job goes on",
                error_id(*id)
            ),
            Self::Invalid(m) | Self::Busy(m) => f.write_str(m),
            Self::UnknownOutcome(o) => write!(f, "unknown reply outcome {o}"),
            Self::JobAborted { job } => write!(f, "job {job} was aborted"),
            Self::JobError { job, error_id: id } => {
                write!(f, "job {job} ended with {}", error_id(*id))
            }
            Self::JobTimeout { job, timeout } => {
                write!(f, "job {job} did not end within {timeout:?}")
            }
            Self::Refused { name, status } => write!(
                f,
                "`{name}` refused its configuration ({})",
                describe_exit(*status)
            ),
            Self::CannotStart {
                name,
                program,
                gateway,
                source,
            } => write!(
                f,
                "cannot start {name} ({}): {source}; build it beside tandem \
                 (cargo build --release --bins){}",
                program.display(),
                if *gateway {
                    ", or run without it: --no-gateway"
                } else {
                    ""
                }
            ),
            Self::Runtime(e) => write!(f, "cannot start the async runtime: {e}"),
            Self::Client(e) => write!(f, "{e}"),
            Self::HostsUnreachable(hosts) => {
                write!(f, "hosts not reachable: {}", hosts.join(", "))
            }
            // The others are written by `Display::fmt` itself.
            _ => Ok(()),
        }
    }
}

impl std::error::Error for CliError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Config(e) => Some(e),
            Self::Ipc(e) => Some(e),
            Self::Client(e) => Some(e),
            Self::Lock { source, .. } => Some(source),
            Self::EtherCatSocket { source, .. } => Some(source),
            Self::EtherCat { source, .. } => Some(source),
            Self::RecordDir { source, .. }
            | Self::CreateTrace { source, .. }
            | Self::CannotStart { source, .. }
            | Self::Runtime(source) => Some(source),
            Self::Sim(source) | Self::Command(source) | Self::IpcPort { source, .. } => {
                Some(source.as_ref())
            }
            _ => None,
        }
    }
}

impl From<ConfigError> for CliError {
    fn from(e: ConfigError) -> Self {
        Self::Config(e)
    }
}

impl From<IpcError> for CliError {
    fn from(e: IpcError) -> Self {
        Self::Ipc(e)
    }
}

impl From<tandem_client::ClientError> for CliError {
    fn from(e: tandem_client::ClientError) -> Self {
        Self::Client(e)
    }
}

/// How a child process ended: `exit code 2`, `signal 9`.
pub fn describe_exit(s: std::process::ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (s.code(), s.signal()) {
        (Some(c), _) => format!("exit code {c}"),
        (None, Some(sig)) => format!("signal {sig}"),
        _ => "unknown status".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_codes_are_the_documented_ones() {
        assert_eq!(CliError::NoCell.exit_code(), 2);
        assert_eq!(CliError::JobAborted { job: 3 }.exit_code(), 1);
        assert_eq!(
            CliError::NoAnswer {
                node: "n".into(),
                within: Duration::from_secs(5)
            }
            .exit_code(),
            3
        );
        assert_eq!(CliError::UnknownOutcome(9).exit_code(), 4);
        let dup = CliError::AlreadySupervised {
            cell: "line".into(),
            host: "local".into(),
            path: "retain/line/local.up.lock".into(),
            pid: Some(4242),
        };
        assert_eq!(dup.exit_code(), 5);
        assert!(dup.to_string().contains("pid 4242"), "{dup}");
        assert_eq!(
            CliError::Client(tandem_client::ClientError::Invalid("x".into())).exit_code(),
            2
        );
        let strict = CliError::Strict {
            rejected: 1,
            axes_in_alarm: 0,
        };
        assert_eq!(strict.exit_code(), 1);
        assert!(!strict.is_printed());
    }

    #[test]
    fn an_error_id_is_named_when_known() {
        let e = CliError::JobError {
            job: 4,
            error_id: 0x8003,
        };
        assert!(e.to_string().starts_with("job 4 ended with 16#8003"), "{e}");
        let e = CliError::JobError {
            job: 4,
            error_id: 0x1,
        };
        assert_eq!(e.to_string(), "job 4 ended with 16#0001");
    }
}
