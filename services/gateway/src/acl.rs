//! The Zenoh access control of a cell in mTLS mode (docs/security.md, "Keys per role"): a pure
//! function of the cell, so the rules and the keys the code uses come from the same place
//! (`tandem_protocol::keys`).
//!
//! Every gateway carries the same ACL: `default_permission: "deny"`, and one subject per
//! certificate common name (exact names, Zenoh has no patterns). The gateways are Zenoh peers,
//! so each link is checked by both ends, on the *remote* end's subject: ingress for what comes
//! from it, egress for what goes to it; declarations are allowed in both flows because a peer
//! forwards only to where a matching declaration came from.
//!
//! - **Host `h`** (CN `host:h`): puts the leading values of *its own* leaders only (a gateway
//!   of another host cannot steer a follower), subscribes to leading values, serves command
//!   and clock queryables, asks the others' clocks, declares its liveliness token.
//! - **Operator** (CN `operator:<name>`): queries the command keys that name it as sender
//!   (`tandem/<c>/*/*/cmd/operator:<name>`, a subject and a rule per operator), and observes.
//! - **Observer** (CN `observer:<name>`): subscribes to state, health, events, log, signals and
//!   the gateways' counters, and to the hosts' liveliness; nothing else.

use serde_json::{json, Value};
use tandem_config::security::{common_name, Role};
use tandem_config::{Cell, Leader};
use tandem_protocol::keys;

/// One rule: its id, the messages it allows, in which flows, on which keys.
fn rule(id: String, messages: &[&str], flows: &[&str], key_exprs: &[String]) -> Value {
    json!({
        "id": id,
        "permission": "allow",
        "flows": flows,
        "messages": messages,
        "key_exprs": key_exprs,
    })
}

const BOTH: &[&str] = &["ingress", "egress"];
const IN: &[&str] = &["ingress"];
const OUT: &[&str] = &["egress"];

/// The leading-value keys of the leaders hosted on host `h` (setpoint and actual).
pub fn own_leading_values(cell: &Cell, h: usize) -> Vec<String> {
    let leaders = (0..cell.axes.len())
        .map(|a| Leader::Axis(tandem_config::AxisIndex(a)))
        .chain((0..cell.encoders.len()).map(|e| Leader::Encoder(tandem_config::EncoderIndex(e))));
    let mut out = Vec::new();
    for l in leaders {
        let on_h = cell
            .leader_node(l)
            .and_then(|n| cell.nodes.get(n))
            .is_some_and(|n| n.host == h);
        if on_h {
            for actual in [false, true] {
                out.push(keys::leading_value(&cell.name, cell.leader_name(l), actual));
            }
        }
    }
    out
}

/// The rules shared by the hosts' gateways, and each host's own leading-value puts.
fn host_rules(cell: &Cell, rules: &mut Vec<Value>) -> Vec<String> {
    let c = &cell.name;
    let lv = keys::leading_values(c);
    rules.push(rule(
        "host-lv-out".into(),
        &["put"],
        OUT,
        std::slice::from_ref(&lv),
    ));
    rules.push(rule(
        "host-declare".into(),
        &["declare_subscriber"],
        BOTH,
        std::slice::from_ref(&lv),
    ));
    rules.push(rule(
        "host-queryables".into(),
        &["declare_queryable"],
        BOTH,
        &[keys::all_commands(c), keys::all_clocks(c)],
    ));
    rules.push(rule(
        "host-clock".into(),
        &["query", "reply"],
        BOTH,
        &[keys::all_clocks(c)],
    ));
    rules.push(rule(
        "host-alive".into(),
        &[
            "liveliness_token",
            "declare_liveliness_subscriber",
            "liveliness_query",
        ],
        BOTH,
        &[keys::alive_all(c)],
    ));
    let ids = vec![
        "host-lv-out".to_string(),
        "host-declare".into(),
        "host-queryables".into(),
        "host-clock".into(),
        "host-alive".into(),
    ];
    // Each host may put only its own leaders' values (a rule per host with leaders).
    for (h, name) in cell.hosts.iter().enumerate() {
        let own = own_leading_values(cell, h);
        if !own.is_empty() {
            rules.push(rule(format!("lv-in-{name}"), &["put"], IN, &own));
        }
    }
    ids
}

