//! Every service name of a cell. A cell's services live under `tandem/<cell>/`, so two cells on
//! one host never meet.

/// The leading values of `leader` (an axis or external encoder), for followers coupled by
/// setpoint (or by `actual` value).
pub fn leading_value(cell: &str, leader: &str, actual: bool) -> String {
    if actual {
        format!("tandem/{cell}/lv/{leader}/actual")
    } else {
        format!("tandem/{cell}/lv/{leader}")
    }
}

/// Event: `node` published its leading values of a cycle (one notification per cycle), so a
/// gateway forwards them at once instead of polling.
pub fn published(cell: &str, node: &str) -> String {
    format!("tandem/{cell}/node/{node}/published")
}

/// Request-response: the instructions addressed to the objects of `node`.
pub fn commands(cell: &str, node: &str) -> String {
    format!("tandem/{cell}/node/{node}/cmd")
}

/// Publish-subscribe: one telemetry snapshot of `node` per cycle.
pub fn telemetry(cell: &str, node: &str) -> String {
    format!("tandem/{cell}/node/{node}/telemetry")
}

/// Publish-subscribe: job events and alarms of `node`, as they happen.
pub fn events(cell: &str, node: &str) -> String {
    format!("tandem/{cell}/node/{node}/events")
}

/// Publish-subscribe: every edge of `node`'s signals, inputs and outputs of its process image.
pub fn signals(cell: &str, node: &str) -> String {
    format!("tandem/{cell}/node/{node}/signals")
}

/// Publish-subscribe: the switching edges of an output cam or cam track, or the measured
/// values of a measuring input, named `object`.
pub fn io(cell: &str, object: &str) -> String {
    format!("tandem/{cell}/io/{object}")
}

/// The iceoryx2 domain of host `host`: the prefix of every file its processes create. Each host
/// of a cell is a domain of its own, so two "hosts" on one machine (network namespaces share
/// /dev/shm) never see each other's services: leading values cross only through the gateways.
pub fn domain(host: &str) -> String {
    format!("tandem_{host}_")
}

/// The iceoryx2 node name of a tandem node process.
pub fn node(cell: &str, node: &str) -> String {
    format!("tandem/{cell}/{node}")
}
