"""Storage URLs: accepted forms and one clear line for bad ones."""

from __future__ import annotations

from pathlib import Path

import pytest

from core.errors import InputError
from core.optimization.storage import absolute_url, kind, normalize_url, open_storage, redact


def test_url_forms() -> None:
    assert normalize_url("studies.db") == "sqlite:///studies.db"
    assert normalize_url("runs/x.log") == "journal:///runs/x.log"
    assert normalize_url("postgresql://u@h:5/d") == "postgresql+psycopg2://u@h:5/d"
    assert kind("journal:///a.log") == "journal" and kind("postgres://u@h/d") == "postgresql"
    assert absolute_url("sqlite:///a.db") == f"sqlite:///{Path('a.db').resolve()}"


@pytest.mark.parametrize(
    ("url", "message"),
    [
        ("mysql://u@h/d", "unknown scheme 'mysql'"),
        ("studies.txt", "expected sqlite:///FILE.db"),
        ("sqlite://x.db", "needs three slashes"),
        ("", "empty"),
    ],
)
def test_bad_urls(url: str, message: str) -> None:
    with pytest.raises(InputError, match=message):
        normalize_url(url)


def test_missing_folder_and_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="does not exist"):
        open_storage(f"sqlite:///{tmp_path}/nope/x.db")
    with pytest.raises(InputError, match="does not exist"):
        open_storage(f"journal:///{tmp_path}/x.log", create=False)


def test_redact_hides_the_password() -> None:
    assert redact("postgresql://bob:secret@h:5/d") == "postgresql://bob:***@h:5/d"
