//! Every fenced block of README.md and of the book under `docs/` runs here, or is marked as what
//! it is (issue 25: "every snippet in the README runs in a test, or is marked as an excerpt of a
//! file that does"; issue 36 cut the README into a short README and a book).
//!
//! The documents are README.md, then every page that `docs/SUMMARY.md` lists, in its order
//! ([`book_pages`]). A Markdown file under `docs/` that SUMMARY.md does not list, or a listed page
//! that does not exist, is an error: a page nobody reaches is a page nobody checks.
//!
//! **One sandbox, in book order.** The pages are not self-contained: a block may use what an
//! earlier block wrote (`my_craft.toml` from the Simulate guide in the lockstep-in-CI guide,
//! `pair.toml` from "Several spacecraft" in "Fleet in the server"), exactly as a reader who
//! follows the README and then the book in order has it. So every shell block runs in the same
//! sandbox directory, README first, then the pages in SUMMARY order; moving a page in SUMMARY.md
//! moves its blocks.
//!
//! The line before each block is a marker, `<!-- snippet: KIND -->`:
//!
//! | KIND | the block | what this test does |
//! |---|---|---|
//! | `run` | shell | runs it with bash (`-e`), in book order, in one sandbox directory; it must exit 0 |
//! | `run (Ctrl-C after N s)` | shell | the same; a command that runs until Ctrl-C gets SIGINT after N s and must exit 0 |
//! | `terminals (Ctrl-C after N s)` | shell | each command in its own terminal, started in order 1 s apart; likewise |
//! | `config` / `config onto PATH` | TOML | its tables replace those of the embedded default (or of PATH); `flexdyn check-config` must accept the result |
//! | `excerpt of PATH` | any | its lines appear, in order, in PATH |
//! | `output of `CMD`` | text | runs CMD in the sandbox; its output holds the block's lines, in order (with ` (numbers vary)`: any number matches any number) |
//! | `synopsis` | text | every `--option` of each line is in `PROGRAM [SUBCOMMAND] --help` |
//! | `bench` | shell | each `cargo bench [-p PKG] --bench NAME` names a `[[bench]]` of PKG with its file |
//! | `install (WHY)` | shell | nothing: installs on the user's machine; WHY says what does the same |
//! | `elsewhere (WHY)` | any | nothing: needs what this machine lacks (a cluster, a lab network); WHY names the test that runs the same command, and the file must exist |
//!
//! Paths in markers (`config onto PATH`, `excerpt of PATH`, the files an `elsewhere` names) are
//! relative to the repository's root, whichever page the block is on.
//!
//! Python blocks are checked by `clients/python/tests/test_readme_snippets.py`.
//!
//! Shell blocks run in the sandbox (`target/<profile>/readme-sandbox`), with `scenarios/` linked
//! in and `target/release/` holding stand-ins (`tests/readme/stand_in.sh`) for `cargo` and the
//! binaries, first on the PATH. The `cargo` stand-in picks the binary of `cargo run` as cargo
//! does, from the workspace's packages as `cargo metadata` reports them (written once into the
//! sandbox's `packages.txt`; [`write_packages`]), so a command real cargo refuses fails here too.
//! Each block runs in its own network namespace (`unshare -rn`, loopback up), so the documents'
//! ports (7447, 17500, 8765) are used as written and can collide with nothing outside; no test
//! here picks a port on the host.

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The longest any block may take.
const BLOCK_LIMIT: Duration = Duration::from_secs(300);

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `target/<profile>`: where `cargo test --workspace` put every binary of the workspace.
fn bin_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_flexdyn"))
        .parent()
        .expect("the profile directory")
        .to_path_buf()
}

#[derive(Debug)]
struct Block {
    /// 1-based line of the opening fence.
    line: usize,
    lang: String,
    marker: Option<String>,
    text: String,
}

