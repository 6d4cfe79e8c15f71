//! tandem-client: a tandem cell over Zenoh, from any machine of the cell network.
//!
//! A user program (or the `tandem` CLI with `--zenoh`) connects to the cell's gateways, sends
//! PLCopen instructions to technology objects and awaits their job outcomes, and reads the
//! state of the axes. Everything is typed, async and bounded by a timeout; a failure is a
//! [`ClientError`] that says what went wrong.
//!
//! ```no_run
//! # async fn demo() -> Result<(), tandem_client::ClientError> {
//! use std::time::Duration;
//! use tandem_client::{Client, ClientError};
//! let c = Client::connect("line", &["tcp/10.0.0.1:7447".into()]).await?;
//! // Send an instruction and return when the node applied it.
//! let accepted = c
//!     .command("leaders", "line", "MC_Power", Duration::from_secs(5))
//!     .await?;
//! println!("job {} at t = {} ns", accepted.job, accepted.t_ns);
//! // Send one and await its job: done, or reached its goal (here InVelocity).
//! match c
//!     .execute("leaders", "line", "MC_MoveVelocity --velocity 800", Duration::from_secs(10))
//!     .await
//! {
//!     Ok(outcome) => println!("{outcome:?}"),
//!     Err(ClientError::Rejected { error_id, .. }) => println!("rejected with {error_id}"),
//!     Err(e) => return Err(e),
//! }
//! c.close().await
//! # }
//! ```

use std::time::Duration;
use tandem_protocol::json::{AxisState, EventJson, ReplyJson};
use tandem_protocol::keys;

/// What can go wrong, with what the cell said.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ClientError {
    /// Zenoh failed (session, declaration, query).
    Zenoh(String),
    /// Nothing came within the timeout.
    Timeout {
        /// What was awaited.
        what: String,
    },
    /// The object rejected the instruction; its running job goes on.
    Rejected {
        /// `16#8003 IllegalVelocity`.
        error_id: String,
        /// In words.
        message: String,
    },
    /// The instruction was not understood (unknown object, instruction or parameter).
    Invalid(String),
    /// The node did not answer (not running) or its queue was full.
    Unreachable(String),
    /// The job ended in error or was aborted.
    JobFailed {
        /// `error` or `aborted`.
        outcome: String,
        /// The ErrorID of an error.
        error_id: String,
        /// The event, as the log shows it.
        message: String,
    },
    /// A payload that is not what the protocol says.
    Malformed(String),
    /// The client's certificate could not be read or names no usable common name.
    Certificate {
        /// The certificate file.
        path: std::path::PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// The sender cannot be the last chunk of a command key ([`keys::valid_sender`]).
    Sender(String),
}

impl core::fmt::Display for ClientError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Zenoh(m) => write!(f, "zenoh: {m}"),
            Self::Timeout { what } => write!(f, "no answer: {what}"),
            Self::Rejected { error_id, message } => {
                write!(
                    f,
                    "rejected with {error_id}: {message}; the running job goes on"
                )
            }
            Self::Invalid(m) => write!(f, "not understood: {m}"),
            Self::Unreachable(m) => write!(f, "unreachable: {m}"),
            Self::JobFailed {
                outcome,
                error_id,
                message,
            } => {
                if error_id.is_empty() {
                    write!(f, "the job was {outcome}: {message}")
                } else {
                    write!(f, "the job ended with {error_id}: {message}")
                }
            }
            Self::Malformed(m) => write!(f, "malformed answer: {m}"),
            Self::Certificate { path, reason } => {
                write!(f, "certificate {}: {reason}", path.display())
            }
            Self::Sender(s) => write!(
                f,
                "sender {s:?} cannot name a command key (empty, `/`, `*`, `$`, `?`, `#`, a leading `@`, or a control character)"
            ),
        }
    }
}

impl std::error::Error for ClientError {}