/// The rules of observers (and, with them, of operators).
fn observer_rules(cell: &Cell, rules: &mut Vec<Value>) -> Vec<String> {
    let c = &cell.name;
    let observable = keys::observable(c);
    rules.push(rule(
        "observe-subscribe".into(),
        &["declare_subscriber"],
        IN,
        &observable,
    ));
    rules.push(rule("observe-put".into(), &["put"], OUT, &observable));
    rules.push(rule(
        "observe-alive-ask".into(),
        &["declare_liveliness_subscriber", "liveliness_query"],
        IN,
        &[keys::alive_all(c)],
    ));
    rules.push(rule(
        "observe-alive".into(),
        &["liveliness_token"],
        OUT,
        &[keys::alive_all(c)],
    ));
    vec![
        "observe-subscribe".into(),
        "observe-put".into(),
        "observe-alive-ask".into(),
        "observe-alive".into(),
    ]
}

/// The rule shared by operators beyond observing: the gateways' command queryable
/// declarations may reach them (they reveal no command).
fn operator_rules(cell: &Cell, rules: &mut Vec<Value>) -> Vec<String> {
    rules.push(rule(
        "commands-declared".into(),
        &["declare_queryable"],
        OUT,
        &[keys::all_commands(&cell.name)],
    ));
    vec!["commands-declared".into()]
}

/// The rules of operator `name` alone (docs/security.md, "Commands with identity"): it may query
/// only the command keys that name its own certificate's common name as sender
/// (`tandem/<c>/*/*/cmd/operator:<name>`) and get their replies, so the sender a gateway reads
/// from the key is the certificate's subject.
fn own_commands_rules(cell: &Cell, name: &str, rules: &mut Vec<Value>) -> [String; 2] {
    let ids = [format!("query-by-{name}"), format!("reply-to-{name}")];
    let own = [keys::sender_commands(
        &cell.name,
        &common_name(Role::Operator, name),
    )];
    let [query, reply] = &ids;
    rules.push(rule(query.clone(), &["query"], IN, &own));
    rules.push(rule(reply.clone(), &["reply"], OUT, &own));
    ids
}

/// One subject and one policy per operator (its own command rule), one subject and one policy
/// for all observers.
fn client_policies(
    cell: &Cell,
    (observe_ids, operate_ids): (&[String], &[String]),
    rules: &mut Vec<Value>,
    (subjects, policies): (&mut Vec<Value>, &mut Vec<Value>),
) {
    for name in cell.security.names(Role::Operator) {
        let id = format!("operator-{name}");
        subjects.push(json!({
            "id": id,
            "cert_common_names": [common_name(Role::Operator, name)],
            "link_protocols": ["tls"],
        }));
        let own = own_commands_rules(cell, name, rules);
        let r: Vec<String> = observe_ids
            .iter()
            .chain(operate_ids.iter())
            .cloned()
            .chain(own)
            .collect();
        policies.push(json!({ "id": id, "rules": r, "subjects": [id] }));
    }
    let names = cell.security.names(Role::Observer);
    if !names.is_empty() {
        let id = "observers";
        let cns: Vec<String> = names
            .iter()
            .map(|n| common_name(Role::Observer, n))
            .collect();
        subjects.push(json!({
            "id": id,
            "cert_common_names": cns,
            "link_protocols": ["tls"],
        }));
        policies.push(json!({ "id": id, "rules": observe_ids, "subjects": [id] }));
    }
}

