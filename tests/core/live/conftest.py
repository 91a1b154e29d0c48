import pytest

from tests.live_capture import write_capture


@pytest.fixture
def capture(tmp_path):
    """(capture bytes, cfg path) of 60 frames at 50 ms."""
    return write_capture(tmp_path)
