"""Will the ship meet the IMO manoeuvring standards, and how sure are we (``mmg imo``, ``mmg.imo``).

:mod:`.standard` the standard manoeuvres of one ship and their criteria (IMO Resolution MSC.137(76),
2002, with MSC/Circ.1053), :mod:`.sampling` the ship's parameters sampled from their covariance and
the manoeuvres run per sample (an executor that maps a function over a list of tasks, by default
:func:`trials.files.sweep.run_sweep` on this machine's cores), :mod:`.result` the result object
(:func:`imo`, :class:`ImoResult`) and :mod:`.report` its files (``imo.json``, ``imo.md``, figures).
May import :mod:`mmg`, :mod:`ekf`, :mod:`trials.files`, :mod:`trials.analysis`, :mod:`trials.runs`
and :mod:`trials.measured` (the identified parameters written into a ship).
"""
