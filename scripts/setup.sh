#!/bin/sh
# Set up everything ttt_sm needs on a fresh Debian machine with only python3:
# python3-venv and Graphviz from Debian when missing, then .venv with the
# package and its test dependencies.  Safe to run again: it only does what is
# missing.
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
