#!/usr/bin/env bash
# Starts gnss_ins_node with one of the presets of params/, where no ROS installation is at
# hand (the node speaks DDS itself; ROS_DOMAIN_ID is honoured).
#
#   launch_scripts/run_node_with_preset.sh [PRESET] [NAME:=VALUE ...] [extra ROS arguments]
#
# PRESET is a file name of params/ without .yaml (default: ermakf), e.g. ekf, ekf_loose;
# it is loaded after the manual params/defaults.yaml (the presets hold only what differs).
# NAME:=VALUE sets one of the node's own parameters as the launch file's arguments do:
# use_sim_time, map_frame, base_frame, odom_frame, publish_tf, tf_mode, queue_depth,
# imu_frame (passed as -p NAME:=VALUE, which wins over the preset). Extra arguments follow --ros-args, e.g. -r __ns:=/robot
# -r imu:=/sensors/imu -p gnss.elevation_mask_deg:=15.0.
# With GNSS_INS_DRY_RUN=1 the command is printed instead of run.
set -euo pipefail

# The node's own parameters (src/ros/node/params.rs, NODE_PARAMETERS).
node_parameters=(use_sim_time map_frame base_frame odom_frame publish_tf tf_mode queue_depth imu_frame)

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset="${1:-ermakf}"
shift $(( $# >= 1 ? 1 : 0 ))
manual="${repo_root}/params/defaults.yaml"
params="${repo_root}/params/${preset}.yaml"
if [[ ! -f "${params}" ]]; then
    echo "$0: no preset ${params}" >&2
    exit 2
fi
# The manual, then the preset (a later file wins; the manual is not given twice).
params_files=(--params-file "${manual}")
if [[ "${params}" != "${manual}" ]]; then
    params_files+=(--params-file "${params}")
fi

# Leading NAME:=VALUE arguments of node parameters become -p NAME:=VALUE.
ros_args=()
while [[ $# -gt 0 && "$1" == *:=* ]]; do
    name="${1%%:=*}"
    known=0
    for p in "${node_parameters[@]}"; do
        [[ "${name}" == "${p}" ]] && known=1
    done
    if [[ ${known} -eq 0 ]]; then
        echo "$0: ${name} is not a node parameter (${node_parameters[*]}); use -p for the others" >&2
        exit 2
    fi
    ros_args+=(-p "$1")
    shift
done

command=(cargo run --quiet --release --manifest-path "${repo_root}/Cargo.toml" --bin gnss_ins_node --
    --ros-args "${params_files[@]}" "${ros_args[@]}" "$@")
if [[ "${GNSS_INS_DRY_RUN:-}" == 1 ]]; then
    printf '%s\n' "${command[*]}"
    exit 0
fi
exec "${command[@]}"
