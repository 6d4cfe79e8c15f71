//! The commands over Zenoh, through the cell's gateways, from any machine of the cell network
//! (`--zenoh`): `status` of every host and `cmd`.

use crate::cmd::CmdRequest;
use crate::error::CliError;
use crate::live::{load, table_row, HEADER};
use std::io::Write;
use std::path::Path;
use std::path::PathBuf;
use std::time::Duration;
use tandem_config::{Cell, SecurityMode};
use tandem_runtime::exec::Secs;
use tracing::debug;

/// The certificate of `--zenoh` for a cell in mTLS mode: `--ca`, `--cert`, `--key`, else
/// `$TANDEM_CA`, `$TANDEM_CERT`, `$TANDEM_KEY`; the CA defaults to the cell's `[security] ca`.
#[derive(Debug, Clone, Default)]
pub struct TlsArgs {
    /// The cell CA's certificate.
    pub ca: Option<PathBuf>,
    /// An operator's or observer's certificate.
    pub cert: Option<PathBuf>,
    /// Its private key.
    pub key: Option<PathBuf>,
}

impl TlsArgs {
    /// `given`, else the environment variable `var`.
    fn or_env(given: &Option<PathBuf>, var: &str) -> Option<PathBuf> {
        given
            .clone()
            .or_else(|| std::env::var_os(var).map(PathBuf::from))
    }

    /// The client's TLS for `cell`: none for a plain cell; for an mTLS cell the certificate and
    /// key are required.
    pub fn resolve(&self, cell: &Cell) -> Result<Option<tandem_client::Tls>, CliError> {
        if cell.security.mode == SecurityMode::Plain {
            return Ok(None);
        }
        let cert = Self::or_env(&self.cert, "TANDEM_CERT");
        let key = Self::or_env(&self.key, "TANDEM_KEY");
        let ca = Self::or_env(&self.ca, "TANDEM_CA").unwrap_or_else(|| cell.security.ca.clone());
        match (cert, key) {
            (Some(certificate), Some(private_key)) => Ok(Some(tandem_client::Tls {
                ca,
                certificate,
                private_key,
            })),
            _ => Err(CliError::TlsIncomplete(
                "the cell's Zenoh links are mTLS ([security]): give an operator's or observer's \
                 certificate with --cert and --key (or TANDEM_CERT and TANDEM_KEY), made by \
                 `tandem certs`",
            )),
        }
    }
}

/// Connects to the cell's gateways, with the client certificate when the cell runs mTLS (the
/// sender of its commands is then the certificate's common name).
async fn connect(
    cell: &Cell,
    endpoints: &[String],
    tls: &TlsArgs,
) -> Result<tandem_client::Client, CliError> {
    let t = tls.resolve(cell)?;
    let client = tandem_client::Client::connect_tls(
        &cell.name,
        &with_cell_endpoints(cell, endpoints),
        t.as_ref(),
    )
    .await?;
    // With a certificate the sender is its common name (the access control checks it);
    // without, the same as `tandem cmd` over iceoryx2 says.
    Ok(match t {
        Some(_) => client,
        None => client.with_sender(&crate::cmd::sender())?,
    })
}

/// The given endpoints plus every host's listen endpoints from the cell file (with none given
/// and none in the cell: multicast scouting).
fn with_cell_endpoints(cell: &Cell, given: &[String]) -> Vec<String> {
    let mut all: Vec<String> = given.to_vec();
    for e in cell.host_listen.iter().flatten() {
        if !all.contains(e) {
            all.push(e.clone());
        }
    }
    all
}

fn runtime() -> Result<tokio::runtime::Runtime, CliError> {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(CliError::Runtime)
}

/// Closes the client's session; a failure only matters to the diagnostics, the command's
/// outcome is known.
async fn close(c: tandem_client::Client) {
    if let Err(e) = c.close().await {
        debug!(error = %e, "closing the Zenoh session");
    }
}

/// `tandem cmd --zenoh`: the same as [`crate::cmd::cmd`] over Zenoh, through the cell's
/// gateways, from any machine.
pub fn cmd_zenoh(
    cell_path: &Path,
    endpoints: &[String],
    tls: &TlsArgs,
    r: &CmdRequest,
    out: &mut impl Write,
) -> Result<(), CliError> {
    let cell = load(cell_path)?;
    let (node, object) = r.node_object()?;
    let span = r.span(node, object);
    let _entered = span.enter();
    r.check(&cell)?;
    let line = r.line();
    let (target, instruction) = (&r.target, &r.instruction);
    runtime()?.block_on(async {
        let c = connect(&cell, endpoints, tls).await?;
        let result = if r.wait {
            c.execute(node, object, &line, r.timeout).await.map(|o| {
                span.record("job", o.job);
                outln!(out, "{target} {instruction}: accepted, job {}", o.job);
                for e in &o.events {
                    outln!(out, "t={} {}", Secs(e.t_ns), e.message);
                }
            })
        } else {
            c.command(node, object, &line, r.timeout).await.map(|a| {
                span.record("job", a.job);
                outln!(
                    out,
                    "{target} {instruction}: accepted, job {} at t={}{}",
                    a.job,
                    Secs(a.t_ns),
                    crate::cmd::Said(&a.message)
                );
            })
        };
        close(c).await;
        Ok::<(), CliError>(result?)
    })
}

/// `tandem status --zenoh`: every axis of every host, from the gateways' telemetry.
pub fn status_zenoh(
    cell_path: &Path,
    endpoints: &[String],
    tls: &TlsArgs,
    out: &mut impl Write,
) -> Result<(), CliError> {
    let cell = load(cell_path)?;
    let (states, hosts) = runtime()?.block_on(async {
        let c = connect(&cell, endpoints, tls).await?;
        let window = Duration::from_secs_f64((3.0 / cell.telemetry_hz).max(0.3));
        let states = c.states(window).await?;
        let hosts = c.alive_hosts(Duration::from_secs(2)).await?;
        close(c).await;
        Ok::<_, CliError>((states, hosts))
    })?;
    outln!(
        out,
        "hosts alive: {}",
        if hosts.is_empty() {
            "none".to_string()
        } else {
            hosts.join(", ")
        }
    );
    outln!(out, "{HEADER}");
    for a in &states {
        let sync = if a.sync == "none" {
            "-"
        } else {
            a.sync.as_str()
        };
        let row = table_row(
            &a.node,
            &a.axis,
            &a.state,
            (a.position, a.velocity),
            sync,
            a.alarm,
            a.job,
        );
        outln!(out, "{row}");
    }
    let missing: Vec<String> = cell
        .hosts
        .iter()
        .filter(|h| !hosts.contains(h))
        .cloned()
        .collect();
    if missing.is_empty() {
        Ok(())
    } else {
        Err(CliError::HostsUnreachable(missing))
    }
}
