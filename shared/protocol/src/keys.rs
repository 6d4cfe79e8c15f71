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

/// The command key of a technology object for commands of `sender`: a command in, the job id
/// or ErrorID out. The sender is part of the key so that, in an mTLS cell, the access control
/// binds it to the querier's certificate: the operator whose certificate's common name is `X`
/// may query only keys ending in `/cmd/X` ([`sender_commands`]; docs/security.md, "Commands
/// with identity").
pub fn command(cell: &str, node: &str, object: &str, sender: &str) -> String {
    format!("tandem/{cell}/{node}/{object}/cmd/{sender}")
}

/// The command key without a sender (plain cells only; the sender then comes from the query's
/// attachment or JSON payload, docs/gateway.md "Command rate").
pub fn command_unbound(cell: &str, node: &str, object: &str) -> String {
    format!("tandem/{cell}/{node}/{object}/cmd")
}

/// All command keys of `node`, of any sender (one queryable per node).
pub fn commands(cell: &str, node: &str) -> String {
    command(cell, node, "*", "*")
}

/// All command keys of `node` without a sender (plain cells only).
pub fn commands_unbound(cell: &str, node: &str) -> String {
    command_unbound(cell, node, "*")
}

/// Whether `sender` can be the last chunk of a command key: not empty, no `/`, none of Zenoh's
/// wildcard or reserved characters (`*`, `$`, `?`, `#`), not starting with `@` (a verbatim
/// chunk), no control characters.
pub fn valid_sender(sender: &str) -> bool {
    !sender.is_empty()
        && !sender.starts_with('@')
        && !sender
            .chars()
            .any(|c| matches!(c, '/' | '*' | '$' | '?' | '#') || c.is_control())
}

/// A parsed command key: the node, the object, and the sender (`None` for a key without one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CommandKey<'a> {
    /// The node serving the object.
    pub node: &'a str,
    /// The technology object.
    pub object: &'a str,
    /// The sender named by the key (bound to the certificate in an mTLS cell).
    pub sender: Option<&'a str>,
}

/// The node, object and sender of a command key (`None` if it is not one of `cell`).
pub fn parse_command<'a>(cell: &str, key: &'a str) -> Option<CommandKey<'a>> {
    let rest = key
        .strip_prefix("tandem/")?
        .strip_prefix(cell)?
        .strip_prefix('/')?;
    let (node, rest) = rest.split_once('/')?;
    let (object, rest) = rest.split_once('/')?;
    let sender = match rest {
        "cmd" => None,
        _ => Some(rest.strip_prefix("cmd/").filter(|s| valid_sender(s))?),
    };
    Some(CommandKey {
        node,
        object,
        sender,
    })
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

/// Every command key of the cell, of every sender (what the gateways serve).
pub fn all_commands(cell: &str) -> String {
    command(cell, "*", "*", "*")
}

/// Every command key of `sender` (what the operator whose certificate's common name is
/// `sender` may query in an mTLS cell).
pub fn sender_commands(cell: &str, sender: &str) -> String {
    command(cell, "*", "*", sender)
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
        let c = command("line", "followers", "feed", "operator:alice");
        assert_eq!(c, "tandem/line/followers/feed/cmd/operator:alice");
        let parsed = parse_command("line", &c).unwrap();
        assert_eq!(
            (parsed.node, parsed.object, parsed.sender),
            ("followers", "feed", Some("operator:alice"))
        );
        let unbound = command_unbound("line", "followers", "feed");
        let parsed = parse_command("line", &unbound).unwrap();
        assert_eq!(
            (parsed.node, parsed.object, parsed.sender),
            ("followers", "feed", None)
        );
        assert_eq!(parse_command("line", "tandem/line/followers/cmd"), None);
        assert_eq!(parse_command("line", "tandem/line/a/b/cmd/"), None);
        assert_eq!(parse_command("line", "tandem/line/a/b/cmd/x/y"), None);
        assert_eq!(parse_command("line", "tandem/line/a/b/state"), None);
        assert_eq!(parse_command("other", &c), None);
        assert_eq!(all_commands("line"), "tandem/line/*/*/cmd/*");
        assert_eq!(commands("line", "n"), "tandem/line/n/*/cmd/*");
        assert_eq!(
            sender_commands("line", "operator:bob"),
            "tandem/line/*/*/cmd/operator:bob"
        );
        for ok in ["operator:alice", "root@ctl1", "anonymous"] {
            assert!(valid_sender(ok), "{ok}");
        }
        for bad in ["", "a/b", "*", "a*", "$x", "a?", "#", "@x", "a\nb"] {
            assert!(!valid_sender(bad), "{bad:?}");
        }
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
