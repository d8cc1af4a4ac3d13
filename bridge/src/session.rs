//! The bridge's Zenoh configuration: a router listening only on the
//! configured `quic/` (default) and `tls/` endpoints, both with mutual
//! TLS, no scouting, and access
//! control generated from the `[[identity]]` list with default deny.
//!
//! # Access control
//!
//! Zenoh checks every message crossing a client's transport against rules
//! whose subject is the client certificate's common name (verified by the
//! TLS handshake against the private CA). Anything not allowed is dropped.
//! For key prefix `P`, every configured identity may:
//!
//! - subscribe to `P/status` and `P/events` (and the advanced publisher's
//!   `P/events/@adv/**`: heartbeat, history queries, its liveliness token)
//!   and receive their samples and replies;
//! - watch the liveliness tokens `P/alive/*`;
//! - declare its own liveliness token `P/clients/<its name>/*` and put its
//!   beats there (PROTOCOL.md, "Lost clients");
//!
//! and an operator moreover may query `P/cmd/<its name>/*` and receive the
//! replies. So the key of a command names an authenticated identity: the
//! bridge takes the `client_id` from it. Nobody may publish but its beats
//! on its own token key, and no client sees another's token or beats. Messages between the bridge's own API and its
//! router are not filtered (not a transport).

use crate::config::{Config, Role};
use serde_json::{Value, json};

/// The `access_control` section for `cfg` (Zenoh's ACL format).
pub fn access_control(cfg: &Config) -> Value {
    let p = &cfg.zenoh.key_prefix;
    let read_keys = json!([
        format!("{p}/status"),
        format!("{p}/events"),
        format!("{p}/events/@adv/**"),
        format!("{p}/plan"),
        format!("{p}/plan/@adv/**")
    ]);
    let alive_keys = json!([format!("{p}/alive/*"), format!("{p}/events/@adv/**")]);
    let mut rules = vec![
        json!({"id": "read-in", "messages": ["declare_subscriber"], "flows": ["ingress"],
               "permission": "allow", "key_exprs": read_keys}),
        json!({"id": "read-out", "messages": ["put"], "flows": ["egress"],
               "permission": "allow", "key_exprs": read_keys}),
        json!({"id": "history-in", "messages": ["query"], "flows": ["ingress"],
               "permission": "allow",
               "key_exprs": [format!("{p}/events/@adv/**"), format!("{p}/plan/@adv/**")]}),
        json!({"id": "history-out", "messages": ["reply", "declare_queryable"], "flows": ["egress"],
               "permission": "allow", "key_exprs": read_keys}),
        json!({"id": "alive-in", "messages": ["declare_liveliness_subscriber", "liveliness_query"],
               "flows": ["ingress"], "permission": "allow", "key_exprs": alive_keys}),
        json!({"id": "alive-out", "messages": ["liveliness_token"], "flows": ["egress"],
               "permission": "allow", "key_exprs": alive_keys}),
    ];
    let common = [
        "read-in",
        "read-out",
        "history-in",
        "history-out",
        "alive-in",
        "alive-out",
    ];
    let mut subjects = Vec::new();
    let mut policies = Vec::new();
    for (i, id) in cfg.identities.iter().enumerate() {
        let name = &id.name;
        let mut own: Vec<String> = common.iter().map(|r| (*r).to_owned()).collect();
        rules.push(
            json!({"id": format!("token-{i}"), "messages": ["liveliness_token", "put"],
            "flows": ["ingress"], "permission": "allow",
            "key_exprs": [format!("{p}/clients/{name}/*")]}),
        );
        own.push(format!("token-{i}"));
        if id.role == Role::Operator {
            rules.push(json!({"id": format!("cmd-in-{i}"), "messages": ["query"],
                "flows": ["ingress"], "permission": "allow",
                "key_exprs": [format!("{p}/cmd/{name}/*")]}));
            rules.push(
                json!({"id": format!("cmd-out-{i}"), "messages": ["reply", "declare_queryable"],
                "flows": ["egress"], "permission": "allow",
                "key_exprs": [format!("{p}/cmd/{name}/*")]}),
            );
            own.push(format!("cmd-in-{i}"));
            own.push(format!("cmd-out-{i}"));
        }
        subjects.push(
            json!({"id": format!("identity-{i}"), "cert_common_names": [name],
            "link_protocols": ["quic", "tls"]}),
        );
        policies.push(json!({"id": format!("policy-{i}"), "rules": own,
            "subjects": [format!("identity-{i}")]}));
    }
    json!({
        "enabled": true,
        "default_permission": "deny",
        "rules": rules,
        "subjects": subjects,
        "policies": policies,
    })
}