fn blocks(text: &str) -> Vec<Block> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if let Some(lang) = lines[i].strip_prefix("```") {
            let start = i;
            let mut j = i + 1;
            while j < lines.len() && !lines[j].starts_with("```") {
                j += 1;
            }
            let marker = start
                .checked_sub(1)
                .and_then(|p| lines[p].strip_prefix("<!-- snippet: "))
                .and_then(|m| m.strip_suffix(" -->"))
                .map(str::to_owned);
            out.push(Block {
                line: start + 1,
                lang: lang.trim().to_owned(),
                marker,
                text: lines[start + 1..j.min(lines.len())].join("\n") + "\n",
            });
            i = j;
        }
        i += 1;
    }
    out
}

/// What a marker asks for.
#[derive(Debug, PartialEq)]
enum Kind {
    Run {
        stop_s: Option<u32>,
    },
    Terminals {
        stop_s: u32,
    },
    Config {
        onto: Option<String>,
    },
    Excerpt(String),
    /// The command, and whether numbers may differ (timings).
    Output(String, bool),
    Synopsis,
    Bench,
    Install,
    Elsewhere(String),
}

fn parse_kind(marker: &str) -> Result<Kind, String> {
    let ctrl_c = |rest: &str| -> Result<u32, String> {
        rest.strip_prefix("(Ctrl-C after ")
            .and_then(|r| r.strip_suffix(" s)"))
            .and_then(|n| n.parse().ok())
            .ok_or_else(|| format!("expected `(Ctrl-C after N s)`, got `{rest}`"))
    };
    Ok(match marker {
        "run" => Kind::Run { stop_s: None },
        "config" => Kind::Config { onto: None },
        "synopsis" => Kind::Synopsis,
        "bench" => Kind::Bench,
        m => {
            if let Some(rest) = m.strip_prefix("run ") {
                Kind::Run {
                    stop_s: Some(ctrl_c(rest)?),
                }
            } else if let Some(rest) = m.strip_prefix("terminals ") {
                Kind::Terminals {
                    stop_s: ctrl_c(rest)?,
                }
            } else if let Some(path) = m.strip_prefix("config onto ") {
                Kind::Config {
                    onto: Some(path.to_owned()),
                }
            } else if let Some(path) = m.strip_prefix("excerpt of ") {
                Kind::Excerpt(path.to_owned())
            } else if let Some(cmd) = m
                .strip_prefix("output of `")
                .and_then(|c| c.strip_suffix("` (numbers vary)"))
            {
                Kind::Output(cmd.to_owned(), true)
            } else if let Some(cmd) = m
                .strip_prefix("output of `")
                .and_then(|c| c.strip_suffix('`'))
            {
                Kind::Output(cmd.to_owned(), false)
            } else if m.starts_with("install (") && m.ends_with(')') {
                Kind::Install
            } else if let Some(why) = m
                .strip_prefix("elsewhere (")
                .and_then(|w| w.strip_suffix(')'))
            {
                Kind::Elsewhere(why.to_owned())
            } else {
                return Err(format!("unknown marker `{m}`"));
            }
        }
    })
}

/// The sandbox: `scenarios` linked, `target/release` holding the stand-ins.
fn sandbox() -> PathBuf {
    let dir = bin_dir().join("readme-sandbox");
    let _ = std::fs::remove_dir_all(&dir);
    let stand_ins = dir.join("target/release");
    std::fs::create_dir_all(&stand_ins).unwrap();
    std::os::unix::fs::symlink(root().join("scenarios"), dir.join("scenarios")).unwrap();
    // The scripts that `output of` blocks run.
    std::fs::create_dir(dir.join("tests")).unwrap();
    std::os::unix::fs::symlink(root().join("tests/readme"), dir.join("tests/readme")).unwrap();
    write_packages(&dir.join(PACKAGES)).unwrap();
    let script = root().join("tests/readme/stand_in.sh");
    for name in [
        "cargo",
        "flexdyn",
        "flexdyn-acs-demo",
        "flexdyn-formation-demo",
        "flexdyn-monitor",
    ] {
        std::os::unix::fs::symlink(&script, stand_ins.join(name)).unwrap();
    }
    dir
}

