#!/usr/bin/env bash
# The "Errors" example of docs/guides/configuration.md: one mistake at a time in a copy of the
# embedded default, `my_craft.toml`, each checked with `flexdyn check-config`. Run by
# tests/cli/readme_snippets.rs, which compares the page's lines with what this prints.
set -u
# In a directory of its own, so that a my_craft.toml of the reader's is left alone.
here=$PWD
cd "$(mktemp -d)"
mistake() { # sed script applied to the default configuration
    flexdyn print-default-config | sed "$1" > my_craft.toml
    flexdyn check-config my_craft.toml 2>&1
}
mistake '47s/mass_kg = 50.0/mass_kg = -50/'
mistake '19a colour = "red"'
mistake '22s/\[0.0, 0.0, 1.0\]/[0.0, 0.0, 1.0, 0.0, 0.0]/'
mistake '20d'
mistake '28s/\[0.05,/[nan,/'
mistake '12s/0.001 /0.003 /'
mistake '20s/750.0/750.0.0/'
rm -f my_craft.toml
cd "$here" && rmdir "$OLDPWD"
