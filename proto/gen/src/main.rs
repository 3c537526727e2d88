//! `cargo run -p flexdyn-wiregen`: writes every mirror of `proto/schema/messages.toml`.
//! `--check`: writes nothing, lists the mirrors that differ and exits with 1 if any does.

use std::path::Path;
use std::process::ExitCode;

fn main() -> ExitCode {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let check = std::env::args().skip(1).any(|a| a == "--check");
    let result = if check {
        flexdyn_wiregen::stale(&root).map(|stale| {
            for p in &stale {
                eprintln!("{} differs from the wire table", p.display());
            }
            stale.is_empty()
        })
    } else {
        flexdyn_wiregen::mirrors(&root).and_then(|mirrors| {
            for m in mirrors {
                let path = root.join(&m.path);
                let old = std::fs::read_to_string(&path).ok();
                if old.as_deref() != Some(m.text.as_str()) {
                    if let Some(dir) = path.parent() {
                        std::fs::create_dir_all(dir)
                            .map_err(|e| format!("{}: {e}", dir.display()))?;
                    }
                    std::fs::write(&path, &m.text)
                        .map_err(|e| format!("{}: {e}", path.display()))?;
                    println!("wrote {}", m.path.display());
                }
            }
            Ok(true)
        })
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("flexdyn-wiregen: {e}");
            ExitCode::from(2)
        }
    }
}
