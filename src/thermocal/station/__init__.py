"""The test station: drive a climatic chamber over Modbus, record serial sensors with host
time stamps, and keep the recording crash-safe.

The public entry points: :func:`thermocal.station.config.load_station` reads
``STATION.toml``, :func:`thermocal.station.check.check_station` asks the chamber and every
sensor to answer, :func:`thermocal.station.run.run_station` runs a chamber program and
records it; the folder it writes is read back as one recording by
:func:`thermocal.read_recording`.

Modules:

* ``config``: ``STATION.toml`` → frozen dataclasses (every key checked, errors name the key);
* ``presets``: controllers' register maps read in their makers' manuals;
* ``chamber``: chamber drivers, ``modbus-tcp``, ``modbus-rtu`` (pymodbus) and ``none`` (by
  hand);
* ``sensors``: serial line readers (pyserial), host time stamps, bad lines counted and kept
  aside;
* ``recorder``: Parquet parts closed every ``part_s`` seconds, ``station.json``;
* ``run``: the program loop, set-points, polling, stale sensors, the safe set-point on stop;
* ``sim``: a simulated chamber (a pymodbus server with first-order dynamics) and simulated
  serial sensors on pseudo-terminals, for tests, rehearsals and the demo.

Units: temperatures [°C], times [s]; host time is the station PC's clock
(:func:`thermocal.station.clock.now`: the wall clock at the start plus the monotonic time
since, unmoved by a step of the host's clock), stored relative to the recording's start
time (``station.json``).
pymodbus and pyserial are an optional extra: ``pip install 'thermocal[station]'``.
"""