/// An accepted instruction.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Accepted {
    /// The job (0 for instructions without one).
    pub job: u32,
    /// The cycle time it was applied at (ns).
    pub t_ns: i64,
    /// The node's words on it: MC_ReadParameter's and MC_WriteParameter's `Tag = value`;
    /// empty for most instructions.
    pub message: String,
}

/// How an awaited job went: the events seen, the last one ending it.
#[derive(Debug, Clone, PartialEq)]
pub struct JobOutcome {
    /// The job.
    pub job: u32,
    /// Every event of the job, in order; the last is `done` or `reached`.
    pub events: Vec<EventJson>,
}

/// The certificate a client presents to the gateways of a cell in mTLS mode (made by `tandem
/// certs`): the cell's CA, and an operator's or observer's certificate and key.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tls {
    /// The cell CA's certificate (PEM).
    pub ca: std::path::PathBuf,
    /// The client's certificate (PEM; CN `operator:<name>` or `observer:<name>`).
    pub certificate: std::path::PathBuf,
    /// The client's private key (PEM).
    pub private_key: std::path::PathBuf,
}

impl Tls {
    /// The common name of the client's certificate (`operator:alice`): its identity in the
    /// cell's access control, and so the sender of its commands.
    pub fn common_name(&self) -> Result<String, ClientError> {
        let path = &self.certificate;
        let err = |reason: String| ClientError::Certificate {
            path: path.clone(),
            reason,
        };
        let text = std::fs::read(path).map_err(|e| err(e.to_string()))?;
        let (_, pem) = x509_parser::pem::parse_x509_pem(&text).map_err(|e| err(e.to_string()))?;
        let cert = pem.parse_x509().map_err(|e| err(e.to_string()))?;
        let cn = cert
            .subject()
            .iter_common_name()
            .next()
            .ok_or_else(|| err("it has no common name (CN)".into()))?
            .as_str()
            .map_err(|e| err(format!("its common name is not text: {e}")))?
            .to_string();
        if !keys::valid_sender(&cn) {
            return Err(err(format!(
                "its common name {cn:?} cannot name a command key"
            )));
        }
        Ok(cn)
    }

    /// Sets the Zenoh keys of a mutually authenticated TLS client.
    fn configure(&self, c: &mut zenoh::Config) -> Result<(), ClientError> {
        let file = |p: &std::path::Path| serde_json::to_string(&p.to_string_lossy()).map_err(z);
        for (key, value) in [
            ("transport/link/protocols", "[\"tls\"]".to_string()),
            ("scouting/gossip/enabled", "false".into()),
            ("transport/link/tls/root_ca_certificate", file(&self.ca)?),
            (
                "transport/link/tls/connect_certificate",
                file(&self.certificate)?,
            ),
            (
                "transport/link/tls/connect_private_key",
                file(&self.private_key)?,
            ),
            ("transport/link/tls/enable_mtls", "true".into()),
            ("transport/link/tls/verify_name_on_connect", "true".into()),
        ] {
            c.insert_json5(key, &value)
                .map_err(|e| ClientError::Zenoh(format!("{key} = {value}: {e}")))?;
        }
        Ok(())
    }
}

/// A connection to one cell.
#[derive(Debug)]
pub struct Client {
    session: zenoh::Session,
    cell: String,
    sender: String,
}

/// The sender of a client without a certificate: `$TANDEM_SENDER` if set, else this.
pub const DEFAULT_SENDER: &str = "anonymous";

fn z(e: impl core::fmt::Display) -> ClientError {
    ClientError::Zenoh(e.to_string())
}

impl Client {
    /// Connects to cell `cell` through the gateways at `endpoints` (`tcp/10.0.0.1:7447`);
    /// with none, Zenoh's multicast scouting finds them. Plain Zenoh: for a cell with
    /// `[security] mode = "mtls"` use [`Client::connect_tls`].
    pub async fn connect(cell: &str, endpoints: &[String]) -> Result<Client, ClientError> {
        Self::connect_tls(cell, endpoints, None).await
    }

