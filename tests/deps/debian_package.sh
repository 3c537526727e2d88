#!/bin/sh
# Installs a Debian package a test needs: `debian_package.sh PROGRAM PACKAGE` exits 0 when
# PROGRAM (a path, or a name on the PATH) is there, installing PACKAGE with apt-get first if it
# is not and this runs as root (CI runs as root on a fresh Debian machine); otherwise it says
# what to install and exits 1. A PROGRAM path need only exist (a library file counts). Used by
# tests/cli/web_view.rs (chromium), clients/c/tests/c_client.rs (valgrind) and
# proto/tests/c_libfuzzer.rs (clang and its libFuzzer runtime).
set -eu
program=$1
package=$2
have() { command -v "$program" >/dev/null 2>&1 || [ -e "$program" ]; }
if have; then
    exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
    echo "debian_package.sh: $program is missing and this is not root; install it: sudo apt-get install $package" >&2
    exit 1
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "debian_package.sh: $program is missing and there is no apt-get here; install $package" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get install -y "$package" || { apt-get update && apt-get install -y "$package"; }
have
