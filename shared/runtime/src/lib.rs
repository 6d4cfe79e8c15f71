//! tandem-runtime: runs the engine. [`exec`] is the cyclic executive of one node (or of a whole
//! cell), free of IO and clocks; [`sim`] drives it on virtual time from a script and traces it
//! to CSV.
//!
//! ```
//! let cell = tandem_config::parse(
//!     "demo.toml",
//!     r#"
//! [cell]
//! name = "demo"
//!
//! [[nodes]]
//! name = "n"
//! cycle_us = 1000
//!
//! [axes.x]
//! node = "n"
//!
//! [axes.x.dynamics]
//! max_velocity = 100.0
//! max_acceleration = 1000.0
//! max_deceleration = 1000.0
//! max_jerk = 10000.0
//! velocity = 50.0
//! acceleration = 500.0
//! deceleration = 500.0
//! jerk = 5000.0
//! emergency_deceleration = 2000.0
//! "#,
//! )
//! .unwrap();
//! let script = tandem_config::script::parse_cell(
//!     "demo-script.toml",
//!     r#"
//! [sim]
//! duration = 0.01
//!
//! [[at]]
//! t = 0
//! axis = "x"
//! instruction = "MC_Power"
//! "#,
//!     &cell,
//! )
//! .unwrap();
//! let (mut trace, mut log) = (Vec::new(), Vec::new());
//! let summary = tandem_runtime::sim::run(&cell, &script, &mut trace, &mut log).unwrap();
//! assert_eq!((summary.rows, summary.commands, summary.rejected), (11, 1, 0));
//! let trace = String::from_utf8(trace).unwrap();
//! assert!(trace.starts_with("time_s,x.state,x.position"));
//! ```

pub mod drives;
mod error;
pub mod exec;
mod inputs;
pub mod lvgate;
mod notes;
mod objects;
mod outputs;
pub mod sim;
mod values;

pub use error::{ExecError, SimError};