    /// Connects as [`Client::connect`] does; with `tls`, over TLS links only, presenting the
    /// operator's or observer's certificate (mTLS, docs/security.md). The session never listens:
    /// it only dials the gateways.
    ///
    /// The sender of its commands (the last chunk of their keys): with `tls`, the common name
    /// of the certificate (the cell's access control lets an operator query only the keys that
    /// name its own); without, `$TANDEM_SENDER`, else [`DEFAULT_SENDER`], or what
    /// [`Client::with_sender`] sets (not authenticated: docs/security.md, "Commands with
    /// identity").
    pub async fn connect_tls(
        cell: &str,
        endpoints: &[String],
        tls: Option<&Tls>,
    ) -> Result<Client, ClientError> {
        let mut config = zenoh::Config::default();
        config.insert_json5("mode", "\"peer\"").map_err(z)?;
        config.insert_json5("listen/endpoints", "[]").map_err(z)?;
        if !endpoints.is_empty() {
            let list = serde_json::to_string(endpoints).map_err(z)?;
            config.insert_json5("connect/endpoints", &list).map_err(z)?;
            config
                .insert_json5("scouting/multicast/enabled", "false")
                .map_err(z)?;
        }
        let sender = match tls {
            Some(t) => {
                t.configure(&mut config)?;
                t.common_name()?
            }
            None => std::env::var("TANDEM_SENDER")
                .ok()
                .map(|s| s.trim().to_string())
                .filter(|s| !s.is_empty())
                .unwrap_or_else(|| DEFAULT_SENDER.to_string()),
        };
        if !keys::valid_sender(&sender) {
            return Err(ClientError::Sender(sender));
        }
        let session = zenoh::open(config).await.map_err(z)?;
        Ok(Client {
            session,
            cell: cell.into(),
            sender,
        })
    }

    /// Names the sender of this client's commands (a client without a certificate; with one,
    /// any other name than its common name is refused by the cell's access control: the
    /// commands get no reply).
    pub fn with_sender(mut self, sender: &str) -> Result<Client, ClientError> {
        if !keys::valid_sender(sender) {
            return Err(ClientError::Sender(sender.into()));
        }
        self.sender = sender.into();
        Ok(self)
    }

    /// The sender of this client's commands.
    pub fn sender(&self) -> &str {
        &self.sender
    }

    /// Sends `line` (`MC_MoveAbsolute --position 10`, the names and parameters of scripts) to
    /// `object` of `node` and returns when the node applied it.
    pub async fn command(
        &self,
        node: &str,
        object: &str,
        line: &str,
        timeout: Duration,
    ) -> Result<Accepted, ClientError> {
        let key = keys::command(&self.cell, node, object, &self.sender);
        let replies = self
            .session
            .get(&key)
            .payload(line)
            .timeout(timeout)
            .await
            .map_err(z)?;
        let reply = tokio::time::timeout(timeout, replies.recv_async())
            .await
            .map_err(|_| ClientError::Timeout {
                what: format!("{key}: no reply within {timeout:?}"),
            })?
            .map_err(|_| {
                ClientError::Unreachable(format!(
                    "{key}: no gateway answered (is the node's host up? `tandem status` there)"
                ))
            })?;
        let sample = reply.result().map_err(|e| {
            ClientError::Zenoh(
                e.payload()
                    .try_to_string()
                    .map(|s| s.to_string())
                    .unwrap_or_default(),
            )
        })?;
        let text = sample
            .payload()
            .try_to_string()
            .map_err(|e| ClientError::Malformed(e.to_string()))?;
        let r: ReplyJson = serde_json::from_str(&text)
            .map_err(|e| ClientError::Malformed(format!("{e}: {text}")))?;
        match r.outcome.as_str() {
            "accepted" => Ok(Accepted {
                job: r.job,
                t_ns: r.t_ns,
                message: r.message,
            }),
            "rejected" => Err(ClientError::Rejected {
                error_id: r.error_id,
                message: r.message,
            }),
            "invalid" => Err(ClientError::Invalid(r.message)),
            "busy" | "unreachable" => Err(ClientError::Unreachable(r.message)),
            other => Err(ClientError::Malformed(format!("outcome `{other}`"))),
        }
    }

