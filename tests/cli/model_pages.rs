//! The model reference is complete: every key a sensor kind or a listed effector kind reads (its
//! schema's keys, from the registries) and every error term a sensor bounds is named on the
//! kind's page of the book (`docs/models/*.md`, the page that shows a `[[<array>]]` entry). A key added to a
//! schema without a word in the book fails here (issue 36: the model reference generated, or
//! held to, the model's own schema keys).

use std::path::PathBuf;

fn pages() -> Vec<(PathBuf, String)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("docs/models");
    let mut out: Vec<(PathBuf, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let p = e.ok()?.path();
            (p.extension()? == "md").then(|| {
                let text = std::fs::read_to_string(&p).unwrap();
                (p, text)
            })
        })
        .collect();
    out.sort();
    out
}

/// Whether `text` names `key`: in backticks alone or at the end of a path (`` `…key` ``,
/// `` `key = …` ``), as a TOML line `key = …`, or as a sub-table header `[….key]`.
fn names(text: &str, key: &str) -> bool {
    text.split('`').skip(1).step_by(2).any(|code| {
        let code = code.trim();
        code == key
            || code.ends_with(&format!(".{key}"))
            || code.starts_with(&format!("{key} ="))
            || code.contains(&format!(".{key}["))
            || code.starts_with(&format!("{key}["))
    }) || text.lines().any(|l| {
        let l = l.trim_start();
        l.starts_with(&format!("{key} ="))
            || (l.starts_with('[') && l.contains(&format!(".{key}]")))
    })
}

/// The keys of `keys` that the model pages showing a `[[array]]` entry do not name, as
/// `array: `key` is not on PAGES`; panics if no page shows such an entry.
fn missing_keys<'k>(
    pages: &[(PathBuf, String)],
    array: &str,
    keys: impl Iterator<Item = &'k str>,
) -> Vec<String> {
    let heading = format!("[[{array}]]");
    let on: Vec<&(PathBuf, String)> = pages.iter().filter(|(_, t)| t.contains(&heading)).collect();
    assert!(
        !on.is_empty(),
        "no page of docs/models shows a {heading} entry"
    );
    let text: String = on.iter().map(|(_, t)| t.as_str()).collect();
    let files = on
        .iter()
        .map(|(p, _)| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join(", ");
    keys.filter(|key| !names(&text, key))
        .map(|key| format!("{array}: `{key}` is not on {files}"))
        .collect()
}

#[test]
fn every_sensor_key_and_error_term_is_on_its_model_page() {
    let pages = pages();
    let mut missing = Vec::new();
    for kind in flexdyn_sensors::KINDS {
        let terms = kind
            .config
            .error_terms
            .iter()
            .map(|(t, _)| t.rsplit('.').next().unwrap());
        missing.extend(missing_keys(
            &pages,
            kind.config_array,
            kind.config.keys.iter().copied().chain(terms),
        ));
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

/// The same for every effector kind configured through the generic list (`[[magnetorquers]]`,
/// `[[thrusters]]`, …: [`flexdyn_dynamics::kinds::KINDS`]).
#[test]
fn every_effector_key_is_on_its_model_page() {
    let pages = pages();
    let mut missing = Vec::new();
    let mut kinds = 0;
    for kind in flexdyn_dynamics::kinds::KINDS {
        let Some(reader) = &kind.reader else {
            continue;
        };
        kinds += 1;
        missing.extend(missing_keys(
            &pages,
            kind.section,
            reader.keys.iter().copied(),
        ));
    }
    assert!(kinds >= 2, "only {kinds} generic effector kinds");
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

#[test]
fn a_key_is_found_only_where_it_is_named() {
    assert!(names("the `noise_sigma_t` key", "noise_sigma_t"));
    assert!(names("`magnetometers[0].bias_s_t`", "bias_s_t"));
    assert!(names("```toml\nrate_hz = 10.0\n```", "rate_hz"));
    assert!(names("```toml\n[imus.gyro]\n```", "gyro"));
    assert!(!names("noise_sigma_t without backticks", "noise_sigma_t"));
    assert!(!names("`noise_sigma_tt`", "noise_sigma_t"));
}
