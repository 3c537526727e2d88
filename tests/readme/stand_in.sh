#!/usr/bin/env bash
# Stands in for `cargo`, `flexdyn`, `flexdyn-acs-demo`, `flexdyn-formation-demo` and
# `flexdyn-monitor` while tests/cli/readme_snippets.rs runs the shell blocks of the README and the
# book (it links this file under each name in the sandbox's `target/release`, which is first on
# the PATH). Each block runs in its own network namespace, so the documents' ports are used as
# written and collide with nothing.
#
# - `cargo run --release [-p PKG] [--bin BIN] [-- ARGS]` runs the binary the suite built, as
#   cargo would after its (no-op) build, and picks it as cargo does: `--bin BIN` must be a binary
#   of PKG; without it, PKG's only binary, else its `default-run`, else cargo's own refusal
#   ("could not determine which binary to run", exit 101). Without `-p`, PKG is the root
#   package. What PKG holds comes from `$README_PACKAGES`, which the test writes from
#   `cargo metadata` (one line per package: `name|default-run|bin,bin,…`, the root
#   package's line first). `cargo build --release --workspace` checks that every
#   binary is there; `cargo test --workspace --release` is the suite running this, so it only
#   says so. Any other cargo command fails: a block that needs one is not a `run` block.
# - A command that runs until Ctrl-C (the server without --duration-s, `record`, `view`, the demo
#   without --idle-exit-s, the monitor without --duration-s) gets SIGINT after $README_STOP_S
#   seconds, as a user would press Ctrl-C, and must then exit 0 on its own. Without
#   README_STOP_S it runs until it ends.
set -u
name=$(basename "$0")
real="$README_BIN_DIR/$name"
args=("$@")
has() { local a; for a in "${args[@]}"; do [[ $a == "$1" || $a == "$1="* ]] && return 0; done; return 1; }
forever=0
case "$name" in
cargo)
    case "${args[*]}" in
    "build --release --workspace")
        for b in flexdyn flexdyn-acs-demo flexdyn-monitor; do
            [[ -x $README_BIN_DIR/$b ]] || { echo "readme stand-in: $b was not built" >&2; exit 1; }
        done
        echo "readme stand-in: the suite's build already built the workspace" >&2
        exit 0 ;;
    "test --workspace --release")
        echo "readme stand-in: this is the suite that is running now" >&2
        exit 0 ;;
    esac
    [[ ${args[0]:-} == run && ${args[1]:-} == --release ]] ||
        { echo "readme stand-in: \`cargo ${args[*]}\` is not run by the snippet test" >&2; exit 97; }
    pkg=
    bin=
    rest=()
    i=2
    while ((i < ${#args[@]})); do
        case "${args[i]}" in
        -p) pkg=${args[i + 1]}; i=$((i + 2)) ;;
        --bin) bin=${args[i + 1]}; i=$((i + 2)) ;;
        --) rest=("${args[@]:i+1}"); break ;;
        *) echo "readme stand-in: unexpected cargo argument ${args[i]}" >&2; exit 97 ;;
        esac
    done
    [[ -r ${README_PACKAGES:-} ]] ||
        { echo "readme stand-in: README_PACKAGES names no readable file" >&2; exit 97; }
    line=
    if [[ -z $pkg ]]; then
        IFS= read -r line < "$README_PACKAGES"
        pkg=${line%%|*}
    else
        while IFS= read -r l; do
            [[ ${l%%|*} == "$pkg" ]] && { line=$l; break; }
        done < "$README_PACKAGES"
        [[ -n $line ]] ||
            { echo "error: package(s) \`$pkg\` not found in workspace" >&2; exit 101; }
    fi
    IFS='|' read -r _ default_run bins <<< "$line"
    IFS=, read -r -a pkg_bins <<< "$bins"
    if [[ -n $bin ]]; then
        found=0
        for b in "${pkg_bins[@]}"; do [[ $b == "$bin" ]] && found=1; done
        ((found)) || {
            echo "error: no bin target named \`$bin\` in \`$pkg\` package" >&2
            exit 101
        }
    elif ((${#pkg_bins[@]} == 0)); then
        echo "error: a bin target must be available for \`cargo run\`" >&2
        exit 101
    elif ((${#pkg_bins[@]} == 1)); then
        bin=${pkg_bins[0]}
    elif [[ -n $default_run ]]; then
        bin=$default_run
    else
        echo "error: \`cargo run\` could not determine which binary to run. Use the \`--bin\` option to specify a binary, or the \`default-run\` manifest key." >&2
        echo "available binaries: ${bins//,/, }" >&2
        exit 101
    fi
    exec "$(dirname "$0")/$bin" "${rest[@]}" ;;
flexdyn)
    sub=${args[0]:-run}
    [[ $sub == -* ]] && sub=run
    case "$sub" in
    run) has --duration-s || forever=1 ;;
    record | view) forever=1 ;;
    esac ;;
flexdyn-acs-demo | flexdyn-formation-demo) has --idle-exit-s || forever=1 ;;
flexdyn-monitor) has --duration-s || forever=1 ;;
esac
if ((forever)) && [[ -n ${README_STOP_S:-} ]]; then
    exec timeout -s INT -k 20 --preserve-status "$README_STOP_S" "$real" "${args[@]}"
fi
exec "$real" "${args[@]}"
