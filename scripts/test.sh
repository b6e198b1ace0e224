#!/usr/bin/env bash
# Run every check and test of the project: Rust (format, lints, tests, no_std
# build) and Python (build and install the package, ruff, stubs, pytest).
# Works on a fresh machine with Rust and Python 3.9+; installs what it needs.
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s\n' "$*"; }

step "Rust: format, lints"
cargo fmt --check
cargo clippy --all-targets -- -D warnings

step "Rust: no_std build of the core"
cargo build --no-default-features

step "Rust: tests"
cargo test
