"""bench transfer: its held-out figures and its refusal without the public recordings."""

import pytest

from core.benchmarks import transfer
from core.errors import InputError
from core.tracking import TrackerParams


def test_without_the_recordings_one_line(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("RADARTUNE_REAL", str(tmp_path))
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match="RADARTUNE_REAL"):
        transfer.real_folder()


def test_scores_of_a_walker_and_a_reference(walker_and_reference) -> None:
    walker, reference = walker_and_reference("ab")
    s = transfer._scores(TrackerParams.default("cv").to_dict(), walker, reference)
    assert set(transfer.FIGURES) <= set(s)
    assert 0.8 < s["walker_right_count"] <= 1.0  # one synthetic walker, mostly one track
    assert s["reference_mean_gospa_m"] < 0.6  # the reference is the walker's own path
