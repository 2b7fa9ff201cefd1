#!/bin/sh
# Debian's headless Chromium for the browser tests of the Rerun view (tests/view): idempotent.
#
#   scripts/install_chromium.sh
#
# apt-get installs Debian's `chromium` only when no `chromium` is on the PATH. Playwright's or
# Selenium's browser downloads are not used: they fetch browser builds from the internet, which a
# machine with nothing but the package registries cannot reach. Without apt-get (not Debian or
# Ubuntu) it warns and exits 0: the browser test then skips, saying why.
set -eu
if command -v chromium >/dev/null 2>&1; then
    echo "install_chromium: $(chromium --version 2>/dev/null || echo chromium) already installed"
    exit 0
fi
if ! command -v apt-get >/dev/null 2>&1; then
    echo "install_chromium: WARNING: no apt-get (not Debian/Ubuntu): chromium not installed; the browser test of the view will be skipped" >&2
    exit 0
fi
SUDO=""
if [ "$(id -u)" != 0 ]; then
    command -v sudo >/dev/null 2>&1 || { echo "install_chromium: need root (or sudo) for apt-get install chromium" >&2; exit 1; }
    SUDO=sudo
fi
echo "install_chromium: installing chromium"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends chromium
chromium --version
