#!/usr/bin/env bash
# Replays a recorded bag through the filter with one of the presets of params/, where no
# ROS installation is at hand, and scores it against the bag's reference when it has one.
#
#   launch_scripts/replay_with_preset.sh BAG.mcap [PRESET] [extra gnss_ins replay args]
#
# PRESET is a file name of params/ without .yaml (default: ermakf), e.g. ekf, srmakf;
# it is loaded after the manual params/defaults.yaml (the presets hold only what differs).
# With GNSS_INS_DRY_RUN=1 the command is printed instead of run.
set -euo pipefail

if [[ $# -lt 1 ]]; then
    echo "usage: $0 BAG.mcap [PRESET] [extra gnss_ins replay arguments]" >&2
    exit 2
fi
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bag="$1"
preset="${2:-ermakf}"
shift $(( $# >= 2 ? 2 : 1 ))
manual="${repo_root}/params/defaults.yaml"
params="${repo_root}/params/${preset}.yaml"
if [[ ! -f "${params}" ]]; then
    echo "$0: no preset ${params}" >&2
    exit 2
fi
# The manual, then the preset (a later file wins; the manual is not given twice).
params_files=(--params "${manual}")
if [[ "${params}" != "${manual}" ]]; then
    params_files+=(--params "${params}")
fi
command=(cargo run --quiet --release --manifest-path "${repo_root}/Cargo.toml" --bin gnss_ins --
    replay "${bag}" "${params_files[@]}" --truth-topic /ground_truth "$@")
if [[ "${GNSS_INS_DRY_RUN:-}" == 1 ]]; then
    printf '%s\n' "${command[*]}"
    exit 0
fi
exec "${command[@]}"
