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
//!
//! The helpers they share are in `tandem-testkit` (`process`, `workspace`, `tandem`). This
//! library itself is empty: a package needs a target, and the tests are its integration tests.
#![warn(missing_docs)]
