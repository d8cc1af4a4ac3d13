#!/usr/bin/env bash
# Prints the crates only gaitd-view depends on (the Rerun SDK and its
# dependencies): the list the workspace's Cargo.toml builds at opt-level 0
# in the dev profile.
set -euo pipefail
cd "$(dirname "$0")/../.."
view=$(cargo tree -p gaitd-view -e normal,build --prefix none | awk '{print $1}' | sort -u)
rest=$(cargo tree --workspace --exclude gaitd-view -e normal,build,dev --all-features --prefix none \
  | awk '{print $1}' | sort -u)
comm -23 <(echo "$view") <(echo "$rest") | grep -vx gaitd-view
