#!/usr/bin/env bash
# Creates the peers' venv at the repo root's .venv-bench/ and installs the four monitors,
# tidystl (dense time), and what run.sh --dense needs to build and run hstl's package.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
venv="$root/.venv-bench"
if ! command -v bison >/dev/null || ! command -v flex >/dev/null; then
    apt-get install -y bison flex
fi
[ -d "$venv" ] || python3.11 -m venv "$venv"
"$venv/bin/pip" install --upgrade pip wheel setuptools
"$venv/bin/pip" install rtamt==0.4.10 || echo "rtamt failed to install" >&2
"$venv/bin/pip" install pybanquo==0.1.1 || echo "pybanquo failed to install" >&2
"$venv/bin/pip" install mstlo-python==0.2.2 || echo "mstlo-python failed to install" >&2
"$venv/bin/pip" install stlrom || echo "stlrom failed to install" >&2
"$venv/bin/pip" install tidystl==0.2.0 || echo "tidystl failed to install" >&2
"$venv/bin/pip" install numpy==2.4.6 pandas==3.1.1 maturin==1.16.0
