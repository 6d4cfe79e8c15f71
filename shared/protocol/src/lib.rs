//! tandem-protocol: what travels between the processes of a cell.
//!
//! - [`names`]: the one place that names iceoryx2 services (and, later, Zenoh key expressions).
//! - [`wire`]: the `#[repr(C)]` payloads: leading-value samples, command requests and replies,
//!   job events and alarms, telemetry snapshots, output edges and measured values.
//! - [`ipc`]: opening those services with the settings they need (history, safe overflow),
//!   shared by `tandem-node` and the `tandem` CLI.
//! - [`keys`]: every Zenoh key expression; [`json`]: what observers read and send on them (JSON,
//!   no Rust types needed), and the binary codec of leading values between hosts.
//!
//! The wire and its iceoryx2 adapter are one crate: the adapter is a few functions.
//!
//! ```
//! use tandem_protocol::json::{decode_leading_value, encode_leading_value, DecodeError};
//! use tandem_protocol::wire::{LeadingValueSample, Text, LV_VALID};
//!
//! // A leading value as a node publishes it, through the binary codec between hosts.
//! let s = LeadingValueSample {
//!     t_ns: 1_000_000,
//!     seq: 1,
//!     p: 90.0,
//!     v: 360.0,
//!     a: 0.0,
//!     modulo_start: 0.0,
//!     modulo_length: 360.0,
//!     status: LV_VALID,
//!     leader: 0,
//! };
//! let bytes = encode_leading_value(&s);
//! assert_eq!(decode_leading_value(&bytes), Ok(s));
//! assert_eq!(decode_leading_value(&bytes[..10]), Err(DecodeError::Size { bytes: 10 }));
//! // Fixed-size text, cut at a character boundary.
//! assert_eq!(Text::new("MC_Halt").as_str(), "MC_Halt");
//! ```

pub mod ipc;
pub mod json;
pub mod keys;
pub mod names;
pub mod rate;
pub mod wire;
