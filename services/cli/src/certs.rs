//! `tandem certs <cell.toml> [--out DIR] [--days N]`: the cell's CA and the certificates of its
//! hosts (gateways), operators and observers, for `[security] mode = "mtls"`
//! (docs/security.md).
//!
//! Every key is ECDSA P-256 (PKCS#8 PEM, written with mode 0600). Each leaf's common name is its
//! ACL identity ([`tandem_config::security::common_name`]: `host:h1`, `operator:alice`,
//! `observer:hmi`). A host's certificate names, as subject alternative names, every address of
//! its `listen` endpoints (what the other gateways and the clients dial, and what their TLS
//! checks), and serves both ends of a link (extended key usages serverAuth and clientAuth); an
//! operator's or observer's only dials (clientAuth, no SAN). The CA's key goes into a directory
//! of its own (`<out>/ca-private/`, mode 0700): it signs, and belongs on no controller.
//!
//! All keys are made on the machine that runs `tandem certs`. In production each key should
//! be made on the machine that uses it and only a signing request leave it; that flow
//! (`--csr`) is not built yet (docs/security.md, "Not yet").

use crate::error::CliError;
use crate::live::load;
use rcgen::{
    BasicConstraints, CertificateParams, DnType, ExtendedKeyUsagePurpose, IsCa, Issuer, KeyPair,
    KeyUsagePurpose, PKCS_ECDSA_P256_SHA256,
};
use std::io::Write;
use std::path::{Path, PathBuf};
use tandem_config::security::{common_name, endpoint_address, Role};
use tandem_config::Cell;

/// What `tandem certs` is given.
#[derive(Clone, Debug)]
pub struct CertsOptions {
    /// The cell file.
    pub cell: PathBuf,
    /// Where to write (default: the directory of the cell's `[security] ca`).
    pub out: Option<PathBuf>,
    /// How long the certificates are valid (days from now).
    pub days: u32,
}

/// One certificate to make: its role, name, subject alternative names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Leaf {
    /// The role (its CN prefix and extended key usages).
    pub role: Role,
    /// The host's, operator's or observer's name.
    pub name: String,
    /// The addresses it is dialled at (hosts only).
    pub sans: Vec<String>,
}

impl Leaf {
    /// The certificate's common name, its ACL identity.
    pub fn common_name(&self) -> String {
        common_name(self.role, &self.name)
    }

    /// The file stem: `host-h1`, `operator-alice`.
    pub fn stem(&self) -> String {
        format!("{}-{}", self.role.name(), self.name)
    }
}

/// Every certificate of the cell: its hosts (SANs = the addresses of their `listen`
/// endpoints), its operators and its observers.
pub fn leaves(cell: &Cell) -> Vec<Leaf> {
    let mut all = Vec::new();
    for (h, name) in cell.hosts.iter().enumerate() {
        let mut sans: Vec<String> = Vec::new();
        for e in cell.host_listen.get(h).into_iter().flatten() {
            if let Some((_, address, _)) = endpoint_address(e) {
                if !sans.iter().any(|s| s == address) {
                    sans.push(address.to_string());
                }
            }
        }
        all.push(Leaf {
            role: Role::Host,
            name: name.clone(),
            sans,
        });
    }
    for role in [Role::Operator, Role::Observer] {
        for n in cell.security.names(role) {
            all.push(Leaf {
                role,
                name: n.clone(),
                sans: Vec::new(),
            });
        }
    }
    all
}

/// The validity of a new certificate: from an hour ago (clocks of a cell differ a little) for
/// `days` days.
fn validity(params: &mut CertificateParams, days: u32) {
    let now = time::OffsetDateTime::now_utc();
    params.not_before = now - time::Duration::hours(1);
    params.not_after = now + time::Duration::days(i64::from(days));
}

fn generate(what: &str) -> Result<KeyPair, CliError> {
    KeyPair::generate_for(&PKCS_ECDSA_P256_SHA256).map_err(|source| CliError::CertGen {
        what: what.into(),
        source,
    })
}

/// The cell's CA: its certificate (PEM), and the issuer that signs the leaves.
fn ca(cell: &Cell, days: u32) -> Result<(String, String, Issuer<'static, KeyPair>), CliError> {
    let err = |source| CliError::CertGen {
        what: "the CA".into(),
        source,
    };
    let mut p = CertificateParams::new(Vec::<String>::new()).map_err(err)?;
    p.distinguished_name = rcgen::DistinguishedName::new();
    p.distinguished_name
        .push(DnType::CommonName, format!("tandem cell {} CA", cell.name));
    p.distinguished_name
        .push(DnType::OrganizationName, "tandem");
    p.is_ca = IsCa::Ca(BasicConstraints::Constrained(0));
    p.key_usages = vec![
        KeyUsagePurpose::KeyCertSign,
        KeyUsagePurpose::CrlSign,
        KeyUsagePurpose::DigitalSignature,
    ];
    validity(&mut p, days);
    let key = generate("the CA")?;
    let cert = p.self_signed(&key).map_err(err)?;
    let key_pem = key.serialize_pem();
    Ok((cert.pem(), key_pem, Issuer::new(p, key)))
}

