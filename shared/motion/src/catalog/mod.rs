//! Catalogues from the manuals, as data: technology alarms with their reactions and the status
//! word layout ([`alarm`]), the ErrorIDs of jobs ([`error_id`]) and the override tables that say
//! which running job a new job aborts ([`override_table`]). The lowest layer: it imports nothing
//! else of the crate.

pub mod alarm;
pub mod error_id;
pub mod override_table;
