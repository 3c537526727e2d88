#!/usr/bin/env bash
# The IMU error examples of docs/models/imu.md ("Keys"): one mistake at a time in a copy of
# scenarios/imu_tactical.toml, `my_craft.toml`, each checked with `flexdyn check-config`. Run by
# tests/cli/readme_snippets.rs, which compares the page's lines with what this prints.
set -u
# In a directory of its own, so that a my_craft.toml of the reader's is left alone.
here=$PWD
cd "$(mktemp -d)"
mistake() { # sed script applied to scenarios/imu_tactical.toml
    sed "$1" "$here/scenarios/imu_tactical.toml" > my_craft.toml
    flexdyn check-config my_craft.toml 2>&1
}
mistake '62s/= 4.3633e-5/= -1/'
mistake '86s/"bracket"/"hub"/'
mistake '75s/= 300.0/= 0/'
mistake '61a arw_deg_rt_h = 0.15'
rm -f my_craft.toml
cd "$here" && rmdir "$OLDPWD"
