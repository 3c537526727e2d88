//! Every relative link in the project's Markdown documents resolves: the linked file exists, and
//! a `#fragment` names a heading of the target document as GitHub renders it (its anchor slug).
//!
//! Oracle: GitHub's heading-anchor rule (the one `github-slugger` implements): lower-case the
//! heading text, drop every character that is not a letter, a digit, a space, `-` or `_`,
//! turn each space into `-`, and suffix `-1`, `-2`, … to repeats. Inline code and emphasis
//! markers are dropped with the punctuation. Links inside fenced code blocks are not links.
//!
//! The documents are the READMEs below and every page of the book, as `docs/SUMMARY.md` lists
//! them (`crate::readme_snippets::book_pages`, which also refuses a page under `docs/` that
//! SUMMARY.md does not list); SUMMARY.md's own links are checked too.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

const DOCUMENTS: &[&str] = &[
    "README.md",
    "proto/README.md",
    "proto/c/README.md",
    "clients/python/README.md",
    "docs/SUMMARY.md",
];

/// The READMEs, SUMMARY.md and every page of the book.
fn documents() -> Vec<PathBuf> {
    let pages = crate::readme_snippets::book_pages().unwrap_or_else(|p| panic!("{}", p.join("\n")));
    DOCUMENTS.iter().map(PathBuf::from).chain(pages).collect()
}

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
    let documents = documents();
    assert!(documents.len() > DOCUMENTS.len(), "the book has no pages");
    let problems: Vec<String> = documents
        .iter()
        .flat_map(|d| broken_links(&root().join(d)))
        .collect();
    assert!(
        problems.is_empty(),
        "broken links:\n{}",
        problems.join("\n")
    );
}

/// The comment lines that open a configuration file, joined into one line (a citation may wrap).
fn header_text(toml: &str) -> String {
    toml.lines()
        .take_while(|l| l.starts_with('#'))
        .map(|l| l.trim_start_matches('#').trim())
        .collect::<Vec<_>>()
        .join(" ")
}

/// The text of the README section whose heading is exactly `title`, up to the next heading of
/// the same or a higher level; None when no heading has that text.
fn section<'a>(readme: &'a str, title: &str) -> Option<&'a str> {
    let lines: Vec<&str> = readme.lines().collect();
    let level = |l: &str| l.chars().take_while(|&c| c == '#').count();
    let start = lines.iter().position(|l| {
        let n = level(l);
        n > 0 && l[n..].trim() == title
    })?;
    let n = level(lines[start]);
    let end = lines[start + 1..]
        .iter()
        .position(|l| (1..=n).contains(&level(l)) && l[level(l)..].starts_with(' '))
        .map_or(lines.len(), |i| start + 1 + i);
    let from = lines[..start].iter().map(|l| l.len() + 1).sum::<usize>();
    let to = lines[..end].iter().map(|l| l.len() + 1).sum::<usize>();
    Some(&readme[from..to.min(readme.len())])
}

/// The `flexdyn-acs-demo` command lines of a README section, each with its `\` continuations.
fn demo_commands(section: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut lines = section.lines();
    while let Some(line) = lines.next() {
        if !line.contains("flexdyn-acs-demo") {
            continue;
        }
        let mut command = line.to_string();
        let mut last = line;
        while last.trim_end().ends_with('\\') {
            let Some(next) = lines.next() else { break };
            command.push(' ');
            command.push_str(next);
            last = next;
        }
        out.push(command);
    }
    out
}

/// What a configuration file's header cites: each `(book, "Section")` must be a heading of
/// README.md or of a page of the book, and each `flexdyn-acs-demo …` command the header quotes must be shown, every
/// option of it, in the cited section (so a newcomer finds the command the file promises).
fn header_problems(file: &str, header: &str, readme: &str) -> Vec<String> {
    let mut problems = Vec::new();
    let mut sections = Vec::new();
    for cite in header.split("book, \"").skip(1) {
        let Some(title) = cite.split('"').next() else {
            continue;
        };
        match section(readme, title) {
            Some(text) => sections.push(text),
            None => problems.push(format!(
                "{file}: cites book section {title:?}, not a heading"
            )),
        }
    }
    for quoted in header.split('`').skip(1).step_by(2) {
        if !quoted.starts_with("flexdyn-acs-demo") {
            continue;
        }
        for flag in quoted.split_whitespace().filter(|w| w.starts_with("--")) {
            let shown = sections
                .iter()
                .flat_map(|s| demo_commands(s))
                .any(|c| c.split_whitespace().any(|w| w == flag));
            if !shown {
                problems.push(format!(
                    "{file}: `{flag}` of its demo command is not in a command of the cited book section"
                ));
            }
        }
    }
    problems
}

#[test]
fn header_problems_are_found() {
    let readme = "# T\n## Wheels\n```sh\nflexdyn-acs-demo --a \\\n    --b\n```\n## Other\n--c\n";
    let ok = "# run `flexdyn-acs-demo --a --b` (book, \"Wheels\")\nx = 1\n";
    assert_eq!(
        header_problems("f", &header_text(ok), readme),
        Vec::<String>::new()
    );
    // A section that is not a heading, and an option the section's command lacks (`--c` is in
    // the README, but in another section and not in a command).
    let bad = "# `flexdyn-acs-demo --a --c` (book, \"Wheels\")\n# (book, \"Wheels\n# and more\")\n";
    let p = header_problems("f", &header_text(bad), readme);
    assert_eq!(p.len(), 2, "{p:?}");
    assert!(p[0].contains("\"Wheels and more\""), "{p:?}");
    assert!(p[1].contains("`--c`"), "{p:?}");
}

/// The shipped scenarios' headers cite README sections that exist and demo options the README
/// shows there. (The header of `wheels_star_tracker.toml` once cited a section, "Reaction wheels
/// and a star tracker", and options that the README never had.) Since the README became a short
/// README and a book (issue 36), a section cited as the README's is a heading of README.md or of
/// a page of the book.
#[test]
fn scenario_headers_cite_what_the_readme_shows() {
    let readme = documents()
        .iter()
        .filter(|d| !DOCUMENTS[1..].contains(&d.to_str().unwrap()))
        .map(|d| std::fs::read_to_string(root().join(d)).unwrap())
        .collect::<Vec<_>>()
        .join("\n");
    let mut problems = Vec::new();
    let mut cited = 0;
    for entry in std::fs::read_dir(root().join("scenarios")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let header = header_text(&std::fs::read_to_string(&path).unwrap());
            cited += header.matches("book, \"").count();
            problems.extend(header_problems(
                &path.display().to_string(),
                &header,
                &readme,
            ));
        }
    }
    assert!(
        cited >= 1,
        "no scenario header cites the README: the test checks nothing"
    );
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
