"""hstl's gymnasium ids: the top-level module ``_hstl_gym`` holds them and their
registration, so that the wheel's ``hstl-gymnasium.pth`` registers them at interpreter start
without importing hstl; this module is their name inside the package."""

from __future__ import annotations

from _hstl_gym import CONTINUOUS, MAX_EPISODE_STEPS, REGISTERED, install, register

__all__ = ["CONTINUOUS", "MAX_EPISODE_STEPS", "REGISTERED", "install", "register"]
