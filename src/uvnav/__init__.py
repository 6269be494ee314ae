"""uvnav: real-time navigation of unmanned vehicles.

Importing uvnav makes its Gymnasium envs (``uvnav/Nav2D-v0``, ``uvnav/Nav3D-v0``,
``uvnav/UUV2D-v0``) known to gymnasium, whichever of the two is imported first, without importing
gymnasium itself (it costs a tenth of a second that the command line does not need): when
gymnasium is already imported they are registered now, else once its import completes
(:func:`uvnav.envs.register_envs`).  So ``import gymnasium, uvnav; gymnasium.make(
"uvnav/Nav2D-v0")`` works, as does the other order.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import importlib.util
import sys
from types import ModuleType

__version__ = "0.1.0"


def _register_envs() -> None:
    """Register the envs with the imported gymnasium (nothing when the envs extra is missing)."""
    try:
        from uvnav.envs import register_envs
    except ImportError:  # pragma: no cover - without the envs extra
        return
    register_envs()


class _AfterGymnasium(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """A one-shot import hook: gymnasium's own loader runs, then the envs are registered."""

    def __init__(self) -> None:
        self._loader: importlib.abc.Loader | None = None

    def find_spec(
        self, fullname: str, path: object = None, target: ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        if fullname != "gymnasium":
            return None
        sys.meta_path.remove(self)  # one shot; the search below finds the real one
        spec = importlib.util.find_spec(fullname)
        if spec is None or spec.loader is None:
            return spec
        self._loader, spec.loader = spec.loader, self
        return spec

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType | None:
        assert self._loader is not None
        return self._loader.create_module(spec)

    def exec_module(self, module: ModuleType) -> None:
        assert self._loader is not None
        module.__spec__.loader = self._loader  # type: ignore[union-attr]
        self._loader.exec_module(module)
        _register_envs()


if "gymnasium" in sys.modules:
    _register_envs()
elif importlib.util.find_spec("gymnasium") is not None:
    sys.meta_path.insert(0, _AfterGymnasium())
