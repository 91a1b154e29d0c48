"""Files radar engineers already have, read and written by RadarTune.

One module per format: ``ti_cfg`` (TI mmWave SDK CLI configuration ``.cfg``: reader and writer
of :class:`~core.config.RadarConfig`), ``ti_uart`` (the TI mmWave demos' UART TLV stream of
every SDK generation: streaming reader, writer) with ``ti_uart_import`` (a log as a recording),
``ti_replay`` (TI Industrial Visualizer replay files). ``recording`` turns a recording and an
optional truth CSV into a :class:`~core.dataset.Dataset`; ``table`` is the one table of the
formats ``radartune import`` / ``export`` know.
"""
