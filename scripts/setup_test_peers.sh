#!/usr/bin/env bash
# Creates the Python virtual environment `.venv/` at the repository root and installs the
# independent test peers of tools/requirements-test-peers.txt into it (from PyPI).
# Idempotent: an existing venv is reused and pip skips what is already installed.
# Any failure stops the script with a non-zero exit status.
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv_dir="${repo_root}/.venv"
requirements="${repo_root}/tools/requirements-test-peers.txt"

if [[ ! -f "${requirements}" ]]; then
    echo "setup_test_peers: missing ${requirements}" >&2
    exit 1
fi

if [[ ! -x "${venv_dir}/bin/python" ]]; then
    echo "setup_test_peers: creating ${venv_dir}"
    python3 -m venv "${venv_dir}"
fi

"${venv_dir}/bin/python" -m pip install --quiet --disable-pip-version-check \
    --requirement "${requirements}"

"${venv_dir}/bin/python" -c "import rosbags, cyclonedds.domain"
echo "setup_test_peers: ready (${venv_dir}/bin/python)"
