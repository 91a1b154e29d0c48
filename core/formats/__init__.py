"""Files radar engineers already have, read and written by RadarTune.

One module per format: ``ti_cfg`` (TI mmWave SDK CLI configuration ``.cfg``: reader and writer
of :class:`~core.config.RadarConfig`).
"""
