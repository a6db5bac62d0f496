"""The fit → validate path as library functions (layer 3, the file layer).

options    :class:`FitOptions`, :class:`ValidateOptions`: typed fields, one per option of
           ``thermocal fit`` / ``thermocal validate`` (a fit's family options in ``params``),
           built from the command line or from a fleet configuration's ``[fit]``/``[validate]``
           tables; ``read_options`` gives how the files are read
reading    :func:`load_recording`: a data file read with the commands' options (text-log
           options, ``--topic``, units as a model file states them)
fit        :func:`fit_files` → :class:`FitResult`: a model (one channel) or a calibration
           (several) fitted on recordings and saved
validate   :func:`validate_files` → :class:`ValidationReport`: a model or calibration judged on
           an independent recording (:func:`thermocal.validation.validate`)
messages   JSON-ready values and warning lines as the command line prints them

Nothing heavy is imported here: ``thermocal fit --help`` loads not even numpy.
"""
