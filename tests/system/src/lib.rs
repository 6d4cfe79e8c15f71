//! tandem's system tests, in `tests/`: they run the workspace's programs (`tandem`,
//! `tandem-node`, `tandem-gateway`) as real processes, so build those first, in the profile of
//! the tests:
//!
//! ```text
//! cargo build --release --workspace --bins
//! cargo test --release -p tandem-system-tests
//! ```
//!
//! (`tests/run.sh` does both for the whole workspace.)
//!
//! - `tests/processes.rs`: the process set of one host, `tandem up` with three nodes over
//!   iceoryx2, against `tandem sim`; a killed node and its recovery; refused configurations
//!   and commands.
//! - `tests/retain.rs`: a node's retained absolute encoder adjustment, killed with SIGKILL
//!   while it stores, restarted: homed at the last completed adjustment, never a torn one; a
//!   changed mechanics configuration voids it, a damaged record is reported and not used.
//! - `tests/hosts.rs`: two and three hosts in network namespaces (root needed), over Zenoh
//!   through the gateways; the Python observer `tests/python/observe.py`; a cut link and a
//!   killed gateway.
//! - `tests/drives.rs`: axes on simulated CiA 402 drives under `tandem up`.
//! - `tests/signals.rs`: input signals and output edges on iceoryx2 and Zenoh.
//! - `tests/security.rs`: an mTLS cell against a client without a certificate, an observer and
//!   an operator, in network namespaces; the attacked run against the plain run.
//! - `tests/identity.rs`: commands audited under the certificate's name, never the claimed one.
//! - `tests/lv_forgery.rs`: forged leading values from a third namespace, all refused.
//! - `tests/command_flood.rs`: 10,000 commands in 10 s; every command answered.
//! - `tests/record_full.rs`: `--record` on a 20 MB tmpfs that fills and frees: whole rows,
//!   exact counts of the lost ones, recording resumes.
//! - `tests/watchdog.rs`: a stalled node reported, rejoining the grid and restarted; one
//!   supervisor per host; a too small /dev/shm named.
//!
//! The helpers they share are in `tandem-testkit` (`process`, `workspace`, `tandem`). This
//! library itself is empty: a package needs a target, and the tests are its integration tests.
#![warn(missing_docs)]
