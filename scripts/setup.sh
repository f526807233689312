#!/bin/sh
# Set up everything ttt_sm needs on a fresh Debian machine with only python3:
# python3-venv, Graphviz and Chromium from Debian when missing, then .venv with
# the package and its test dependencies, then the tests' JavaScript packages
# (tests/js: the Mermaid library the diagram test renders with) when npm is
# there.  Safe to run again: it only does what is missing.
set -eu
cd "$(dirname "$0")/.."

as_root() {
    if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null 2>&1; then sudo "$@"; else
        echo "setup: need root for: $*" >&2; return 1; fi
}
apt_install() {
    if command -v apt-get >/dev/null 2>&1; then
        if [ ! -f /tmp/.ttt_sm_apt_updated ]; then
            as_root apt-get update -qq && touch /tmp/.ttt_sm_apt_updated
        fi
        DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq "$@" >/dev/null
    else
        echo "setup: please install $* with your package manager" >&2
        return 1
    fi
}

if ! python3 -c "import venv, ensurepip" >/dev/null 2>&1; then
    echo "setup: installing python3-venv (Debian)"
    apt_install python3-venv
fi
if ! command -v dot >/dev/null 2>&1; then
    echo "setup: installing graphviz (Debian) for diagram export"
    apt_install graphviz || echo "setup: graphviz not installed; diagram export will be unavailable" >&2
fi
if ! command -v chromium >/dev/null 2>&1; then
    # The browser tests drive Debian's Chromium through Playwright (Playwright's
    # own browser download is not used).
    echo "setup: installing chromium (Debian) for the browser tests"
    apt_install chromium || echo "setup: chromium not installed; browser tests will be skipped" >&2
fi
if [ ! -x .venv/bin/python ]; then
    echo "setup: creating .venv"
    python3 -m venv .venv
fi
stamp=.venv/.ttt_sm-installed
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
    echo "setup: installing ttt_sm and its dependencies into .venv"
    .venv/bin/python -m pip install -q --upgrade pip
    .venv/bin/python -m pip install -q -e ".[test,dev]"
    touch "$stamp"
fi
js_stamp=tests/js/node_modules/.ttt_sm-installed
if [ ! -f "$js_stamp" ] || [ tests/js/package-lock.json -nt "$js_stamp" ]; then
    if command -v npm >/dev/null 2>&1; then
        echo "setup: installing the tests' JavaScript packages (tests/js, npm ci)"
        (cd tests/js && npm ci --no-audit --no-fund --loglevel=error >/dev/null) && touch "$js_stamp"
    else
        echo "setup: npm not found; the Mermaid rendering test will be skipped" >&2
    fi
fi
