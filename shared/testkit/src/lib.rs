//! What tandem's tests share, in one crate that the others take as a dev-dependency:
//!
//! - [`counting`]: the counting global allocator of the zero-allocation tests (the engine's
//!   cyclic path and the runtime's executives must not allocate), installed per test binary with
//!   [`counting_allocator!`];
//! - `rig` and `strategies` (feature `motion`): the axis rig of the motion tests (an axis,
//!   or a leader with a synchronous follower, stepped at 1 ms with their job events collected)
//!   and the proptest strategies of machine dynamics;
//! - [`process`], [`workspace`] and [`tandem`]: the system tests' helpers that find the
//!   workspace's programs, start them with their output collected, and wait for them and for
//!   conditions, always with a timeout; [`scratch`]: their temporary directories;
//!   [`node_log`]: reading the logs of the nodes; [`netns`]: a network namespace with a veth
//!   pair for the EtherCAT tests.
//!
//! A test counting what a piece of code allocates:
//!
//! ```
//! use tandem_testkit::counting::measure;
//!
//! tandem_testkit::counting_allocator!();
//!
//! fn main() {
//!     let mut window = [0.0f64; 64];
//!     let counts = measure(|| {
//!         for (k, x) in window.iter_mut().enumerate() {
//!             *x = (k as f64 * 1e-3).sin();
//!         }
//!     });
//!     assert_eq!(counts.allocations, 0);
//!     assert_eq!(counts.deallocations, 0);
//! }
//! ```
// The kit exists to fail the tests that use it, by panicking with what was wrong.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
#![warn(missing_docs)]

pub mod counting;
pub mod netns;
pub mod node_log;
pub mod process;
#[cfg(feature = "motion")]
pub mod rig;
pub mod scratch;
#[cfg(feature = "motion")]
pub mod strategies;
pub mod tandem;
pub mod workspace;
