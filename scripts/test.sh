#!/usr/bin/env bash
# Run every check and test of the project: Rust (format, lints, tests, no_std
# build) and Python (build and install the package, ruff, stubs, pytest).
# Works on a fresh machine with Rust and Python 3.9+; installs what it needs.
#
# The Python package is installed with its test tools into a virtual
# environment under target/ (reused by later runs; override with
# ADAPTIMP_VENV=DIR, the interpreter with PYTHON=...). pip's build of the
# extension reuses the Rust build cache in target/ (CARGO_TARGET_DIR).
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s  [%d s]\n' "$*" "$SECONDS"; }

step "System tools: CMake and valgrind for the C ABI's examples"
need=()
command -v cmake >/dev/null || need+=(cmake)
command -v valgrind >/dev/null || need+=(valgrind)
if [ ${#need[@]} -gt 0 ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
        apt-get update -qq && apt-get install -y -qq "${need[@]}" >/dev/null
    else
        echo "please install: ${need[*]}" >&2
        exit 1
    fi
fi

step "Rust: format, lints"
cargo fmt --all --check
cargo fmt --manifest-path fuzz/Cargo.toml --check
cargo clippy --workspace --all-targets -- -D warnings
cargo clippy --all-targets --features python -- -D warnings

step "Rust: no_std builds of the core (firmware: without and with alloc; the simulator), docs"
cargo build --no-default-features
cargo build --no-default-features --features alloc
cargo build --no-default-features --features sim
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps --quiet

step "Rust: tests (the core, and the C ABI with its header check)"
cargo test --workspace
# The examples under the harness's own arguments (-q, a filter): they must not read them.
cargo test -q --examples runs

step "Fuzzing: a short run of each cargo-fuzz target (nightly)"
if ! cargo +nightly --version >/dev/null 2>&1; then
    echo "the nightly toolchain is needed for cargo-fuzz (rustup toolchain install nightly)" >&2
    exit 1
fi
command -v cargo-fuzz >/dev/null || cargo install --locked cargo-fuzz
for target in config steps abi; do
    (cd fuzz && cargo +nightly fuzz run -O "$target" -- \
        -max_total_time="${ADAPTIMP_FUZZ_SECONDS:-15}" -timeout=5 -rss_limit_mb=2048 2>&1 |
        grep -E "^Done|ERROR|panicked|SUMMARY")
done

step "Python: build and install the package with its test tools"
export CARGO_TARGET_DIR="$PWD/target"
venv="${ADAPTIMP_VENV:-$PWD/target/py-venv}"
if [ ! -x "$venv/bin/python" ]; then
    "${PYTHON:-python3}" -m venv "$venv"
fi
py="$venv/bin/python"
"$py" -m pip install --quiet --disable-pip-version-check ".[test]"

step "Python: ruff, type stubs, mypy"
"$py" -m ruff check python tests examples benches scripts
"$py" -m ruff format --check python tests examples benches scripts
"$py" -m mypy.stubtest adaptimp._adaptimp
"$py" -m mypy

step "Docs: the site, warnings as errors (MkDocs + mkdocstrings)"
NO_MKDOCS_2_WARNING=1 "$py" -m mkdocs build --strict --quiet

step "Python: tests"
"$py" -m pytest
