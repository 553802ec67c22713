#!/usr/bin/env bash
# Starts gnss_ins_node with one of the presets of params/, where no ROS installation is at
# hand (the node speaks DDS itself; ROS_DOMAIN_ID is honoured).
#
#   launch_scripts/run_node_with_preset.sh [PRESET] [extra ROS arguments]
#
# PRESET is a file name of params/ without .yaml (default: ermakf), e.g. ekf, ekf_loose.
# Extra arguments follow --ros-args, e.g. -r __ns:=/robot -r imu:=/sensors/imu.
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset="${1:-ermakf}"
shift $(( $# >= 1 ? 1 : 0 ))
params="${repo_root}/params/${preset}.yaml"
if [[ ! -f "${params}" ]]; then
    echo "$0: no preset ${params}" >&2
    exit 2
fi
exec cargo run --quiet --release --manifest-path "${repo_root}/Cargo.toml" --bin gnss_ins_node -- \
    --ros-args --params-file "${params}" "$@"
