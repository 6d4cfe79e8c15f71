#!/usr/bin/env bash
# The test command of README: sets up what the tests need on a fresh machine, then runs them.
#  1. Python oracles: installs the pinned `ruckig` and `pyplcopen` packages and regenerates the
#     committed fixtures into temp files; they must match byte for byte (the oracles are real).
#     It also installs `eclipse-zenoh`, the Python observer of the multi-host tests.
#  2. All binaries (the system tests of tests/system run `tandem`, `tandem-node` and
#     `tandem-gateway` from the target directory: `tandem up` starts the node and the gateway
#     from beside itself), then all Rust tests of the workspace, the system tests among them,
#     in release.
set -euo pipefail
cd "$(dirname "$0")/.."

python3 -m pip install --quiet --disable-pip-version-check -r tests/oracle/requirements.txt -r tests/python/requirements.txt
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 tests/oracle/gen_ruckig_fixtures.py --out "$tmp/ruckig_1dof.csv" >/dev/null
if ! cmp -s "$tmp/ruckig_1dof.csv" shared/motion/tests/fixtures/ruckig_1dof.csv; then
    echo "error: the ruckig fixtures do not match tests/oracle/gen_ruckig_fixtures.py output" >&2
    exit 1
fi
echo "ruckig oracle fixtures: reproduced exactly"
python3 tests/oracle/gen_cam_fixtures.py --out "$tmp/cam_laws.csv" >/dev/null
if ! cmp -s "$tmp/cam_laws.csv" shared/motion/tests/fixtures/cam_laws.csv; then
    echo "error: the cam law fixtures do not match tests/oracle/gen_cam_fixtures.py output" >&2
    exit 1
fi
echo "pyplcopen cam law fixtures: reproduced exactly"

cargo build --workspace --release --locked --bins
cargo test --workspace --release --locked "$@"