/// The sandbox's list of the workspace's packages, which the `cargo` stand-in reads.
const PACKAGES: &str = "packages.txt";

/// Writes, for every package of the workspace, `name|default-run|bin,bin,…` (the root package's
/// line first), from `cargo metadata`: the cargo that runs this test (`$CARGO`) reads the
/// manifests, so the stand-in resolves `cargo run` from the same facts as cargo. (`cargo run` or
/// `cargo build` from here would wait forever for the build directory, which `cargo test` holds.)
fn write_packages(file: &Path) -> Result<(), String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = Command::new(cargo)
        .args([
            "metadata",
            "--no-deps",
            "--format-version",
            "1",
            "--offline",
        ])
        .current_dir(root())
        .output()
        .map_err(|e| format!("cargo metadata: {e}"))?;
    if !out.status.success() {
        return Err(format!("cargo metadata: {}", shown(&out)));
    }
    let meta: serde_json::Value =
        serde_json::from_slice(&out.stdout).map_err(|e| format!("cargo metadata: {e}"))?;
    let root_manifest = root().join("Cargo.toml");
    let mut lines = Vec::new();
    for pkg in meta["packages"]
        .as_array()
        .ok_or("cargo metadata: no packages")?
    {
        let name = pkg["name"]
            .as_str()
            .ok_or("cargo metadata: a package without a name")?;
        let bins: Vec<&str> = pkg["targets"]
            .as_array()
            .into_iter()
            .flatten()
            .filter(|t| {
                t["kind"]
                    .as_array()
                    .is_some_and(|k| k.iter().any(|k| k == "bin"))
            })
            .filter_map(|t| t["name"].as_str())
            .collect();
        let line = format!(
            "{name}|{}|{}",
            pkg["default_run"].as_str().unwrap_or(""),
            bins.join(",")
        );
        let is_root = pkg["manifest_path"]
            .as_str()
            .is_some_and(|m| Path::new(m) == root_manifest);
        if is_root {
            lines.insert(0, line);
        } else {
            lines.push(line);
        }
    }
    std::fs::write(file, lines.join("\n") + "\n").map_err(|e| format!("{}: {e}", file.display()))
}

