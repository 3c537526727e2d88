//! Every relative link in the project's Markdown documents resolves: the linked file exists, and
//! a `#fragment` names a heading of the target document as GitHub renders it (its anchor slug).
//!
//! Oracle: GitHub's heading-anchor rule (the one `github-slugger` implements): lower-case the
//! heading text, drop every character that is not a letter, a digit, a space, `-` or `_`,
//! turn each space into `-`, and suffix `-1`, `-2`, … to repeats. Inline code and emphasis
//! markers are dropped with the punctuation. Links inside fenced code blocks are not links.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

const DOCUMENTS: &[&str] = &[
    "README.md",
    "proto/README.md",
    "proto/c/README.md",
    "clients/python/README.md",
    "docs/errata.md",
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The document's lines outside fenced code blocks, with their 1-based numbers.
fn prose_lines(text: &str) -> Vec<(usize, &str)> {
    let mut fenced = false;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            out.push((i + 1, line));
        }
    }
    out
}

/// GitHub's anchor slug of a heading's text (see the module docs).
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// Every anchor a document's headings define, with GitHub's `-N` suffixes for repeats.
fn anchors(text: &str) -> HashSet<String> {
    let mut seen = HashSet::new();
    for (_, line) in prose_lines(text) {
        let hashes = line.chars().take_while(|c| *c == '#').count();
        if hashes == 0 || hashes > 6 || !line[hashes..].starts_with(' ') {
            continue;
        }
        let base = slug(&line[hashes..]);
        let mut candidate = base.clone();
        let mut n = 0;
        while seen.contains(&candidate) {
            n += 1;
            candidate = format!("{base}-{n}");
        }
        seen.insert(candidate);
    }
    seen
}

/// The targets of the inline links `[text](target)` on a line, without titles.
fn link_targets(line: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(i) = rest.find("](") {
        let after = &rest[i + 2..];
        let Some(end) = after.find(')') else { break };
        let target = after[..end].split_whitespace().next().unwrap_or("");
        out.push(target);
        rest = &after[end..];
    }
    out
}

/// Problems with the relative links of one document (empty if every one resolves).
fn broken_links(doc: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(doc).unwrap();
    let own_anchors = anchors(&text);
    let mut problems = Vec::new();
    for (n, line) in prose_lines(&text) {
        for target in link_targets(line) {
            if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let (path, fragment) = match target.split_once('#') {
                Some((p, f)) => (p, Some(f)),
                None => (target, None),
            };
            let file = if path.is_empty() {
                doc.to_path_buf()
            } else {
                doc.parent().unwrap().join(path)
            };
            let here = format!("{}:{n}: `{target}`", doc.display());
            if !file.exists() {
                problems.push(format!("{here}: no file {}", file.display()));
                continue;
            }
            let Some(fragment) = fragment else { continue };
            let defined = if path.is_empty() {
                own_anchors.contains(fragment)
            } else if file.extension().is_some_and(|e| e == "md") {
                anchors(&std::fs::read_to_string(&file).unwrap()).contains(fragment)
            } else {
                // A fragment into a source file (e.g. `#L10`) is not checked.
                true
            };
            if !defined {
                problems.push(format!("{here}: no heading with anchor #{fragment}"));
            }
        }
    }
    problems
}

#[test]
fn slug_follows_githubs_rule() {
    // Worked by hand from the rule in the module docs.
    assert_eq!(slug(" Lockstep in CI"), "lockstep-in-ci");
    assert_eq!(
        slug(" Recording, replay and viewing"),
        "recording-replay-and-viewing"
    );
    assert_eq!(
        slug(" CommandMsg — `flexdyn/<sc-id>/cmd/<sender-id>` (86, 38 or 94 + inputs bytes)"),
        "commandmsg--flexdynsc-idcmdsender-id-86-38-or-94--inputs-bytes"
    );
    let repeats = anchors("## Keys\n### Keys\n```\n## not a heading\n```\n## Keys\n");
    let expected: HashSet<String> = ["keys", "keys-1", "keys-2"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(repeats, expected);
}

#[test]
fn broken_links_are_found() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("doc_links");
    std::fs::create_dir_all(&dir).unwrap();
    let doc = dir.join("doc.md");
    std::fs::write(
        &doc,
        "# Title\n## Real section\n[ok](#real-section) [bad](#gone) [file](missing.md)\n\
         ```\n[in code](#not-checked)\n```\n",
    )
    .unwrap();
    let problems = broken_links(&doc);
    assert_eq!(problems.len(), 2, "{problems:#?}");
    assert!(problems[0].contains("#gone"));
    assert!(problems[1].contains("missing.md"));
}

#[test]
fn every_relative_link_in_the_documents_resolves() {
    let problems: Vec<String> = DOCUMENTS
        .iter()
        .flat_map(|d| broken_links(&root().join(d)))
        .collect();
    assert!(
        problems.is_empty(),
        "broken links:\n{}",
        problems.join("\n")
    );
}
