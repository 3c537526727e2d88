//! Binding participants to authenticated Zenoh subjects (`server.participant_subjects`).
//!
//! Zenoh enforces who may command: user/password authentication (`transport/auth/usrpwd`)
//! names every peer, and the access-control list (`access_control`) decides, per subject, which
//! messages may cross the server's interfaces on which keys. Each participant publishes on its
//! own key `flexdyn/<sc>/cmd/<sender_id>` (protocol 4), and the server rejects a command whose
//! `sender_id` differs from its key's (`rejected.wrong_identity`). So a participant's sender id
//! is bound to a subject exactly when the ACL lets only that subject `put` on that key.
//!
//! [`check`] verifies that before the server starts, with Zenoh's own decision rule
//! (`zenoh/src/net/routing/interceptor/authorization.rs`, `policy_decision_point`): for a
//! subject, a message is denied if any of its deny rules' key expressions includes the key;
//! otherwise, with `default_permission: "deny"`, it is allowed only if one of its allow rules
//! includes it. A subject that matches peers by anything other than a user name (interfaces,
//! link protocols, …) could be any user, so it may not hold a command key. The same holds for
//! the participant's lockstep liveliness token `flexdyn/<sc>/participant/<id>`: another user
//! allowed to declare it could fake the participant's presence, and in lockstep the bound user
//! must be allowed to.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use flexdyn_proto::Topics;
use serde_json::Value;
use zenoh::key_expr::KeyExpr;

use super::error::SettingsError;
use super::settings::ServerSettings;

fn bad(problem: impl Into<String>) -> SettingsError {
    SettingsError::Invalid {
        name: "server.participant_subjects".into(),
        problem: problem.into(),
    }
}

fn get(config: &zenoh::Config, key: &str) -> Value {
    config
        .get_json(key)
        .ok()
        .and_then(|s| serde_json::from_str(&s).ok())
        .unwrap_or(Value::Null)
}

fn strings(v: &Value, field: &str) -> Vec<String> {
    v.get(field)
        .and_then(Value::as_array)
        .map(|a| {
            a.iter()
                .filter_map(|x| x.as_str().map(str::to_owned))
                .collect()
        })
        .unwrap_or_default()
}

fn includes(rule_key: &str, key: &KeyExpr<'_>) -> Result<bool, SettingsError> {
    let rule = KeyExpr::try_from(rule_key).map_err(|e| {
        bad(format!(
            "access_control rule key expression `{rule_key}` is invalid: {e}"
        ))
    })?;
    Ok(rule.includes(key))
}

/// Whether the rules `rule_ids` let a `message` (`put`, `liveliness_token`), flowing `ingress`,
/// on `key`: deny wins, then any allow (the default permission being deny).
fn may(
    rules: &[Value],
    rule_ids: &BTreeSet<String>,
    message: &str,
    key: &KeyExpr<'_>,
) -> Result<bool, SettingsError> {
    let mut allowed = false;
    for rule in rules {
        let Some(id) = rule.get("id").and_then(Value::as_str) else {
            continue;
        };
        if !rule_ids.contains(id) {
            continue;
        }
        let messages = strings(rule, "messages");
        // Zenoh applies a rule without `flows` to both directions.
        let flows = strings(rule, "flows");
        if !messages.iter().any(|m| m == message)
            || !(flows.is_empty() || flows.iter().any(|f| f == "ingress"))
        {
            continue;
        }
        let mut hit = false;
        for ke in strings(rule, "key_exprs") {
            hit |= includes(&ke, key)?;
        }
        if hit {
            match rule.get("permission").and_then(Value::as_str) {
                Some("deny") => return Ok(false),
                Some("allow") => allowed = true,
                _ => {}
            }
        }
    }
    Ok(allowed)
}

/// The user names of a usrpwd dictionary file (`user:password` per line).
fn dictionary_users(path: &Path) -> Result<BTreeSet<String>, SettingsError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        bad(format!(
            "cannot read transport/auth/usrpwd/dictionary_file `{}`: {e}",
            path.display()
        ))
    })?;
    Ok(text
        .lines()
        .filter_map(|l| l.split_once(':').map(|(u, _)| u.trim().to_owned()))
        .filter(|u| !u.is_empty())
        .collect())
}

