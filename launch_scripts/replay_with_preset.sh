#!/usr/bin/env bash
# Replays a recorded bag through the filter with one of the presets of params/, where no
# ROS installation is at hand, and scores it against the bag's reference when it has one.
#
#   launch_scripts/replay_with_preset.sh BAG.mcap [PRESET] [extra gnss_ins replay args]
#
# PRESET is a file name of params/ without .yaml (default: ermakf), e.g. ekf, srmakf.
set -euo pipefail

if [[ $# -lt 1 ]]; then
    echo "usage: $0 BAG.mcap [PRESET] [extra gnss_ins replay arguments]" >&2
    exit 2
fi
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bag="$1"
preset="${2:-ermakf}"
shift $(( $# >= 2 ? 2 : 1 ))
params="${repo_root}/params/${preset}.yaml"
if [[ ! -f "${params}" ]]; then
    echo "$0: no preset ${params}" >&2
    exit 2
fi
exec cargo run --quiet --release --manifest-path "${repo_root}/Cargo.toml" --bin gnss_ins -- \
    replay "${bag}" --params "${params}" --truth-topic /ground_truth "$@"
