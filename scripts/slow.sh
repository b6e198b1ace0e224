#!/usr/bin/env bash
# The slow tier, outside CI (about 10 minutes on 2 cores): a 1 h soak of the
# robot scenario, and a short fuzzing session of each target (needs the
# nightly toolchain; installs cargo-fuzz if missing).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo run --release --example soak -- "${SOAK_HOURS:-1}"
