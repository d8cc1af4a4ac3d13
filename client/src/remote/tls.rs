//! Endpoints, certificate files and the Zenoh configuration of a remote
//! client (mutual TLS, client mode, no scouting).

use super::RemoteError;
use crate::remote_options::{RemoteOptions, TlsFiles};
use std::path::Path;
use std::time::Duration;

/// A parsed bridge endpoint.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Endpoint {
    /// The Zenoh locator, `quic/HOST:PORT` or `tls/HOST:PORT`.
    pub locator: String,
    /// The link protocol, `quic` or `tls`.
    pub protocol: &'static str,
    /// `HOST:PORT` (for a plain TCP reachability check of a `tls/` link).
    pub address: String,
}

/// Parses `quic/HOST:PORT`, `tls/HOST:PORT` or `HOST:PORT` (QUIC); other
/// protocols are refused (the bridge only speaks mutual TLS, over QUIC or
/// TCP).
pub fn parse_endpoint(endpoint: &str) -> Result<Endpoint, RemoteError> {
    let bad = |why| RemoteError::BadEndpoint {
        endpoint: endpoint.to_owned(),
        why,
    };
    let (protocol, address) = match endpoint.split_once('/') {
        Some(("quic", rest)) => ("quic", rest),
        Some(("tls", rest)) => ("tls", rest),
        Some(("tcp" | "udp" | "ws", _)) => {
            return Err(bad("the bridge only accepts quic/ or tls/ (mutual TLS)"));
        }
        Some(_) => return Err(bad("unknown protocol")),
        None => ("quic", endpoint),
    };
    // Zenoh endpoint metadata or configuration (`?…`, `#…`) is not ours to set.
    if address.contains(['?', '#', '/']) || address.is_empty() {
        return Err(bad("expected HOST:PORT after the protocol"));
    }
    let (host, port) = address.rsplit_once(':').ok_or_else(|| bad("no :PORT"))?;
    if host.is_empty() || (host.contains(':') && !(host.starts_with('[') && host.ends_with(']'))) {
        return Err(bad("bad host (IPv6 addresses go in brackets: [::1]:PORT)"));
    }
    match port.parse::<u16>() {
        Ok(p) if p > 0 => {}
        _ => return Err(bad("the port must be a number in 1..65535")),
    }
    Ok(Endpoint {
        locator: format!("{protocol}/{address}"),
        protocol,
        address: address.to_owned(),
    })
}

/// Reads a PEM file, or says clearly why not.
pub fn read_pem(what: &'static str, path: &Path) -> Result<Vec<u8>, RemoteError> {
    let err = |why: String| RemoteError::TlsFile {
        what,
        path: path.to_owned(),
        why,
    };
    let bytes = std::fs::read(path).map_err(|e| err(e.to_string()))?;
    if !bytes.windows(11).any(|w| w == b"-----BEGIN ") {
        return Err(err("not a PEM file".into()));
    }
    Ok(bytes)
}

/// The subject common name of the first certificate in a PEM file.
pub fn common_name(pem: &[u8]) -> Result<String, String> {
    let (_, pem) =
        x509_parser::pem::parse_x509_pem(pem).map_err(|e| format!("not a PEM certificate: {e}"))?;
    let cert = pem
        .parse_x509()
        .map_err(|e| format!("not an X.509 certificate: {e}"))?;
    let cn = cert
        .subject()
        .iter_common_name()
        .next()
        .ok_or("the certificate has no common name (CN)")?;
    cn.as_str()
        .map(str::to_owned)
        .map_err(|_| "the common name is not a string".to_owned())
}

/// Checks the three TLS files and returns the certificate's common name.
pub fn check_files(tls: &TlsFiles) -> Result<String, RemoteError> {
    read_pem("CA certificate", &tls.ca)?;
    let cert = read_pem("client certificate", &tls.cert)?;
    read_pem("client key", &tls.key)?;
    common_name(&cert).map_err(|why| RemoteError::TlsFile {
        what: "client certificate",
        path: tls.cert.clone(),
        why,
    })
}

fn path_str(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// The Zenoh configuration of a remote client: client mode, only the
/// bridge's endpoint, mutual TLS with the private CA, no scouting, no
/// listening, a short lease (the bridge notices a dead client within it)
/// and quick reconnection.
pub fn client_config(
    ep: &Endpoint,
    opts: &RemoteOptions,
    connect_timeout: Duration,
) -> Result<zenoh::Config, RemoteError> {
    let lease_ms = opts.lease.as_millis().clamp(500, 600_000) as u64;
    let json = serde_json::json!({
        "mode": "client",
        "connect": {
            "endpoints": [ep.locator],
            "timeout_ms": connect_timeout.as_millis().max(1) as i64,
            "exit_on_failure": true,
            "retry": { "period_init_ms": 200, "period_max_ms": 1000, "period_increase_factor": 1.5 },
        },
        "listen": { "endpoints": [] },
        "scouting": {
            "multicast": { "enabled": false },
            "gossip": { "enabled": false },
        },
        "transport": {
            "link": {
                "protocols": [ep.protocol],
                "tx": { "lease": lease_ms, "keep_alive": 4 },
                "tls": {
                    "root_ca_certificate": path_str(&opts.tls.ca),
                    "connect_certificate": path_str(&opts.tls.cert),
                    "connect_private_key": path_str(&opts.tls.key),
                    "enable_mtls": true,
                    "verify_name_on_connect": true,
                },
            },
            "shared_memory": { "enabled": false },
        },
    });
    zenoh::Config::from_json5(&json.to_string()).map_err(|e| RemoteError::Zenoh(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_parse_or_say_why() {
        let e = parse_endpoint("tls/127.0.0.1:7460").unwrap();
        assert_eq!(e.locator, "tls/127.0.0.1:7460");
        assert_eq!(e.address, "127.0.0.1:7460");
        assert_eq!(e.protocol, "tls");
        let q = parse_endpoint("localhost:9").unwrap();
        assert_eq!(
            (q.locator.as_str(), q.protocol),
            ("quic/localhost:9", "quic")
        );
        assert_eq!(
            parse_endpoint("quic/127.0.0.1:7460").unwrap().locator,
            "quic/127.0.0.1:7460"
        );
        assert_eq!(
            parse_endpoint("tls/[::1]:7460").unwrap().address,
            "[::1]:7460"
        );
        for bad in [
            "tcp/127.0.0.1:7460",
            "udp/127.0.0.1:7460",
            "quic/127.0.0.1",
            "tls/127.0.0.1",
            "tls/127.0.0.1:0",
            "tls/127.0.0.1:70000",
            "tls/:7460",
            "tls/::1:7460",
            "tls/h:1?x=y",
            "http/h:1",
            "",
        ] {
            assert!(parse_endpoint(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn missing_files_are_named() {
        let t = TlsFiles::new("/nonexistent/ca.pem", "/nonexistent/c.pem", "/x");
        let e = check_files(&t).unwrap_err().to_string();
        assert!(e.contains("CA certificate /nonexistent/ca.pem"), "{e}");
    }
}
