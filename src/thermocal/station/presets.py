"""Register maps of chamber controllers, from their makers' published communications
manuals (``[chamber] preset = NAME`` in ``STATION.toml``).

A preset fills in the register addresses, the register kind and the sign of the generic
map (:class:`thermocal.station.chamber.RegisterMap`); it never fills in ``scale``: these
controllers send temperatures as 16-bit integers at the resolution configured on the
controller's display (one decimal place: 0.1 °C per count; none: 1 °C per count), which no
manual can state for a given chamber.  A key of the map given beside a preset must agree
with it: a set-point written to the wrong register is the one mistake a station must not
make, so a disagreement is an error, not an override.

Only maps read in a manual (or in a maker's document quoting it, named below) are here;
controllers whose map depends on firmware options (Watlow F4/F4T, ESPEC, Vötsch/Weiss
SIMPATI) are left to the generic keys.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ControllerPreset:
    """A controller's register map, as its maker's manual gives it.

    Parameters
    ----------
    name : str
        The preset's name (``[chamber] preset``).
    setpoint_register : int
        The set-point register written.
    temperature_register : int
        The temperature (process value) register read.
    register_kind : str
        ``"holding"`` or ``"input"``.
    signed : bool
        Signed 16-bit counts.
    source : str
        The manual the map was read in.
    note : str
        What the controller must be set to for the map to hold.
    """

    name: str
    setpoint_register: int
    temperature_register: int
    register_kind: str
    signed: bool
    source: str
    note: str


PRESETS: dict[str, ControllerPreset] = {
    "eurotherm-2000": ControllerPreset(
        name="eurotherm-2000",
        setpoint_register=24,  # SP1, the local set-point (read/write)
        temperature_register=1,  # PV, the process value (read only)
        register_kind="holding",
        signed=True,
        source=(
            "Eurotherm 2000 Series Communications Handbook, HA026230 (Modbus addresses: "
            "1 process variable, 24 setpoint 1; scaled integers at the configured "
            "resolution), as tabulated in AERCO OMM-0003 Appendix A (Eurotherm 2408)"
        ),
        note=(
            "2204/2208/2216/2404/2408/2416 controllers: setpoint 1 must be the selected "
            "set-point (SP.SL = SP1) and the controller in Modbus mode at the station's "
            "unit (slave) address"
        ),
    ),
}
"""Known presets by name."""

MAP_KEYS = ("setpoint_register", "temperature_register", "register_kind", "signed")
"""The keys of ``[chamber]`` a preset sets."""


__all__ = ["MAP_KEYS", "PRESETS", "ControllerPreset"]
