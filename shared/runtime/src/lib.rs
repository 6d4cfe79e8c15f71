//! tandem-runtime: runs the engine. [`exec`] is the cyclic executive of one node (or of a whole
//! cell), free of IO and clocks; [`sim`] drives it on virtual time from a script and traces it
//! to CSV.

pub mod exec;
mod objects;
pub mod sim;