    /// Sends `line` and awaits the job: `Ok` when it is done or reached its goal (InVelocity,
    /// InGear, InSync, Status TRUE), [`ClientError::JobFailed`] when it ended in error or was
    /// aborted. An instruction without a job returns at once with no events.
    pub async fn execute(
        &self,
        node: &str,
        object: &str,
        line: &str,
        timeout: Duration,
    ) -> Result<JobOutcome, ClientError> {
        // Subscribe first, so no event of the job is missed.
        let events = self
            .session
            .declare_subscriber(keys::events(&self.cell, node, object))
            .await
            .map_err(z)?;
        let accepted = self.command(node, object, line, timeout).await?;
        let mut out = JobOutcome {
            job: accepted.job,
            events: Vec::new(),
        };
        if accepted.job == 0 {
            return Ok(out);
        }
        let deadline = tokio::time::Instant::now() + timeout;
        loop {
            let sample = tokio::time::timeout_at(deadline, events.recv_async())
                .await
                .map_err(|_| ClientError::Timeout {
                    what: format!(
                        "job {} of {node}/{object} did not end within {timeout:?}",
                        accepted.job
                    ),
                })?
                .map_err(z)?;
            let text = sample
                .payload()
                .try_to_string()
                .map_err(|e| ClientError::Malformed(e.to_string()))?
                .to_string();
            let Ok(e) = serde_json::from_str::<EventJson>(&text) else {
                continue;
            };
            // The gateway's `command` record of this very command is not a job event.
            if e.job != accepted.job || e.outcome == "command" {
                continue;
            }
            let outcome = e.outcome.clone();
            out.events.push(e);
            match outcome.as_str() {
                "done" | "reached" => return Ok(out),
                "error" | "aborted" => {
                    let last = out.events.last().cloned();
                    return Err(ClientError::JobFailed {
                        outcome,
                        error_id: last
                            .as_ref()
                            .map(|x| x.error_id.clone())
                            .unwrap_or_default(),
                        message: last.map(|x| x.message).unwrap_or_default(),
                    });
                }
                _ => {}
            }
        }
    }

    /// The state of every axis the gateways publish, collected for `window` (at least one
    /// telemetry period), sorted by node and axis.
    pub async fn states(&self, window: Duration) -> Result<Vec<AxisState>, ClientError> {
        let sub = self
            .session
            .declare_subscriber(format!("tandem/{}/*/*/state", self.cell))
            .await
            .map_err(z)?;
        let mut seen: std::collections::BTreeMap<(String, String), AxisState> =
            std::collections::BTreeMap::new();
        let deadline = tokio::time::Instant::now() + window;
        while let Ok(Ok(s)) = tokio::time::timeout_at(deadline, sub.recv_async()).await {
            let Ok(text) = s.payload().try_to_string() else {
                continue;
            };
            if let Ok(a) = serde_json::from_str::<AxisState>(&text) {
                seen.insert((a.node.clone(), a.axis.clone()), a);
            }
        }
        Ok(seen.into_values().collect())
    }

    /// The hosts whose gateways are alive (liveliness tokens).
    pub async fn alive_hosts(&self, timeout: Duration) -> Result<Vec<String>, ClientError> {
        let replies = self
            .session
            .liveliness()
            .get(keys::alive_all(&self.cell))
            .timeout(timeout)
            .await
            .map_err(z)?;
        let mut hosts = Vec::new();
        while let Ok(r) = replies.recv_async().await {
            if let Ok(s) = r.result() {
                if let Some(h) = s.key_expr().as_str().rsplit('/').next() {
                    hosts.push(h.to_string());
                }
            }
        }
        hosts.sort();
        Ok(hosts)
    }

    /// Closes the session.
    pub async fn close(self) -> Result<(), ClientError> {
        self.session.close().await.map_err(z)
    }
}
