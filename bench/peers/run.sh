#!/usr/bin/env bash
# Side-by-side timing of the peer STL monitors on the benchmark walk (not for CI).
# Installs them into /work/main/.venv-bench (see setup.sh), writes the walk CSV with the
# hstl-robustness example, and prints a table of samples/s. Extra arguments go to peers.py
# (e.g. --steps 100000 --repeats 1).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
here="$root/bench/peers"
[ -x "$root/.venv-bench/bin/python" ] || "$here/setup.sh"
walk="$root/target/walk.csv"
(cd "$root" && cargo run --release -q -p hstl-robustness --example walk -- "$walk")
"$root/.venv-bench/bin/python" "$here/peers.py" "$walk" "$@"
