//! tandem-runtime: runs the engine. For now the deterministic simulator ([`sim`]): the
//! configured axes of a cell on virtual time, driven by a script, traced to CSV.

pub mod sim;
