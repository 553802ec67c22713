#!/usr/bin/env bash
# Creates the Python virtual environment `.venv/` at the repository root and installs the
# independent test peers of tools/requirements-test-peers.txt into it (from PyPI): rosbags,
# Eclipse Cyclone DDS and ROS 2 Jazzy's rclpy on Fast DDS (about 160 MB of the venv's
# 315 MB; from an empty pip cache the whole install took 26 s to 2 min here, by load).
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
# The Jazzy peer's libraries load (through the LD_LIBRARY_PATH that ros-wheels-bootstrapper
# sets), Fast DDS among them; this creates no DDS participant, so sends nothing.
RMW_IMPLEMENTATION=rmw_fastrtps_cpp "${venv_dir}/bin/python" -c "
import diagnostic_msgs.msg, nav_msgs.msg, rcl_interfaces.msg, rosgraph_msgs.msg, sensor_msgs.msg
from rclpy.utilities import get_rmw_implementation_identifier as rmw
assert rmw() == 'rmw_fastrtps_cpp', rmw()
"
echo "setup_test_peers: ready (${venv_dir}/bin/python)"