/// Runs `script` (bash) in the sandbox, in a network namespace of its own with loopback up,
/// with the stand-ins first on the PATH; kills it after [`BLOCK_LIMIT`].
fn run_in_sandbox(sandbox: &Path, script: &str, stop_s: Option<u32>) -> Output {
    let path = format!(
        "{}:{}:/usr/sbin:/sbin",
        sandbox.join("target/release").display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let file = sandbox.join("block.sh");
    std::fs::write(&file, script).unwrap();
    let mut cmd = Command::new("unshare");
    cmd.args([
        "-rn",
        "bash",
        "-c",
        "ip link set lo up && exec bash -e block.sh",
    ])
    .current_dir(sandbox)
    .env("PATH", path)
    .env("README_BIN_DIR", bin_dir())
    .env("README_PACKAGES", sandbox.join(PACKAGES))
    .env_remove("README_STOP_S")
    .stdin(Stdio::null())
    .stdout(Stdio::piped())
    .stderr(Stdio::piped());
    if let Some(s) = stop_s {
        cmd.env("README_STOP_S", s.to_string());
    }
    let mut child = cmd.spawn().expect(
        "`unshare` (util-linux) and `ip` (iproute2) run every README block in a network \
         namespace of its own",
    );
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if start.elapsed() > BLOCK_LIMIT {
            let _ = child.kill();
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

fn shown(out: &Output) -> String {
    format!(
        "exit: {}\n--- stdout\n{}--- stderr\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// A shell block's commands: `\`-continued lines joined; comments and blank lines dropped.
fn commands(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut current = String::new();
    for line in text.lines() {
        let line = line.trim();
        if current.is_empty() && (line.is_empty() || line.starts_with('#')) {
            continue;
        }
        if let Some(head) = line.strip_suffix('\\') {
            current.push_str(head.trim_end());
            current.push(' ');
        } else {
            current.push_str(line);
            out.push(std::mem::take(&mut current));
        }
    }
    out
}

/// The block's lines appear, in order, in `haystack` (each line trimmed; blank lines skipped).
fn in_order(block: &str, haystack: &str) -> Result<(), String> {
    let mut rest = haystack;
    for line in block.lines().map(str::trim).filter(|l| !l.is_empty()) {
        match rest.find(line) {
            Some(at) => rest = &rest[at + line.len()..],
            None => return Err(format!("{line:?} is not there (in order)")),
        }
    }
    Ok(())
}

/// `text` with every number (digits, a point, digits) replaced by `#`.
fn numbers_as_hash(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut in_number = false;
    for c in text.chars() {
        let digit = c.is_ascii_digit() || (in_number && c == '.');
        if digit && !in_number {
            out.push('#');
        } else if !digit {
            out.push(c);
        }
        in_number = digit;
    }
    out
}

/// `base` with each top-level key of `block` replacing its own.
fn merged_config(base: &str, block: &str) -> Result<String, String> {
    let mut base: toml::Table = base.parse().map_err(|e| format!("base: {e}"))?;
    let block: toml::Table = block.parse().map_err(|e| format!("block: {e}"))?;
    for (k, v) in block {
        base.insert(k, v);
    }
    Ok(toml::to_string(&base).unwrap())
}

/// Checks one block; `Err` says what does not hold.
fn check(block: &Block, kind: &Kind, sandbox: &Path) -> Result<(), String> {
    let flexdyn = env!("CARGO_BIN_EXE_flexdyn");
    match kind {
        Kind::Run { stop_s } => {
            let out = run_in_sandbox(sandbox, &block.text, *stop_s);
            if !out.status.success() {
                return Err(shown(&out));
            }
        }
        Kind::Terminals { stop_s } => {
            let mut script = String::from("set -m\npids=()\n");
            for (i, c) in commands(&block.text).iter().enumerate() {
                std::fs::write(sandbox.join(format!("terminal{i}.sh")), c).unwrap();
                script += &format!(
                    "bash -e terminal{i}.sh > terminal{i}.log 2>&1 & pids+=($!); sleep 1\n"
                );
            }
            script += "rc=0\nfor i in \"${!pids[@]}\"; do\n  if ! wait \"${pids[$i]}\"; then \
                       rc=1; echo \"terminal $i failed:\"; cat terminal$i.log; fi\ndone\nexit $rc\n";
            let out = run_in_sandbox(sandbox, &script, Some(*stop_s));
            if !out.status.success() {
                return Err(shown(&out));
            }
        }
        Kind::Config { onto } => {
            let base = match onto {
                Some(p) => {
                    std::fs::read_to_string(root().join(p)).map_err(|e| format!("{p}: {e}"))?
                }
                None => String::from_utf8(
                    Command::new(flexdyn)
                        .arg("print-default-config")
                        .output()
                        .unwrap()
                        .stdout,
                )
                .unwrap(),
            };
            let file = sandbox.join(format!("readme_line_{}.toml", block.line));
            std::fs::write(&file, merged_config(&base, &block.text)?).unwrap();
            let out = Command::new(flexdyn)
                .arg("check-config")
                .arg(&file)
                .current_dir(root())
                .output()
                .unwrap();
            if !out.status.success() {
                return Err(shown(&out));
            }
        }
        Kind::Excerpt(path) => {
            let source =
                std::fs::read_to_string(root().join(path)).map_err(|e| format!("{path}: {e}"))?;
            in_order(&block.text, &source).map_err(|e| format!("{e} in {path}"))?;
        }
        Kind::Output(cmd, numbers_vary) => {
            let out = run_in_sandbox(sandbox, &format!("{cmd}\n"), None);
            let text = String::from_utf8_lossy(&out.stdout).into_owned()
                + &String::from_utf8_lossy(&out.stderr);
            let (expected, text) = if *numbers_vary {
                (numbers_as_hash(&block.text), numbers_as_hash(&text))
            } else {
                (block.text.clone(), text)
            };
            in_order(&expected, &text).map_err(|e| format!("{e}\n{}", shown(&out)))?;
        }
        Kind::Synopsis => {
            // A line that starts with blanks continues the one above.
            let mut lines: Vec<String> = Vec::new();
            for l in block.text.lines().filter(|l| !l.trim().is_empty()) {
                match lines.last_mut() {
                    Some(last) if l.starts_with(char::is_whitespace) => *last += l,
                    _ => lines.push(l.to_owned()),
                }
            }
            for line in lines {
                let words: Vec<&str> = line.split_whitespace().collect();
                let mut help = Command::new(bin_dir().join(words[0]));
                if let Some(sub) = words
                    .get(1)
                    .filter(|w| w.starts_with(|c: char| c.is_ascii_lowercase()))
                {
                    help.arg(sub);
                }
                let out = help
                    .arg("--help")
                    .output()
                    .map_err(|e| format!("{line}: {e}"))?;
                let text = String::from_utf8_lossy(&out.stdout);
                for option in line
                    .split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
                    .filter(|w| w.starts_with("--"))
                {
                    if !text
                        .split(|c: char| c.is_whitespace() || c == ',')
                        .any(|w| w == option)
                    {
                        return Err(format!("`{line}`: {option} is not in its --help"));
                    }
                }
            }
        }
        Kind::Bench => {
            for line in commands(&block.text) {
                let words: Vec<&str> = line.split('#').next().unwrap().split_whitespace().collect();
                let after = |flag: &str| {
                    words
                        .iter()
                        .position(|w| *w == flag)
                        .and_then(|i| words.get(i + 1))
                        .copied()
                };
                let name = after("--bench").ok_or(format!("`{line}`: no --bench NAME"))?;
                let dir = match after("-p") {
                    None | Some("flexdyn") => root(),
                    Some(p) => package_dir(p).ok_or(format!("`{line}`: no package {p}"))?,
                };
                let manifest: toml::Table = std::fs::read_to_string(dir.join("Cargo.toml"))
                    .unwrap()
                    .parse()
                    .unwrap();
                let declared = manifest
                    .get("bench")
                    .and_then(|b| b.as_array())
                    .is_some_and(|b| {
                        b.iter()
                            .any(|b| b.get("name").and_then(|n| n.as_str()) == Some(name))
                    });
                if !declared || !dir.join(format!("benches/{name}.rs")).is_file() {
                    return Err(format!(
                        "`{line}`: no [[bench]] {name} in {}",
                        dir.display()
                    ));
                }
            }
        }
        Kind::Install => {}
        Kind::Elsewhere(why) => {
            let named = why
                .split(|c: char| c.is_whitespace() || c == ',' || c == ';' || c == '`')
                .filter(|w| w.contains('/') && root().join(w).is_file())
                .count();
            if named == 0 {
                return Err(format!(
                    "`{why}` names no file of the repository that runs the same"
                ));
            }
        }
    }
    Ok(())
}

/// The directory of the workspace member named `package`.
fn package_dir(package: &str) -> Option<PathBuf> {
    let manifest: toml::Table = std::fs::read_to_string(root().join("Cargo.toml"))
        .ok()?
        .parse()
        .ok()?;
    manifest["workspace"]["members"]
        .as_array()?
        .iter()
        .filter_map(|m| m.as_str())
        .map(|m| root().join(m))
        .find(|dir| {
            std::fs::read_to_string(dir.join("Cargo.toml"))
                .ok()
                .and_then(|t| t.parse::<toml::Table>().ok())
                .and_then(|t| {
                    t.get("package")?
                        .get("name")?
                        .as_str()
                        .map(|n| n == package)
                })
                .unwrap_or(false)
        })
}

/// The book's pages, in the order `docs/SUMMARY.md` lists them (its `- [Title](path.md)` items),
/// relative to the repository's root. Errors: a listed page that does not exist, a page listed
/// twice, and a Markdown file under `docs/` (but SUMMARY.md itself) that SUMMARY.md does not
/// list.
pub(crate) fn book_pages() -> Result<Vec<PathBuf>, Vec<String>> {
    let docs = root().join("docs");
    let summary = std::fs::read_to_string(docs.join("SUMMARY.md"))
        .map_err(|e| vec![format!("docs/SUMMARY.md: {e}")])?;
    let mut problems = Vec::new();
    let mut pages: Vec<PathBuf> = Vec::new();
    for (n, line) in summary.lines().enumerate() {
        let item = line.trim_start();
        if !(item.starts_with("- [") || item.starts_with("* [")) {
            continue;
        }
        let Some(target) = item
            .split_once("](")
            .and_then(|(_, rest)| rest.split_once(')'))
            .map(|(t, _)| t)
        else {
            problems.push(format!("docs/SUMMARY.md:{}: an item without a link", n + 1));
            continue;
        };
        let page = PathBuf::from("docs").join(target);
        if !root().join(&page).is_file() {
            problems.push(format!(
                "docs/SUMMARY.md:{}: {} does not exist",
                n + 1,
                page.display()
            ));
        } else if pages.contains(&page) {
            problems.push(format!(
                "docs/SUMMARY.md:{}: {} is listed twice",
                n + 1,
                page.display()
            ));
        } else {
            pages.push(page);
        }
    }
    let mut stack = vec![docs.clone()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "md") {
                let rel = path.strip_prefix(root()).unwrap().to_path_buf();
                if rel != Path::new("docs/SUMMARY.md") && !pages.contains(&rel) {
                    problems.push(format!(
                        "{}: not listed in docs/SUMMARY.md, so no reader finds it and no test runs it",
                        rel.display()
                    ));
                }
            }
        }
    }
    if problems.is_empty() {
        Ok(pages)
    } else {
        Err(problems)
    }
}

/// README.md, then the book's pages in SUMMARY order: the documents whose blocks run here.
pub(crate) fn documents() -> Result<Vec<PathBuf>, Vec<String>> {
    let mut docs = vec![PathBuf::from("README.md")];
    docs.extend(book_pages()?);
    Ok(docs)
}

#[test]
fn every_block_of_the_readme_and_the_book_runs_or_is_marked() {
    let documents = documents().unwrap_or_else(|p| panic!("\n{}", p.join("\n")));
    let sandbox = sandbox();
    let mut problems = Vec::new();
    let mut counts = std::collections::BTreeMap::<String, usize>::new();
    for doc in &documents {
        let text = std::fs::read_to_string(root().join(doc)).unwrap();
        for block in blocks(&text).iter().filter(|b| b.lang != "python") {
            let where_ = format!("{}:{} ({})", doc.display(), block.line, block.lang);
            check_block(block, &where_, &sandbox, &mut problems, &mut counts);
        }
    }
    eprintln!("blocks by kind: {counts:?}");
    assert!(problems.is_empty(), "\n{}", problems.join("\n\n"));
    // 62 blocks when the README was cut into the book (issue 36): far fewer means pages are gone.
    assert!(
        counts.values().sum::<usize>() > 50,
        "only {} blocks: are the book's pages there?",
        counts.values().sum::<usize>()
    );
}

/// Checks one block of a document; a problem goes into `problems`, and the block is counted by
/// kind.
fn check_block(
    block: &Block,
    where_: &str,
    sandbox: &Path,
    problems: &mut Vec<String>,
    counts: &mut std::collections::BTreeMap<String, usize>,
) {
    let Some(marker) = &block.marker else {
        problems.push(format!("{where_}: no <!-- snippet: ... --> marker"));
        return;
    };
    let kind = match parse_kind(marker) {
        Ok(k) => k,
        Err(e) => {
            problems.push(format!("{where_}: {e}"));
            return;
        }
    };
    let shell = matches!(block.lang.as_str(), "sh" | "bash");
    let fits = match &kind {
        Kind::Run { .. } | Kind::Terminals { .. } | Kind::Bench | Kind::Install => shell,
        Kind::Config { .. } => block.lang == "toml",
        Kind::Output(..) | Kind::Synopsis => block.lang == "text",
        Kind::Excerpt(_) | Kind::Elsewhere(_) => true,
    };
    if !fits {
        problems.push(format!(
            "{where_}: `{marker}` does not apply to a {} block",
            block.lang
        ));
        return;
    }
    let started = Instant::now();
    let verdict = check(block, &kind, sandbox);
    eprintln!(
        "{where_}: {marker}: {} in {:.1} s",
        if verdict.is_ok() { "ok" } else { "FAILED" },
        started.elapsed().as_secs_f64()
    );
    *counts
        .entry(
            format!("{kind:?}")
                .split([' ', '('])
                .next()
                .unwrap()
                .to_owned(),
        )
        .or_default() += 1;
    if let Err(e) = verdict {
        problems.push(format!("{where_}: `{marker}`: {e}"));
    }
}

/// The `cargo` stand-in refuses what cargo refuses. `cargo run --release -p flexdyn-acs-demo`,
/// in the Quick start, failed under real cargo ("could not determine which binary to run": the
/// package has two binaries and had no `default-run`) while the old stand-in, which took the
/// package's name for the binary's, ran it. Here the stand-in gets a package list like the old
/// one and must exit 101 with cargo's message; with the workspace's own list (from `cargo
/// metadata`, so the `default-run` line is really there) it must run the demo.
#[test]
fn the_cargo_stand_in_picks_the_binary_as_cargo_does() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("readme_stand_in");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::os::unix::fs::symlink(root().join("tests/readme/stand_in.sh"), dir.join("cargo")).unwrap();
    for bin in ["flexdyn", "flexdyn-acs-demo", "flexdyn-formation-demo"] {
        let fake = dir.join(bin);
        std::fs::write(&fake, format!("#!/bin/sh\necho \"ran {bin} $*\"\n")).unwrap();
        std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let run = |packages: &str, args: &[&str]| -> Output {
        let list = dir.join("packages.txt");
        std::fs::write(&list, packages).unwrap();
        Command::new(dir.join("cargo"))
            .args(args)
            .env("README_PACKAGES", &list)
            .env("README_BIN_DIR", &dir)
            .output()
            .unwrap()
    };
    let quick_start = [
        "run",
        "--release",
        "-p",
        "flexdyn-acs-demo",
        "--",
        "--sigma-rn",
        "0.1,0.2,-0.1",
    ];
    // The package as it was: two binaries, no default-run.
    let old = "flexdyn|flexdyn|flexdyn\nflexdyn-acs-demo||flexdyn-acs-demo,flexdyn-formation-demo\nflexdyn-kernel||\n";
    let out = run(old, &quick_start);
    assert_eq!(out.status.code(), Some(101), "{}", shown(&out));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains(
            "error: `cargo run` could not determine which binary to run. Use the `--bin` option \
             to specify a binary, or the `default-run` manifest key."
        ),
        "{}",
        shown(&out)
    );
    // --bin picks among the package's binaries only; a package without any runs nothing.
    let out = run(
        old,
        &[
            "run",
            "--release",
            "-p",
            "flexdyn-acs-demo",
            "--bin",
            "flexdyn-formation-demo",
        ],
    );
    assert!(out.status.success(), "{}", shown(&out));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "ran flexdyn-formation-demo \n"
    );
    let out = run(
        old,
        &[
            "run",
            "--release",
            "-p",
            "flexdyn-acs-demo",
            "--bin",
            "flexdyn",
        ],
    );
    assert_eq!(out.status.code(), Some(101), "{}", shown(&out));
    let out = run(old, &["run", "--release", "-p", "flexdyn-kernel"]);
    assert_eq!(out.status.code(), Some(101), "{}", shown(&out));
    let out = run(old, &["run", "--release", "-p", "no-such-package"]);
    assert_eq!(out.status.code(), Some(101), "{}", shown(&out));
    // Without -p: the root package, through its default-run.
    let out = run(old, &["run", "--release", "--", "simulate"]);
    assert!(out.status.success(), "{}", shown(&out));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "ran flexdyn simulate\n"
    );
    // The workspace as it is.
    let list = dir.join("workspace.txt");
    write_packages(&list).unwrap();
    let workspace = std::fs::read_to_string(&list).unwrap();
    assert!(
        workspace.starts_with("flexdyn|flexdyn|"),
        "the root package first: {workspace}"
    );
    let demo: Vec<&str> = workspace
        .lines()
        .find(|l| l.starts_with("flexdyn-acs-demo|"))
        .expect("the demo's package")
        .split('|')
        .collect();
    assert_eq!(demo[1], "flexdyn-acs-demo", "its default-run: {workspace}");
    let mut bins: Vec<&str> = demo[2].split(',').collect();
    bins.sort_unstable();
    assert_eq!(
        bins,
        ["flexdyn-acs-demo", "flexdyn-formation-demo"],
        "{workspace}"
    );
    let out = run(&workspace, &quick_start);
    assert!(out.status.success(), "{}", shown(&out));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "ran flexdyn-acs-demo --sigma-rn 0.1,0.2,-0.1\n"
    );
}

