//! Commands with identity (issue 12, docs/security.md "Commands with identity"): in an mTLS
//! cell the sender of a command is the common name of the querier's certificate, bound by the
//! key (`…/cmd/<sender>`) and the access control (an operator may query only the keys naming
//! its own common name), with real processes (`tandem up` with its node and gateway, the
//! Python `eclipse-zenoh` client of tests/python/observe.py, `tandem cmd --zenoh`) on loopback.
//!
//! - Operator alice's certificate querying bob's command key gets no reply (the access control
//!   refuses the query), and the node never sees the command (no audit line).
//! - Alice's certificate on her own key with a JSON payload claiming `"sender":
//!   "operator:bob"`: accepted, audited as `operator:alice`, and the gateway's `command` event
//!   names `operator:alice`.
//! - `tandem cmd --zenoh --cert` with alice's certificate: the client names its certificate's
//!   common name as the sender (accepted, audited as alice).
//! - Bob's certificate on his own key: accepted, audited as bob (the access control does not
//!   just refuse everyone).
//!
//! Every wait has a timeout.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;
use tandem_testkit::process::{run, text, until, Spawned};
use tandem_testkit::scratch::{fresh_dir, remove_dir};
use tandem_testkit::tandem::tandem;
use tandem_testkit::workspace::root;

/// tests/python/observe.py against the cell at `endpoint` with `args`, its JSON summary.
fn observe(name: &str, endpoint: &str, args: &[String]) -> serde_json::Value {
    let mut c = Command::new("python3");
    c.arg(root().join("tests/python/observe.py"))
        .args(["--cell", name, "--seconds", "2", "--connect", endpoint])
        .args(args)
        .stdin(Stdio::null());
    let o = run(c, Duration::from_secs(60));
    let said = text(&o);
    assert!(o.status.success(), "observe.py: {said}");
    let out = String::from_utf8_lossy(&o.stdout).to_string();
    serde_json::from_str(out.trim()).unwrap_or_else(|e| panic!("{e}: {said}"))
}

/// The certificate arguments of observe.py for `who` (`operator-alice`).
fn cert_args(pki: &Path, who: &str) -> Vec<String> {
    let p = |f: String| pki.join(f).to_string_lossy().to_string();
    vec![
        "--ca".into(),
        p("ca.pem".into()),
        "--cert".into(),
        p(format!("{who}.pem")),
        "--key".into(),
        p(format!("{who}.key")),
    ]
}