/// Checks that `config` (the server's Zenoh configuration) authenticates peers and that its
/// access-control list reserves each participant's command key for the subject
/// `settings.participant_subjects` names. Nothing to check when that setting is empty.
pub fn check(config: &zenoh::Config, settings: &ServerSettings) -> Result<(), SettingsError> {
    if settings.participant_subjects.is_empty() {
        return Ok(());
    }
    let dictionary = get(config, "transport/auth/usrpwd/dictionary_file");
    let Some(dictionary) = dictionary.as_str() else {
        return Err(bad(
            "binding participants to subjects needs authenticated peers: set \
             transport/auth/usrpwd/dictionary_file in the server's --zenoh-config (see \
             scenarios/zenoh/secure-server.json5)",
        ));
    };
    let users = dictionary_users(&PathBuf::from(dictionary))?;
    for (id, user) in &settings.participant_subjects {
        if !users.contains(user) {
            return Err(bad(format!(
                "participant {id}'s subject `{user}` is not a user of the dictionary file \
                 `{dictionary}`"
            )));
        }
    }
    let acl = get(config, "access_control");
    if acl.get("enabled") != Some(&Value::Bool(true)) {
        return Err(bad(
            "binding participants to subjects needs Zenoh's access control: set \
             access_control.enabled = true in the server's --zenoh-config",
        ));
    }
    if acl.get("default_permission").and_then(Value::as_str) != Some("deny") {
        return Err(bad(
            "access_control.default_permission must be \"deny\": with \"allow\" any \
             authenticated peer not named in a policy may put on the command keys",
        ));
    }
    let list = |field: &str| {
        acl.get(field)
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default()
    };
    let (rules, subjects, policies) = (list("rules"), list("subjects"), list("policies"));
    let topics = Topics::new(&settings.sc_id).map_err(|e| bad(e.to_string()))?;
    let lockstep = settings.mode == flexdyn_proto::Mode::Lockstep;
    for (&sender, user) in &settings.participant_subjects {
        // The command key, and the lockstep liveliness token (whoever may declare it can make
        // the server believe participant `sender` is present).
        let checks = [
            (
                "put",
                topics.cmd(sender),
                "put on",
                "command key",
                "commands would never arrive",
                true,
            ),
            (
                "liveliness_token",
                topics.participant(sender),
                "declare",
                "lockstep liveliness token",
                "presence would never be seen and lockstep would not start",
                lockstep,
            ),
        ];
        for (message, key_text, verb, what, consequence, owner_needed) in checks {
            let key = KeyExpr::try_from(key_text.as_str()).map_err(|e| bad(e.to_string()))?;
            let mut owner_may = false;
            for subject in &subjects {
                let Some(subject_id) = subject.get("id").and_then(Value::as_str) else {
                    continue;
                };
                let rule_ids: BTreeSet<String> = policies
                    .iter()
                    .filter(|p| strings(p, "subjects").iter().any(|s| s == subject_id))
                    .flat_map(|p| strings(p, "rules"))
                    .collect();
                if !may(&rules, &rule_ids, message, &key)? {
                    continue;
                }
                let usernames = strings(subject, "usernames");
                if usernames.is_empty() {
                    return Err(bad(format!(
                        "access_control subject `{subject_id}` may {verb} `{key_text}` but \
                         names no user (usernames), so any authenticated peer matching it \
                         could act as participant {sender}; only `{user}` may"
                    )));
                }
                if let Some(other) = usernames.iter().find(|u| *u != user) {
                    return Err(bad(format!(
                        "access_control lets user `{other}` (subject `{subject_id}`) {verb} \
                         `{key_text}`, participant {sender}'s {what}; only `{user}` may"
                    )));
                }
                owner_may = true;
            }
            if owner_needed && !owner_may {
                return Err(bad(format!(
                    "access_control does not let `{user}` {verb} `{key_text}`: participant \
                     {sender}'s {consequence}"
                )));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(subjects: &[(u32, &str)]) -> ServerSettings {
        ServerSettings {
            participants: subjects.iter().map(|(id, _)| *id).collect(),
            participant_subjects: subjects
                .iter()
                .map(|(id, u)| (*id, (*u).to_owned()))
                .collect(),
            ..ServerSettings::default()
        }
    }

    fn config(dictionary: &Path, acl: &str) -> zenoh::Config {
        let mut c = zenoh::Config::default();
        c.insert_json5(
            "transport/auth/usrpwd/dictionary_file",
            &serde_json::to_string(&dictionary.to_string_lossy()).unwrap(),
        )
        .unwrap();
        if !acl.is_empty() {
            c.insert_json5("access_control", acl).unwrap();
        }
        c
    }

    const GOOD: &str = r#"{
        enabled: true, default_permission: "deny",
        rules: [
          { id: "fsw-cmd", messages: ["put"], flows: ["ingress"], permission: "allow",
            key_exprs: ["flexdyn/sc1/cmd/1"] },
          { id: "gnc-cmd", messages: ["put"], flows: ["ingress"], permission: "allow",
            key_exprs: ["flexdyn/sc1/cmd/2"] },
          { id: "tlm", messages: ["put", "declare_subscriber"], permission: "allow",
            key_exprs: ["flexdyn/sc1/tlm/**", "flexdyn/sc1/status"] } ],
        subjects: [ { id: "fsw", usernames: ["fsw"] }, { id: "gnc", usernames: ["gnc"] },
                    { id: "anyone", usernames: ["fsw", "gnc", "viewer"] } ],
        policies: [ { rules: ["fsw-cmd"], subjects: ["fsw"] },
                    { rules: ["gnc-cmd"], subjects: ["gnc"] },
                    { rules: ["tlm"], subjects: ["anyone"] } ] }"#;

    fn problem(r: Result<(), SettingsError>) -> String {
        match r {
            Err(SettingsError::Invalid { name, problem }) => {
                assert_eq!(name, "server.participant_subjects");
                problem
            }
            other => panic!("expected an error, got {other:?}"),
        }
    }

    #[test]
    fn a_correct_acl_passes_and_every_hole_is_named() {
        let dir = std::env::temp_dir().join(format!("flexdyn-access-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let dict = dir.join("users.txt");
        std::fs::write(&dict, "fsw:a\ngnc:b\nviewer:c\n").unwrap();
        let s = settings(&[(1, "fsw"), (2, "gnc")]);
        check(&config(&dict, GOOD), &s).unwrap();
        // Nothing to check without subjects, whatever the config.
        check(&zenoh::Config::default(), &ServerSettings::default()).unwrap();

        // No authentication.
        let p = problem(check(&zenoh::Config::default(), &s));
        assert!(p.contains("transport/auth/usrpwd/dictionary_file"), "{p}");
        // A subject that is no user of the dictionary.
        let p = problem(check(
            &config(&dict, GOOD),
            &settings(&[(1, "fsw"), (2, "nobody")]),
        ));
        assert!(p.contains("`nobody` is not a user"), "{p}");
        // No ACL, or a permissive one.
        let p = problem(check(&config(&dict, ""), &s));
        assert!(p.contains("access_control.enabled"), "{p}");
        let allow = GOOD.replace(
            "default_permission: \"deny\"",
            "default_permission: \"allow\"",
        );
        let p = problem(check(&config(&dict, &allow), &s));
        assert!(p.contains("default_permission must be \"deny\""), "{p}");
        // Swapped keys: gnc may put on participant 1's key.
        let swapped = GOOD
            .replace("\"flexdyn/sc1/cmd/1\"", "\"flexdyn/sc1/cmd/X\"")
            .replace("\"flexdyn/sc1/cmd/2\"", "\"flexdyn/sc1/cmd/1\"")
            .replace("\"flexdyn/sc1/cmd/X\"", "\"flexdyn/sc1/cmd/2\"");
        let p = problem(check(&config(&dict, &swapped), &s));
        assert!(
            p.contains("lets user `gnc` (subject `gnc`) put on `flexdyn/sc1/cmd/1`"),
            "{p}"
        );
        // A wildcard rule for everyone covers the command keys.
        let wild = GOOD.replace("\"flexdyn/sc1/tlm/**\"", "\"flexdyn/sc1/**\"");
        let p = problem(check(&config(&dict, &wild), &s));
        assert!(p.contains("put on `flexdyn/sc1/cmd/1`"), "{p}");
        // ...unless a deny rule takes it back (deny wins, as in Zenoh).
        let denied = wild
            .replace(
                "{ rules: [\"tlm\"], subjects: [\"anyone\"] }",
                "{ rules: [\"tlm\", \"no-cmd\"], subjects: [\"anyone\"] }",
            )
            .replace(
                "rules: [\n",
                "rules: [\n          { id: \"no-cmd\", messages: [\"put\"], flows: [\"ingress\"], \
                 permission: \"deny\", key_exprs: [\"flexdyn/sc1/cmd/*\"] },\n",
            );
        check(&config(&dict, &denied), &s).unwrap();
        // A subject matched by interface only could be anyone.
        let iface = GOOD.replace(
            "{ id: \"fsw\", usernames: [\"fsw\"] }",
            "{ id: \"fsw\", interfaces: [\"lo\"] }",
        );
        let p = problem(check(&config(&dict, &iface), &s));
        assert!(p.contains("names no user"), "{p}");
        // The owner cannot put: its commands would never arrive.
        let egress = GOOD.replacen("flows: [\"ingress\"]", "flows: [\"egress\"]", 1);
        let p = problem(check(&config(&dict, &egress), &s));
        assert!(
            p.contains("does not let `fsw` put on `flexdyn/sc1/cmd/1`"),
            "{p}"
        );

        // Liveliness tokens: GOOD grants none. Real time does not need them; lockstep does.
        let lockstep = ServerSettings {
            mode: flexdyn_proto::Mode::Lockstep,
            ..s.clone()
        };
        let p = problem(check(&config(&dict, GOOD), &lockstep));
        assert!(
            p.contains("does not let `fsw` declare `flexdyn/sc1/participant/1`"),
            "{p}"
        );
        let tokens = GOOD.replace(
            "rules: [\n",
            "rules: [\n          { id: \"tokens\", messages: [\"liveliness_token\"], \
             flows: [\"ingress\"], permission: \"allow\", key_exprs: [\"flexdyn/sc1/participant/*\"] },\n",
        );
        // Everyone may declare every token: gnc could fake participant 1's presence.
        let shared_tokens = tokens.replace(
            "{ rules: [\"tlm\"], subjects: [\"anyone\"] }",
            "{ rules: [\"tlm\", \"tokens\"], subjects: [\"anyone\"] }",
        );
        let p = problem(check(&config(&dict, &shared_tokens), &lockstep));
        assert!(
            p.contains("lets user `gnc` (subject `anyone`) declare `flexdyn/sc1/participant/1`"),
            "{p}"
        );
        // Each participant its own token: accepted.
        let own_tokens = GOOD
            .replace(
                "{ id: \"tlm\",",
                "{ id: \"fsw-token\", messages: [\"liveliness_token\"], permission: \"allow\", \
                 key_exprs: [\"flexdyn/sc1/participant/1\"] },\n          \
                 { id: \"gnc-token\", messages: [\"liveliness_token\"], permission: \"allow\", \
                 key_exprs: [\"flexdyn/sc1/participant/2\"] },\n          { id: \"tlm\",",
            )
            .replace(
                "rules: [\"fsw-cmd\"]",
                "rules: [\"fsw-cmd\", \"fsw-token\"]",
            )
            .replace(
                "rules: [\"gnc-cmd\"]",
                "rules: [\"gnc-cmd\", \"gnc-token\"]",
            );
        check(&config(&dict, &own_tokens), &lockstep).unwrap();
        std::fs::remove_dir_all(&dir).ok();
    }
}
