"""What a record shows, measured or simulated.  The IMO manoeuvre metrics (:mod:`.metrics`: turning
advance, transfer and diameters, zigzag overshoots, initial turning time and period; ``mmg metrics``)
and the linear Nomoto models identified from a zigzag (:mod:`.nomoto`, pure numerics), with their
plot (:mod:`.nomoto_plot`) and the ``mmg nomoto`` report (:mod:`.nomoto_report`).  "The zigzag
overshoot is wrong on real records" starts here (and, for reading the record, in
:mod:`trials.files`).  May import :mod:`mmg` and :mod:`trials.files`.
"""
