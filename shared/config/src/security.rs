//! `[security]`: how the cell's Zenoh links are authenticated and who may do what
//! (docs/security.md). Every gateway link uses TLS with mutual authentication (mTLS) by
//! certificates of the cell's CA, and the ACL identity of a peer is its certificate's common
//! name: [`common_name`].

use std::path::{Path, PathBuf};

/// How the cell's Zenoh links are secured.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum SecurityMode {
    /// TLS links only, both ends present a certificate of the cell's CA, and each role gets
    /// exactly its keys (`mode = "mtls"`, the default of a `[security]` section).
    Mtls,
    /// Plain, unauthenticated Zenoh: anyone who reaches an endpoint may read, command and
    /// publish leading values. Written explicitly (`mode = "plain"`), or implied for a cell
    /// without `[security]` whose gateways are reachable only from this machine (loopback
    /// endpoints or none); `tandem up` warns on every start.
    Plain,
}

/// The role of a certificate: what its holder may do on the cell's keys.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Role {
    /// A host's gateway: leading values in and out, state and telemetry out, commands served.
    Host,
    /// A person or program that commands: queries the command keys, and observes.
    Operator,
    /// A person or program that only observes: state, health, events, log, signals.
    Observer,
}

impl Role {
    /// Every role.
    pub const ALL: [Role; 3] = [Role::Host, Role::Operator, Role::Observer];

    /// The role's name, the prefix of its common names and file names.
    pub fn name(self) -> &'static str {
        match self {
            Role::Host => "host",
            Role::Operator => "operator",
            Role::Observer => "observer",
        }
    }
}

/// The common name (CN) of the certificate of `name` in `role`, its ACL identity:
/// `host:h1`, `operator:alice`, `observer:hmi`.
pub fn common_name(role: Role, name: &str) -> String {
    format!("{}:{name}", role.name())
}

/// The cell's `[security]`, validated.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Security {
    /// mTLS or plain.
    pub mode: SecurityMode,
    /// The cell file has a `[security]` section (plain was written, not implied).
    pub declared: bool,
    /// The cell CA's certificate (PEM), resolved against the cell file's directory.
    pub ca: PathBuf,
    /// Each host's certificate; `{host}` stands for the host's name.
    pub certificate: PathBuf,
    /// Each host's private key; `{host}` stands for the host's name.
    pub private_key: PathBuf,
    /// The operators' names (their certificates' CN is `operator:<name>`).
    pub operators: Vec<String>,
    /// The observers' names (their certificates' CN is `observer:<name>`).
    pub observers: Vec<String>,
    /// Zenoh's multicast scouting (off unless asked for).
    pub multicast_scouting: bool,
}

/// The default path of the CA certificate, relative to the cell file.
pub const DEFAULT_CA: &str = "pki/ca.pem";
/// The default path of a host's certificate, relative to the cell file.
pub const DEFAULT_CERTIFICATE: &str = "pki/host-{host}.pem";
/// The default path of a host's private key, relative to the cell file.
pub const DEFAULT_PRIVATE_KEY: &str = "pki/host-{host}.key";

impl Security {
    /// What a cell without `[security]` gets (plain, implied; valid only for a cell reachable
    /// from this machine alone), with the default paths under `dir`.
    pub fn implied(dir: &Path) -> Security {
        Security {
            mode: SecurityMode::Plain,
            declared: false,
            ca: dir.join(DEFAULT_CA),
            certificate: dir.join(DEFAULT_CERTIFICATE),
            private_key: dir.join(DEFAULT_PRIVATE_KEY),
            operators: Vec::new(),
            observers: Vec::new(),
            multicast_scouting: false,
        }
    }

    /// Host `host`'s certificate file.
    pub fn host_certificate(&self, host: &str) -> PathBuf {
        for_host(&self.certificate, host)
    }

    /// Host `host`'s private key file.
    pub fn host_private_key(&self, host: &str) -> PathBuf {
        for_host(&self.private_key, host)
    }

    /// The names of `role` (for [`Role::Host`]: none here, the hosts are the cell's).
    pub fn names(&self, role: Role) -> &[String] {
        match role {
            Role::Host => &[],
            Role::Operator => &self.operators,
            Role::Observer => &self.observers,
        }
    }
}

fn for_host(template: &Path, host: &str) -> PathBuf {
    PathBuf::from(template.to_string_lossy().replace("{host}", host))
}

/// The address part of a Zenoh endpoint `<protocol>/<address>:<port>[#options]`: an IP
/// (brackets of an IPv6 address removed) or a DNS name. `None` if the endpoint is not of that
/// form.
pub fn endpoint_address(endpoint: &str) -> Option<(&str, &str, u16)> {
    let (protocol, rest) = endpoint.split_once('/')?;
    let rest = rest.split('#').next()?;
    let (address, port) = rest.rsplit_once(':')?;
    let address = address
        .strip_prefix('[')
        .and_then(|a| a.strip_suffix(']'))
        .unwrap_or(address);
    let port = port.parse::<u16>().ok()?;
    let valid = !protocol.is_empty()
        && protocol.chars().all(|c| c.is_ascii_lowercase())
        && !address.is_empty()
        && address
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | ':' | '_'));
    valid.then_some((protocol, address, port))
}

/// True if `address` is reachable from this machine only (127.0.0.0/8, ::1, `localhost`).
pub fn is_loopback(address: &str) -> bool {
    address == "localhost"
        || address
            .parse::<std::net::IpAddr>()
            .is_ok_and(|ip| ip.is_loopback())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_split_and_loopback_is_known() {
        assert_eq!(
            endpoint_address("tls/10.0.0.1:7447"),
            Some(("tls", "10.0.0.1", 7447))
        );
        assert_eq!(
            endpoint_address("tcp/[::1]:7447#iface=lo"),
            Some(("tcp", "::1", 7447))
        );
        assert_eq!(
            endpoint_address("tls/router.cell:1"),
            Some(("tls", "router.cell", 1))
        );
        for bad in [
            "garbage",
            "tcp/10.0.0.1",
            "tcp/:7447",
            "tcp/a:70000",
            "/a:1",
        ] {
            assert_eq!(endpoint_address(bad), None, "{bad}");
        }
        assert!(is_loopback("127.0.0.1") && is_loopback("::1") && is_loopback("localhost"));
        assert!(!is_loopback("10.0.0.1") && !is_loopback("0.0.0.0") && !is_loopback("::"));
        assert_eq!(common_name(Role::Operator, "alice"), "operator:alice");
        let s = Security::implied(Path::new("/c"));
        assert_eq!(
            s.host_certificate("h1"),
            PathBuf::from("/c/pki/host-h1.pem")
        );
        assert_eq!(
            s.host_private_key("h1"),
            PathBuf::from("/c/pki/host-h1.key")
        );
    }
}
