"""Tests under core/ keep their on-disk caches (data sets, false-alarm pool) out of ~/.cache."""

import pytest


@pytest.fixture(autouse=True, scope="session")
def _private_cache(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    mp.setenv("RADARTUNE_CACHE", str(tmp_path_factory.mktemp("radartune-cache")))
    yield
    mp.undo()
