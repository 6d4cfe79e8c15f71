//! The leading-value gates' refusals in the node's health (docs/processes.md, "Refused
//! samples").

use crate::ports::LeaderIn;
use tandem_protocol::wire::NodeHealth;
use tandem_runtime::lvgate::GateCounts;

/// Writes the refusals of every gate of `leaders` into `health` by kind.
pub(crate) fn count(leaders: &[LeaderIn], health: &mut NodeHealth) {
    let mut all = GateCounts::default();
    for x in leaders {
        all.add(&x.gate.counts);
    }
    health.lv_future = all.future;
    health.lv_stale = all.stale;
    health.lv_sequence = all.sequence;
    health.lv_jump = all.jump;
    health.lv_reanchored = all.reanchored;
}
