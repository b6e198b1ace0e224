#!/usr/bin/env bash
# The slow tier, outside CI (about 1 h 20 min on 2 cores): a 1 h soak of the
# robot scenario (SOAK_HOURS=24 for a day), then a longer fuzzing session of
# each target (ADAPTIMP_FUZZ_SECONDS each, default 300; needs the nightly
# toolchain, installs cargo-fuzz into ~/.cargo/bin if missing).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo run --release --example soak -- "${SOAK_HOURS:-1}"

command -v cargo-fuzz >/dev/null || cargo install --locked --quiet cargo-fuzz
for target in config steps abi; do
    (cd fuzz && cargo +nightly fuzz run -O "$target" -- \
        -max_total_time="${ADAPTIMP_FUZZ_SECONDS:-300}" -timeout=5 -rss_limit_mb=2048 2>&1 |
        grep -E "^Done|ERROR|panicked|SUMMARY")
done
