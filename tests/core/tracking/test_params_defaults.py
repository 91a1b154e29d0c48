"""TrackerParams(model=...) alone is valid: p0 follows the model."""

from core.tracking import TrackerParams
from core.tracking.params import DEFAULT_P0, STATE_DIM


def test_model_alone_takes_that_models_p0() -> None:
    for model in ("cv", "ca"):
        params = TrackerParams(model=model)
        assert len(params.p0) == STATE_DIM[model]
        assert params.p0 == tuple(DEFAULT_P0[model])
        assert params == TrackerParams.default(model)
        assert TrackerParams.from_dict(params.to_dict()) == params
