#!/bin/sh
# Installs Debian's Chromium for tests/cli/web_view.rs (issue 36: `flexdyn view`'s web page is
# checked in a real headless browser). Runs `apt-get install -y chromium` when run as root (CI
# runs as root on Debian); otherwise says what to install. Exit status 0 when
# /usr/bin/chromium is there afterwards.
set -eu
if [ -x /usr/bin/chromium ]; then
    exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
    echo "install_chromium.sh: not root; install Debian's Chromium yourself: sudo apt-get install chromium" >&2
    exit 1
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "install_chromium.sh: no apt-get here; install Chromium so that /usr/bin/chromium exists" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get install -y chromium || { apt-get update && apt-get install -y chromium; }
test -x /usr/bin/chromium
