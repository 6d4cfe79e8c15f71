//! Catalogues from the manuals, as data: technology alarms with their reactions and the status
//! word layout ([`alarm`]), the ErrorIDs of jobs ([`error_id`]), the error codes of the Beckhoff
//! hydraulic positioning library ([`hyd_error`]) and the override tables that say which running
//! job a new job aborts ([`override_table`]). The lowest layer: it imports nothing
//! else of the crate.

pub mod alarm;
pub mod error_id;
pub mod hyd_error;
pub mod override_table;
