"""Production batches: many units, one machine's processes or a Dask cluster.

The public entry points: :func:`thermocal.fleet.config.load_config` reads the TOML
configuration, :func:`thermocal.fleet.batch.run_fleet` calibrates every unit and writes the
summary and the report, :func:`thermocal.fleet.stats.robust_z` and
:func:`thermocal.fleet.stats.outliers` are the statistics across units.

Modules: ``config`` (the TOML file), ``batch`` (the batch driver: units found, each
calibrated, results and limits gathered), ``stats`` (the figures and their statistics
across units), ``report`` (the fleet's HTML report).
"""
