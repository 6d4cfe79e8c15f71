//! `[security]` and the gateways' `listen` endpoints it governs (docs/security.md).

use super::{pick, plain_name, Ctx};
use crate::error::{ConfigError, Problem};
use crate::schema::CellFile;
use crate::security::{
    endpoint_address, is_loopback, Security, SecurityMode, DEFAULT_CA, DEFAULT_CERTIFICATE,
    DEFAULT_PRIVATE_KEY,
};
use std::path::Path;

/// `[security]`, and every host's `listen` endpoints checked against it: well formed; `tls/`
/// with a dialable address in mTLS mode; without the section, reachable from this machine only
/// (plain Zenoh on the network must be written out).
pub(super) fn security(
    cx: Ctx<'_>,
    raw: &CellFile,
    dir: Option<&Path>,
) -> Result<Security, ConfigError> {
    let dir = dir.unwrap_or(Path::new(""));
    let mut s = Security::implied(dir);
    if let Some(sec) = &raw.security {
        s.declared = true;
        s.mode = match &sec.mode {
            None => SecurityMode::Mtls,
            Some(m) => pick(
                "mode",
                m,
                &[("mtls", SecurityMode::Mtls), ("plain", SecurityMode::Plain)],
            )
            .map_err(|(k, p)| cx.at(&["security", k], p))?,
        };
        for (key, value, default) in [
            ("ca", &sec.ca, DEFAULT_CA),
            ("certificate", &sec.certificate, DEFAULT_CERTIFICATE),
            ("private_key", &sec.private_key, DEFAULT_PRIVATE_KEY),
        ] {
            let v = value.as_deref().unwrap_or(default);
            if v.trim().is_empty() {
                return Err(cx.at(&["security", key], Problem::Invalid("must name a file")));
            }
            let path = dir.join(v);
            match key {
                "ca" => s.ca = path,
                "certificate" => s.certificate = path,
                _ => s.private_key = path,
            }
        }
        for (key, names) in [("operators", &sec.operators), ("observers", &sec.observers)] {
            for (i, n) in names.iter().enumerate() {
                if !plain_name(n) || names[..i].contains(n) {
                    return Err(cx.at(&["security", key], Problem::NameTaken(n.clone())));
                }
            }
        }
        s.operators = sec.operators.clone();
        s.observers = sec.observers.clone();
        s.multicast_scouting = sec.multicast_scouting;
    }
    for (i, h) in raw.hosts.iter().enumerate() {
        for e in &h.listen {
            check_endpoint(&s, e).map_err(|p| cx.in_array("hosts", i, "listen", p))?;
        }
    }
    Ok(s)
}

/// One `listen` endpoint under `s`.
fn check_endpoint(s: &Security, e: &str) -> Result<(), Problem> {
    let bad = |why| Problem::Endpoint {
        endpoint: e.into(),
        why,
    };
    let Some((protocol, address, _)) = endpoint_address(e) else {
        return Err(bad(
            "must be <protocol>/<address>:<port>, e.g. tls/10.0.0.1:7447",
        ));
    };
    match (s.mode, s.declared) {
        (SecurityMode::Mtls, _) if protocol != "tls" => Err(bad(
            "with [security] mode = \"mtls\" a gateway listens on tls/ endpoints only",
        )),
        (SecurityMode::Mtls, _)
            if address
                .parse::<std::net::IpAddr>()
                .is_ok_and(|ip| ip.is_unspecified()) =>
        {
            Err(bad("name the address clients dial (it goes into the host's certificate), not an unspecified one"))
        }
        (SecurityMode::Plain, false) if !is_loopback(address) => {
            Err(Problem::PlainNotDeclared(e.into()))
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use crate::{parse, Role, SecurityMode};
    use std::path::PathBuf;

    const CELL: &str = r#"
[cell]
name = "t"

[[hosts]]
name = "h1"
listen = ["ENDPOINT"]

[[nodes]]
name = "n"
cycle_us = 1000
"#;

    fn with(endpoint: &str, security: &str) -> String {
        CELL.replace("ENDPOINT", endpoint) + security
    }

    #[test]
    fn mtls_is_the_default_of_the_section_and_takes_tls_endpoints_only() {
        let c = parse(
            "c.toml",
            &with(
                "tls/10.0.0.1:7447",
                "\n[security]\noperators = [\"alice\"]\nobservers = [\"hmi\", \"log\"]\n",
            ),
        )
        .unwrap();
        let s = &c.security;
        assert_eq!((s.mode, s.declared), (SecurityMode::Mtls, true));
        assert_eq!(s.ca, PathBuf::from("pki/ca.pem"));
        assert_eq!(s.host_certificate("h1"), PathBuf::from("pki/host-h1.pem"));
        assert_eq!(s.names(Role::Observer), ["hmi", "log"]);
        assert!(!s.multicast_scouting);
        let e = parse("c.toml", &with("tcp/10.0.0.1:7447", "\n[security]\n")).unwrap_err();
        assert_eq!(e.key, "hosts[0].listen");
        assert_eq!(e.line, Some(7));
        assert!(e.to_string().contains("tls/ endpoints only"), "{e}");
        let e = parse("c.toml", &with("tls/0.0.0.0:7447", "\n[security]\n")).unwrap_err();
        assert!(e.to_string().contains("not an unspecified one"), "{e}");
        let e = parse(
            "c.toml",
            &with("tls/10.0.0.1:7447", "\n[security]\nmode = \"none\"\n"),
        )
        .unwrap_err();
        assert_eq!(e.key, "security.mode");
        let e = parse(
            "c.toml",
            &with(
                "tls/10.0.0.1:7447",
                "\n[security]\noperators = [\"a\", \"a\"]\n",
            ),
        )
        .unwrap_err();
        assert_eq!(e.key, "security.operators");
        let e = parse(
            "c.toml",
            &with("garbage", "\n[security]\nmode = \"plain\"\n"),
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .contains("must be <protocol>/<address>:<port>"),
            "{e}"
        );
    }

    #[test]
    fn plain_on_the_network_must_be_written_out() {
        // Without [security], a gateway reachable from the network is refused...
        let e = parse("c.toml", &with("tcp/10.0.0.1:7447", "")).unwrap_err();
        assert_eq!((e.key.as_str(), e.line), ("hosts[0].listen", Some(7)));
        assert!(e.to_string().contains("mode = \"plain\""), "{e}");
        let e = parse("c.toml", &with("tcp/0.0.0.0:7447", "")).unwrap_err();
        assert!(e.to_string().contains("no [security]"), "{e}");
        // ...one on loopback only is plain, implied (and `tandem up` warns)...
        let c = parse("c.toml", &with("tcp/127.0.0.1:7447", "")).unwrap();
        assert_eq!(
            (c.security.mode, c.security.declared),
            (SecurityMode::Plain, false)
        );
        // ...and written out, plain is allowed anywhere.
        let c = parse(
            "c.toml",
            &with(
                "tcp/10.0.0.1:7447",
                "\n[security]\nmode = \"plain\"\nmulticast_scouting = true\n",
            ),
        )
        .unwrap();
        assert_eq!(
            (c.security.mode, c.security.declared),
            (SecurityMode::Plain, true)
        );
        assert!(c.security.multicast_scouting);
    }
}
