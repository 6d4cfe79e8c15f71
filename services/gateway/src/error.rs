//! Why the gateway could not run, with the exit code of each reason.

use std::fmt;
use std::path::PathBuf;
use tandem_config::ConfigError;
use tandem_protocol::ipc::IpcError;

/// A failure of [`crate::run`] or of one of the gateway's threads.
///
/// Exit codes ([`GatewayError::exit_code`]): 2 the cell or host is wrong (the configuration is
/// refused; `tandem up` does not restart a gateway that exits with 2), 1 it could not run.
#[derive(Debug)]
pub enum GatewayError {
    /// The cell file could not be read or is invalid.
    Config(ConfigError),
    /// `--host` names no host of the cell.
    UnknownHost {
        /// The cell file.
        cell: PathBuf,
        /// The host asked for.
        host: String,
        /// The cell's hosts.
        hosts: Vec<String>,
    },
    /// The cell has several hosts and `--host` was not given.
    HostRequired {
        /// The cell file.
        cell: PathBuf,
        /// The cell's hosts.
        hosts: Vec<String>,
    },
    /// A Zenoh configuration key refused its value.
    ZenohConfig {
        /// The key (`listen/endpoints`).
        key: &'static str,
        /// The value given (JSON5).
        value: String,
        /// What Zenoh said.
        source: zenoh::Error,
    },
    /// A Zenoh call failed: opening the session, or declaring a token, publisher, subscriber
    /// or queryable.
    Zenoh {
        /// What was being declared (`liveliness token`, `publisher tandem/line/lv/x`).
        what: String,
        /// What Zenoh said.
        source: zenoh::Error,
    },
    /// An iceoryx2 node or service of this host could not be opened.
    Ipc(IpcError),
    /// An iceoryx2 port (listener, subscriber, publisher, client) could not be created.
    IpcPort {
        /// Which port (`telemetry subscriber`).
        port: &'static str,
        /// What iceoryx2 said.
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// A certificate or key of `[security]` cannot be read (mTLS mode).
    Certificate {
        /// What it is (`CA certificate`, `host certificate`, `host private key`).
        what: &'static str,
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// One of the gateway's threads could not be started.
    Thread {
        /// The thread (`lv-out`, `commands`...).
        name: &'static str,
        /// What the OS said.
        source: std::io::Error,
    },
}

impl GatewayError {
    /// The process exit code for this failure: 2 the cell or host is wrong, 1 it could not run.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Config(_)
            | Self::UnknownHost { .. }
            | Self::HostRequired { .. }
            | Self::Certificate { .. } => 2,
            Self::ZenohConfig { .. }
            | Self::Zenoh { .. }
            | Self::Ipc(_)
            | Self::IpcPort { .. }
            | Self::Thread { .. } => 1,
        }
    }

    /// An iceoryx2 port that could not be created, for `map_err`.
    pub(crate) fn port<E>(port: &'static str) -> impl FnOnce(E) -> Self
    where
        E: std::error::Error + Send + Sync + 'static,
    {
        move |e| Self::IpcPort {
            port,
            source: Box::new(e),
        }
    }

    /// A Zenoh declaration that failed, for `map_err`.
    pub(crate) fn zenoh(what: impl Into<String>) -> impl FnOnce(zenoh::Error) -> Self {
        let what = what.into();
        move |source| Self::Zenoh { what, source }
    }
}

impl fmt::Display for GatewayError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Config(e) => write!(f, "{e}"),
            Self::UnknownHost { cell, host, hosts } => write!(
                f,
                "{}: no host `{host}`; the cell has: {}",
                cell.display(),
                hosts.join(", ")
            ),
            Self::HostRequired { cell, hosts } => write!(
                f,
                "{}: the cell has several hosts ({}): say which with --host",
                cell.display(),
                hosts.join(", ")
            ),
            Self::ZenohConfig { key, value, source } => {
                write!(f, "zenoh config {key} = {value}: {source}")
            }
            Self::Zenoh { what, source } => write!(f, "{what}: {source}"),
            Self::Ipc(e) => write!(f, "{e}"),
            Self::IpcPort { port, source } => write!(f, "{port}: {source}"),
            Self::Thread { name, source } => write!(f, "cannot start the {name} thread: {source}"),
            Self::Certificate { what, path, source } => write!(
                f,
                "{what} {}: {source} (create the certificates with `tandem certs`, docs/security.md)",
                path.display()
            ),
        }
    }
}

impl std::error::Error for GatewayError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Config(e) => Some(e),
            Self::Ipc(e) => Some(e),
            Self::ZenohConfig { source, .. } | Self::Zenoh { source, .. } => Some(source.as_ref()),
            Self::IpcPort { source, .. } => Some(source.as_ref()),
            Self::Thread { source, .. } | Self::Certificate { source, .. } => Some(source),
            Self::UnknownHost { .. } | Self::HostRequired { .. } => None,
        }
    }
}

impl From<ConfigError> for GatewayError {
    fn from(e: ConfigError) -> Self {
        Self::Config(e)
    }
}

impl From<IpcError> for GatewayError {
    fn from(e: IpcError) -> Self {
        Self::Ipc(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wrong_cell_or_host_exits_2_anything_else_1() {
        let cell = PathBuf::from("cell.toml");
        let hosts = vec!["h1".to_string(), "h2".to_string()];
        let unknown = GatewayError::UnknownHost {
            cell: cell.clone(),
            host: "h3".into(),
            hosts: hosts.clone(),
        };
        assert_eq!(unknown.exit_code(), 2);
        assert_eq!(
            unknown.to_string(),
            "cell.toml: no host `h3`; the cell has: h1, h2"
        );
        assert_eq!(GatewayError::HostRequired { cell, hosts }.exit_code(), 2);
        let thread = GatewayError::Thread {
            name: "clock",
            source: std::io::Error::other("no"),
        };
        assert_eq!(thread.exit_code(), 1);
    }
}