#[test]
fn the_sender_of_a_command_is_the_common_name_of_the_certificate() {
    let pid = std::process::id();
    let dir = fresh_dir(&format!("tandem-identity-{pid}"));
    let name = format!("ident{pid}");
    let port = 20_000 + (pid + 11) % 20_000;
    let endpoint = format!("tls/127.0.0.1:{port}");
    let src = std::fs::read_to_string(root().join("config/glue-dot.toml")).unwrap();
    let src = src
        .replace("name = \"glue-dot\"", &format!("name = \"{name}\""))
        .replace(
            "[[nodes]]",
            &format!(
                "retain_dir = \"{}\"\n\n[security]\nmode = \"mtls\"\noperators = [\"alice\", \"bob\"]\n\n[[nodes]]",
                dir.join("retain").display()
            ),
        )
        + &format!("\n[[hosts]]\nname = \"local\"\nlisten = [\"{endpoint}\"]\n");
    let cell = dir.join("ident.toml");
    std::fs::write(&cell, src).unwrap();
    let mut certs = tandem();
    certs.arg("certs").arg(&cell);
    let o = run(certs, Duration::from_secs(30));
    assert!(o.status.success(), "tandem certs: {}", text(&o));
    let pki = dir.join("pki");
    let script = dir.join("script.toml");
    std::fs::write(
        &script,
        "[sim]\nduration = 40.0\n\n[[at]]\nt = 0.0\naxis = \"conveyor\"\ninstruction = \"MC_Power\"\n",
    )
    .unwrap();
    let up = Spawned::start(
        tandem_testkit::tandem::up(tandem(), &cell, &dir.join("rec"))
            .arg("--script")
            .arg(&script),
    );

    // `tandem cmd --zenoh` with alice's certificate (until the gateway is up).
    let (cert, key) = (
        pki.join("operator-alice.pem"),
        pki.join("operator-alice.key"),
    );
    until(
        Duration::from_secs(30),
        "tandem cmd --zenoh accepted",
        || {
            let mut c = tandem();
            c.arg("cmd").arg("--cell").arg(&cell);
            c.args(["--zenoh", &endpoint]).arg("--cert").arg(&cert);
            c.arg("--key").arg(&key);
            c.args(["packer/conveyor", "MC_Reset", "--timeout", "3"]);
            run(c, Duration::from_secs(20)).status.success()
        },
    );

    let alice = cert_args(&pki, "operator-alice");
    let command = |target: &str, text: &str| -> Vec<String> {
        vec!["--command".into(), target.into(), text.into()]
    };
    // Alice on bob's key: the access control refuses the query, nothing replies.
    let seen = observe(
        &name,
        &endpoint,
        &[
            &alice[..],
            &["--sender".into(), "operator:bob".into()],
            &command("packer/conveyor", "MC_Halt"),
        ]
        .concat(),
    );
    assert_eq!(
        seen["replies"][0]["reply"],
        serde_json::Value::Null,
        "alice on bob's key: {seen}"
    );
    // Alice on her own key, her payload claiming to be bob: accepted, as alice.
    let claim = r#"{"instruction": "MC_MoveVelocity", "params": {"velocity": 50.0}, "sender": "operator:bob"}"#;
    let seen = observe(
        &name,
        &endpoint,
        &[
            &alice[..],
            &["--sender".into(), "operator:alice".into()],
            &command("packer/conveyor", claim),
        ]
        .concat(),
    );
    assert_eq!(seen["replies"][0]["reply"]["outcome"], "accepted", "{seen}");
    let events = seen["command_events"].as_array().unwrap();
    let moved: Vec<&serde_json::Value> = events
        .iter()
        .filter(|e| {
            e["message"]
                .as_str()
                .unwrap_or("")
                .starts_with("MC_MoveVelocity")
        })
        .collect();
    assert_eq!(moved.len(), 1, "{seen}");
    assert_eq!(moved[0]["sender"], "operator:alice", "{seen}");
    assert_eq!(moved[0]["object"], "conveyor", "{seen}");
    // Bob on his own key.
    let seen = observe(
        &name,
        &endpoint,
        &[
            &cert_args(&pki, "operator-bob")[..],
            &["--sender".into(), "operator:bob".into()],
            &command("packer/conveyor", "MC_Reset"),
        ]
        .concat(),
    );
    assert_eq!(seen["replies"][0]["reply"]["outcome"], "accepted", "{seen}");

    let (status, up_log) = up.wait(Duration::from_secs(120), "tandem up");
    assert!(status.success(), "tandem up failed: {status}\n{up_log}");
    let audit =
        std::fs::read_to_string(dir.join("retain").join(&name).join("packer/audit.log")).unwrap();
    let lines: Vec<&str> = audit.lines().collect();
    let sender_of = |l: &str| {
        l.split(" sender=")
            .nth(1)
            .and_then(|x| x.split(' ').next())
            .unwrap_or("")
            .to_string()
    };
    // Every command the node saw came from a certificate's common name.
    assert!(
        lines
            .iter()
            .all(|l| ["\"operator:alice\"", "\"operator:bob\""].contains(&sender_of(l).as_str())),
        "{audit}"
    );
    // The refused query never reached the node.
    assert!(!audit.contains("MC_Halt"), "{audit}");
    // The claim of the payload was overridden by the key's sender.
    let moved: Vec<&&str> = lines
        .iter()
        .filter(|l| l.contains("command=\"conveyor MC_MoveVelocity"))
        .collect();
    assert_eq!(moved.len(), 1, "{audit}");
    assert_eq!(sender_of(moved[0]), "\"operator:alice\"", "{audit}");
    assert!(moved[0].contains("outcome=accepted"), "{audit}");
    // `tandem cmd --zenoh --cert` named alice; bob's own command is his.
    let resets = |who: &str| {
        lines
            .iter()
            .filter(|l| l.contains("command=\"conveyor MC_Reset") && sender_of(l) == who)
            .count()
    };
    assert!(resets("\"operator:alice\"") >= 1, "{audit}");
    assert_eq!(resets("\"operator:bob\""), 1, "{audit}");
    remove_dir(&dir);
}
