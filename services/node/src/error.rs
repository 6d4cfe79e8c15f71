//! [`NodeError`]: why a node could not run, with the exit code `tandem-node` ends with.

use std::error::Error;
use std::fmt;
use std::path::PathBuf;
use tandem_config::ConfigError;
use tandem_protocol::ipc::IpcError;

/// Why [`crate::run`] failed.
#[derive(Debug)]
pub enum NodeError {
    /// The cell file cannot be read or is wrong.
    Cell(ConfigError),
    /// The cell has no node of that name.
    UnknownNode {
        /// The cell file.
        cell: PathBuf,
        /// The name asked for.
        node: String,
        /// The nodes the cell has.
        nodes: Vec<String>,
    },
    /// The script is wrong.
    Script(ConfigError),
    /// The engine refused the cell's configuration.
    Engine(Box<dyn Error + Send + Sync>),
    /// An iceoryx2 port of the node could not be opened.
    Port {
        /// The port, e.g. `publisher for master`, `telemetry publisher`.
        port: String,
        /// What iceoryx2 said.
        source: IpcError,
    },
    /// The node's EtherCAT segment could not be started or does not match the cell file.
    Ethercat(crate::ethercat::EthercatError),
    /// A thread of the node could not be started.
    Thread {
        /// The thread's name.
        thread: &'static str,
        /// Why.
        source: std::io::Error,
    },
}

impl NodeError {
    /// The exit code of `tandem-node`: 2 when the input (cell, node, script) is wrong, 1 when
    /// the node could not run (iceoryx2 resources, threads), 3 when its EtherCAT segment
    /// cannot be opened, does not reach OP or does not match the cell file.
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Ethercat(_) => 3,
            Self::Cell(_) | Self::UnknownNode { .. } | Self::Script(_) | Self::Engine(_) => 2,
            Self::Port { .. } | Self::Thread { .. } => 1,
        }
    }

    /// An error of opening port `port`.
    pub(crate) fn port(port: impl Into<String>, source: IpcError) -> Self {
        Self::Port {
            port: port.into(),
            source,
        }
    }
}

impl fmt::Display for NodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Cell(e) | Self::Script(e) => write!(f, "{e}"),
            Self::UnknownNode { cell, node, nodes } => write!(
                f,
                "{}: no node `{node}`; the cell has: {}",
                cell.display(),
                nodes.join(", ")
            ),
            Self::Engine(e) => write!(f, "the engine refused the cell: {e}"),
            Self::Ethercat(e) => write!(f, "{e}"),
            Self::Port { port, source } => write!(f, "{port}: {source}"),
            Self::Thread { thread, source } => {
                write!(f, "cannot start the {thread} thread: {source}")
            }
        }
    }
}

impl Error for NodeError {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        match self {
            Self::Cell(e) | Self::Script(e) => Some(e),
            Self::UnknownNode { .. } => None,
            Self::Engine(e) => Some(e.as_ref()),
            Self::Ethercat(e) => Some(e),
            Self::Port { source, .. } => Some(source),
            Self::Thread { source, .. } => Some(source),
        }
    }
}
