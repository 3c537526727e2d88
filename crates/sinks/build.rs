//! Records the git commit flexdyn is built from (for recordings' metadata), when the source is a
//! git checkout and `git` is installed; otherwise the commit is "unknown".
//!
//! It watches the files that change with the commit, where git keeps them: in a linked worktree
//! `.git` is a file and HEAD lives elsewhere. A watched file that does not exist would make cargo
//! rerun this script, and rebuild the crate and every test linking it, at every build.

use std::path::PathBuf;
use std::process::Command;

/// `git rev-parse <args>` in this package's directory, trimmed; `None` without git or a checkout.
fn git(args: &[&str]) -> Option<String> {
    Command::new("git")
        .args(args)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_owned())
}

fn main() {
    let git_dir = git(&["rev-parse", "--git-dir"]).map(PathBuf::from);
    let common_dir = git(&["rev-parse", "--git-common-dir"]).map(PathBuf::from);
    match (git_dir, common_dir) {
        (Some(git_dir), Some(common_dir)) => {
            for watched in [git_dir.join("HEAD"), common_dir.join("refs/heads")] {
                if watched.exists() {
                    println!("cargo:rerun-if-changed={}", watched.display());
                }
            }
        }
        // Not a checkout: nothing to watch but this script.
        _ => println!("cargo:rerun-if-changed=build.rs"),
    }
    let commit = git(&["rev-parse", "HEAD"]).unwrap_or_default();
    println!("cargo:rustc-env=FLEXDYN_GIT_COMMIT={commit}");
}
