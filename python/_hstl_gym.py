"""hstl's gymnasium ids, registered without importing gymnasium or hstl first.

This module is top-level (not in the ``hstl`` package) so that the wheel's
``hstl-gymnasium.pth`` can import it at every interpreter start without loading hstl's
extension: gymnasium 1.x has no plugin entry points, and this is how
``gymnasium.make("hstl/GridWorld-v0")`` works without ``import hstl`` (setuptools and
coverage start the same way). It costs well under a millisecond; ``HSTL_NO_GYMNASIUM_IDS=1``
turns it off. ``import hstl`` calls ``install()`` too, for installs without the ``.pth``.

``import hstl`` does not import gymnasium (it costs about 150 ms, and most uses of the
monitors need none of it). The ids still work as gymnasium users expect: when gymnasium is
already imported, ``install()`` registers them at once; otherwise it puts a finder on
``sys.meta_path`` that registers them as soon as gymnasium's own import ends, and then
leaves. Registering needs only strings (``entry_point="hstl._gym:GridWorldEnv"``), so
``hstl._gym`` itself loads when an environment is first made.
"""

from __future__ import annotations

import sys

# Only what the interpreter has loaded anyway is imported at startup: `importlib.abc` alone
# took about 20 ms, so the finder and loader are the protocols, not subclasses.
TYPE_CHECKING = False
if TYPE_CHECKING:
    import importlib.machinery
    import types
    from typing import Any, Optional, Sequence

#: The episode length of the registered environments: the length of the greedy runs that
#: ``hstlc eval`` and ``Policy.evaluate`` score (their ``steps`` default).
MAX_EPISODE_STEPS = 2000

#: The ids registered for the built-in grid worlds, and the world each makes.
REGISTERED = {"hstl/GridWorld-v0": "paper", "hstl/FourRooms-v0": "four-rooms"}

#: The ids registered for the continuous worlds: each one's entry point and default kwargs
#: (``gymnasium.make(id, world=...)`` and ``window=`` override them).
CONTINUOUS: dict[str, tuple[str, dict[str, Any]]] = {
    "hstl/Plane-v0": ("hstl._gym:PlaneEnv", {"world": "paper-plane"}),
    "hstl/MountainCar-v0": ("hstl._gym:MountainCarEnv", {}),
    "hstl/MountainCarPatrol-v0": ("hstl._gym:make_mountain_car_patrol", {"window": 200}),
}


def register() -> None:
    """Registers the built-in worlds' ids with gymnasium (imports it; idempotent)."""
    import gymnasium
    from gymnasium.envs.registration import registry

    ids = {env_id: ("hstl._gym:GridWorldEnv", {"world": world}) for env_id, world in REGISTERED.items()}
    ids.update(CONTINUOUS)
    for env_id, (entry_point, kwargs) in ids.items():
        if env_id not in registry:
            gymnasium.register(
                id=env_id,
                entry_point=entry_point,
                kwargs=dict(kwargs),
                max_episode_steps=MAX_EPISODE_STEPS,
            )


def startup() -> None:
    """What ``hstl-gymnasium.pth`` runs at interpreter start: ``install()``, unless the
    environment sets ``HSTL_NO_GYMNASIUM_IDS`` to anything but ``""`` or ``0``."""
    import os

    if os.environ.get("HSTL_NO_GYMNASIUM_IDS", "") in ("", "0"):
        install()


def install() -> None:
    """Registers the ids now if gymnasium is imported, else once it is."""
    if "gymnasium" in sys.modules:
        register()
    elif not any(isinstance(f, _RegisterAfterImport) for f in sys.meta_path):
        sys.meta_path.insert(0, _RegisterAfterImport())


class _RegisterAfterImport:
    """Finds gymnasium as the other finders do, and wraps its loader so that the ids are
    registered right after the package has run; removes itself once it has."""

    def find_spec(
        self, fullname: str, path: Optional[Sequence[str]], target: Optional[types.ModuleType] = None
    ) -> Optional[importlib.machinery.ModuleSpec]:
        if fullname != "gymnasium":
            return None
        if self in sys.meta_path:
            sys.meta_path.remove(self)
        for finder in sys.meta_path:
            find = getattr(finder, "find_spec", None)
            spec: Optional[importlib.machinery.ModuleSpec] = find(fullname, path, target) if find is not None else None
            if spec is not None:
                if spec.loader is not None and hasattr(spec.loader, "exec_module"):
                    # A loader by its methods, not its class (see the imports above).
                    spec.loader = _Loader(spec.loader)  # type: ignore[assignment]
                return spec
        return None


class _Loader:
    """gymnasium's own loader, then the registration."""

    def __init__(self, loader: Any) -> None:
        self._loader = loader

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> Optional[types.ModuleType]:
        module: Optional[types.ModuleType] = self._loader.create_module(spec)
        return module

    def exec_module(self, module: types.ModuleType) -> None:
        self._loader.exec_module(module)
        try:
            register()
        except Exception as e:  # gymnasium itself imported; only the ids are missing
            import warnings

            warnings.warn(f"hstl could not register its gymnasium ids: {e}", stacklevel=2)

    def __getattr__(self, name: str) -> Any:
        # What else importlib or a resource reader asks of the loader is gymnasium's.
        if name == "_loader":
            raise AttributeError(name)
        return getattr(self._loader, name)
