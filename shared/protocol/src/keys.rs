//! Every Zenoh key expression of a cell (docs/gateway.md, "Observation and commands (JSON)"). Everything of cell `c` is under
//! `tandem/<c>/`, so `tandem/<c>/**` observes the whole cell.

/// Leading values of `leader` between hosts (binary, RealTime, express, drop on congestion).
pub fn leading_value(cell: &str, leader: &str, actual: bool) -> String {
    if actual {
        format!("tandem/{cell}/lv/{leader}/actual")
    } else {
        format!("tandem/{cell}/lv/{leader}")
    }
}

/// All leading values of the cell.
pub fn leading_values(cell: &str) -> String {
    format!("tandem/{cell}/lv/**")
}

/// The leader and coupling of a leading-value key (`None` if it is not one of `cell`).
pub fn parse_leading_value<'a>(cell: &str, key: &'a str) -> Option<(&'a str, bool)> {
    let rest = key
        .strip_prefix("tandem/")?
        .strip_prefix(cell)?
        .strip_prefix("/lv/")?;
    match rest.strip_suffix("/actual") {
        Some(leader) => Some((leader, true)),
        None if !rest.contains('/') => Some((rest, false)),
        None => None,
    }
}

/// The state of a technology object, as JSON, at the telemetry rate.
pub fn state(cell: &str, node: &str, object: &str) -> String {
    format!("tandem/{cell}/{node}/{object}/state")
}

/// Job events and alarms of a technology object, as JSON, as they happen.
pub fn events(cell: &str, node: &str, object: &str) -> String {
    format!("tandem/{cell}/{node}/{object}/events")
}

/// The queryable of a technology object: a command in, the job id or ErrorID out.
pub fn command(cell: &str, node: &str, object: &str) -> String {
    format!("tandem/{cell}/{node}/{object}/cmd")
}

/// All command keys of `node` (one queryable per node).
pub fn commands(cell: &str, node: &str) -> String {
    format!("tandem/{cell}/{node}/*/cmd")
}

/// The node and object of a command key.
pub fn parse_command<'a>(cell: &str, key: &'a str) -> Option<(&'a str, &'a str)> {
    let rest = key
        .strip_prefix("tandem/")?
        .strip_prefix(cell)?
        .strip_prefix('/')?;
    let rest = rest.strip_suffix("/cmd")?;
    let (node, object) = rest.split_once('/')?;
    (!object.contains('/')).then_some((node, object))
}

/// Each edge of signal `signal` (an input or output of `node`'s process image), as JSON, as it
/// happens.
pub fn signal(cell: &str, node: &str, signal: &str) -> String {
    format!("tandem/{cell}/{node}/{signal}/signal")
}

/// Every signal of the cell.
pub fn signals(cell: &str) -> String {
    format!("tandem/{cell}/*/*/signal")
}

/// A node's health (cycle, compute, lateness, overruns), as JSON.
pub fn health(cell: &str, node: &str) -> String {
    format!("tandem/{cell}/{node}/health")
}

/// A node's log lines, as JSON.
pub fn log(cell: &str, node: &str) -> String {
    format!("tandem/{cell}/{node}/log")
}

/// A gateway's own health (counters, clock offsets), as JSON.
pub fn gateway(cell: &str, host: &str) -> String {
    format!("tandem/{cell}/gateway/{host}")
}

/// The clock queryable of a host's gateway (replies with its clock, for the offset).
pub fn clock(cell: &str, host: &str) -> String {
    format!("tandem/{cell}/clock/{host}")
}

/// The liveliness token of a host (its gateway is up).
pub fn alive(cell: &str, host: &str) -> String {
    format!("tandem/{cell}/alive/{host}")
}

/// All liveliness tokens of the cell.
pub fn alive_all(cell: &str) -> String {
    format!("tandem/{cell}/alive/*")
}

/// Every command key of the cell (what an operator may query).
pub fn all_commands(cell: &str) -> String {
    command(cell, "*", "*")
}

/// Every clock queryable of the cell (what the gateways ask each other).
pub fn all_clocks(cell: &str) -> String {
    clock(cell, "*")
}

/// Every key an observer may subscribe to, one expression per kind: the state of every object,
/// every node's health, job events and log, every signal, every gateway's counters. A client
/// of a cell with access control subscribes to these (or narrower ones): a broader expression
/// such as `tandem/<c>/**` is refused as a whole (docs/security.md).
pub fn observable(cell: &str) -> [String; 6] {
    [
        state(cell, "*", "*"),
        health(cell, "*"),
        events(cell, "*", "*"),
        log(cell, "*"),
        signals(cell),
        gateway(cell, "*"),
    ]
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn keys_parse_back() {
        let k = leading_value("line", "master", false);
        assert_eq!(parse_leading_value("line", &k), Some(("master", false)));
        let k = leading_value("line", "master", true);
        assert_eq!(parse_leading_value("line", &k), Some(("master", true)));
        assert_eq!(parse_leading_value("other", &k), None);
        assert_eq!(parse_leading_value("line", "tandem/line/lv/a/b"), None);
        let c = command("line", "followers", "feed");
        assert_eq!(parse_command("line", &c), Some(("followers", "feed")));
        assert_eq!(parse_command("line", "tandem/line/followers/cmd"), None);
        assert_eq!(all_commands("line"), "tandem/line/*/*/cmd");
        assert_eq!(
            observable("line"),
            [
                "tandem/line/*/*/state",
                "tandem/line/*/health",
                "tandem/line/*/*/events",
                "tandem/line/*/log",
                "tandem/line/*/*/signal",
                "tandem/line/gateway/*",
            ]
        );
    }
}
