"""The fit → validate path as library functions (layer 3, the file layer).

options    :class:`FitOptions`, :class:`ValidateOptions`: typed fields, one per option of
           ``thermocal fit`` / ``thermocal validate`` (a fit's family options in ``params``),
           built from the command line or from a fleet configuration's ``[fit]``/``[validate]``
           tables; ``read_options`` gives how the files are read
reading    :func:`read_options` / :func:`read_options_of`: the commands' options as one
           ``ReadOptions``; :func:`check_recording`: what a command needs of a recording
fit        :func:`fit_files` → :class:`FitResult`: a model (one channel) or a calibration
           (several) fitted on recordings and saved
validate   :func:`validate_files` → :class:`ValidationReport`: a model or calibration judged on
           an independent recording (:func:`thermocal.validation.validate`)
compensate :func:`compensate_calibration_file`: a model or calibration applied to a recording
           in chunks with constant memory
messages   JSON-ready values and warning lines as the command line prints them

Nothing heavy is imported here: the help of the ``fit`` command loads not even numpy.
"""
