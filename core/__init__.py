"""RadarTune core: radar simulation, processing, IPDA tracking, evaluation and optimisation.

Nothing in this package imports Qt (``tests/test_architecture.py`` proves it).
"""

__version__ = "0.1.0"