#[test]
fn the_checker_catches_what_it_should() {
    // An unmarked block, an unknown marker, an excerpt out of order and a wrong bench are caught.
    let readme = "text\n```sh\nls\n```\n<!-- snippet: made up -->\n```text\nx\n```\n";
    let b = blocks(readme);
    assert_eq!(b.len(), 2);
    assert_eq!(b[0].marker, None);
    assert!(parse_kind(b[1].marker.as_deref().unwrap()).is_err());
    assert!(in_order("a\nb\n", "b a").is_err());
    assert!(in_order("a\n\nb\n", "xa yb").is_ok());
    assert_eq!(
        parse_kind("run (Ctrl-C after 3 s)"),
        Ok(Kind::Run { stop_s: Some(3) })
    );
    assert!(parse_kind("run (Ctrl-C after soon)").is_err());
    let sandbox = PathBuf::from("/nonexistent");
    let bench = Block {
        line: 1,
        lang: "sh".into(),
        marker: None,
        text: "cargo bench --bench no_such_bench\n".into(),
    };
    assert!(check(&bench, &Kind::Bench, &sandbox).is_err());
    let step = Block {
        text: "cargo bench --bench step -- nomatch\n".into(),
        ..bench
    };
    assert!(check(&step, &Kind::Bench, &sandbox).is_ok());
    assert!(check(
        &step,
        &Kind::Elsewhere("a cluster; no file".into()),
        &sandbox
    )
    .is_err());
    assert_eq!(
        commands("# c\na \\\n  b\n\nc # d\n"),
        vec!["a b".to_string(), "c # d".to_string()]
    );
    assert_eq!(
        numbers_as_hash("steps=10000 wall_s=0.04 x1"),
        "steps=# wall_s=# x#"
    );
    assert!(merged_config("[a]\nx = 1\n[b]\ny = 2\n", "[a]\nz = 3\n")
        .unwrap()
        .contains("z = 3"));
}