/// The whole Zenoh configuration of the bridge.
pub fn router_config(cfg: &Config) -> Value {
    let z = &cfg.zenoh;
    let path = |p: &std::path::Path| p.to_string_lossy().into_owned();
    json!({
        "mode": "router",
        "listen": { "endpoints": z.listen },
        "connect": { "endpoints": [] },
        "scouting": {
            "multicast": { "enabled": false },
            "gossip": { "enabled": false },
        },
        "transport": {
            "link": {
                "protocols": crate::config::link_protocols(&z.listen),
                // Clients notice a dead bridge within its lease.
                "tx": { "lease": z.lease_ms, "keep_alive": 4 },
                "tls": {
                    "root_ca_certificate": path(&z.ca),
                    "listen_certificate": path(&z.cert),
                    "listen_private_key": path(&z.key),
                    "enable_mtls": true,
                    "close_link_on_expiration": true,
                },
            },
            "shared_memory": { "enabled": false },
        },
        "adminspace": { "enabled": false },
        "access_control": access_control(cfg),
    })
}

/// Opens the bridge's Zenoh session (listening).
pub fn open(cfg: &Config) -> anyhow::Result<zenoh::Session> {
    use anyhow::Context;
    use zenoh::Wait;
    let json = router_config(cfg).to_string();
    let zc = zenoh::Config::from_json5(&json)
        .map_err(|e| anyhow::anyhow!(gaitd_client::remote::zenoh_text(e)))
        .context("building the Zenoh configuration")?;
    zenoh::open(zc)
        .wait()
        .map_err(|e| anyhow::anyhow!(gaitd_client::remote::zenoh_text(e)))
        .with_context(|| format!("listening on {}", cfg.zenoh.listen.join(", ")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn cfg() -> Config {
        Config::parse(
            "[zenoh]\nkey_prefix = \"lab\"\n\
             [[identity]]\nname = \"op\"\nrole = \"operator\"\n\
             [[identity]]\nname = \"dash\"\nrole = \"monitor\"\n",
            Path::new("t.toml"),
        )
        .unwrap()
    }

    fn policy_rules(acl: &Value, i: usize) -> Vec<String> {
        acl["policies"][i]["rules"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r.as_str().unwrap().to_owned())
            .collect()
    }

    #[test]
    fn default_deny_and_commands_only_for_operators() {
        let acl = access_control(&cfg());
        assert_eq!(acl["default_permission"], "deny");
        assert_eq!(acl["subjects"][0]["cert_common_names"][0], "op");
        let op = policy_rules(&acl, 0);
        let dash = policy_rules(&acl, 1);
        assert!(op.contains(&"cmd-in-0".to_owned()));
        assert!(!dash.iter().any(|r| r.starts_with("cmd-")));
        assert!(dash.contains(&"token-1".to_owned()));
        let text = acl.to_string();
        assert!(text.contains("lab/cmd/op/*"));
        assert!(!text.contains("lab/cmd/dash"));
        // Nobody is allowed to publish, but its beats on its own token key.
        for r in acl["rules"].as_array().unwrap() {
            if r["flows"][0] == "ingress"
                && r["messages"].as_array().unwrap().contains(&json!("put"))
            {
                let keys = r["key_exprs"].as_array().unwrap();
                assert!(
                    keys.iter()
                        .all(|k| k.as_str().unwrap().starts_with("lab/clients/")),
                    "{r}"
                );
            }
        }
    }

    #[test]
    fn the_generated_config_is_accepted_by_zenoh() {
        let json = router_config(&cfg()).to_string();
        zenoh::Config::from_json5(&json).expect("valid Zenoh config");
    }
}
