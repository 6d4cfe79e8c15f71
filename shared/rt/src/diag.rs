//! Diagnostics output of the services and the CLI: `tracing` events and spans written to
//! stderr, as text or as one JSON object per line, filtered `RUST_LOG`-style.
//!
//! The filter is read from `TANDEM_LOG`, else `RUST_LOG`, else the service's default (for
//! example `info`); its syntax is `tracing_subscriber`'s `EnvFilter`
//! (`warn,tandem_node=debug`). The cyclic thread of a node never calls `tracing`: it hands
//! fixed-size records to a non-cyclic thread, which emits them.

use tracing_subscriber::EnvFilter;

/// How diagnostics are written.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Default)]
pub enum LogFormat {
    /// One human-readable line per event: time, level, target, spans, message and fields.
    #[default]
    Text,
    /// One JSON object per line (`timestamp`, `level`, `target`, `fields`, `spans`).
    Json,
}

impl LogFormat {
    /// Parses `text` or `json`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "text" => Some(Self::Text),
            "json" => Some(Self::Json),
            _ => None,
        }
    }
}

/// Installs the process' subscriber. `default_filter` applies when neither `TANDEM_LOG` nor
/// `RUST_LOG` is set. A second call in the same process (tests) changes nothing and returns
/// `false`; an unparsable filter falls back to `default_filter` and is reported once.
pub fn init(default_filter: &str, format: LogFormat) -> bool {
    let (filter, bad) = match std::env::var("TANDEM_LOG").or_else(|_| std::env::var("RUST_LOG")) {
        Ok(s) => match EnvFilter::try_new(&s) {
            Ok(f) => (f, None),
            Err(e) => (EnvFilter::new(default_filter), Some((s, e))),
        },
        Err(_) => (EnvFilter::new(default_filter), None),
    };
    let builder = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(false);
    let installed = match format {
        LogFormat::Text => builder.try_init().is_ok(),
        LogFormat::Json => builder.json().with_current_span(true).try_init().is_ok(),
    };
    if let Some((s, e)) = bad {
        tracing::warn!(filter = %s, error = %e, "log filter not understood; using the default");
    }
    installed
}
