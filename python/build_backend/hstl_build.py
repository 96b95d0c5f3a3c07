"""The build backend of ``pip install ./python``: maturin's, with two changes.

- Without cargo on ``PATH`` the build stops at once with one line that says what is missing
  and what to do, instead of maturin's default of downloading a Rust toolchain into a
  temporary folder (``puccinialin``), which fails with a long traceback on a machine that
  cannot reach the Rust servers. ``HSTL_INSTALL_RUST=1`` in the environment brings
  maturin's download back.
- The build says that it compiles Rust and how long that takes, before cargo starts.

pip shows a backend's output only with ``pip install -v`` (or when the build fails), so
cargo's progress is seen with ``-v``; nothing here can change that (README, "Python").
Everything else is maturin's own hook, unchanged.
"""

from __future__ import annotations

import os
import shutil
import sys
from typing import Any, Mapping, Optional

_DOWNLOAD = os.environ.get("HSTL_INSTALL_RUST") == "1"
if not _DOWNLOAD:
    # Read by maturin's hooks (get_requires_for_build_wheel adds puccinialin without it).
    os.environ.setdefault("MATURIN_NO_INSTALL_RUST", "1")

from maturin import *  # noqa: E402,F401,F403 - the hooks this module does not change
from maturin import build_editable as _build_editable  # noqa: E402
from maturin import build_wheel as _build_wheel  # noqa: E402
from maturin import prepare_metadata_for_build_wheel as _prepare_metadata  # noqa: E402

_NO_CARGO = (
    "hstl: cannot build: cargo is not on PATH, and the package compiles its Rust extension; "
    "install Rust (https://rustup.rs, or the system's package manager) and run pip again, set "
    "HSTL_INSTALL_RUST=1 to let maturin download a toolchain, or install a wheel built where "
    "Rust is (scripts/wheel)"
)


def _check_cargo() -> None:
    if not _DOWNLOAD and shutil.which("cargo") is None:
        sys.stderr.write(_NO_CARGO + "\n")
        sys.exit(1)


def _say_building() -> None:
    print(
        "hstl: compiling the Rust extension with cargo (release): 2-3 minutes on 2 cores the "
        "first time, quicker after; pip shows cargo's progress with -v",
        flush=True,
    )


def prepare_metadata_for_build_wheel(metadata_directory: str, config_settings: Optional[Mapping[str, Any]] = None) -> str:
    _check_cargo()
    return str(_prepare_metadata(metadata_directory, config_settings))


def build_wheel(
    wheel_directory: str,
    config_settings: Optional[Mapping[str, Any]] = None,
    metadata_directory: Optional[str] = None,
) -> str:
    _check_cargo()
    _say_building()
    return str(_build_wheel(wheel_directory, config_settings, metadata_directory))


def build_editable(
    wheel_directory: str,
    config_settings: Optional[Mapping[str, Any]] = None,
    metadata_directory: Optional[str] = None,
) -> str:
    _check_cargo()
    _say_building()
    return str(_build_editable(wheel_directory, config_settings, metadata_directory))
