"""Plain C99 code computing a model's correction sample by sample.

"Coefficients solidified in the IMU software": :func:`generate_c` turns a model
file's dict (:func:`thermocal.pipeline.model_file.load_model_dict`) into a header and a
source file with

* no dynamic allocation, no library beyond ``<math.h>``-free C99 (``<stddef.h>``);
* the coefficients as ``static const`` arrays, the clamp range of every input;
* a state struct ``<p>_state`` and the functions::

      void    <p>_init(<p>_state *s, double sample_interval_s);
      <p>_real <p>_update(<p>_state *s, double time_s,
                          const <p>_real temps_c[<P>_N_TEMPS], <p>_real signal);
      <p>_real <p>_compensate(<p>_state *s, double time_s,
                              const <p>_real temps_c[<P>_N_TEMPS], <p>_real signal);
      void    <p>_set_known_input(<p>_state *s, <p>_real known_input);

  ``update`` returns the model value ŷ (the temperature-induced signal);
  ``compensate`` returns ``signal − ŷ``.  Signal, known input and results are in the
  data's own unit (the unit the model was fitted on as given, model file ``inputs``;
  ``unit`` for another of the same kind, :func:`c_signal_unit`), named in every
  function's comment and in ``<P>_SIGNAL_UNIT``; the family arithmetic runs in the
  model's unit behind ``<P>_TO_MODEL_UNIT``.  ``temps_c`` are in the model's temperature
  unit (``<P>_TEMPERATURE_UNIT``: °C, or raw counts for a model fitted in counts); a model
  fitted on converted counts also gets ``<p>_temps_from_counts``.  ``init`` is a power-on (it
  forgets every state); ``sample_interval_s`` is the nominal sample interval τ:
  a time step longer than ``GAP_FACTOR`` (1.5) × τ resets the rate estimate, as
  in :class:`thermocal.compensate.kernels.StreamingCompensator`;
* a comment block with the model file's identity (family, format version,
  thermocal version, checksum, signal, temperatures, data files).

Names come from files and parameters (columns, channels, temperatures, triads, ``name``, string
fields of a model file) and may hold anything: every one reaches the C through the one gate,
:mod:`thermocal.identifiers` (identifiers by :func:`~thermocal.identifiers.c_identifier`,
names that meet after mapping refused; comment text by
:func:`~thermocal.identifiers.c_comment`; string literals by
:func:`~thermocal.identifiers.c_string`), and every module is checked by
:func:`~thermocal.identifiers.check_generated_c` before it is written.

The arithmetic follows the family's ``ModelStream`` operation by operation, so
the double build agrees with the Python streaming compensator to rounding
(tests: 1e-9 relative on 10⁵ samples with cc -O2 -std=c99).  Time is ``double``
in both builds; ``real="float"`` makes every other quantity ``float`` and its
worst-case error against double is measured (:func:`measure_float_error`).
Temperatures are always clamped to the fitted range (the Python default,
``extrapolate=False``).

Each family declares its generator on its class (``C_GENERATOR``, next to its options and
chunk context): the modules ``poly``, ``piecewise`` (both methods), ``warmup`` and ``bank`` of
this package, each a ``generate(ctx)``; :mod:`.core` holds the skeleton, :mod:`.harness` the
compile-and-run checks, :mod:`.calibration` one module for a calibration.  Each reads the
``state`` layout
documented in its module docstring and emits only the constants, state and
parameters the model uses, so the module builds with ``-Wall -Wextra -Werror``
(e.g. a poly model without rate terms has no rate buffer or rate constants).
"""

from __future__ import annotations

from thermocal.export.c.calibration import export_c, fitted_sample_interval, generate_c_calibration
from thermocal.export.c.core import (
    REAL_TYPES,
    CExport,
    ExportContext,
    FamilyCode,
    c_signal_unit,
    family_generator,
    generate_c,
)
from thermocal.export.c.harness import (
    CFLAGS,
    FloatError,
    c_harness,
    compile_harness,
    exercise_inputs,
    find_compiler,
    measure_float_error,
    run_harness,
)
from thermocal.identifiers import c_identifier

__all__ = [
    "CFLAGS",
    "REAL_TYPES",
    "CExport",
    "ExportContext",
    "FamilyCode",
    "FloatError",
    "c_harness",
    "c_identifier",
    "c_signal_unit",
    "compile_harness",
    "exercise_inputs",
    "export_c",
    "family_generator",
    "find_compiler",
    "fitted_sample_interval",
    "generate_c",
    "generate_c_calibration",
    "measure_float_error",
    "run_harness",
]