/// The `access_control` section of every gateway of `cell` (Zenoh 1.10 schema).
pub fn access_control(cell: &Cell) -> Value {
    let mut rules = Vec::new();
    let host_ids = host_rules(cell, &mut rules);
    let observe_ids = observer_rules(cell, &mut rules);
    let operate_ids = operator_rules(cell, &mut rules);
    let mut subjects = Vec::new();
    let mut policies = Vec::new();
    for (h, name) in cell.hosts.iter().enumerate() {
        let id = format!("host-{name}");
        subjects.push(json!({
            "id": id,
            "cert_common_names": [common_name(Role::Host, name)],
            "link_protocols": ["tls"],
        }));
        let mut r = host_ids.clone();
        if !own_leading_values(cell, h).is_empty() {
            r.push(format!("lv-in-{name}"));
        }
        policies.push(json!({ "id": id, "rules": r, "subjects": [id] }));
    }
    client_policies(
        cell,
        (&observe_ids, &operate_ids),
        &mut rules,
        (&mut subjects, &mut policies),
    );
    json!({
        "enabled": true,
        "default_permission": "deny",
        "rules": rules,
        "subjects": subjects,
        "policies": policies,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
    use super::*;

    const CELL: &str = r#"
[cell]
name = "c"

[security]
operators = ["alice", "bob"]
observers = ["hmi", "log"]

[[hosts]]
name = "h1"
listen = ["tls/10.0.0.1:7447"]

[[hosts]]
name = "h2"
listen = ["tls/10.0.0.2:7447"]

[[nodes]]
name = "na"
cycle_us = 1000
host = "h1"

[[nodes]]
name = "nb"
cycle_us = 1000
host = "h2"

[axes.master]
node = "na"
virtual = true

[axes.master.leading_value]
delay_us = 10000

[axes.master.dynamics]
max_velocity = 100.0
max_acceleration = 1000.0
max_deceleration = 1000.0
max_jerk = 10000.0
velocity = 50.0
acceleration = 500.0
deceleration = 500.0
jerk = 5000.0
emergency_deceleration = 2000.0
"#;

    /// The rules (by id) of the policy of subject `subject`.
    fn allowed(acl: &Value, subject: &str) -> Vec<Value> {
        let policy = acl["policies"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["subjects"][0] == subject)
            .unwrap_or_else(|| panic!("no policy for {subject}"));
        policy["rules"]
            .as_array()
            .unwrap()
            .iter()
            .map(|id| {
                acl["rules"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .find(|r| r["id"] == *id)
                    .unwrap()
                    .clone()
            })
            .collect()
    }

    /// Whether `subject` may `message` on `key` (exact key of a rule) in `flow`.
    fn may(acl: &Value, subject: &str, message: &str, flow: &str, key: &str) -> bool {
        allowed(acl, subject).iter().any(|r| {
            r["messages"]
                .as_array()
                .unwrap()
                .iter()
                .any(|m| m == message)
                && r["flows"].as_array().unwrap().iter().any(|f| f == flow)
                && r["key_exprs"].as_array().unwrap().iter().any(|k| k == key)
        })
    }

    #[test]
    fn each_role_gets_exactly_its_keys() {
        let cell = tandem_config::parse("c.toml", CELL).unwrap();
        let acl = access_control(&cell);
        assert_eq!(acl["default_permission"], "deny");
        assert_eq!(acl["enabled"], true);
        // Subjects are the certificates' common names, over TLS only.
        let subjects = acl["subjects"].as_array().unwrap();
        let cns: Vec<&Value> = subjects.iter().map(|s| &s["cert_common_names"]).collect();
        assert_eq!(
            cns,
            [
                &json!(["host:h1"]),
                &json!(["host:h2"]),
                &json!(["operator:alice"]),
                &json!(["operator:bob"]),
                &json!(["observer:hmi", "observer:log"]),
            ]
        );
        assert!(subjects
            .iter()
            .all(|s| s["link_protocols"] == json!(["tls"])));
        // Leading values: only h1 hosts `master`, so only h1 may put it.
        let lv = "tandem/c/lv/master";
        assert!(may(&acl, "host-h1", "put", "ingress", lv));
        assert!(may(
            &acl,
            "host-h1",
            "put",
            "ingress",
            "tandem/c/lv/master/actual"
        ));
        assert!(!may(&acl, "host-h2", "put", "ingress", lv));
        assert!(acl["rules"]
            .as_array()
            .unwrap()
            .iter()
            .all(|r| r["id"] != "lv-in-h2"));
        for s in ["host-h1", "host-h2"] {
            assert!(may(&acl, s, "put", "egress", "tandem/c/lv/**"));
            assert!(may(
                &acl,
                s,
                "declare_subscriber",
                "ingress",
                "tandem/c/lv/**"
            ));
            assert!(may(
                &acl,
                s,
                "declare_subscriber",
                "egress",
                "tandem/c/lv/**"
            ));
            assert!(may(
                &acl,
                s,
                "declare_queryable",
                "ingress",
                "tandem/c/*/*/cmd/*"
            ));
            assert!(may(&acl, s, "query", "ingress", "tandem/c/clock/*"));
            assert!(may(
                &acl,
                s,
                "liveliness_token",
                "ingress",
                "tandem/c/alive/*"
            ));
            // A gateway does not command another host's nodes.
            assert!(!may(&acl, s, "query", "ingress", "tandem/c/*/*/cmd/*"));
        }
        // Operators: their own command queries in, their replies out, and what observers may.
        for (op, own, other) in [
            ("operator-alice", "operator:alice", "operator:bob"),
            ("operator-bob", "operator:bob", "operator:alice"),
        ] {
            let own = format!("tandem/c/*/*/cmd/{own}");
            let other = format!("tandem/c/*/*/cmd/{other}");
            assert!(may(&acl, op, "query", "ingress", &own));
            assert!(may(&acl, op, "reply", "egress", &own));
            assert!(!may(&acl, op, "query", "ingress", &other));
            assert!(!may(&acl, op, "query", "ingress", "tandem/c/*/*/cmd/*"));
            assert!(may(
                &acl,
                op,
                "declare_queryable",
                "egress",
                "tandem/c/*/*/cmd/*"
            ));
            assert!(may(
                &acl,
                op,
                "declare_subscriber",
                "ingress",
                "tandem/c/*/*/state"
            ));
            assert!(!may(&acl, op, "put", "ingress", lv));
        }
        // Observers: subscriptions to what is observable, nothing in.
        let obs = "observers";
        for k in keys::observable("c") {
            assert!(may(&acl, obs, "declare_subscriber", "ingress", &k), "{k}");
            assert!(may(&acl, obs, "put", "egress", &k), "{k}");
        }
        assert!(may(
            &acl,
            obs,
            "liveliness_query",
            "ingress",
            "tandem/c/alive/*"
        ));
        for r in allowed(&acl, obs) {
            let messages = r["messages"].as_array().unwrap();
            assert!(
                !messages.iter().any(|m| m == "query") || r["flows"] == json!(["egress"]),
                "{r}"
            );
            if r["flows"] == json!(["ingress"]) {
                assert!(
                    messages
                        .iter()
                        .all(|m| m != "put" && m != "query" && m != "reply"),
                    "observers send nothing: {r}"
                );
            }
            for k in r["key_exprs"].as_array().unwrap() {
                assert!(!k.as_str().unwrap().contains("/lv/"), "{r}");
                assert!(!k.as_str().unwrap().contains("/cmd"), "{r}");
            }
        }
        // Every policy names existing rules and subjects; ids are unique.
        let ids: Vec<&Value> = acl["rules"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| &r["id"])
            .collect();
        for (i, id) in ids.iter().enumerate() {
            assert!(!ids[..i].contains(id), "{id} twice");
        }
        for p in acl["policies"].as_array().unwrap() {
            for r in p["rules"].as_array().unwrap() {
                assert!(ids.contains(&r), "{r}");
            }
        }
    }

    /// Every rule that lets a client query or be replied on a command key names exactly one
    /// sender: the common name of the one operator whose policy holds it.
    #[test]
    fn each_operator_may_query_only_the_commands_naming_its_own_certificate() {
        let cell = tandem_config::parse("c.toml", CELL).unwrap();
        let acl = access_control(&cell);
        let mut seen = 0;
        for p in acl["policies"].as_array().unwrap() {
            let subject = p["subjects"][0].as_str().unwrap();
            let s = acl["subjects"]
                .as_array()
                .unwrap()
                .iter()
                .find(|s| s["id"] == subject)
                .unwrap();
            for r in allowed(&acl, subject) {
                let messages = r["messages"].as_array().unwrap();
                let client_side = (r["flows"] == json!(["ingress"])
                    && messages.iter().any(|m| m == "query"))
                    || (r["flows"] == json!(["egress"]) && messages.iter().any(|m| m == "reply"));
                let keys: Vec<&str> = r["key_exprs"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|k| k.as_str().unwrap())
                    .collect();
                if !client_side || !keys.iter().any(|k| k.contains("/cmd")) {
                    continue;
                }
                // Only an operator, on its own key only.
                assert!(subject.starts_with("operator-"), "{subject}: {r}");
                assert_eq!(s["cert_common_names"].as_array().unwrap().len(), 1);
                let cn = s["cert_common_names"][0].as_str().unwrap();
                assert_eq!(keys, [format!("tandem/c/*/*/cmd/{cn}")], "{subject}: {r}");
                seen += 1;
            }
        }
        // A query rule and a reply rule for each of the two operators.
        assert_eq!(seen, 4);
    }

    #[test]
    fn a_cell_without_operators_or_observers_has_only_host_subjects() {
        let src = CELL
            .replace("operators = [\"alice\", \"bob\"]\n", "")
            .replace("observers = [\"hmi\", \"log\"]\n", "");
        let cell = tandem_config::parse("c.toml", &src).unwrap();
        let acl = access_control(&cell);
        assert_eq!(acl["subjects"].as_array().unwrap().len(), 2);
        assert_eq!(acl["policies"].as_array().unwrap().len(), 2);
        // Zenoh refuses empty lists in rules and subjects: there are none.
        for r in acl["rules"].as_array().unwrap() {
            for k in ["messages", "flows", "key_exprs"] {
                assert!(!r[k].as_array().unwrap().is_empty(), "{r}");
            }
        }
    }
}
