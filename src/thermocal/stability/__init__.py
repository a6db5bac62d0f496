"""Frequency-stability analysis: the NIST SP 1065 deviation family (:mod:`.deviations`),
Greenhall's equivalent degrees of freedom and power-law noise identification (:mod:`.edf`),
several deviations of one record with intervals (:mod:`.family`), IEEE 952 noise terms read
where real sensors show them (:mod:`thermocal.stability.allan`) and the noise model for estimators
(:mod:`.noise_model`).  Pure numpy/scipy maths: no I/O, no plotting."""