/// A leaf's certificate and key (PEM), signed by `issuer`.
fn leaf(
    l: &Leaf,
    issuer: &Issuer<'static, KeyPair>,
    days: u32,
) -> Result<(String, String), CliError> {
    let err = |source| CliError::CertGen {
        what: l.common_name(),
        source,
    };
    let mut p = CertificateParams::new(l.sans.clone()).map_err(err)?;
    p.distinguished_name = rcgen::DistinguishedName::new();
    p.distinguished_name
        .push(DnType::CommonName, l.common_name());
    p.distinguished_name
        .push(DnType::OrganizationName, "tandem");
    p.is_ca = IsCa::ExplicitNoCa;
    p.key_usages = vec![KeyUsagePurpose::DigitalSignature];
    p.extended_key_usages = match l.role {
        Role::Host => vec![
            ExtendedKeyUsagePurpose::ServerAuth,
            ExtendedKeyUsagePurpose::ClientAuth,
        ],
        Role::Operator | Role::Observer => vec![ExtendedKeyUsagePurpose::ClientAuth],
    };
    p.use_authority_key_identifier_extension = true;
    validity(&mut p, days);
    let key = generate(&l.common_name())?;
    let cert = p.signed_by(&key, issuer).map_err(err)?;
    Ok((cert.pem(), key.serialize_pem()))
}

/// Writes `text` to a new file `path` with permissions `mode` (a key: 0600).
fn write_new(path: &Path, text: &str, mode: u32) -> Result<(), CliError> {
    use std::os::unix::fs::OpenOptionsExt;
    let err = |source| CliError::CertWrite {
        path: path.to_path_buf(),
        source,
    };
    let mut f = std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .mode(mode)
        .open(path)
        .map_err(err)?;
    // `mode` applies to a new file only; an old one gets it here.
    std::fs::set_permissions(path, std::os::unix::fs::PermissionsExt::from_mode(mode))
        .map_err(err)?;
    f.write_all(text.as_bytes()).map_err(err)?;
    f.sync_all().map_err(err)
}

fn create_dir(path: &Path, mode: u32) -> Result<(), CliError> {
    use std::os::unix::fs::DirBuilderExt;
    std::fs::DirBuilder::new()
        .recursive(true)
        .mode(mode)
        .create(path)
        .map_err(|source| CliError::CertWrite {
            path: path.to_path_buf(),
            source,
        })
}

/// `tandem certs`: writes `ca.pem`, `ca-private/ca.key`, and `<role>-<name>.pem` / `.key` for
/// every host, operator and observer of the cell into the output directory, and says what it
/// wrote.
pub fn certs(o: &CertsOptions, out: &mut impl Write) -> Result<(), CliError> {
    let cell = load(&o.cell)?;
    let dir = match &o.out {
        Some(d) => d.clone(),
        None => cell
            .security
            .ca
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default(),
    };
    let ca_path = dir.join("ca.pem");
    if ca_path.exists() {
        return Err(CliError::CertsExist(ca_path));
    }
    create_dir(&dir, 0o755)?;
    let private = dir.join("ca-private");
    create_dir(&private, 0o700)?;
    let (ca_pem, ca_key, issuer) = ca(&cell, o.days)?;
    write_new(&private.join("ca.key"), &ca_key, 0o600)?;
    write_new(&ca_path, &ca_pem, 0o644)?;
    outln!(
        out,
        "{}: the CA of cell `{}` (its key: {}; keep it off the controllers)",
        ca_path.display(),
        cell.name,
        private.join("ca.key").display()
    );
    for l in leaves(&cell) {
        let (cert, key) = leaf(&l, &issuer, o.days)?;
        let stem = l.stem();
        write_new(&dir.join(format!("{stem}.key")), &key, 0o600)?;
        write_new(&dir.join(format!("{stem}.pem")), &cert, 0o644)?;
        outln!(
            out,
            "{}: CN {}{}",
            dir.join(format!("{stem}.pem")).display(),
            l.common_name(),
            if l.sans.is_empty() {
                String::new()
            } else {
                format!(", for {}", l.sans.join(", "))
            }
        );
    }
    outln!(
        out,
        "valid {} days. Copy to each machine only its own .pem/.key and ca.pem (docs/security.md)",
        o.days
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;

    #[test]
    fn every_host_operator_and_observer_gets_its_name_and_addresses() {
        let src = r#"
[cell]
name = "c"

[security]
operators = ["alice"]
observers = ["hmi"]

[[hosts]]
name = "h1"
listen = ["tls/10.0.0.1:7447", "tls/[fd00::1]:7447", "tls/ctl1.cell:7448"]

[[hosts]]
name = "h2"

[[nodes]]
name = "n"
cycle_us = 1000
host = "h1"
"#;
        let cell = tandem_config::parse("c.toml", src).unwrap();
        let l = leaves(&cell);
        let cns: Vec<String> = l.iter().map(Leaf::common_name).collect();
        assert_eq!(
            cns,
            ["host:h1", "host:h2", "operator:alice", "observer:hmi"]
        );
        assert_eq!(l[0].sans, ["10.0.0.1", "fd00::1", "ctl1.cell"]);
        assert!(l[1].sans.is_empty() && l[2].sans.is_empty());
        assert_eq!(l[2].stem(), "operator-alice");
        // The CA and a leaf really are made (PEM).
        let (ca_pem, ca_key, issuer) = ca(&cell, 1).unwrap();
        assert!(ca_pem.starts_with("-----BEGIN CERTIFICATE-----"));
        assert!(ca_key.starts_with("-----BEGIN PRIVATE KEY-----"));
        let (cert, key) = leaf(&l[0], &issuer, 1).unwrap();
        assert!(cert.starts_with("-----BEGIN CERTIFICATE-----"));
        assert!(key.starts_with("-----BEGIN PRIVATE KEY-----"));
    }
}
