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
//! The design splits the wire (`tandem-protocol`) from the iceoryx2 adapter (`tandem-ipc`); the
//! two are one crate until Zenoh arrives, since the adapter is a few functions.

pub mod ipc;
pub mod json;
pub mod keys;
pub mod names;
pub mod wire;
